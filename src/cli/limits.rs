//! Limits and costs said up front: option values a run cannot use are refused (exit 2) before
//! any work, and a run whose cost is far beyond the usual starts with a warning that gives the
//! estimate and the option that changes it.
//!
//! - [`threads`]: `--threads` from 1 to [`MAX_THREADS`]; the worker pool is built once;
//! - [`samples`] / [`tolerance`]: `--samples` up to [`MAX_SAMPLES`], `--tolerance` down to
//!   [`MIN_TOLERANCE`](lambert::viewfactor::limits::MIN_TOLERANCE);
//! - [`mesh_cost`]: a mesh surface with more patches than the dense limit, on a method that
//!   integrates every patch pair.
use lambert::scene::{Scene, Shape};
use lambert::viewfactor::Method;
use lambert::{Error, Result};
use std::sync::OnceLock;

/// Most worker threads: the view-factor engine keeps four rows in flight per thread within
/// its 4,096-row wave, and beyond about a thousand threads their stacks alone reserve
/// gigabytes of address space; no machine lambert runs on gains from more.
pub const MAX_THREADS: usize = 1024;
pub use lambert::viewfactor::limits::MAX_SAMPLES;
/// Patch pairs per CPU-second of the exact methods on geometry that is not a regular grid
/// (README "Performance", validation/speed.md), for the cost estimate.
pub const PAIRS_PER_CPU_SECOND: f64 = 1e7;
/// Patches of one mesh surface above which a pairwise run is warned about its cost: `solve`'s
/// dense limit (above it `--exchange auto` clusters the patches).
pub const MESH_PATCH_WARN: usize = lambert::plan::HIERARCHICAL_MIN_PATCHES;

/// The worker-thread count of the first configured run in this process.
static POOL: OnceLock<usize> = OnceLock::new();

/// Checks `--threads` and builds the worker pool (once per process; a later call keeps it).
pub fn threads(n: usize) -> Result<()> {
    if !(1..=MAX_THREADS).contains(&n) {
        return Err(Error::Usage(format!("--threads {n}: give 1 to {MAX_THREADS} worker threads")));
    }
    if POOL.get().is_some() {
        return Ok(());
    }
    rayon::ThreadPoolBuilder::new().num_threads(n).build_global().map_err(|e| {
        Error::Usage(format!("--threads {n}: the worker threads cannot be started ({e}); give fewer"))
    })?;
    let _ = POOL.set(n);
    Ok(())
}

/// Checks `--samples`.
pub fn samples(n: usize) -> Result<usize> {
    if n == 0 {
        return Err(Error::Usage("--samples must be at least 1".into()));
    }
    if n > MAX_SAMPLES {
        return Err(Error::Usage(format!(
            "--samples {n} is above the cap of {MAX_SAMPLES} per patch: the standard error is already below \
             5e-5·√F there; for tighter factors use -m auto with --tolerance (exact where the view is clear)"
        )));
    }
    Ok(n)
}

/// Checks a tolerance given as `what` (`--tolerance`, or a scene file's View3D `eps`).
pub fn tolerance(t: f64, what: &str) -> Result<f64> {
    lambert::viewfactor::limits::tolerance(t, what)
}

/// Thousands separators for a count.
fn grouped(n: usize) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (k, c) in s.chars().enumerate() {
        if k > 0 && (s.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A duration in words (s, min, h, days).
fn duration(secs: f64) -> String {
    match secs {
        s if s < 120.0 => format!("{s:.0} s"),
        s if s < 7200.0 => format!("{:.0} min", s / 60.0),
        s if s < 172_800.0 => format!("{:.1} h", s / 3600.0),
        s => format!("{:.0} days", s / 86_400.0),
    }
}

/// The warning for a pairwise run (`auto`, `analytic`) on a scene whose largest mesh surface
/// has more than [`MESH_PATCH_WARN`] patches: the pair count and time estimate at
/// [`PAIRS_PER_CPU_SECOND`] on `threads`, and what changes it (`alternative`).
pub fn mesh_cost(scene: &Scene, method: Method, threads: usize, alternative: &str) -> Option<String> {
    if !method.is_symmetric() {
        return None;
    }
    let big = scene
        .surfaces
        .iter()
        .filter(|s| s.shape == Shape::Mesh && s.patches.len() > MESH_PATCH_WARN)
        .max_by_key(|s| s.patches.len())?;
    let n = scene.patches.len();
    let pairs = n as f64 * (n as f64 + 1.0) / 2.0;
    let secs = pairs / (PAIRS_PER_CPU_SECOND * threads.max(1) as f64);
    Some(format!(
        "surface '{}' is a mesh of {} triangles, each one patch: the {} patches make {pairs:.1e} pairs, about {} \
         at ~{PAIRS_PER_CPU_SECOND:.0e} pairs per CPU-second on {threads} thread(s); {alternative}",
        big.name,
        grouped(big.patches.len()),
        grouped(n),
        duration(secs)
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use lambert::geometry::{DVec3, Polygon};

    #[test]
    fn option_ranges() {
        assert!(threads(0).is_err());
        let e = threads(MAX_THREADS + 1).unwrap_err();
        assert_eq!(e.exit_code(), 2);
        assert!(e.to_string().contains("--threads 1025"), "{e}");
        assert_eq!(samples(MAX_SAMPLES).unwrap(), MAX_SAMPLES);
        let e = samples(1_000_000_000).unwrap_err();
        assert!(e.to_string().contains("--samples 1000000000") && e.to_string().contains("cap"), "{e}");
        assert!(samples(0).is_err());
        assert_eq!(tolerance(1e-13, "--tolerance").unwrap(), 1e-13);
        let e = tolerance(1e-300, "--tolerance").unwrap_err();
        assert!(e.to_string().contains("--tolerance 1e-300") && e.to_string().contains("round-off"), "{e}");
        assert!(tolerance(f64::NAN, "--tolerance").is_err() && tolerance(1.0, "--tolerance").is_err());
    }

    #[test]
    fn words_for_counts_and_times() {
        assert_eq!(grouped(980_000), "980,000");
        assert_eq!(grouped(12), "12");
        assert_eq!(grouped(1_000), "1,000");
        assert_eq!(duration(30.0), "30 s");
        assert_eq!(duration(600.0), "10 min");
        assert_eq!(duration(16_200.0), "4.5 h");
        assert_eq!(duration(864_000.0), "10 days");
    }

    #[test]
    fn a_large_mesh_surface_is_costed() {
        let tri = |k: usize| {
            let x = k as f64;
            Polygon::new(vec![
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 1.0, 0.0, 0.0),
                DVec3::new(x, 1.0, 0.0),
            ])
            .unwrap()
        };
        let n = MESH_PATCH_WARN + 1;
        let mut b = Scene::builder();
        b.push_surface("part", Shape::Mesh, (0..n).map(tri).collect(), 1.0, None);
        b.push_surface("small", Shape::Mesh, (0..10).map(tri).collect(), 1.0, None);
        let scene = b.build();
        let w = mesh_cost(&scene, Method::Auto, 2, "coarsen it").expect("warned");
        let pairs = (n + 10) as f64 * (n + 11) as f64 / 2.0;
        assert!(
            w.contains("'part'") && w.contains("12,001 triangles") && w.contains("12,011 patches"),
            "{w}"
        );
        assert!(w.contains(&format!("{pairs:.1e} pairs")) && w.contains("coarsen it"), "{w}");
        // 7.2e7 pairs at 2e7 per second: 4 s.
        assert!(w.contains("about 4 s"), "{w}");
        assert!(mesh_cost(&scene, Method::McCosine, 2, "").is_none());
        let mut small = Scene::builder();
        small.push_surface("part", Shape::Mesh, (0..MESH_PATCH_WARN).map(tri).collect(), 1.0, None);
        assert!(mesh_cost(&small.build(), Method::Analytic, 2, "").is_none());
    }
}
