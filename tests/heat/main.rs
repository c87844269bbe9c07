//! Integration tests of the exchange and the solve: sparse, dense and clustered stores, bands, conductances and decks.
//!
//! One test binary per area (each links the whole crate once); every file under `tests/heat/` is
//! a module here. Run one with `cargo test --release --test heat <module>::`.
#[path = "../common/mod.rs"]
mod common;
mod decks_agree;
mod dense;
mod exchange;
mod solve;
mod solve_bands;
mod solve_conductance;
