//! The `analytic` method: exact for planar polygons, with a Gauss ladder where provably
//! accurate enough, and exact shadow clipping for obstructed pairs.
//!
//! Exact kernels: [`crate::viewfactor::exact`] (re-exported here under their old paths).
//!
//! Shadows: obstructed pairs are the [`super::shadow`] module's; the kernel calls its
//! [`Shadows`](super::shadow::Shadows) branch. Layering: the exact kernels ←
//! `shadow` (which integrates Lambert's edge term over shadows) ← [`kernel`] ← `auto`;
//! no file here or in `shadow` uses `auto`.
//!
//! The method on a scene:
//! - [`ladder`]: Gauss area rules per patch and their a-priori error model (far pairs);
//! - [`lattice`]: one evaluation per offset for translated pairs of gridded surfaces;
//! - [`kernel`]: the [`crate::viewfactor::row::RowKernel`] tying them together.
pub mod kernel;
pub mod ladder;
pub mod lattice;

use super::accuracy::{Knob, MethodInfo, ANALYTIC_REL};
use super::engine::RowKernel;
use super::Params;
use crate::scene::Scene;
use crate::Result;

/// The `analytic` row of the method registry: error `ANALYTIC_REL`·F, its own rows close to
/// [`kernel::ANALYTIC_LEAK_TOL`].
pub const INFO: MethodInfo = MethodInfo {
    knob: Knob::Tolerance,
    symmetric: true,
    monte_carlo: false,
    counts_hits: false,
    exact_shadows: true,
    kernel: row_kernel,
    error_bound: |_, e| ANALYTIC_REL * e.f,
    own_leak_tol: |_, _| Some(kernel::ANALYTIC_LEAK_TOL),
    colour: (crate::palette::BLACK, false),
};

fn row_kernel<'a>(scene: &'a Scene, _: &Params) -> Result<Option<Box<dyn RowKernel + 'a>>> {
    Ok(Some(Box::new(kernel::AnalyticKernel::new(scene, kernel::GAUSS_REL_TOL))))
}
