//! Integration tests of the view-factor methods: exact kernels, `auto`, hemicube, Monte Carlo, shadows and visibility.
//!
//! Every file under `tests/viewfactor/` is a module here, and this area a module of the one
//! integration-test binary (`tests/integration.rs`). Run one with
//! `cargo test --release --test integration viewfactor::<module>::`.
mod analytic_accuracy;
mod analytic_method;
mod analytic_properties;
mod analytic_scale;
mod auto;
mod concave;
mod hemicube;
mod lattice_reuse;
mod monte_carlo;
mod points;
mod real_parts;
mod shadowed;
mod visibility;
