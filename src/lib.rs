//! lambert: diffuse view factors and gray-body radiative exchange.
//!
//! Pipeline (one-way dependencies, left to right):
//!
//! ```text
//! geometry ← scene ← {visibility, viewfactor} ← exchange ← solve ← report ← cli
//! ```
//!
//! - [`geometry`]: planar polygons, clipping, triangulation, quadrature rules.
//! - [`scene`]: TOML / glTF loading, validation, surfaces, patches, boundary conditions.
//! - [`visibility`]: one BVH (obvhs) over every triangle; occlusion and closest-hit queries.
//! - [`viewfactor`]: the view-factor methods behind one `Method` enum and one engine.
//! - [`exchange`]: symmetric exchange areas S = A·F, ambient node, enforcement, diagnostics.
//! - [`solve`]: the net-radiation system K = D − S and its solvers.
//! - [`plan`]: the route to a `solve` result (store, tolerance meaning, refusals) and its run.
//! - [`report`]: CSV writers and charts; the one place that turns results into bytes.
//! - [`distributed`]: runs under `mpirun` (feature `mpi`): rank, row blocks, gathers.
//! - [`validate`]: the textbook validation suite, its error models and studies.
#![warn(missing_docs)]
// `!(x > tol)` is the NaN-safe way to reject degenerate or non-finite measures; keep it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod distributed;
pub mod error;
pub mod exchange;
pub mod geometry;
pub mod plan;
pub mod report;
pub mod scene;
pub mod solve;
pub mod validate;
pub mod viewfactor;
pub mod visibility;

pub use error::{Error, Result};

/// Stefan–Boltzmann constant σ, W m⁻² K⁻⁴ (CODATA 2018).
pub const SIGMA: f64 = 5.670374419e-8;
