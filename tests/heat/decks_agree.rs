//! Every conductance deck `solve --conductances` writes gives back the heat rates of the solve
//! it comes with: Q_i = σ Σ_j RADK_ij (T_i⁴ − T_j⁴) with the solved temperatures, in the CSV,
//! SINDA and ESATAN formats, per patch and per surface, closed and open. A per-surface deck
//! that cannot reproduce the solve (a subdivided heat-flux surface) is refused with exit 2
//! before any work, naming `--patches`; so is a gray deck of a semi-gray scene.
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");
const SIGMA: f64 = 5.670374419e-8;
/// The solve's own energy balance tolerance (SPEC): a deck off by less is exact.
const AGREE_TOL: f64 = 1e-9;

fn run(args: &[&str]) -> Output {
    Command::new(BIN).args(args).output().expect("run lambert")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Name → (temperature, heat_rate) from a `solve` CSV (the ambient row included).
fn solution(text: &str) -> Vec<(String, f64, f64)> {
    text.lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].to_string(), f[3].parse().unwrap(), f[5].parse().unwrap())
        })
        .collect()
}

/// The deck as RADK by ordered name pair (network decks hold each unordered pair once).
fn deck(text: &str) -> HashMap<(String, String), f64> {
    let mut g = HashMap::new();
    if let Some(body) = text.strip_prefix("from,to,radk\n") {
        for l in body.lines() {
            let f: Vec<&str> = l.split(',').collect();
            g.insert((f[0].to_string(), f[1].to_string()), f[2].parse().unwrap());
        }
        return g;
    }
    // Node map from the header comments: `C   3 = wall_y0` or `#   3 = wall_y0`.
    let mut node: HashMap<usize, String> = HashMap::new();
    for l in text.lines().filter(|l| l.starts_with("C ") || l.starts_with("# ")) {
        if let Some((k, name)) = l[2..].split_once(" = ") {
            if let Ok(k) = k.trim().parse() {
                node.insert(k, name.trim().to_string());
            }
        }
    }
    for l in text.lines() {
        let t = l.trim();
        let f: Vec<&str> = if let Some(rest) = t.strip_prefix("GR(") {
            rest.split([',', ')', '=', ';']).map(str::trim).filter(|s| !s.is_empty()).collect()
        } else if t.starts_with('-') {
            t.split(',').map(str::trim).skip(1).collect()
        } else {
            continue;
        };
        let (a, b, v): (usize, usize, f64) =
            (f[0].parse().unwrap(), f[1].parse().unwrap(), f[2].parse().unwrap());
        g.insert((node[&a].clone(), node[&b].clone()), v);
        g.insert((node[&b].clone(), node[&a].clone()), v);
    }
    g
}

/// Runs `solve` with `--conductances` in each format and checks every node's heat rate.
fn assert_decks_reproduce(dir: &Path, scene: &str, extra: &[&str]) {
    for ext in ["csv", "sin", "d"] {
        let (out, radk) = (dir.join("out.csv"), dir.join(format!("radk.{ext}")));
        let mut args =
            vec!["solve", scene, "-o", out.to_str().unwrap(), "--conductances", radk.to_str().unwrap()];
        args.extend_from_slice(extra);
        let o = run(&args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
        let sol = solution(&std::fs::read_to_string(&out).unwrap());
        let g = deck(&std::fs::read_to_string(&radk).unwrap());
        let max = sol.iter().map(|r| r.2.abs()).fold(0.0, f64::max);
        assert!(max > 0.0);
        for (i, ti, qi) in &sol {
            let q: f64 = sol
                .iter()
                .map(|(j, tj, _)| {
                    SIGMA * g.get(&(i.clone(), j.clone())).copied().unwrap_or(0.0) * (ti.powi(4) - tj.powi(4))
                })
                .sum();
            assert!(
                (q - qi).abs() <= AGREE_TOL * max,
                "{scene} {extra:?} .{ext}: {i}: deck {q} W, solve {qi} W"
            );
        }
    }
}

fn furnace() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("cases/cube_furnace/scene.toml"))
        .unwrap()
}

#[test]
fn patch_decks_reproduce_the_solve_of_a_subdivided_furnace() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("furnace.toml");
    std::fs::write(&scene, furnace()).unwrap();
    assert_decks_reproduce(dir.path(), scene.to_str().unwrap(), &["--patches"]);
}

#[test]
fn surface_decks_reproduce_the_solve_when_every_subdivided_surface_is_isothermal() {
    let dir = tempfile::tempdir().unwrap();
    // Closed: the furnace with its walls at fixed temperatures (each surface one node).
    let scene = dir.path().join("isothermal.toml");
    std::fs::write(&scene, furnace().replace("heat_flux = 0.0", "temperature = 700.0")).unwrap();
    assert_decks_reproduce(dir.path(), scene.to_str().unwrap(), &[]);
    // Open, with the ambient node: a subdivided hot floor and one adiabatic lid.
    let open = dir.path().join("open.toml");
    std::fs::write(
        &open,
        "[ambient]\ntemperature = 300.0\n\n[[surface]]\nname = \"floor\"\n\
         rectangle = { origin = [0, 0, 0], u = [1, 0, 0], v = [0, 1, 0] }\nsubdivide = [3, 3]\n\
         emissivity = 0.8\ntemperature = 1000.0\n\n[[surface]]\nname = \"lid\"\n\
         rectangle = { origin = [0, 0, 0.5], u = [0, 1, 0], v = [1, 0, 0] }\nemissivity = 0.5\nheat_flux = 0.0\n",
    )
    .unwrap();
    assert_decks_reproduce(dir.path(), open.to_str().unwrap(), &[]);
}

#[test]
fn a_surface_level_view_factor_file_gives_a_surface_deck_of_its_own_solve() {
    // With per-surface view factors the solve itself has one node per surface, so the
    // subdivided adiabatic walls are one node each there too.
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("furnace.toml");
    std::fs::write(&scene, furnace()).unwrap();
    let vf = dir.path().join("vf.csv");
    let o = run(&["viewfactors", scene.to_str().unwrap(), "-o", vf.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_decks_reproduce(dir.path(), scene.to_str().unwrap(), &["--viewfactors", vf.to_str().unwrap()]);
}

#[test]
fn a_surface_deck_of_subdivided_flux_surfaces_is_refused_naming_patches() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("furnace.toml");
    std::fs::write(&scene, furnace()).unwrap();
    let (out, radk) = (dir.path().join("out.csv"), dir.path().join("radk.sin"));
    let o = run(&[
        "solve",
        scene.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--conductances",
        radk.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    for needle in
        ["furnace.toml", "surface 'wall_y0'", "heat_flux condition over 16 patches", "3 more", "--patches"]
    {
        assert!(err.contains(needle), "missing {needle:?} in {err}");
    }
    // Refused before any work: no view factors computed, nothing written.
    assert!(!err.contains("pairs") && !out.exists() && !radk.exists(), "{err}");
}

#[test]
fn a_gray_deck_of_a_semi_gray_scene_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bands.toml");
    let text = furnace().replace("heat_flux = 0.0", "temperature = 700.0").replace(
        "emissivity = 0.8\ntemperature = 1000.0",
        "emissivity = 0.8\nemissivity_bands = [0.3, 0.8]\ntemperature = 1000.0",
    ) + "\n[[band]]\nname = \"short\"\nlower = 0.0\nupper = 4.0\n\n[[band]]\nname = \"long\"\nlower = 4.0\n";
    std::fs::write(&scene, text).unwrap();
    let radk = dir.path().join("radk.csv");
    let o = run(&[
        "solve",
        scene.to_str().unwrap(),
        "--patches",
        "-o",
        "-",
        "--conductances",
        radk.to_str().unwrap(),
    ]);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("surface 'floor' has band emissivities 0.3, 0.8") && err.contains("gray"), "{err}");
    assert!(!radk.exists());
}
