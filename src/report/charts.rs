//! Log–log line charts (plotters, SVG and PNG) for the validation studies: error against time,
//! against a degeneracy parameter, or against the sample count. Text uses the vendored
//! DejaVu Sans registered as "sans-serif" (no system font libraries).
use crate::{Error, Result};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

static FONT: &[u8] = include_bytes!("../../assets/DejaVuSans.ttf");
static REGISTER: Once = Once::new();

/// Chart size in pixels (PNG) and user units (SVG).
pub const SIZE: (u32, u32) = (960, 620);
/// Values below this are drawn at it (log axes cannot show 0); the chart notes it.
pub const LOG_FLOOR: f64 = 1e-17;

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
    /// Points; non-positive coordinates are clamped to [`LOG_FLOOR`].
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
    /// Put the legend in the lower left instead of the upper right.
    pub legend_lower_left: bool,
}

/// A fixed colour per method so every chart agrees.
pub fn method_color(name: &str) -> (u8, u8, u8) {
    match name {
        "analytic" => (0, 0, 0),
        "auto" => (120, 120, 120),
        "hemicube" => (31, 119, 180),
        "single-plane" => (23, 190, 207),
        "mc-area" => (214, 39, 40),
        "mc-uniform" => (255, 127, 14),
        "mc-cosine" => (44, 160, 44),
        _ => (148, 103, 189),
    }
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
    if (1e-2..1e4).contains(&v) {
        format!("{}", (v * 1e3).round() / 1e3)
    } else {
        format!("{v:.0e}")
    }
}

/// Axis range covering `values`, widened to whole decades.
fn decade_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() || hi <= 0.0 {
        return (0.1, 1.0);
    }
    let lo = 10f64.powf(lo.log10().floor());
    let mut hi = 10f64.powf(hi.log10().ceil());
    if hi <= lo {
        hi = lo * 10.0;
    }
    (lo, hi)
}

fn clamp(p: (f64, f64)) -> (f64, f64) {
    (p.0.max(LOG_FLOOR), p.1.max(LOG_FLOOR))
}

fn draw<DB: DrawingBackend>(root: DrawingArea<DB, Shift>, chart: &Chart) -> std::result::Result<(), String> {
    let e = |x: DrawingAreaErrorKind<DB::ErrorType>| x.to_string();
    root.fill(&WHITE).map_err(e)?;
    let pts = || chart.series.iter().flat_map(|s| s.points.iter().copied().map(clamp));
    let (x0, x1) = decade_range(pts().map(|p| p.0));
    let (y0, y1) = decade_range(pts().map(|p| p.1));
    let mut ctx = ChartBuilder::on(&root)
        .caption(&chart.title, ("sans-serif", 22))
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
    for s in &chart.series {
        let color = RGBColor(s.color.0, s.color.1, s.color.2);
        let points: Vec<(f64, f64)> = s.points.iter().copied().map(clamp).collect();
        let line = color.stroke_width(2);
        match s.style {
            Style::LinePoints => {
                ctx.draw_series(LineSeries::new(points.clone(), line))
                    .map_err(e)?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], color.stroke_width(2)));
                ctx.draw_series(points.iter().map(|p| Circle::new(*p, 4, color.filled()))).map_err(e)?;
            }
            Style::Dashed => {
                ctx.draw_series(DashedLineSeries::new(points, 8, 6, line))
                    .map_err(e)?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 22, y)], color.stroke_width(1)));
            }
            Style::Points => {
                ctx.draw_series(points.iter().map(|p| Circle::new(*p, 4, color.filled())))
                    .map_err(e)?
                    .label(s.name.as_str())
                    .legend(move |(x, y)| Circle::new((x + 11, y), 4, color.filled()));
            }
        }
    }
    ctx.configure_series_labels()
        .position(if chart.legend_lower_left {
            SeriesLabelPosition::LowerLeft
        } else {
            SeriesLabelPosition::UpperRight
        })
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(e)
}

/// Writes `chart` as `<stem>.svg` and `<stem>.png` in `dir`.
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
        assert_eq!(decade_range([0.03, 7.0].into_iter()), (0.01, 10.0));
    }

    #[test]
    fn writes_svg_and_png() {
        let dir = tempfile::tempdir().unwrap();
        let chart = Chart {
            title: "test".into(),
            x_label: "samples N".into(),
            y_label: "error".into(),
            series: vec![
                Series {
                    name: "a".into(),
                    points: vec![(1.0, 1.0), (100.0, 0.1)],
                    color: (0, 0, 0),
                    style: Style::LinePoints,
                },
                Series {
                    name: "b".into(),
                    points: vec![(1.0, 0.0), (100.0, 0.01)],
                    color: (200, 0, 0),
                    style: Style::Dashed,
                },
            ],
            legend_lower_left: false,
        };
        write(&chart, dir.path(), "t").unwrap();
        let svg = std::fs::read_to_string(dir.path().join("t.svg")).unwrap();
        assert!(svg.contains("samples N") && svg.contains("font-family=\"sans-serif\""));
        assert!(std::fs::metadata(dir.path().join("t.png")).unwrap().len() > 1000);
    }
}
