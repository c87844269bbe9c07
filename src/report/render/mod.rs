//! `lambert render`: a false-colour picture of a result on the scene geometry.
//!
//! - [`values`]: one column of a `solve` CSV spread onto the patches;
//! - [`camera`]: the pinhole camera, its default framing and `--camera` syntax;
//! - [`raster`]: the z-buffer rasteriser with Gouraud (vertex-smoothed) values;
//! - [`colormap`]: viridis, value range, colour-bar ticks;
//! - this file: triangles from the patch mesh, the picture with outlines, caption and colour
//!   bar (plotters on an RGB buffer, vendored DejaVu Sans), and the PNG file.
//!
//! Surfaces are one-sided: only the front (emitting) side carries a value. Back faces are
//! culled by default (`two_sided` shows them in grey), so from outside a closed enclosure the
//! picture looks through the near walls onto the inside of the far ones.
pub mod camera;
pub mod colormap;
pub mod raster;
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
    /// Caption above the picture.
    pub caption: String,
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

/// Renders `patch_values` on `scene`.
pub fn render(scene: &Scene, patch_values: &[f64], opts: &Options) -> Result<Image> {
    let (w, h) = opts.size;
    if w < MIN_SIZE.0 || h < MIN_SIZE.1 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::Usage(format!(
            "--size {w}x{h}: expected between {}x{} and {MAX_SIDE}x{MAX_SIDE}",
            MIN_SIZE.0, MIN_SIZE.1
        )));
    }
    let (lo, hi) = opts.range.unwrap_or_else(|| colormap::range(patch_values));
    let pw = (w - BAR_PANEL) as usize;
    let mut r = Raster::new(pw, h as usize);
    r.draw(&opts.camera, &triangles(scene, patch_values), opts.two_sided);
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    for y in 0..h as usize {
        for x in 0..pw {
            let k = y * pw + x;
            let outline =
                (x + 1 < pw && r.boundary(k, k + 1)) || (y + 1 < h as usize && r.boundary(k, k + pw));
            let c = match r.frag[k] {
                _ if outline => OUTLINE,
                Fragment::Empty => BACKGROUND,
                Fragment::Neutral => NEUTRAL,
                Fragment::Value(v) => colormap::viridis((v - lo) / (hi - lo)),
            };
            rgb[3 * (y * w as usize + x)..][..3].copy_from_slice(&c);
        }
    }
    annotate(&mut rgb, opts, (lo, hi)).map_err(|m| Error::Compute(format!("drawing the picture: {m}")))?;
    Ok(Image { w, h, rgb })
}

/// Caption, colour bar, its ticks and its title with units, drawn with plotters.
fn annotate(rgb: &mut [u8], opts: &Options, (lo, hi): (f64, f64)) -> std::result::Result<(), String> {
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
    let (ticks, decimals) = colormap::ticks(lo, hi, TICKS);
    let font = ("sans-serif", 15).into_font().color(&BLACK);
    for t in ticks {
        let y = bottom - 1 - ((t - lo) / (hi - lo) * (bottom - 1 - top) as f64).round() as i32;
        root.draw(&PathElement::new(vec![(x0 + BAR.1, y), (x0 + BAR.1 + 6, y)], BLACK)).map_err(e)?;
        root.draw(&Text::new(colormap::label(t, decimals), (x0 + BAR.1 + 10, y - 8), font.clone()))
            .map_err(e)?;
    }
    let title = format!("{} [{}]", opts.field, opts.unit);
    root.draw(&Text::new(title, (x0 - 14, top - 34), ("sans-serif", 17).into_font().color(&BLACK)))
        .map_err(e)?;
    let caption_font = ("sans-serif", 17).into_font().color(&BLACK);
    let room = (w - BAR_PANEL) as i64 - 24;
    // Shorten a long caption (scene titles can be) so it stays clear of the colour bar.
    let mut caption = opts.caption.clone();
    let mut n = caption.chars().count();
    while n > 0 && root.estimate_text_size(&caption, &caption_font).map_err(e)?.0 as i64 > room {
        n -= 1;
        caption = opts.caption.chars().take(n).collect::<String>().trim_end().to_string() + "…";
    }
    root.draw(&Text::new(caption, (12, 10), caption_font)).map_err(e)?;
    root.present().map_err(e)
}

/// Writes `img` as PNG to `path` through a temporary beside it, renamed on success.
pub fn write_png(img: &Image, path: &Path) -> Result<()> {
    super::outputs::write_file("output", "-o", "PNG picture", path, |w, p| encode_png(img, w, p))
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
        };
        assert!(matches!(render(&scene, &values, &opts), Err(Error::Usage(_))));
    }

    /// The PNG written through the output set is byte for byte the file plotters' bitmap
    /// backend saves for the same pixels.
    #[test]
    fn png_bytes_match_the_bitmap_backend() {
        let (w, h) = (37u32, 23u32);
        let rgb: Vec<u8> = (0..w * h * 3).map(|k| (k * 7 % 251) as u8).collect();
        let img = Image { w, h, rgb };
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
        // A missing folder is refused before anything is encoded, naming the flag and folder.
        let e = write_png(&img, &dir.path().join("nodir/x.png")).unwrap_err();
        assert!(e.to_string().contains("-o") && e.to_string().contains("nodir"), "{e}");
    }
}
