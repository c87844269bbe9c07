//! The integration tests, one binary: each area is a module over its folder (every file in
//! it a module), so a fresh `cargo test --release` compiles and links the test code once
//! instead of once per area (the link-time optimisation of each test binary was most of the
//! test build). Run one area or module with
//! `cargo test --release --test integration viewfactor::auto::`.
//!
//! - [`viewfactor`]: exact kernels, `auto`, hemicube, Monte Carlo, shadows and visibility;
//! - [`scene`]: TOML, glTF/GLB, STL/OBJ meshes, .vs3, patching and their errors;
//! - [`heat`]: the exchange and the solve on every store, bands, conductances and decks;
//! - [`cli`]: the command line: errors, hints, outputs, rendering, progress, determinism, fuzzing;
//! - [`validate`]: the quick validation suite;
//! - [`common`]: the shared helpers and scene builders.
//!
//! The MPI tests (`tests/mpi.rs`, feature `mpi`) stay a binary of their own.
mod common;

#[path = "cli/main.rs"]
mod cli;
#[path = "heat/main.rs"]
mod heat;
#[path = "scene/main.rs"]
mod scene;
mod validate;
#[path = "viewfactor/main.rs"]
mod viewfactor;
