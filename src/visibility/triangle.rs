//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, JCGT 2(1)).
//!
//! The ray is translated to the origin and sheared so that it runs along +z; the three edge
//! functions are then 2-D cross products of the projected vertices. An edge shared by two
//! triangles gives the same function with opposite sign, bit for bit, so a ray through a
//! shared edge or vertex hits at least one of them: no leaks through a watertight mesh.
//! Exact zeros are re-evaluated in f64, as the paper prescribes.
use glam::Vec3A;

/// One ray prepared for many triangle tests: origin and the shear as three SIMD columns, so
/// that M·(v − o) = (v−o)[kx] − Sx·(v−o)[kz], (v−o)[ky] − Sy·(v−o)[kz], Sz·(v−o)[kz].
#[derive(Debug, Clone, Copy)]
pub struct ShearedRay {
    origin: Vec3A,
    cols: [Vec3A; 3],
    /// Axis permutation (kx, ky, kz) and shear (Sx, Sy) for the f64 re-evaluation.
    k: [usize; 3],
    s: [f32; 2],
}

/// An f32 edge function smaller than this fraction of its two products may have the wrong
/// sign (each product carries ~2⁻²⁴ relative rounding, the shear a few more): re-evaluate in
/// f64. This catches a ray whose origin lies on the line of an edge (a concave corner).
const EDGE_CANCEL: f32 = 1.0 / (1 << 20) as f32;

/// A hit: parameter t along the (unit) ray direction and the side that was hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriHit {
    /// Ray parameter; may be slightly negative when the origin sits just past the triangle.
    pub t: f32,
    /// True when the ray meets the front side (counter-clockwise vertices seen from the origin).
    pub front: bool,
}

impl ShearedRay {
    /// Prepares a ray with a non-zero direction.
    #[inline]
    pub fn new(origin: Vec3A, dir: Vec3A) -> Self {
        let a = dir.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Swapping keeps the winding of the projected triangle when the ray points down kz.
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        let mut cols = [Vec3A::ZERO; 3];
        cols[kx].x = 1.0;
        cols[ky].y = 1.0;
        cols[kz] = Vec3A::new(-sx, -sy, sz);
        Self { origin, cols, k: [kx, ky, kz], s: [sx, sy] }
    }

    /// Vertex in ray space: sheared x, y and scaled z.
    #[inline(always)]
    fn shear(&self, v: Vec3A) -> Vec3A {
        let p = v - self.origin;
        self.cols[0] * p.x + self.cols[1] * p.y + self.cols[2] * p.z
    }

    /// Sheared x, y of a vertex in f64.
    #[cold]
    fn shear64(&self, v: Vec3A) -> (f64, f64) {
        let p = v - self.origin;
        let [kx, ky, kz] = self.k;
        let z = p[kz] as f64;
        (p[kx] as f64 - self.s[0] as f64 * z, p[ky] as f64 - self.s[1] as f64 * z)
    }

    /// Intersects triangle (v0, v1, v2); `None` when the ray's line misses it.
    #[inline(always)]
    pub fn intersect(&self, v: &[Vec3A; 3]) -> Option<TriHit> {
        let (a, b, c) = (self.shear(v[0]), self.shear(v[1]), self.shear(v[2]));
        let (ax, ay, bx, by, cx, cy) = (a.x, a.y, b.x, b.y, c.x, c.y);
        // Scaled barycentric edge functions.
        let mut u = cx * by - cy * bx;
        let mut w_ = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        let tiny = |e: f32, p: f32, q: f32| e.abs() <= EDGE_CANCEL * (p.abs() + q.abs());
        let (tu, tv, tw) = (tiny(u, cx * by, cy * bx), tiny(w_, ax * cy, ay * cx), tiny(w, bx * ay, by * ax));
        if tu || tv || tw {
            // Re-evaluate those edges in f64 (edge or vertex hits, origins on an edge's line):
            // f32 inputs make the shear products exact, so collinear cases come out exactly 0.
            // Per edge, so two triangles sharing an edge still agree on it bit for bit.
            let [(ax, ay), (bx, by), (cx, cy)] = [v[0], v[1], v[2]].map(|x| self.shear64(x));
            if tu {
                u = (cx * by - cy * bx) as f32;
            }
            if tv {
                w_ = (ax * cy - ay * cx) as f32;
            }
            if tw {
                w = (bx * ay - by * ax) as f32;
            }
        }
        if (u < 0.0 || w_ < 0.0 || w < 0.0) && (u > 0.0 || w_ > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + w_ + w;
        if det == 0.0 {
            return None;
        }
        // Scaled hit distance, then divide once.
        let t = (u * a.z + w_ * b.z + w * c.z) / det;
        // With this shear, counter-clockwise triangles seen from the origin give det > 0.
        Some(TriHit { t, front: det > 0.0 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::vec3a;

    const TRI: [Vec3A; 3] = [Vec3A::new(0.0, 0.0, 0.0), Vec3A::new(1.0, 0.0, 0.0), Vec3A::new(0.0, 1.0, 0.0)];

    #[test]
    fn front_and_back_hits_have_the_right_side_and_distance() {
        // Normal +z: a ray from above going down meets the front side.
        let down = ShearedRay::new(vec3a(0.2, 0.2, 2.0), vec3a(0.0, 0.0, -1.0)).intersect(&TRI).unwrap();
        assert!(down.front && (down.t - 2.0).abs() < 1e-6, "{down:?}");
        let up = ShearedRay::new(vec3a(0.2, 0.2, -3.0), vec3a(0.0, 0.0, 1.0)).intersect(&TRI).unwrap();
        assert!(!up.front && (up.t - 3.0).abs() < 1e-6, "{up:?}");
        // Oblique, every dominant axis and sign.
        for d in
            [vec3a(0.3, -0.2, -1.0), vec3a(-2.0, 0.1, -1.0), vec3a(0.1, 3.0, -1.0), vec3a(-0.5, -4.0, -1.0)]
        {
            let d = d.normalize();
            let target = vec3a(0.25, 0.25, 0.0);
            let o = target - d * 1.5;
            let h = ShearedRay::new(o, d).intersect(&TRI).unwrap();
            assert!(h.front && (h.t - 1.5).abs() < 1e-5, "{d}: {h:?}");
            let h = ShearedRay::new(target + d * 1.5, -d).intersect(&TRI).unwrap();
            assert!(!h.front && (h.t - 1.5).abs() < 1e-5, "{d}: {h:?}");
        }
        assert!(ShearedRay::new(vec3a(0.8, 0.8, 1.0), vec3a(0.0, 0.0, -1.0)).intersect(&TRI).is_none());
    }

    #[test]
    fn shared_edges_and_vertices_never_leak() {
        // A fan of 8 triangles around the origin; rays straight through its edges and centre.
        let fan: Vec<[Vec3A; 3]> = (0..8)
            .map(|k| {
                let a0 = k as f32 * std::f32::consts::FRAC_PI_4;
                let a1 = (k + 1) as f32 * std::f32::consts::FRAC_PI_4;
                [Vec3A::ZERO, vec3a(a0.cos(), a0.sin(), 0.0), vec3a(a1.cos(), a1.sin(), 0.0)]
            })
            .collect();
        let mut targets = vec![Vec3A::ZERO];
        for k in 0..8 {
            let a = k as f32 * std::f32::consts::FRAC_PI_4;
            for r in [0.1f32, 0.37, 0.9] {
                targets.push(vec3a(r * a.cos(), r * a.sin(), 0.0));
            }
        }
        for t in targets {
            for d in [vec3a(0.0, 0.0, -1.0), vec3a(0.3, 0.7, -1.0), vec3a(-0.9, 0.2, -0.3)] {
                let d = d.normalize();
                let ray = ShearedRay::new(t - d * 2.0, d);
                let hits = fan.iter().filter(|tri| ray.intersect(tri).is_some()).count();
                assert!(hits >= 1, "ray towards {t} along {d} leaked through the fan");
            }
        }
    }
}
