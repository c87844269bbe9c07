//! The malformed glTF corpus (tests/data/gltf/malformed, written by
//! tests/data/make_malformed_gltf.py) through the real binary: each file breaks one glTF 2.0
//! rule and must end with exit 2 and one error line naming the file, the node/mesh/accessor
//! and the rule, never a panic. Also: buffer paths outside the folder with and without
//! `--allow-outside-paths`, sparse accessors, and the one-line internal-error report.
use lambert::scene;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf").join(name)
}

fn lambert(args: &[&std::ffi::OsStr], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_lambert"));
    c.args(args).env_remove("RUST_BACKTRACE").env_remove("LAMBERT_BACKTRACE");
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run lambert")
}

fn viewfactors(scene: &Path, extra: &[&str]) -> (Option<i32>, String, String) {
    let mut args: Vec<&std::ffi::OsStr> = vec!["viewfactors".as_ref(), scene.as_os_str()];
    args.extend(["-m", "mc-area", "--samples", "8", "-q"].iter().map(std::ffi::OsStr::new));
    args.extend(extra.iter().map(std::ffi::OsStr::new));
    let o = lambert(&args, &[]);
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    )
}

/// (file, what the one error line must contain besides the file name). `SURFACE` marks errors
/// inside the surface's mesh, which must also name the surface, the mesh and the node.
const CORPUS: [(&str, &[&str]); 48] = [
    ("attribute_counts_differ.gltf", &[SURFACE, "NORMAL accessor 2", "`count` is 8 but POSITION has 9"]),
    (
        "buffer_shorter_than_declared.gltf",
        &[SURFACE, "buffer 0", "156 bytes, fewer than its `byteLength` 400"],
    ),
    ("byte_indices.gltf", &[SURFACE, "indices accessor 1", "SCALAR of BYTE (5120)", "UNSIGNED_BYTE"]),
    ("child_out_of_range.gltf", &["node 0", "`children[0]` is 4, but the file has 1 nodes"]),
    (
        "count_float.gltf",
        &[SURFACE, "POSITION accessor 0", "`count` must be a non-negative integer, got 9.5"],
    ),
    (
        "count_huge.gltf",
        &[SURFACE, "POSITION accessor 0", "but buffer view 0 has 108", "inside their buffer views"],
    ),
    ("count_negative.gltf", &[SURFACE, "POSITION accessor 0", "got -9"]),
    ("count_zero.gltf", &[SURFACE, "POSITION accessor 0", "`count` is 0; glTF requires at least 1"]),
    ("float_indices.gltf", &[SURFACE, "indices accessor 1", "SCALAR of FLOAT (5126)"]),
    ("glb_bin_short.glb", &[SURFACE, "buffer 0", "100 bytes, fewer than its `byteLength` 156"]),
    ("glb_no_bin.glb", &[SURFACE, "buffer 0", "no BIN chunk"]),
    ("index_past_vertices.gltf", &[SURFACE, "indices accessor 1", "index 99 is past the 9 vertices"]),
    ("indices_accessor_out_of_range.gltf", &[SURFACE, "`indices` is 5, but the file has 2 accessors"]),
    ("indices_past_view.gltf", &[SURFACE, "indices accessor 1", "need 60 bytes but buffer view 1 has 48"]),
    ("matrix_and_trs.gltf", &["node 0", "both `matrix` and translation/rotation/scale"]),
    ("mesh_without_primitives.gltf", &["surface 'Grid'", "(mesh 0, node 0)", "no primitives"]),
    ("mode_9.gltf", &[SURFACE, "`mode` 9 is not a glTF primitive mode"]),
    ("name_not_string.gltf", &["node 0, mesh 0", "`name` must be a string, got 7"]),
    ("no_accessors.gltf", &[SURFACE, "POSITION accessor is 0, but the file has 0 accessors"]),
    ("offset_misaligned.gltf", &[SURFACE, "POSITION accessor 0", "`byteOffset` 2 is not a multiple of 4"]),
    (
        "position_accessor_out_of_range.gltf",
        &[SURFACE, "POSITION accessor is 7, but the file has 2 accessors"],
    ),
    (
        "position_mat4.gltf",
        &[SURFACE, "POSITION accessor 0", "POSITION is MAT4 of FLOAT", "requires VEC3 of FLOAT"],
    ),
    ("position_ushort.gltf", &[SURFACE, "POSITION accessor 0", "POSITION is VEC3 of UNSIGNED_SHORT"]),
    ("position_vec2.gltf", &[SURFACE, "POSITION accessor 0", "POSITION is VEC2 of FLOAT"]),
    ("required_extension.gltf", &["requires the glTF extension \"KHR_draco_mesh_compression\""]),
    (
        "restart_index.gltf",
        &[SURFACE, "indices accessor 1", "index 65535 (entry 23) is the primitive-restart value"],
    ),
    ("scene_node_out_of_range.gltf", &["scene 0", "`nodes[0]` is 1099511627776, but the file has 1 nodes"]),
    ("signed_indices.gltf", &[SURFACE, "indices accessor 1", "SCALAR of SHORT (5122)"]),
    (
        "sparse_index_past_count.gltf",
        &[SURFACE, "POSITION accessor 0", "sparse index 0 is 65536", "below the count 9"],
    ),
    (
        "stride_below_element.gltf",
        &[SURFACE, "POSITION accessor 0", "`byteStride` 8, less than the 12-byte element"],
    ),
    ("stride_not_multiple_of_4.gltf", &[SURFACE, "buffer view 0: `byteStride` is 13"]),
    ("stride_on_indices.gltf", &[SURFACE, "indices accessor 1", "buffer view 1 has a `byteStride`"]),
    ("triangles_not_in_threes.gltf", &[SURFACE, "22 vertex indices, not a multiple of 3"]),
    ("unknown_component_type.gltf", &[SURFACE, "POSITION accessor 0", "`componentType` 5124"]),
    ("unknown_type.gltf", &[SURFACE, "POSITION accessor 0", "`type` \"VEC5\""]),
    ("uri_bad_percent.gltf", &[SURFACE, "buffer 0", "not UTF-8"]),
    (
        "uri_dev_urandom.gltf",
        &[SURFACE, "buffer 0", "'/dev/urandom' is an absolute path", "--allow-outside-paths"],
    ),
    ("uri_dev_zero.gltf", &[SURFACE, "buffer 0", "'/dev/zero' is an absolute path"]),
    (
        "uri_dotdot_hostname.gltf",
        &[SURFACE, "buffer 0", "'../../../../etc/hostname'", "leaves the glTF file's folder"],
    ),
    ("uri_etc_passwd.gltf", &[SURFACE, "buffer 0", "'/etc/passwd' is an absolute path"]),
    ("uri_file_scheme.gltf", &[SURFACE, "buffer 0", "'file:///etc/passwd' is a file: URI"]),
    ("uri_http.gltf", &[SURFACE, "buffer 0", "scheme 'http:'"]),
    ("uri_missing.gltf", &[SURFACE, "buffer 0", "cannot open the buffer file", "missing.bin"]),
    ("vec2_indices.gltf", &[SURFACE, "indices accessor 1", "VEC2 of UNSIGNED_SHORT"]),
    ("version_1.gltf", &["unsupported glTF version \"1.0\""]),
    (
        "view_index_2_40.gltf",
        &[SURFACE, "POSITION accessor 0", "`bufferView` is 1099511627776, but the file has 2"],
    ),
    (
        "view_offset_2_64.gltf",
        &[SURFACE, "indices accessor 1", "buffer view 1 spans bytes 18446744073709551615.."],
    ),
    ("view_past_buffer.gltf", &[SURFACE, "buffer view 1 spans bytes 108..508 of buffer 0, which has 156"]),
];

/// Stands for "surface 'Grid'", "primitive 0" and "(mesh 0, node 0)" in [`CORPUS`].
const SURFACE: &str = "<surface>";

#[test]
fn every_malformed_file_is_one_clear_error_line() {
    let dir = data("malformed");
    let mut files: Vec<String> =
        std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    files.sort();
    let listed: Vec<&str> = CORPUS.iter().map(|(f, _)| *f).collect();
    assert_eq!(files, listed, "every corpus file has an expectation, in order");
    for (file, needles) in CORPUS {
        let (code, stderr, stdout) = viewfactors(&dir.join(file), &[]);
        assert_eq!(code, Some(2), "{file}: {stderr}");
        assert!(stdout.is_empty(), "{file}: {stdout}");
        assert_eq!(stderr.lines().count(), 1, "{file}: one line: {stderr}");
        assert!(stderr.starts_with("lambert: error: ") && stderr.contains(file), "{file}: {stderr}");
        assert!(!stderr.contains("panicked") && !stderr.contains("internal error"), "{file}: {stderr}");
        for n in needles.iter() {
            if *n == SURFACE {
                for part in [": surface 'Grid': ", "primitive 0", "(mesh 0, node 0)"] {
                    assert!(stderr.contains(part), "{file}: {part:?} missing: {stderr}");
                }
            } else {
                assert!(stderr.contains(n), "{file}: {n:?} missing: {stderr}");
            }
        }
    }
}

#[test]
fn allow_outside_paths_reads_outside_files_but_never_devices() {
    let dir = tempfile::tempdir().unwrap();
    let sub = dir.path().join("models");
    std::fs::create_dir(&sub).unwrap();
    let mut doc: serde_json::Value =
        serde_json::from_slice(&std::fs::read(data("grid.gltf")).unwrap()).unwrap();
    let uri = doc["buffers"][0]["uri"].as_str().unwrap().to_string();
    use base64::Engine;
    let bytes = base64::engine::general_purpose::STANDARD.decode(uri.split_once(',').unwrap().1).unwrap();
    std::fs::write(dir.path().join("grid.bin"), &bytes).unwrap();
    doc["buffers"][0]["uri"] = "../grid.bin".into();
    let outside = sub.join("outside.gltf");
    std::fs::write(&outside, doc.to_string()).unwrap();
    let (code, stderr, _) = viewfactors(&outside, &[]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("'../grid.bin'") && stderr.contains("--allow-outside-paths"), "{stderr}");
    let (code, stderr, allowed) = viewfactors(&outside, &["--allow-outside-paths"]);
    assert_eq!(code, Some(0), "{stderr}");
    let (_, _, embedded) = viewfactors(&data("grid.gltf"), &[]);
    assert_eq!(allowed, embedded, "the outside file holds the same bytes as the embedded buffer");
    // The flag never opens a device, and a file: URI stays refused.
    for (uri, needle) in [("/dev/zero", "not a regular file"), ("file:///dev/zero", "file: URI")] {
        doc["buffers"][0]["uri"] = uri.into();
        std::fs::write(&outside, doc.to_string()).unwrap();
        let (code, stderr, _) = viewfactors(&outside, &["--allow-outside-paths"]);
        assert_eq!(code, Some(2), "{stderr}");
        assert!(stderr.contains(needle), "{uri}: {stderr}");
    }
    // The same rules for a model of a TOML scene, resolved beside the model file.
    doc["buffers"][0]["uri"] = "../grid.bin".into();
    std::fs::write(&outside, doc.to_string()).unwrap();
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, "[[model]]\nfile = \"models/outside.gltf\"\n").unwrap();
    let (code, stderr, _) = viewfactors(&toml, &[]);
    assert!(code == Some(2) && stderr.contains("outside.gltf: surface 'Grid'"), "{stderr}");
    let (code, stderr, _) = viewfactors(&toml, &["--allow-outside-paths"]);
    assert_eq!(code, Some(0), "{stderr}");
}

#[test]
fn valid_grid_sparse_and_containers_load() {
    let plain = scene::load(&data("grid.gltf")).unwrap();
    let glb = scene::load(&data("grid.glb")).unwrap();
    assert_eq!(plain.patches, glb.patches);
    assert_eq!(plain.patches.len(), 8);
    assert!((plain.surfaces[0].area - 1.0).abs() < 1e-12);
    // Sparse: vertex 4, the centre, moves to z = 0.25; the other eight stay at z = 0.
    let sparse = scene::load(&data("grid_sparse.gltf")).unwrap();
    let zs: Vec<f64> = sparse.patches.iter().flat_map(|p| p.polygon.vertices().iter().map(|v| v.z)).collect();
    // The grid's diagonals run from (0,0) to (1,1): 6 of its 8 triangles have the centre.
    assert_eq!(zs.iter().filter(|&&z| z == 0.25).count(), 6);
    assert!(zs.iter().all(|&z| z == 0.0 || z == 0.25));
}

#[test]
fn a_panic_is_one_line_and_exit_101() {
    let run = |env: &[(&str, &str)]| {
        let o = lambert(&["viewfactors".as_ref(), "x.toml".as_ref()], env);
        (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
    };
    for env in [
        &[("LAMBERT_PANIC_SELF_TEST", "1")][..],
        &[("LAMBERT_PANIC_SELF_TEST", "1"), ("RUST_BACKTRACE", "full")],
    ] {
        let (code, stderr) = run(env);
        assert_eq!(code, Some(101), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.starts_with("lambert: internal error: self-test panic"), "{stderr}");
        assert!(
            stderr.contains(" at src/main.rs:") && stderr.trim_end().ends_with("; please report it"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked") && !stderr.contains("backtrace"), "{stderr}");
    }
    let (code, stderr) = run(&[("LAMBERT_PANIC_SELF_TEST", "1"), ("LAMBERT_BACKTRACE", "1")]);
    assert_eq!(code, Some(101));
    // The backtrace follows the one line: frames of lambert's own code (their names survive a
    // release build's inlining only as `lambert::…` symbols or `main.rs` line tables).
    let frames: Vec<&str> = stderr.lines().skip(1).collect();
    assert!(frames.iter().any(|l| l.contains("lambert::") || l.contains("main.rs")), "{stderr}");
}
