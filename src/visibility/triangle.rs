//! Watertight ray–triangle intersection (Woop, Benthin & Wald 2013, JCGT 2(1)).
//!
//! The ray is translated to the origin and sheared so that it runs along +z; the three edge
//! functions are then 2-D cross products of the projected vertices. An edge shared by two
//! triangles gives the same function with opposite sign, bit for bit, so a ray through a
//! shared edge or vertex hits at least one of them: no leaks through a watertight mesh.
//! Exact zeros are re-evaluated in f64, as the paper prescribes.
//!
//! Triangles are stored transposed ([`transpose`]: rows x, y, z of the three vertices), so the
//! shear of all three vertices and the three edge functions are a few SIMD operations; every
//! lane performs the same IEEE operations as the per-vertex formulation, so the results (and
//! the bit-for-bit agreement on shared edges) are the same.
use glam::{Vec3A, Vec3Swizzles};

/// Vertices (v0, v1, v2) ↔ coordinate rows (x, y, z of v0, v1, v2); its own inverse.
#[inline(always)]
pub fn transpose(m: &[Vec3A; 3]) -> [Vec3A; 3] {
    let [a, b, c] = *m;
    [Vec3A::new(a.x, b.x, c.x), Vec3A::new(a.y, b.y, c.y), Vec3A::new(a.z, b.z, c.z)]
}

/// One ray prepared for many triangle tests: origin, axis permutation (kx, ky, kz) and shear
/// (Sx, Sy, Sz), so that M·(v − o) = ((v−o)\[kx\] − Sx·(v−o)\[kz\], (v−o)\[ky\] − Sy·(v−o)\[kz\],
/// Sz·(v−o)\[kz\]).
#[derive(Debug, Clone, Copy)]
pub struct ShearedRay {
    origin: [Vec3A; 3],
    k: [usize; 3],
    s: [Vec3A; 3],
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
        Self {
            origin: [Vec3A::splat(origin.x), Vec3A::splat(origin.y), Vec3A::splat(origin.z)],
            k: [kx, ky, kz],
            s: [Vec3A::splat(sx), Vec3A::splat(sy), Vec3A::splat(sz)],
        }
    }

    /// Sheared x, y of vertex `i` in f64, from its f32 offsets `p` (rows x, y, z) to the origin.
    #[cold]
    fn shear64(&self, p: &[Vec3A; 3], i: usize) -> (f64, f64) {
        let [kx, ky, kz] = self.k;
        let z = p[kz][i] as f64;
        (p[kx][i] as f64 - self.s[0].x as f64 * z, p[ky][i] as f64 - self.s[1].x as f64 * z)
    }

    /// Intersects triangle (v0, v1, v2); `None` when the ray's line misses it.
    #[cfg(test)]
    pub fn intersect(&self, v: &[Vec3A; 3]) -> Option<TriHit> {
        self.intersect_rows(&transpose(v))
    }

    /// Intersects a triangle stored transposed (rows x, y, z of v0, v1, v2).
    #[inline(always)]
    pub fn intersect_rows(&self, m: &[Vec3A; 3]) -> Option<TriHit> {
        let [kx, ky, kz] = self.k;
        let p = [m[0] - self.origin[0], m[1] - self.origin[1], m[2] - self.origin[2]];
        let pz = p[kz];
        // Lanes are the vertices a, b, c: sheared x, y and scaled z.
        let x = p[kx] - self.s[0] * pz;
        let y = p[ky] - self.s[1] * pz;
        let z = self.s[2] * pz;
        // Scaled barycentric edge functions (u, w', w) = (cx·by − cy·bx, ax·cy − ay·cx,
        // bx·ay − by·ax), and the products behind them.
        let (p1, p2) = (x.zxy() * y.yzx(), y.zxy() * x.yzx());
        let mut e = p1 - p2;
        let tiny = e.abs().cmple(Vec3A::splat(EDGE_CANCEL) * (p1.abs() + p2.abs()));
        if tiny.any() {
            // Re-evaluate those edges in f64 (edge or vertex hits, origins on an edge's line):
            // f32 inputs make the shear products exact, so collinear cases come out exactly 0.
            // Per edge, so two triangles sharing an edge still agree on it bit for bit.
            let [(ax, ay), (bx, by), (cx, cy)] = [0, 1, 2].map(|i| self.shear64(&p, i));
            let mask = tiny.bitmask();
            if mask & 1 != 0 {
                e.x = (cx * by - cy * bx) as f32;
            }
            if mask & 2 != 0 {
                e.y = (ax * cy - ay * cx) as f32;
            }
            if mask & 4 != 0 {
                e.z = (bx * ay - by * ax) as f32;
            }
        }
        if e.cmplt(Vec3A::ZERO).any() && e.cmpgt(Vec3A::ZERO).any() {
            return None;
        }
        let det = e.x + e.y + e.z;
        if det == 0.0 {
            return None;
        }
        // Scaled hit distance, then divide once.
        let ez = e * z;
        let t = (ez.x + ez.y + ez.z) / det;
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
