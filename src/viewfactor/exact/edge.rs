//! Edge-pair terms of the double contour integral (docs/literature.md §2, recipe step 4).
//!
//! For edges e (from `a`, direction ê, length |e|) and f, the term is (ê·f̂)·K with
//! K = ∫_e ∫_f ln‖x − y‖ dl_y dl_x in arclength. Three exact evaluations:
//! - parallel lines: K in closed form from G(w) = ¼(w² − d²) ln(w² + d²) − ¾w² + d·w·atan(w/d),
//!   which reduces to the collinear ½w² ln|w| − ¾w² when d = 0 (identical edges L²(ln L − 3/2));
//! - lines crossing at a point O (coplanar): K = Re of a complex double antiderivative, written
//!   with two branch-cut choices that keep it C¹ (see [`coplanar_antiderivative`]), so shared
//!   vertices, crossings and 0·ln 0 need no special handling;
//! - otherwise (skew lines; edges far apart, where the 4-corner closed forms would cancel; or
//!   nearly parallel lines, whose crossing point is ill-conditioned): the analytic inner
//!   integral J(x) (Mitalas–Stephenson form of recipe 4b near f, a multipole series beyond two
//!   edge lengths, both free of cancellation) integrated over e by singularity-graded Gauss
//!   ([`super::gauss::integrate`]).
//!
//! Inputs are in the normalised frame of [`super::contour`] (coordinates of order 1).
use super::angle::{atan2, atan2_pos};
use super::gauss::{integrate, Singularity};
use crate::geometry::tolerance::LINES_COPLANAR_REL;
use glam::DVec3;

/// Edges with |ê·f̂| below this contribute (ê·f̂)·K ≤ 1e-15·|K|: skipped (perpendicular).
const PERPENDICULAR: f64 = 1e-15;
/// Lines count as parallel when sin α·|e|·|f| is below this (normalised frame): the parallel
/// closed form, which sets the offset at f's midpoint, then errs by at most (π/2)·sin α·|e||f|.
const PARALLEL: f64 = 1e-16;
/// Also parallel: sin α at the round-off of two unit vectors' cross product (≈ 4.5ε), as left
/// by rotating parallel edges; the error bound above is then 1.6e-15·|e||f|, at round-off.
const PARALLEL_SIN: f64 = 1e-15;
/// Below this sin α the crossing point of two coplanar lines is computed with a relative error
/// ε/sin α too large for the closed form (it shifts the edges against each other); such pairs
/// go to quadrature unless they share an exact vertex.
const CROSSING_MIN_SIN: f64 = 0.1;
/// The inner integral uses its multipole series beyond this many edge lengths from the edge's
/// midpoint: q = (b/2R)² ≤ 1/16, so 13 terms reach 1e-17.
const FAR_FIELD: f64 = 2.0;
/// Series terms below this are dropped (relative to b, against J's round-off of about ε·b).
const SERIES_CUTOFF: f64 = 1e-18;
/// The closed forms are used only while every corner parameter is within this many edge
/// lengths (|e| + |f|) of the lines' crossing point, or of the other edge for parallel lines:
/// their corner values grow like M² ln M and cancel, whereas quadrature stays local.
const CLOSED_FORM_REACH: f64 = 2.0;

/// One edge-pair term with the magnitude its round-off scales with.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Term {
    /// The value.
    pub value: f64,
    /// Sum of the magnitudes of the quantities that cancel in `value` (corner values of a
    /// closed form; |K| + |e||f| for quadrature), so that |round-off| ≈ a few ε·magnitude.
    pub magnitude: f64,
}

impl Term {
    fn scaled(self, c: f64) -> Term {
        Term { value: c * self.value, magnitude: c.abs() * self.magnitude }
    }
}

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

/// (ê·f̂)·∫_e∫_f ln‖x − y‖ dl dl: the edge-pair term of 2π·A₁F₁₂ = Σ (ê·f̂) K.
pub fn pair_term(e: &Edge, f: &Edge) -> Term {
    let c = e.dir.dot(f.dir);
    if c.abs() <= PERPENDICULAR {
        return Term::default();
    }
    let scale = CLOSED_FORM_REACH * (e.len + f.len);
    let cr = e.dir.cross(f.dir);
    let sn = cr.length();
    let w = f.a - e.a;
    // Step: parallel lines, in closed form when close.
    if sn <= PARALLEL_SIN || sn * e.len * f.len <= PARALLEL {
        let (ya, yb) = (w.dot(e.dir), (f.b - e.a).dot(e.dir));
        let reach = ya.abs().max(yb.abs()).max((ya - e.len).abs()).max((yb - e.len).abs());
        let d = (0.5 * (f.a + f.b) - e.a).cross(e.dir).length();
        if reach <= scale && d <= scale {
            return parallel(e.len, ya.min(yb), ya.max(yb), d).scaled(c);
        }
        return quadrature(e, f, None).scaled(c);
    }
    // Step: an exactly shared vertex is the lines' crossing point, known without round-off.
    if let Some((s0, t0)) = shared_vertex(e, f) {
        return coplanar(c, sn, [-s0, e.len - s0], [-t0, f.len - t0]).scaled(c);
    }
    // Step: closest points of the two lines, s* on e and t* on f (arclength from the starts).
    let n = cr / sn;
    let s_star = w.cross(f.dir).dot(n) / sn;
    let t_star = w.cross(e.dir).dot(n) / sn;
    let d = w.dot(n).abs();
    let reach = s_star.abs().max((e.len - s_star).abs()).max(t_star.abs()).max((f.len - t_star).abs());
    if d <= LINES_COPLANAR_REL && sn >= CROSSING_MIN_SIN && reach <= scale {
        return coplanar(c, sn, [-s_star, e.len - s_star], [-t_star, f.len - t_star]).scaled(c);
    }
    let pinch = (t_star > 0.0 && t_star < f.len).then_some(Singularity { x: s_star, y: d / sn });
    quadrature(e, f, pinch).scaled(c)
}

/// Arclength positions (on e, on f) of a vertex the two edges share exactly, if any.
fn shared_vertex(e: &Edge, f: &Edge) -> Option<(f64, f64)> {
    if e.a == f.a {
        Some((0.0, 0.0))
    } else if e.a == f.b {
        Some((0.0, f.len))
    } else if e.b == f.a {
        Some((e.len, 0.0))
    } else if e.b == f.b {
        Some((e.len, f.len))
    } else {
        None
    }
}

/// K for parallel edges: e spans [0, `len`] and f spans [`lo`, `hi`] along ê, offset `d`.
pub fn parallel(len: f64, lo: f64, hi: f64, d: f64) -> Term {
    let g = |w: f64| parallel_antiderivative(w, d);
    corners([g(len - lo), g(len - hi), g(-lo), g(-hi)])
}

/// The 4-corner combination c₀ − c₁ − c₂ + c₃ of a double antiderivative.
fn corners(v: [f64; 4]) -> Term {
    Term { value: v[0] - v[1] - v[2] + v[3], magnitude: v.iter().map(|x| x.abs()).sum() }
}

/// G(w) with G'' = ln √(w² + d²): the double antiderivative for parallel edges at offset d.
pub fn parallel_antiderivative(w: f64, d: f64) -> f64 {
    let r2 = w * w + d * d;
    if r2 == 0.0 {
        return 0.0;
    }
    // w·atan(w/d) is even in w: evaluated on |w| with the fast non-negative atan2.
    0.25 * (w * w - d * d) * r2.ln() - 0.75 * w * w + d * w.abs() * atan2_pos(w.abs(), d)
}

/// K for lines crossing at a point O, with e spanning s ∈ `s` and f spanning t ∈ `t` from O.
pub fn coplanar(c: f64, sn: f64, s: [f64; 2], t: [f64; 2]) -> Term {
    let alpha = atan2_pos(sn, c);
    let p = |s: f64, t: f64| coplanar_antiderivative(s, t, c, sn, alpha);
    corners([p(s[1], t[1]), p(s[1], t[0]), p(s[0], t[1]), p(s[0], t[0])])
}

/// P(s, t) with ∂²P/∂s∂t = ln r, r² = s² + t² − 2st·cos α, for lines at angle α through O.
///
/// P = Re[−e^{−iα} Q(w)], w = s − t·e^{iα}, Q(w) = ½w² log w − ¾w² (Q'' = log w). Its real
/// form is −½(c(s² + t²) − 2st)(ln r − 3/2) − ½ sin α (s²·φ_s − t²·φ_t), where φ_s and φ_t are
/// two determinations of arg w whose cuts lie on s = 0 and t = 0 respectively, exactly where
/// their factors s² and t² vanish; P is therefore C¹ on the whole plane.
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
    // The sign of a zero first argument does not matter: t² or s² multiplies it.
    let phi_t = atan2(-t * sn, s - t * c);
    let phi_s = atan2(-s * sn, s * c - t) + alpha;
    -0.5 * coef * (0.5 * r2.ln() - 1.5) - 0.5 * sn * (s * s * phi_s - t * t * phi_t)
}

/// K by graded Gauss over e of the analytic inner integral J.
fn quadrature(e: &Edge, f: &Edge, pinch: Option<Singularity>) -> Term {
    // Step: singularities of σ ↦ J(x(σ)): f's endpoints seen from e's line, and the pinch
    // where skew lines pass closest when that point lies inside f.
    let near = |q: DVec3| {
        let v = q - e.a;
        Singularity { x: v.dot(e.dir), y: v.cross(e.dir).length().max(f64::MIN_POSITIVE) }
    };
    let mut sing = [near(f.a), near(f.b), Singularity { x: 0.0, y: 0.0 }];
    let count = match pinch {
        Some(p) => {
            sing[2] = Singularity { x: p.x, y: p.y.max(f64::MIN_POSITIVE) };
            3
        }
        None => 2,
    };
    let w0 = e.a - f.a;
    let k = integrate(e.len, &sing[..count], |sigma| inner(w0 + sigma * e.dir, f));
    Term { value: k, magnitude: k.abs() + e.len * f.len }
}

/// J(x) = ∫_f ln‖x − y‖ dl_y from v₀ = x − f.a: the multipole series [`inner_far`] when x is
/// at least 2|f| from f's midpoint, else the closed form [`inner_near`].
pub fn inner(v0: DVec3, f: &Edge) -> f64 {
    let vm = v0 - (0.5 * f.len) * f.dir;
    let rm2 = vm.length_squared();
    if rm2 >= FAR_FIELD * FAR_FIELD * f.len * f.len {
        inner_far(vm, rm2, f)
    } else {
        inner_near(v0, f)
    }
}

/// J(x) = ½[b ln r₁² + u ln(r₀²/r₁²)] − b + h·θ, with θ the angle f subtends at x and u, h the
/// axial and radial coordinates of x about f (Mitalas–Stephenson form of recipe 4b).
pub fn inner_near(v0: DVec3, f: &Edge) -> f64 {
    let b = f.len;
    let v1 = v0 - b * f.dir;
    let (r0, r1) = (v0.length_squared(), v1.length_squared());
    let u = v0.dot(f.dir);
    let h = v0.cross(f.dir).length();
    let theta = atan2_pos(h * b, v0.dot(v1));
    if r0 == 0.0 || r1 == 0.0 {
        // x at an end of f: the 0·ln 0 limits.
        let l0 = if r0 > 0.0 { u * r0.ln() } else { 0.0 };
        let l1 = if r1 > 0.0 { (b - u) * r1.ln() } else { 0.0 };
        return 0.5 * (l0 + l1) - b + h * theta;
    }
    // ln(r₀²/r₁²) with r₀² − r₁² = b(2u − b): through ln_1p when the ratio is near 1.
    let x = b * (2.0 * u - b) / r1;
    let ratio = if x.abs() < 0.5 { x.ln_1p() } else { r0.ln() - r1.ln() };
    0.5 * (b * r1.ln() + u * ratio) - b + h * theta
}

/// J(x) = b ln R − (b/2) Σ_k q^k cos(2kφ)/(k(2k + 1)), q = (b/2R)², from the expansion
/// ln|1 − z e^{iφ}| = −Σ zⁿ cos(nφ)/n integrated over f; R = |x − m| (m: f's midpoint, `vm` =
/// x − m, `rm2` = R²) and φ the angle between x − m and f. No term cancels, so the far field
/// keeps full relative accuracy, at one logarithm.
pub fn inner_far(vm: DVec3, rm2: f64, f: &Edge) -> f64 {
    let b = f.len;
    let q = 0.25 * b * b / rm2;
    let cos2 = 2.0 * vm.dot(f.dir).powi(2) / rm2 - 1.0;
    // Step: Σ q^k T_k(cos 2φ)/(k(2k + 1)) by the Chebyshev recurrence, until q^k is negligible.
    let (mut t_prev, mut t) = (1.0, cos2);
    let (mut qk, mut sum) = (q, 0.0);
    for c in SERIES {
        sum += qk * t * c;
        qk *= q;
        if qk <= SERIES_CUTOFF {
            break;
        }
        (t_prev, t) = (t, 2.0 * cos2 * t - t_prev);
    }
    0.5 * b * rm2.ln() - 0.5 * b * sum
}

/// 1/(k(2k + 1)) for k = 1, 2, …: enough terms for q ≤ 1/(2·FAR_FIELD)² = 1/16.
const SERIES: [f64; 15] = {
    let mut c = [0.0; 15];
    let mut k = 0;
    while k < 15 {
        let kk = (k + 1) as f64;
        c[k] = 1.0 / (kk * (2.0 * kk + 1.0));
        k += 1;
    }
    c
};

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
        pts.windows(2).map(|p| tanh_sinh(p[0], p[1], &|s| inner(e.a + s * e.dir - f.a, f))).sum()
    }

    #[test]
    fn inner_integral_matches_quadrature() {
        let f = Edge::new(DVec3::new(0.2, -0.1, 0.3), DVec3::new(1.1, 0.4, -0.2));
        let mid = 0.5 * (f.a + f.b);
        let pts = [
            DVec3::new(0.5, 0.9, 0.1),
            DVec3::new(-3.0, 2.0, 1.0),
            mid + 0.01 * DVec3::Z,
            mid,
            f.a - 0.3 * f.dir,
        ];
        let far = [
            DVec3::new(4.0, -3.0, 1.0),
            f.a + 2.05 * f.len * f.dir.any_orthonormal_vector(),
            DVec3::new(40.0, 2.0, -9.0),
        ];
        for x in pts.into_iter().chain(far) {
            // Reference: tanh-sinh on both sides of the foot of x on f.
            let u = (x - f.a).dot(f.dir).clamp(0.0, f.len);
            let g = |t: f64| (x - f.a - t * f.dir).length().ln();
            let want = tanh_sinh(0.0, u, &g) + tanh_sinh(u, f.len, &g);
            let got = inner(x - f.a, &f);
            assert!((got - want).abs() < 2e-15 * (1.0 + want.abs()), "{x}: {got} vs {want}");
        }
    }

    #[test]
    fn identical_edges_give_l_squared_ln_l_minus_three_halves() {
        let l = 0.7;
        let e = Edge::new(DVec3::ZERO, DVec3::new(l, 0.0, 0.0));
        let f = Edge::new(DVec3::new(l, 0.0, 0.0), DVec3::ZERO);
        let exact = l * l * (l.ln() - 1.5);
        let k = parallel(l, 0.0, l, 0.0).value;
        assert!((k - exact).abs() < 1e-15, "{k} vs {exact}");
        assert!((pair_term(&e, &f).value + exact).abs() < 1e-15);
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
            let got = pair_term(&e, &f).value;
            let want = e.dir.dot(f.dir) * reference(&e, &f, &breaks);
            assert!((got - want).abs() < 1e-12, "{a} {b} / {p} {q}: {got} vs {want}");
        }
    }
}
