//! The real binary on bad scenes: exit code 2, a message naming file, surface and problem on
//! stderr, nothing on stdout, and an existing `-o` file left untouched.
use std::path::Path;
use std::process::Command;

const EXISTING: &str = "from,to,factor\nearlier,result,0.5\n";

/// Runs `lambert viewfactors SCENE -o OUT` and returns (exit code, stderr).
fn run(scene: &Path, out: &Path) -> (Option<i32>, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_lambert"))
        .args(["viewfactors".as_ref(), scene.as_os_str(), "-o".as_ref(), out.as_os_str()])
        .output()
        .expect("run lambert");
    (
        o.status.code(),
        String::from_utf8_lossy(&o.stderr).into_owned(),
        String::from_utf8_lossy(&o.stdout).into_owned(),
    )
}

#[test]
fn bad_scenes_exit_2_and_keep_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            "unknown.toml",
            "[[surface]]\nname = \"floor\"\npolygon = [[0,0,0],[1,0,0],[0,1,0]]\nemisivity = 0.5\n",
            "unknown.toml:4: surface 'floor': unknown field `emisivity`",
        ),
        ("nan.toml", "[[surface]]\nname = \"lid\"\npolygon = [[0,0,0],[1,0,0],[0,nan,0]]\n", "nan.toml:3: surface 'lid': polygon vertex 2 is NaN"),
        (
            "emissivity.toml",
            "[[surface]]\nname = \"w\"\nrectangle = { origin = [0,0,0], u = [1,0,0], v = [0,1,0] }\nemissivity = 1.2\n",
            "emissivity.toml:4: surface 'w': emissivity is 1.2",
        ),
        ("syntax.toml", "[[surface]\n", "syntax.toml:1: "),
    ];
    for (file, text, needle) in cases {
        let scene = dir.path().join(file);
        std::fs::write(&scene, text).unwrap();
        let out = dir.path().join("result.csv");
        std::fs::write(&out, EXISTING).unwrap();
        let (code, stderr, stdout) = run(&scene, &out);
        assert_eq!(code, Some(2), "{file}: {stderr}");
        assert!(stderr.contains("lambert: error: ") && stderr.contains(needle), "{file}: {stderr}");
        assert!(!stderr.contains("panicked"), "{file}: {stderr}");
        assert!(stdout.is_empty(), "{file}: {stdout}");
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            EXISTING,
            "{file}: the earlier result must survive"
        );
        assert!(!dir.path().join("result.csv.partial").exists());
    }
}

#[test]
fn missing_files_and_bad_gltf_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.csv");
    let (code, stderr, _) = run(&dir.path().join("absent.toml"), &out);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("absent.toml: cannot read the file"), "{stderr}");
    assert!(!out.exists(), "no output for a failed run");
    let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/bad_lines.gltf");
    let (code, stderr, _) = run(&bad, &out);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("bad_lines.gltf: surface 'Panel': primitive 0 draws Lines"), "{stderr}");
    let model = dir.path().join("model.toml");
    std::fs::write(&model, "[[model]]\nfile = \"gone.glb\"\n").unwrap();
    let (code, stderr, _) = run(&model, &out);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("model.toml:2: model file") && stderr.contains("does not exist"), "{stderr}");
}
