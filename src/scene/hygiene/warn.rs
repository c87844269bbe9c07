//! One stderr line per kind of finding, with the count and the worst example.
//!
//! Open edges are said only in closed scenes and only for exchanging surfaces (an open panel
//! in an open scene, or a thin shade, is normal). A closed component facing inward is said
//! when it does not enclose the rest of the scene: an enclosure faces inward by design, a
//! body inside one must not.
use super::{Example, MeshReport, SLIVER_ASPECT};
use crate::scene::Scene;
use glam::DVec3;

/// Relative slack of the "encloses the scene" box test.
const ENCLOSE_SLACK: f64 = 1e-6;

/// The warning lines for `r` in `scene` (already assembled).
pub fn warnings(r: &MeshReport, scene: &Scene) -> Vec<String> {
    let file = r.file.display();
    let at = |e: &Example| format!("surface '{}' triangle {}", r.name(e.at), e.at.index);
    let mut out = Vec::new();
    // Moves within the default tolerance are round-off of the file's coordinates.
    if r.weld.moved > 0 && r.weld.max_move > super::WELD_REL * r.diag {
        out.push(format!(
            "{file}: welded {} vertices onto neighbours within {:.3e} m (at most {:.3e} m apart){}",
            r.weld.moved,
            r.weld_tol,
            r.weld.max_move,
            if r.weld.collapsed > 0 {
                format!("; {} triangles lost their area to welding and were dropped", r.weld.collapsed)
            } else {
                String::new()
            }
        ));
    }
    if let Some(log) = &r.repair {
        out.push(repair_line(r, log));
    }
    let is_obstruction = |name: &str| scene.obstructions.iter().any(|o| o.name == name);
    let open: Vec<(&str, usize)> = r
        .surfaces
        .iter()
        .filter(|s| s.boundary_edges > 0 && !is_obstruction(&s.name))
        .map(|s| (s.name.as_str(), s.boundary_edges))
        .collect();
    if scene.is_closed() && !open.is_empty() {
        let total: usize = open.iter().map(|s| s.1).sum();
        let most = open.iter().max_by_key(|s| s.1).map_or(("", 0), |s| *s);
        let longest = r
            .boundary
            .worst
            .filter(|e| !is_obstruction(r.name(e.at)))
            .map(|e| format!("; the longest is on {}, {:.3e} m", at(&e), e.value))
            .unwrap_or_default();
        out.push(format!(
            "{file}: open mesh: {total} boundary edges (used by one triangle) on {} surface(s), most on '{}' \
             ({}){longest}; radiation leaves through the openings unless other surfaces close them",
            open.len(),
            most.0,
            most.1
        ));
    }
    if let (n, Some(e)) = (r.nonmanifold.count, r.nonmanifold.worst) {
        out.push(format!(
            "{file}: {n} non-manifold edges (shared by more than two triangles); worst: {}, on an edge of {} \
             triangles",
            at(&e),
            e.value
        ));
    }
    if let (n, Some(e)) = (r.duplicates.count, r.duplicates.worst) {
        let first = e.other.map(|o| format!(" repeats surface '{}' triangle {}", r.name(o), o.index));
        out.push(format!(
            "{file}: {n} duplicate faces; e.g. {}{} ({} copies); repair drops them",
            at(&e),
            first.unwrap_or_default(),
            e.value
        ));
    }
    if let (n, Some(e)) = (r.against.count, r.against.worst) {
        out.push(format!(
            "{file}: {n} triangles are wound against their neighbours ({} edges are run the same way by both \
             of their triangles); e.g. {}; repair flips them",
            r.inconsistent_edges.count,
            at(&e)
        ));
    }
    out.extend(inward_line(r, scene));
    if let (n, Some(e)) = (r.slivers.count, r.slivers.worst) {
        out.push(format!(
            "{file}: {n} sliver triangles (aspect ratio above {SLIVER_ASPECT:e}: longest edge over the height on \
             it, 1 for an equilateral triangle); worst: {}, aspect {:.3e}; repair drops them",
            at(&e),
            e.value
        ));
    }
    if let (n, Some(e)) = (r.intersections.count, r.intersections.worst) {
        let other =
            e.other.map(|o| format!("surface '{}' triangle {}", r.name(o), o.index)).unwrap_or_default();
        let how = if e.value > 0.0 { format!("along {:.3e} m", e.value) } else { "in its plane".into() };
        out.push(format!(
            "{file}: {n} pairs of triangles cross each other; worst: {} crosses {other} {how}; the mesh is not \
             a valid solid there",
            at(&e)
        ));
    }
    out
}

fn repair_line(r: &MeshReport, log: &super::repair::RepairLog) -> String {
    let file = r.file.display();
    if log.is_empty() {
        return format!("{file}: repair: nothing to change");
    }
    let mut parts = Vec::new();
    if log.duplicates > 0 {
        parts.push(format!("dropped {} duplicate faces", log.duplicates));
    }
    if log.slivers > 0 {
        parts.push(format!("dropped {} slivers ({:.3e} m² in all)", log.slivers, log.sliver_area));
    }
    if log.flipped > 0 {
        parts.push(format!("flipped {} triangles to agree with their neighbours", log.flipped));
    }
    if log.turned_components > 0 {
        parts.push(format!(
            "turned {} closed component(s) ({} triangles) that faced inward outward (an empty enclosure meant \
             to be seen from inside needs repair off)",
            log.turned_components, log.turned_triangles
        ));
    }
    let mut line = format!("{file}: repair: {}", parts.join(", "));
    if log.boundary_after > log.boundary_before {
        line.push_str(&format!(
            "; dropping triangles opened {} edges (holes of {:.3e} m² in all)",
            log.boundary_after - log.boundary_before,
            log.sliver_area
        ));
    }
    line
}

fn inward_line(r: &MeshReport, scene: &Scene) -> Option<String> {
    let (lo, hi) = scene_box(scene);
    let slack = ENCLOSE_SLACK * (hi - lo).length();
    let encloses = |c: &super::Component| c.lo.cmple(lo + slack).all() && c.hi.cmpge(hi - slack).all();
    let inward: Vec<&super::Component> =
        r.components.iter().filter(|c| c.is_inward() && !encloses(c)).collect();
    let first = inward.first()?;
    let names: Vec<&str> = first.surfaces.iter().map(|&s| r.surfaces[s].name.as_str()).collect();
    Some(format!(
        "{}: {} closed component(s) face inward (negative volume) without enclosing the rest of the scene, \
         e.g. the one of surface '{}' ({:.3e} m³): it is seen from inside, as an enclosure is; a body must \
         face the other way (repair turns it)",
        r.file.display(),
        inward.len(),
        names.join("', '"),
        first.volume
    ))
}

/// Bounding box of every patch and obstruction of the scene.
pub fn scene_box(scene: &Scene) -> (DVec3, DVec3) {
    let polys =
        scene.patches.iter().map(|p| &p.polygon).chain(scene.obstructions.iter().flat_map(|o| &o.polygons));
    polys
        .flat_map(|p| p.vertices())
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &v| (lo.min(v), hi.max(v)))
}
