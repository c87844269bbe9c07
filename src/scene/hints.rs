//! Facts checked before a hint is printed, so a hint never sends the user the wrong way:
//!
//! - [`obstruction_note`]: a closed scene whose rows fall short while obstructions stand in
//!   front of the short surface. Obstructions (`role = "obstruction"`, View3D `O` records)
//!   block views but take no part in the exchange, so what a surface sends onto them is
//!   missing from its row: inside an enclosure that is a leak by construction. View3D's
//!   `encl = 1` rescales such rows to 1 without a word (research/view3d.md §2); lambert
//!   refuses and names the obstructions.
//! - [`facing_away`]: a planar surface of an open scene whose front side faces none of the
//!   other surfaces while one of them lies behind it, where it would see it: it exchanges
//!   only with the ambient, the mark of a flipped normal.
//!
//! Both are plane-side tests on vertices (a necessary condition for two one-sided planar
//! pieces to see each other: each has a point strictly in front of the other's plane).
use super::Scene;
use crate::geometry::convex::convex_hull;
use crate::geometry::frame::Frame;
use crate::geometry::Polygon;
use glam::{DVec2, DVec3};
use rayon::prelude::*;

/// A vertex is on a side of a plane when farther than this fraction of the scene's size:
/// far above the round-off of coordinates (1e-16 relative), far below any real offset.
pub const SIDE_TOL: f64 = 1e-9;

/// Names listed in a note.
const LIST: usize = 5;

/// The scene's size: the diagonal of the box around every patch and obstruction vertex.
fn scale(scene: &Scene) -> f64 {
    let polys =
        scene.patches.iter().map(|p| &p.polygon).chain(scene.obstructions.iter().flat_map(|o| &o.polygons));
    let (lo, hi) = polys
        .flat_map(|p| p.vertices().iter().copied())
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if lo.x <= hi.x {
        (hi - lo).length()
    } else {
        0.0
    }
}

/// True when some vertex of `pts` is farther than `tol` in front of `plane` (or behind it,
/// for `sign` = −1).
fn any_side(plane: &Polygon, pts: &[DVec3], sign: f64, tol: f64) -> bool {
    pts.iter().any(|v| sign * plane.plane_distance(*v) > tol)
}

/// Why the rows of a closed scene leak, when obstructions stand in front of surface `name`
/// (a surface or `surface#k` patch name): `None` for an open scene, a scene without
/// obstructions, or when none of them is in front of that surface.
pub fn obstruction_note(scene: &Scene, name: &str) -> Option<String> {
    if !scene.is_closed() || scene.obstructions.is_empty() {
        return None;
    }
    let surface = name.rsplit_once('#').map_or(name, |(s, _)| s);
    let s = scene.surface_index(surface)?;
    let tol = SIDE_TOL * scale(scene);
    let patches = &scene.patches[scene.surfaces[s].patches.clone()];
    let in_front: Vec<&str> = scene
        .obstructions
        .iter()
        .filter(|o| {
            patches.iter().any(|p| o.polygons.iter().any(|q| any_side(&p.polygon, q.vertices(), 1.0, tol)))
        })
        .map(|o| o.name.as_str())
        .collect();
    if in_front.is_empty() {
        return None;
    }
    let more =
        if in_front.len() > LIST { format!(" and {} more", in_front.len() - LIST) } else { String::new() };
    Some(format!(
        "{} obstruction(s) stand in front of '{surface}' ({}{more}): an obstruction (role = \"obstruction\", a \
         View3D `O` record) blocks views but takes no part in the exchange, so what a surface sends onto it \
         is missing from its row, and an enclosure around it cannot close. If it belongs to the enclosure, \
         make it an exchanging surface (a View3D `S` record, or a [[surface]] with a boundary condition); \
         View3D's encl = 1 would rescale the short rows to 1 without saying so",
        in_front.len(),
        in_front.iter().take(LIST).copied().collect::<Vec<_>>().join(", ")
    ))
}

/// A planar surface of an open scene that sees none of the others while `behind` lies behind it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FacingAway {
    /// The surface.
    pub surface: usize,
    /// A surface behind it, facing its back.
    pub behind: usize,
}

/// The planar surfaces of an open scene whose front side faces none of the other surfaces
/// while another surface lies behind them and faces their back side (empty for closed scenes,
/// where the leak check speaks).
pub fn facing_away(scene: &Scene) -> Vec<FacingAway> {
    if scene.is_closed() || scene.surfaces.len() < 2 {
        return Vec::new();
    }
    let tol = SIDE_TOL * scale(scene);
    let found: Vec<Option<FacingAway>> = (0..scene.surfaces.len())
        .into_par_iter()
        .map(|s| {
            let surf = &scene.surfaces[s];
            if !surf.planar || surf.patches.is_empty() {
                return None;
            }
            let plane = &scene.patches[surf.patches.start].polygon;
            let outline = outline(scene, s, plane);
            let mut behind = None;
            for q in scene.patches.iter().filter(|q| q.surface != s) {
                // Only a piece whose front faces some point of this surface can exchange with it.
                if !any_side(&q.polygon, &outline, 1.0, tol) {
                    continue;
                }
                if any_side(plane, q.polygon.vertices(), 1.0, tol) {
                    return None;
                }
                if behind.is_none() && any_side(plane, q.polygon.vertices(), -1.0, tol) {
                    behind = Some(q.surface);
                }
            }
            behind.map(|b| FacingAway { surface: s, behind: b })
        })
        .collect();
    found.into_iter().flatten().collect()
}

/// The warning for [`facing_away`].
pub fn facing_away_warning(scene: &Scene, f: &FacingAway) -> String {
    format!(
        "surface '{}' faces away from every other surface and exchanges only with the ambient, while '{}' \
         lies behind it; if it should face the scene, reverse its vertex order (a rectangle's u and v, a \
         disk's normal)",
        scene.surfaces[f.surface].name, scene.surfaces[f.behind].name
    )
}

/// The corners of a planar surface: the convex hull of its patches' vertices in its plane (a
/// plane-side test over the surface needs no other point).
fn outline(scene: &Scene, s: usize, plane: &Polygon) -> Vec<DVec3> {
    let frame = Frame::of_polygon(plane);
    let mut pts: Vec<DVec2> = scene.patches[scene.surfaces[s].patches.clone()]
        .iter()
        .flat_map(|p| p.polygon.vertices().iter().map(|v| frame.in_plane(*v)))
        .collect();
    let mut hull = Vec::new();
    convex_hull(&mut pts, &mut hull);
    hull.into_iter().map(|p| frame.from_plane(p)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::BoundaryCondition;

    fn rect(o: [f64; 3], u: [f64; 3], v: [f64; 3]) -> Polygon {
        let (o, u, v) = (DVec3::from(o), DVec3::from(u), DVec3::from(v));
        Polygon::new(vec![o, o + u, o + u + v, o + v]).unwrap()
    }

    fn open(panel: Polygon) -> Scene {
        let t = Some(BoundaryCondition::Temperature(300.0));
        Scene::builder()
            .surface("floor", vec![rect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])], 0.9, t)
            .surface("panel", vec![panel], 0.9, t)
            .ambient(300.0)
            .build()
    }

    #[test]
    fn a_flipped_panel_over_a_floor_is_named_and_a_facing_one_is_not() {
        let facing = rect([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(facing_away(&open(facing.clone())).is_empty());
        let found = facing_away(&open(facing.flipped()));
        assert_eq!(found, vec![FacingAway { surface: 1, behind: 0 }]);
        let w = facing_away_warning(&open(facing.flipped()), &found[0]);
        assert!(w.contains("'panel'") && w.contains("'floor'"), "{w}");
        // The same scene closed: the leak check speaks instead.
        let mut closed = open(facing.flipped());
        closed.ambient = None;
        assert!(facing_away(&closed).is_empty());
    }

    #[test]
    fn a_panel_that_flipping_would_not_help_is_not_named() {
        // Back to back with the floor (below it, facing down): neither faces the other.
        let below = rect([0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]);
        assert!(facing_away(&open(below)).is_empty());
        // Beside the floor in its plane: neither sees the other, whatever the orientation.
        let beside = rect([2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        assert!(facing_away(&open(beside.clone())).is_empty());
        assert!(facing_away(&open(beside.flipped())).is_empty());
    }

    #[test]
    fn obstructions_are_named_only_in_front_of_the_short_surface_of_a_closed_scene() {
        let t = Some(BoundaryCondition::Temperature(300.0));
        let floor = rect([0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let scene = |z: f64, ambient: bool| {
            let mut b = Scene::builder()
                .surface("floor", vec![floor.clone()], 0.9, t)
                .surface("lid", vec![rect([0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0])], 0.9, t)
                .obstruction("shade", vec![rect([0.2, 0.2, z], [0.5, 0.0, 0.0], [0.0, 0.5, 0.0])]);
            if ambient {
                b = b.ambient(300.0);
            }
            b.build()
        };
        let note = obstruction_note(&scene(0.5, false), "floor#0").expect("in front of the floor");
        assert!(note.contains("'floor'") && note.contains("shade") && note.contains("`S` record"), "{note}");
        assert!(obstruction_note(&scene(0.5, true), "floor").is_none(), "open scene");
        assert!(obstruction_note(&scene(-0.5, false), "floor").is_none(), "behind the floor");
        assert!(obstruction_note(&scene(0.5, false), "nowhere").is_none(), "unknown name");
    }
}
