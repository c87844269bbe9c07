//! The single-plane method (Sillion & Puech 1989): per patch, the scene is projected onto one
//! plane parallel to the patch at unit height, of half-width s, and resolved there by
//! Warnock-style adaptive subdivision.
//!
//! - `grid`: the R × R pixel grid and its exact cell factors (node table of
//!   the corner factor; it replaces per-level delta tables and serves every level);
//! - `warnock`: projection and the subdivision itself.
//!
//! Scene gathering, clipping and the receiver/blocker rules are the projection base it shares
//! with the hemicube (`super::projection`): front faces receive, back faces and obstructions
//! only block.
//!
//! **Grazing-angle bias.** The plane sees only directions within atan(s) of the normal in
//! both x and y; the rest of the hemisphere, 1 − 4·F_corner(s, s, 1) ≈ 0.81/s², is never
//! sampled. With the default s = [`DEFAULT_HALF_WIDTH`] that is 8.2e-5 of every row (the
//! classic s = 10 misses 8.1e-3). The bias is one-sided: factors to receivers near the
//! patch's horizon come out low (of a wall at distance d from the eye, the strip below
//! height d/s is lost) and closed-scene row sums fall short by up to that amount. It is reported, not corrected
//! (rescaling would move it onto receivers that lie inside the plane). tests/viewfactor/hemicube.rs
//! measures it. Within the plane, errors are the hemicube's: O(h) where edges cut pixels,
//! aliasing of targets a few pixels wide, and the proximity error ([`Positions`]).
//!
//! **Pixel layout.** With [`Spacing::EqualAngle`] (default) pixels subtend near-equal
//! angles, so a wide plane costs no resolution near the zenith (π/R rad per pixel at most,
//! a hemicube's top face has 2/R); uniform spacing is kept for comparison.
use super::accuracy::{raster, Knob, MethodInfo};
use super::closed_form::element_to_rectangle_corner;
use super::engine::{Row, RowKernel};
use super::flags::{Flag, FlagLog};
use super::projection::prepare::{Gathered, Prepared};
use super::projection::{checked_resolution, credit, emit, positions, Positions, EYE_NEAR_REL};
use super::{MethodSet, Params};
use crate::geometry::frame::Frame;
use crate::scene::Scene;
use crate::Result;
use std::sync::Mutex;

pub(crate) mod grid;
pub(crate) mod warnock;

use grid::PlaneGrid;
pub use grid::Spacing;
use warnock::PlaneScene;

/// Default half-width s of the plane at unit height: captures 4·F_corner(100, 100, 1) =
/// 0.999918 of the hemisphere. Equal-angle pixels make the wide plane cheap (they grow only
/// 6 % in angle from s = 10), and the bias is 100× below the classic s = 10.
pub const DEFAULT_HALF_WIDTH: f64 = 100.0;

/// The `single-plane` row of the method registry: error the hemicube's terms plus
/// min(F, the hemisphere fraction outside the plane), the method's one-sided grazing bias.
pub const INFO: MethodInfo = MethodInfo {
    knob: Knob::Resolution,
    symmetric: false,
    monte_carlo: false,
    counts_hits: false,
    exact_shadows: false,
    kernel: row_kernel,
    error_bound: |params, e| e.point_bias + raster(e.f, params.resolution) + e.f.min(missed()),
    own_leak_tol: super::accuracy::no_own_leak_tol,
    colour: (crate::palette::SKY_BLUE, false),
};

fn row_kernel<'a>(scene: &'a Scene, params: &Params) -> Result<Option<Box<dyn RowKernel + 'a>>> {
    Ok(Some(Box::new(SinglePlaneKernel::new(scene, params.resolution, SinglePlaneOptions::default())?)))
}

/// The hemisphere fraction outside the plane of half-width [`DEFAULT_HALF_WIDTH`] at unit
/// height, 1 − 4·F_corner(s, s, 1).
pub fn missed() -> f64 {
    missed_at(DEFAULT_HALF_WIDTH)
}

/// The same for a plane of half-width `s`.
pub fn missed_at(s: f64) -> f64 {
    1.0 - 4.0 * element_to_rectangle_corner(s, s, 1.0)
}

/// Options of the single-plane kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SinglePlaneOptions {
    /// Half-width s of the plane at unit height.
    pub half_width: f64,
    /// Pixel layout.
    pub spacing: Spacing,
    /// Projection positions per patch.
    pub positions: Positions,
}

impl Default for SinglePlaneOptions {
    fn default() -> Self {
        Self { half_width: DEFAULT_HALF_WIDTH, spacing: Spacing::EqualAngle, positions: Positions::Adaptive }
    }
}

/// Per-thread scratch, reused across rows.
#[derive(Default)]
struct Workspace {
    gathered: Gathered,
    plane: PlaneScene,
    acc: Vec<f64>,
    touched: Vec<u32>,
}

/// The single plane as a (non-symmetric) row kernel.
pub struct SinglePlaneKernel<'a> {
    scene: &'a Scene,
    prep: Prepared,
    grid: PlaneGrid,
    options: SinglePlaneOptions,
    pool: Mutex<Vec<Workspace>>,
    /// Rows with receivers that reach past the plane's edge.
    flags: FlagLog,
}

impl<'a> SinglePlaneKernel<'a> {
    /// A kernel with `resolution` pixels along each axis of the plane.
    pub fn new(scene: &'a Scene, resolution: usize, options: SinglePlaneOptions) -> Result<Self> {
        let r = checked_resolution("single-plane", resolution)?;
        if !(options.half_width.is_finite() && options.half_width > 0.0) {
            return Err(crate::Error::Usage(format!(
                "single-plane half-width must be positive, got {}",
                options.half_width
            )));
        }
        let grid = PlaneGrid::new(r, options.half_width, options.spacing);
        let flags = FlagLog::default();
        Ok(Self { scene, prep: Prepared::new(scene), grid, options, pool: Mutex::new(Vec::new()), flags })
    }

    /// The fraction of the hemisphere the plane captures, 4·F_corner(s, s, 1); one minus it
    /// is the grazing-angle bias of a closed row.
    pub fn captured(&self) -> f64 {
        self.grid.captured()
    }
}

impl RowKernel for SinglePlaneKernel<'_> {
    fn symmetric(&self) -> bool {
        false
    }

    fn flags(&self) -> Vec<Flag> {
        self.flags.sorted()
    }

    fn absorb(&self, flags: Vec<Flag>, _misses: (u64, Option<super::shadow::misses::Miss>)) {
        for f in flags {
            self.flags.push(f);
        }
    }

    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        let mut ws = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop().unwrap_or_default();
        ws.acc.resize(self.scene.patches.len(), 0.0);
        let poly = &self.scene.patches[i].polygon;
        let rule = positions::rule(poly, self.options.positions.order(&self.prep, poly, i));
        let v = poly.vertices();
        let near = EYE_NEAR_REL * self.prep.near_scale;
        let mut cut: Vec<u32> = Vec::new();
        for (k, (&x, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
            let eye = Frame::along(x, poly.normal(), v[1] - v[0]).turned(self.options.positions.turn(k));
            ws.gathered.gather(&self.prep, &eye, i);
            ws.plane.project(&ws.gathered, self.options.half_width, near);
            cut.extend_from_slice(&ws.plane.cut);
            let Workspace { plane, acc, touched, .. } = &mut ws;
            plane.resolve(&self.grid, &mut |id, f| credit(acc, touched, id, w * f));
        }
        cut.sort_unstable();
        cut.dedup();
        if let Some(&first) = cut.first() {
            let missed = missed_at(self.options.half_width);
            self.flags.push(Flag {
                from: i,
                to: first as usize,
                method: MethodSet::SINGLE_PLANE,
                note: format!(
                    "{} receiver(s) of this row, the first shown, reach past the projection plane \
                     (half-width {}): the part beyond it is not counted, up to {missed:.2e} of the row",
                    cut.len(),
                    self.options.half_width
                ),
            });
        }
        let Workspace { acc, touched, .. } = &mut ws;
        emit(acc, touched, MethodSet::SINGLE_PLANE, out);
        out.pairs = self.scene.patches.len().saturating_sub(1) as u64;
        self.pool.lock().unwrap_or_else(|e| e.into_inner()).push(ws);
        Ok(())
    }
}
