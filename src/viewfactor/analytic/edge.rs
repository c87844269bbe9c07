//! Edge-pair terms of the double contour integral (literature.md §2, recipe step 4).
//!
//! For edges e (from a, direction ê, length a_len) and f, the term is
//! (ê·f̂)·K with K = ∫_e ∫_f ln‖x − y‖ dl_y dl_x in arclength. Three exact evaluations:
//! - parallel lines: K in closed form from G(w) = ¼(w² − d²) ln(w² + d²) − ¾w² + d·w·atan(w/d),
//!   which reduces to the collinear ½w² ln|w| − ¾w² when d = 0 (identical edges L²(ln L − 3/2));
//! - intersecting (coplanar) lines: K = Re of a complex double antiderivative, written with two
//!   branch-cut choices that keep it C¹ (see [`coplanar_antiderivative`]), so shared vertices,
//!   crossings and 0·ln 0 need no special handling;
//! - skew lines: the analytic inner integral J(x) = (b − u) ln r₁ + u ln r₀ − b + hθ
//!   (Mitalas–Stephenson form of recipe 4b) integrated over e by singularity-graded Gauss
//!   ([`super::gauss::integrate`]).
//!
//! Inputs are in the normalised frame of [`super::contour`] (coordinates of order 1).
use super::gauss::{integrate, Singularity};
use glam::DVec3;

/// Edges with |ê·f̂| below this contribute (ê·f̂)·K ≤ 1e-15·|K|: skipped (perpendicular).
const PERPENDICULAR: f64 = 1e-15;
/// sin α below this counts as parallel: the parallel closed form with the mean offset then errs
/// by at most π·sin α·L² (the offset enters K linearly), 1e-14 in the normalised frame.
const PARALLEL: f64 = 1e-14;
/// Lines closer than this (normalised) are coplanar; ignoring the skew distance d changes K by
/// O(d²·ln d), far below round-off.
const COPLANAR: f64 = 1e-10;
/// The coplanar antiderivative is used only while the lines' crossing point lies within this
/// distance (normalised) of the edge ends: its corner values grow like M² ln M and cancel.
const NEAR_CROSSING: f64 = 4.0;

/// A directed polygon edge with its unit direction and length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Start point.
    pub a: DVec3,
    /// End point.
    pub b: DVec3,
    /// Unit direction (zero for a zero-length edge).
    pub dir: DVec3,
    /// Length.
    pub len: f64,
}

impl Edge {
    /// The edge from `a` to `b`.
    pub fn new(a: DVec3, b: DVec3) -> Self {
        let d = b - a;
        let len = d.length();
        let dir = if len > 0.0 { d / len } else { DVec3::ZERO };
        Self { a, b, dir, len }
    }
}

/// (ê·f̂)·∫_e∫_f ln‖x − y‖ dl dl, the edge-pair term of A₁F₁₂ = (1/2π) Σ (e·f) I.
pub fn pair_term(e: &Edge, f: &Edge) -> f64 {
    let c = e.dir.dot(f.dir);
    if c.abs() <= PERPENDICULAR {
        return 0.0;
    }
    let cr = e.dir.cross(f.dir);
    let sn = cr.length();
    if sn <= PARALLEL {
        return c * parallel(e, f);
    }
    // Step: closest points of the two lines, s* on e and t* on f (arclength from the starts).
    let w = f.a - e.a;
    let n = cr / sn;
    let s_star = w.cross(f.dir).dot(n) / sn;
    let t_star = w.cross(e.dir).dot(n) / sn;
    let d = w.dot(n).abs();
    let reach = s_star.abs().max((e.len - s_star).abs()).max(t_star.abs()).max((f.len - t_star).abs());
    if d <= COPLANAR && reach <= NEAR_CROSSING {
        let k = coplanar(c, sn, [-s_star, e.len - s_star], [-t_star, f.len - t_star]);
        return c * k;
    }
    c * skew(e, f, s_star, t_star, d / sn)
}

/// K for parallel lines: the offset d is taken at f's midpoint, axial positions along ê.
pub fn parallel(e: &Edge, f: &Edge) -> f64 {
    let (ya, yb) = ((f.a - e.a).dot(e.dir), (f.b - e.a).dot(e.dir));
    let (lo, hi) = if ya <= yb { (ya, yb) } else { (yb, ya) };
    let mid = 0.5 * (f.a + f.b) - e.a;
    let d = mid.cross(e.dir).length();
    let g = |w: f64| parallel_antiderivative(w, d);
    g(e.len - lo) - g(e.len - hi) - g(-lo) + g(-hi)
}

/// G(w) with G'' = ln √(w² + d²): the double antiderivative for parallel edges at offset d.
pub fn parallel_antiderivative(w: f64, d: f64) -> f64 {
    let r2 = w * w + d * d;
    if r2 == 0.0 {
        return 0.0;
    }
    0.25 * (w * w - d * d) * r2.ln() - 0.75 * w * w + d * w * w.atan2(d)
}

/// K for lines crossing at a point O, with e spanning s ∈ `s` and f spanning t ∈ `t` from O.
pub fn coplanar(c: f64, sn: f64, s: [f64; 2], t: [f64; 2]) -> f64 {
    let alpha = sn.atan2(c);
    let p = |s: f64, t: f64| coplanar_antiderivative(s, t, c, sn, alpha);
    p(s[1], t[1]) - p(s[1], t[0]) - p(s[0], t[1]) + p(s[0], t[0])
}

/// P(s, t) with ∂²P/∂s∂t = ln r, r² = s² + t² − 2st·cos α, for lines at angle α through O.
///
/// P = Re[−e^{−iα} Q(w)], w = s − t·e^{iα}, Q(w) = ½w² log w − ¾w². Its real form is
/// −½(c(s² + t²) − 2st)(ln r − 3/2) − ½ sin α (s²·φ_s − t²·φ_t), where φ_s and φ_t are two
/// determinations of arg w whose cuts lie on s = 0 and t = 0 respectively, exactly where their
/// factors s² and t² vanish; P is therefore C¹ on the whole plane.
pub fn coplanar_antiderivative(s: f64, t: f64, c: f64, sn: f64, alpha: f64) -> f64 {
    // Step: r² and the ln coefficient without cancellation when c → ±1.
    let (r2, coef) = if c >= 0.0 {
        let one_minus = sn * sn / (1.0 + c);
        ((s - t) * (s - t) + 2.0 * s * t * one_minus, c * (s - t) * (s - t) - 2.0 * s * t * one_minus)
    } else {
        let one_plus = sn * sn / (1.0 - c);
        ((s + t) * (s + t) - 2.0 * s * t * one_plus, c * (s + t) * (s + t) - 2.0 * s * t * one_plus)
    };
    if r2 == 0.0 {
        return 0.0;
    }
    let phi_t = (-t * sn).atan2(s - t * c);
    let phi_s = (-s * sn).atan2(s * c - t) + alpha;
    -0.5 * coef * (0.5 * r2.ln() - 1.5) - 0.5 * sn * (s * s * phi_s - t * t * phi_t)
}

/// K for skew (or far-crossing) lines by graded Gauss over e of the analytic inner integral.
fn skew(e: &Edge, f: &Edge, s_star: f64, t_star: f64, pinch: f64) -> f64 {
    // Step: singularities of σ ↦ J(x(σ)): f's endpoints seen from e's line, and the pinch
    // where the lines pass closest when that point lies inside f.
    let near = |q: DVec3| {
        let v = q - e.a;
        Singularity { x: v.dot(e.dir), y: v.cross(e.dir).length() }
    };
    let mut sing = [near(f.a), near(f.b), Singularity { x: s_star, y: pinch }];
    let count = if t_star > 0.0 && t_star < f.len { 3 } else { 2 };
    for s in &mut sing[..count] {
        s.y = s.y.max(f64::MIN_POSITIVE);
    }
    integrate(e.len, &sing[..count], |sigma| inner(e.a + sigma * e.dir, f))
}

/// J(x) = ∫_f ln‖x − y‖ dl_y = (b − u) ln r₁ + u ln r₀ − b + h·θ (θ: angle f subtends at x).
pub fn inner(x: DVec3, f: &Edge) -> f64 {
    let v0 = x - f.a;
    let v1 = x - f.b;
    let (r0, r1) = (v0.length_squared(), v1.length_squared());
    let u = v0.dot(f.dir);
    let h = v0.cross(f.dir).length();
    let theta = (h * f.len).atan2(v0.dot(v1));
    let l0 = if r0 > 0.0 { u * r0.ln() } else { 0.0 };
    let l1 = if r1 > 0.0 { (f.len - u) * r1.ln() } else { 0.0 };
    0.5 * (l0 + l1) - f.len + h * theta
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ∫ₐᵇ g by tanh-sinh, robust to endpoint singularities (reference only).
    fn tanh_sinh(a: f64, b: f64, g: &dyn Fn(f64) -> f64) -> f64 {
        let (h, half) = (1.0 / 64.0, 0.5 * (b - a));
        let mut sum = 0.0;
        for k in -256i32..=256 {
            let t = k as f64 * h;
            let u = std::f64::consts::FRAC_PI_2 * t.sinh();
            // Distance from the nearer end, 1 ∓ tanh(u), without cancellation.
            let off = 2.0 / (1.0 + (2.0 * u.abs()).exp());
            let w = std::f64::consts::FRAC_PI_2 * t.cosh() / u.cosh().powi(2);
            let x = if u < 0.0 { a + half * off } else { b - half * off };
            if off > 0.0 && w.is_finite() {
                sum += w * g(x);
            }
        }
        sum * half * h
    }

    /// Reference K: tanh-sinh over e between the given breakpoints.
    fn reference(e: &Edge, f: &Edge, breaks: &[f64]) -> f64 {
        let mut pts = vec![0.0];
        pts.extend(breaks.iter().copied().filter(|&b| b > 0.0 && b < e.len));
        pts.push(e.len);
        pts.windows(2).map(|p| tanh_sinh(p[0], p[1], &|s| inner(e.a + s * e.dir, f))).sum()
    }

    #[test]
    fn identical_edges_give_l_squared_ln_l_minus_three_halves() {
        let l = 0.7;
        let e = Edge::new(DVec3::ZERO, DVec3::new(l, 0.0, 0.0));
        let f = Edge::new(DVec3::new(l, 0.0, 0.0), DVec3::ZERO);
        let exact = l * l * (l.ln() - 1.5);
        assert!((parallel(&e, &f) - exact).abs() < 1e-15, "{} vs {exact}", parallel(&e, &f));
        assert!((pair_term(&e, &f) + exact).abs() < 1e-15);
    }

    #[test]
    fn each_branch_matches_brute_force() {
        // (e start, e end, f start, f end, breakpoints on e where J is not smooth)
        let v = DVec3::new;
        let cases = [
            // skew, well separated
            (v(0.0, 0.0, 0.0), v(1.0, 0.2, 0.0), v(0.3, 1.0, 0.8), v(-0.5, 0.4, 1.1), vec![]),
            // coplanar, sharing a vertex at 60°
            (DVec3::ZERO, DVec3::X, DVec3::ZERO, v(0.5, 3f64.sqrt() / 2.0, 0.0), vec![]),
            // coplanar crossing at x = 0.1 + 0.2·5/11, i.e. σ = 0.5 + 1/11 along e
            (
                v(-0.4, 0.0, 0.0),
                v(0.8, 0.0, 0.0),
                v(0.1, -0.5, 0.0),
                v(0.3, 0.6, 0.0),
                vec![0.5 + 1.0 / 11.0],
            ),
            // parallel offset
            (DVec3::ZERO, DVec3::X, v(1.5, 0.3, 0.4), v(0.2, 0.3, 0.4), vec![]),
            // skew, passing 1e-3 apart near σ = 0.5 + 0.05
            (v(-0.5, 0.0, 0.0), v(0.5, 0.0, 0.0), v(0.0, -0.5, 1e-3), v(0.1, 0.5, 1e-3), vec![0.55]),
            // collinear, overlapping by half
            (DVec3::ZERO, DVec3::X, v(1.5, 0.0, 0.0), v(0.5, 0.0, 0.0), vec![0.5]),
        ];
        for (a, b, p, q, breaks) in cases {
            let (e, f) = (Edge::new(a, b), Edge::new(p, q));
            let got = pair_term(&e, &f);
            let want = e.dir.dot(f.dir) * reference(&e, &f, &breaks);
            assert!((got - want).abs() < 1e-12, "{a} {b} / {p} {q}: {got} vs {want}");
        }
    }
}
