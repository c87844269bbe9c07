//! Integration tests of the view-factor methods: exact kernels, `auto`, hemicube, Monte Carlo, shadows and visibility.
//!
//! One test binary per area (each links the whole crate once); every file under `tests/viewfactor/` is
//! a module here. Run one with `cargo test --release --test viewfactor <module>::`.
mod analytic_accuracy;
mod analytic_method;
mod analytic_properties;
mod analytic_scale;
mod auto;
#[path = "../common/mod.rs"]
mod common;
mod concave;
mod hemicube;
mod lattice_reuse;
mod monte_carlo;
mod points;
mod real_parts;
mod shadowed;
mod visibility;
