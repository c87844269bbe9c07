//! The exact kernel at every scale (issue 19): polygons of very different size, far-off
//! coordinates, elongated triangles, and the range check that no impossible factor is written.
//!
//! The reference for the unit square over the long triangle is an independent mpmath area
//! integral of Lambert's point factor at 30 digits (validation/reference/long_triangle.py,
//! values in long_triangle.csv); for long strips, catalogue C-11 at 60 digits (strips.py).
use glam::DVec3;
use lambert::geometry::Polygon;
use lambert::viewfactor::exact::pair::polygon_polygon_with_round_off;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The exact kernel's promise: 1e-9 relative.
const REL_TOL: f64 = 1e-9;

fn poly(v: &[[f64; 3]]) -> Polygon {
    Polygon::new(v.iter().map(|&a| DVec3::from_array(a)).collect()).expect("valid polygon")
}

/// The unit square [0, 1]² at z = 1, facing down.
fn square() -> Polygon {
    poly(&[[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [1.0, 1.0, 1.0], [1.0, 0.0, 1.0]])
}

/// The triangle (0, 0, ½), (L, 0, ½), (0, ½, ½), facing up.
fn long_triangle(l: f64) -> Polygon {
    poly(&[[0.0, 0.0, 0.5], [l, 0.0, 0.5], [0.0, 0.5, 0.5]])
}

/// (L, F(square → triangle)) from the committed mpmath table.
fn reference() -> Vec<(f64, f64)> {
    include_str!("../../validation/reference/long_triangle.csv")
        .lines()
        .skip(1)
        .map(|line| {
            let mut cols = line.split(',');
            let l: f64 = cols.next().unwrap().parse().unwrap();
            let f: f64 = cols.next().unwrap().parse().unwrap();
            (l, f)
        })
        .collect()
}

/// F(p → q) and its round-off bound relative to F.
fn factor(p: &Polygon, q: &Polygon) -> (f64, f64) {
    let x = polygon_polygon_with_round_off(p, q);
    (x.value / p.area(), x.round_off / x.value)
}

#[test]
fn square_over_the_long_triangle_matches_the_reference_at_every_length() {
    let table = reference();
    assert_eq!(table.len(), 12, "L = 1e0 … 1e11");
    for (l, want) in table {
        let (s, t) = (square(), long_triangle(l));
        let (f, bound) = factor(&s, &t);
        // Reciprocity: the other polygon's side of the same exchange.
        let back = polygon_polygon_with_round_off(&t, &s).value / s.area();
        eprintln!(
            "L = {l:e}: F = {f:.15} (reference {want:.15}), error {:.1e}, bound {bound:.1e}",
            f / want - 1.0
        );
        assert!((f / want - 1.0).abs() < REL_TOL, "L = {l:e}: {f} vs {want}");
        assert!((back / want - 1.0).abs() < REL_TOL, "L = {l:e} (reciprocal): {back} vs {want}");
        assert!(bound < REL_TOL, "L = {l:e}: bound {bound:e} does not prove the promise");
    }
}

#[test]
fn long_strips_over_each_other_are_bounded_honestly() {
    // Both polygons long against their distance: the contour terms (L² ln L) cancel to L
    // and the error grows like L². Not fixed: the round-off bound must cover the error, and
    // the kernel flags the entry once the bound passes the 1e-9 promise (catalogue C-11 at
    // 60 digits, validation/reference/strips.py).
    let table: Vec<(f64, f64)> = include_str!("../../validation/reference/strips.csv")
        .lines()
        .skip(1)
        .map(|line| {
            let mut cols = line.split(',');
            (cols.next().unwrap().parse().unwrap(), cols.next().unwrap().parse().unwrap())
        })
        .collect();
    assert_eq!(table.len(), 12);
    for (l, want) in table {
        let bottom = poly(&[[0.0, 0.0, 0.0], [l, 0.0, 0.0], [l, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        let top = poly(&[[0.0, 0.0, 1.0], [0.0, 1.0, 1.0], [l, 1.0, 1.0], [l, 0.0, 1.0]]);
        let (f, bound) = factor(&bottom, &top);
        let err = f / want - 1.0;
        eprintln!("L = {l:e}: F = {f:.15} (C-11 {want:.15}), error {err:.1e}, bound {bound:.1e}");
        assert!(err.abs() <= bound, "L = {l:e}: error {err:e} above the bound {bound:e}");
        if l <= 1e4 {
            assert!(err.abs() < REL_TOL, "L = {l:e}: {f} vs {want}");
        }
    }
    // The kernel says so on stderr.
    let dir = tempfile::tempdir().unwrap();
    let strips = "[ambient]\ntemperature = 300.0\n\
        [[surface]]\nname = \"bottom\"\npolygon = [[0,0,0],[1e9,0,0],[1e9,1,0],[0,1,0]]\ntemperature = 300.0\n\
        [[surface]]\nname = \"top\"\npolygon = [[0,0,1],[0,1,1],[1e9,1,1],[1e9,0,1]]\ntemperature = 300.0\n";
    let s = scene(dir.path(), "strips.toml", strips);
    for cmd in ["viewfactors", "solve"] {
        let out = run(&[cmd, s.to_str().unwrap(), "-m", "analytic"]);
        assert!(out.status.success(), "{cmd}: {}", String::from_utf8_lossy(&out.stderr));
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("warning: analytic entry bottom -> top") && err.contains("round-off bound"),
            "{cmd}: {err}"
        );
    }
    // `auto` promises --tolerance on F, which a bound of ~1e-7 relative keeps: no flag there,
    // until the goal is finer than the bound.
    let quiet = run(&["viewfactors", s.to_str().unwrap()]);
    assert!(quiet.status.success());
    assert!(!String::from_utf8_lossy(&quiet.stderr).contains("round-off bound"));
    let fine = run(&["viewfactors", s.to_str().unwrap(), "--tolerance", "1e-12"]);
    assert!(String::from_utf8_lossy(&fine.stderr).contains("round-off bound"));
}

/// Pairs of every kind: size ratios near 1 and up to 1e6, touching and apart.
fn pairs() -> Vec<(&'static str, Polygon, Polygon)> {
    let ground = |w: f64| poly(&[[-w, -w, 0.0], [w, -w, 0.0], [w, w, 0.0], [-w, w, 0.0]]);
    let small = poly(&[[-0.5, -0.5, 1.0], [-0.5, 0.5, 1.0], [0.5, 0.5, 1.0], [0.5, -0.5, 1.0]]);
    vec![
        ("square over long triangle", square(), long_triangle(1e3)),
        ("square over 2e6 m ground", small.clone(), ground(1e6)),
        (
            "perpendicular squares sharing an edge",
            poly(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]),
            poly(&[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0], [0.0, 0.0, 1.0]]),
        ),
        (
            "small plate standing on a wide floor",
            poly(&[[0.0, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.1, 0.1], [0.0, 0.0, 0.1]]),
            ground(100.0),
        ),
        (
            "square high over a wide ground",
            square(),
            poly(&[[-1e4, -1e4, -9.0], [1e4, -1e4, -9.0], [1e4, 1e4, -9.0], [-1e4, 1e4, -9.0]]),
        ),
    ]
}

fn moved(p: &Polygon, scale: f64, shift: DVec3) -> Polygon {
    Polygon::new(p.vertices().iter().map(|v| *v * scale + shift).collect()).unwrap()
}

#[test]
fn scaling_and_translation_leave_factors_unchanged() {
    for (name, p, q) in pairs() {
        let (f0, _) = factor(&p, &q);
        assert!(f0 > 0.0 && f0 <= 1.0 + 1e-12, "{name}: {f0}");
        // The smaller polygon's size, for translations relative to it (coordinates carry
        // rounding relative to their magnitude, so that is what a shift can keep to 1e-9).
        let size = p.bounding_radius().min(q.bounding_radius());
        for scale in [1e-6, 1e-3, 0.7, 1e3, 1e6] {
            for shift in [0.0, 1e-6, 1.0, 1e3, 1e6] {
                let d = DVec3::new(1.0, -0.6, 0.3) * shift * size * scale;
                let (f, _) = factor(&moved(&p, scale, d), &moved(&q, scale, d));
                assert!(
                    (f / f0 - 1.0).abs() < REL_TOL,
                    "{name}: scale {scale:e}, shift {shift:e} sizes: {f} vs {f0} ({:e})",
                    f / f0 - 1.0
                );
            }
        }
    }
}

#[test]
fn a_square_over_a_ground_of_any_width_sees_all_of_it() {
    // F(square → ground) = 1 − the solid angle beyond the ground's edge, below 1e-9 from
    // 2e4 m on (4/π·h/w at height h = 1 over half-width w, in cosine measure (h/w)²).
    let small = poly(&[[-0.5, -0.5, 1.0], [-0.5, 0.5, 1.0], [0.5, 0.5, 1.0], [0.5, -0.5, 1.0]]);
    for w in [1e5, 1e6, 1e7, 1e9, 1e12] {
        let g = poly(&[[-w, -w, 0.0], [w, -w, 0.0], [w, w, 0.0], [-w, w, 0.0]]);
        let (f, bound) = factor(&small, &g);
        eprintln!("ground half-width {w:e}: F = {f:.15}, 1 − F = {:.1e}, bound {bound:.1e}", 1.0 - f);
        assert!((f - 1.0).abs() < REL_TOL, "half-width {w:e}: F = {f}");
    }
}

#[test]
fn a_corrupted_far_vertex_gives_a_possible_factor() {
    // One vertex of a triangle thrown to 7.8e11 m (a 2 m base: thinner ones are rejected as
    // degenerate): the pair is exact, never above 1.
    let t = poly(&[[0.0, 0.0, 0.0], [7.8e11, 1.0, 0.0], [0.0, 2.0, 0.0]]);
    let (f, bound) = factor(&square(), &t);
    // Near the square the triangle is the strip 0 ≤ y ≤ 2 (to 1e-9 within 1e3 m; beyond, the
    // square sees nothing that matters at 1e-6).
    let strip = poly(&[[0.0, 0.0, 0.0], [1e9, 0.0, 0.0], [1e9, 2.0, 0.0], [0.0, 2.0, 0.0]]);
    let (want, _) = factor(&square(), &strip);
    eprintln!("F = {f}, strip {want}, bound {bound:e}");
    assert!(f > 0.0 && f <= 1.0, "{f}");
    assert!((f / want - 1.0).abs() < 1e-6, "{f} vs strip {want}");
    assert!(bound < REL_TOL, "bound {bound:e}");
}

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn scene(dir: &Path, name: &str, toml: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, toml).unwrap();
    p
}

/// A square at height 1 facing down over a ground of half-width `w` facing up, open.
fn ground_scene(w: f64) -> String {
    format!(
        "[ambient]\ntemperature = 300.0\n\
         [[surface]]\nname = \"square\"\npolygon = [[-0.5,-0.5,1],[-0.5,0.5,1],[0.5,0.5,1],[0.5,-0.5,1]]\ntemperature = 300.0\n\
         [[surface]]\nname = \"ground\"\npolygon = [[-{w},-{w},0],[{w},-{w},0],[{w},{w},0],[-{w},{w},0]]\ntemperature = 300.0\n"
    )
}

/// F(square → ground) and its standard error from a `viewfactors` run.
fn square_to_ground(out: &Output) -> (f64, f64) {
    let csv = String::from_utf8_lossy(&out.stdout);
    let line =
        csv.lines().find(|l| l.starts_with("square,ground,")).unwrap_or_else(|| panic!("no entry: {csv}"));
    let cols: Vec<&str> = line.split(',').collect();
    // hemicube and single-plane write an empty std_error (no estimate): read as 0.
    (cols[2].parse().unwrap(), if cols[3].is_empty() { 0.0 } else { cols[3].parse().unwrap() })
}

#[test]
fn every_method_finds_a_ground_two_million_metres_wide() {
    let dir = tempfile::tempdir().unwrap();
    let s = scene(dir.path(), "ground.toml", &ground_scene(1e6));
    let path = s.to_str().unwrap();
    for method in ["analytic", "mc-cosine", "mc-uniform", "mc-area", "hemicube", "single-plane"] {
        let out = run(&["viewfactors", path, "-m", method, "--samples", "20000"]);
        assert!(out.status.success(), "{method}: {}", String::from_utf8_lossy(&out.stderr));
        let (f, se) = square_to_ground(&out);
        // Single plane misses the grazing 8.2e-5; the others see (almost) all of the ground.
        let tol = 1e-4 + 4.0 * se;
        assert!((f - 1.0).abs() < tol, "{method}: F = {f} ± {se}");
    }
}

#[test]
fn hemicube_sees_the_billion_metre_triangle_and_never_exceeds_one() {
    let dir = tempfile::tempdir().unwrap();
    let tri = "[ambient]\ntemperature = 300.0\n\
        [[surface]]\nname = \"square\"\npolygon = [[0,0,1],[0,1,1],[1,1,1],[1,0,1]]\ntemperature = 300.0\n\
        [[surface]]\nname = \"tri\"\npolygon = [[0,0,0.5],[1e9,0,0.5],[0,0.5,0.5]]\ntemperature = 300.0\n";
    let s = scene(dir.path(), "tri.toml", tri);
    let out = run(&["viewfactors", s.to_str().unwrap(), "-m", "hemicube"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = String::from_utf8_lossy(&out.stdout);
    let f: f64 = csv
        .lines()
        .find(|l| l.starts_with("square,tri,"))
        .expect("an entry")
        .split(',')
        .nth(2)
        .unwrap()
        .parse()
        .unwrap();
    // Reference 0.2583 (mpmath); the hemicube's proximity error at a few positions is percent-level.
    assert!((f / 0.258321817 - 1.0).abs() < 0.05, "F = {f}");
    // --resolution 5 (6): the raw midpoint total is 1.0154; normalised, F stays ≤ 1.
    let g = scene(dir.path(), "ground.toml", &ground_scene(1e6));
    let out = run(&["viewfactors", g.to_str().unwrap(), "-m", "hemicube", "--resolution", "5"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let (f, _) = square_to_ground(&out);
    assert!(f <= 1.0 + 1e-12 && f > 0.999, "F = {f}");
}

#[test]
fn single_plane_says_when_a_receiver_reaches_past_its_plane() {
    let dir = tempfile::tempdir().unwrap();
    let g = scene(dir.path(), "ground.toml", &ground_scene(1e6));
    let out = run(&["viewfactors", g.to_str().unwrap(), "-m", "single-plane"]);
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("warning: single-plane entry square -> ground")
            && err.contains("past the projection plane"),
        "{err}"
    );
}

#[test]
fn monte_carlo_refuses_a_standard_error_from_one_sample() {
    let dir = tempfile::tempdir().unwrap();
    let g = scene(dir.path(), "ground.toml", &ground_scene(10.0));
    for method in ["mc-area", "mc-uniform", "mc-cosine"] {
        let out = run(&["viewfactors", g.to_str().unwrap(), "-m", method, "--samples", "1"]);
        assert_eq!(out.status.code(), Some(2), "{method}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("at least 2 samples"), "{method}: {err}");
        // Two samples are accepted (an estimate of F near 1 that far off may then fail the
        // range check: exit 1, not 2).
        let two = run(&["viewfactors", g.to_str().unwrap(), "-m", method, "--samples", "2"]);
        assert_ne!(two.status.code(), Some(2), "{method}: {}", String::from_utf8_lossy(&two.stderr));
    }
}
