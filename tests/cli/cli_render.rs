//! `lambert render` end to end: the PNG's size, no partial file left behind, and every error
//! path (exit 2 with the file and the problem).
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
const FURNACE: &str = "cases/cube_furnace/scene.toml";
const ROOM: &str = "cases/o3_obstructed_room/scene.toml";

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A per-patch `solve` CSV of the furnace in `dir`.
fn furnace_result(dir: &Path, patches: bool) -> PathBuf {
    let csv = dir.join(if patches { "p.csv" } else { "s.csv" });
    let mut args = vec!["solve", FURNACE, "-o", csv.to_str().unwrap()];
    if patches {
        args.push("--patches");
    }
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    csv
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let b = std::fs::read(path).unwrap();
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "not a PNG");
    assert_eq!(&b[12..16], b"IHDR");
    let be = |k: usize| u32::from_be_bytes([b[k], b[k + 1], b[k + 2], b[k + 3]]);
    (be(16), be(20))
}

#[test]
fn writes_a_png_of_the_asked_size() {
    let dir = tempfile::tempdir().unwrap();
    for patches in [true, false] {
        let csv = furnace_result(dir.path(), patches);
        let png = dir.path().join("view.png");
        let o = run(&[
            "render",
            FURNACE,
            csv.to_str().unwrap(),
            "--field",
            "heat_flux",
            "-o",
            png.to_str().unwrap(),
            "--size",
            "640x480",
            "--camera",
            "fov=40",
        ]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(png_size(&png), (640, 480));
        assert!(stderr(&o).contains("fov=40"), "{}", stderr(&o));
        let left: Vec<_> =
            std::fs::read_dir(dir.path()).unwrap().filter_map(|e| e.ok()).map(|e| e.file_name()).collect();
        assert!(left.iter().all(|n| !n.to_string_lossy().contains("partial")), "{left:?}");
    }
}

/// Runs render on `result` (with extra args) and returns stderr after asserting exit 2.
fn refused(scene: &str, result: &Path, extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("v.png");
    let mut args = vec!["render", scene, result.to_str().unwrap(), "-o", png.to_str().unwrap()];
    let extra_has_o = extra.contains(&"-o");
    if extra_has_o {
        args.truncate(3);
    }
    args.extend_from_slice(extra);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    assert!(!png.exists(), "a refused run wrote a picture");
    stderr(&o)
}

#[test]
fn option_errors() {
    let dir = tempfile::tempdir().unwrap();
    let csv = furnace_result(dir.path(), true);
    let e = refused(FURNACE, &csv, &["--field", "colour"]);
    assert!(e.contains("invalid value 'colour' for '--field") && e.contains("heat_flux, heat_rate"), "{e}");
    assert!(refused(FURNACE, &csv, &["--camera", "eye=1,2"]).contains("--camera"));
    assert!(refused(FURNACE, &csv, &["--camera", "fov=200"]).contains("fov"));
    assert!(refused(FURNACE, &csv, &["--size", "big"]).contains("--size"));
    assert!(refused(FURNACE, &csv, &["--size", "100x50"]).contains("--size 100x50"));
    assert!(refused(FURNACE, &csv, &["--range", "5,1"]).contains("--range"));
    let jpg = dir.path().join("v.jpg");
    assert!(refused(FURNACE, &csv, &["-o", jpg.to_str().unwrap()]).contains("PNG"));
}

#[test]
fn result_file_errors_name_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let good = std::fs::read_to_string(furnace_result(dir.path(), false)).unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let missing = dir.path().join("nope.csv");
    let e = refused(FURNACE, &missing, &[]);
    assert!(e.contains("nope.csv") && e.contains("cannot read"), "{e}");

    let vf = write("vf.csv", "from,to,factor\nfloor,ceiling,0.2\n");
    let e = refused(FURNACE, &vf, &[]);
    assert!(e.contains("vf.csv:1") && e.contains("no 'surface' column"), "{e}");

    let no_col = write("nocol.csv", "surface,area\nfloor,1\n");
    let e = refused(FURNACE, &no_col, &[]);
    assert!(e.contains("nocol.csv:1") && e.contains("no column 'temperature'"), "{e}");

    let unknown = write("unknown.csv", &good.replacen("wall_x0", "wall_q", 1));
    let e = refused(FURNACE, &unknown, &[]);
    assert!(e.contains("unknown.csv:") && e.contains("'wall_q' is neither a surface nor a patch"), "{e}");

    let lines: Vec<&str> = good.lines().collect();
    let short = write("short.csv", &(lines[..lines.len() - 1].join("\n") + "\n"));
    let e = refused(FURNACE, &short, &[]);
    assert!(
        e.contains("short.csv") && e.contains("no row for 'wall_x1'") && e.contains("does not match"),
        "{e}"
    );

    let twice = write("twice.csv", &(good.clone() + lines[1] + "\n"));
    let e = refused(FURNACE, &twice, &[]);
    assert!(e.contains("twice.csv:8") && e.contains("appears twice"), "{e}");

    let mut bad = lines.clone();
    let row = bad[1].replacen(",1000,", ",hot,", 1);
    bad[1] = &row;
    let e = refused(FURNACE, &write("bad.csv", &(bad.join("\n") + "\n")), &[]);
    assert!(e.contains("bad.csv:2") && e.contains("'hot'"), "{e}");

    let mixed = write("mixed.csv", &format!("{}\nfloor#0,1,1,1,1,1,1,1\n", good.trim_end()));
    let e = refused(FURNACE, &mixed, &[]);
    assert!(e.contains("mixes surface and patch rows"), "{e}");

    // The furnace's result on another scene: names do not match.
    let e = refused(ROOM, &write("furnace.csv", &good), &[]);
    assert!(e.contains("no row for") || e.contains("neither a surface"), "{e}");
}

/// Runs render with `extra` args on `scene` and `csv`, returning the decoded picture and stderr.
fn picture(scene: &str, csv: &Path, extra: &[&str]) -> (image::RgbImage, String) {
    let png = csv.with_extension(format!("{}.png", extra.len()));
    let mut args =
        vec!["render", scene, csv.to_str().unwrap(), "-o", png.to_str().unwrap(), "--size", "800x600"];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    (image::open(&png).unwrap().to_rgb8(), stderr(&o))
}

/// The 1,280-facet sphere in its room, sphere at 500 K and walls at 300 K: shaded, the
/// sphere's yellow varies in brightness from its centre to its rim; `--flat`, it is one
/// colour. The axis triad's red, green and blue are in the lower-left corner.
#[test]
fn a_sphere_is_shaded_and_flat_is_exact() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("sphere.csv");
    let mut rows = String::from("surface,temperature\n");
    for s in ["floor", "ceiling", "wall_x0", "wall_x1", "wall_y0", "wall_y1"] {
        rows.push_str(&format!("{s},300\n"));
    }
    rows.push_str("sphere,500\n");
    std::fs::write(&csv, rows).unwrap();
    let scene = "cases/o8_sphere_in_room/scene.toml";
    // Yellow-ish pixels (the top of viridis, darkened or not) left of the colour bar.
    let sphere = |img: &image::RgbImage| -> Vec<[u8; 3]> {
        img.enumerate_pixels()
            .filter(|(x, _, _)| *x < 800 - 190)
            .map(|(_, _, p)| p.0)
            .filter(|c| {
                c[0] > 40 && (c[2] as u32) * 3 < c[0] as u32 && (c[1] as u32) * 10 > (c[0] as u32) * 8
            })
            .collect()
    };
    let (img, err) = picture(scene, &csv, &[]);
    assert!(err.contains("colour range 300..500"), "{err}");
    let s = sphere(&img);
    assert!(s.len() > 5000, "sphere covers {} pixels", s.len());
    let (lo, hi) = s.iter().fold((255, 0), |(l, h), c| (l.min(c[0]), h.max(c[0])));
    assert!(hi >= 240 && (lo as f64) < 0.75 * hi as f64, "sphere red channel spans {lo}..{hi}: not shaded");
    for c in [[213u8, 40, 40], [30, 150, 30], [40, 80, 210]] {
        let n = img.enumerate_pixels().filter(|(x, y, p)| *x < 120 && *y > 480 && p.0 == c).count();
        assert!(n > 20, "triad colour {c:?}: {n} pixels");
    }
    let (flat, _) = picture(scene, &csv, &["--flat"]);
    let s = sphere(&flat);
    assert!(s.len() > 5000 && s.iter().all(|c| *c == [253, 231, 37]), "flat sphere is not one colour");
}

/// The furnace from its default eye: the ceiling is hidden, so the colour bar spans the other
/// surfaces' temperatures; `--range` overrides it. With `--two-sided` the backs of the near
/// walls and the ceiling hide every value, and the bar spans them all.
#[test]
fn colour_bar_spans_the_visible_surfaces() {
    let dir = tempfile::tempdir().unwrap();
    let csv = furnace_result(dir.path(), false);
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut rd = text.lines();
    let head: Vec<&str> = rd.next().unwrap().split(',').collect();
    let (sc, tc) = (
        head.iter().position(|h| *h == "surface").unwrap(),
        head.iter().position(|h| *h == "temperature").unwrap(),
    );
    let temps: Vec<(String, f64)> = rd
        .map(|l| l.split(',').collect::<Vec<_>>())
        .map(|f| (f[sc].to_string(), f[tc].parse().unwrap()))
        .collect();
    let shown = temps.iter().filter(|(n, _)| n != "ceiling").map(|t| t.1);
    let (lo, hi) = shown.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), t| (l.min(t), h.max(t)));
    let ceiling = temps.iter().find(|t| t.0 == "ceiling").unwrap().1;
    assert!(ceiling < lo, "the test needs the hidden ceiling coldest: {temps:?}");
    let (_, err) = picture(FURNACE, &csv, &[]);
    assert!(err.contains(&format!("colour range {lo}..{hi}")), "{err}");
    let (_, err) = picture(FURNACE, &csv, &["--two-sided"]);
    assert!(err.contains(&format!("colour range {ceiling}..{hi}")), "{err}");
    let (_, err) = picture(FURNACE, &csv, &["--range", "0,2000"]);
    assert!(err.contains("colour range 0..2000"), "{err}");
}
