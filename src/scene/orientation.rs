//! Geometry facts that a leak hint is checked against before it is printed: does the scene
//! close, does something enclose it, which closed bodies face outward or inward, which meshes
//! are open or wound against themselves, which patches are slivers. Built once from the
//! scene and its mesh checks ([`super::hygiene`]); `exchange::leak` turns them and the
//! leaking rows into the hint.
use super::hygiene::{aspect, warn::scene_box, SLIVER_ASPECT};
use super::{Scene, Shape};
use glam::DVec3;

/// A mesh surface without a mesh report is closed when its area vectors cancel to this
/// fraction of its area: a closed surface's Σ A_k n_k is exactly 0 (divergence theorem), an
/// open one keeps its opening's.
pub const CLOSED_TOL: f64 = 1e-9;

/// The exchanging surfaces together close when |Σ A n| is below this fraction of their area:
/// an opening of a millionth of the area cannot explain a row short by the leak threshold
/// (1e-3 or more).
pub const SCENE_CLOSED_TOL: f64 = 1e-6;

/// A closed, consistently wound mesh component (a body seen from outside, or a shell seen from
/// inside).
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// Its surfaces' names.
    pub surfaces: Vec<String>,
    /// Positive: faces outward.
    pub volume: f64,
    /// Its box contains every patch and obstruction of the scene.
    pub encloses_scene: bool,
}

/// An open or inconsistently wound mesh surface.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshDefect {
    /// Surface name.
    pub surface: String,
    /// Boundary edges.
    pub boundary_edges: usize,
    /// Triangles wound against their neighbours' majority.
    pub against: usize,
}

/// What the leak hint may rely on.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneFacts {
    /// Surface names, in scene order.
    pub names: Vec<String>,
    /// First patch of each surface.
    pub patch_start: Vec<usize>,
    /// |Σ A n| over the exchanging patches, m².
    pub area_vector: f64,
    /// Σ A over them, m².
    pub area: f64,
    /// Signed volume they enclose, m³: negative when an inward shell surrounds the rest.
    pub volume: f64,
    /// Closed mesh components.
    pub bodies: Vec<Body>,
    /// Open or inconsistently wound mesh surfaces.
    pub defects: Vec<MeshDefect>,
    /// Every mesh surface comes from a checked file, and no shape (polygon, rectangle, disk) is
    /// exchanging: the mesh checks then see the whole scene.
    pub all_checked_meshes: bool,
    /// Patches whose polygon is a sliver.
    pub sliver_patches: Vec<usize>,
    /// The scene is a bare mesh file (it cannot say `[ambient]`).
    pub bare: bool,
}

impl SceneFacts {
    /// Gathers the facts of `scene`.
    pub fn of(scene: &Scene) -> Self {
        let mut f =
            SceneFacts {
                names: scene.surfaces.iter().map(|s| s.name.clone()).collect(),
                patch_start: scene.surfaces.iter().map(|s| s.patches.start).collect(),
                bare: scene.source.extension().and_then(|e| e.to_str()).is_some_and(|e| {
                    ["gltf", "glb", "stl", "obj"].contains(&e.to_ascii_lowercase().as_str())
                }),
                ..Self::default()
            };
        let (mut flux, mut moment) = (DVec3::ZERO, DVec3::ZERO);
        for p in &scene.patches {
            let a = p.polygon.area();
            f.area += a;
            flux += a * p.polygon.normal();
            moment += a * p.polygon.centroid();
        }
        f.area_vector = flux.length();
        if f.area > 0.0 {
            let c = moment / f.area;
            f.volume = scene
                .patches
                .iter()
                .map(|p| p.polygon.area() * p.polygon.normal().dot(p.polygon.centroid() - c) / 3.0)
                .sum();
        }
        f.sliver_patches = (0..scene.patches.len())
            .filter(|&i| {
                let v = scene.patches[i].polygon.vertices();
                v.len() == 3 && aspect([v[0], v[1], v[2]]) > SLIVER_ASPECT
            })
            .collect();

        let (lo, hi) = scene_box(scene);
        let slack = 1e-6 * (hi - lo).length();
        let exchanging = |name: &str| scene.surface_index(name).is_some();
        let mut checked: Vec<&str> = Vec::new();
        for r in &scene.meshes {
            for c in r.components.iter().filter(|c| c.closed && c.consistent) {
                let surfaces: Vec<String> = c
                    .surfaces
                    .iter()
                    .map(|&s| r.surfaces[s].name.clone())
                    .filter(|n| exchanging(n))
                    .collect();
                if surfaces.is_empty() {
                    continue;
                }
                let encloses_scene = c.lo.cmple(lo + slack).all() && c.hi.cmpge(hi - slack).all();
                f.bodies.push(Body { surfaces, volume: c.volume, encloses_scene });
            }
            for s in r.surfaces.iter().filter(|s| exchanging(&s.name)) {
                checked.push(&s.name);
                if s.boundary_edges > 0 || s.against > 0 {
                    f.defects.push(MeshDefect {
                        surface: s.name.clone(),
                        boundary_edges: s.boundary_edges,
                        against: s.against,
                    });
                }
            }
        }
        // Mesh surfaces without a report (programmatic scenes): the area-vector test.
        for (k, s) in scene.surfaces.iter().enumerate() {
            if !matches!(s.shape, Shape::Mesh) || checked.contains(&s.name.as_str()) {
                continue;
            }
            if let Some(volume) = closed_volume(scene, k) {
                let patches = &scene.patches[s.patches.clone()];
                let (blo, bhi) = patches
                    .iter()
                    .flat_map(|p| p.polygon.vertices())
                    .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
                let encloses_scene = blo.cmple(lo + slack).all() && bhi.cmpge(hi - slack).all();
                f.bodies.push(Body { surfaces: vec![s.name.clone()], volume, encloses_scene });
            }
        }
        f.all_checked_meshes = scene.surfaces.iter().all(|s| checked.contains(&s.name.as_str()));
        f
    }

    /// The surfaces' area vectors cancel: no opening that could explain a leak is in sight.
    pub fn closes(&self) -> bool {
        self.area_vector <= SCENE_CLOSED_TOL * self.area
    }

    /// Index of the surface of an output row (`surface` or `surface#k`).
    pub fn surface_of(&self, row: &str) -> Option<usize> {
        let name = row.rsplit_once('#').map_or(row, |(s, _)| s);
        self.names.iter().position(|n| n == name)
    }

    /// The patch of an output row `surface#k`.
    pub fn patch_of(&self, row: &str) -> Option<usize> {
        let (name, k) = row.rsplit_once('#')?;
        let s = self.names.iter().position(|n| n == name)?;
        Some(self.patch_start[s] + k.parse::<usize>().ok()?)
    }
}

/// Signed volume of mesh surface `k` when its area vectors cancel ([`CLOSED_TOL`]).
fn closed_volume(scene: &Scene, k: usize) -> Option<f64> {
    let patches = &scene.patches[scene.surfaces[k].patches.clone()];
    let area: f64 = patches.iter().map(|p| p.polygon.area()).sum();
    let flux: DVec3 = patches.iter().map(|p| p.polygon.area() * p.polygon.normal()).sum();
    if area <= 0.0 || flux.length() > CLOSED_TOL * area {
        return None;
    }
    let c = patches.iter().map(|p| p.polygon.area() * p.polygon.centroid()).sum::<DVec3>() / area;
    Some(
        patches
            .iter()
            .map(|p| p.polygon.area() * p.polygon.normal().dot(p.polygon.centroid() - c))
            .sum::<f64>()
            / 3.0,
    )
}
