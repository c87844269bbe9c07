//! The Gauss pair sum s_ij = (1/π) Σ_a Σ_b β_a γ_b / r_ab⁴, in a portable form and an AVX form
//! that performs the same operations in the same order (bit-identical results).
use super::rules::PointsRef;
use glam::DVec3;
use std::f64::consts::PI;

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
    use crate::geometry::Polygon;
    use crate::viewfactor::analytic::ladder::{PatchRules, Points, MAX_ORDER};

    fn square(o: DVec3, u: DVec3, v: DVec3) -> Polygon {
        Polygon::new(vec![o, o + u, o + u + v, o + v]).unwrap()
    }

    #[test]
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
