//! Log–log line charts (plotters, SVG and PNG) for the validation studies: error against time,
//! against a degeneracy parameter, or against the sample count. Text uses the vendored
//! DejaVu Sans registered as "sans-serif" (no system font libraries).
//!
//! - layout: the plot on the left, the legend in its own panel on the right (never over data);
//! - axes: fitted to the positive values with a small margin (not widened to whole decades);
//! - lines join points in x order; a value a log axis cannot show (zero, negative) is drawn as
//!   an arrow at the edge it lies beyond, and the legend says so;
//! - colours: the Okabe–Ito palette (colour-blind safe), one fixed colour per method (its row
//!   in the method registry, `crate::viewfactor::registry`);
//! - files: `<stem>.svg`, `<stem>.png` and `<stem>.csv` (columns `series,x,y`, the numbers drawn).
use crate::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Chart size in pixels (PNG) and user units (SVG).
pub const SIZE: (u32, u32) = (1060, 620);
/// Width of the legend panel right of the plot, pixels: room for "slope −0.656 (Sobol)".
const LEGEND_W: u32 = 230;
/// Margin added beyond the data on each log axis, decades: markers stay clear of the frame.
const PAD_DECADES: f64 = 0.08;
/// Line width of every series, pixels (the legend samples use the same).
const LINE_W: u32 = 2;
/// Dash and gap lengths of dashed series, pixels (plot and legend alike).
const DASH: (u32, u32) = (8, 6);

/// The Okabe–Ito palette ([`crate::palette`]), under the name the charts use.
pub use crate::palette as okabe_ito;

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// Markers joined by a solid line.
    LinePoints,
    /// A dashed line without markers (reference slopes, bounds).
    Dashed,
    /// Markers only.
    Points,
}

/// One named series of (x, y) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend entry.
    pub name: String,
    /// Points in any order; lines join them in x order. Non-positive coordinates are drawn as
    /// arrows at the edge of the axis.
    pub points: Vec<(f64, f64)>,
    /// Colour, RGB.
    pub color: (u8, u8, u8),
    /// Drawing style.
    pub style: Style,
}

/// A log–log chart.
#[derive(Debug, Clone, PartialEq)]
pub struct Chart {
    /// Caption.
    pub title: String,
    /// X axis description with units.
    pub x_label: String,
    /// Y axis description with units.
    pub y_label: String,
    /// The series.
    pub series: Vec<Series>,
}

/// Registers the vendored font as "sans-serif" (once per process).
pub(crate) fn register_font() {
    REGISTER.call_once(|| {
        // The font is compiled in; registration only fails on a corrupt file, caught by tests.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT);
    });
}

/// Tick label for a log axis: powers of ten as `1e-6`, others compactly.
fn log_label(v: f64) -> String {
    if v <= 0.0 {
        return "0".into();
    }
    let e = v.log10();
    if (e - e.round()).abs() < 1e-9 {
        let e = e.round() as i32;
        return match e {
            -2..=3 => format!("{}", 10f64.powi(e)),
            _ => format!("1e{e}"),
        };
    }
    // Between decades only 2 and 5 × 10^k are labelled: plotters ticks every integer
    // multiple, and on a short axis their labels run into each other.
    let m = v / 10f64.powf(e.floor());
    if !((m - 2.0).abs() < 1e-6 || (m - 5.0).abs() < 1e-6) {
        return String::new();
    }
    if (1e-2..1e4).contains(&v) {
        format!("{}", (v * 1e3).round() / 1e3)
    } else {
        format!("{v:.0e}")
    }
}

/// True when a log axis can show `v`.
fn shown(v: f64) -> bool {
    v > 0.0 && v.is_finite()
}

/// Log-axis range covering the positive finite `values` with [`PAD_DECADES`] on each side;
/// one decade around a single value; (0.1, 1) when there is none.
fn fitted_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) =
        values.filter(|v| shown(*v)).fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return (0.1, 1.0);
    }
    let pad = if hi > lo { 10f64.powf(PAD_DECADES) } else { 10f64.sqrt() };
    (lo / pad, hi * pad)
}

/// Points of `s` in x order (stable for equal x).
fn sorted(s: &Series) -> Vec<(f64, f64)> {
    let mut p = s.points.clone();
    p.sort_by(|a, b| a.0.total_cmp(&b.0));
    p
}

/// Runs of consecutive points (in x order) that the axes can show: the pieces of a line.
fn runs(points: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
    let mut out: Vec<Vec<(f64, f64)>> = vec![Vec::new()];
    for &p in points {
        if shown(p.0) && shown(p.1) {
            out.last_mut().expect("never empty").push(p);
        } else if !out.last().expect("never empty").is_empty() {
            out.push(Vec::new());
        }
    }
    out.retain(|r| !r.is_empty());
    out
}

/// Pixel geometry of an edge arrow: head length and half width, stem length.
const ARROW: (i32, i32, i32) = (9, 5, 12);

/// An arrow in `color` whose tip sits at `tip`, pointing along `dir` (unit, pixels).
fn arrow<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    tip: (i32, i32),
    dir: (i32, i32),
    color: RGBColor,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (len, half, stem) = ARROW;
    let base = (tip.0 - dir.0 * len, tip.1 - dir.1 * len);
    let side = (dir.1 * half, -dir.0 * half);
    area.draw(&Polygon::new(
        vec![tip, (base.0 + side.0, base.1 + side.1), (base.0 - side.0, base.1 - side.1)],
        color.filled(),
    ))?;
    area.draw(&PathElement::new(
        vec![base, (base.0 - dir.0 * stem, base.1 - dir.1 * stem)],
        color.stroke_width(LINE_W),
    ))
}

/// A dashed polyline through pixel points, [`DASH`] pattern: the legend sample of a dashed series.
fn dashes(x0: i32, x1: i32, y: i32) -> Vec<[(i32, i32); 2]> {
    let (on, off) = (DASH.0 as i32, DASH.1 as i32);
    (0..)
        .map(|k| x0 + k * (on + off))
        .take_while(|&a| a < x1)
        .map(|a| [(a, y), ((a + on).min(x1), y)])
        .collect()
}

/// Largest font size from `sizes` at which `text` fits in `width` pixels (the smallest if none).
fn fitting_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    text: &str,
    width: u32,
    sizes: &[u32],
) -> u32 {
    let fits = |s: u32| {
        area.estimate_text_size(text, &("sans-serif", s).into_text_style(area)).is_ok_and(|(w, _)| w <= width)
    };
    sizes.iter().copied().find(|&s| fits(s)).unwrap_or(*sizes.last().expect("sizes given"))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, chart: &Chart) -> std::result::Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let title_size = fitting_size(&root, &chart.title, SIZE.0 - 24, &[22, 20, 18, 16, 14]);
    let body = root.titled(&chart.title, ("sans-serif", title_size)).map_err(e)?;
    let (plot, legend) = body.split_horizontally(SIZE.0 - LEGEND_W);
    let pts = || chart.series.iter().flat_map(|s| s.points.iter().copied());
    let (x0, x1) = fitted_range(pts().map(|p| p.0));
    let (y0, y1) = fitted_range(pts().map(|p| p.1));
    let mut ctx = ChartBuilder::on(&plot)
        .margin(14)
        .x_label_area_size(52)
        .y_label_area_size(78)
        .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
        .map_err(e)?;
    ctx.configure_mesh()
        .x_desc(&chart.x_label)
        .y_desc(&chart.y_label)
        .axis_desc_style(("sans-serif", 17))
        .label_style(("sans-serif", 14))
        .x_label_formatter(&|v| log_label(*v))
        .y_label_formatter(&|v| log_label(*v))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(200, 200, 200))
        .draw()
        .map_err(e)?;
    let (px, py) = ctx.plotting_area().get_pixel_range();
    let mut clipped = false;
    for s in &chart.series {
        let color = RGBColor(s.color.0, s.color.1, s.color.2);
        let points = sorted(s);
        let line = color.stroke_width(LINE_W);
        for run in runs(&points) {
            match s.style {
                Style::LinePoints => {
                    ctx.draw_series(LineSeries::new(run, line)).map_err(e)?;
                }
                Style::Dashed => {
                    ctx.draw_series(DashedLineSeries::new(run, DASH.0, DASH.1, line)).map_err(e)?;
                }
                Style::Points => {}
            }
        }
        if s.style != Style::Dashed {
            let inside = points.iter().filter(|p| shown(p.0) && shown(p.1));
            ctx.draw_series(inside.map(|p| Circle::new(*p, 4, color.filled()))).map_err(e)?;
        }
        // Values the log axes cannot show: an arrow just inside the edge they lie beyond.
        for &(x, y) in points.iter().filter(|p| !(shown(p.0) && shown(p.1))) {
            clipped = true;
            let (ax, ay) = ctx.backend_coord(&(if shown(x) { x } else { x0 }, if shown(y) { y } else { y0 }));
            if !shown(y) {
                arrow(&plot, (ax, py.end - 3), (0, 1), color).map_err(e)?;
            } else {
                arrow(&plot, (px.start + 3, ay), (-1, 0), color).map_err(e)?;
            }
        }
    }
    draw_legend(&legend, chart, clipped, py.start).map_err(e)?;
    root.present().map_err(e)
}

/// The legend panel: a sample of each series drawn exactly as in the plot, its name, and a
/// note on edge arrows when there are any.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    chart: &Chart,
    clipped: bool,
    top: i32,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font().color(&BLACK);
    let row = 24;
    let (sx0, sx1, tx) = (6, 38, 46);
    let mut y = top.max(0) + 10;
    for s in &chart.series {
        let color = RGBColor(s.color.0, s.color.1, s.color.2);
        match s.style {
            Style::LinePoints => {
                area.draw(&PathElement::new(vec![(sx0, y), (sx1, y)], color.stroke_width(LINE_W)))?;
                area.draw(&Circle::new(((sx0 + sx1) / 2, y), 4, color.filled()))?;
            }
            Style::Dashed => {
                for d in dashes(sx0, sx1, y) {
                    area.draw(&PathElement::new(d.to_vec(), color.stroke_width(LINE_W)))?;
                }
            }
            Style::Points => area.draw(&Circle::new(((sx0 + sx1) / 2, y), 4, color.filled()))?,
        }
        area.draw(&Text::new(s.name.clone(), (tx, y - 8), font.clone()))?;
        y += row;
    }
    if clipped {
        y += row / 2;
        arrow(area, ((sx0 + sx1) / 2, y + 8), (0, 1), RGBColor(80, 80, 80))?;
        for (k, line) in ["zero or negative:", "drawn at the axis edge"].iter().enumerate() {
            area.draw(&Text::new(*line, (tx, y - 8 + k as i32 * 18), font.clone()))?;
        }
    }
    Ok(())
}

/// The chart's numbers as CSV: `series,x,y`, one row per point in the series' x order.
pub fn csv(chart: &Chart) -> String {
    let mut out = String::from("series,x,y\n");
    for s in &chart.series {
        let name = if s.name.contains([',', '"']) {
            format!("\"{}\"", s.name.replace('"', "\"\""))
        } else {
            s.name.clone()
        };
        for (x, y) in sorted(s) {
            let _ = writeln!(out, "{name},{x},{y}");
        }
    }
    out
}

/// Writes `chart` as `<stem>.svg`, `<stem>.png` and its numbers as `<stem>.csv` in `dir`.
pub fn write(chart: &Chart, dir: &Path, stem: &str) -> Result<()> {
    register_font();
    let fail = |path: &Path, msg: String| Error::Io {
        path: path.to_path_buf(),
        source: std::io::Error::other(format!("cannot write the chart: {msg}")),
    };
    let svg = dir.join(format!("{stem}.svg"));
    draw(SVGBackend::new(&svg, SIZE).into_drawing_area(), chart).map_err(|m| fail(&svg, m))?;
    let png = dir.join(format!("{stem}.png"));
    draw(BitMapBackend::new(&png, SIZE).into_drawing_area(), chart).map_err(|m| fail(&png, m))?;
    let path = dir.join(format!("{stem}.csv"));
    std::fs::write(&path, csv(chart)).map_err(|source| Error::Io { path, source })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_and_ranges() {
        assert_eq!(log_label(1e-6), "1e-6");
        assert_eq!(log_label(0.01), "0.01");
        assert_eq!(log_label(100.0), "100");
        assert_eq!(
            (log_label(0.02), log_label(5e-3), log_label(3e-3), log_label(70.0)),
            ("0.02".into(), "5e-3".into(), String::new(), String::new())
        );
        // Fitted to the data with a small margin, zeros and negatives ignored.
        let (lo, hi) = fitted_range([0.03, 7.0, 0.0, -1.0].into_iter());
        let pad = 10f64.powf(PAD_DECADES);
        assert!((lo - 0.03 / pad).abs() < 1e-15 && (hi - 7.0 * pad).abs() < 1e-12, "{lo} {hi}");
        assert!(hi > 7.0 && hi < 10.0);
        assert_eq!(fitted_range([0.0].into_iter()), (0.1, 1.0));
    }

    #[test]
    fn lines_follow_x_and_break_at_unshowable_values() {
        let s = Series {
            name: "a".into(),
            points: vec![(3.0, 1.0), (1.0, 2.0), (4.0, 0.0), (2.0, 5.0), (5.0, 1.0)],
            color: (0, 0, 0),
            style: Style::LinePoints,
        };
        let p = sorted(&s);
        assert_eq!(p.iter().map(|q| q.0).collect::<Vec<_>>(), vec![1.0, 2.0, 3.0, 4.0, 5.0]);
        assert_eq!(runs(&p), vec![vec![(1.0, 2.0), (2.0, 5.0), (3.0, 1.0)], vec![(5.0, 1.0)]]);
        let chart = Chart { title: "t".into(), x_label: "x".into(), y_label: "y".into(), series: vec![s] };
        assert_eq!(csv(&chart), "series,x,y\na,1,2\na,2,5\na,3,1\na,4,0\na,5,1\n");
    }

    /// The legend sits right of the plot, its dashed sample has gaps like the plotted line,
    /// and a zero value is an arrow at the bottom edge, not a marker on the frame.
    #[test]
    fn legend_outside_dashes_and_edge_arrows() {
        let dir = tempfile::tempdir().unwrap();
        let red = (213, 94, 0);
        let chart = Chart {
            title: "test".into(),
            x_label: "samples N".into(),
            y_label: "error".into(),
            series: vec![
                Series {
                    name: "a".into(),
                    points: vec![(100.0, 0.1), (1.0, 1.0), (10.0, 0.0)],
                    color: red,
                    style: Style::LinePoints,
                },
                Series {
                    name: "b".into(),
                    points: vec![(1.0, 0.5), (100.0, 0.01)],
                    color: (0, 114, 178),
                    style: Style::Dashed,
                },
            ],
        };
        write(&chart, dir.path(), "t").unwrap();
        let svg = std::fs::read_to_string(dir.path().join("t.svg")).unwrap();
        assert!(svg.contains("samples N") && svg.contains("font-family=\"sans-serif\""));
        assert!(svg.contains("drawn at the axis edge"));
        let csv = std::fs::read_to_string(dir.path().join("t.csv")).unwrap();
        assert!(csv.starts_with("series,x,y\na,1,1\na,10,0\n"), "{csv}");
        let img = image::open(dir.path().join("t.png")).unwrap().to_rgb8();
        assert_eq!(img.dimensions(), SIZE);
        let is = |x: u32, y: u32, c: (u8, u8, u8)| img.get_pixel(x, y).0 == [c.0, c.1, c.2];
        let legend_x = SIZE.0 - LEGEND_W;
        // Legend samples of both series lie in the panel right of the plot.
        let count = |c, x0: u32, x1: u32| {
            (0..SIZE.1).flat_map(|y| (x0..x1).map(move |x| (x, y))).filter(|&(x, y)| is(x, y, c)).count()
        };
        assert!(count(red, legend_x, SIZE.0) > 20 && count((0, 114, 178), legend_x, SIZE.0) > 20);
        // The dashed sample: along its row, blue runs separated by gaps.
        let row = (0..SIZE.1)
            .find(|&y| (legend_x..legend_x + 40).filter(|&x| is(x, y, (0, 114, 178))).count() > 6)
            .expect("dashed sample");
        let blue: Vec<bool> = (legend_x..legend_x + 45).map(|x| is(x, row, (0, 114, 178))).collect();
        let starts = blue.windows(2).filter(|w| !w[0] && w[1]).count();
        assert!(starts >= 2, "dashed sample is one solid line: {blue:?}");
        // The zero at x = 10: red arrow pixels in the bottom rows of the plot, none in the plot
        // panel's lowest 40 rows elsewhere than near that column (only the arrow is there).
        let reds: Vec<(u32, u32)> = (SIZE.1 - 120..SIZE.1)
            .flat_map(|y| (0..legend_x).map(move |x| (x, y)))
            .filter(|&(x, y)| is(x, y, red))
            .collect();
        assert!(reds.len() > 15, "no arrow at the bottom edge");
        let (xmin, xmax) = reds.iter().fold((u32::MAX, 0), |(a, b), p| (a.min(p.0), b.max(p.0)));
        assert!(xmax - xmin <= 2 * ARROW.1 as u32 + 2, "arrow spread over {xmin}..{xmax}");
    }
}
