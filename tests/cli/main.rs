//! Integration tests of the `lambert` command line: errors and hints, outputs, rendering, progress, determinism, shards and fuzzing.
//!
//! Every file under `tests/cli/` is a module here, and this area a module of the one
//! integration-test binary (`tests/integration.rs`). Run one with
//! `cargo test --release --test integration cli::<module>::`.
mod cli_errors;
mod cli_hints;
mod cli_mesh;
mod cli_outputs;
mod cli_progress;
mod cli_render;
mod cli_rough_edges;
mod cli_solve;
mod cli_vs3;
mod determinism;
mod fuzz;
mod points;
mod quiet;
mod shards;
mod small_messages;
mod vtk_output;
