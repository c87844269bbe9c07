//! The projection base of the hemicube and single-plane methods: both project the scene seen
//! from a patch onto image planes and credit each receiver with the pixels it wins.
//!
//! - `prepare`: the flattened scene and the per-eye gather (receiver / blocker rules: front
//!   faces receive; back faces and obstructions only block);
//! - clipping to a pyramid before the perspective divide: [`crate::geometry::clip::watertight`];
//! - `raster`: the scanline item buffer, point sampled at pixel centres;
//! - `positions`: one or several projection positions per patch;
//! - the shared limits and the accumulation of a row (`credit`, `emit`).
use super::engine::{RawEntry, Row};
use super::MethodSet;
use crate::{Error, Result};
use prepare::NO_RECEIVER;

pub(crate) mod positions;
pub(crate) mod prepare;
pub(crate) mod raster;

pub use positions::Positions;

/// Largest accepted resolution: one face buffer is 8R² bytes per thread (134 MB at 4096).
pub const MAX_RESOLUTION: usize = 4096;

/// Near plane w ≥ ε as a fraction of the scene size (at most [`prepare::LOCAL_SPAN`] patch
/// radii): only guards the perspective divide (the side planes of each face pyramid pass
/// through the eye, so nothing else is cut).
pub(crate) const EYE_NEAR_REL: f64 = 1e-9;

/// Receivers' inverse depth is scaled by 1 + this, so a front face beats a coincident
/// blocker (a plate modelled as two back-to-back surfaces) despite round-off; it exceeds the
/// f32 depth precision (6e-8) and is far below any real depth gap.
pub(crate) const RECEIVER_DEPTH_BIAS: f64 = 1e-6;

/// Validates and evens a requested resolution.
pub(crate) fn checked_resolution(method: &str, r: usize) -> Result<usize> {
    if !(2..=MAX_RESOLUTION).contains(&r) {
        return Err(Error::Usage(format!(
            "{method} resolution must be between 2 and {MAX_RESOLUTION}, got {r}"
        )));
    }
    Ok(r + r % 2)
}

/// Adds `s` to receiver `id`'s exchange area, noting first touches; blockers get nothing.
#[inline]
pub(crate) fn credit(acc: &mut [f64], touched: &mut Vec<u32>, id: u32, s: f64) {
    if id != NO_RECEIVER && s > 0.0 {
        let a = &mut acc[id as usize];
        if *a == 0.0 {
            touched.push(id);
        }
        *a += s;
    }
}

/// Moves the accumulated exchange areas into `out` (sorted by column) and clears `acc`.
pub(crate) fn emit(acc: &mut [f64], touched: &mut Vec<u32>, method: MethodSet, out: &mut Row) {
    touched.sort_unstable();
    out.entries.clear();
    out.entries.extend(touched.iter().map(|&j| RawEntry { j, method, s: acc[j as usize], var: 0.0 }));
    for &j in touched.iter() {
        acc[j as usize] = 0.0;
    }
    touched.clear();
    out.shared_samples = 0;
}
