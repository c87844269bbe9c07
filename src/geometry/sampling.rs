//! Sampling warps from the unit square to patches and hemispheres, each with its pdf and its
//! inverse (pbrt-v4 style: `sample_*`, `*_pdf`, `invert_*`); directions are local to a
//! [`super::frame::Frame`].
//!
//! - hemisphere: [`sample_uniform_hemisphere`], [`sample_cosine_hemisphere`] (Malley's method
//!   over the concentric disk of Shirley & Chiu);
//! - area: [`sample_triangle`] (uniform barycentrics) and [`PolygonSampler`] (area-weighted
//!   triangle choice that reuses the selecting coordinate, so a stratified or low-discrepancy
//!   point stays well distributed on the polygon).
use super::Polygon;
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI};

/// Uniform direction on the hemisphere z ≥ 0: z = u₀, φ = 2πu₁; pdf 1/(2π).
pub fn sample_uniform_hemisphere(u: DVec2) -> DVec3 {
    let z = u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    DVec3::new(r * c, r * s, z)
}

/// pdf of [`sample_uniform_hemisphere`] per steradian.
pub fn uniform_hemisphere_pdf() -> f64 {
    0.5 * FRAC_1_PI
}

/// Inverse of [`sample_uniform_hemisphere`].
pub fn invert_uniform_hemisphere(w: DVec3) -> DVec2 {
    DVec2::new(w.z, unit_angle(w.y.atan2(w.x)))
}

/// Concentric map of the unit square to the unit disk (Shirley & Chiu 1997).
pub fn sample_concentric_disk(u: DVec2) -> DVec2 {
    let o = 2.0 * u - DVec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return DVec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    r * DVec2::new(theta.cos(), theta.sin())
}

/// Inverse of [`sample_concentric_disk`].
pub fn invert_concentric_disk(p: DVec2) -> DVec2 {
    let r = p.length();
    if r == 0.0 {
        return DVec2::splat(0.5);
    }
    let mut phi = p.y.atan2(p.x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    // The four wedges of the concentric map, each a quarter turn centred on an axis.
    let o = if phi < FRAC_PI_4 {
        DVec2::new(r, r * phi / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        DVec2::new(-r * (phi - FRAC_PI_2) / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        DVec2::new(-r, -r * (phi - PI) / FRAC_PI_4)
    } else {
        DVec2::new(r * (phi - 3.0 * FRAC_PI_2) / FRAC_PI_4, -r)
    };
    (o + DVec2::ONE) * 0.5
}

/// Cosine-weighted direction (Malley): a concentric-disk point lifted to the hemisphere;
/// pdf cosθ/π.
pub fn sample_cosine_hemisphere(u: DVec2) -> DVec3 {
    let d = sample_concentric_disk(u);
    let z = (1.0 - d.length_squared()).max(0.0).sqrt();
    DVec3::new(d.x, d.y, z)
}

/// pdf of [`sample_cosine_hemisphere`] per steradian: cosθ/π.
pub fn cosine_hemisphere_pdf(cos_theta: f64) -> f64 {
    cos_theta.max(0.0) * FRAC_1_PI
}

/// Inverse of [`sample_cosine_hemisphere`].
pub fn invert_cosine_hemisphere(w: DVec3) -> DVec2 {
    invert_concentric_disk(DVec2::new(w.x, w.y))
}

/// Uniform point on triangle (a, b, c): barycentrics (1 − √u₀, u₁√u₀); pdf 1/area.
pub fn sample_triangle(a: DVec3, b: DVec3, c: DVec3, u: DVec2) -> DVec3 {
    let s = u.x.sqrt();
    let (b1, b2) = (s * (1.0 - u.y), s * u.y);
    a + (b - a) * b1 + (c - a) * b2
}

/// Inverse of [`sample_triangle`]: the unit-square point that maps to `p` (p in the triangle).
pub fn invert_triangle(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> DVec2 {
    let (b1, b2) = barycentrics(a, b, c, p);
    let s = b1 + b2;
    let v = if s > 0.0 { b2 / s } else { 0.5 };
    DVec2::new(s * s, v)
}

/// Area-uniform sampling of a planar polygon through its triangulation; pdf 1/area.
#[derive(Debug, Clone)]
pub struct PolygonSampler {
    tris: Vec<[DVec3; 3]>,
    /// Cumulative area fractions, last = 1.
    cdf: Vec<f64>,
    area: f64,
}

impl PolygonSampler {
    /// Prepares the triangle table of `polygon`.
    pub fn new(polygon: &Polygon) -> Self {
        let tris = polygon.triangulate();
        let areas: Vec<f64> = tris.iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).collect();
        let total: f64 = areas.iter().sum();
        let mut acc = 0.0;
        let mut cdf: Vec<f64> = areas
            .iter()
            .map(|a| {
                acc += a;
                acc / total
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { tris, cdf, area: polygon.area() }
    }
    /// Polygon area (the inverse of the pdf).
    pub fn area(&self) -> f64 {
        self.area
    }
    /// Uniform point: u₀ picks a triangle by area and is rescaled to [0, 1) for reuse.
    pub fn sample(&self, u: DVec2) -> DVec3 {
        let (k, u0) = self.select(u.x);
        let [a, b, c] = self.tris[k];
        sample_triangle(a, b, c, DVec2::new(u0, u.y))
    }
    /// pdf per unit area of [`PolygonSampler::sample`].
    pub fn pdf(&self) -> f64 {
        1.0 / self.area
    }
    /// Inverse of [`PolygonSampler::sample`] for a point `p` of triangle `k`.
    pub fn invert(&self, k: usize, p: DVec3) -> DVec2 {
        let [a, b, c] = self.tris[k];
        let local = invert_triangle(a, b, c, p);
        let lo = if k == 0 { 0.0 } else { self.cdf[k - 1] };
        DVec2::new(lo + local.x * (self.cdf[k] - lo), local.y)
    }
    /// True when `p` (a point of the polygon's plane) lies inside the polygon.
    pub fn contains(&self, p: DVec3) -> bool {
        self.tris.iter().any(|&[a, b, c]| {
            let (b1, b2) = barycentrics(a, b, c, p);
            b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0
        })
    }
    /// Triangle `k` of the table.
    pub fn triangle(&self, k: usize) -> Option<[DVec3; 3]> {
        self.tris.get(k).copied()
    }
    /// Number of triangles.
    pub fn triangles(&self) -> usize {
        self.tris.len()
    }

    fn select(&self, u: f64) -> (usize, f64) {
        let k = self.cdf.partition_point(|&c| c <= u).min(self.cdf.len() - 1);
        let lo = if k == 0 { 0.0 } else { self.cdf[k - 1] };
        let w = self.cdf[k] - lo;
        let r = if w > 0.0 { ((u - lo) / w).clamp(0.0, 1.0 - f64::EPSILON) } else { 0.5 };
        (k, r)
    }
}

/// Barycentrics (b₁, b₂) of `p` (projected on the plane) for triangle (a, b, c).
fn barycentrics(a: DVec3, b: DVec3, c: DVec3, p: DVec3) -> (f64, f64) {
    let (e1, e2, d) = (b - a, c - a, p - a);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (r1, r2) = (d.dot(e1), d.dot(e2));
    let det = d11 * d22 - d12 * d12;
    ((d22 * r1 - d12 * r2) / det, (d11 * r2 - d12 * r1) / det)
}

/// Maps an angle in (−π, π] to [0, 1).
fn unit_angle(phi: f64) -> f64 {
    let t = phi / (2.0 * PI);
    if t < 0.0 {
        t + 1.0
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Round-trip tolerance: the warps are a few flops of f64 (plus one atan2 / sqrt).
    const ROUND_TRIP_TOL: f64 = 1e-12;

    fn grid(n: usize) -> impl Iterator<Item = DVec2> {
        (0..n).flat_map(move |i| {
            (0..n).map(move |j| DVec2::new((i as f64 + 0.37) / n as f64, (j as f64 + 0.61) / n as f64))
        })
    }

    #[test]
    fn hemisphere_warps_round_trip() {
        for u in grid(40) {
            let w = sample_uniform_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 1e-14 && w.z >= 0.0);
            let back = invert_uniform_hemisphere(w);
            assert!((back - u).length() < ROUND_TRIP_TOL, "uniform {u} -> {w} -> {back}");
            let w = sample_cosine_hemisphere(u);
            assert!((w.length() - 1.0).abs() < 1e-14 && w.z >= 0.0);
            let back = invert_cosine_hemisphere(w);
            assert!((back - u).length() < ROUND_TRIP_TOL, "cosine {u} -> {w} -> {back}");
        }
    }

    /// The pdf integrates to 1 and matches the histogram of the warp: the fraction of samples
    /// with cosθ > c is ∫ pdf over that cap (uniform: 1 − c; cosine: 1 − c²).
    #[test]
    fn hemisphere_pdfs_match_the_warps() {
        let n = 200;
        let samples: Vec<DVec2> = grid(n).collect();
        for c in [0.1, 0.5, 0.9] {
            let uni = samples.iter().filter(|u| sample_uniform_hemisphere(**u).z > c).count() as f64;
            let cos = samples.iter().filter(|u| sample_cosine_hemisphere(**u).z > c).count() as f64;
            let total = samples.len() as f64;
            // Cap integral of each pdf: 2π∫_c^1 pdf(μ) dμ.
            let uni_cap = 2.0 * PI * uniform_hemisphere_pdf() * (1.0 - c);
            let cos_cap = 2.0 * PI * (0.5 * FRAC_1_PI) * (1.0 - c * c);
            assert!((uni / total - uni_cap).abs() < 2e-3, "uniform cap {c}: {} vs {uni_cap}", uni / total);
            assert!((cos / total - cos_cap).abs() < 2e-3, "cosine cap {c}: {} vs {cos_cap}", cos / total);
        }
        assert!((cosine_hemisphere_pdf(1.0) - FRAC_1_PI).abs() < 1e-16);
        assert_eq!(cosine_hemisphere_pdf(-0.5), 0.0);
    }

    #[test]
    fn polygon_sampler_round_trips_and_is_area_uniform() {
        // An L-shaped (non-convex) hexagon, area 3.
        let p = Polygon::new(vec![
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(2.0, 0.0, 1.0),
            DVec3::new(2.0, 1.0, 1.0),
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(1.0, 2.0, 1.0),
            DVec3::new(0.0, 2.0, 1.0),
        ])
        .unwrap();
        let s = PolygonSampler::new(&p);
        assert!((s.area() - 3.0).abs() < 1e-14 && (s.pdf() - 1.0 / 3.0).abs() < 1e-15);
        let mut in_square = 0usize;
        let mut total = 0usize;
        for u in grid(60) {
            let x = s.sample(u);
            assert!((x.z - 1.0).abs() < 1e-15);
            assert!(!(x.x > 1.0 && x.y > 1.0), "sample outside the L: {x}");
            let k = s.select(u.x).0;
            let back = s.invert(k, x);
            assert!((back - u).length() < ROUND_TRIP_TOL, "{u} -> {x} -> {back}");
            total += 1;
            in_square += usize::from(x.x < 1.0 && x.y < 1.0);
        }
        assert!(s.contains(DVec3::new(0.5, 1.5, 1.0)) && !s.contains(DVec3::new(1.5, 1.5, 1.0)));
        assert!(!s.contains(DVec3::new(-0.1, 0.5, 1.0)) && s.contains(DVec3::new(1.9, 0.1, 1.0)));
        // The unit corner square holds 1/3 of the area.
        let frac = in_square as f64 / total as f64;
        assert!((frac - 1.0 / 3.0).abs() < 0.01, "corner fraction {frac}");
    }
}
