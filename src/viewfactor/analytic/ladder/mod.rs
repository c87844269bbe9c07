//! The far-field rung of the analytic ladder: tensor Gauss area rules on both patches ("2AI"),
//! used only where an a-priori error bound guarantees the per-pair relative error target.
//!
//! - `rules`: per-patch Gauss points ([`PatchRules`]): parallelograms directly, other
//!   polygons through their triangles (Duffy rule);
//! - `sum`: [`gauss_exchange`], s_ij = (1/π) Σ_a Σ_b w_a w_b cosθ_a cosθ_b / r_ab²;
//! - `model`: [`ErrorModel`], the smallest order per patch that meets the target.
//!
//! **Error bound.** Fix all integration variables but one. Along that parameter s ∈ [0, 1] the
//! point moves on a line x(s) = x₀ + s·u (|u| ≤ L, the patch's *parameter length*) and the
//! integrand is ℓ(s)·g(s): ℓ ≥ 0 is linear (the other patch's cosine factor, times the Duffy
//! Jacobian 1 − s on triangles) and g = 1/(π r²(s)²), r²(s) = |u|²(s − s₀)² + d², has double
//! poles at s₀ ± i·d/|u|, at distance min_t |x(t) − y|/|u| ≥ D/L from the real segment (D: a
//! lower bound of the distance between the patches). By the Bernstein-ellipse theorem
//! (Trefethen, ATAP Thm 19.3) the m-point Gauss error on the slice decays like ρ^(−2m), with
//! ρ(λ) = 1 + 2λ + 2√(λ² + λ) the ellipse through a pole at normalised distance 2λ beyond an end
//! of [−1, 1], λ = D/L. When ℓ varies strongly over the patch (relative variation ν, up to 2
//! when it vanishes on an edge: grazing pairs) one order is lost, ρ^(1−2m); on Duffy triangles
//! the Jacobian costs one more. The tensor-rule error is the sum of the slice errors, each
//! weighted by positive rules, so the pair's relative error is at most E_i + E_j with
//!
//!   E(m, λ, ν) = SAFETY·(A_m ρ^(−p) + B_m ν ρ^(1−p)),  p = 2m (parallelograms), 2m − 1 (triangles).
//!
//! The theorem's own constants (|ℓ|, |g| bounded over the whole ellipse) are 10³–10⁵ times
//! pessimistic here, so A_m and B_m are *calibrated*: the envelope of 80 000 worst-case pairs
//! (parallel, offset, perpendicular and grazing, tilted, random; squares, 5:1 rectangles,
//! triangles; `examples/ladder_calibration`), times [`SAFETY`] = 4 for geometry the sweep missed.
//! `tests/viewfactor/analytic_method.rs` checks 1 000+ further random pairs against the exact contour
//! integral; the worst is 13× inside the target.
pub(crate) mod model;
pub(crate) mod rules;
pub(crate) mod sum;

pub use model::{rho, ErrorModel, SAFETY};
pub use rules::{gauss_nodes, PatchRules, Points, PointsRef, CACHED_ORDERS, MAX_ORDER};
pub use sum::gauss_exchange;
