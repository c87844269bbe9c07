//! Stability: relative error against a degeneracy parameter for every method — plates
//! touching, far field, a vanishing receiver, grazing tilt.
use super::scenes;
use super::sweep::{measure, series, table, Point};
use crate::report::charts::{self, Chart};
use crate::scene::Scene;
use crate::validate::runner::METHODS;
use crate::validate::Budget;
use crate::viewfactor::{Method, ViewFactors};
use crate::Result;
use std::path::Path;

/// Touching plates (gap 0) are drawn at this gap on the log axis.
const TOUCHING_AT: f64 = 1e-9;

struct Study {
    stem: &'static str,
    title: &'static str,
    x_label: &'static str,
    /// (parameter, x for the chart)
    params: Vec<(f64, f64)>,
    build: fn(f64, usize) -> (Scene, f64),
}

fn studies(quick: bool) -> Vec<Study> {
    let pick = |full: Vec<f64>, q: Vec<f64>| if quick { q } else { full };
    vec![
        Study {
            stem: "gap",
            title: "Perpendicular unit squares, wall lifted by d (d = 0 touching, drawn at 1e-9)",
            x_label: "gap d / side (touching at 1e-9)",
            params: pick(vec![1.0, 0.3, 0.1, 0.03, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 0.0], vec![1.0, 1e-3, 0.0])
                .into_iter()
                .map(|d| (d, if d == 0.0 { TOUCHING_AT } else { d }))
                .collect(),
            build: scenes::perpendicular_gap,
        },
        Study {
            stem: "far",
            title: "Opposed unit squares at distance c (far field)",
            x_label: "distance / side",
            params: pick(vec![1.0, 3.0, 10.0, 30.0, 100.0, 300.0, 1e3, 3e3, 1e4], vec![1.0, 100.0, 1e4])
                .into_iter()
                .map(|c| (c, c))
                .collect(),
            build: scenes::parallel_far,
        },
        Study {
            stem: "small",
            title: "Receiver square of side s at height 1 over a unit emitter",
            x_label: "receiver side / emitter side",
            params: pick(vec![1.0, 0.3, 0.1, 0.03, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4], vec![1.0, 1e-2, 1e-4])
                .into_iter()
                .map(|s| (s, s))
                .collect(),
            build: scenes::small_receiver,
        },
        Study {
            stem: "tilt",
            title: "Unit emitter tilted by θ under a unit receiver (grazing as θ → 90°)",
            x_label: "90° − θ [degrees]",
            params: pick(vec![0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9, 89.99], vec![0.0, 89.0, 89.99])
                .into_iter()
                .map(|t: f64| (t.to_radians(), 90.0 - t))
                .collect(),
            build: scenes::tilted,
        },
    ]
}

/// Runs the four sweeps, writes `stability_<study>.{svg,png}` and returns the report section.
pub fn run(quick: bool, out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String> {
    let budget = if quick { Budget::quick() } else { Budget::full() };
    let samples = if quick { 2_000 } else { 100_000 };
    let patches = 4;
    let mut md = format!(
        "## Stability\n\nRelative error |F − F_exact| / F_exact of F(a → b) as a configuration degenerates; {patches}×{patches} patches per plate (one patch for the small receiver); Monte Carlo {samples} samples per patch, resolution {}, auto goal {:e}. References: the V4 strip algebra (gap), C-11 with ln_1p then 10-point 2AI (far field), Gauss over the small receiver of Lambert's formula (small), Gauss over the tilted emitter (tilt), all in `src/validate/oracle`. An estimate of 0 counts as relative error 1.\n",
        budget.resolution, budget.auto_tolerance
    );
    for s in studies(quick) {
        progress(&format!("stability: {}", s.title));
        let mut points: Vec<Point> = Vec::new();
        for &(param, x) in &s.params {
            let (scene, exact) = (s.build)(param, patches);
            let rel = move |vf: &ViewFactors| (vf.get(0, 1) - exact).abs() / exact;
            for method in METHODS {
                let mut params = budget.params(method, 1);
                if method.is_monte_carlo() {
                    params.samples = samples;
                }
                let p = measure(&scene, &params, x, &rel);
                points.push(p);
            }
        }
        let shown: Vec<Method> = METHODS.to_vec();
        let chart = Chart {
            title: s.title.into(),
            x_label: s.x_label.into(),
            y_label: "relative error".into(),
            series: series(&points, &shown, |p| Some((p.knob, p.error?))),
        };
        let file = format!("stability_{}", s.stem);
        charts::write(&chart, out, &file)?;
        md.push_str(&format!("\n### {}\n\n![{}]({file}.png)\n\n", s.title, s.title));
        md.push_str(&table(&points, s.x_label, "relative error"));
    }
    Ok(md)
}
