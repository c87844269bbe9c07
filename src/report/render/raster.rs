//! Z-buffer software rasteriser: triangles in world space, clipped at the near plane, projected
//! by a pinhole [`Camera`], filled at pixel centres with perspective-correct interpolation of
//! one scalar per vertex (Gouraud). The nearest fragment wins; back faces are culled or drawn
//! as a neutral shade.
use super::camera::Camera;
use glam::DVec3;

/// Neighbouring pixels whose normals differ by more than this angle (cos 30°) lie on
/// different facets: a crease such as a box edge inside one surface, drawn as an outline.
/// Finely tessellated curves turn by far less between neighbouring pixels.
pub const CREASE_COS: f32 = 0.866;

/// Near plane as a fraction of the eye–target distance: in front of the eye, yet far closer
/// than any surface the camera is meant to see.
const CAMERA_NEAR_REL: f64 = 1e-4;

/// What covers a pixel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Fragment {
    /// Nothing: background.
    Empty,
    /// The front (emitting) side of a result surface, with its interpolated value.
    Value(f64),
    /// The back of a result surface (`two_sided`) or an obstruction: no value.
    Neutral,
}

/// A triangle to draw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tri {
    /// Corners, counter-clockwise seen from the front.
    pub p: [DVec3; 3],
    /// Value at each corner (ignored when `neutral`).
    pub v: [f64; 3],
    /// Group id for outlines (surface index, obstructions after the surfaces).
    pub id: u32,
    /// Always drawn without a value, from either side (obstructions).
    pub neutral: bool,
}

/// Pixel buffers of one rendering.
#[derive(Debug, Clone)]
pub struct Raster {
    /// Width in pixels.
    pub w: usize,
    /// Height in pixels.
    pub h: usize,
    /// Camera depth of the nearest fragment (∞ = none).
    pub depth: Vec<f64>,
    /// The nearest fragment.
    pub frag: Vec<Fragment>,
    /// Group id of the nearest fragment (`u32::MAX` = none).
    pub id: Vec<u32>,
    /// Unit normal of the nearest fragment's triangle (zero = none), for crease outlines.
    pub normal: Vec<[f32; 3]>,
}

/// Where the image plane lands in the picture: focal length and principal point, pixels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// Focal length, pixels.
    pub focal: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
}

impl Intrinsics {
    /// The camera's own frame: its fov spans the height, its axis at the centre.
    pub fn centred(cam: &Camera, w: usize, h: usize) -> Intrinsics {
        Intrinsics {
            focal: (h as f64 / 2.0) / (cam.fov.to_radians() / 2.0).tan(),
            cx: w as f64 / 2.0,
            cy: h as f64 / 2.0,
        }
    }

    /// The frame that fits every corner of `tris` seen by `cam` into the box `x0..x1 × y0..y1`
    /// of pixels (zoom and pan of the image plane; the eye stays). The camera's own frame
    /// when a corner lies behind the eye (nothing can fit) or there is nothing to fit.
    pub fn fit(
        cam: &Camera,
        tris: &[Tri],
        w: usize,
        h: usize,
        (x0, x1, y0, y1): (f64, f64, f64, f64),
    ) -> Intrinsics {
        let (right, up, fwd) = cam.basis();
        let near = CAMERA_NEAR_REL * (cam.target - cam.eye).length();
        let mut b = [f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY];
        for p in tris.iter().flat_map(|t| t.p) {
            let d = p - cam.eye;
            let z = d.dot(fwd);
            if !(z > near) {
                return Intrinsics::centred(cam, w, h);
            }
            let (u, v) = (d.dot(right) / z, d.dot(up) / z);
            b = [b[0].min(u), b[1].max(u), b[2].min(v), b[3].max(v)];
        }
        let (du, dv) = (b[1] - b[0], b[3] - b[2]);
        if !(du.is_finite() && dv.is_finite()) || du.max(dv) <= 0.0 || x1 <= x0 || y1 <= y0 {
            return Intrinsics::centred(cam, w, h);
        }
        let focal = ((x1 - x0) / du.max(1e-300)).min((y1 - y0) / dv.max(1e-300));
        Intrinsics {
            focal,
            cx: (x0 + x1) / 2.0 - focal * (b[0] + b[1]) / 2.0,
            cy: (y0 + y1) / 2.0 + focal * (b[2] + b[3]) / 2.0,
        }
    }

    /// Unit direction of the ray from the eye through the centre of pixel (x, y).
    pub fn ray(&self, cam: &Camera, x: usize, y: usize) -> DVec3 {
        let (right, up, fwd) = cam.basis();
        let (u, v) = ((x as f64 + 0.5 - self.cx) / self.focal, (self.cy - y as f64 - 0.5) / self.focal);
        (right * u + up * v + fwd).normalize()
    }

    /// Pixel position of world point `p` (in front of the eye).
    pub fn project(&self, cam: &Camera, p: DVec3) -> (f64, f64) {
        let (right, up, fwd) = cam.basis();
        let d = p - cam.eye;
        let z = d.dot(fwd);
        (self.cx + self.focal * d.dot(right) / z, self.cy - self.focal * d.dot(up) / z)
    }
}

/// Projection of one camera onto a w × h image.
struct View {
    eye: DVec3,
    right: DVec3,
    up: DVec3,
    fwd: DVec3,
    focal: f64,
    near: f64,
    cx: f64,
    cy: f64,
}

impl Raster {
    /// An empty w × h raster.
    pub fn new(w: usize, h: usize) -> Raster {
        Raster {
            w,
            h,
            depth: vec![f64::INFINITY; w * h],
            frag: vec![Fragment::Empty; w * h],
            id: vec![u32::MAX; w * h],
            normal: vec![[0.0; 3]; w * h],
        }
    }

    /// Draws every triangle seen by `cam`; `two_sided` draws result back faces as neutral
    /// instead of culling them.
    #[cfg(test)]
    pub fn draw(&mut self, cam: &Camera, tris: &[Tri], two_sided: bool) {
        self.draw_framed(cam, Intrinsics::centred(cam, self.w, self.h), tris, two_sided);
    }

    /// Draws every triangle seen by `cam` (back faces as in `draw`) with the image plane placed
    /// by `frame`.
    pub fn draw_framed(&mut self, cam: &Camera, frame: Intrinsics, tris: &[Tri], two_sided: bool) {
        let (right, up, fwd) = cam.basis();
        let view = View {
            eye: cam.eye,
            right,
            up,
            fwd,
            focal: frame.focal,
            near: CAMERA_NEAR_REL * (cam.target - cam.eye).length(),
            cx: frame.cx,
            cy: frame.cy,
        };
        for t in tris {
            let n = (t.p[1] - t.p[0]).cross(t.p[2] - t.p[0]);
            let front = n.dot(cam.eye - t.p[0]) > 0.0;
            let neutral = t.neutral || !front;
            if !front && !t.neutral && !two_sided {
                continue;
            }
            let n = n.normalize_or_zero().as_vec3().to_array();
            self.triangle(&view, t, neutral, n);
        }
    }

    /// Clips `t` at the near plane (Sutherland–Hodgman in camera space) and fills the pieces.
    fn triangle(&mut self, v: &View, t: &Tri, neutral: bool, normal: [f32; 3]) {
        // Camera-space corners (x, y, z) with their values.
        let cs: Vec<(DVec3, f64)> = (0..3)
            .map(|k| {
                let d = t.p[k] - v.eye;
                (DVec3::new(d.dot(v.right), d.dot(v.up), d.dot(v.fwd)), t.v[k])
            })
            .collect();
        let mut poly = Vec::with_capacity(4);
        for k in 0..3 {
            let (a, b) = (cs[k], cs[(k + 1) % 3]);
            let (ia, ib) = (a.0.z >= v.near, b.0.z >= v.near);
            if ia {
                poly.push(a);
            }
            if ia != ib {
                let s = (v.near - a.0.z) / (b.0.z - a.0.z);
                poly.push((a.0 + (b.0 - a.0) * s, a.1 + (b.1 - a.1) * s));
            }
        }
        if poly.len() < 3 {
            return;
        }
        // Screen x, y, 1/z, value/z.
        let scr: Vec<[f64; 4]> = poly
            .iter()
            .map(|(p, val)| [v.cx + v.focal * p.x / p.z, v.cy - v.focal * p.y / p.z, 1.0 / p.z, val / p.z])
            .collect();
        for k in 1..scr.len() - 1 {
            self.fill(&[scr[0], scr[k], scr[k + 1]], t.id, neutral, normal);
        }
    }

    /// Fills one screen triangle at pixel centres, depth-tested.
    fn fill(&mut self, s: &[[f64; 4]; 3], id: u32, neutral: bool, normal: [f32; 3]) {
        let area = edge(s[0], s[1], s[2]);
        if !(area.abs() > 0.0) {
            return;
        }
        let xmin = s.iter().map(|p| p[0]).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
        let xmax =
            s.iter().map(|p| p[0]).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.w as f64) as usize;
        let ymin = s.iter().map(|p| p[1]).fold(f64::INFINITY, f64::min).floor().max(0.0) as usize;
        let ymax =
            s.iter().map(|p| p[1]).fold(f64::NEG_INFINITY, f64::max).ceil().min(self.h as f64) as usize;
        for y in ymin..ymax {
            for x in xmin..xmax {
                let p = [x as f64 + 0.5, y as f64 + 0.5, 0.0, 0.0];
                let b = [edge(s[1], s[2], p) / area, edge(s[2], s[0], p) / area, edge(s[0], s[1], p) / area];
                if b.iter().any(|&w| w < 0.0) {
                    continue;
                }
                let inv_z = b[0] * s[0][2] + b[1] * s[1][2] + b[2] * s[2][2];
                let z = 1.0 / inv_z;
                let k = y * self.w + x;
                if z < self.depth[k] {
                    self.depth[k] = z;
                    self.id[k] = id;
                    self.normal[k] = normal;
                    self.frag[k] = if neutral {
                        Fragment::Neutral
                    } else {
                        Fragment::Value((b[0] * s[0][3] + b[1] * s[1][3] + b[2] * s[2][3]) * z)
                    };
                }
            }
        }
    }
}

impl Raster {
    /// True when pixels `a` and `b` show different groups or a crease between facets.
    pub fn boundary(&self, a: usize, b: usize) -> bool {
        let (na, nb) = (self.normal[a], self.normal[b]);
        let dot = na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2];
        self.id[a] != self.id[b] || (self.id[a] != u32::MAX && dot < CREASE_COS)
    }
}

/// Twice the signed area of (a, b, c) in screen coordinates.
fn edge(a: [f64; 4], b: [f64; 4], c: [f64; 4]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Camera on +z looking down at the origin, 90° fov: at distance 1 the image spans ±1.
    fn cam() -> Camera {
        Camera { eye: DVec3::new(0.0, 0.0, 1.0), target: DVec3::ZERO, up: DVec3::Y, fov: 90.0 }
    }

    fn quad(z: f64, vals: [f64; 4], id: u32) -> Vec<Tri> {
        let p = [
            DVec3::new(-1.0, -1.0, z),
            DVec3::new(1.0, -1.0, z),
            DVec3::new(1.0, 1.0, z),
            DVec3::new(-1.0, 1.0, z),
        ];
        vec![
            Tri { p: [p[0], p[1], p[2]], v: [vals[0], vals[1], vals[2]], id, neutral: false },
            Tri { p: [p[0], p[2], p[3]], v: [vals[0], vals[2], vals[3]], id, neutral: false },
        ]
    }

    fn value(r: &Raster, x: usize, y: usize) -> Fragment {
        r.frag[y * r.w + x]
    }

    /// Gouraud: a value linear in x across a plane facing the camera (constant depth, so the
    /// perspective correction is exact) is reproduced at pixel centres.
    #[test]
    fn gouraud_is_linear_between_two_vertex_values() {
        let mut r = Raster::new(100, 100);
        r.draw(&cam(), &quad(0.0, [10.0, 20.0, 20.0, 10.0], 0), false);
        for x in [0usize, 25, 50, 99] {
            let want = 10.0 + 10.0 * (x as f64 + 0.5) / 100.0;
            match value(&r, x, 40) {
                Fragment::Value(v) => assert!((v - want).abs() < 1e-9, "x {x}: {v} vs {want}"),
                f => panic!("x {x}: {f:?}"),
            }
        }
    }

    #[test]
    fn nearest_surface_wins_in_either_order() {
        let near = quad(0.5, [2.0; 4], 1);
        let far = quad(0.0, [1.0; 4], 0);
        for order in [[&near, &far], [&far, &near]] {
            let tris: Vec<Tri> = order.iter().flat_map(|t| t.iter().copied()).collect();
            let mut r = Raster::new(64, 64);
            r.draw(&cam(), &tris, false);
            assert_eq!(value(&r, 32, 32), Fragment::Value(2.0));
            assert_eq!(r.id[32 * 64 + 32], 1);
            // The near quad spans ±1 at depth 0.5 (±2 of the image): it covers every pixel.
            assert_eq!(value(&r, 1, 1), Fragment::Value(2.0));
        }
    }

    #[test]
    fn outlines_at_groups_and_creases() {
        let mut r = Raster::new(3, 1);
        r.id = vec![0, 0, 1];
        r.normal = vec![[0.0, 0.0, 1.0], [0.0, 0.6, 0.8], [0.0, 0.6, 0.8]];
        // 37° between the first two facets of one group: a crease; then a group change.
        assert!(r.boundary(0, 1) && r.boundary(1, 2));
        r.normal[1] = [0.0, 0.2, 0.98];
        r.id[2] = 0;
        r.normal[2] = r.normal[1];
        assert!(!r.boundary(0, 1) && !r.boundary(1, 2), "gentle turns and equal facets are not edges");
    }

    #[test]
    fn back_faces_are_culled_or_neutral() {
        let mut back = quad(0.0, [1.0; 4], 0);
        for t in &mut back {
            t.p.swap(1, 2);
        }
        let mut r = Raster::new(32, 32);
        r.draw(&cam(), &back, false);
        assert_eq!(value(&r, 16, 16), Fragment::Empty);
        r.draw(&cam(), &back, true);
        assert_eq!(value(&r, 16, 16), Fragment::Neutral);
    }

    /// A fitted frame puts every corner inside the asked box, touching two opposite sides.
    #[test]
    fn fit_puts_the_corners_in_the_box() {
        let tris = quad(0.0, [0.0; 4], 0);
        let c = Camera { eye: DVec3::new(0.3, -2.0, 3.0), target: DVec3::ZERO, up: DVec3::Z, fov: 20.0 };
        let bx = (20.0, 380.0, 90.0, 280.0);
        let f = Intrinsics::fit(&c, &tris, 400, 300, bx);
        let px: Vec<(f64, f64)> = tris.iter().flat_map(|t| t.p).map(|p| f.project(&c, p)).collect();
        let e = 1e-9;
        assert!(
            px.iter().all(|&(x, y)| x >= bx.0 - e && x <= bx.1 + e && y >= bx.2 - e && y <= bx.3 + e),
            "{px:?}"
        );
        let touch = |a: f64, f: fn(&(f64, f64)) -> f64| px.iter().any(|p| (f(p) - a).abs() < 1e-6);
        assert!(
            (touch(bx.0, |p| p.0) && touch(bx.1, |p| p.0)) || (touch(bx.2, |p| p.1) && touch(bx.3, |p| p.1))
        );
        // An eye inside the geometry cannot be fitted: the camera's own frame.
        let inside = Camera { eye: DVec3::new(0.0, 0.0, -0.5), target: DVec3::new(0.0, 0.0, -1.0), ..c };
        let mut behind = tris.clone();
        behind[0].p[0].z = 2.0;
        assert_eq!(Intrinsics::fit(&inside, &behind, 400, 300, bx), Intrinsics::centred(&inside, 400, 300));
    }

    #[test]
    fn geometry_behind_the_eye_is_clipped() {
        // A quad straddling the eye plane: the part behind must not wrap around.
        let p = [DVec3::new(-1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, 2.0), DVec3::new(1.0, -1.0, -1.0)];
        let mut r = Raster::new(32, 32);
        r.draw(&cam(), &[Tri { p, v: [0.0; 3], id: 0, neutral: true }], true);
        // Its plane y = −1 lies below the eye: nothing may land in the upper half.
        assert!((0..16 * 32).all(|k| r.frag[k] == Fragment::Empty));
        assert!(r.frag.contains(&Fragment::Neutral));
    }
}
