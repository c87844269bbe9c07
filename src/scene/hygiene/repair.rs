//! `repair = true` / `--repair`: on the welded mesh of a model file, in this order,
//! 1. drop duplicate faces (the first copy read stays);
//! 2. drop slivers (aspect ratio above [`super::SLIVER_ASPECT`]); a sliver inside a closed
//!    mesh leaves a hole of its own area, so the edges this opens are counted and said;
//! 3. flip the triangles wound against the majority of their orientation patch;
//! 4. turn closed components that face inward (negative volume) outward, as a body needs,
//!    except one whose box holds another component of the file: an enclosure around bodies
//!    stays as it is. A lone inward shell (an empty room) is turned, and the log says so.
//!
//! Self-intersections and non-manifold edges are reported, never changed.
use super::{aspect, duplicate_groups, majority_flips, SLIVER_ASPECT};
use crate::scene::mesh::TriMesh;
use glam::DVec3;

/// What repair changed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RepairLog {
    /// Duplicate faces dropped.
    pub duplicates: usize,
    /// Slivers dropped.
    pub slivers: usize,
    /// Their total area, m².
    pub sliver_area: f64,
    /// Boundary edges before and after dropping.
    pub boundary_before: usize,
    /// Boundary edges at the end.
    pub boundary_after: usize,
    /// Triangles flipped to agree with their neighbours.
    pub flipped: usize,
    /// Closed components turned outward.
    pub turned_components: usize,
    /// Triangles in them.
    pub turned_triangles: usize,
}

impl RepairLog {
    /// True when repair changed nothing.
    pub fn is_empty(&self) -> bool {
        self.duplicates + self.slivers + self.flipped + self.turned_components == 0
    }
}

/// Repairs `mesh` in place (see the module docs).
pub fn repair(mesh: &mut TriMesh) -> RepairLog {
    let boundary = |m: &TriMesh| m.edges().iter().filter(|e| e.is_boundary()).count();
    let mut log = RepairLog { boundary_before: boundary(mesh), ..RepairLog::default() };

    // 1. Duplicates: the first triangle of each sorted vertex triple stays.
    let mut keep = vec![true; mesh.triangles.len()];
    for g in duplicate_groups(mesh) {
        for &t in &g[1..] {
            keep[t] = false;
            log.duplicates += 1;
        }
    }
    // 2. Slivers.
    for (t, k) in keep.iter_mut().enumerate() {
        if *k && aspect(mesh.corners(t)) > SLIVER_ASPECT {
            *k = false;
            log.slivers += 1;
            log.sliver_area += 0.5 * mesh.area2(t).length();
        }
    }
    mesh.retain(|t| keep[t]);

    // 3. Consistent winding.
    let edges = mesh.edges();
    for (t, flip) in majority_flips(mesh, &edges, &[]).into_iter().enumerate() {
        if flip {
            mesh.flip(t);
            log.flipped += 1;
        }
    }
    // 4. Closed components outward.
    let edges = mesh.edges();
    let (ids, n) = mesh.components(&edges);
    let mut closed = vec![true; n];
    for e in &edges {
        if e.uses.len() != 2 || e.is_inconsistent() {
            closed[ids[e.uses[0].0 as usize] as usize] = false;
        }
    }
    let mut volume = vec![0.0; n];
    let mut origin = vec![None; n];
    let mut boxes = vec![(DVec3::INFINITY, DVec3::NEG_INFINITY); n];
    for (t, &c) in ids.iter().enumerate() {
        let [a, b, p] = mesh.corners(t);
        let o = *origin[c as usize].get_or_insert(a);
        volume[c as usize] += (a - o).dot((b - o).cross(p - o));
        let bx = &mut boxes[c as usize];
        *bx = (bx.0.min(a.min(b).min(p)), bx.1.max(a.max(b).max(p)));
    }
    let holds = |c: usize, d: usize| boxes[c].0.cmplt(boxes[d].0).all() && boxes[c].1.cmpgt(boxes[d].1).all();
    let turn: Vec<bool> =
        (0..n).map(|c| closed[c] && volume[c] < 0.0 && !(0..n).any(|d| d != c && holds(c, d))).collect();
    log.turned_components = turn.iter().filter(|&&t| t).count();
    for (t, &c) in ids.iter().enumerate() {
        if turn[c as usize] {
            mesh.flip(t);
            log.turned_triangles += 1;
        }
    }
    log.boundary_after = boundary(mesh);
    log
}
