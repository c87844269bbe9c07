//! The far-field rung of the analytic ladder: tensor Gauss area rules on both patches ("2AI"),
//! used only where an a-priori error bound guarantees the per-pair relative error target.
//!
//! - [`PatchRules`]: per-patch Gauss points (SoA) for every order, cached for low orders;
//! - [`gauss_exchange`]: s_ij = (1/π) Σ_a Σ_b w_a w_b cosθ_a cosθ_b / r_ab² on two point sets;
//! - [`ErrorModel`]: the smallest order per patch that meets the target at a separation.
//!
//! **Pieces.** A parallelogram patch takes an n×n tensor rule directly; any other polygon is
//! triangulated once and each triangle takes the collapsed (Duffy) n×n rule.
//!
//! **Error bound.** Fix all integration variables but one; along that parameter s ∈ [0, 1] the
//! point moves on a line x(s) = x₀ + s·u (|u| ≤ L, the patch's *parameter length*), and the
//! integrand is ℓ(s)·g(s): ℓ ≥ 0 is linear (the cosine factor of the other patch, times the
//! Duffy Jacobian on triangles) and g = 1/(π r²(s)²) with r²(s) = |u|²(s − s₀)² + d².
//! g has double poles at s₀ ± i·d/|u|, whose distance to the real segment is
//! min_t |x(t) − y|/|u| ≥ D/L, D being a lower bound of the distance between the patches.
//! By the Bernstein-ellipse theorem (Trefethen, ATAP Thm 19.3) the m-point Gauss error on
//! that slice decays like ρ^(−2m), ρ = 1 + 2λ + 2√(λ² + λ) the ellipse through a pole at
//! normalised distance 2λ beyond an end of [−1, 1], λ = D/L. The tensor-rule error is the sum
//! of the slice errors (each weighted by a positive rule), so the relative pair error is at most
//! E(m_i, λ_i) + E(m_j, λ_j) with E(m, λ) = K_m·ρ(λ)^(−2m)·(1 + 1/λ)^P per patch (two slice
//! directions each). The rigorous constants of the theorem are 10³–10⁵ times pessimistic here
//! (they bound |ℓ| and |g| on the whole ellipse), so K_m and P are *calibrated*: measured
//! maxima over a sweep of worst-case geometries (parallel, offset, perpendicular and grazing,
//! tilted, random; squares, long rectangles and triangles), times [`SAFETY`]. The calibration
//! is the example `ladder_calibration`; `tests/analytic_method.rs` sweeps separations and
//! asserts that the ladder never exceeds its target.
use crate::geometry::quadrature::{gauss_legendre, AreaRule};
use crate::geometry::Polygon;
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// Highest Gauss order on a patch; beyond it the exact contour integral is as cheap.
pub const MAX_ORDER: usize = 6;
/// Orders 1..=CACHED_ORDERS are precomputed per patch (the far field uses them); higher
/// orders are generated per pair, where their n⁴ kernel evaluations dominate anyway.
pub const CACHED_ORDERS: usize = 4;
/// Relative tolerance for "this quad is a parallelogram" (f32 CAD round-off is ~1e-7).
const PARALLELOGRAM_TOL: f64 = 1e-9;

/// A piece of a patch on which a tensor Gauss rule is polynomially exact.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Piece {
    /// o + s·u + t·v, s, t ∈ [0, 1].
    Parallelogram { o: DVec3, u: DVec3, v: DVec3 },
    /// Triangle a, b, c (Duffy-collapsed square).
    Triangle { a: DVec3, b: DVec3, c: DVec3 },
}

impl Piece {
    /// Longest parameter-direction length |∂x/∂s| over the piece (the L of the bound).
    fn param_len(&self) -> f64 {
        match *self {
            Piece::Parallelogram { u, v, .. } => u.length().max(v.length()),
            Piece::Triangle { a, b, c } => a.distance(b).max(b.distance(c)).max(c.distance(a)),
        }
    }
    /// Appends the order-`order` tensor rule (the same nodes as
    /// [`AreaRule::parallelogram`] / [`AreaRule::triangle`], from cached 1-D nodes).
    fn push_rule(&self, order: usize, out: &mut Points) {
        let (x, w) = gauss_nodes(order);
        match *self {
            Piece::Parallelogram { o, u, v } => {
                let area = u.cross(v).length();
                for (xs, ws) in x.iter().zip(w) {
                    for (xt, wt) in x.iter().zip(w) {
                        out.push(o + *xs * u + *xt * v, area * ws * wt);
                    }
                }
            }
            Piece::Triangle { a, b, c } => {
                let area = 0.5 * (b - a).cross(c - a).length();
                for (xs, ws) in x.iter().zip(w) {
                    for (xt, wt) in x.iter().zip(w) {
                        let t = xt * (1.0 - xs);
                        out.push(a + *xs * (b - a) + t * (c - a), 2.0 * area * ws * wt * (1.0 - xs));
                    }
                }
            }
        }
    }
}

/// Splits a polygon into Gauss pieces: itself when it is a parallelogram or a triangle,
/// otherwise its triangles.
fn pieces_of(poly: &Polygon) -> Vec<Piece> {
    let v = poly.vertices();
    if v.len() == 3 {
        return vec![Piece::Triangle { a: v[0], b: v[1], c: v[2] }];
    }
    if v.len() == 4 {
        let (u, w) = (v[1] - v[0], v[3] - v[0]);
        let scale = u.length().max(w.length());
        if (v[2] - (v[0] + u + w)).length() <= PARALLELOGRAM_TOL * scale {
            return vec![Piece::Parallelogram { o: v[0], u, v: w }];
        }
    }
    poly.triangulate().into_iter().map(|[a, b, c]| Piece::Triangle { a, b, c }).collect()
}

/// Gauss points in structure-of-arrays form; weights in m² (they sum to the area).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Points {
    /// x coordinates.
    pub x: Vec<f64>,
    /// y coordinates.
    pub y: Vec<f64>,
    /// z coordinates.
    pub z: Vec<f64>,
    /// Weights, m².
    pub w: Vec<f64>,
}

impl Points {
    /// Empties the set, keeping its capacity.
    pub fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.w.clear();
    }
    /// Appends one point.
    pub fn push(&mut self, p: DVec3, w: f64) {
        self.x.push(p.x);
        self.y.push(p.y);
        self.z.push(p.z);
        self.w.push(w);
    }
    /// Appends every point of an [`AreaRule`].
    pub fn push_rule(&mut self, r: &AreaRule) {
        for (p, w) in r.points.iter().zip(&r.weights) {
            self.push(*p, *w);
        }
    }
    /// Borrowed view.
    pub fn view(&self) -> PointsRef<'_> {
        PointsRef { x: &self.x, y: &self.y, z: &self.z, w: &self.w }
    }
}

/// Borrowed SoA points.
#[derive(Debug, Clone, Copy)]
pub struct PointsRef<'a> {
    /// x coordinates.
    pub x: &'a [f64],
    /// y coordinates.
    pub y: &'a [f64],
    /// z coordinates.
    pub z: &'a [f64],
    /// Weights, m².
    pub w: &'a [f64],
}

/// Gauss pieces and cached low-order rules of every patch of a scene.
#[derive(Debug, Clone, Default)]
pub struct PatchRules {
    pieces: Vec<Piece>,
    piece_start: Vec<u32>,
    param_len: Vec<f64>,
    cache: Points,
    /// Start of (patch p, order o) at p·CACHED_ORDERS + o − 1.
    cache_start: Vec<u32>,
}

impl PatchRules {
    /// Decomposes every polygon and caches its rules of order 1..=[`CACHED_ORDERS`].
    pub fn new<'a>(polys: impl IntoIterator<Item = &'a Polygon>) -> Self {
        let mut r = PatchRules::default();
        r.piece_start.push(0);
        r.cache_start.push(0);
        for poly in polys {
            let pieces = pieces_of(poly);
            r.param_len.push(pieces.iter().map(Piece::param_len).fold(0.0, f64::max));
            for order in 1..=CACHED_ORDERS {
                for piece in &pieces {
                    piece.push_rule(order, &mut r.cache);
                }
                r.cache_start.push(r.cache.w.len() as u32);
            }
            r.pieces.extend(pieces);
            r.piece_start.push(r.pieces.len() as u32);
        }
        r
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.param_len.len()
    }
    /// True when there are no patches.
    pub fn is_empty(&self) -> bool {
        self.param_len.is_empty()
    }
    /// The L of the error bound: the longest parameter-direction length of the patch's pieces.
    pub fn param_len(&self, p: usize) -> f64 {
        self.param_len[p]
    }
    /// True when patch `p` is integrated on Duffy triangles (not a single parallelogram).
    pub fn triangulated(&self, p: usize) -> bool {
        matches!(self.pieces[self.piece_start[p] as usize], Piece::Triangle { .. })
    }

    /// The order-`order` rule of patch `p`, from the cache or generated into `buf`.
    #[inline]
    pub fn points<'a>(&'a self, p: usize, order: usize, buf: &'a mut Points) -> PointsRef<'a> {
        debug_assert!((1..=MAX_ORDER).contains(&order));
        if order <= CACHED_ORDERS {
            let k = p * CACHED_ORDERS + order - 1;
            let (a, b) = (self.cache_start[k] as usize, self.cache_start[k + 1] as usize);
            let c = &self.cache;
            return PointsRef { x: &c.x[a..b], y: &c.y[a..b], z: &c.z[a..b], w: &c.w[a..b] };
        }
        buf.clear();
        let range = self.piece_start[p] as usize..self.piece_start[p + 1] as usize;
        for piece in &self.pieces[range] {
            piece.push_rule(order, buf);
        }
        buf.view()
    }
}

/// Exchange area s_ij = ∫∫ cosθ_i cosθ_j /(π r²) dA_j dA_i by the product of two point rules,
/// with the separable numerator (y_b·n_i − h_i)(x_a·n_j − h_j) (h = plane offset n·p).
/// Both patches must lie in front of each other's plane, and apart (r > 0 at every node pair).
/// `scratch` is reused across calls. Bit-identical with and without AVX (no FMA contraction).
pub fn gauss_exchange(
    pi: PointsRef,
    ni: DVec3,
    hi: f64,
    pj: PointsRef,
    nj: DVec3,
    hj: f64,
    scratch: &mut Vec<f64>,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: AVX was detected on this CPU just above.
        return unsafe { simd::exchange(pi, ni, hi, pj, nj, hj, scratch) } / PI;
    }
    let (beta, gamma) = weights(pi, ni, hi, pj, nj, hj, scratch);
    pair_sum(pi, beta, pj, gamma) / PI
}

/// Emitter weights β_a = w_a·(x_a·n_j − h_j) and receiver weights γ_b = w_b·(y_b·n_i − h_i),
/// stored in `scratch`.
#[inline(always)]
fn weights<'s>(
    pi: PointsRef,
    ni: DVec3,
    hi: f64,
    pj: PointsRef,
    nj: DVec3,
    hj: f64,
    scratch: &'s mut Vec<f64>,
) -> (&'s [f64], &'s [f64]) {
    let (na, nb) = (pi.w.len(), pj.w.len());
    scratch.resize(na + nb, 0.0);
    let (beta, gamma) = scratch.split_at_mut(na);
    let (xi, yi, zi, wi) = (&pi.x[..na], &pi.y[..na], &pi.z[..na], &pi.w[..na]);
    for a in 0..na {
        beta[a] = wi[a] * (xi[a] * nj.x + yi[a] * nj.y + zi[a] * nj.z - hj);
    }
    let (xj, yj, zj, wj) = (&pj.x[..nb], &pj.y[..nb], &pj.z[..nb], &pj.w[..nb]);
    for b in 0..nb {
        gamma[b] = wj[b] * (xj[b] * ni.x + yj[b] * ni.y + zj[b] * ni.z - hi);
    }
    (beta, gamma)
}

/// Σ_a Σ_b β_a γ_b / r_ab⁴ (r_ab > 0), the reference order of operations that the AVX path
/// reproduces bit for bit: rows a take receivers b in chunks of 8, whose halves (4 lanes
/// each) share one division, γ₀/q₀ + γ₁/q₁ = (γ₀q₁ + γ₁q₀)/(q₀q₁) with q = r⁴ (q₀q₁ = r⁸
/// stays in range for 1e-38 < r < 1e38), then a chunk of 4; row lanes are weighted by β_a
/// and summed across lanes once. The leftover receivers (< 4) are summed as columns over a
/// in the same way; the last corner term by term.
#[allow(clippy::needless_range_loop)] // (a, b) index pairs read clearer than zipped iterators
#[inline(always)]
fn pair_sum(pi: PointsRef, beta: &[f64], pj: PointsRef, gamma: &[f64]) -> f64 {
    let (na, nb) = (beta.len(), gamma.len());
    let (b8, b4) = (nb - nb % 8, nb - nb % 4);
    let (a8, a4) = (na - na % 8, na - na % 4);
    let q = |a: usize, b: usize| {
        let (dx, dy, dz) = (pj.x[b] - pi.x[a], pj.y[b] - pi.y[a], pj.z[b] - pi.z[a]);
        let r2 = dx * dx + dy * dy + dz * dz;
        r2 * r2
    };
    // Rows: lane sums weighted by β_a, one horizontal sum at the end.
    let mut rows = [0.0f64; 4];
    for a in 0..na {
        let mut acc = [0.0f64; 4];
        for b in (0..b8 / 8).map(|c| 8 * c) {
            for k in 0..4 {
                let (ql, qh) = (q(a, b + k), q(a, b + 4 + k));
                acc[k] += (gamma[b + k] * qh + gamma[b + 4 + k] * ql) / (ql * qh);
            }
        }
        for b in (b8 / 4..b4 / 4).map(|c| 4 * c) {
            for k in 0..4 {
                acc[k] += gamma[b + k] / q(a, b + k);
            }
        }
        for k in 0..4 {
            rows[k] += beta[a] * acc[k];
        }
    }
    let mut total = (rows[0] + rows[1]) + (rows[2] + rows[3]);
    for b in b4..nb {
        let mut acc = [0.0f64; 4];
        for a in (0..a8 / 8).map(|c| 8 * c) {
            for k in 0..4 {
                let (ql, qh) = (q(a + k, b), q(a + 4 + k, b));
                acc[k] += (beta[a + k] * qh + beta[a + 4 + k] * ql) / (ql * qh);
            }
        }
        for a in (a8 / 4..a4 / 4).map(|c| 4 * c) {
            for k in 0..4 {
                acc[k] += beta[a + k] / q(a + k, b);
            }
        }
        let mut col = (acc[0] + acc[1]) + (acc[2] + acc[3]);
        for a in a4..na {
            col += beta[a] / q(a, b);
        }
        total += gamma[b] * col;
    }
    total
}

/// The AVX version of [`pair_sum`].
#[cfg(target_arch = "x86_64")]
mod simd {
    use super::PointsRef;
    use glam::DVec3;
    use std::arch::x86_64::*;

    /// Sum of the four lanes as ((l0 + l1) + (l2 + l3)), matching the portable order.
    #[inline(always)]
    unsafe fn hsum(v: __m256d) -> f64 {
        let mut l = [0.0f64; 4];
        _mm256_storeu_pd(l.as_mut_ptr(), v);
        (l[0] + l[1]) + (l[2] + l[3])
    }

    /// r⁴ between one broadcast point (x, y, z) and four points loaded from `p` at `k`.
    #[inline(always)]
    unsafe fn q4(p: PointsRef, k: usize, x: __m256d, y: __m256d, z: __m256d) -> __m256d {
        let dx = _mm256_sub_pd(_mm256_loadu_pd(p.x.as_ptr().add(k)), x);
        let dy = _mm256_sub_pd(_mm256_loadu_pd(p.y.as_ptr().add(k)), y);
        let dz = _mm256_sub_pd(_mm256_loadu_pd(p.z.as_ptr().add(k)), z);
        let r2 =
            _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy)), _mm256_mul_pd(dz, dz));
        _mm256_mul_pd(r2, r2)
    }

    /// Four lanes of (w_lo·q_hi + w_hi·q_lo)/(q_lo·q_hi).
    #[inline(always)]
    unsafe fn paired(wl: __m256d, wh: __m256d, ql: __m256d, qh: __m256d) -> __m256d {
        _mm256_div_pd(_mm256_add_pd(_mm256_mul_pd(wl, qh), _mm256_mul_pd(wh, ql)), _mm256_mul_pd(ql, qh))
    }

    /// π·s_ij as [`super::gauss_exchange`] computes it, compiled for AVX.
    ///
    /// # Safety
    /// The CPU must support AVX.
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn exchange(
        pi: PointsRef,
        ni: DVec3,
        hi: f64,
        pj: PointsRef,
        nj: DVec3,
        hj: f64,
        scratch: &mut Vec<f64>,
    ) -> f64 {
        let (na, nb) = (pi.w.len(), pj.w.len());
        scratch.resize(na + nb, 0.0);
        let (beta, gamma) = scratch.split_at_mut(na);
        weights4(pi, nj, hj, beta);
        weights4(pj, ni, hi, gamma);
        pair_sum(pi, beta, pj, gamma)
    }

    /// out_k = w_k·(((x_k·n.x + y_k·n.y) + z_k·n.z) − h), four at a time, in the scalar order of
    /// [`super::weights`].
    #[inline(always)]
    unsafe fn weights4(p: PointsRef, n: DVec3, h: f64, out: &mut [f64]) {
        let len = out.len();
        assert!(p.x.len() >= len && p.y.len() >= len && p.z.len() >= len && p.w.len() >= len);
        let (nx, ny, nz, hv) =
            (_mm256_set1_pd(n.x), _mm256_set1_pd(n.y), _mm256_set1_pd(n.z), _mm256_set1_pd(h));
        let l4 = len - len % 4;
        for k in (0..l4 / 4).map(|c| 4 * c) {
            let x = _mm256_mul_pd(_mm256_loadu_pd(p.x.as_ptr().add(k)), nx);
            let y = _mm256_mul_pd(_mm256_loadu_pd(p.y.as_ptr().add(k)), ny);
            let z = _mm256_mul_pd(_mm256_loadu_pd(p.z.as_ptr().add(k)), nz);
            let d = _mm256_sub_pd(_mm256_add_pd(_mm256_add_pd(x, y), z), hv);
            _mm256_storeu_pd(out.as_mut_ptr().add(k), _mm256_mul_pd(_mm256_loadu_pd(p.w.as_ptr().add(k)), d));
        }
        for (k, o) in out.iter_mut().enumerate().take(len).skip(l4) {
            *o = p.w[k] * (p.x[k] * n.x + p.y[k] * n.y + p.z[k] * n.z - h);
        }
    }

    /// [`super::pair_sum`] with 4-lane AVX vectors.
    ///
    /// # Safety
    /// The CPU must support AVX; slices must have the lengths of `beta` / `gamma`.
    #[target_feature(enable = "avx")]
    #[inline]
    #[allow(clippy::needless_range_loop)] // mirrors the portable loops index for index
    pub(super) unsafe fn pair_sum(pi: PointsRef, beta: &[f64], pj: PointsRef, gamma: &[f64]) -> f64 {
        let (na, nb) = (beta.len(), gamma.len());
        assert!(pi.x.len() >= na && pi.y.len() >= na && pi.z.len() >= na);
        assert!(pj.x.len() >= nb && pj.y.len() >= nb && pj.z.len() >= nb);
        let (b8, b4) = (nb - nb % 8, nb - nb % 4);
        let (a8, a4) = (na - na % 8, na - na % 4);
        let mut rows = _mm256_setzero_pd();
        for a in 0..na {
            let (x, y, z) = (_mm256_set1_pd(pi.x[a]), _mm256_set1_pd(pi.y[a]), _mm256_set1_pd(pi.z[a]));
            let mut acc = _mm256_setzero_pd();
            for b in (0..b8 / 8).map(|c| 8 * c) {
                let (ql, qh) = (q4(pj, b, x, y, z), q4(pj, b + 4, x, y, z));
                let (gl, gh) =
                    (_mm256_loadu_pd(gamma.as_ptr().add(b)), _mm256_loadu_pd(gamma.as_ptr().add(b + 4)));
                acc = _mm256_add_pd(acc, paired(gl, gh, ql, qh));
            }
            for b in (b8 / 4..b4 / 4).map(|c| 4 * c) {
                let g = _mm256_loadu_pd(gamma.as_ptr().add(b));
                acc = _mm256_add_pd(acc, _mm256_div_pd(g, q4(pj, b, x, y, z)));
            }
            rows = _mm256_add_pd(rows, _mm256_mul_pd(_mm256_set1_pd(beta[a]), acc));
        }
        let mut total = hsum(rows);
        for b in b4..nb {
            let (x, y, z) = (_mm256_set1_pd(pj.x[b]), _mm256_set1_pd(pj.y[b]), _mm256_set1_pd(pj.z[b]));
            let mut acc = _mm256_setzero_pd();
            // r is symmetric: (x_a − y_b)² = (y_b − x_a)² exactly, so loading a-points works.
            for a in (0..a8 / 8).map(|c| 8 * c) {
                let (ql, qh) = (q4(pi, a, x, y, z), q4(pi, a + 4, x, y, z));
                let (wl, wh) =
                    (_mm256_loadu_pd(beta.as_ptr().add(a)), _mm256_loadu_pd(beta.as_ptr().add(a + 4)));
                acc = _mm256_add_pd(acc, paired(wl, wh, ql, qh));
            }
            for a in (a8 / 4..a4 / 4).map(|c| 4 * c) {
                let w = _mm256_loadu_pd(beta.as_ptr().add(a));
                acc = _mm256_add_pd(acc, _mm256_div_pd(w, q4(pi, a, x, y, z)));
            }
            let mut col = hsum(acc);
            for a in a4..na {
                let (dx, dy, dz) = (pj.x[b] - pi.x[a], pj.y[b] - pi.y[a], pj.z[b] - pi.z[a]);
                let r2 = dx * dx + dy * dy + dz * dz;
                col += beta[a] / (r2 * r2);
            }
            total += gamma[b] * col;
        }
        total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(o: DVec3, u: DVec3, v: DVec3) -> Polygon {
        Polygon::new(vec![o, o + u, o + u + v, o + v]).unwrap()
    }

    #[test]
    fn cached_rules_match_area_rules() {
        let p = square(DVec3::new(0.1, 0.2, 0.3), DVec3::new(0.5, 0.1, 0.0), DVec3::new(-0.1, 0.4, 0.2));
        let t = Polygon::new(vec![DVec3::ZERO, DVec3::X, DVec3::new(0.3, 0.8, 0.1)]).unwrap();
        let rules = PatchRules::new([&p, &t]);
        let mut buf = Points::default();
        for order in 1..=MAX_ORDER {
            let v = p.vertices();
            let want = AreaRule::parallelogram(v[0], v[1] - v[0], v[3] - v[0], order);
            let got = rules.points(0, order, &mut buf);
            for (k, q) in want.points.iter().enumerate() {
                assert!((DVec3::new(got.x[k], got.y[k], got.z[k]) - *q).length() < 1e-15, "order {order}");
                assert!((got.w[k] - want.weights[k]).abs() < 1e-15);
            }
            let tv = t.vertices();
            let want = AreaRule::triangle(tv[0], tv[1], tv[2], order);
            let got = rules.points(1, order, &mut buf);
            let sum: f64 = got.w.iter().sum();
            assert!((sum - t.area()).abs() < 1e-15, "order {order}");
            assert_eq!(got.w.len(), want.weights.len());
        }
        assert!(!rules.triangulated(0) && rules.triangulated(1));
    }

    #[test]
    fn thresholds_fall_with_the_order_and_orders_meet_the_budget() {
        for tol in [1e-3, 5e-8, 1e-10, 1e-12] {
            let model = ErrorModel::new(tol);
            for (kind, table) in model.lambda_min.iter().enumerate() {
                for m in 1..MAX_ORDER {
                    for (bin, (now, before)) in table[m].iter().zip(&table[m - 1]).enumerate() {
                        assert!(
                            now <= before,
                            "tol {tol} kind {kind} order {} bin {bin}",
                            m + 1
                        );
                    }
                }
            }
            // The chosen order meets the budget at ν; the one below it fails at ν rounded up to
            // its bin edge (the lookup is conservative by at most one bin).
            let tol_ok = model.side_tol() * (1.0 + 1e-9);
            for k in 0..2000 {
                let lambda = 0.3 * 1.01f64.powi(k);
                let (lo, hi) = (k as f64 % 7.0, 7.0);
                for tri in [false, true] {
                    let nu = if tri { 2.0 } else { 2.0 * (hi - lo) / (hi + lo) };
                    let nu_edge = (nu * NU_BINS as f64 / 2.0).ceil() * 2.0 / NU_BINS as f64;
                    match model.order(tri, lambda, lo, hi) {
                        Some(m) => {
                            assert!(
                                ErrorModel::side_error(m, tri, lambda, nu) <= tol_ok,
                                "λ {lambda} ν {nu} m {m}"
                            );
                            if m > 1 {
                                assert!(
                                    ErrorModel::side_error(m - 1, tri, lambda, nu_edge)
                                        > model.side_tol() * 0.999
                                );
                            }
                        }
                        None => assert!(
                            ErrorModel::side_error(MAX_ORDER, tri, lambda, nu_edge)
                                > model.side_tol() * 0.999
                        ),
                    }
                }
            }
        }
    }

    #[test]
    #[allow(clippy::needless_range_loop)] // the plain reference loop indexes four arrays
    fn simd_and_portable_sums_agree_bit_for_bit() {
        // Point counts that exercise every chunk path: 1, 4, 9, 16, 25, 36 and triangle pairs.
        let a = square(DVec3::ZERO, DVec3::X, DVec3::Y);
        let b = square(DVec3::new(0.3, 0.2, 2.0), DVec3::Y, DVec3::X);
        let t = Polygon::new(vec![
            DVec3::new(0.0, 0.0, 1.5),
            DVec3::new(1.0, 0.5, 3.0),
            DVec3::new(0.0, 1.0, 2.0),
        ])
        .unwrap()
        .flipped();
        let rules = PatchRules::new([&a, &b, &t]);
        let (mut b1, mut b2) = (Points::default(), Points::default());
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            for mi in 1..=MAX_ORDER {
                for mj in 1..=MAX_ORDER {
                    let pi = rules.points(p, mi, &mut b1);
                    let pj = rules.points(q, mj, &mut b2);
                    let beta: Vec<f64> = (0..pi.w.len()).map(|k| pi.w[k] * (1.0 + k as f64)).collect();
                    let gamma: Vec<f64> =
                        (0..pj.w.len()).map(|k| pj.w[k] * (2.0 - 0.01 * k as f64)).collect();
                    let portable = pair_sum(pi, &beta, pj, &gamma);
                    #[cfg(target_arch = "x86_64")]
                    if std::arch::is_x86_feature_detected!("avx") {
                        // SAFETY: AVX detected.
                        let simd = unsafe { simd::pair_sum(pi, &beta, pj, &gamma) };
                        assert_eq!(simd.to_bits(), portable.to_bits(), "pair {p},{q} orders {mi},{mj}");
                        // The whole exchange, weights included.
                        let (ni, nj) =
                            (DVec3::new(0.1, 0.2, 0.97).normalize(), DVec3::new(-0.3, 0.1, -0.9).normalize());
                        let mut scratch = Vec::new();
                        let (bw, gw) = weights(pi, ni, 0.3, pj, nj, -2.1, &mut scratch);
                        let portable = pair_sum(pi, bw, pj, gw);
                        // SAFETY: AVX detected.
                        let simd = unsafe { simd::exchange(pi, ni, 0.3, pj, nj, -2.1, &mut Vec::new()) };
                        assert_eq!(simd.to_bits(), portable.to_bits(), "exchange {p},{q} orders {mi},{mj}");
                    }
                    // Against the plain double loop.
                    let mut plain = 0.0;
                    for (x, bx) in beta.iter().enumerate() {
                        for (y, gy) in gamma.iter().enumerate() {
                            let d = DVec3::new(pj.x[y] - pi.x[x], pj.y[y] - pi.y[x], pj.z[y] - pi.z[x]);
                            plain += bx * gy / d.length_squared().powi(2);
                        }
                    }
                    assert!(((portable - plain) / plain).abs() < 1e-13, "{portable} vs {plain}");
                }
            }
        }
    }
}

/// The 1-D Gauss–Legendre rules of every ladder order, computed once.
pub fn gauss_nodes(order: usize) -> &'static (Vec<f64>, Vec<f64>) {
    static NODES: OnceLock<Vec<(Vec<f64>, Vec<f64>)>> = OnceLock::new();
    &NODES.get_or_init(|| (1..=MAX_ORDER).map(gauss_legendre).collect())[order - 1]
}

/// Calibrated constants of E(m, λ, ν) = A·ρ^(−p) + B·ν·ρ^(1−p) per order m = 1..=MAX_ORDER,
/// `[parallelogram, triangle]`: p = 2m on parallelograms (m-point Gauss is exact to degree
/// 2m − 1), p = 2m − 1 on Duffy triangles (the Jacobian 1 − s costs one degree).
/// Envelopes of `examples/ladder_calibration` (20 000 receivers × 4 emitter shapes, seed 7;
/// the larger of two runs' fits);
/// B of orders ≥ 4 (parallelograms) and ≥ 5 (triangles) had no sample above round-off in the
/// asymptotic range and is extrapolated geometrically.
const MODEL_A: [[f64; MAX_ORDER]; 2] =
    [[18.1, 33.5, 117.6, 298.4, 816.7, 2097.0], [1.02, 3.08, 6.22, 12.4, 38.4, 85.1]];
/// See [`MODEL_A`].
const MODEL_B: [[f64; MAX_ORDER]; 2] =
    [[1.94, 5.35, 11.3, 25.0, 50.0, 100.0], [0.128, 0.185, 0.202, 0.25, 0.3, 0.4]];
/// Factor between the calibrated envelope and the bound used: margin for geometry the sweep
/// did not draw; it costs only 4^(1/p) in the separation thresholds.
pub const SAFETY: f64 = 4.0;
/// ν bins of the threshold table (ν ∈ [0, 2] is rounded up to a bin edge).
const NU_BINS: usize = 8;

/// Bernstein-ellipse parameter of a pole at normalised distance 2λ beyond an end of [−1, 1].
pub fn rho(lambda: f64) -> f64 {
    1.0 + 2.0 * lambda + 2.0 * (lambda * lambda + lambda).sqrt()
}

/// The order selector: smallest Gauss order per patch that keeps the pair within target.
#[derive(Debug, Clone)]
pub struct ErrorModel {
    /// Per-patch share of the pair's relative error target.
    side_tol: f64,
    /// λ_min[kind][m − 1][bin]: the least λ at which order m meets `side_tol` for ν ≤ bin
    /// edge, kind 0 = parallelogram, 1 = triangles.
    lambda_min: [[[f64; NU_BINS + 1]; MAX_ORDER]; 2],
}

impl ErrorModel {
    /// Relative error bound of an order-`m` rule on one patch at separation λ = D/L, where ν
    /// is the relative variation of the other patch's cosine factor over this patch (0 to 2).
    pub fn side_error(m: usize, triangles: bool, lambda: f64, nu: f64) -> f64 {
        let r = rho(lambda);
        let k = triangles as usize;
        let p = 2 * m as i32 - k as i32;
        SAFETY * (MODEL_A[k][m - 1] * r.powi(-p) + MODEL_B[k][m - 1] * nu * r.powi(1 - p))
    }

    /// Threshold table for a per-pair relative target `rel_tol` (half per patch).
    pub fn new(rel_tol: f64) -> Self {
        let side_tol = 0.5 * rel_tol;
        let mut lambda_min = [[[f64::INFINITY; NU_BINS + 1]; MAX_ORDER]; 2];
        for (kind, table) in lambda_min.iter_mut().enumerate() {
            for (m, row) in table.iter_mut().enumerate() {
                for (bin, slot) in row.iter_mut().enumerate() {
                    let nu = 2.0 * bin as f64 / NU_BINS as f64;
                    let err = |lambda| Self::side_error(m + 1, kind == 1, lambda, nu);
                    // Bisection on log λ: the bound decreases in λ.
                    let (mut lo, mut hi) = (1e-3f64, 1e9f64);
                    if err(hi) > side_tol {
                        continue;
                    }
                    for _ in 0..100 {
                        let mid = (lo * hi).sqrt();
                        if err(mid) <= side_tol {
                            hi = mid;
                        } else {
                            lo = mid;
                        }
                    }
                    *slot = hi;
                }
            }
        }
        ErrorModel { side_tol, lambda_min }
    }

    /// The per-patch relative error budget.
    pub fn side_tol(&self) -> f64 {
        self.side_tol
    }

    /// Smallest order whose bound meets the budget at (λ, ν), or `None` (use the exact integral).
    /// ν is given by the extremes lo ≥ 0, hi of the linear factor: ν = 2(hi − lo)/(hi + lo).
    #[inline]
    pub fn order(&self, triangles: bool, lambda: f64, lo: f64, hi: f64) -> Option<usize> {
        // Bin = ⌈ν·NU_BINS/2⌉ without a division: count the edges k with ν·NU_BINS/2 > k.
        let (num, den) = (NU_BINS as f64 * (hi - lo), hi + lo);
        let bin =
            if triangles { NU_BINS } else { (0..NU_BINS).map(|k| (num > k as f64 * den) as usize).sum() };
        // λ_min falls with the order, so the first order that fits is one past the count of
        // orders that do not (branch-free: the pattern varies from pair to pair).
        let table = &self.lambda_min[triangles as usize];
        let misses: usize = (0..MAX_ORDER).map(|m| (lambda < table[m][bin]) as usize).sum();
        (misses < MAX_ORDER).then_some(misses + 1)
    }
}
