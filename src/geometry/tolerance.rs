//! Every geometric epsilon, one name per concept, each with its reason. Relative values are
//! multiplied by the size named in their doc (polygon diameter, scene size, pair size).
//!
//! Left beside their formulas on purpose: the branch cut-offs of the edge-pair integrand
//! (`viewfactor::exact::edge`: perpendicular, parallel, series), which switch between
//! closed forms rather than classify geometry, and the hierarchy's own tests
//! (`exchange::hierarchy`).

/// Relative planarity tolerance: a vertex may sit this fraction of the polygon's diameter off
/// its best-fit plane (CAD exports carry f32 round-off, about 1e-7).
pub const PLANARITY_TOL: f64 = 1e-6;

/// Relative collinearity tolerance: a polygon whose area is below this fraction of its
/// diameter squared is degenerate (zero area or collinear vertices).
pub const DEGENERACY_TOL: f64 = 1e-12;

/// A right turn below this fraction of the local scale (edge lengths, or |q|² of a 2-D ring)
/// counts as straight when testing convexity: round-off of collinear vertices.
pub const CONVEX_TURN_REL: f64 = 1e-14;

/// Distance, relative to the coordinates' magnitude, below which two convex-hull vertices are
/// one point: the spread of one point computed along different paths (a few dozen ulps). Kept
/// apart, the two make an edge whose direction is round-off.
pub const HULL_MERGE_REL: f64 = 64.0 * f64::EPSILON;

/// Edge length, relative to its coordinates' magnitude, below which a ring's edge offers no
/// separating axis: its direction is then uncertain by more than 1e-7 rad, and a line through
/// a point touching the other ring could be turned either way.
pub const AXIS_EDGE_MIN_REL: f64 = 1e-9;

/// The patches of one surface share one plane and one normal (normal cosine within this of 1,
/// vertices within 1e3 × this × the largest patch radius of the plane): a test on the user's
/// input, so looser than the kernels' [`PATCH_COPLANAR_REL`].
pub const SURFACE_COPLANAR_TOL: f64 = 1e-9;

/// Patches whose planes agree to this fraction of the scene extent share a plane (coplanar
/// pairs exchange nothing): round-off level, so nearly coplanar geometry is integrated as given.
pub const PATCH_COPLANAR_REL: f64 = 1e-12;

/// Cosine tolerance for "same plane direction" when grouping planes (normals within ~1.4e-6 rad).
pub const PLANE_NORMAL_COS_TOL: f64 = 1e-12;

/// A polygon whose vertices all lie within this distance (normalised frame, i.e. relative to
/// the pair's size) of the other's plane is coplanar with it in the contour integral: F = 0.
pub const CONTOUR_COPLANAR_REL: f64 = 1e-12;

/// The contour integral's clipping counts vertices within this distance (normalised) of the
/// plane as on it, so a polygon touching the other's plane along an edge is kept whole.
pub const CONTOUR_CLIP_SNAP_REL: f64 = 1e-13;

/// Lines closer than this (normalised) are coplanar in the edge-pair integrand; ignoring the
/// skew distance d changes the kernel by O(d²·ln d), far below round-off.
pub const LINES_COPLANAR_REL: f64 = 1e-10;

/// A point within this fraction of the polygon's size from its plane is in the plane (Lambert's
/// point factor is then 0).
pub const POINT_IN_PLANE_REL: f64 = 1e-14;

/// The hemicube eye counts as lying in a polygon's plane within this fraction of the scene size:
/// subdivided coplanar patches differ from exactly coplanar by f64 round-off only.
pub const EYE_IN_PLANE_REL: f64 = 1e-9;

/// Snapping distance to a grid line, relative to the polygon's extent: a few ulps, so points that
/// round-off puts beside a line land on it exactly, while the area moves by far less than 1e-12.
pub const GRID_SNAP_REL: f64 = 1e-14;

/// A point this fraction of the scene size off a blocker plane is on it (round-off of the
/// vertices).
pub const BLOCKER_SNAP_REL: f64 = 1e-10;

/// Relative size (of the receiver) below which a vertex sits on a shadow edge and a shadow piece
/// is a sliver: far below any accuracy goal, far above f64 round-off of the clipped coordinates.
pub const SHADOW_SNAP_REL: f64 = 1e-12;

/// Blocker box padding as a fraction of the scene size: boxes already hold their vertices
/// exactly (rounded outwards); this covers the round-off of the predicates evaluated on them.
pub const BLOCKER_BOX_PAD_REL: f64 = 1e-9;

/// Relative tolerance for "the patches tile their convex hull" (areas agree to round-off).
pub const TILE_AREA_REL: f64 = 1e-9;

/// Relative thickness (of the scene size) below which an overlap counts as touching, not
/// blocking: far above the round-off of coordinates (1e-16 relative), far below any feature.
pub const OCCLUSION_TOL: f64 = 1e-9;

/// Edges whose directions differ by less than this angle (radians) are parallel (kink planes
/// of the adaptive shadow integration).
pub const EDGE_PARALLEL_ANGLE: f64 = 1e-9;

/// A quad is a parallelogram when |v0 + v2 − v1 − v3| is below this fraction of its size:
/// round-off only, so the bilinear map of its projection positions and samples is exact.
pub const PARALLELOGRAM_REL: f64 = 1e-12;

/// Relative tolerance for "this quad is a parallelogram" in the Gauss ladder's rules
/// (f32 CAD round-off is ~1e-7).
pub const PARALLELOGRAM_CAD_REL: f64 = 1e-9;

/// Distance, relative to a closed body's box diagonal, within which a vertex counts as behind a
/// face when the body is tested for convexity: round-off only (coplanar faces of a box), so a
/// body taken as convex has its shadow's hull within the exact method's error.
pub const CONVEX_BODY_REL: f64 = 1e-9;

/// Height difference over the emitter's plane, relative to a segment's length, below which a
/// shadow event's sight line counts as parallel to that plane: its trace there would run to
/// infinity, so the segment is cut short of it.
pub const EVENT_LEVEL_REL: f64 = 1e-9;
