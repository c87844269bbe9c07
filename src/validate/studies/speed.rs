//! Speed–accuracy: error against wall time for every method across its knob (Monte Carlo
//! samples, hemicube / single-plane resolution, analytic / auto tolerance) on the cube
//! interior, the squares with a blocker and the obstructed room.
use super::scenes;
use super::sweep::{measure, series, table, Point};
use crate::report::charts::{self, Chart};
use crate::scene::Scene;
use crate::validate::runner::METHODS;
use crate::viewfactor::accuracy::Knob;
use crate::viewfactor::{Params, ViewFactors};
use crate::Result;
use std::path::Path;

/// A run longer than this stops the sweep of that method: the next knob step costs 2–4×
/// more, so no single run much exceeds a minute.
const TIME_CAP_S: f64 = 20.0;

/// A study scene: file stem, title, scene, error measure.
type Study = (&'static str, String, Scene, Box<dyn Fn(&ViewFactors) -> f64>);

/// Knob values per method family.
struct Knobs {
    samples: Vec<usize>,
    resolutions: Vec<usize>,
    tolerances: Vec<f64>,
}

fn sweep(
    scene: &Scene,
    error: &dyn Fn(&ViewFactors) -> f64,
    k: &Knobs,
    progress: &mut dyn FnMut(&str),
) -> Vec<Point> {
    let mut points = Vec::new();
    for method in METHODS {
        let runs: Vec<(f64, Params)> = match method.knob() {
            Knob::Tolerance => k
                .tolerances
                .iter()
                .map(|&t| (t, Params { method, tolerance: t, ..Params::default() }))
                .collect(),
            Knob::Resolution => k
                .resolutions
                .iter()
                .map(|&r| (r as f64, Params { method, resolution: r, ..Params::default() }))
                .collect(),
            Knob::Samples => k
                .samples
                .iter()
                .map(|&n| (n as f64, Params { method, samples: n, seed: 1, ..Params::default() }))
                .collect(),
        };
        for (knob, params) in runs {
            let p = measure(scene, &params, knob, error);
            let stop = p.error.is_none() || p.seconds > TIME_CAP_S;
            progress(&format!(
                "  {:<13} knob {:<8e} {:>8.3} s  error {}",
                method,
                knob,
                p.seconds,
                p.error.map(|e| format!("{e:.2e}")).unwrap_or_else(|| p.note.clone().unwrap_or_default())
            ));
            points.push(p);
            if stop {
                break;
            }
        }
    }
    points
}

/// Runs the sweeps, writes `speed_accuracy_<scene>.{svg,png}` and returns the report section.
pub fn run(quick: bool, out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String> {
    let knobs = if quick {
        Knobs { samples: vec![100, 1000], resolutions: vec![32, 128], tolerances: vec![1e-3, 1e-6] }
    } else {
        Knobs {
            samples: vec![30, 100, 300, 1000, 3000, 10_000, 30_000],
            resolutions: vec![32, 64, 128, 256, 512, 1024],
            tolerances: vec![1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-8],
        }
    };
    let (cube_n, room_n) = if quick { (4, None) } else { (8, Some((12, 6))) };
    let blocked = |vf: &ViewFactors| (vf.get(0, 1) - scenes::BLOCKED_SQUARES).abs();
    let mut studies: Vec<Study> = vec![
        (
            "cube",
            format!("unit cube interior, {cube_n}×{cube_n} patches per face"),
            scenes::cube(cube_n),
            Box::new(scenes::cube_error),
        ),
        (
            "blocked_squares",
            "unit squares 1 apart with a centred blocker, 4×4 patches each".into(),
            scenes::blocked_squares(4),
            Box::new(blocked),
        ),
    ];
    if let Some((nr, nb)) = room_n {
        studies.push((
            "room",
            format!("obstructed room, {nr}×{nr} per room face, {nb}×{nb} per block face"),
            scenes::room(nr, nb),
            Box::new(scenes::room_error),
        ));
    }
    let mut md = String::from("## Speed–accuracy\n\nError against wall time for every method across its knob: Monte Carlo samples per patch, hemicube / single-plane resolution, analytic / auto tolerance. Error = largest |F_IJ − F_exact| over the reported surface pairs. Times are wall-clock on this machine with all threads.\n");
    for (stem, title, scene, error) in &studies {
        progress(&format!("speed–accuracy: {title}"));
        let points = sweep(scene, error.as_ref(), &knobs, progress);
        let chart = Chart {
            title: format!("Speed–accuracy: {title}"),
            x_label: "wall time [s]".into(),
            y_label: "max |F − F_exact|".into(),
            series: series(&points, &METHODS, |p| Some((p.seconds, p.error?))),
        };
        let file = format!("speed_accuracy_{stem}");
        charts::write(&chart, out, &file)?;
        md.push_str(&format!("\n### {title}\n\n![{title}]({file}.png)\n\n"));
        md.push_str(&table(&points, "knob", "max abs. error"));
    }
    Ok(md)
}
