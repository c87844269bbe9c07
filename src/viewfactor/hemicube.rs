//! The hemicube method (Cohen & Greenberg 1985): per patch, the scene is projected onto the
//! five faces of a unit half-cube over the patch (the top face z = 1 and four half side
//! faces) with an item buffer of patch ids, and each patch collects the precomputed delta
//! form factors of the pixels it wins.
//!
//! - `delta`: the delta form factor tables, one per resolution;
//! - the projection base it shares with the single-plane method (`super::projection`): the
//!   flattened scene and the per-eye gather, homogeneous clipping to each face's pyramid
//!   before the divide, the scanline item buffer, and the projection positions per patch.
//!
//! Error behaviour (docs/literature.md §4, measured in tests/viewfactor/hemicube.rs): the delta factors are
//! a midpoint rule, O(h²) for a receiver whose projection edges align with pixels; edges
//! crossing pixels cost O(h) (an edge on the hemicube horizon worst of all); receivers that
//! project to a few pixels alias (a 0.05×0.05 target at unit distance: −100 % at R = 32,
//! +56 % at 64); a single centroid projection has the proximity error, which
//! [`Positions`] trades against cost. Shadows make it worse: a blocker close to a patch puts
//! kinks in the point factor across the patch (the centred 0.5² blocker midway between unit
//! squares: the centroid sees nothing, 3×3 Gauss positions miss by 9 %), so shadowed
//! emitters must be subdivided (4×4 patches with 2×2 positions: 1e-5). `compute` uses
//! [`Positions::Adaptive`]. The row is not symmetric: row i is patch i's view, and
//! reciprocity is left to enforcement.
//!
//! Cost: 3R² pixels per position plus a clip of every polygon in front of the patch, so a
//! row is O(R² + N) and the method O(N·R² + N²) per position.
//!
//! Resolution: R pixels along the top face (R/2 rows on each side face); an odd R is rounded
//! up to the next even number, and R is capped at [`MAX_RESOLUTION`].
use super::accuracy::{raster, Knob, MethodInfo};
use super::engine::{Row, RowKernel};
use super::{MethodSet, Params};
use crate::scene::Scene;
use crate::Result;
use glam::{DVec2, DVec3, DVec4};
use std::sync::Mutex;

pub(crate) mod delta;

use super::projection::prepare::{Gathered, Prepared, NO_RECEIVER};
use super::projection::raster::{DepthPlane, ItemBuffer};
pub use super::projection::Positions;
pub use super::projection::MAX_RESOLUTION;
use super::projection::{checked_resolution, credit, emit, positions, EYE_NEAR_REL, RECEIVER_DEPTH_BIAS};
use crate::geometry::clip::watertight as clip;
use crate::geometry::frame::Frame;

/// The `hemicube` row of the method registry: error the point bias plus the raster term.
pub const INFO: MethodInfo = MethodInfo {
    knob: Knob::Resolution,
    symmetric: false,
    monte_carlo: false,
    counts_hits: false,
    exact_shadows: false,
    kernel: row_kernel,
    error_bound: |params, e| e.point_bias + raster(e.f, params.resolution),
    own_leak_tol: super::accuracy::no_own_leak_tol,
    colour: (crate::palette::BLUE, false),
};

fn row_kernel<'a>(scene: &'a Scene, params: &Params) -> Result<Option<Box<dyn RowKernel + 'a>>> {
    Ok(Some(Box::new(HemicubeKernel::new(scene, params.resolution, Positions::Adaptive)?)))
}

/// One hemicube face: local axes (u, v, w), its clipping pyramid and its pixel grid.
struct Face {
    eu: DVec3,
    ev: DVec3,
    ew: DVec3,
    /// Lowest v of the window (−1 on top, 0 on the sides).
    v0: f64,
    rows: usize,
    planes: [DVec4; 5],
    top: bool,
}

impl Face {
    fn new(eu: DVec3, ev: DVec3, ew: DVec3, top: bool, r: usize, near: f64) -> Self {
        let h = |a: DVec3, d: f64| DVec4::new(a.x, a.y, a.z, d);
        let bottom = if top { h(ew + ev, 0.0) } else { h(ev, 0.0) };
        let planes = [h(ew - eu, 0.0), h(ew + eu, 0.0), h(ew - ev, 0.0), bottom, h(ew, -near)];
        Self { eu, ev, ew, v0: if top { -1.0 } else { 0.0 }, rows: if top { r } else { r / 2 }, planes, top }
    }
}

/// Per-thread scratch, reused across rows.
#[derive(Default)]
struct Workspace {
    gathered: Gathered,
    buffer: ItemBuffer,
    clipped: Vec<DVec3>,
    tmp: Vec<DVec3>,
    pts: Vec<DVec2>,
    acc: Vec<f64>,
    touched: Vec<u32>,
}

/// The hemicube as a (non-symmetric) row kernel.
pub struct HemicubeKernel<'a> {
    scene: &'a Scene,
    prep: Prepared,
    deltas: delta::DeltaTables,
    positions: Positions,
    faces: [Face; 5],
    pool: Mutex<Vec<Workspace>>,
}

impl<'a> HemicubeKernel<'a> {
    /// A kernel at `resolution` pixels along the top face.
    pub fn new(scene: &'a Scene, resolution: usize, positions: Positions) -> Result<Self> {
        let r = checked_resolution("hemicube", resolution)?;
        let prep = Prepared::new(scene);
        let near = EYE_NEAR_REL * prep.near_scale;
        let (x, y, z) = (DVec3::X, DVec3::Y, DVec3::Z);
        let faces = [
            Face::new(x, y, z, true, r, near),
            Face::new(y, z, x, false, r, near),
            Face::new(y, z, -x, false, r, near),
            Face::new(x, z, y, false, r, near),
            Face::new(x, z, -y, false, r, near),
        ];
        Ok(Self {
            scene,
            prep,
            deltas: delta::DeltaTables::new(r),
            positions,
            faces,
            pool: Mutex::new(Vec::new()),
        })
    }

    /// The resolution in use (the requested one, evened).
    pub fn resolution(&self) -> usize {
        self.deltas.resolution
    }

    /// Σ of the (normalised) delta factors over the five faces, 1 up to round-off: the row sum
    /// of a closed scene.
    pub fn delta_total(&self) -> f64 {
        self.deltas.total()
    }

    /// Σ of the raw midpoint delta factors (1 + O(h²)), by which they are divided.
    pub fn midpoint_total(&self) -> f64 {
        self.deltas.midpoint_total()
    }

    /// Renders one face for the gathered scene and adds weight × its delta factors to `acc`.
    fn render_face(&self, face: &Face, ws: &mut Workspace, weight: f64) {
        let r = self.deltas.resolution;
        let h = 2.0 / r as f64;
        ws.buffer.reset(r, face.rows);
        for p in &ws.gathered.polys {
            if clip::sphere_outside(&face.planes, p.centre, p.radius) {
                continue;
            }
            clip::clip_polygon(ws.gathered.vertices(p), &face.planes, &mut ws.clipped, &mut ws.tmp);
            if ws.clipped.is_empty() {
                continue;
            }
            ws.pts.clear();
            ws.pts.extend(ws.clipped.iter().map(|q| {
                let w = q.dot(face.ew);
                DVec2::new((q.dot(face.eu) / w + 1.0) / h, (q.dot(face.ev) / w - face.v0) / h)
            }));
            // Inverse depth (m·D)/c along D = u'·eu + v'·ev + ew, rewritten in pixel units.
            let s = (if p.id == NO_RECEIVER { 1.0 } else { 1.0 + RECEIVER_DEPTH_BIAS }) / p.c;
            let (mu, mv, mw) = (p.m.dot(face.eu) * s, p.m.dot(face.ev) * s, p.m.dot(face.ew) * s);
            let depth = DepthPlane { a: mu * h, b: mv * h, c: mw - mu + mv * face.v0 };
            ws.buffer.draw(&ws.pts, depth, p.id);
        }
        // Credit each run of equal ids along a pixel row with its delta factors (prefix sums).
        let prefix = if face.top { &self.deltas.top_prefix } else { &self.deltas.side_prefix };
        for (ids, pre) in ws.buffer.ids().chunks_exact(r).zip(prefix.chunks_exact(r + 1)) {
            let mut start = 0;
            while start < r {
                let id = ids[start];
                let end = ids[start..].iter().position(|&k| k != id).map_or(r, |n| start + n);
                credit(&mut ws.acc, &mut ws.touched, id, weight * (pre[end] - pre[start]));
                start = end;
            }
        }
    }
}

impl RowKernel for HemicubeKernel<'_> {
    fn symmetric(&self) -> bool {
        false
    }

    fn row(&self, i: usize, out: &mut Row) -> Result<()> {
        let mut ws = self.pool.lock().unwrap_or_else(|e| e.into_inner()).pop().unwrap_or_default();
        ws.acc.resize(self.scene.patches.len(), 0.0);
        let poly = &self.scene.patches[i].polygon;
        let rule = positions::rule(poly, self.positions.order(&self.prep, poly, i));
        let v = poly.vertices();
        for (k, (&x, &w)) in rule.points.iter().zip(&rule.weights).enumerate() {
            let eye = Frame::along(x, poly.normal(), v[1] - v[0]).turned(self.positions.turn(k));
            ws.gathered.gather(&self.prep, &eye, i);
            for face in &self.faces {
                self.render_face(face, &mut ws, w);
            }
        }
        emit(&mut ws.acc, &mut ws.touched, MethodSet::HEMICUBE, out);
        out.pairs = self.scene.patches.len().saturating_sub(1) as u64;
        self.pool.lock().unwrap_or_else(|e| e.into_inner()).push(ws);
        Ok(())
    }
}
