//! Integration tests of the exchange and the solve: sparse, dense and clustered stores, bands, conductances and decks.
//!
//! Every file under `tests/heat/` is a module here, and this area a module of the one
//! integration-test binary (`tests/integration.rs`). Run one with
//! `cargo test --release --test integration heat::<module>::`.
mod decks_agree;
mod dense;
mod exchange;
mod solve;
mod solve_bands;
mod solve_conductance;
