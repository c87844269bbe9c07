//! Indexed triangle meshes for the mesh checks and the STL/OBJ readers: vertex welding within
//! a tolerance, the edge table (each undirected edge with the triangles that use it and their
//! direction) and connected components.
//!
//! Every triangle keeps a [`Tag`]: the surface it belongs to (within one model file) and its
//! index as read, so findings can name "surface S, triangle k" whatever was welded or dropped.
use crate::geometry::groups::Groups;
use glam::DVec3;
use std::collections::HashMap;

/// Where a triangle came from: its surface within the file and its index as read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Tag {
    /// Surface index within the model file.
    pub surface: u32,
    /// Triangle index within that surface, in file order (after polygon triangulation).
    pub index: u32,
}

/// An indexed triangle mesh; triangles are counter-clockwise seen from their front.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions, m.
    pub vertices: Vec<DVec3>,
    /// Vertex index triples.
    pub triangles: Vec<[u32; 3]>,
    /// One tag per triangle.
    pub tags: Vec<Tag>,
}

/// What welding did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct WeldInfo {
    /// Vertices before welding (3 per triangle of a soup).
    pub before: usize,
    /// Distinct vertices after welding.
    pub after: usize,
    /// Vertices merged with a representative at a different position (not bit-identical).
    pub moved: usize,
    /// Largest distance a merged vertex moved, m.
    pub max_move: f64,
    /// Triangles that lost their area because two corners welded together (dropped).
    pub collapsed: usize,
}

/// Relative size below which a weld tolerance cannot separate f64 coordinates: treated as 0
/// (bit-identical positions only), which also keeps grid keys finite.
const WELD_EXACT_REL: f64 = 1e-15;

/// Welds a triangle soup: vertices within `tol` (m) of an earlier representative take its
/// position (the first one read wins, so the result does not depend on anything but file
/// order); `tol = 0` merges bit-identical positions only. Triangles whose corners weld together
/// are dropped and counted.
pub fn weld(soup: &[[DVec3; 3]], tags: &[Tag], tol: f64) -> (TriMesh, WeldInfo) {
    let scale = soup.iter().flatten().map(|p| p.abs().max_element()).fold(0.0, f64::max);
    let tol = if tol > WELD_EXACT_REL * scale { tol } else { 0.0 };
    let mut mesh = TriMesh::default();
    let mut info = WeldInfo { before: 3 * soup.len(), ..WeldInfo::default() };
    let mut exact: HashMap<[u64; 3], u32> = HashMap::new();
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let key = |p: DVec3| (p / tol).floor().as_i64vec3().to_array();
    let mut index_of = |p: DVec3, mesh: &mut TriMesh, info: &mut WeldInfo| -> u32 {
        let bits = (p + DVec3::ZERO).to_array().map(f64::to_bits); // -0 and +0 alike
        if let Some(&i) = exact.get(&bits) {
            return i;
        }
        if tol > 0.0 {
            let k = key(p);
            let mut best: Option<u32> = None;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) else { continue };
                        for &i in list {
                            if mesh.vertices[i as usize].distance(p) <= tol && best.is_none_or(|b| i < b) {
                                best = Some(i);
                            }
                        }
                    }
                }
            }
            if let Some(i) = best {
                info.moved += 1;
                info.max_move = info.max_move.max(mesh.vertices[i as usize].distance(p));
                exact.insert(bits, i);
                return i;
            }
            grid.entry(k).or_default().push(mesh.vertices.len() as u32);
        }
        let i = mesh.vertices.len() as u32;
        mesh.vertices.push(p);
        exact.insert(bits, i);
        i
    };
    for (t, tag) in soup.iter().zip(tags) {
        let ix = t.map(|p| index_of(p, &mut mesh, &mut info));
        if ix[0] == ix[1] || ix[1] == ix[2] || ix[0] == ix[2] {
            info.collapsed += 1;
            continue;
        }
        mesh.triangles.push(ix);
        mesh.tags.push(*tag);
    }
    info.after = mesh.vertices.len();
    (mesh, info)
}

impl TriMesh {
    /// Corner positions of triangle `t`.
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|i| self.vertices[i as usize])
    }
    /// Twice the area vector of triangle `t` (length 2A, along the front normal).
    pub fn area2(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(c - a)
    }
    /// The undirected edges with their uses, sorted by (low, high) vertex.
    pub fn edges(&self) -> Vec<Edge> {
        let mut uses: Vec<(u32, u32, u32, bool)> = Vec::with_capacity(3 * self.triangles.len());
        for (t, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                uses.push((a.min(b), a.max(b), t as u32, a < b));
            }
        }
        uses.sort_unstable();
        let mut out = Vec::new();
        let mut k = 0;
        while k < uses.len() {
            let (a, b) = (uses[k].0, uses[k].1);
            let mut e = Edge { a, b, uses: Vec::new() };
            while k < uses.len() && uses[k].0 == a && uses[k].1 == b {
                e.uses.push((uses[k].2, uses[k].3));
                k += 1;
            }
            out.push(e);
        }
        out
    }
    /// Connected components through shared edges: a component id per triangle (numbered in
    /// order of their first triangle) and the component count.
    pub fn components(&self, edges: &[Edge]) -> (Vec<u32>, usize) {
        let n = self.triangles.len();
        let mut groups = Groups::new(n);
        for e in edges {
            let first = e.uses[0].0;
            for &(t, _) in &e.uses[1..] {
                groups.join(first as usize, t as usize);
            }
        }
        let mut ids = vec![u32::MAX; n];
        let mut roots: HashMap<u32, u32> = HashMap::new();
        for (t, id) in ids.iter_mut().enumerate() {
            let r = groups.root(t) as u32;
            let next = roots.len() as u32;
            *id = *roots.entry(r).or_insert(next);
        }
        (ids, roots.len())
    }
    /// Reverses triangle `t` (its front becomes its back).
    pub fn flip(&mut self, t: usize) {
        self.triangles[t].swap(1, 2);
    }
    /// Keeps the triangles for which `keep(t)` is true.
    pub fn retain(&mut self, keep: impl Fn(usize) -> bool) {
        let idx: Vec<usize> = (0..self.triangles.len()).filter(|&t| keep(t)).collect();
        self.triangles = idx.iter().map(|&t| self.triangles[t]).collect();
        self.tags = idx.iter().map(|&t| self.tags[t]).collect();
    }
}

/// One undirected edge (a < b) and the triangles that use it, each with `true` when it runs
/// a → b.
#[derive(Debug, Clone, PartialEq)]
pub struct Edge {
    /// Lower vertex index.
    pub a: u32,
    /// Higher vertex index.
    pub b: u32,
    /// (triangle, runs a → b).
    pub uses: Vec<(u32, bool)>,
}

impl Edge {
    /// Used by one triangle only: on the mesh's boundary.
    pub fn is_boundary(&self) -> bool {
        self.uses.len() == 1
    }
    /// Used by more than two triangles.
    pub fn is_nonmanifold(&self) -> bool {
        self.uses.len() > 2
    }
    /// Two triangles that run it the same way: they disagree on which side is the front.
    pub fn is_inconsistent(&self) -> bool {
        self.uses.len() == 2 && self.uses[0].1 == self.uses[1].1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tags(n: usize) -> Vec<Tag> {
        (0..n as u32).map(|index| Tag { surface: 0, index }).collect()
    }

    #[test]
    fn welding_merges_near_vertices_and_drops_collapsed_triangles() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0));
        let eps = DVec3::splat(1e-9);
        let soup = [[a, b, c], [b + eps, d, c - eps], [a, a + eps, b]];
        let (m, info) = weld(&soup, &tags(3), 1e-6);
        assert_eq!((m.vertices.len(), m.triangles.len()), (4, 2));
        assert_eq!((info.before, info.after, info.moved, info.collapsed), (9, 4, 3, 1));
        assert!(info.max_move > 1.7e-9 && info.max_move < 1.8e-9, "{}", info.max_move);
        let edges = m.edges();
        assert_eq!(edges.len(), 5);
        assert_eq!(edges.iter().filter(|e| e.is_boundary()).count(), 4);
        assert!(edges.iter().all(|e| !e.is_inconsistent()));
        // Without a tolerance only bit-identical corners are shared.
        let (m, _) = weld(&soup, &tags(3), 0.0);
        assert_eq!((m.vertices.len(), m.triangles.len()), (7, 3));
    }

    #[test]
    fn components_follow_shared_edges() {
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let soup = [
            [p(0.0, 0.0), p(1.0, 0.0), p(0.0, 1.0)],
            [p(5.0, 0.0), p(6.0, 0.0), p(5.0, 1.0)],
            [p(1.0, 0.0), p(1.0, 1.0), p(0.0, 1.0)],
        ];
        let (m, _) = weld(&soup, &tags(3), 0.0);
        let (ids, n) = m.components(&m.edges());
        assert_eq!((ids, n), (vec![0, 1, 0], 2));
    }
}
