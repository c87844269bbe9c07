//! Each finding on a small hand-made mesh: a unit cube of 12 triangles, then one defect at a
//! time, and what repair makes of it.
use super::*;
use crate::scene::mesh::weld;

/// The 12 outward triangles of the cube [o, o + s]³.
fn cube(o: DVec3, s: f64) -> Vec<[DVec3; 3]> {
    let p = |x: f64, y: f64, z: f64| o + s * DVec3::new(x, y, z);
    let quads = [
        [p(0., 0., 0.), p(0., 1., 0.), p(1., 1., 0.), p(1., 0., 0.)], // z = 0, normal −z
        [p(0., 0., 1.), p(1., 0., 1.), p(1., 1., 1.), p(0., 1., 1.)], // z = 1, +z
        [p(0., 0., 0.), p(1., 0., 0.), p(1., 0., 1.), p(0., 0., 1.)], // y = 0, −y
        [p(0., 1., 0.), p(0., 1., 1.), p(1., 1., 1.), p(1., 1., 0.)], // y = 1, +y
        [p(0., 0., 0.), p(0., 0., 1.), p(0., 1., 1.), p(0., 1., 0.)], // x = 0, −x
        [p(1., 0., 0.), p(1., 1., 0.), p(1., 1., 1.), p(1., 0., 1.)], // x = 1, +x
    ];
    quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect()
}

fn run(soup: &[[DVec3; 3]]) -> (MeshReport, TriMesh) {
    let tags: Vec<Tag> = (0..soup.len() as u32).map(|index| Tag { surface: 0, index }).collect();
    let (mesh, info) = weld(soup, &tags, 1e-9);
    (check("part.stl".into(), &["part".to_string()], &mesh, 1e-9, info), mesh)
}

fn flipped(t: [DVec3; 3]) -> [DVec3; 3] {
    [t[0], t[2], t[1]]
}

#[test]
fn a_clean_cube_is_one_closed_outward_body() {
    let (r, _) = run(&cube(DVec3::ZERO, 1.0));
    assert_eq!(r.components.len(), 1);
    let c = &r.components[0];
    assert!(c.closed && c.consistent && c.is_outward_body(), "{c:?}");
    assert!((c.volume - 1.0).abs() < 1e-15, "{}", c.volume);
    for f in [r.boundary, r.nonmanifold, r.duplicates, r.against, r.slivers, r.intersections] {
        assert_eq!(f.count, 0, "{r:?}");
    }
    assert_eq!(r.weld.after, 8);
}

#[test]
fn inward_cube_has_negative_volume_and_repair_turns_it() {
    let soup: Vec<_> = cube(DVec3::ZERO, 2.0).into_iter().map(flipped).collect();
    let (r, mut mesh) = run(&soup);
    assert!(r.components[0].is_inward() && (r.components[0].volume + 8.0).abs() < 1e-14);
    let log = repair::repair(&mut mesh);
    assert_eq!((log.turned_components, log.turned_triangles, log.flipped), (1, 12, 0));
    let r2 = check("part.stl".into(), &["part".into()], &mesh, 1e-9, r.weld);
    assert!(r2.components[0].is_outward_body());
}

#[test]
fn one_flipped_triangle_is_against_its_neighbours_and_repair_flips_it_back() {
    let mut soup = cube(DVec3::ZERO, 1.0);
    soup[7] = flipped(soup[7]);
    let (r, mut mesh) = run(&soup);
    assert_eq!((r.against.count, r.inconsistent_edges.count), (1, 3));
    assert_eq!(r.against.worst.unwrap().at.index, 7);
    assert_eq!(r.surfaces[0].against, 1);
    assert!(!r.components[0].consistent && r.components[0].closed);
    let log = repair::repair(&mut mesh);
    assert_eq!((log.flipped, log.turned_components), (1, 0));
    let r2 = check("part.stl".into(), &["part".into()], &mesh, 1e-9, r.weld);
    assert!(r2.components[0].is_outward_body() && r2.against.count == 0);
}

#[test]
fn duplicates_are_counted_and_dropped() {
    let mut soup = cube(DVec3::ZERO, 1.0);
    soup.push(soup[4]);
    soup.push(flipped(soup[9]));
    let (r, mut mesh) = run(&soup);
    assert_eq!(r.duplicates.count, 2);
    let w = r.duplicates.worst.unwrap();
    let pair = (w.at.index, w.other.unwrap().index);
    assert!(w.value == 2.0 && (pair == (12, 4) || pair == (13, 9)), "{w:?}");
    // Each copied face puts a third triangle on its three edges.
    assert_eq!(r.nonmanifold.count, 6);
    let log = repair::repair(&mut mesh);
    assert_eq!(log.duplicates, 2);
    let r2 = check("part.stl".into(), &["part".into()], &mesh, 1e-9, r.weld);
    assert!(r2.components[0].is_outward_body() && r2.nonmanifold.count == 0, "{r2:?}");
}

#[test]
fn a_missing_triangle_opens_three_edges() {
    let mut soup = cube(DVec3::ZERO, 1.0);
    soup.remove(3);
    let (r, _) = run(&soup);
    assert_eq!((r.boundary.count, r.surfaces[0].boundary_edges), (3, 3));
    assert!(!r.components[0].closed);
    // The longest open edge is the face diagonal.
    assert!((r.boundary.worst.unwrap().value - 2f64.sqrt()).abs() < 1e-15);
}

#[test]
fn slivers_are_found_and_dropping_one_is_said_to_open_the_mesh() {
    // Split the top face's first triangle at a point 1e-5 off its diagonal: a sliver of
    // aspect ≈ 1.41 / 1e-5 · (√3/2) ≈ 1.2e5 beside a regular triangle.
    let mut soup = cube(DVec3::ZERO, 1.0);
    let [a, b, c] = soup[2];
    let m = 0.5 * (a + c) + DVec3::new(1e-5, -1e-5, 0.0) / 2f64.sqrt();
    soup[2] = [a, b, m];
    soup.push([b, c, m]);
    soup.push([a, m, c]);
    let (r, mut mesh) = run(&soup);
    assert_eq!(r.slivers.count, 1);
    let w = r.slivers.worst.unwrap();
    assert_eq!(w.at.index, 13);
    let expect = 3f64.sqrt() * 2.0 / (4.0 * 0.5 * 2f64.sqrt() * 1e-5);
    assert!((w.value / expect - 1.0).abs() < 1e-6, "{} vs {expect}", w.value);
    let log = repair::repair(&mut mesh);
    assert_eq!((log.slivers, log.boundary_before, log.boundary_after), (1, 0, 3));
}

#[test]
fn interpenetrating_cubes_cross_and_touching_ones_do_not() {
    let mut soup = cube(DVec3::ZERO, 1.0);
    soup.extend(cube(DVec3::splat(0.5), 1.0));
    let (r, _) = run(&soup);
    assert!(r.intersections.count > 0);
    let w = r.intersections.worst.unwrap();
    assert!(w.value > 0.0 && w.value <= 0.5 * 2f64.sqrt() + 1e-12, "{w:?}");
    assert_eq!(r.components.len(), 2);
    // Face to face: contact, not a crossing.
    let mut soup = cube(DVec3::ZERO, 1.0);
    soup.extend(cube(DVec3::new(1.0, 0.25, 0.25), 0.5));
    let (r, _) = run(&soup);
    assert_eq!(r.intersections.count, 0, "{:?}", r.intersections);
}

#[test]
fn aspect_is_one_for_equilateral_and_grows_as_length_over_height() {
    let eq = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, 3f64.sqrt() / 2.0, 0.0)];
    assert!((aspect(eq) - 1.0).abs() < 1e-14);
    let thin = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1e-3, 0.0)];
    assert!((aspect(thin) - 3f64.sqrt() / 2.0 * 1e3).abs() < 1e-9);
}

#[test]
fn a_face_meshed_apart_meets_its_neighbours_in_seams_not_openings() {
    // The z = 0 face split at the midpoint of its edge on y = 0: that point is a corner of the
    // face's triangles but not of the y = 0 face's, a T-junction.
    let mut soup = cube(DVec3::ZERO, 1.0);
    let m = DVec3::new(0.5, 0.0, 0.0);
    let (o, y, xy, x) = (DVec3::ZERO, DVec3::Y, DVec3::new(1.0, 1.0, 0.0), DVec3::X);
    soup.splice(0..2, [[o, y, m], [m, y, xy], [m, xy, x]]);
    let (r, _) = run(&soup);
    assert_eq!((r.boundary.count, r.seams), (0, 3), "{r:?}");
    assert_eq!(r.components.len(), 1);
    assert!(r.components[0].is_outward_body() && (r.components[0].volume - 1.0).abs() < 1e-15);
    // Flipping the split face's triangles is seen across the seam as well.
    let soup: Vec<_> = soup.iter().enumerate().map(|(k, t)| if k < 3 { flipped(*t) } else { *t }).collect();
    let (r, _) = run(&soup);
    assert_eq!(r.against.count, 3);
    assert!(!r.components[0].consistent);
}
