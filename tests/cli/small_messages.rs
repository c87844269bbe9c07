//! The smaller wrong messages of issue 19, through the real binary: vectors with the wrong
//! number of components are exit 2; a given temperature anchors an enclosure whatever its
//! emissivity; an isothermal enclosure's round-off is no energy-balance warning; ambient rows
//! carry no `-0` and no empty method.
use std::path::Path;
use std::process::Command;

fn run(dir: &Path, scene: &str, args: &[&str]) -> (Option<i32>, String, String) {
    let p = dir.join("scene.toml");
    std::fs::write(&p, scene).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(args.iter().take(1))
        .arg(&p)
        .args(args.iter().skip(1))
        .output()
        .expect("run lambert");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    )
}

#[test]
fn vectors_need_exactly_three_components() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("rectangle = { origin = [0,0,0], u = [1,0,0,5], v = [0,1,0] }", "invalid length 4"),
        ("rectangle = { origin = [0,0,0,0,0], u = [1,0,0], v = [0,1,0] }", "invalid length 5"),
        ("polygon = [[0,0,0],[1,0,0,1],[0,1,0]]", "invalid length 4"),
        ("polygon = [[0,0,0],[1,0],[0,1,0]]", "invalid length 2"),
        ("disk = { center = [0,0,0,1], normal = [0,0,1], radius = 1 }", "invalid length 4"),
        ("disk = { center = [0,0,0], normal = [0,0,1,0,0], radius = 1 }", "invalid length 5"),
    ];
    for (shape, needle) in cases {
        let (code, err, out) =
            run(dir.path(), &format!("[[surface]]\nname = \"s\"\n{shape}\n"), &["viewfactors"]);
        assert_eq!(code, Some(2), "{shape}: {err}");
        assert!(err.contains("scene.toml:3: surface 's': ") && err.contains(needle), "{shape}: {err}");
        assert!(err.contains("expected 3 numbers [x, y, z]") && out.is_empty(), "{shape}: {err}");
    }
}

/// A closed unit cube: floor at 1000 K, ceiling at 400 K, four walls at `walls`; every
/// surface has emissivity `eps`.
fn cube(eps: &str, walls: &str) -> String {
    let faces = [
        ("floor", "[0,0,0]", "[1,0,0]", "[0,1,0]", "temperature = 1000"),
        ("ceiling", "[0,0,1]", "[0,1,0]", "[1,0,0]", "temperature = 400"),
        ("wall_y0", "[0,0,0]", "[0,0,1]", "[1,0,0]", walls),
        ("wall_y1", "[0,1,0]", "[1,0,0]", "[0,0,1]", walls),
        ("wall_x0", "[0,0,0]", "[0,1,0]", "[0,0,1]", walls),
        ("wall_x1", "[1,0,0]", "[0,0,1]", "[0,1,0]", walls),
    ];
    let mut s = format!("[defaults]\nemissivity = {eps}\n");
    for (name, o, u, v, bc) in faces {
        s += &format!(
            "[[surface]]\nname = \"{name}\"\nrectangle = {{ origin = {o}, u = {u}, v = {v} }}\n{bc}\n"
        );
    }
    s
}

fn heat_rate(csv: &str, name: &str) -> f64 {
    let row = csv.lines().find(|l| l.starts_with(&format!("{name},"))).unwrap_or_else(|| panic!("{csv}"));
    row.split(',').nth(5).unwrap().parse().unwrap()
}

#[test]
fn given_temperatures_anchor_whatever_the_emissivity() {
    let dir = tempfile::tempdir().unwrap();
    let solve = ["solve", "-m", "analytic"];
    let (code, err, hot) = run(dir.path(), &cube("1e-10", "heat_flux = 0"), &solve);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("anchor") && !err.contains("not conserved"), "{err}");
    let (code, err, warm) = run(dir.path(), &cube("1e-9", "heat_flux = 0"), &solve);
    assert_eq!(code, Some(0), "{err}");
    // For ε → 0 the net exchange is proportional to ε (to first order, O(ε) relative).
    let (q10, q9) = (heat_rate(&hot, "floor"), heat_rate(&warm, "floor"));
    assert!(q10 > 0.0 && (q10 / q9 - 0.1).abs() < 1e-6, "{q10} vs {q9}");
    assert!((heat_rate(&hot, "ceiling") + q10).abs() <= 1e-6 * q10, "{hot}");
    // Without any given temperature the enclosure is still refused, at any emissivity.
    let all_flux = cube("1e-10", "heat_flux = 0").replace("temperature = 1000", "heat_flux = 5");
    let all_flux = all_flux.replace("temperature = 400", "heat_flux = -5");
    let (code, err, _) = run(dir.path(), &all_flux, &solve);
    assert_eq!(code, Some(2), "{err}");
    assert!(err.contains("no temperature anchor"), "{err}");
}

#[test]
fn an_isothermal_enclosure_is_no_balance_warning() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err, out) = run(
        dir.path(),
        &cube("0.5", "temperature = 700").replace("= 1000", "= 700").replace("= 400", "= 700"),
        &["solve"],
    );
    assert_eq!(code, Some(0), "{err}");
    let line = err.lines().find(|l| l.contains("energy balance")).expect("balance line");
    assert!(!line.contains("WARNING"), "{line}");
    assert!(line.contains("W exchanged"), "{line}");
    for name in ["floor", "ceiling", "wall_x0"] {
        assert!(heat_rate(&out, name).abs() < 1e-9, "{out}");
    }
}

#[test]
fn ambient_rows_have_no_negative_zero_and_a_method() {
    let dir = tempfile::tempdir().unwrap();
    // Two coplanar squares side by side see nothing but the ambient.
    let scene = "[ambient]\ntemperature = 300\n\
        [[surface]]\nname = \"a\"\nrectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\ntemperature = 300\n\
        [[surface]]\nname = \"b\"\nrectangle = { origin = [2,0,0], u = [1,0,0], v = [0,1,0] }\ntemperature = 300\n";
    let (code, err, vf) = run(dir.path(), scene, &["viewfactors"]);
    assert_eq!(code, Some(0), "{err}");
    // The first five columns (the sixth carries the scene's geometry fingerprint).
    let first_five: Vec<String> =
        vf.lines().map(|l| l.split(',').take(5).collect::<Vec<_>>().join(",")).collect();
    assert_eq!(first_five, ["from,to,factor,std_error,method", "a,ambient,1,0,none", "b,ambient,1,0,none"]);
    let (code, err, sol) = run(dir.path(), scene, &["solve"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!sol.contains("-0,") && !sol.contains(",-0\n") && !err.contains("= -0 W"), "{sol}\n{err}");
    assert!(sol.ends_with("ambient,,1,300,,0,459.300327939,\n"), "{sol}");
}
