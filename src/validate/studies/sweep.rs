//! One measured run of a method on a study scene: wall time and error, or why it has none.
use crate::report::charts::{Series, Style};
use crate::scene::Scene;
use crate::viewfactor::{self, Level, Method, Params, ViewFactors};
use crate::Error;
use std::fmt::Write;
use std::time::Instant;

/// A measured point.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Method.
    pub method: Method,
    /// Knob value (samples, resolution, tolerance, or the study's parameter).
    pub knob: f64,
    /// Wall time, s.
    pub seconds: f64,
    /// The study's error measure; `None` when the method refused or failed.
    pub error: Option<f64>,
    /// Why there is no error value.
    pub note: Option<String>,
}

/// Runs `method` with `params` on `scene` at surface level and measures `error(vf)`.
pub fn measure(scene: &Scene, params: &Params, knob: f64, error: &dyn Fn(&ViewFactors) -> f64) -> Point {
    let start = Instant::now();
    let result = viewfactor::compute(scene, params, Level::Surface);
    let seconds = start.elapsed().as_secs_f64();
    let (error, note) = match result {
        Ok(vf) => (Some(error(&vf)), None),
        Err(Error::Unsupported(why)) => (None, Some(format!("n/a: {why}"))),
        Err(e) => (None, Some(format!("failed: {e}"))),
    };
    Point { method: params.method, knob, seconds, error, note }
}

/// Chart series, one per method, mapping each point through `xy`.
pub fn series(
    points: &[Point],
    methods: &[Method],
    xy: impl Fn(&Point) -> Option<(f64, f64)>,
) -> Vec<Series> {
    methods
        .iter()
        .filter_map(|&m| {
            let pts: Vec<(f64, f64)> = points.iter().filter(|p| p.method == m).filter_map(&xy).collect();
            // `auto` often coincides with analytic: dashed, drawn over it, both stay visible.
            let (color, dashed) = m.colour();
            let style = if dashed { Style::Dashed } else { Style::LinePoints };
            (!pts.is_empty()).then(|| Series { name: m.to_string(), points: pts, color, style })
        })
        .collect()
}

/// A markdown table of the points: method, knob, time, error, note.
pub fn table(points: &[Point], knob: &str, error: &str) -> String {
    let mut s = format!("| method | {knob} | time [s] | {error} | note |\n|---|---:|---:|---:|---|\n");
    for p in points {
        let e = p.error.map(|e| format!("{e:.3e}")).unwrap_or_else(|| "–".into());
        let knob = if p.knob.fract() == 0.0 && p.knob.abs() < 1e9 {
            format!("{}", p.knob)
        } else {
            format!("{:e}", p.knob)
        };
        let _ = writeln!(
            s,
            "| {} | {} | {:.4} | {} | {} |",
            p.method,
            knob,
            p.seconds,
            e,
            p.note.as_deref().unwrap_or("").replace('|', "/")
        );
    }
    s
}
