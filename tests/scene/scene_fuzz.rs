//! The loader never panics: valid scenes with random byte, token and line mutations,
//! truncations and number swaps (nan, inf, 1e308, -0, …) must load or give an input error.
//! Loaded scenes must satisfy the scene invariants. Same for mutated glTF files.
use lambert::scene::{self, toml_scene, Scene};
use lambert::Error;
use proptest::prelude::*;
use std::path::{Path, PathBuf};

/// Valid starting points: the shipped cases, a mixed scene, a scene with a glTF model.
const BASES: [&str; 4] = [
    include_str!("../../cases/cube_furnace/scene.toml"),
    include_str!("../../cases/coaxial_disks/scene.toml"),
    include_str!("../data/model_scene.toml"),
    r#"title = "mixed"
[ambient]
temperature = 250
[defaults]
emissivity = 0.4
max_patch_size = 0.5
[[surface]]
name = "l"
polygon = [[0,0,0],[2,0,0],[2,1,0],[1,1,0],[1,2,0],[0,2,0]]
subdivide = [3, 2]
temperature = 300
[[surface]]
name = "shade"
disk = { center = [0.5,0.5,0.5], normal = [0,0,1], radius = 0.2, segments = 12 }
role = "obstruction"
[[surface]]
name = "lid"
disk = { center = [0,0,3], normal = [0,0,-2], radius = 0.75, segments = 16 }
heat_flux = 0
"#,
];

/// Replacements for numbers.
const NUMBERS: [&str; 24] = [
    "nan",
    "-nan",
    "inf",
    "-inf",
    "+inf",
    "1e308",
    "-1e308",
    "-0",
    "-0.0",
    "0",
    "1e-320",
    "-1",
    "2.5",
    "99999999999999999999",
    "0x10",
    "1_000",
    "\"x\"",
    "[]",
    "{}",
    "true",
    "[1,2]",
    "1e12",
    "4096",
    "3",
];

/// Lines to insert.
const LINES: [&str; 26] = [
    "subdivide = [0, 3]",
    "subdivide = [10000, 26]",
    "subdivide = [400, 2]",
    "max_patch_size = 1e-9",
    "max_patch_size = 0.01",
    "role = \"obstruction\"",
    "role = \"x\"",
    "emissivity = nan",
    "temperature = -1",
    "heat_flux = inf",
    "[[surface]]",
    "name = \"floor\"",
    "name = \"\"",
    "polygon = [[0,0,0],[1,0,0]]",
    "polygon = [[0,0,0],[1e12,0,0],[0,1e12,0]]",
    "rectangle = { origin = [0,0,0], u = [1,0,0], v = [1e-300,1,0] }",
    "disk = { center = [0,0,0], normal = [1e-300,0,0], radius = 1e-300 }",
    "disk = { center = [0,0,0], normal = [0,0,1], radius = 1, segments = 4096 }",
    "[ambient]",
    "temperature = 300",
    "[defaults]",
    "[[model]]",
    "file = \"gltf/hierarchy.gltf\"",
    "file = \"gltf\"",
    "title = 1",
    "surface = []",
];

#[derive(Debug, Clone)]
enum Mutation {
    Byte(usize, u8),
    Truncate(usize),
    Number(usize, usize),
    Insert(usize, usize),
    Delete(usize),
    Duplicate(usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    // Weighted towards edits that keep the TOML well-formed, so validation is reached.
    prop_oneof![
        1 => (any::<usize>(), any::<u8>()).prop_map(|(p, b)| Mutation::Byte(p, b)),
        1 => any::<usize>().prop_map(Mutation::Truncate),
        6 => (any::<usize>(), 0..NUMBERS.len()).prop_map(|(k, r)| Mutation::Number(k, r)),
        3 => (any::<usize>(), 0..LINES.len()).prop_map(|(k, l)| Mutation::Insert(k, l)),
        1 => any::<usize>().prop_map(Mutation::Delete),
        1 => any::<usize>().prop_map(Mutation::Duplicate),
    ]
}

/// Byte spans of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut k = 0;
    while k < b.len() {
        let starts = b[k].is_ascii_digit() || (b[k] == b'-' && b.get(k + 1).is_some_and(u8::is_ascii_digit));
        if starts && (k == 0 || !b[k - 1].is_ascii_alphanumeric() && b[k - 1] != b'_') {
            let s = k;
            k += 1;
            while k < b.len() && (b[k].is_ascii_digit() || b"._eE+-".contains(&b[k])) {
                k += 1;
            }
            out.push((s, k));
        } else {
            k += 1;
        }
    }
    out
}

fn apply(text: &str, m: &Mutation) -> String {
    let mut bytes = text.as_bytes().to_vec();
    let lines: Vec<&str> = text.lines().collect();
    match *m {
        Mutation::Byte(p, b) if !bytes.is_empty() => {
            let n = bytes.len();
            bytes[p % n] = b;
            String::from_utf8_lossy(&bytes).into_owned()
        }
        Mutation::Truncate(p) => String::from_utf8_lossy(&bytes[..p % (bytes.len() + 1)]).into_owned(),
        Mutation::Number(k, r) => {
            let spans = numbers(text);
            if spans.is_empty() {
                return text.to_string();
            }
            let (s, e) = spans[k % spans.len()];
            format!("{}{}{}", &text[..s], NUMBERS[r], &text[e..])
        }
        Mutation::Insert(k, l) => {
            let mut v = lines.clone();
            v.insert(k % (lines.len() + 1), LINES[l]);
            v.join("\n")
        }
        Mutation::Delete(k) if !lines.is_empty() => {
            let mut v = lines.clone();
            v.remove(k % lines.len());
            v.join("\n")
        }
        Mutation::Duplicate(k) if !lines.is_empty() => {
            let mut v = lines.clone();
            let l = v[k % lines.len()];
            v.insert(k % lines.len(), l);
            v.join("\n")
        }
        _ => text.to_string(),
    }
}

/// What every loaded scene guarantees.
fn check_invariants(s: &Scene) -> Result<(), TestCaseError> {
    prop_assert!(!s.surfaces.is_empty());
    let mut names: Vec<&str> = s.surfaces.iter().map(|x| x.name.as_str()).collect();
    names.extend(s.obstructions.iter().map(|o| o.name.as_str()));
    let n = names.len();
    names.sort_unstable();
    names.dedup();
    prop_assert_eq!(names.len(), n, "unique names");
    for x in &s.surfaces {
        prop_assert!(!x.name.trim().is_empty() && !x.patches.is_empty());
        prop_assert!(x.area.is_finite() && x.area > 0.0, "{} area {}", x.name, x.area);
        prop_assert!(x.emissivity > 0.0 && x.emissivity <= 1.0);
    }
    for p in &s.patches {
        prop_assert!(p.polygon.area() > 0.0 && p.polygon.vertices().iter().all(|v| v.is_finite()));
    }
    // Either outcome is fine; it must not panic.
    let _ = s.check_boundary_conditions();
    Ok(())
}

fn base_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz.toml")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 600, rng_seed: proptest::test_runner::RngSeed::Fixed(1), ..ProptestConfig::default() })]

    #[test]
    fn mutated_toml_never_panics(base in 0..BASES.len(), ms in prop::collection::vec(mutation(), 1..5)) {
        let text = ms.iter().fold(BASES[base].to_string(), |t, m| apply(&t, m));
        match toml_scene::from_str(&base_path(), &text) {
            Ok(s) => check_invariants(&s)?,
            Err(Error::Input(e)) => {
                prop_assert!(!e.problem.is_empty());
                prop_assert!(e.file.ends_with("fuzz.toml") || e.file.extension().is_some_and(|x| x == "gltf" || x == "glb"));
            }
            Err(other) => prop_assert!(false, "not an input error: {:?}", other),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, rng_seed: proptest::test_runner::RngSeed::Fixed(2), ..ProptestConfig::default() })]

    #[test]
    fn mutated_gltf_never_panics(
        glb in any::<bool>(),
        edits in prop::collection::vec((any::<usize>(), any::<u8>()), 1..6),
        cut in prop::option::of(any::<usize>()),
    ) {
        let name = if glb { "hierarchy.glb" } else { "hierarchy.gltf" };
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf");
        let mut bytes = std::fs::read(dir.join(name)).unwrap();
        for (p, b) in edits {
            let n = bytes.len();
            bytes[p % n] = b;
        }
        if let Some(c) = cut {
            bytes.truncate(c % (bytes.len() + 1));
        }
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join(name);
        std::fs::write(&path, &bytes).unwrap();
        match scene::load(&path) {
            Ok(s) => check_invariants(&s)?,
            Err(Error::Input(e)) => prop_assert!(!e.problem.is_empty()),
            Err(other) => prop_assert!(false, "not an input error: {:?}", other),
        }
    }
}

#[test]
fn number_scanner_finds_numbers() {
    assert_eq!(numbers("a = [1, -2.5e3]\nb_2 = 7"), vec![(5, 6), (8, 14), (22, 23)]);
}
