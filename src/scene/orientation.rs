//! Orientation of closed mesh surfaces: a closed body whose normals all face outward sees
//! nothing of an enclosure from inside it, the usual cause of a leaking CAD room exported
//! with the wrong winding. Used to name that cause next to a leak warning or refusal.
use super::{Scene, Shape};
use glam::DVec3;

/// A surface is closed when its area vectors cancel to this fraction of its area: a closed
/// surface's Σ A_k n_k is exactly 0 (divergence theorem), an open one keeps its opening's.
pub const CLOSED_TOL: f64 = 1e-9;

/// Indices of the mesh surfaces that are closed with every normal facing outward (positive
/// enclosed volume V = Σ_k A_k n_k · (c_k − c)/3 about the area centroid c).
pub fn outward_closed_meshes(scene: &Scene) -> Vec<usize> {
    (0..scene.surfaces.len())
        .filter(|&s| matches!(scene.surfaces[s].shape, Shape::Mesh))
        .filter(|&s| {
            let patches = &scene.patches[scene.surfaces[s].patches.clone()];
            let area: f64 = patches.iter().map(|p| p.polygon.area()).sum();
            let flux: DVec3 = patches.iter().map(|p| p.polygon.area() * p.polygon.normal()).sum();
            if area <= 0.0 || flux.length() > CLOSED_TOL * area {
                return false;
            }
            let c = patches.iter().map(|p| p.polygon.area() * p.polygon.centroid()).sum::<DVec3>() / area;
            let volume: f64 = patches
                .iter()
                .map(|p| p.polygon.area() * p.polygon.normal().dot(p.polygon.centroid() - c))
                .sum::<f64>()
                / 3.0;
            volume > 0.0
        })
        .collect()
}

/// The hint printed beside a leak that involves surface `name`.
pub fn outward_hint(name: &str) -> String {
    format!(
        "surface '{name}' is a closed mesh whose normals all face outward, so it sees nothing from \
         inside; if it is the enclosure, reverse its triangles' winding (flip its normals)"
    )
}
