//! Pinhole camera: eye, target, up and vertical field of view; the default framing; the
//! `--camera "eye=x,y,z target=x,y,z up=x,y,z fov=deg"` syntax.
use crate::scene::Scene;
use crate::{Error, Result};
use glam::DVec3;

/// Default vertical field of view, degrees: a moderate telephoto keeps walls undistorted.
pub const DEFAULT_FOV: f64 = 35.0;
/// Extra distance beyond the bounding sphere so the scene does not touch the image border.
const FRAME_MARGIN: f64 = 1.08;
/// Elevation of the default view direction relative to the horizontal diagonals (iso-like).
const ELEVATION: f64 = 0.8;

/// A perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: DVec3,
    /// Point looked at (image centre).
    pub target: DVec3,
    /// Approximate up direction.
    pub up: DVec3,
    /// Vertical field of view, degrees.
    pub fov: f64,
}

impl Camera {
    /// The default view: from outside the bounding sphere, along the diagonal direction (of
    /// eight) that shows the most front-facing patch area Σ A·max(0, n·d). Surfaces are
    /// one-sided, so in a closed enclosure this looks through the culled near walls onto the
    /// inside of the far ones (a cutaway), and at a body it looks at its outside. Up is +z,
    /// or +y for a bare glTF scene (glTF's convention).
    pub fn frame(scene: &Scene) -> Camera {
        let (lo, hi) = super::super::mesh::scene_bounds(scene).unwrap_or((DVec3::ZERO, DVec3::ONE));
        let target = (lo + hi) / 2.0;
        let radius = ((hi - lo).length() / 2.0).max(f64::MIN_POSITIVE);
        let gltf = scene
            .source
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("gltf") || e.eq_ignore_ascii_case("glb"));
        // (horizontal, horizontal, vertical) → world; right-handed either way.
        let world = |a: f64, b: f64, up: f64| if gltf { DVec3::new(a, up, -b) } else { DVec3::new(a, b, up) };
        let mut best = (f64::NEG_INFINITY, world(1.0, -1.0, ELEVATION).normalize());
        for sz in [1.0, -1.0] {
            for (sx, sy) in [(1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
                let d = world(sx, sy, sz * ELEVATION).normalize();
                let seen: f64 =
                    scene.patches.iter().map(|p| p.polygon.area() * p.polygon.normal().dot(d).max(0.0)).sum();
                if seen > best.0 * (1.0 + 1e-9) {
                    best = (seen, d);
                }
            }
        }
        let dist = FRAME_MARGIN * radius / (DEFAULT_FOV.to_radians() / 2.0).sin();
        let up = if gltf { DVec3::Y } else { DVec3::Z };
        Camera { eye: target + best.1 * dist, target, up, fov: DEFAULT_FOV }
    }

    /// Applies `eye=… target=… up=… fov=…` (any subset, separated by spaces or `;`) on top of
    /// `self`. Errors name the bad token.
    pub fn with_spec(mut self, spec: &str) -> Result<Camera> {
        let bad = |msg: String| Error::Usage(format!("{}: {msg}", crate::error::opt("camera")));
        for tok in spec.split(|c: char| c.is_whitespace() || c == ';').filter(|t| !t.is_empty()) {
            let (key, val) = tok.split_once('=').ok_or_else(|| bad(format!("'{tok}' is not key=value")))?;
            let vec = || -> Result<DVec3> {
                let v: Vec<f64> = val
                    .split(',')
                    .map(|x| x.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|_| bad(format!("'{tok}': expected three numbers x,y,z")))?;
                match v[..] {
                    [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(x, y, z)),
                    _ => Err(bad(format!("'{tok}': expected three finite numbers x,y,z"))),
                }
            };
            match key {
                "eye" => self.eye = vec()?,
                "target" => self.target = vec()?,
                "up" => self.up = vec()?,
                "fov" => {
                    let f: f64 = val.parse().map_err(|_| bad(format!("'{tok}': fov is not a number")))?;
                    if !(f > 1.0 && f < 170.0) {
                        return Err(bad(format!("fov must be between 1 and 170 degrees, got {val}")));
                    }
                    self.fov = f;
                }
                _ => return Err(bad(format!("unknown key '{key}'; expected eye, target, up or fov"))),
            }
        }
        let f = self.target - self.eye;
        if !(f.length() > 0.0) {
            return Err(bad("eye and target coincide".into()));
        }
        if !(f.normalize().cross(self.up).length() > 1e-9) {
            return Err(bad("up is parallel to the view direction (or zero)".into()));
        }
        Ok(self)
    }

    /// Orthonormal basis (right, up, forward).
    pub fn basis(&self) -> (DVec3, DVec3, DVec3) {
        let f = (self.target - self.eye).normalize();
        let r = f.cross(self.up).normalize();
        (r, r.cross(f), f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The default eye is outside the bounding box and looks at its centre; z up for TOML
    /// scenes, y up for a bare glTF file.
    #[test]
    fn default_framing() {
        for (path, up) in
            [("cases/cube_furnace/scene.toml", DVec3::Z), ("tests/fixtures/concentric_boxes.gltf", DVec3::Y)]
        {
            let scene = crate::scene::load(std::path::Path::new(path)).unwrap();
            let (lo, hi) = crate::report::mesh::scene_bounds(&scene).unwrap();
            let c = Camera::frame(&scene);
            assert_eq!((c.up, c.target), (up, (lo + hi) / 2.0), "{path}");
            let outside = (0..3).any(|k| c.eye[k] < lo[k] || c.eye[k] > hi[k]);
            let radius = (hi - lo).length() / 2.0;
            assert!(
                outside && (c.eye - c.target).length() * (c.fov.to_radians() / 2.0).sin() >= radius,
                "{path}"
            );
        }
    }

    #[test]
    fn spec_parsing_and_errors() {
        let c = Camera { eye: DVec3::new(5.0, 0.0, 0.0), target: DVec3::ZERO, up: DVec3::Z, fov: 30.0 };
        let d = c.with_spec("eye=0,-4,1; fov=50").unwrap();
        assert_eq!((d.eye, d.fov, d.target), (DVec3::new(0.0, -4.0, 1.0), 50.0, DVec3::ZERO));
        for bad in ["eye=1,2", "fov=0", "zoom=2", "eye", "up=1,0,0", "target=5,0,0", "eye=a,b,c"] {
            let e = c.with_spec(bad).unwrap_err().to_string();
            assert!(e.starts_with("camera"), "{bad}: {e}");
        }
    }
}
