//! lambert: diffuse view factors and gray-body radiative exchange.
//!
//! A shipped case from scene file to heat rates, by the route the `lambert solve` command
//! takes ([`plan`]):
//!
//! ```
//! use lambert::plan::{Plan, Request, Silent};
//! let scene = lambert::scene::load(std::path::Path::new("cases/cube_furnace/scene.toml"))?;
//! let plan = Plan::new(&scene, &Request::default())?;
//! let out = plan.run(&scene, &mut Silent)?;
//! for (name, r) in out.solution.names.iter().zip(&out.solution.results) {
//!     println!("{name}: {:.1} W", r.heat_rate);
//! }
//! // A closed furnace exchanges only with itself: its heat rates sum to zero.
//! let rates: Vec<f64> = out.solution.results.iter().map(|r| r.heat_rate).collect();
//! let largest = rates.iter().fold(0.0f64, |m, q| m.max(q.abs()));
//! assert!(rates.iter().sum::<f64>().abs() <= 1e-9 * largest);
//! # Ok::<(), lambert::Error>(())
//! ```
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
//! - [`choice`]: the enums a user picks by name (method, store, solver, ...), named once.
//! - [`distributed`]: runs under `mpirun` (feature `mpi`): rank, row blocks, gathers.
//! - [`validate`]: the textbook validation suite, its error models and studies.
#![warn(missing_docs)]
// `!(x > tol)` is the NaN-safe way to reject degenerate or non-finite measures; keep it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod choice;
pub mod distributed;
pub mod error;
pub mod exchange;
pub mod geometry;
pub mod palette;
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
