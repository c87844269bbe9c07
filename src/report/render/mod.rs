//! `lambert render`: a false-colour picture of a result on the scene geometry.
//!
//! - [`values`]: one column of a `solve` CSV spread onto the patches;
//! - [`camera`]: the pinhole camera, its default framing and `--camera` syntax;
//! - `raster`: the z-buffer rasteriser with Gouraud (vertex-smoothed) values;
//! - `colormap`: viridis, value range, colour-bar ticks;
//! - this file: triangles from the patch mesh, the picture with outlines, caption and colour
//!   bar (plotters on an RGB buffer, vendored DejaVu Sans), and the PNG file.
//!
//! Surfaces are one-sided: only the front (emitting) side carries a value. Back faces are
//! culled by default (`two_sided` shows them in grey), so from outside a closed enclosure the
//! picture looks through the near walls onto the inside of the far ones.
//!
//! Every face is lit by a headlight (Lambert, [`AMBIENT_LIGHT`] floor) on top of its colour unless
//! `flat`; the colour bar spans the surfaces that show (not hidden ones) unless a range is
//! given, and labels both its ends; the scene is framed below the caption for any camera; an
//! axis triad sits in the lower-left corner.
pub mod camera;
pub(crate) mod colormap;
pub(crate) mod raster;
pub mod values;

use super::mesh::PatchMesh;
use crate::scene::Scene;
use crate::{Error, Result};
use camera::Camera;
use plotters::prelude::*;
use raster::{Fragment, Raster, Tri};
use std::path::Path;

/// Width of the colour-bar panel at the right of the picture, pixels.
pub const BAR_PANEL: u32 = 190;
/// Smallest picture that leaves room for the scene and the colour bar.
pub const MIN_SIZE: (u32, u32) = (320, 240);
/// Largest picture accepted (memory: a few buffers of w·h values).
pub const MAX_SIDE: u32 = 8192;
/// Colour of back faces and obstructions.
pub const NEUTRAL: [u8; 3] = [190, 190, 190];
/// Colour of outlines (surface boundaries, silhouettes and creases).
pub const OUTLINE: [u8; 3] = [40, 40, 40];
/// Background.
pub const BACKGROUND: [u8; 3] = [255, 255, 255];
/// Colour-bar geometry: x of its left edge from the panel start, width, top and bottom margins.
const BAR: (i32, i32, i32, i32) = (30, 28, 70, 40);
/// Number of colour-bar ticks to aim for.
const TICKS: usize = 6;

/// What to draw.
#[derive(Debug, Clone)]
pub struct Options {
    /// Picture size in pixels, colour bar included.
    pub size: (u32, u32),
    /// The camera.
    pub camera: Camera,
    /// Show back faces in grey instead of culling them.
    pub two_sided: bool,
    /// Colour range; `None` = the values' min and max.
    pub range: Option<(f64, f64)>,
    /// Field name (colour-bar title).
    pub field: String,
    /// Its unit.
    pub unit: String,
    /// Caption above the picture (wrapped, then shrunk, to fit).
    pub caption: String,
    /// Plain false colour without the headlight shading (exact colour reading).
    pub flat: bool,
    /// Zoom and pan the image plane so the scene fills the picture below the caption; off
    /// keeps the camera's own field of view.
    pub fit: bool,
}

/// An RGB picture.
#[derive(Debug, Clone, PartialEq)]
pub struct Image {
    /// Width, pixels.
    pub w: u32,
    /// Height, pixels.
    pub h: u32,
    /// Row-major RGB bytes.
    pub rgb: Vec<u8>,
    /// The colour bar's value range (bottom, top).
    pub range: (f64, f64),
}

impl Image {
    /// The colour at (x, y).
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        let k = 3 * (y * self.w + x) as usize;
        [self.rgb[k], self.rgb[k + 1], self.rgb[k + 2]]
    }
}

/// Triangles of every patch with its vertex-averaged values, then every obstruction (neutral).
pub fn triangles(scene: &Scene, patch_values: &[f64]) -> Vec<Tri> {
    let mesh = PatchMesh::build(scene);
    let vertex = mesh.to_points(patch_values);
    let mut tris = Vec::new();
    for (c, patch) in scene.patches.iter().enumerate() {
        let ids = mesh.cell(c);
        let corners = patch.polygon.vertices();
        let at = |p: glam::DVec3| {
            corners.iter().position(|q| *q == p).map_or(patch_values[c], |k| vertex[ids[k] as usize])
        };
        for t in patch.polygon.triangulate() {
            tris.push(Tri {
                p: t,
                v: [at(t[0]), at(t[1]), at(t[2])],
                id: patch.surface as u32,
                neutral: false,
            });
        }
    }
    let base = scene.surfaces.len() as u32;
    for (k, o) in scene.obstructions.iter().enumerate() {
        for poly in &o.polygons {
            for t in poly.triangulate() {
                tris.push(Tri { p: t, v: [0.0; 3], id: base + k as u32, neutral: true });
            }
        }
    }
    tris
}

/// Light that reaches a face seen edge-on, as a fraction of its colour: the headlight's
/// ambient floor, so grazing faces stay readable (and dark colours stay dark, not black).
pub const AMBIENT_LIGHT: f64 = 0.35;
/// Margin between the scene and the picture's edges when framing, pixels.
const FRAME_PAD: f64 = 16.0;
/// Caption font sizes to try, largest first: a long caption wraps, then shrinks.
const CAPTION_SIZES: [u32; 3] = [17, 15, 13];
/// Most caption lines at the larger sizes (the smallest size takes as many as it needs).
const CAPTION_LINES: usize = 2;
/// Axis triad: length of each axis and distance of its origin from the lower-left corner, pixels.
const TRIAD: (f64, i32) = (34.0, 52);
/// Triad colours of x, y and z (the red–green–blue convention of CAD programs).
pub const TRIAD_COLORS: [[u8; 3]; 3] = [[213, 40, 40], [30, 150, 30], [40, 80, 210]];
/// Smallest gap between colour-bar labels, pixels: a nice tick this close to an end label yields.
const LABEL_GAP: i32 = 18;

/// Renders `patch_values` on `scene`.
pub fn render(scene: &Scene, patch_values: &[f64], opts: &Options) -> Result<Image> {
    let (w, h) = opts.size;
    if w < MIN_SIZE.0 || h < MIN_SIZE.1 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::Usage(format!(
            "{} {w}x{h}: expected between {}x{} and {MAX_SIDE}x{MAX_SIDE}",
            crate::error::opt("size"),
            MIN_SIZE.0,
            MIN_SIZE.1
        )));
    }
    let pw = (w - BAR_PANEL) as usize;
    let caption = caption_lines(&opts.caption, pw as u32 - 24);
    let tris = triangles(scene, patch_values);
    let frame = frame(&opts.camera, &tris, opts, caption_height(&caption));
    let mut r = Raster::new(pw, h as usize);
    r.draw_framed(&opts.camera, frame, &tris, opts.two_sided);
    let (lo, hi) = opts.range.unwrap_or_else(|| visible_range(scene, patch_values, &r));
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    for y in 0..h as usize {
        for x in 0..pw {
            let k = y * pw + x;
            let outline =
                (x + 1 < pw && r.boundary(k, k + 1)) || (y + 1 < h as usize && r.boundary(k, k + pw));
            let base = match r.frag[k] {
                _ if outline => OUTLINE,
                Fragment::Empty => BACKGROUND,
                Fragment::Neutral => NEUTRAL,
                Fragment::Value(v) => colormap::viridis((v - lo) / (hi - lo)),
            };
            let lit = !outline && r.frag[k] != Fragment::Empty && !opts.flat;
            let c = if lit { shade(base, r.normal[k], frame.ray(&opts.camera, x, y)) } else { base };
            rgb[3 * (y * w as usize + x)..][..3].copy_from_slice(&c);
        }
    }
    annotate(&mut rgb, opts, (lo, hi), &caption)
        .map_err(|m| Error::Compute(format!("drawing the picture: {m}")))?;
    Ok(Image { w, h, rgb, range: (lo, hi) })
}

/// The image-plane frame of the picture: fitted to the scene below the caption unless the
/// camera's own zoom is asked for (`fit` off).
pub fn frame(cam: &Camera, tris: &[Tri], opts: &Options, caption_h: i32) -> raster::Intrinsics {
    let (pw, h) = ((opts.size.0 - BAR_PANEL) as usize, opts.size.1 as usize);
    if !opts.fit {
        return raster::Intrinsics::centred(cam, pw, h);
    }
    let top = caption_h as f64 + FRAME_PAD / 2.0;
    raster::Intrinsics::fit(cam, tris, pw, h, (FRAME_PAD, pw as f64 - FRAME_PAD, top, h as f64 - FRAME_PAD))
}

/// Headlight (a light at the eye): `base` scaled by AMBIENT_LIGHT + (1 − AMBIENT_LIGHT)·|n·ray|, so a
/// face turned away from the viewer darkens; back faces are lit like front ones.
fn shade(base: [u8; 3], n: [f32; 3], ray: glam::DVec3) -> [u8; 3] {
    let cos = (n[0] as f64 * ray.x + n[1] as f64 * ray.y + n[2] as f64 * ray.z).abs().min(1.0);
    let s = AMBIENT_LIGHT + (1.0 - AMBIENT_LIGHT) * cos;
    base.map(|c| (c as f64 * s).round() as u8)
}

/// Colour range of the surfaces that show in the raster (a hidden surface does not stretch
/// the bar); every value when none shows.
fn visible_range(scene: &Scene, patch_values: &[f64], r: &Raster) -> (f64, f64) {
    let mut seen = vec![false; scene.surfaces.len()];
    for (k, &id) in r.id.iter().enumerate() {
        if matches!(r.frag[k], Fragment::Value(_)) {
            seen[id as usize] = true;
        }
    }
    let vals: Vec<f64> =
        scene.patches.iter().zip(patch_values).filter(|(p, _)| seen[p.surface]).map(|(_, v)| *v).collect();
    colormap::range(if vals.is_empty() { patch_values } else { &vals })
}

/// Colour-bar labels for `lo..hi` on a bar `px` pixels tall: both ends always, then the nice
/// ticks at least `LABEL_GAP` pixels from every other label. (value, text), bottom first.
pub fn bar_labels(lo: f64, hi: f64, px: i32) -> Vec<(f64, String)> {
    let (ticks, decimals) = colormap::ticks(lo, hi, TICKS);
    let gap = (hi - lo) * LABEL_GAP as f64 / px.max(1) as f64;
    // The ends get enough decimals to tell them apart from their neighbours.
    let end_decimals = decimals + usize::from(ticks.len() > 1);
    let mut out = vec![(lo, colormap::label(lo, end_decimals))];
    for t in ticks {
        if t - lo >= gap && hi - t >= gap {
            out.push((t, colormap::label(t, decimals)));
        }
    }
    out.push((hi, colormap::label(hi, end_decimals)));
    out
}

/// The caption broken into lines that fit `width` pixels: one line at the largest size if it
/// fits, else wrapped at spaces at each size in turn, at most `CAPTION_LINES` lines until the
/// smallest size, which takes as many lines as it needs. Returns (font size, lines).
pub fn caption_lines(text: &str, width: u32) -> (u32, Vec<String>) {
    let fits =
        |s: &str, size: u32| ("sans-serif", size).into_font().box_size(s).map_or(true, |(w, _)| w <= width);
    super::charts::register_font();
    for (k, &size) in CAPTION_SIZES.iter().enumerate() {
        let lines = wrap(text, |s| fits(s, size));
        if lines.len() <= CAPTION_LINES || k + 1 == CAPTION_SIZES.len() {
            return (size, lines);
        }
    }
    unreachable!("the last size always returns")
}

/// Greedy word wrap; a word too long for a line on its own is broken between characters.
fn wrap(text: &str, fits: impl Fn(&str) -> bool) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut cur = String::new();
    for word in text.split_whitespace() {
        let joined = if cur.is_empty() { word.to_string() } else { format!("{cur} {word}") };
        if fits(&joined) {
            cur = joined;
            continue;
        }
        if !cur.is_empty() {
            lines.push(std::mem::take(&mut cur));
        }
        for ch in word.chars() {
            cur.push(ch);
            if !fits(&cur) && cur.chars().count() > 1 {
                cur.pop();
                lines.push(std::mem::replace(&mut cur, ch.to_string()));
            }
        }
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

/// Height of the caption band, pixels.
fn caption_height((size, lines): &(u32, Vec<String>)) -> i32 {
    10 + lines.len() as i32 * (*size as i32 + 5)
}

/// Caption, axis triad, colour bar, its labels and its title with units, drawn with plotters.
fn annotate(
    rgb: &mut [u8],
    opts: &Options,
    (lo, hi): (f64, f64),
    caption: &(u32, Vec<String>),
) -> std::result::Result<(), String> {
    super::charts::register_font();
    let (w, h) = opts.size;
    let root = BitMapBackend::with_buffer(rgb, (w, h)).into_drawing_area();
    let e = |x: DrawingAreaErrorKind<_>| x.to_string();
    let x0 = (w - BAR_PANEL) as i32 + BAR.0;
    let (top, bottom) = (BAR.2, h as i32 - BAR.3);
    for y in top..bottom {
        let t = (bottom - 1 - y) as f64 / (bottom - 1 - top) as f64;
        let [cr, cg, cb] = colormap::viridis(t);
        root.draw(&Rectangle::new([(x0, y), (x0 + BAR.1, y + 1)], RGBColor(cr, cg, cb).filled()))
            .map_err(e)?;
    }
    root.draw(&Rectangle::new([(x0, top), (x0 + BAR.1, bottom)], BLACK.stroke_width(1))).map_err(e)?;
    let font = ("sans-serif", 15).into_font().color(&BLACK);
    for (t, text) in bar_labels(lo, hi, bottom - 1 - top) {
        let y = bottom - 1 - ((t - lo) / (hi - lo) * (bottom - 1 - top) as f64).round() as i32;
        root.draw(&PathElement::new(vec![(x0 + BAR.1, y), (x0 + BAR.1 + 6, y)], BLACK)).map_err(e)?;
        root.draw(&Text::new(text, (x0 + BAR.1 + 10, y - 8), font.clone())).map_err(e)?;
    }
    let title = format!("{} [{}]", opts.field, opts.unit);
    root.draw(&Text::new(title, (x0 - 14, top - 34), ("sans-serif", 17).into_font().color(&BLACK)))
        .map_err(e)?;
    let (size, lines) = caption;
    // A white band keeps the caption readable when a fixed fov lets the scene run under it.
    let band = [(0, 0), ((w - BAR_PANEL) as i32 - 1, caption_height(caption))];
    root.draw(&Rectangle::new(band, WHITE.filled())).map_err(e)?;
    for (k, line) in lines.iter().enumerate() {
        let style = ("sans-serif", *size).into_font().color(&BLACK);
        root.draw(&Text::new(line.as_str(), (12, 10 + k as i32 * (*size as i32 + 5)), style)).map_err(e)?;
    }
    triad(&root, &opts.camera, h as i32).map_err(e)?;
    root.present().map_err(e)
}

/// The axis triad in the lower-left corner: x, y and z as seen by the camera (direction only),
/// farthest axis drawn first, each labelled at its tip.
fn triad<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    cam: &Camera,
    h: i32,
) -> std::result::Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (right, up, fwd) = cam.basis();
    let o = (TRIAD.1, h - TRIAD.1);
    let mut axes: Vec<(usize, glam::DVec3)> = (0..3).map(|k| (k, glam::DVec3::AXES[k])).collect();
    axes.sort_by(|a, b| b.1.dot(fwd).total_cmp(&a.1.dot(fwd)));
    for (k, a) in axes {
        let [r, g, b] = TRIAD_COLORS[k];
        let color = RGBColor(r, g, b);
        let tip = (o.0 + (TRIAD.0 * a.dot(right)).round() as i32, o.1 - (TRIAD.0 * a.dot(up)).round() as i32);
        root.draw(&PathElement::new(vec![o, tip], color.stroke_width(3)))?;
        let label =
            (o.0 + (1.4 * TRIAD.0 * a.dot(right)) as i32 - 5, o.1 - (1.4 * TRIAD.0 * a.dot(up)) as i32 - 8);
        root.draw(&Text::new(["x", "y", "z"][k], label, ("sans-serif", 15).into_font().color(&color)))?;
    }
    Ok(())
}

/// Writes `img` as PNG to `path` through a temporary beside it, renamed on success.
pub fn write_png(img: &Image, path: &Path) -> Result<()> {
    super::outputs::write_file("output", &crate::error::opt("output"), "PNG picture", path, |w, p| {
        encode_png(img, w, p)
    })
}

/// Encodes `img` as PNG into `out` (the encoder and settings plotters' bitmap files use);
/// `path` names the file in errors.
pub fn encode_png(img: &Image, out: &mut dyn std::io::Write, path: &Path) -> Result<()> {
    use image::ImageEncoder;
    image::codecs::png::PngEncoder::new(out)
        .write_image(&img.rgb, img.w, img.h, image::ColorType::Rgb8)
        .map_err(|e| {
            let source = match e {
                image::ImageError::IoError(e) => e,
                other => std::io::Error::other(other.to_string()),
            };
            Error::Io { path: path.to_path_buf(), source }
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Pixel of world point `p` seen by `cam` in a picture of `size` (the raster part).
    fn project(cam: &Camera, size: (u32, u32), p: DVec3) -> (u32, u32) {
        let (r, u, f) = cam.basis();
        let d = p - cam.eye;
        let h = size.1 as f64;
        let focal = (h / 2.0) / (cam.fov.to_radians() / 2.0).tan();
        let (w, z) = ((size.0 - BAR_PANEL) as f64, d.dot(f));
        ((w / 2.0 + focal * d.dot(r) / z) as u32, (h / 2.0 - focal * d.dot(u) / z) as u32)
    }

    /// The furnace with the floor at 1 and every other patch at 0: the floor's centre shows
    /// the top colour, the culled ceiling never shows, the colour bar runs from the bottom
    /// colour to the top one, and the corners are background.
    #[test]
    fn furnace_picture() {
        let scene = crate::scene::load(Path::new("cases/cube_furnace/scene.toml")).unwrap();
        let values: Vec<f64> = scene.patches.iter().map(|p| if p.surface == 0 { 1.0 } else { 0.0 }).collect();
        let cam = Camera::frame(&scene);
        let opts = Options {
            size: (800, 600),
            camera: cam,
            two_sided: false,
            range: None,
            field: "temperature".into(),
            unit: "K".into(),
            caption: "test".into(),
            flat: true,
            fit: false,
        };
        let img = render(&scene, &values, &opts).unwrap();
        assert_eq!((img.w, img.h, img.rgb.len()), (800, 600, 800 * 600 * 3));
        let (x, y) = project(&cam, opts.size, DVec3::new(0.5, 0.5, 0.0));
        assert_eq!(img.pixel(x, y), colormap::viridis(1.0), "floor centre at ({x}, {y})");
        // The ceiling faces away from an eye above it: culled, so its centre shows a wall.
        let (x, y) = project(&cam, opts.size, DVec3::new(0.5, 0.5, 1.0));
        assert_eq!(img.pixel(x, y), colormap::viridis(0.0));
        // Both-sided: the ceiling's back is nearest there and drawn neutral.
        let img2 = render(&scene, &values, &Options { two_sided: true, ..opts.clone() }).unwrap();
        assert_eq!(img2.pixel(x, y), NEUTRAL);
        let bx = (800 - BAR_PANEL) as i32 + BAR.0 + BAR.1 / 2;
        // Bar rows inside its border: t = (bottom − 1 − y) / (bottom − 1 − top).
        let (top, bottom) = (BAR.2, 600 - BAR.3);
        for y in [top + 1, (top + bottom) / 2, bottom - 2] {
            let t = (bottom - 1 - y) as f64 / (bottom - 1 - top) as f64;
            assert_eq!(img.pixel(bx as u32, y as u32), colormap::viridis(t), "bar row {y}");
        }
        assert!(colormap::viridis((bottom - 2 - top) as f64 / (bottom - 1 - top) as f64)[0] > 240);
        assert_eq!(img.pixel(5, 599), BACKGROUND);
        // Tick labels are drawn in black right of the bar.
        let dark = (0..600)
            .flat_map(|y| (bx as u32 + 30..790).map(move |x| (x, y)))
            .filter(|&(x, y)| img.pixel(x, y)[0] < 80)
            .count();
        assert!(dark > 50, "no tick labels ({dark} dark pixels)");
    }

    /// Options for the furnace at 800 × 600 with the default camera, fitted and shaded.
    fn furnace_opts(scene: &Scene) -> Options {
        Options {
            size: (800, 600),
            camera: Camera::frame(scene),
            two_sided: false,
            range: None,
            field: "temperature".into(),
            unit: "K".into(),
            caption: "furnace".into(),
            flat: false,
            fit: true,
        }
    }

    /// The colour bar spans the surfaces that show: the furnace's ceiling (hidden from the
    /// default eye above) at 5 does not stretch a 0..1 bar, unless asked by the range.
    #[test]
    fn colour_bar_spans_what_shows() {
        let scene = crate::scene::load(Path::new("cases/cube_furnace/scene.toml")).unwrap();
        let ceiling = scene.surfaces.iter().position(|s| s.name == "ceiling").unwrap();
        let values: Vec<f64> = scene
            .patches
            .iter()
            .map(|p| {
                if p.surface == 0 {
                    1.0
                } else if p.surface == ceiling {
                    5.0
                } else {
                    0.0
                }
            })
            .collect();
        let opts = furnace_opts(&scene);
        let tris = triangles(&scene, &values);
        let mut r = Raster::new(600, 600);
        r.draw_framed(&opts.camera, frame(&opts.camera, &tris, &opts, 30), &tris, false);
        assert_eq!(visible_range(&scene, &values, &r), (0.0, 1.0));
        // Both-sided from outside: the backs of the near walls and the ceiling hide every
        // value, so the bar falls back to all of them.
        let mut r2 = Raster::new(600, 600);
        r2.draw_framed(&opts.camera, frame(&opts.camera, &tris, &opts, 30), &tris, true);
        assert!(
            r2.frag.contains(&Fragment::Neutral) && !r2.frag.iter().any(|f| matches!(f, Fragment::Value(_)))
        );
        assert_eq!(visible_range(&scene, &values, &r2), (0.0, 5.0));
    }

    /// Both ends are labelled, round or not, and no two labels crowd each other.
    #[test]
    fn bar_labels_both_ends() {
        let l = bar_labels(412.7, 987.3, 600);
        assert_eq!((l[0].0, l.last().unwrap().0), (412.7, 987.3));
        assert_eq!((l[0].1.as_str(), l.last().unwrap().1.as_str()), ("412.7", "987.3"));
        assert!(l.iter().any(|(_, t)| t == "500"), "{l:?}");
        for pair in l.windows(2) {
            assert!((pair[1].0 - pair[0].0) / (987.3 - 412.7) * 600.0 >= LABEL_GAP as f64, "{l:?}");
        }
        // A round end is not labelled twice.
        let l = bar_labels(400.0, 1000.0, 600);
        assert_eq!(l.iter().filter(|(v, _)| *v == 400.0).count(), 1, "{l:?}");
    }

    /// A long caption wraps at spaces (then shrinks) and keeps every word; a short one stays
    /// one line at the largest size.
    #[test]
    fn captions_wrap_instead_of_being_cut() {
        assert_eq!(caption_lines("short", 500), (CAPTION_SIZES[0], vec!["short".to_string()]));
        let long = "temperature per patch: 1,280-facet sphere (r = 0.6, glTF, facing out) centred in a 4 m \
                    cube room (8×8 patches per wall) with a much longer tail of words to force wrapping";
        let (size, lines) = caption_lines(long, 500);
        assert!(lines.len() >= 2, "{lines:?}");
        assert_eq!(lines.join(" "), long.split_whitespace().collect::<Vec<_>>().join(" "));
        for l in &lines {
            let w = ("sans-serif", size).into_font().box_size(l).unwrap().0;
            assert!(w <= 500 && !l.contains('…'), "{l}: {w}");
        }
    }

    /// Shading: the furnace's walls (one value each) show several shades, `flat` one colour
    /// per value; the triad's three colours are drawn in the lower-left corner.
    #[test]
    fn headlight_shading_and_triad() {
        let scene = crate::scene::load(Path::new("cases/cube_furnace/scene.toml")).unwrap();
        let values = vec![0.5; scene.patches.len()];
        let opts = furnace_opts(&scene);
        let mid = colormap::viridis(0.5);
        let hue = |c: [u8; 3]| c != BACKGROUND && c != OUTLINE && c != NEUTRAL;
        let colours = |img: &Image| {
            let mut c: Vec<[u8; 3]> = (0..img.h)
                .flat_map(|y| (0..img.w - BAR_PANEL).map(move |x| (x, y)))
                .filter(|&(x, y)| x > 120 || y < img.h - 120) // not the triad
                .map(|(x, y)| img.pixel(x, y))
                .filter(|c| hue(*c) && c[1] > c[0] && c[1] > 40)
                .collect();
            c.sort();
            c.dedup();
            c
        };
        let img = render(&scene, &values, &opts).unwrap();
        let shaded = colours(&img);
        assert!(shaded.len() >= 3 && shaded.iter().all(|c| c[1] <= mid[1]), "{shaded:?}");
        let flat = render(&scene, &values, &Options { flat: true, ..opts.clone() }).unwrap();
        assert_eq!(colours(&flat), vec![mid]);
        for c in TRIAD_COLORS {
            let n = (img.h - 110..img.h)
                .flat_map(|y| (0..110).map(move |x| (x, y)))
                .filter(|&(x, y)| img.pixel(x, y) == c)
                .count();
            assert!(n > 20, "triad colour {c:?}: {n} pixels");
        }
    }

    /// Any camera is framed: an off-axis eye close to the furnace still shows every corner
    /// inside the picture, below the caption.
    #[test]
    fn custom_camera_is_framed() {
        let scene = crate::scene::load(Path::new("cases/cube_furnace/scene.toml")).unwrap();
        let values = vec![0.5; scene.patches.len()];
        let mut opts = furnace_opts(&scene);
        opts.camera = opts.camera.with_spec("eye=2.2,-1.4,1.9").unwrap();
        let tris = triangles(&scene, &values);
        let f = frame(&opts.camera, &tris, &opts, 40);
        for p in tris.iter().flat_map(|t| t.p) {
            let (x, y) = f.project(&opts.camera, p);
            assert!((FRAME_PAD - 1e-6..=(800 - BAR_PANEL) as f64 - FRAME_PAD + 1e-6).contains(&x), "x {x}");
            assert!((40.0..=600.0 - FRAME_PAD + 1e-6).contains(&y), "y {y}");
        }
    }

    #[test]
    fn size_limits() {
        let scene = crate::scene::load(Path::new("cases/cube_furnace/scene.toml")).unwrap();
        let values = vec![1.0; scene.patches.len()];
        let opts = Options {
            size: (100, 100),
            camera: Camera::frame(&scene),
            two_sided: false,
            range: None,
            field: "t".into(),
            unit: "K".into(),
            caption: String::new(),
            flat: false,
            fit: true,
        };
        assert!(matches!(render(&scene, &values, &opts), Err(Error::Usage(_))));
    }

    /// The PNG written through the output set is byte for byte the file plotters' bitmap
    /// backend saves for the same pixels.
    #[test]
    fn png_bytes_match_the_bitmap_backend() {
        let (w, h) = (37u32, 23u32);
        let rgb: Vec<u8> = (0..w * h * 3).map(|k| (k * 7 % 251) as u8).collect();
        let img = Image { w, h, rgb, range: (0.0, 1.0) };
        let dir = tempfile::tempdir().unwrap();
        let by_plotters = dir.path().join("plotters.png");
        {
            let mut be = BitMapBackend::new(&by_plotters, (w, h));
            be.blit_bitmap((0, 0), (w, h), &img.rgb).unwrap();
            be.present().unwrap();
        }
        let ours = dir.path().join("ours.png");
        write_png(&img, &ours).unwrap();
        assert_eq!(std::fs::read(&ours).unwrap(), std::fs::read(&by_plotters).unwrap());
        // A missing folder is refused before anything is encoded, naming the option (the
        // keyword `output` for a library call, `--output` on the command line) and the folder.
        let missing = dir.path().join("nodir/x.png");
        let e = write_png(&img, &missing).unwrap_err();
        let head = format!("output {}: the folder ", missing.display());
        assert!(e.to_string().starts_with(&head) && e.to_string().contains("nodir"), "{e}");
        let flag = |k: &str| format!("--{k}");
        assert!(e.spelled(&flag).starts_with(&format!("--{head}")), "{e}");
    }
}
