//! Monte Carlo convergence: RMS error over seeds against samples per patch for the three
//! estimators, with the 1/√N (independent sampling) and N^−0.656 (scrambled Sobol on this
//! 4-D integrand, docs/literature.md §4) slopes drawn.
use super::scenes;
use crate::report::charts::{self, okabe_ito, Chart, Series, Style};
use crate::viewfactor::{self, Level, Method, Params};
use crate::Result;
use std::fmt::Write;
use std::path::Path;

/// Fitted RQMC slope of scrambled Sobol on point-plus-direction sampling (docs/literature.md §4).
const SOBOL_SLOPE: f64 = -0.656;

/// Runs the sweep, writes `mc_convergence.{svg,png}` and returns the report section.
pub fn run(quick: bool, out: &Path, progress: &mut dyn FnMut(&str)) -> Result<String> {
    let (ns, seeds): (Vec<usize>, u64) = if quick {
        (vec![100, 1000, 10_000], 4)
    } else {
        (vec![100, 316, 1000, 3162, 10_000, 31_623, 100_000, 316_228, 1_000_000], 16)
    };
    let (scene, exact) = scenes::parallel_far(1.0, 1);
    let mut md = format!(
        "## Monte Carlo convergence\n\nF(a → b) of opposed unit squares at gap 1 (one patch each, exact {exact:.12}); RMS error over {seeds} seeds against samples per patch, and the mean reported standard error. The dashed lines are the 1/√N slope and the N^{SOBOL_SLOPE} slope that scrambled Sobol points reach on this discontinuous 4-D integrand (docs/literature.md §4).\n\n| method | samples | RMS error | mean reported σ | σ / RMS |\n|---|---:|---:|---:|---:|\n"
    );
    let mut series = Vec::new();
    let mut anchor = None;
    for method in [Method::McArea, Method::McUniform, Method::McCosine] {
        let mut pts = Vec::new();
        for &n in &ns {
            let (mut sq, mut sig, mut runs) = (0.0, 0.0, 0u64);
            for seed in 0..seeds {
                let params = Params { method, samples: n, seed: seed + 1, ..Params::default() };
                match viewfactor::compute(&scene, &params, Level::Surface) {
                    Ok(vf) => {
                        let e = vf.rows[0].iter().find(|e| e.to == 1);
                        let (f, s) = e.map(|e| (e.factor, e.std_error)).unwrap_or((0.0, 0.0));
                        sq += (f - exact) * (f - exact);
                        sig += s;
                        runs += 1;
                    }
                    Err(e) => {
                        let _ =
                            writeln!(md, "| {method} | {n} | – | – | {} |", e.to_string().replace('|', "/"));
                        break;
                    }
                }
            }
            if runs == 0 {
                break;
            }
            let rms = (sq / runs as f64).sqrt();
            let sigma = sig / runs as f64;
            let _ =
                writeln!(md, "| {method} | {n} | {rms:.3e} | {sigma:.3e} | {:.2} |", sigma / rms.max(1e-300));
            progress(&format!("  mc convergence {method} N={n}: rms {rms:.2e}, σ {sigma:.2e}"));
            pts.push((n as f64, rms));
        }
        if method == Method::McCosine {
            anchor = pts.first().copied();
        }
        if !pts.is_empty() {
            series.push(Series {
                name: method.to_string(),
                points: pts,
                color: method.colour().0,
                style: Style::LinePoints,
            });
        }
    }
    if let Some((n0, e0)) = anchor {
        let n1 = *ns.last().expect("non-empty sweep") as f64;
        for (name, slope, color) in [
            ("slope −1/2", -0.5, okabe_ito::GREY),
            ("slope −0.656 (Sobol)", SOBOL_SLOPE, okabe_ito::REDDISH_PURPLE),
        ] {
            series.push(Series {
                name: name.into(),
                points: vec![(n0, e0), (n1, e0 * (n1 / n0).powf(slope))],
                color,
                style: Style::Dashed,
            });
        }
    }
    let chart = Chart {
        title: "Monte Carlo convergence: opposed unit squares at gap 1".into(),
        x_label: "samples per patch N".into(),
        y_label: "RMS error of F over seeds".into(),
        series,
    };
    charts::write(&chart, out, "mc_convergence")?;
    md.push_str("\n![Monte Carlo convergence](mc_convergence.png)\n");
    Ok(md)
}
