//! The patch polygons of a scene as one indexed mesh: coincident vertices welded within a
//! surface, so per-patch (cell) values can be averaged to the vertices (Gouraud smoothing).
//! Shared by the VTK writer and the renderer.
//!
//! Vertices are welded per surface, never across surfaces: two surfaces that meet at an edge
//! (a hot floor and a cold wall) keep their own vertex values, so the step between them stays
//! sharp instead of being blurred by the average.
use crate::scene::Scene;
use glam::DVec3;
use std::collections::HashMap;

/// Weld tolerance relative to the scene's bounding-box diagonal: subdivision and glTF
/// round-off put shared corners within ~1e-15 of each other, real features are far above 1e-9.
pub const OUTPUT_WELD_REL: f64 = 1e-9;

/// Indexed polygons, one cell per patch, in patch order.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchMesh {
    /// Welded vertex positions.
    pub points: Vec<DVec3>,
    /// Concatenated vertex indices of every cell.
    pub connectivity: Vec<u32>,
    /// End of each cell in `connectivity` (VTK XML convention).
    pub offsets: Vec<u32>,
    /// Cell (patch) areas, m².
    pub areas: Vec<f64>,
    /// Owning surface of each cell.
    pub surface: Vec<u32>,
    /// Whether each cell is a convex polygon.
    pub convex: Vec<bool>,
}

/// Axis-aligned bounds (min, max) of every patch vertex and obstruction; `None` when empty.
pub fn scene_bounds(scene: &Scene) -> Option<(DVec3, DVec3)> {
    let pts =
        scene.patches.iter().flat_map(|p| p.polygon.vertices().iter()).chain(
            scene.obstructions.iter().flat_map(|o| o.polygons.iter().flat_map(|p| p.vertices().iter())),
        );
    pts.fold(None, |acc, &v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

impl PatchMesh {
    /// Builds the mesh of `scene.patches`, welding vertices of one surface that lie within
    /// [`OUTPUT_WELD_REL`] × the bounding-box diagonal. Memory and time are O(vertices).
    pub fn build(scene: &Scene) -> PatchMesh {
        let diag = scene_bounds(scene).map_or(1.0, |(lo, hi)| (hi - lo).length());
        let tol = (OUTPUT_WELD_REL * diag).max(f64::MIN_POSITIVE);
        let mut grid: HashMap<(u32, [i64; 3]), Vec<u32>> = HashMap::new();
        let mut mesh = PatchMesh {
            points: Vec::new(),
            connectivity: Vec::new(),
            offsets: Vec::with_capacity(scene.patches.len()),
            areas: Vec::with_capacity(scene.patches.len()),
            surface: Vec::with_capacity(scene.patches.len()),
            convex: Vec::with_capacity(scene.patches.len()),
        };
        for patch in &scene.patches {
            let s = patch.surface as u32;
            for &v in patch.polygon.vertices() {
                let id = weld(&mut grid, &mut mesh.points, s, v, tol);
                mesh.connectivity.push(id);
            }
            mesh.offsets.push(mesh.connectivity.len() as u32);
            mesh.areas.push(patch.polygon.area());
            mesh.surface.push(s);
            mesh.convex.push(patch.polygon.is_convex());
        }
        mesh
    }

    /// Number of cells.
    pub fn cells(&self) -> usize {
        self.offsets.len()
    }

    /// Vertex indices of cell `c`.
    pub fn cell(&self, c: usize) -> &[u32] {
        let start = if c == 0 { 0 } else { self.offsets[c - 1] as usize };
        &self.connectivity[start..self.offsets[c] as usize]
    }

    /// Area-weighted average of the cells sharing each vertex: v_k = Σ A_c x_c / Σ A_c.
    /// Non-finite cell values are left out; a vertex with none gets NaN.
    pub fn to_points(&self, cell_values: &[f64]) -> Vec<f64> {
        let mut num = vec![0.0; self.points.len()];
        let mut den = vec![0.0; self.points.len()];
        for (c, &x) in cell_values.iter().enumerate().take(self.cells()) {
            if !x.is_finite() {
                continue;
            }
            for &k in self.cell(c) {
                num[k as usize] += self.areas[c] * x;
                den[k as usize] += self.areas[c];
            }
        }
        num.iter().zip(&den).map(|(n, d)| if *d > 0.0 { n / d } else { f64::NAN }).collect()
    }
}

/// Index of the welded vertex at `v` in surface `s`, adding it when new. The 27 grid cells
/// around `v` are searched, so points within `tol` weld even across a cell boundary.
fn weld(
    grid: &mut HashMap<(u32, [i64; 3]), Vec<u32>>,
    points: &mut Vec<DVec3>,
    s: u32,
    v: DVec3,
    tol: f64,
) -> u32 {
    let key = |p: DVec3| [(p.x / tol).floor() as i64, (p.y / tol).floor() as i64, (p.z / tol).floor() as i64];
    let k = key(v);
    for dx in -1..=1 {
        for dy in -1..=1 {
            for dz in -1..=1 {
                if let Some(ids) = grid.get(&(s, [k[0] + dx, k[1] + dy, k[2] + dz])) {
                    if let Some(&id) = ids.iter().find(|&&id| points[id as usize].distance(v) <= tol) {
                        return id;
                    }
                }
            }
        }
    }
    let id = points.len() as u32;
    points.push(v);
    grid.entry((s, k)).or_default().push(id);
    id
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::Scene;

    fn two_by_one() -> Scene {
        let src = r#"
            [[surface]]
            name = "floor"
            rectangle = { origin = [0,0,0], u = [2,0,0], v = [0,1,0] }
            subdivide = [2, 1]
            [[surface]]
            name = "wall"
            rectangle = { origin = [0,0,0], u = [0,1,0], v = [0,0,1] }
        "#;
        crate::scene::toml_scene::from_str(std::path::Path::new("t.toml"), src).unwrap()
    }

    #[test]
    fn welds_within_a_surface_only() {
        let scene = two_by_one();
        let mesh = PatchMesh::build(&scene);
        assert_eq!(mesh.cells(), 3);
        // Floor: two quads sharing an edge → 6 points; the wall keeps its own 4.
        assert_eq!(mesh.points.len(), 10);
        assert_eq!(mesh.offsets, vec![4, 8, 12]);
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(40))]
        /// Under any placement and scale, the subdivision grid welds to (nu+1)(nv+1) points, a
        /// second surface sharing its edge keeps its own 4, and every vertex value lies
        /// between its cells' values.
        #[test]
        fn welds_and_bounds_under_rigid_motion_and_scale(
            nu in 1usize..7,
            nv in 1usize..7,
            off in proptest::array::uniform3(-1e3f64..1e3),
            scale in 1e-3f64..1e3,
            vals in proptest::collection::vec(-1e3f64..1e3, 37),
        ) {
            let o = format!("[{:?}, {:?}, {:?}]", off[0], off[1], off[2]);
            let src = format!(
                "[[surface]]\nname = \"a\"\nrectangle = {{ origin = {o}, u = [{:?}, 0, 0], v = [0, {:?}, 0] }}\nsubdivide = [{nu}, {nv}]\n\
                 [[surface]]\nname = \"b\"\nrectangle = {{ origin = {o}, u = [0, {:?}, 0], v = [0, 0, {:?}] }}\n",
                1.3 * scale, 0.7 * scale, 0.7 * scale, scale
            );
            let scene = crate::scene::toml_scene::from_str(std::path::Path::new("p.toml"), &src).unwrap();
            let mesh = PatchMesh::build(&scene);
            proptest::prop_assert_eq!(mesh.cells(), nu * nv + 1);
            proptest::prop_assert_eq!(mesh.points.len(), (nu + 1) * (nv + 1) + 4);
            let cell: Vec<f64> = vals[..mesh.cells()].to_vec();
            let pv = mesh.to_points(&cell);
            let mut lo = vec![f64::INFINITY; pv.len()];
            let mut hi = vec![f64::NEG_INFINITY; pv.len()];
            for (c, &x) in cell.iter().enumerate() {
                for &k in mesh.cell(c) {
                    lo[k as usize] = lo[k as usize].min(x);
                    hi[k as usize] = hi[k as usize].max(x);
                }
            }
            for k in 0..pv.len() {
                // Round-off of the weighted mean: a few ulps of the largest magnitude.
                let slack = 1e-12 * lo[k].abs().max(hi[k].abs()).max(1.0);
                proptest::prop_assert!(pv[k] >= lo[k] - slack && pv[k] <= hi[k] + slack);
            }
        }
    }

    #[test]
    fn vertex_average_is_area_weighted() {
        let scene = two_by_one();
        let mesh = PatchMesh::build(&scene);
        let pv = mesh.to_points(&[1.0, 3.0, 7.0]);
        // Shared floor vertices average the two equal-area patches; the others keep theirs.
        let shared = mesh.cell(0).iter().filter(|k| mesh.cell(1).contains(k)).count();
        assert_eq!(shared, 2);
        for &k in mesh.cell(0) {
            let want = if mesh.cell(1).contains(&k) { 2.0 } else { 1.0 };
            assert_eq!(pv[k as usize], want);
        }
        for &k in mesh.cell(2) {
            assert_eq!(pv[k as usize], 7.0);
        }
    }
}
