//! The exact-shadow branch: obstructed patch pairs, from blocker detection to the obstructed
//! exchange area. Depends on geometry and on `analytic`'s exact kernels (Lambert's edge term,
//! and the contour integral for the calibration pairs);
//! the analytic kernel ([`crate::viewfactor::analytic::kernel`]) calls [`Shadows`]. Never
//! depends on `auto`, which picks a [`Policy`] and hands it to the analytic kernel.
//!
//! Blockers and detection:
//! - `blockers`: the scene's convex blockers (surface outlines) and their box hierarchies;
//! - [`detect`]: which patch pairs have part of their view cut (the unshadowed analytic
//!   method's check, a separating-axis test per blocker plane);
//!
//! Classification:
//! - `volume`: exact clear / blocked / partial class of a receiver against one blocker
//!   (penumbra and umbra volumes);
//! - [`classify`]: per row, the obstructed receivers and their partial blockers;
//!
//! Integration:
//! - [`viewpoint`]: shadow clipping from one viewpoint (the shaded integrand g);
//! - `silhouette`: a closed body's outline loops from one viewpoint, chained on the mesh;
//! - `adaptive`: adaptive emitter integration of g with per-cell re-classification;
//! - `solid`: pairs behind one convex solid: the blocked exchange summed over its faces
//!   (exact contour integrals, or small integrals over the faces);
//! - `pair`: one obstructed pair: emitter choice, shadow integration, A·F;
//! - `mc_pair`: the Monte Carlo ratio estimator for one pair (`auto` only);
//! - `segtree`: a per-pair box tree over its partial blockers for the sampled segments;
//!
//! Policy:
//! - [`policy`]: [`Policy`] (exact or `auto`), and [`policy::CostModel`], the per-pair
//!   shadow-integration-vs-Monte-Carlo decision with its prices;
//! - [`calibrate`]: the prices fitted on a few of the scene's own pairs (counted work);
//! - `branch`: [`Shadows`], the branch a kernel row calls: classify, then integrate under
//!   the policy;
//! - `misses`: entries whose error estimate ended above their goal (named by the run).
pub(crate) mod adaptive;
pub mod blockers;
pub(crate) mod branch;
pub mod calibrate;
pub mod classify;
pub mod detect;
pub(crate) mod mc_pair;
pub(crate) mod misses;
pub(crate) mod pair;
pub mod policy;
#[cfg(test)]
mod prism;
pub(crate) mod segtree;
pub(crate) mod silhouette;
pub(crate) mod solid;
pub mod viewpoint;
pub(crate) mod volume;

pub use branch::{Obstructed, PairAt, PairWork, ShadowScratch, Shadows};
pub use policy::Policy;
