//! The same numbers on any rank count (feature `mpi`, needs `mpiexec` on PATH, MPICH): the
//! output files of `mpiexec -np 1/2/3 lambert …` are byte-identical to a run without MPI, for
//! auto, analytic and Monte Carlo view factors (patch and surface level) and the solve routes
//! (packed dense, sparse patch rows, hierarchical — distributed, one and two passes, open and
//! closed — and iterative), with the measured and the estimated row split, and as merged
//! shards; each rank holds a share of the hierarchy's links and pairs, and of the dense
//! store's rows (whose memory check is per rank). Ranks that load different geometry are
//! refused with exit code 2, and only rank 0 writes; a leaking or unanchored closed scene is
//! refused alike on any rank count.
//!
//! Run with `cargo test --release --features mpi --test mpi` (the release binary is the one
//! `cargo build --release --features mpi` makes, so CI builds it once).
#![cfg(feature = "mpi")]
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_lambert");

fn case(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("cases").join(name).join("scene.toml")
}

/// The obstructed room with 4×4 patches per wall and 2×2 per block face (120 patches).
fn room(dir: &Path) -> String {
    let text = std::fs::read_to_string(case("o3_obstructed_room"))
        .unwrap()
        .replace("subdivide = [12, 12]", "subdivide = [4, 4]")
        .replace("subdivide = [6, 6]", "subdivide = [2, 2]");
    let p = dir.join("room.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// The cube furnace with 6×6 patches per face (216 patches).
fn furnace(dir: &Path) -> String {
    let text = std::fs::read_to_string(case("cube_furnace"))
        .unwrap()
        .replace("subdivide = [4, 4]", "subdivide = [6, 6]");
    let p = dir.join("furnace.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// Runs lambert with `args`, under `mpiexec -np np` when `np` is given, with 1 thread per rank
/// on 3 and 4 ranks and 2 otherwise (the thread count must not matter either).
fn run(np: Option<usize>, args: &[String]) -> Output {
    let threads = if np >= Some(3) { "1" } else { "2" };
    let mut cmd = match np {
        Some(np) => {
            let mut c = Command::new("mpiexec");
            c.args(["-np", &np.to_string(), BIN]);
            c
        }
        None => Command::new(BIN),
    };
    cmd.args(args).args(["--threads", threads]);
    cmd.output().expect("run lambert (is mpiexec on PATH?)")
}

/// Runs `cmd scene args -o out` without MPI and under 1, 2 and 3 ranks, and asserts every
/// output file is byte-identical to the run without MPI.
fn assert_same_on_any_rank_count(dir: &Path, what: &str, cmd: &str, scene: &str, args: &[&str]) {
    assert_same_on(&[None, Some(1), Some(2), Some(3)], dir, what, cmd, scene, args);
}

/// As [`assert_same_on_any_rank_count`] on the rank counts `nps` (`None`: without MPI, first).
fn assert_same_on(nps: &[Option<usize>], dir: &Path, what: &str, cmd: &str, scene: &str, args: &[&str]) {
    let mut reference: Option<Vec<u8>> = None;
    for &np in nps {
        let out = dir.join(format!("{}_{}.csv", what.replace(' ', "_"), np.unwrap_or(0)));
        let mut all: Vec<String> = vec![cmd.into(), scene.into(), "-o".into(), out.to_str().unwrap().into()];
        all.extend(args.iter().map(|s| s.to_string()));
        let o = run(np, &all);
        assert!(o.status.success(), "{what}, np {np:?}: {}", String::from_utf8_lossy(&o.stderr));
        let bytes =
            std::fs::read(&out).unwrap_or_else(|e| panic!("{what}, np {np:?}: {}: {e}", out.display()));
        assert!(bytes.len() > 100, "{what}: the output is nearly empty");
        match &reference {
            None => reference = Some(bytes),
            Some(r) => assert!(r == &bytes, "{what}: np {np:?} differs from the run without MPI"),
        }
    }
    // Nothing but the outputs: no temporaries left by any rank.
    let partial: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("partial"))
        .collect();
    assert!(partial.is_empty(), "{what}: temporaries left: {partial:?}");
}

#[test]
fn view_factors_are_the_same_on_any_rank_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let room = room(d);
    for (what, args) in [
        ("auto patches", vec!["--patches"]),
        ("auto surfaces", vec![]),
        ("analytic patches", vec!["--patches", "-m", "analytic"]),
        ("mc-area patches", vec!["--patches", "-m", "mc-area", "--samples", "2000", "--seed", "7"]),
        ("mc-cosine surfaces", vec!["-m", "mc-cosine", "--samples", "2000"]),
        ("hemicube patches", vec!["--patches", "-m", "hemicube", "--resolution", "32"]),
    ] {
        assert_same_on_any_rank_count(d, what, "viewfactors", &room, &args);
    }
}

#[test]
fn solves_are_the_same_on_any_rank_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    for (what, args) in [
        ("solve packed", vec!["--patches"]),
        ("solve surfaces", vec![]),
        ("solve mc-area", vec!["--patches", "-m", "mc-area", "--samples", "20000"]),
        ("solve jacobi", vec!["--solver", "jacobi"]),
        ("solve hierarchical", vec!["--exchange", "hierarchical"]),
    ] {
        assert_same_on_any_rank_count(d, what, "solve", &furnace, &args);
    }
}

#[test]
fn both_row_splits_and_merged_shards_give_the_same_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let room = room(d);
    let file = |name: &str| d.join(name).to_str().unwrap().to_string();
    let vf = |out: &str| -> Vec<String> {
        ["viewfactors", &room, "--patches", "-o", out].iter().map(|s| s.to_string()).collect()
    };
    let o = run(None, &vf(&file("single.csv")));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let want = std::fs::read(d.join("single.csv")).unwrap();
    for split in ["measured", "estimated"] {
        let out = file(&format!("{split}.csv"));
        let mut cmd = Command::new("mpiexec");
        cmd.args(["-np", "3", BIN]).args(vf(&out)).args(["--threads", "1"]);
        let o = cmd.env("LAMBERT_MPI_BALANCE", split).env("LAMBERT_MPI_STATS", "1").output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(o.status.success(), "{split}: {err}");
        assert!(err.contains(&format!("{split} split, compute seconds max/mean")), "{split}: {err}");
        assert!(std::fs::read(&out).unwrap() == want, "the {split} split differs from the run without MPI");
    }
    let mut parts = Vec::new();
    for i in 0..3 {
        let part = file(&format!("part_{i}"));
        let mut args = vf(&part);
        args.extend(["--shard".to_string(), format!("{i}/3")]);
        assert!(run(None, &args).status.success());
        parts.push(part);
    }
    let merged = file("merged.csv");
    let o = Command::new(BIN).arg("merge").args(&parts).args(["-o", &merged]).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(std::fs::read(&merged).unwrap() == want, "the merged shards differ from the run without MPI");
}

/// The open-top cube furnace (ambient at 0 K) with 6×6 patches per face (180 patches).
fn open_cube(dir: &Path) -> String {
    let text = std::fs::read_to_string(case("e4_cube_open_top")).unwrap();
    let text: String =
        text.lines()
            .map(|l| {
                if l.starts_with("rectangle") {
                    format!("{l}\nsubdivide = [6, 6]\n")
                } else {
                    format!("{l}\n")
                }
            })
            .collect();
    let p = dir.join("open.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

#[test]
fn hierarchical_solves_are_the_same_on_any_rank_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (furnace, open) = (furnace(d), open_cube(d));
    // The obstructed room with conditions: the floor at 400 K, the rest at 300 K, ε 0.6.
    let heated = heated_room(d);
    // One pass at 1e-2, two passes (the first's pairs reused) at 1e-3; closed and open scenes,
    // the room with its blocker's shadows.
    for (what, scene, tol) in [
        ("furnace one pass", &furnace, "1e-2"),
        ("furnace two passes", &furnace, "1e-3"),
        ("heated room two passes", &heated, "1e-3"),
        ("open one pass", &open, "1e-2"),
        ("open two passes", &open, "1e-3"),
    ] {
        let args = ["--patches", "--exchange", "hierarchical", "--tolerance", tol];
        // 4 ranks too: each refines a quarter of the tasks (oversubscribed on 2 cores).
        assert_same_on(&[None, Some(1), Some(2), Some(3), Some(4)], d, what, "solve", scene, &args);
    }
}

/// (links, patch pairs, links and pairs refined) of each rank of the last hierarchy a run
/// built, from its statistics.
fn shares(np: Option<usize>, scene: &str, out: &Path) -> Vec<(usize, usize, usize)> {
    let mut cmd = match np {
        Some(np) => {
            let mut c = Command::new("mpiexec");
            c.args(["-np", &np.to_string(), BIN]);
            c
        }
        None => Command::new(BIN),
    };
    let o = cmd
        .args(["solve", scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "hierarchical"])
        .args(["--tolerance", "1e-3"])
        .env("LAMBERT_MPI_STATS", "1")
        .output()
        .expect("run lambert");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let lines: Vec<(usize, usize, usize)> = err
        .lines()
        .filter(|l| l.contains("mpi: hierarchy rank") && l.contains("links"))
        .map(|l| {
            let num = |word: &str| {
                let before = l.split(word).next().unwrap();
                before.trim_end().rsplit([' ', ',']).next().unwrap().parse::<usize>().unwrap()
            };
            (num(" links"), num(" patch pairs"), num(" refined"))
        })
        .collect();
    let k = np.unwrap_or(1);
    assert!(lines.len() >= k, "{err}");
    lines[lines.len() - k..].to_vec()
}

#[test]
fn each_rank_holds_a_share_of_the_links_and_pairs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    let whole = shares(None, &furnace, &d.join("one.csv"));
    assert_eq!(whole.len(), 1);
    let (links, pairs, refined) = whole[0];
    assert!(links > 10 && pairs > 1000 && refined >= links + pairs, "{whole:?}");
    for np in [2, 3] {
        let parts = shares(Some(np), &furnace, &d.join(format!("np{np}.csv")));
        // Every link and pair is held by exactly one rank, and refined by exactly one ...
        assert_eq!(parts.iter().map(|p| p.0).sum::<usize>(), links, "np {np}: {parts:?}");
        assert_eq!(parts.iter().map(|p| p.1).sum::<usize>(), pairs, "np {np}: {parts:?}");
        assert_eq!(parts.iter().map(|p| p.2).sum::<usize>(), refined, "np {np}: {parts:?}");
        // ... and each holds about 1/np of them, and never refined the whole list.
        for (r, &(l, p, f)) in parts.iter().enumerate() {
            let share = (l + p) as f64 / (links + pairs) as f64;
            let made = f as f64 / refined as f64;
            for (what, x) in [("held", share), ("refined", made)] {
                assert!(
                    x > 0.5 / np as f64 && x < 1.5 / np as f64,
                    "np {np}, rank {r}: {what} {x} of the entries ({parts:?})"
                );
            }
        }
    }
}

/// Runs `viewfactors` under MPMD `mpiexec`: rank 0 on `a`, rank 1 on `b`, one output name.
fn two_scenes(a: &str, b: &str, out: &Path) -> Output {
    Command::new("mpiexec")
        .args(["-np", "1", BIN, "viewfactors", a, "-o", out.to_str().unwrap(), ":"])
        .args(["-np", "1", BIN, "viewfactors", b, "-o", out.to_str().unwrap()])
        .output()
        .expect("run mpiexec")
}

#[test]
fn ranks_with_different_geometry_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let room = room(d);
    let text = std::fs::read_to_string(&room).unwrap();
    // Rank 1 splits the floor into 3×3 patches instead of 4×4: a valid scene, another hash.
    let finer = d.join("finer.toml");
    std::fs::write(&finer, text.replacen("subdivide = [4, 4]", "subdivide = [3, 3]", 1)).unwrap();
    let out = d.join("vf.csv");
    let o = two_scenes(&room, finer.to_str().unwrap(), &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("do not hold the same scene geometry") && err.contains("rank 1 has hash"), "{err}");
    assert!(!out.exists(), "a refused run wrote its output");
    // Rank 1's floor moved by 1 mm: its scene no longer loads, so it finishes while rank 0
    // waits for rows; the run is refused all the same.
    let moved = d.join("moved.toml");
    std::fs::write(&moved, text.replacen("origin = [0", "origin = [0.001", 1)).unwrap();
    let o = two_scenes(&room, moved.to_str().unwrap(), &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("rank 1 is finishing while rank 0 is about to compute"), "{err}");
    assert!(!out.exists(), "a refused run wrote its output");
}

#[test]
fn bad_input_fails_on_every_rank_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let bad = d.join("bad.toml");
    std::fs::write(&bad, "[[surface]]\nname = \"a\"\n").unwrap();
    let o = run(Some(2), &["viewfactors".into(), bad.to_str().unwrap().into()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    // Rank 0 alone speaks: the message appears once.
    assert_eq!(err.matches("bad.toml").count(), 1, "{err}");
}

#[test]
fn ranks_refining_different_hierarchies_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    let text = std::fs::read_to_string(&furnace).unwrap();
    let out = d.join("q.csv");
    let solve = |a: &str, b: &str| {
        let args = |scene: &str| -> Vec<String> {
            ["solve", scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "hierarchical"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        };
        Command::new("mpiexec")
            .args(["-np", "1", BIN])
            .args(args(a))
            .arg(":")
            .args(["-np", "1", BIN])
            .args(args(b))
            .output()
            .expect("run mpiexec")
    };
    // Rank 1 subdivides one face 5×5: another tree, refused before any link is refined.
    let finer = d.join("finer.toml");
    std::fs::write(&finer, text.replacen("subdivide = [6, 6]", "subdivide = [5, 5]", 1)).unwrap();
    let o = solve(&furnace, finer.to_str().unwrap());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("do not hold the same scene geometry, cluster tree") && err.contains("rank 1 has hash"),
        "{err}"
    );
    assert!(!out.exists(), "a refused run wrote its output");
    // Rank 1's scene does not load: it finishes while rank 0 is about to refine.
    let bad = d.join("bad.toml");
    std::fs::write(&bad, "[[surface]]\nname = \"a\"\n").unwrap();
    let o = solve(&furnace, bad.to_str().unwrap());
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("rank 1 is finishing while rank 0 is about to refine the link hierarchy"), "{err}");
    assert!(!out.exists(), "a refused run wrote its output");
}

/// The obstructed room with conditions: the floor at 400 K, the rest at 300 K, ε 0.6.
fn heated_room(dir: &Path) -> String {
    let text = std::fs::read_to_string(room(dir))
        .unwrap()
        .replace("[[surface]]\n", "[[surface]]\nemissivity = 0.6\ntemperature = 300.0\n");
    let heated = dir.join("heated.toml");
    std::fs::write(&heated, text.replacen("temperature = 300.0", "temperature = 400.0", 1)).unwrap();
    heated.to_str().unwrap().to_string()
}

#[test]
fn dense_solves_on_row_blocks_are_the_same_on_any_rank_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (furnace, open, heated) = (furnace(d), open_cube(d), heated_room(d));
    // Closed (closure scaling) and open (capped scaling, ambient) scenes, the room with its
    // blocker's shadows; patch and surface outputs; 4 ranks too (oversubscribed on 2 cores).
    // Hemicube rows are folded, not symmetric: they keep the gathered route.
    for (what, scene, args) in [
        ("dense furnace", &furnace, vec!["--patches"]),
        ("dense furnace surfaces", &furnace, vec![]),
        ("dense open", &open, vec!["--patches"]),
        ("dense heated room", &heated, vec!["--patches"]),
        ("dense analytic room", &heated, vec!["--patches", "-m", "analytic"]),
        ("dense hemicube furnace", &furnace, vec!["--patches", "-m", "hemicube", "--resolution", "32"]),
    ] {
        let mut all = vec!["--exchange", "dense"];
        all.extend(args);
        assert_same_on(&[None, Some(1), Some(2), Some(3), Some(4)], d, what, "solve", scene, &all);
    }
}

/// (first row, end row, store bytes) of each rank's block of the dense store under the
/// estimated split, from the statistics of `solve --exchange dense` on `np` ranks, and the
/// patch count.
fn dense_blocks(np: usize, scene: &str, out: &Path) -> (Vec<(usize, usize, usize)>, usize) {
    let o = Command::new("mpiexec")
        .args(["-np", &np.to_string(), BIN, "solve", scene, "-o", out.to_str().unwrap()])
        .args(["--patches", "--exchange", "dense", "--threads", "1"])
        // The pair-count split (the measured one follows the rows' timings).
        .env("LAMBERT_MPI_BALANCE", "estimated")
        .env("LAMBERT_MPI_STATS", "1")
        .output()
        .expect("run mpiexec");
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let mut n = 0;
    let blocks = err
        .lines()
        .filter(|l| l.contains("mpi: dense rank"))
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            let at = |w: &str| words.iter().position(|x| *x == w).unwrap_or_else(|| panic!("{l}"));
            let (a, b) = words[at("rows") + 1].split_once("..").unwrap();
            n = words[at("of") + 1].trim_end_matches(',').parse().unwrap();
            (a.parse().unwrap(), b.parse().unwrap(), words[at("store") - 1].parse().unwrap())
        })
        .collect();
    (blocks, n)
}

#[test]
fn each_rank_holds_a_share_of_the_dense_store() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    // Without MPI the store is whole and nothing is reported.
    let o =
        run(None, &["solve".into(), furnace.clone(), "-o".into(), d.join("w.csv").to_str().unwrap().into()]);
    assert!(!String::from_utf8_lossy(&o.stderr).contains("mpi: dense rank"));
    for np in [2, 3, 4] {
        let (blocks, n) = dense_blocks(np, &furnace, &d.join(format!("np{np}.csv")));
        assert_eq!((blocks.len(), n), (np, 216), "np {np}: {blocks:?}");
        // Contiguous blocks, every row held once ...
        assert_eq!((blocks[0].0, blocks[np - 1].1), (0, n), "np {np}: {blocks:?}");
        assert!(blocks.windows(2).all(|w| w[0].1 == w[1].0), "np {np}: {blocks:?}");
        // ... the triangle's n(n+1)/2 cells held once in all, about 1/np of them each.
        let cells = n * (n + 1) / 2;
        assert_eq!(blocks.iter().map(|b| b.2).sum::<usize>(), 8 * cells, "np {np}: {blocks:?}");
        for (r, b) in blocks.iter().enumerate() {
            let share = b.2 as f64 / (8 * cells) as f64;
            assert!(share > 0.7 / np as f64 && share < 1.3 / np as f64, "np {np}, rank {r}: {share}");
        }
    }
}

#[test]
fn the_dense_memory_check_is_per_rank_and_a_refusal_ends_every_rank() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    // 216 patches: 23,436 cells of 8 bytes and 25 % headroom, 234 kB in one process; about
    // half on each of two ranks. 160 kB: too little for one process, enough for two ranks.
    let solve = |np: Option<usize>, mem: &str, out: &str| {
        let mut cmd = match np {
            Some(np) => {
                let mut c = Command::new("mpiexec");
                c.args(["-np", &np.to_string(), BIN]);
                c
            }
            None => Command::new(BIN),
        };
        let out = d.join(out);
        cmd.args(["solve", &furnace, "-o", out.to_str().unwrap(), "--patches", "--exchange", "dense"])
            .env("LAMBERT_MEM_AVAILABLE", mem)
            // The pair-count split: the final, measured share has its own test below.
            .env("LAMBERT_MPI_BALANCE", "estimated")
            .output()
            .expect("run lambert")
    };
    for np in [None, Some(1)] {
        let o = solve(np, "160000", "one.csv");
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "np {np:?}: {err}");
        assert!(err.contains("216 patches need about") && err.contains("LAMBERT_MEM_AVAILABLE"), "{err}");
    }
    assert!(!d.join("one.csv").exists(), "a refused run wrote its output");
    let o = solve(Some(2), "160000", "two.csv");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = run(
        None,
        &[
            "solve".into(),
            furnace.clone(),
            "-o".into(),
            d.join("ref.csv").to_str().unwrap().into(),
            "--patches".into(),
        ],
    );
    assert!(o.status.success());
    assert!(std::fs::read(d.join("two.csv")).unwrap() == std::fs::read(d.join("ref.csv")).unwrap());
    // 100 kB: not even half fits. Every rank refuses, rank 0 alone says so, naming the rank.
    let o = solve(Some(2), "100000", "no.csv");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.matches("per MPI rank").count(), 1, "{err}");
    assert!(
        err.contains("shared by 2 ranks (rank 0 holds rows 0..") && err.contains("run on more ranks"),
        "{err}"
    );
    assert!(!d.join("no.csv").exists(), "a refused run wrote its output");
}

#[test]
fn a_leaking_scene_is_refused_alike_on_any_rank_count() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The furnace without its ceiling, still closed (no ambient): every row leaks.
    let text = std::fs::read_to_string(furnace(d)).unwrap();
    let parts: Vec<&str> = text.split("[[surface]]").filter(|p| !p.contains("name = \"ceiling\"")).collect();
    let leaky = d.join("leaky.toml");
    std::fs::write(&leaky, parts.join("[[surface]]")).unwrap();
    let out = d.join("leak.csv");
    let args = ["solve", leaky.to_str().unwrap(), "-o", out.to_str().unwrap(), "--patches"];
    refused_alike(&args, &out, |line| line.contains("the closed scene leaks: 180 row(s)"));
}

/// Runs `args` without MPI and on 2 and 3 ranks: every run exits 2 with exactly one error line,
/// which `says` accepts and which is the same on every rank count, and writes nothing at `out`.
fn refused_alike(args: &[&str], out: &Path, says: impl Fn(&str) -> bool) {
    let args: Vec<String> = args.iter().map(|s| s.to_string()).collect();
    let mut first: Option<String> = None;
    for np in [None, Some(2), Some(3)] {
        let o = run(np, &args);
        let err = String::from_utf8_lossy(&o.stderr).to_string();
        assert_eq!(o.status.code(), Some(2), "np {np:?}: {err}");
        let line = err.lines().find(|l| l.contains("error:")).unwrap_or_else(|| panic!("{err}")).to_string();
        assert!(says(&line), "{line}");
        assert_eq!(err.matches("error:").count(), 1, "np {np:?}: {err}");
        assert!(!out.exists(), "a refused run wrote its output");
        match &first {
            None => first = Some(line),
            Some(f) => assert_eq!(f, &line, "np {np:?}"),
        }
    }
}

#[test]
fn an_unanchored_enclosure_is_refused_alike_on_any_rank_count() {
    // The furnace with heat fluxes on every face: singular, refused by the one anchoring
    // check, whose coupled groups are gathered across the ranks' row blocks.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(furnace(d))
        .unwrap()
        .replace("temperature = 1000.0", "heat_flux = 100.0")
        .replace("temperature = 400.0", "heat_flux = -100.0");
    let flux = d.join("flux.toml");
    std::fs::write(&flux, text).unwrap();
    let out = d.join("flux.csv");
    let args =
        ["solve", flux.to_str().unwrap(), "-o", out.to_str().unwrap(), "--patches", "--exchange", "dense"];
    refused_alike(&args, &out, |line| line.contains("flux.toml") && line.contains("no temperature anchor"));
}

#[test]
fn ranks_solving_different_scenes_on_the_dense_store_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let furnace = furnace(d);
    let text = std::fs::read_to_string(&furnace).unwrap();
    let out = d.join("q.csv");
    let solve = |b: &Path| {
        let args = |scene: &str| -> Vec<String> {
            ["solve", scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "dense"]
                .iter()
                .map(|s| s.to_string())
                .collect()
        };
        Command::new("mpiexec")
            .args(["-np", "1", BIN])
            .args(args(&furnace))
            .arg(":")
            .args(["-np", "1", BIN])
            .args(args(b.to_str().unwrap()))
            .output()
            .expect("run mpiexec")
    };
    // Rank 1's floor is at 900 K: the same geometry, but the ranks would mix two right-hand
    // sides in one CG. Then another patch count, then a scene that does not load.
    let cooler = d.join("cooler.toml");
    std::fs::write(&cooler, text.replacen("temperature = 1000.0", "temperature = 900.0", 1)).unwrap();
    let finer = d.join("finer.toml");
    std::fs::write(&finer, text.replacen("subdivide = [6, 6]", "subdivide = [5, 5]", 1)).unwrap();
    let bad = d.join("bad.toml");
    std::fs::write(&bad, "[[surface]]\nname = \"a\"\n").unwrap();
    for (scene, says) in [
        (&cooler, "do not hold the same patch count, surface conditions and dense store"),
        (&finer, "do not hold the same patch count, surface conditions and dense store"),
        (&bad, "rank 1 is finishing while rank 0 is about to check the memory of the dense store"),
    ] {
        let o = solve(scene);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", scene.display());
        assert!(err.contains(says), "{}: {err}", scene.display());
        assert!(!out.exists(), "a refused run wrote its output");
    }
}

/// Runs lambert under `mpiexec -np np` (1 thread per rank) with `env` set.
fn run_env(np: usize, args: &[&str], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new("mpiexec");
    c.args(["-np", &np.to_string(), BIN]).args(args).args(["--threads", "1"]);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run mpiexec")
}

#[test]
fn solves_with_the_measured_and_the_estimated_split_are_the_same() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let heated = heated_room(d);
    for (what, args) in [
        ("dense", vec!["--patches", "--exchange", "dense"]),
        ("hierarchical", vec!["--patches", "--exchange", "hierarchical", "--tolerance", "1e-3"]),
    ] {
        let want = d.join(format!("{what}.csv"));
        let mut all = vec!["solve", &heated, "-o", want.to_str().unwrap()];
        all.extend(&args);
        let o = Command::new(BIN).args(&all).output().unwrap();
        assert!(o.status.success(), "{what}: {}", String::from_utf8_lossy(&o.stderr));
        let want = std::fs::read(&want).unwrap();
        for split in ["measured", "estimated"] {
            for np in [1, 2, 3] {
                let out = d.join(format!("{what}_{split}_{np}.csv"));
                let mut all = vec!["solve", &heated, "-o", out.to_str().unwrap()];
                all.extend(&args);
                let o = run_env(np, &all, &[("LAMBERT_MPI_BALANCE", split), ("LAMBERT_MPI_STATS", "1")]);
                let err = String::from_utf8_lossy(&o.stderr);
                assert!(o.status.success(), "{what}, {split}, np {np}: {err}");
                let said = if what == "dense" {
                    format!("dense {split} split")
                } else {
                    "measured split".to_string()
                };
                // One rank has nothing to split; the hierarchy names a measured split only.
                let named = err.contains(&said);
                assert_eq!(
                    named,
                    np > 1 && (what == "dense" || split == "measured"),
                    "{what}, {split}, np {np}: {err}"
                );
                assert!(
                    std::fs::read(&out).unwrap() == want,
                    "{what}, {split} split, np {np}: differs from no MPI"
                );
            }
        }
    }
}

/// Two 10×10 plates facing each other across a blocking plate (every pair between them
/// shadow-tested), then 20×10 coplanar patches far below, facing away from everything (every
/// pair culled at once): 408 patches whose first rows cost far more per pair than the rest.
fn uneven(dir: &Path) -> String {
    let text = r#"
[ambient]
temperature = 300.0

[[surface]]
name = "bottom"
rectangle = { origin = [0.0, 0.0, 0.0], u = [1.0, 0.0, 0.0], v = [0.0, 1.0, 0.0] }
subdivide = [10, 10]
emissivity = 0.8
temperature = 400.0

[[surface]]
name = "top"
rectangle = { origin = [0.0, 0.0, 1.0], u = [0.0, 1.0, 0.0], v = [1.0, 0.0, 0.0] }
subdivide = [10, 10]
emissivity = 0.8
temperature = 300.0

[[surface]]
name = "plate_down"
rectangle = { origin = [0.25, 0.25, 0.5], u = [0.0, 0.5, 0.0], v = [0.5, 0.0, 0.0] }
subdivide = [2, 2]
emissivity = 0.5
temperature = 350.0

[[surface]]
name = "plate_up"
rectangle = { origin = [0.25, 0.25, 0.5], u = [0.5, 0.0, 0.0], v = [0.0, 0.5, 0.0] }
subdivide = [2, 2]
emissivity = 0.5
temperature = 350.0

[[surface]]
name = "shelf"
rectangle = { origin = [0.0, 0.0, -5.0], u = [0.0, 1.0, 0.0], v = [2.0, 0.0, 0.0] }
subdivide = [10, 20]
emissivity = 0.8
temperature = 300.0
"#;
    let p = dir.join("uneven.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// (first, end) row of each rank's dense block under `split`, from the statistics.
fn dense_rows(scene: &str, out: &Path, np: usize, split: &str) -> Vec<(usize, usize)> {
    let args = ["solve", scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "dense"];
    let o = run_env(np, &args, &[("LAMBERT_MPI_BALANCE", split), ("LAMBERT_MPI_STATS", "1")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    err.lines()
        .filter(|l| l.contains("mpi: dense rank") && l.contains("holds rows"))
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            let at = words.iter().position(|x| *x == "rows").unwrap();
            let (a, b) = words[at + 1].split_once("..").unwrap();
            (a.parse().unwrap(), b.parse().unwrap())
        })
        .collect()
}

/// Each rank's chunk range and refined entries of the last hierarchy built under `split`,
/// from the statistics.
fn chunk_runs(scene: &str, out: &Path, np: usize, split: &str) -> Vec<(String, usize)> {
    let args = ["solve", scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "hierarchical"];
    let o = run_env(np, &args, &[("LAMBERT_MPI_BALANCE", split), ("LAMBERT_MPI_STATS", "1")]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let runs: Vec<(String, usize)> = err
        .lines()
        .filter(|l| l.contains("mpi: hierarchy rank") && l.contains("chunks "))
        .map(|l| {
            let run = l.split("chunks ").nth(1).unwrap().split(',').next().unwrap().to_string();
            let refined = l.split(" refined").next().unwrap().rsplit(' ').next().unwrap().parse().unwrap();
            (run, refined)
        })
        .collect();
    assert_eq!(runs.len(), np, "{err}");
    runs
}

/// The obstructed room of validation/scenes/room_8472.toml at half its patches per side
/// (2,054 patches: cluster links and patch pairs; floor 1000 K, the rest 300 K).
fn room_2k(dir: &Path) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("validation/scenes/room_8472.toml");
    let text = std::fs::read_to_string(path)
        .unwrap()
        .replace("subdivide = [34, 34]", "subdivide = [17, 17]")
        .replace("subdivide = [16, 16]", "subdivide = [8, 8]");
    let p = dir.join("room_2k.toml");
    std::fs::write(&p, text).unwrap();
    p.to_str().unwrap().to_string()
}

/// Largest over mean of the refined entries per rank.
fn spread(runs: &[(String, usize)]) -> f64 {
    let max = runs.iter().map(|r| r.1).max().unwrap() as f64;
    max * runs.len() as f64 / runs.iter().map(|r| r.1).sum::<usize>() as f64
}

#[test]
fn the_measured_split_moves_rows_and_chunks_off_the_dear_ranks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = uneven(d);
    // Dense: by pair count rank 0 holds about the first 29 % of the rows, most of them the
    // dear plates' rows; measured, it holds about half of the plates' cost and fewer rows.
    let estimated = dense_rows(&scene, &d.join("e.csv"), 2, "estimated");
    let measured = dense_rows(&scene, &d.join("m.csv"), 2, "measured");
    assert_eq!(estimated.len(), 2, "{estimated:?}");
    assert_eq!(estimated, dense_rows(&scene, &d.join("e2.csv"), 2, "estimated"), "the estimate is fixed");
    assert_eq!((measured[0].0, measured[1].1), (0, 408), "{measured:?}");
    assert_eq!(measured[0].1, measured[1].0, "{measured:?}");
    assert!(measured[0].1 + 20 < estimated[0].1, "measured {measured:?} against estimated {estimated:?}");
    assert!(std::fs::read(d.join("e.csv")).unwrap() == std::fs::read(d.join("m.csv")).unwrap());
    // Hierarchy: on the room the estimate gives the middle rank 1.36 × the mean of the
    // refined entries; the measured split (entries the probe tasks refined) moves chunks
    // and evens them, the same on every run (counts, not times), with the same output.
    let room = room_2k(d);
    let est = chunk_runs(&room, &d.join("he.csv"), 3, "estimated");
    let meas = chunk_runs(&room, &d.join("hm.csv"), 3, "measured");
    assert_ne!(est, meas, "the measured split moved no chunk");
    assert_eq!(est.iter().map(|r| r.1).sum::<usize>(), meas.iter().map(|r| r.1).sum::<usize>());
    assert!(spread(&meas) < spread(&est) - 0.05, "measured {meas:?} against estimated {est:?}");
    assert_eq!(meas, chunk_runs(&room, &d.join("hm2.csv"), 3, "measured"));
    assert!(std::fs::read(d.join("he.csv")).unwrap() == std::fs::read(d.join("hm.csv")).unwrap());
}

#[test]
fn the_dense_memory_check_uses_each_ranks_final_share() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = uneven(d);
    // 408 patches: 83,436 cells, 834 kB with the headroom; by pair count about 417 kB a
    // rank at np 2. Measured, rank 1 takes the cheap rows, over 480 kB of them: the early
    // check (estimated split) passes, the final one refuses, naming rank 1 and its rows.
    let solve = |split: &str, out: &str| {
        let out = d.join(out);
        let args = ["solve", &scene, "-o", out.to_str().unwrap(), "--patches", "--exchange", "dense"];
        run_env(2, &args, &[("LAMBERT_MPI_BALANCE", split), ("LAMBERT_MEM_AVAILABLE", "480000")])
    };
    let o = solve("estimated", "e.csv");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let o = solve("measured", "m.csv");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert_eq!(err.matches("per MPI rank").count(), 1, "{err}");
    assert!(err.contains("shared by 2 ranks (rank 1 holds rows "), "{err}");
    assert!(err.contains("of probe rows in passing") && err.contains("run on more ranks"), "{err}");
    assert!(!d.join("m.csv").exists(), "a refused run wrote its output");
}
