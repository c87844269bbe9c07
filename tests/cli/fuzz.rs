//! A fuzz harness that stays: valid seed inputs (the shipped cases, the glTF/GLB fixtures and
//! corpus, the .vs3 files, command lines) are mutated at random and fed to the TOML, glTF/GLB
//! and .vs3 readers and to the command-line parser. Every input must give a result or a clear
//! error: no panic, no hang past [`timeout`], and, where a scene loads and is small, view
//! factors in [0, 1] with no NaN. A failing input is saved under the system temp folder
//! (`lambert-fuzz/`) and its path printed.
//!
//! Open findings: view factors above 1 from the analytic kernel on extremely elongated
//! triangles and from the mc-area estimator with few samples (validation/reliability.md). Until
//! those kernels are fixed, an out-of-range factor is printed as `open finding` and fails the
//! run only with `LAMBERT_FUZZ_STRICT_RANGE=1`; NaN and every other check always fail.
//!
//! Budget: `LAMBERT_FUZZ_CASES` inputs per target (default [`DEFAULT_CASES`], a few seconds),
//! `LAMBERT_FUZZ_SEED` picks the campaign (default 0), `LAMBERT_FUZZ_TIMEOUT_S` the per-input
//! bound, `LAMBERT_FUZZ_KEEP_GOING=1` reports every failing input instead of stopping at the
//! first. A long campaign: `LAMBERT_FUZZ_CASES=20000 LAMBERT_FUZZ_SEED=1
//! LAMBERT_FUZZ_KEEP_GOING=1 cargo test --release --test integration cli::fuzz:: -- --nocapture` (validation/reliability.md).
use lambert::scene::{self, toml_scene, Scene};
use lambert::viewfactor::{self, Level, Method, Params};
use lambert::Error;
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// Inputs per target when `LAMBERT_FUZZ_CASES` is not set: keeps CI to a few seconds.
const DEFAULT_CASES: usize = 300;
/// Per-input bound when `LAMBERT_FUZZ_TIMEOUT_S` is not set, s: every seed runs in well under
/// a second; a debug build on two shared cores gets a wide margin.
const DEFAULT_TIMEOUT_S: u64 = 60;
/// Scenes up to this many patches also get view factors (a cheap method keeps it fast).
const MAX_VF_PATCHES: usize = 300;
/// Rays per patch for the Monte Carlo check on larger loaded scenes.
const MC_SAMPLES: usize = 64;

fn env_or<T: std::str::FromStr>(key: &str, default: T) -> T {
    std::env::var(key).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

fn cases() -> usize {
    env_or("LAMBERT_FUZZ_CASES", DEFAULT_CASES)
}

fn timeout() -> Duration {
    Duration::from_secs(env_or("LAMBERT_FUZZ_TIMEOUT_S", DEFAULT_TIMEOUT_S))
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One RNG per (campaign seed, target, input): any input can be replayed alone, and campaigns
/// of different seeds draw unrelated inputs.
fn rng(target: u64, k: usize) -> Pcg64 {
    let base: u64 = Pcg64::seed_from_u64(env_or("LAMBERT_FUZZ_SEED", 0u64)).random();
    Pcg64::seed_from_u64(base ^ (target << 48) ^ k as u64)
}

/// Runs `f` on its own thread with the per-input bound; a panic or a timeout is a failure.
fn bounded<T: Send + 'static>(what: &str, f: impl FnOnce() -> T + Send + 'static) -> Result<T, String> {
    let (tx, rx) = mpsc::channel();
    let start = Instant::now();
    std::thread::spawn(move || {
        let out = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
        let _ = tx.send(out);
    });
    match rx.recv_timeout(timeout()) {
        Ok(Ok(v)) => Ok(v),
        Ok(Err(p)) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(format!("{what}: panicked: {msg}"))
        }
        Err(_) => Err(format!("{what}: no answer after {:?} (hang?)", start.elapsed())),
    }
}

/// Fails on a hard problem; prints out-of-range factors (failing on them only when strict).
fn judge(
    target: &str,
    k: usize,
    name: &str,
    bytes: &[u8],
    outcome: Result<Result<Vec<String>, String>, String>,
) {
    match outcome {
        Err(p) | Ok(Err(p)) => fail(target, k, name, bytes, &p),
        Ok(Ok(findings)) if !findings.is_empty() => {
            let first = &findings[0];
            if env_or("LAMBERT_FUZZ_STRICT_RANGE", 0u8) == 1 {
                fail(target, k, name, bytes, &format!("factor outside [0, 1]: {first}"));
            }
            let path = save(target, k, name, bytes);
            eprintln!(
                "open finding: {target} input {k} ({name}): {} factor(s) outside [0, 1], first {first}; saved to {}",
                findings.len(),
                path.display()
            );
        }
        Ok(Ok(_)) => {}
    }
}

/// Saves an input under the system temp folder; returns its path.
fn save(target: &str, k: usize, name: &str, bytes: &[u8]) -> PathBuf {
    let dir = std::env::temp_dir().join("lambert-fuzz");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("{target}-{k}-{name}"));
    let _ = std::fs::write(&path, bytes);
    path
}

/// The targets of the failing inputs so far, in `LAMBERT_FUZZ_KEEP_GOING=1` campaigns.
static FAILURES: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());

/// In a keep-going campaign, fails the target at its end if any of its inputs failed.
fn finish(target: &str) {
    let n = FAILURES.lock().unwrap_or_else(|e| e.into_inner()).iter().filter(|t| *t == target).count();
    assert_eq!(n, 0, "{target}: {n} failing input(s) in this campaign (see the `FAILURE:` lines)");
}

/// Saves a failing input and fails the test with its path (in a keep-going campaign: reports
/// it, counts it and goes on).
fn fail(target: &str, k: usize, name: &str, bytes: &[u8], problem: &str) {
    let path = save(target, k, name, bytes);
    if env_or("LAMBERT_FUZZ_KEEP_GOING", 0u8) == 1 {
        FAILURES.lock().unwrap_or_else(|e| e.into_inner()).push(target.to_string());
        eprintln!("FAILURE: {target} input {k} ({name}) failed: {problem}; saved to {}", path.display());
        return;
    }
    panic!("{target} input {k} ({name}) failed: {problem}\n  input saved to {}", path.display());
}

// ---------------------------------------------------------------- checks on what loads

/// Scene invariants, then (small scenes) view factors without NaN; factors outside [0, 1] are
/// returned as findings (see the module docs).
fn check_scene(s: &Scene) -> Result<Vec<String>, String> {
    if s.surfaces.is_empty() {
        return Err("a scene without surfaces loaded".into());
    }
    for x in &s.surfaces {
        if !(x.area.is_finite() && x.area > 0.0 && x.emissivity > 0.0 && x.emissivity <= 1.0) {
            return Err(format!("surface {} has area {} and emissivity {}", x.name, x.area, x.emissivity));
        }
    }
    if s.patches.iter().any(|p| !p.polygon.vertices().iter().all(|v| v.is_finite())) {
        return Err("a patch has a non-finite vertex".into());
    }
    let _ = s.check_boundary_conditions();
    if s.patches.len() > MAX_VF_PATCHES {
        return Ok(Vec::new());
    }
    let method = if s.patches.len() <= 60 { Method::Analytic } else { Method::McArea };
    let params = Params { method, samples: MC_SAMPLES, progress: false, ..Params::default() };
    let vf = match viewfactor::compute(s, &params, Level::Patch) {
        Ok(vf) => vf,
        // A refusal is fine (e.g. a method that cannot treat the configuration); it must say why.
        Err(e) if !e.to_string().is_empty() => return Ok(Vec::new()),
        Err(e) => return Err(format!("an empty error: {e:?}")),
    };
    let mut findings = Vec::new();
    for (i, row) in vf.rows.iter().enumerate() {
        for e in row {
            let what = format!(
                "{method:?}: F({} → {}) = {} ± {}",
                vf.names[i], vf.names[e.to as usize], e.factor, e.std_error
            );
            if !(e.factor.is_finite() && e.std_error.is_finite() && e.std_error >= 0.0) {
                return Err(what);
            }
            if !(0.0..=1.0).contains(&e.factor) {
                findings.push(what);
            }
        }
    }
    Ok(findings)
}

/// A load outcome: a scene that passes [`check_scene`], or an input error that says what.
fn check_load(r: lambert::Result<Scene>) -> Result<Vec<String>, String> {
    match r {
        Ok(s) => check_scene(&s),
        Err(Error::Input(e)) if !e.problem.is_empty() => Ok(Vec::new()),
        Err(other) => Err(format!("not an input error: {other:?}")),
    }
}

// ---------------------------------------------------------------- mutations

/// Replacement numbers: huge, tiny, negative, NaN-ish, non-integers, wrong types.
const NUMBERS: [&str; 26] = [
    "nan",
    "-nan",
    "inf",
    "-inf",
    "1e308",
    "-1e308",
    "1e309",
    "-0",
    "0",
    "1e-320",
    "-1",
    "2.5",
    "3",
    "4294967295",
    "4294967296",
    "1099511627776",
    "18446744073709551615",
    "18446744073709551616",
    "1e12",
    "65535",
    "255",
    "\"x\"",
    "[]",
    "{}",
    "null",
    "true",
];

/// Byte spans of the numbers in `text`.
fn number_spans(text: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut k = 0;
    while k < text.len() {
        let starts =
            text[k].is_ascii_digit() || (text[k] == b'-' && text.get(k + 1).is_some_and(u8::is_ascii_digit));
        if starts && (k == 0 || !text[k - 1].is_ascii_alphanumeric() && text[k - 1] != b'_') {
            let s = k;
            k += 1;
            while k < text.len() && (text[k].is_ascii_digit() || b"._eE+-".contains(&text[k])) {
                k += 1;
            }
            out.push((s, k));
        } else {
            k += 1;
        }
    }
    out
}

/// Byte-level edits: flips, insertions, deletions, duplications, truncation.
fn mutate_bytes(rng: &mut Pcg64, mut b: Vec<u8>) -> Vec<u8> {
    for _ in 0..rng.random_range(1..4) {
        let n = b.len();
        if n == 0 {
            b.push(rng.random());
            continue;
        }
        let p = rng.random_range(0..n);
        match rng.random_range(0..6) {
            0 | 1 => b[p] = rng.random(),
            2 => b[p] ^= 1 << rng.random_range(0..8),
            3 => b.insert(p, rng.random()),
            4 => {
                let e = (p + rng.random_range(1..16)).min(n);
                b.drain(p..e);
            }
            _ => b.truncate(p),
        }
    }
    b
}

/// Text edits: number swaps, line insertions from `lines`, deletions and duplications.
fn mutate_text(rng: &mut Pcg64, text: &[u8], lines: &[&str]) -> Vec<u8> {
    let mut t = text.to_vec();
    for _ in 0..rng.random_range(1..4) {
        match rng.random_range(0..10) {
            0..=4 => {
                let spans = number_spans(&t);
                if let Some(&(s, e)) = spans.choose(rng) {
                    let r = NUMBERS.choose(rng).unwrap().as_bytes();
                    t.splice(s..e, r.iter().copied());
                }
            }
            5 | 6 if !lines.is_empty() => {
                let mut v: Vec<Vec<u8>> = t.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
                let at = rng.random_range(0..=v.len());
                v.insert(at, lines.choose(rng).unwrap().as_bytes().to_vec());
                t = v.join(&b'\n');
            }
            7 | 8 => {
                let mut v: Vec<Vec<u8>> = t.split(|&c| c == b'\n').map(<[u8]>::to_vec).collect();
                let at = rng.random_range(0..v.len());
                if rng.random() {
                    v.remove(at);
                } else {
                    let l = v[at].clone();
                    v.insert(at, l);
                }
                t = v.join(&b'\n');
            }
            _ => t = mutate_bytes(rng, t),
        }
    }
    t
}

/// JSON values a glTF field may be swapped for.
fn odd_value(rng: &mut Pcg64) -> Value {
    let s: &str = [
        "-1",
        "0",
        "1",
        "2",
        "3",
        "4",
        "5",
        "6",
        "7",
        "9",
        "12",
        "13",
        "255",
        "65535",
        "5120",
        "5121",
        "5122",
        "5123",
        "5125",
        "5126",
        "4294967295",
        "4294967296",
        "1099511627776",
        "18446744073709551615",
        "1e300",
        "-1e300",
        "1.5",
        "-0.0",
        "\"VEC2\"",
        "\"VEC3\"",
        "\"SCALAR\"",
        "\"MAT4\"",
        "\"\"",
        "\"../x.bin\"",
        "\"/dev/zero\"",
        "\"file:///etc/passwd\"",
        "\"data:;base64,@@\"",
        "\"data:;base64,AAAA\"",
        "\"a%FFb\"",
        "null",
        "[]",
        "{}",
        "[0,0,0]",
        "[1,0,0,0]",
        "true",
    ]
    .choose(rng)
    .unwrap();
    serde_json::from_str(s).unwrap()
}

/// Keys a glTF object may gain.
const KEYS: [&str; 14] = [
    "byteStride",
    "byteOffset",
    "count",
    "bufferView",
    "sparse",
    "indices",
    "mode",
    "matrix",
    "children",
    "mesh",
    "componentType",
    "normalized",
    "uri",
    "extensionsRequired",
];

/// One structural edit somewhere in a glTF document.
fn mutate_json(rng: &mut Pcg64, v: &mut Value) {
    // Collect pointers to every value, pick one.
    fn paths(v: &Value, at: String, out: &mut Vec<String>) {
        out.push(at.clone());
        match v {
            Value::Object(m) => m.iter().for_each(|(k, x)| {
                paths(x, format!("{at}/{}", k.replace('~', "~0").replace('/', "~1")), out)
            }),
            Value::Array(a) => a.iter().enumerate().for_each(|(i, x)| paths(x, format!("{at}/{i}"), out)),
            _ => {}
        }
    }
    let mut all = Vec::new();
    paths(v, String::new(), &mut all);
    let at = all.choose(rng).unwrap().clone();
    let Some(target) = v.pointer_mut(&at) else { return };
    match target {
        Value::Array(a) if !a.is_empty() && rng.random_bool(0.6) => match rng.random_range(0..3) {
            0 => {
                a.pop();
            }
            1 => a.clear(),
            _ => {
                let x = a[0].clone();
                a.push(x);
            }
        },
        Value::Object(m) if rng.random_bool(0.6) => {
            if rng.random() && !m.is_empty() {
                let k = m.keys().nth(rng.random_range(0..m.len())).unwrap().clone();
                m.remove(&k);
            } else {
                m.insert(KEYS.choose(rng).unwrap().to_string(), odd_value(rng));
            }
        }
        other => *other = odd_value(rng),
    }
}

// ---------------------------------------------------------------- targets

fn files(dirs: &[&str], ext: &[&str]) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for d in dirs {
        let Ok(read) = std::fs::read_dir(root().join(d)) else { continue };
        for e in read.flatten() {
            let p = e.path();
            if p.is_dir() {
                let sub = p.strip_prefix(root()).unwrap().to_str().unwrap().to_string();
                out.extend(files(&[&sub], ext));
            } else if p.extension().and_then(|x| x.to_str()).is_some_and(|x| ext.contains(&x)) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

const TOML_LINES: [&str; 20] = [
    "subdivide = [0, 3]",
    "subdivide = [400, 2]",
    "max_patch_size = 1e-9",
    "max_patch_size = 0.2",
    "role = \"obstruction\"",
    "emissivity = 1e-10",
    "temperature = 0",
    "heat_flux = inf",
    "[[surface]]",
    "name = \"floor\"",
    "polygon = [[0,0,0],[1,0,0]]",
    "polygon = [[0,0,0],[1,0,0,7],[0,1,0]]",
    "rectangle = { origin = [0,0,0], u = [1,0,0], v = [1e-300,1,0] }",
    "disk = { center = [0,0,0], normal = [1e-300,0,0], radius = 1e-300 }",
    "[ambient]",
    "temperature = 300",
    "[defaults]",
    "[[model]]",
    "file = \"/dev/zero\"",
    "file = \"../../tests/data/gltf/grid.gltf\"",
];

#[test]
fn fuzz_toml_scenes() {
    let seeds = files(&["cases", "tests/data"], &["toml"]);
    assert!(seeds.len() >= 30, "{} seeds", seeds.len());
    for k in 0..cases() {
        let mut r = rng(1, k);
        let seed = seeds.choose(&mut r).unwrap().clone();
        let text = mutate_text(&mut r, &std::fs::read(&seed).unwrap(), &TOML_LINES);
        let path = seed.clone();
        let input = String::from_utf8_lossy(&text).into_owned();
        let outcome = bounded("toml", move || check_load(toml_scene::from_str(&path, &input)));
        judge("toml", k, seed.file_name().unwrap().to_str().unwrap(), &text, outcome);
    }
    finish("toml");
}

/// GLB: JSON chunk and BIN chunk.
fn glb_split(b: &[u8]) -> Option<(Vec<u8>, Vec<u8>)> {
    let word = |k: usize| u32::from_le_bytes(b[k..k + 4].try_into().unwrap()) as usize;
    let jl = word(12);
    let json = b.get(20..20 + jl)?.to_vec();
    let bin = b.get(20 + jl + 8..).map(<[u8]>::to_vec).unwrap_or_default();
    Some((json, bin))
}

fn glb_join(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let mut js = json.to_vec();
    js.resize(js.len().div_ceil(4) * 4, b' ');
    let mut bn = bin.to_vec();
    bn.resize(bn.len().div_ceil(4) * 4, 0);
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((28 + js.len() + bn.len()) as u32).to_le_bytes());
    out.extend((js.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&js);
    out.extend((bn.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&bn);
    out
}

#[test]
fn fuzz_gltf_and_glb() {
    let seeds = files(&["tests/data/gltf", "cases"], &["gltf", "glb"]);
    assert!(seeds.len() >= 60, "{} seeds", seeds.len());
    for k in 0..cases() {
        let mut r = rng(2, k);
        let seed = seeds.choose(&mut r).unwrap().clone();
        let bytes = std::fs::read(&seed).unwrap();
        let glb = bytes.starts_with(b"glTF");
        let json_edit = r.random_bool(0.7);
        let out = match (glb, json_edit) {
            (false, true) => match serde_json::from_slice::<Value>(&bytes) {
                Ok(mut v) => {
                    for _ in 0..r.random_range(1..4) {
                        mutate_json(&mut r, &mut v);
                    }
                    serde_json::to_vec(&v).unwrap()
                }
                Err(_) => mutate_bytes(&mut r, bytes),
            },
            (true, true) => match glb_split(&bytes)
                .and_then(|(j, b)| Some((serde_json::from_slice::<Value>(&j).ok()?, b)))
            {
                Some((mut v, bin)) => {
                    mutate_json(&mut r, &mut v);
                    let bin = if r.random_bool(0.3) { mutate_bytes(&mut r, bin) } else { bin };
                    glb_join(&serde_json::to_vec(&v).unwrap(), &bin)
                }
                None => mutate_bytes(&mut r, bytes),
            },
            (_, false) => mutate_text(&mut r, &bytes, &[]),
        };
        // The mutated file sits beside copies of the seed's .bin files (external buffers).
        let dir = tempfile::tempdir().unwrap();
        for bin in files(&[seed.parent().unwrap().strip_prefix(root()).unwrap().to_str().unwrap()], &["bin"])
        {
            std::fs::copy(&bin, dir.path().join(bin.file_name().unwrap())).unwrap();
        }
        let path = dir.path().join(seed.file_name().unwrap());
        std::fs::write(&path, &out).unwrap();
        let outcome = bounded("gltf", move || check_load(scene::load(&path)));
        judge("gltf", k, seed.file_name().unwrap().to_str().unwrap(), &out, outcome);
    }
    finish("gltf");
}

const VS3_LINES: [&str; 12] = [
    "C encl=1 list=0 eps=1e-4 maxu=8 maxo=8 mino=0 emit=0",
    "C encl=0 eps=0",
    "F 3",
    "V 1 0 0 0",
    "V 99 1e308 0 0",
    "S 1 1 2 3 4 0 0 0 s1",
    "S 9 1 1 1 1 0 0 0 bad",
    "O 0 0 1 0 0 0 0 0 obst",
    "M 1 2 3 4 5",
    "E 0.5",
    "T title",
    "End of Data",
];

#[test]
fn fuzz_vs3_files() {
    let seeds = files(&["tests/data/vs3", "cases"], &["vs3"]);
    assert!(seeds.len() >= 5, "{} seeds", seeds.len());
    for k in 0..cases() {
        let mut r = rng(3, k);
        let seed = seeds.choose(&mut r).unwrap().clone();
        let text = mutate_text(&mut r, &std::fs::read(&seed).unwrap(), &VS3_LINES);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(seed.file_name().unwrap());
        std::fs::write(&path, &text).unwrap();
        let outcome = bounded("vs3", move || check_load(scene::load(&path)));
        judge("vs3", k, seed.file_name().unwrap().to_str().unwrap(), &text, outcome);
    }
    finish("vs3");
}

/// Option values for the command line: valid, out of range and malformed.
fn cli_options(rng: &mut Pcg64, dir: &Path) -> Vec<String> {
    let d = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let choices: Vec<(&str, Vec<String>)> = vec![
        (
            "--method",
            ["auto", "analytic", "hemicube", "single-plane", "mc-area", "mc-uniform", "mc-cosine", "x", ""]
                .map(String::from)
                .to_vec(),
        ),
        ("--samples", ["0", "1", "16", "-1", "x", "99999999999999999999999"].map(String::from).to_vec()),
        ("--resolution", ["0", "1", "2", "8", "16385", "-4", "nan"].map(String::from).to_vec()),
        ("--tolerance", ["0", "1", "1e-3", "nan", "inf", "-1", "1e-300", "0.5"].map(String::from).to_vec()),
        (
            "--seed",
            ["0", "1", "-1", "18446744073709551615", "18446744073709551616"].map(String::from).to_vec(),
        ),
        ("--threads", ["0", "1", "2", "-1", "x"].map(String::from).to_vec()),
        ("--enforce", ["none", "reciprocity", "closure", "x", ""].map(String::from).to_vec()),
        ("--patches", vec![]),
        ("-q", vec![]),
        ("--allow-outside-paths", vec![]),
        ("-o", vec!["-".into(), d("out.csv"), d("missing/out.csv"), dir.to_str().unwrap().into()]),
        ("--vtk", vec![d("v.vtu"), d("v.vtp"), d("v.txt")]),
        ("--viewfactors", vec![d("vf.csv"), d("garbage.csv"), d("absent.csv")]),
        ("--conductances", vec![d("c.csv"), d("c.sinda"), d("c.txt")]),
        ("--format", ["csv", "sinda", "esatan", "x"].map(String::from).to_vec()),
        ("--solver", ["direct", "jacobi", "gauss-seidel", "x"].map(String::from).to_vec()),
        ("--exchange", ["auto", "dense", "hierarchical", "x"].map(String::from).to_vec()),
        ("--field", ["temperature", "heat_flux", "area", "x"].map(String::from).to_vec()),
        ("--size", ["100x80", "0x0", "99999x99999", "x", "-5x3"].map(String::from).to_vec()),
        ("--range", ["0,1", "1,0", "nan,1", "x"].map(String::from).to_vec()),
        (
            "--camera",
            ["eye=5,5,5 target=0,0,0", "fov=0", "eye=0,0,0 target=0,0,0", "x=1"].map(String::from).to_vec(),
        ),
        ("--two-sided", vec![]),
        ("--bogus", vec![]),
    ];
    let mut args = Vec::new();
    for _ in 0..rng.random_range(0..6) {
        let (flag, values) = choices.choose(rng).unwrap();
        args.push(flag.to_string());
        if let Some(v) = values.choose(rng) {
            args.push(v.clone());
        }
    }
    args
}

/// Runs the binary with a deadline; (exit code, stdout, stderr), or a hang report.
fn run_bounded(args: &[String]) -> Result<(Option<i32>, String, String), String> {
    use std::process::{Command, Stdio};
    let mut child = Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(args)
        .env_remove("LAMBERT_PANIC_SELF_TEST")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| e.to_string())?;
    // Readers on threads so a full pipe never stalls the child.
    let mut so = child.stdout.take().unwrap();
    let mut se = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut so, &mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut se, &mut s);
        s
    });
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            return Ok((status.code(), out.join().unwrap(), err.join().unwrap()));
        }
        if start.elapsed() > timeout() {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("no exit after {:?} (hang?)", timeout()));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn fuzz_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("pair.toml");
    std::fs::write(
        &scene,
        "[ambient]\ntemperature = 300\n[[surface]]\nname = \"a\"\nrectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\n\
         temperature = 400\nsubdivide = [2, 2]\n[[surface]]\nname = \"b\"\nrectangle = { origin = [0,0,1], u = [0,1,0], v = [1,0,0] }\n\
         heat_flux = 0\n",
    )
    .unwrap();
    let s = scene.to_str().unwrap().to_string();
    let (code, vf, err) = run_bounded(&["viewfactors".into(), s.clone(), "-q".into()]).unwrap();
    assert_eq!(code, Some(0), "{err}");
    std::fs::write(dir.path().join("vf.csv"), vf).unwrap();
    std::fs::write(dir.path().join("garbage.csv"), "from,to,factor\na,b,2\nnan,,\n").unwrap();
    let (code, sol, err) = run_bounded(&["solve".into(), s.clone(), "-q".into()]).unwrap();
    assert_eq!(code, Some(0), "{err}");
    std::fs::write(dir.path().join("sol.csv"), sol).unwrap();
    let gltf = root().join("tests/data/gltf/grid.gltf").to_str().unwrap().to_string();
    for k in 0..cases() {
        let mut r = rng(4, k);
        let sub = ["viewfactors", "solve", "render", "bogus", ""].choose(&mut r).unwrap().to_string();
        let mut args = vec![sub.clone()];
        match r.random_range(0..6) {
            0 => args.push(gltf.clone()),
            1 => args.push(dir.path().join("absent.toml").to_str().unwrap().into()),
            2 => {}
            _ => args.push(s.clone()),
        }
        if sub == "render" {
            args.push(dir.path().join("sol.csv").to_str().unwrap().into());
            args.extend(["-o".into(), dir.path().join("pic.png").to_str().unwrap().into()]);
        }
        let mut opts = cli_options(&mut r, dir.path());
        // Flags may come before the positional arguments too.
        if r.random_bool(0.3) {
            opts.append(&mut args.split_off(1));
        }
        args.extend(opts);
        let line = args.join(" ");
        let outcome = run_bounded(&args).and_then(|(code, out, err)| {
            if !matches!(code, Some(0..=2)) || err.contains("panicked") || err.contains("internal error") {
                return Err(format!("exit {code:?}: {err}"));
            }
            if code == Some(0) && out.starts_with("from,to,factor") {
                for row in out.lines().skip(1) {
                    let f: f64 = row.split(',').nth(2).and_then(|x| x.parse().ok()).unwrap_or(f64::NAN);
                    if !(0.0..=1.0).contains(&f) {
                        return Err(format!("factor row '{row}'"));
                    }
                }
            }
            if out.to_ascii_lowercase().contains("nan") {
                return Err(format!("NaN in the output: {out}"));
            }
            Ok(())
        });
        if let Err(p) = outcome {
            fail("cli", k, "args.txt", line.as_bytes(), &p);
        }
    }
    finish("cli");
}

// ---------------------------------------------------------------- open findings

/// Factors of `scene` at patch level by `method`, all in [0, 1].
fn assert_in_range(path: &Path, method: Method, samples: usize) {
    let s = scene::load(path).unwrap_or_else(|e| panic!("{e}"));
    let params = Params { method, samples, progress: false, ..Params::default() };
    let vf = viewfactor::compute(&s, &params, Level::Patch).unwrap();
    for (i, row) in vf.rows.iter().enumerate() {
        for e in row {
            assert!(
                (0.0..=1.0).contains(&e.factor),
                "F({} → {}) = {}",
                vf.names[i],
                vf.names[e.to as usize],
                e.factor
            );
        }
    }
}

fn finding(name: &str) -> PathBuf {
    root().join("tests/data/fuzz_findings").join(name)
}

/// A unit square under a 1 m wide strip at gap 0.5: F(square → strip) is 0.5166436… for any
/// length past 1e4 m (the rest of the strip adds < 1e-12), but the analytic kernel's round-off
/// grows with the length: 2e-7 off at 1e5 m, 1e-6 at 1e6 m, 8e-4 at 1e7 m, 13 % at 1e8 m and
/// 22 (not a fraction) at 1e9 m, each with standard error 0 from the default method, where
/// the README promises analytic factors to 1e-9·F.
#[test]
fn former_finding_analytic_round_off_on_long_strips() {
    let dir = tempfile::tempdir().unwrap();
    let f = |length: f64| {
        let path = dir.path().join("strip.toml");
        let text = format!(
            "[[surface]]\nname = \"square\"\nrectangle = {{ origin = [0,0,0], u = [1,0,0], v = [0,1,0] }}\n\
             [[surface]]\nname = \"strip\"\nrectangle = {{ origin = [0,0,0.5], u = [0,{length:e},0], v = [1,0,0] }}\n"
        );
        std::fs::write(&path, text).unwrap();
        let s = scene::load(&path).unwrap();
        let params = Params { progress: false, ..Params::default() };
        viewfactor::compute(&s, &params, Level::Surface).unwrap().get(0, 1)
    };
    let reference = f(1e4);
    for length in [1e5, 1e6, 1e7, 1e8, 1e9] {
        let got = f(length);
        assert!((got - reference).abs() <= 1e-9 * reference, "length {length:e}: F = {got}, not {reference}");
    }
}

/// Two .vs3 inputs of the campaigns (a vertex moved to z ≈ 4.3e9 makes a 1 × 4.3e9 m
/// triangle): the default method gives F = 4.0 and 8.2 (analytic contour integral, round-off).
#[test]
fn former_finding_analytic_factors_above_one_on_elongated_triangles() {
    for f in ["elongated_triangle.vs3", "elongated_triangle_blocked.vs3"] {
        assert_in_range(&finding(f), Method::Auto, MC_SAMPLES);
    }
}

/// The shipped V19 case with 64 rays per patch: mc-area estimates F = 1.145 ± 1.145 for a
/// pair of neighbouring facets (the point-to-area kernel is unbounded).
#[test]
#[ignore = "open finding: mc-area estimates above 1 with few samples"]
fn open_finding_mc_area_estimates_above_one() {
    assert_in_range(&root().join("cases/v19_coaxial_cylinders/scene.toml"), Method::McArea, MC_SAMPLES);
}

/// A .vs3 input of the campaigns: the shadow integration's shaded part comes out negative
/// (−8e-27 against an unobstructed 3.3e-38), tripping the debug assertion in
/// src/viewfactor/shadow/pair.rs (release builds return 8e-27).
#[test]
fn former_finding_shadow_debug_assertion() {
    assert_in_range(&finding("shadow_assert.vs3"), Method::Analytic, MC_SAMPLES);
}

/// A .vs3 input of the campaigns (the L-shaped room with a wall's rotation angle changed from
/// 270 to −1 and a vertex line duplicated): `-m analytic` at patch level stalled at 57 of 66
/// pairs for more than 90 s in a release build. Nine pairs' error estimates stop falling
/// (cells at the depth limit along the broken triangle); the integration now stops when its
/// error stops falling, and the run ends with those entries named in a warning.
#[test]
fn former_finding_analytic_stalls_on_a_mis_rotated_wall() {
    let path = finding("rotated_wall_stall.vs3");
    let outcome = bounded("rotated_wall_stall", move || {
        let s = scene::load(&path).unwrap();
        let params = Params { method: Method::Analytic, progress: false, ..Params::default() };
        viewfactor::compute(&s, &params, Level::Patch).map(|vf| vf.warnings).map_err(|e| e.to_string())
    });
    let warnings = outcome.expect("finishes within the bound").expect("computes");
    assert!(
        warnings
            .iter()
            .any(|w| w.contains("ended with an error estimate above its goal") && w.contains("worst: F(")),
        "the entries that stopped short are counted and the worst is named: {warnings:?}"
    );
}

/// A .vs3 input of the campaigns (one vertex moved to y ≈ 4.3e9 in the L-shaped room with
/// obstructions): `-m analytic` at patch level takes 132 s in a release build (then refuses the
/// scene as leaking, as the default method does in 0.07 s), past the harness's 60 s bound.
#[test]
fn former_finding_analytic_shadow_runs_long_on_extreme_geometry() {
    let path = finding("slow_shadow.vs3");
    let outcome = bounded("slow_shadow", move || {
        let s = scene::load(&path).unwrap();
        let params = Params { method: Method::Analytic, progress: false, ..Params::default() };
        viewfactor::compute(&s, &params, Level::Patch).map(|_| ()).map_err(|e| e.to_string())
    });
    assert!(outcome.is_ok(), "{outcome:?}");
}
