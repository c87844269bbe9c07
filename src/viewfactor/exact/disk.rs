//! Exact element-to-disk factor for any position and orientation (docs/literature.md V11).
//!
//! Lambert's contour integral on the exact circle x(φ) = c + R(cos φ u + sin φ w), u × w = m:
//! with R⃗ = x − p, the integrand n·(R⃗ × dR⃗)/|R⃗|² is (A + B cos φ + C sin φ)/(D + E cos φ +
//! G sin φ) dφ, a rational trigonometric function with closed-form integrals.
//! - Whole disk in the element's front half-space:
//!   F = −A/S + (BE + CG)/((S + D)S), S = √(D² − E² − G²), free of cancellation.
//! - Element plane cutting the disk: the visible circular segment is bounded by an arc (closed
//!   form through ∫dψ/(D + ρ cos ψ) = (2/S) atan(k tan ψ/2), or Gauss–Legendre when ρ = √(E²+G²)
//!   is small and the closed form would cancel) and a chord (one Lambert edge term).
//! - Disk entirely behind the element, or element not in front of the disk: 0.
use super::lambert::edge_term;
use crate::geometry::quadrature::gauss_legendre;
use crate::scene::Disk;
use glam::DVec3;
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

/// Below ρ/D = this the arc is integrated by Gauss–Legendre: its integrand's poles sit at
/// Im ψ = ±acosh(D/ρ) ≥ 2.06, so 16 points per quarter turn reach round-off, while the closed
/// form would lose digits to the 1/ρ cancellation.
const ARC_CLOSED_MIN: f64 = 0.25;
/// Gauss points per quarter turn of arc.
const ARC_POINTS: usize = 16;

/// Exact element-to-disk factor, any position/orientation the closed forms cover (V11).
pub fn point_to_disk(p: DVec3, n: DVec3, disk: &Disk) -> f64 {
    let m = disk.normal.normalize();
    let big_r = disk.radius;
    let v = disk.center - p;
    // Step: the element must be in front of the disk.
    if -v.dot(m) <= 0.0 || big_r.is_nan() || big_r <= 0.0 {
        return 0.0;
    }
    let u = m.any_orthonormal_vector();
    let w = m.cross(u);
    let coeffs = Coeffs::new(v, n, u, w, m, big_r);
    // Step: which part of the circle lies in the element's front half-space.
    let (nu, nw) = (n.dot(u), n.dot(w));
    let kappa = nu.hypot(nw);
    let vn = v.dot(n);
    if vn >= big_r * kappa {
        return coeffs.full().max(0.0);
    }
    if vn <= -big_r * kappa {
        return 0.0;
    }
    let centre = nw.atan2(nu);
    let half = (-vn / (big_r * kappa)).clamp(-1.0, 1.0).acos();
    let (phi_a, phi_b) = (centre - half, centre + half);
    let at = |phi: f64| v + big_r * (phi.cos() * u + phi.sin() * w);
    // Contour: arc from φa to φb (counter-clockwise about m), then the chord back.
    let arc = coeffs.arc(phi_a, phi_b);
    let chord = edge_term(n, at(phi_b), at(phi_a));
    (-arc / TAU + chord / TAU).max(0.0)
}

/// Coefficients of n·(R⃗ × dR⃗/dφ) = A + B cos φ + C sin φ and |R⃗|² = D + E cos φ + G sin φ,
/// with D ∓ ρ = (R ∓ a)² + h² (a: distance of p from the axis, h: height) kept apart.
struct Coeffs {
    a: f64,
    b: f64,
    c: f64,
    d: f64,
    e: f64,
    g: f64,
    d_minus: f64,
    d_plus: f64,
}

impl Coeffs {
    fn new(v: DVec3, n: DVec3, u: DVec3, w: DVec3, m: DVec3, r: f64) -> Self {
        let h = v.dot(m);
        let axis = v.dot(u).hypot(v.dot(w));
        Self {
            a: r * r * m.dot(n),
            b: r * v.cross(w).dot(n),
            c: -r * v.cross(u).dot(n),
            d: v.length_squared() + r * r,
            e: 2.0 * r * v.dot(u),
            g: 2.0 * r * v.dot(w),
            d_minus: (r - axis).powi(2) + h * h,
            d_plus: (r + axis).powi(2) + h * h,
        }
    }

    /// S = √(D² − ρ²) = √((D − ρ)(D + ρ)), without cancellation.
    fn s(&self) -> f64 {
        self.d_minus.sqrt() * self.d_plus.sqrt()
    }

    /// F for the whole circle: −(1/2π)∮ = −A/S + (BE + CG)/((S + D)S).
    fn full(&self) -> f64 {
        let s = self.s();
        -self.a / s + (self.b * self.e + self.c * self.g) / ((s + self.d) * s)
    }

    /// ∫_{φa}^{φb} (A + B cos φ + C sin φ)/(D + E cos φ + G sin φ) dφ.
    fn arc(&self, phi_a: f64, phi_b: f64) -> f64 {
        let rho = self.e.hypot(self.g);
        if rho < ARC_CLOSED_MIN * self.d {
            return self.arc_gauss(phi_a, phi_b);
        }
        // Step: rotate by φ0 so the denominator is D + ρ cos ψ.
        let phi0 = self.g.atan2(self.e);
        let (b1, b2) = ((self.b * self.e + self.c * self.g) / rho, (self.c * self.e - self.b * self.g) / rho);
        let (pa, pb) = (phi_a - phi0, phi_b - phi0);
        let s = self.s();
        let k = (self.d_minus / self.d_plus).sqrt();
        let t = |psi: f64| lifted_half_angle(psi, k) / s;
        let dt = t(pb) - t(pa);
        let dlog = ((self.d + rho * pb.cos()) / (self.d + rho * pa.cos())).ln();
        self.a * dt + b1 * ((pb - pa) - self.d * dt) / rho - b2 * dlog / rho
    }

    fn arc_gauss(&self, phi_a: f64, phi_b: f64) -> f64 {
        static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
        let (x, wt) = RULE.get_or_init(|| gauss_legendre(ARC_POINTS));
        let pieces = ((phi_b - phi_a) / (0.5 * PI)).ceil().max(1.0) as usize;
        let h = (phi_b - phi_a) / pieces as f64;
        let mut sum = 0.0;
        for k in 0..pieces {
            let l = phi_a + k as f64 * h;
            for (&x, &w) in x.iter().zip(wt) {
                let (s, c) = (l + h * x).sin_cos();
                sum += w * h * (self.a + self.b * c + self.c * s) / (self.d + self.e * c + self.g * s);
            }
        }
        sum
    }
}

/// 2·atan(k·tan(ψ/2)), continued across ψ = ±π so that it increases with ψ.
fn lifted_half_angle(psi: f64, k: f64) -> f64 {
    let turns = (psi / TAU).round();
    let p = psi - turns * TAU;
    let (s, c) = (0.5 * p).sin_cos();
    2.0 * (k * s).atan2(c) + turns * TAU
}
