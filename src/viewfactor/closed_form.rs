//! Closed-form configuration factors: the validation oracles (Howell's catalogue,
//! docs/literature.md §1.1, IDs V1–V19).
//!
//! Conventions: `F` is from surface 1 to surface 2; functions named `*_exchange` return the
//! exchange area A₁F₁₂ (m², or m for 2-D). Every function is f64 arithmetic of the published
//! formula; the tests check each against the printed value.
use std::f64::consts::{FRAC_PI_2, PI};

/// C-11 (V1): identical, parallel, directly opposed rectangles a × b at gap c.
pub fn parallel_opposed_rectangles(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (x2, y2) = (x * x, y * y);
    let (sx, sy) = ((1.0 + x2).sqrt(), (1.0 + y2).sqrt());
    2.0 / (PI * x * y)
        * (0.5 * ((1.0 + x2) * (1.0 + y2) / (1.0 + x2 + y2)).ln()
            + x * sy * (x / sy).atan()
            + y * sx * (y / sx).atan()
            - x * x.atan()
            - y * y.atan())
}

/// C-14 (V2, V3): perpendicular rectangles with a common edge of length l; surface 1 has width
/// w, surface 2 height h (both measured away from the common edge).
pub fn perpendicular_common_edge(w: f64, h: f64, l: f64) -> f64 {
    let (bw, bh) = (w / l, h / l);
    let (w2, h2) = (bw * bw, bh * bh);
    let s = (w2 + h2).sqrt();
    let angles = bw * (1.0 / bw).atan() + bh * (1.0 / bh).atan() - s * (1.0 / s).atan();
    let logs = ((1.0 + w2) * (1.0 + h2) / (1.0 + w2 + h2)).ln()
        + w2 * (w2 * (1.0 + w2 + h2) / ((1.0 + w2) * (w2 + h2))).ln()
        + h2 * (h2 * (1.0 + w2 + h2) / ((1.0 + h2) * (w2 + h2))).ln();
    (angles + 0.25 * logs) / (PI * bw)
}

/// C-14 exchange area w·l·F₁₂ of the common-edge configuration; 0 when any size is 0.
pub fn perpendicular_common_edge_exchange(w: f64, h: f64, l: f64) -> f64 {
    if w == 0.0 || h == 0.0 || l == 0.0 {
        return 0.0;
    }
    w * l * perpendicular_common_edge(w, h, l)
}

/// Perpendicular rectangles in general aligned position by C-14 algebra (V4, V5, V6): floor
/// x ∈ `x`, y ∈ `y1` (z = 0, facing +z) and wall z ∈ `z`, y ∈ `y2` (x = 0, facing +x); x and z
/// are distances from the intersection line (≥ 0). Returns the exchange area A₁F₁₂.
///
/// Bilinear in the x and z extents (V4: G(b,d) − G(a,d) − G(b,c) + G(a,c)); along y, translation
/// invariance gives ½[Φ(y₁ᵇ − y₂ᵃ) − Φ(y₁ᵇ − y₂ᵇ) − Φ(y₁ᵃ − y₂ᵃ) + Φ(y₁ᵃ − y₂ᵇ)] with Φ(L) the
/// common-edge exchange area of length |L| (V5 corner touch, V6 half-shared edge).
pub fn perpendicular_rectangles_exchange(x: [f64; 2], z: [f64; 2], y1: [f64; 2], y2: [f64; 2]) -> f64 {
    let strip = |w: f64, h: f64| {
        let phi = |l: f64| perpendicular_common_edge_exchange(w, h, l.abs());
        0.5 * (phi(y1[1] - y2[0]) - phi(y1[1] - y2[1]) - phi(y1[0] - y2[0]) + phi(y1[0] - y2[1]))
    };
    strip(x[1], z[1]) - strip(x[0], z[1]) - strip(x[1], z[0]) + strip(x[0], z[0])
}

/// C-13 corner sum (V7): parallel rectangles x ∈ `x`, y ∈ `y` (plane 0) and ξ ∈ `xi`,
/// η ∈ `eta` (plane at distance `z`), facing each other. Returns the exchange area A₁F₁₂.
pub fn parallel_rectangles_exchange(x: [f64; 2], y: [f64; 2], xi: [f64; 2], eta: [f64; 2], z: f64) -> f64 {
    let g = |u: f64, v: f64| {
        let (p, q) = ((u * u + z * z).sqrt(), (v * v + z * z).sqrt());
        let t = |a: f64, b: f64| if a == 0.0 { 0.0 } else { a * b * (a / b).atan() };
        (t(v, p) + t(u, q) - 0.5 * z * z * (u * u + v * v + z * z).ln()) / (2.0 * PI)
    };
    let mut sum = 0.0;
    for (i, &xv) in x.iter().enumerate() {
        for (j, &yv) in y.iter().enumerate() {
            for (k, &ev) in eta.iter().enumerate() {
                for (l, &xiv) in xi.iter().enumerate() {
                    let sign = if (i + j + k + l) % 2 == 0 { 1.0 } else { -1.0 };
                    sum += sign * g(xv - xiv, yv - ev);
                }
            }
        }
    }
    sum
}

/// Section B (V10): element parallel to an a × b rectangle at distance c, its normal through a
/// corner.
pub fn element_to_rectangle_corner(a: f64, b: f64, c: f64) -> f64 {
    let (x, y) = (a / c, b / c);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * PI)
}

/// C-40/C-41 (V8, V9): coaxial parallel disks of radii r1 → r2 at distance h.
pub fn coaxial_disks(r1: f64, r2: f64, h: f64) -> f64 {
    let (a, b) = (r1 / h, r2 / h);
    let s = 1.0 + (1.0 + b * b) / (a * a);
    0.5 * (s - (s * s - 4.0 * (b / a).powi(2)).sqrt())
}

/// B-section (V11): element on the axis of a parallel disk of radius r at height h.
pub fn element_to_disk_on_axis(r: f64, h: f64) -> f64 {
    r * r / (r * r + h * h)
}

/// B-13 (V11): element on the axis of a disk (radius r, height h), tilted by θ: cos θ/(1 + H²)
/// with H = h/r. `None` when the element's plane cuts the disk (tan θ > h/r), where B-13 does
/// not apply.
pub fn element_to_disk_tilted_on_axis(r: f64, h: f64, theta: f64) -> Option<f64> {
    if theta.abs() > FRAC_PI_2 || theta.abs().tan() * r > h {
        return None;
    }
    let big_h = h / r;
    Some(theta.cos() / (1.0 + big_h * big_h))
}

/// Section B (V11): element parallel to a disk of radius r at height h, offset a from the axis.
pub fn element_to_disk_parallel_offset(r: f64, h: f64, a: f64) -> f64 {
    if a == 0.0 {
        return element_to_disk_on_axis(r, h);
    }
    let (bh, br) = (h / a, r / a);
    let (h2, r2) = (bh * bh, br * br);
    0.5 * (1.0 - (1.0 + h2 - r2) / ((1.0 + h2 + r2).powi(2) - 4.0 * r2).sqrt())
}

/// C-125 (V14): sphere to a coaxial disk of radius a whose plane is at distance h from the
/// sphere's centre (independent of the sphere's radius).
pub fn sphere_to_disk(a: f64, h: f64) -> f64 {
    0.5 * (1.0 - 1.0 / (1.0 + (a / h).powi(2)).sqrt())
}

/// C-135 (V13): concentric spheres r1 < r2: (F₁₂, F₂₁, F₂₂).
pub fn concentric_spheres(r1: f64, r2: f64) -> (f64, f64, f64) {
    let f21 = (r1 / r2).powi(2);
    (1.0, f21, 1.0 - f21)
}

/// C-63: infinitely long concentric cylinders r1 < r2: F₂₁ = r1/r2.
pub fn concentric_cylinders(r1: f64, r2: f64) -> f64 {
    r1 / r2
}

/// V16, Hottel's crossed strings (2-D): exchange length L₁F₁₂ between segments a1–b1 and
/// a2–b2, named so that a1–a2 and b1–b2 are the uncrossed strings.
pub fn crossed_strings(a1: [f64; 2], b1: [f64; 2], a2: [f64; 2], b2: [f64; 2]) -> f64 {
    let d = |p: [f64; 2], q: [f64; 2]| (p[0] - q[0]).hypot(p[1] - q[1]);
    0.5 * ((d(a1, b2) + d(b1, a2)) - (d(a1, a2) + d(b1, b2)))
}

/// C-1 (V16): infinitely long parallel plates of equal width w at gap h: √(1 + H²) − H.
pub fn parallel_plates_2d(w: f64, h: f64) -> f64 {
    let big_h = h / w;
    (1.0 + big_h * big_h).sqrt() - big_h
}

/// C-3 (V16): infinitely long plates with a common edge at 90°, widths w (1) and h (2):
/// ½(1 + H − √(1 + H²)), H = h/w.
pub fn perpendicular_plates_2d(w: f64, h: f64) -> f64 {
    let big_h = h / w;
    0.5 * (1.0 + big_h - (1.0 + big_h * big_h).sqrt())
}

/// C-4 (V16): infinitely long equal plates with a common edge at angle α: 1 − sin(α/2).
pub fn wedge_plates_2d(alpha: f64) -> f64 {
    1.0 - (0.5 * alpha).sin()
}

/// C-68 (V17): infinitely long parallel cylinders of radius r at surface gap s.
pub fn parallel_cylinders(r: f64, s: f64) -> f64 {
    let x = 1.0 + s / (2.0 * r);
    ((x * x - 1.0).sqrt() + (1.0 / x).asin() - x) / PI
}

/// C-69 (V18): infinitely long parallel cylinders r1 → r2 at surface gap s.
pub fn parallel_cylinders_unequal(r1: f64, r2: f64, s: f64) -> f64 {
    let (r, c) = (r2 / r1, 1.0 + r2 / r1 + s / r1);
    (PI + (c * c - (r + 1.0).powi(2)).sqrt() - (c * c - (r - 1.0).powi(2)).sqrt()
        + (r - 1.0) * ((r - 1.0) / c).acos()
        - (r + 1.0) * ((r + 1.0) / c).acos())
        / (2.0 * PI)
}

/// Factors between coaxial cylinders of length l: inner (1) radius r1, outer (2) radius r2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CoaxialCylinders {
    /// Inner to outer.
    pub f12: f64,
    /// Outer to inner.
    pub f21: f64,
    /// Outer to itself.
    pub f22: f64,
    /// Outer to both end annuli together, 1 − F₂₁ − F₂₂.
    pub f2_ends: f64,
}

/// V19 (Siegel & Howell, 4th ed. p. 847; C-91): coaxial cylinders of finite length l.
pub fn coaxial_cylinders(r1: f64, r2: f64, l: f64) -> CoaxialCylinders {
    let (r, h) = (r2 / r1, l / r1);
    let a = h * h + r * r - 1.0;
    let b = h * h - r * r + 1.0;
    let f21 = 1.0 / r
        - (1.0 / (PI * r))
            * ((b / a).acos()
                - (1.0 / (2.0 * h))
                    * (((a + 2.0).powi(2) - 4.0 * r * r).sqrt() * (b / (r * a)).acos()
                        + b * (1.0 / r).asin()
                        - PI * a / 2.0));
    let root = (4.0 * r * r + h * h).sqrt();
    let f22 = 1.0 - 1.0 / r + (2.0 / (PI * r)) * (2.0 * (r * r - 1.0).sqrt() / h).atan()
        - (h / (2.0 * PI * r))
            * ((root / h)
                * ((4.0 * (r * r - 1.0) + (h * h / (r * r)) * (r * r - 2.0))
                    / (h * h + 4.0 * (r * r - 1.0)))
                    .asin()
                - ((r * r - 2.0) / (r * r)).asin()
                + FRAC_PI_2 * (root / h - 1.0));
    CoaxialCylinders { f12: r * f21, f21, f22, f2_ends: 1.0 - f21 - f22 }
}
