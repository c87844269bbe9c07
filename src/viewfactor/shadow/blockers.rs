//! The scene's blockers for the shadowed `analytic` path: convex polygons in a box hierarchy
//! (`crate::visibility::boxes::BoxTree`), plus a hierarchy over the patches, so candidate
//! blockers and affected receivers are found by region queries, never by a linear scan.
//!
//! - **Blockers** are the polygons that can cut a sight line, as convex rings:
//!   - a planar surface whose patches tile their convex hull (a subdivided rectangle, disk or
//!     convex polygon) is one blocker, its outline: one shadow instead of a shadow per patch,
//!     and no seams between patch shadows;
//!   - the coplanar, edge-sharing polygons of a mesh (an obstruction's, or the patches of a
//!     surface) that tile their convex hull (a meshed body's flat face) are one blocker, its
//!     hull (`coplanar_tiles`);
//!   - any other patch, and every other obstruction polygon, is its own blocker, split into
//!     triangles when non-convex.
//! - A blocker is kept only when patches lie strictly on both sides of its plane; otherwise no
//!   segment between two patches can cross it (the walls of a convex room never block).
//! - Both hierarchies are walked with a box predicate; boxes are padded, so a conservative
//!   predicate gives a conservative query.
use crate::geometry::convex::{convex_hull, twice_area};
use crate::geometry::groups::Groups;
use crate::geometry::tolerance::{BLOCKER_BOX_PAD_REL, BLOCKER_SNAP_REL, CONVEX_BODY_REL, TILE_AREA_REL};

/// Unit normals this close (each component) count as one plane's in
/// [`Blockers::splits_patches`]: over a scene 1e4 times the snap's scale the planes part by
/// far less than the snap.
const SAME_PLANE_NORMAL: f64 = 1e-14;
/// Face × vertex tests above which a body's convexity rests on its edges alone.
const CONVEX_BODY_FULL_CHECK: usize = 20_000_000;
/// Neighbouring mesh polygons whose unit normals differ by less than this (1 − cos) and
/// whose vertices lie within the snap length of each other's plane are one flat face.
const COPLANAR_NORMAL_TOL: f64 = 1e-12;
use crate::geometry::Polygon;
use crate::scene::Scene;
use crate::visibility::boxes::BoxTree;
use glam::{DVec2, DVec3};

/// Where a blocker comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BlockerSource {
    /// The outline of a whole planar surface.
    Surface(usize),
    /// One patch (or a triangle of it).
    Patch(usize),
    /// Polygon `polygon` of obstruction `obstruction` (or a triangle of it).
    Obstruction {
        /// Obstruction index.
        obstruction: usize,
        /// Polygon index within it.
        polygon: usize,
    },
}

/// One convex blocker polygon.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocker {
    /// Counter-clockwise vertices about `normal`.
    pub ring: Vec<DVec3>,
    /// Unit normal.
    pub normal: DVec3,
    /// What it belongs to.
    pub source: BlockerSource,
    /// Per edge k (ring\[k\] → ring\[k + 1\]): the one other blocker sharing it, when exactly one
    /// does. Across such an edge the two blockers fold, and the edge casts a shadow edge only
    /// from viewpoints where it is on their silhouette.
    pub across: Vec<Option<u32>>,
    /// +1 (or −1) when the blocker is a face of a closed, consistently oriented mesh whose
    /// faces' normals point out of (or into) it; 0 otherwise. Every sight line from outside
    /// that crosses a closed body enters it through a face turned towards the viewpoint, so
    /// for a solid part (+1) the other faces can be skipped.
    pub closed: i8,
    /// For a face of a closed *convex* body: the body's id (its first face). The shadow of a
    /// convex body is the convex hull of its faces' shadows.
    pub body: Option<u32>,
    /// Faces of that convex body (0 when there is none).
    pub body_faces: u32,
    /// For a blocker of coplanar patches (`coplanar_tiles`): the patches besides its
    /// source's; empty otherwise.
    pub also: Vec<u32>,
}

/// The scene's blockers with their box hierarchies.
#[derive(Debug, Clone)]
pub struct Blockers {
    blockers: Vec<Blocker>,
    blocker_tree: BoxTree,
    patch_tree: BoxTree,
    snap: f64,
    pad: f64,
}

impl Blockers {
    /// Hash of both box trees (blockers and patches) and the snap and pad lengths: the
    /// agreement check of MPI ranks and shards.
    pub fn tree_hash(&self) -> u64 {
        use std::hash::Hasher;
        let mut h = fnv::FnvHasher::default();
        self.blocker_tree.hash_into(&mut h);
        self.patch_tree.hash_into(&mut h);
        h.write_u64(self.snap.to_bits());
        h.write_u64(self.pad.to_bits());
        h.finish()
    }

    /// Collects, filters and indexes the blockers of `scene`.
    pub fn new(scene: &Scene) -> Self {
        Self::seen_from(scene, &[])
    }

    /// As [`Self::new`], also keeping blockers with only `viewpoints` (points outside the
    /// patches, such as sensors) on one side of their plane and patch material on the other.
    pub fn seen_from(scene: &Scene, viewpoints: &[DVec3]) -> Self {
        let (lo, hi) = scene
            .patches
            .iter()
            .map(|p| &p.polygon)
            .chain(scene.obstructions.iter().flat_map(|o| o.polygons.iter()))
            .flat_map(|p| p.vertices().iter().copied())
            .fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), v| {
                (l.min(v), h.max(v))
            });
        let size = if lo.x <= hi.x { (hi - lo).length() + lo.abs().max(hi.abs()).max_element() } else { 1.0 };
        let pad = BLOCKER_BOX_PAD_REL * size;
        let snap = BLOCKER_SNAP_REL * size;
        let patch_tree = BoxTree::new(scene.patches.iter().map(|p| bounds(p.polygon.vertices())), pad);
        let mut all = Vec::new();
        collect(scene, snap, &mut all);
        let mut me = Self { blockers: Vec::new(), blocker_tree: BoxTree::default(), patch_tree, snap, pad };
        // Keep blockers with patch material strictly on both sides of their plane.
        let kept: Vec<Blocker> = all
            .into_iter()
            .filter(|b| {
                let off = b.normal.dot(b.ring[0]);
                let seen = |n: DVec3, d: f64| viewpoints.iter().any(|&x| n.dot(x) + d > snap);
                (me.any_patch_vertex(scene, b.normal, -off) || seen(b.normal, -off))
                    && (me.any_patch_vertex(scene, -b.normal, off) || seen(-b.normal, off))
            })
            .collect();
        let mut kept = kept;
        link_shared_edges(&mut kept);
        me.blocker_tree = BoxTree::new(kept.iter().map(|b| bounds(&b.ring)), pad);
        me.blockers = kept;
        me
    }

    /// Number of blockers.
    pub fn len(&self) -> usize {
        self.blockers.len()
    }
    /// True when nothing in the scene can block a sight line.
    pub fn is_empty(&self) -> bool {
        self.blockers.is_empty()
    }
    /// Blocker `k`.
    pub fn get(&self, k: usize) -> &Blocker {
        &self.blockers[k]
    }
    /// Length below which points count as coincident or on a plane.
    pub fn snap(&self) -> f64 {
        self.snap
    }
    /// Padding of every box in the hierarchies, beyond the round-off of a cut point.
    pub fn pad(&self) -> f64 {
        self.pad
    }

    /// True when blocker `k` is a face of a non-convex solid part (closed, normals out) with
    /// every point of `pts` on or behind its plane: a sight line leaving those points crosses
    /// the part only by entering it through a face turned towards its start, so this face is
    /// never the first one crossed and can be left out of their shadows (convex solids keep
    /// every face: their facet sum counts faces turned towards either patch).
    pub fn turned_from(&self, k: usize, pts: &[DVec3]) -> bool {
        let b = &self.blockers[k];
        if b.closed != 1 || b.body.is_some() {
            return false;
        }
        let off = b.normal.dot(b.ring[0]);
        pts.iter().all(|&x| b.normal.dot(x) - off <= self.snap)
    }

    /// Blockers whose padded box passes `keep(lo, hi)` at every level, appended to `out`.
    pub fn blockers_where(&self, keep: impl FnMut(DVec3, DVec3) -> bool, out: &mut Vec<u32>) {
        self.blocker_tree.collect(keep, out);
    }
    /// Calls `visit(index)` for each blocker whose padded box passes `keep(lo, hi)` at every
    /// level.
    pub fn walk_blockers(&self, keep: impl FnMut(DVec3, DVec3) -> bool, mut visit: impl FnMut(u32)) {
        self.blocker_tree.walk(keep, |k| {
            visit(k);
            true
        });
    }
    /// Some blocker whose padded box passes `keep(lo, hi)` at every level of the tree and that
    /// passes `accept`, `None` exactly when a walk with `keep` finds none; the search starts
    /// at the blockers `hints` and their neighbourhood in the tree ([`BoxTree::find_near`]).
    pub fn blocker_accepted(
        &self,
        hints: &[u32],
        keep: impl FnMut(DVec3, DVec3) -> bool,
        mut accept: impl FnMut(&Blocker) -> bool,
    ) -> Option<u32> {
        self.blocker_tree.find_near(hints, keep, |k| accept(&self.blockers[k as usize]))
    }
    /// The hierarchy over patch boxes (index = patch).
    pub fn patch_tree(&self) -> &BoxTree {
        &self.patch_tree
    }
    /// Patches whose padded box passes `keep(lo, hi)` at every level, appended to `out`.
    pub fn patches_where(&self, keep: impl FnMut(DVec3, DVec3) -> bool, out: &mut Vec<u32>) {
        self.patch_tree.collect(keep, out);
    }

    /// A test for a run of polygons (patches in scene order, then obstruction polygons): true
    /// when patch vertices lie strictly (beyond the snap) on both sides of the polygon's plane
    /// (its vertices' spread along the normal counted as on it), the rule that keeps a
    /// blocker: only then can it separate two points of the patches. A polygon in the plane of
    /// the one before (normals within [`SAME_PLANE_NORMAL`], its spread within a tenth of the
    /// snap of that one's) takes its answer: a wall's patches lie in one plane, and each test
    /// of a wall walks every patch of that plane.
    pub fn splits_patches<'a>(&'a self, scene: &'a Scene) -> impl FnMut(&Polygon) -> bool + 'a {
        let mut last: Option<(DVec3, f64, f64, bool)> = None;
        let near = 0.1 * self.snap;
        move |poly| {
            let n = poly.normal();
            let (lo, hi) = poly.vertices().iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                let o = n.dot(*v);
                (l.min(o), h.max(o))
            });
            if let Some((m, l, h, answer)) = last {
                if (n - m).abs().max_element() <= SAME_PLANE_NORMAL && lo >= l - near && hi <= h + near {
                    return answer;
                }
            }
            let answer = self.any_patch_vertex(scene, n, -lo) && self.any_patch_vertex(scene, -n, hi);
            last = Some((n, lo, hi, answer));
            answer
        }
    }

    /// True when some patch vertex x has n·x + d > snap.
    fn any_patch_vertex(&self, scene: &Scene, n: DVec3, d: f64) -> bool {
        let snap = self.snap;
        let mut found = false;
        let box_max = |lo: DVec3, hi: DVec3| n.dot(0.5 * (lo + hi)) + n.abs().dot(0.5 * (hi - lo)) + d;
        self.patch_tree.walk(
            |lo, hi| box_max(lo, hi) > snap,
            |p| {
                found = scene.patches[p as usize].polygon.vertices().iter().any(|&x| n.dot(x) + d > snap);
                !found
            },
        );
        found
    }
}

/// Every candidate blocker of the scene, before the two-sides filter.
fn collect(scene: &Scene, snap: f64, out: &mut Vec<Blocker>) {
    for (s, surface) in scene.surfaces.iter().enumerate() {
        let patches = &scene.patches[surface.patches.clone()];
        if patches.len() > 1 && surface.planar {
            if let Some(ring) = tiled_outline(patches.iter().map(|p| &p.polygon), surface.area) {
                let normal = patches[0].polygon.normal();
                out.push(Blocker {
                    ring,
                    normal,
                    source: BlockerSource::Surface(s),
                    across: Vec::new(),
                    closed: 0,
                    body: None,
                    body_faces: 0,
                    also: Vec::new(),
                });
                continue;
            }
        }
        let polys: Vec<&Polygon> = patches.iter().map(|p| &p.polygon).collect();
        for piece in coplanar_tiles(&polys, snap) {
            let source = BlockerSource::Patch(surface.patches.start + piece.first);
            let also = piece.members[1..].iter().map(|&k| (surface.patches.start + k) as u32).collect();
            push_tile(piece, &polys, source, also, out);
        }
    }
    for (o, obs) in scene.obstructions.iter().enumerate() {
        let polys: Vec<&Polygon> = obs.polygons.iter().collect();
        for piece in coplanar_tiles(&polys, snap) {
            let source = BlockerSource::Obstruction { obstruction: o, polygon: piece.first };
            push_tile(piece, &polys, source, Vec::new(), out);
        }
    }
}

/// The blocker of `piece`: its merged ring, or its one polygon ([`push_convex`]).
fn push_tile(piece: Tile, polys: &[&Polygon], source: BlockerSource, also: Vec<u32>, out: &mut Vec<Blocker>) {
    match piece.ring {
        Some(ring) => out.push(Blocker {
            ring,
            normal: polys[piece.first].normal(),
            source,
            across: Vec::new(),
            closed: 0,
            body: None,
            body_faces: 0,
            also,
        }),
        None => push_convex(polys[piece.first], source, out),
    }
}

/// One blocker of a mesh: polygon `first` alone (`ring` `None`), or the convex ring that it and
/// its coplanar neighbours (`members`, `first` the first of them) tile.
struct Tile {
    first: usize,
    ring: Option<Vec<DVec3>>,
    members: Vec<usize>,
}

/// A mesh's polygons (an obstruction's, or a surface's patches) with every connected set of
/// coplanar neighbours (sharing an edge, bit-identical end points) that tiles its convex hull
/// taken as that hull: a meshed body's flat face is one blocker, not one per triangle (fewer
/// shadows to cast and classify, and no seam between them). The hull's corners are the
/// polygons' own vertices, so the merged faces still share their edges bit for bit. Other
/// polygons stay as they are.
fn coplanar_tiles(polys: &[&Polygon], snap: f64) -> Vec<Tile> {
    let n = polys.len();
    let mut groups = Groups::new(n);
    let coplanar = |a: &Polygon, b: &Polygon| {
        a.normal().dot(b.normal()) > 1.0 - COPLANAR_NORMAL_TOL
            && b.vertices().iter().all(|&x| a.normal().dot(x - a.vertices()[0]).abs() <= snap)
    };
    for sharing in edge_uses(polys.iter().map(|p| p.vertices())).values() {
        if let [(a, _), (b, _)] = sharing[..] {
            let (a, b) = (a as usize, b as usize);
            if a != b && coplanar(polys[a], polys[b]) {
                groups.join(a, b);
            }
        }
    }
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for k in 0..n {
        members[groups.root(k)].push(k);
    }
    let mut out = Vec::with_capacity(n);
    for (r, group) in members.iter().enumerate() {
        if group.is_empty() {
            continue;
        }
        if group.len() > 1 {
            let area: f64 = group.iter().map(|&k| polys[k].area()).sum();
            if let Some(ring) = tiled_corners(group.iter().map(|&k| polys[k]), area) {
                out.push(Tile { first: r, ring: Some(ring), members: group.clone() });
                continue;
            }
        }
        out.extend(group.iter().map(|&k| Tile { first: k, ring: None, members: vec![k] }));
    }
    out.sort_by_key(|t| t.first);
    out
}

/// As [`tiled_outline`], the hull's corners being the polygons' own vertices.
fn tiled_corners<'a>(polys: impl Iterator<Item = &'a Polygon> + Clone, area: f64) -> Option<Vec<DVec3>> {
    let first = polys.clone().next()?;
    let (n, o) = (first.normal(), first.centroid());
    let (e1, _) = n.any_orthonormal_pair();
    let e2 = n.cross(e1);
    let flat = |v: DVec3| DVec2::new((v - o).dot(e1), (v - o).dot(e2));
    let corners: Vec<(DVec2, DVec3)> =
        polys.flat_map(|p| p.vertices().iter()).map(|&v| (flat(v), v)).collect();
    let mut pts: Vec<DVec2> = corners.iter().map(|c| c.0).collect();
    let mut hull = Vec::new();
    convex_hull(&mut pts, &mut hull);
    let hull_area = 0.5 * twice_area(&hull);
    if hull.len() < 3 || (hull_area - area).abs() > TILE_AREA_REL * area {
        return None;
    }
    hull.iter().map(|q| corners.iter().find(|c| c.0 == *q).map(|c| c.1)).collect()
}

/// Fills every blocker's [`Blocker::across`]: edges with bit-identical end points shared by
/// exactly two consistently oriented blockers (walking it in opposite directions) are linked.
/// A pair wound against each other stays unlinked: its faces' shadows turn the same way along
/// the edge, which an outline must keep.
fn link_shared_edges(blockers: &mut [Blocker]) {
    let edges = edge_uses(blockers.iter().map(|b| b.ring.as_slice()));
    for bl in blockers.iter_mut() {
        bl.across = vec![None; bl.ring.len()];
    }
    let mut consistent = vec![true; blockers.len()];
    for sharing in edges.values() {
        if let [(b0, k0), (b1, k1)] = sharing[..] {
            if b0 != b1 {
                // Consistent orientation walks a shared edge in opposite directions.
                let start = |b: u32, k: u32| vertex_key(blockers[b as usize].ring[k as usize]);
                if start(b0, k0) == start(b1, k1) {
                    consistent[b0 as usize] = false;
                    consistent[b1 as usize] = false;
                    continue;
                }
                blockers[b0 as usize].across[k0 as usize] = Some(b1);
                blockers[b1 as usize].across[k1 as usize] = Some(b0);
            }
        }
    }
    mark_closed(blockers, &consistent);
}

/// A vertex's bits: vertices are one only when bit-identical.
fn vertex_key(v: DVec3) -> [u64; 3] {
    v.to_array().map(f64::to_bits)
}

/// Undirected edges (end points by [`vertex_key`], lower first) and their uses (ring, edge).
type EdgeUses = std::collections::HashMap<([u64; 3], [u64; 3]), Vec<(u32, u32)>>;

/// Every undirected edge of the rings (end points by [`vertex_key`], either direction) with its
/// uses: (ring, edge k from vertex k to k + 1).
fn edge_uses<'a>(rings: impl Iterator<Item = &'a [DVec3]>) -> EdgeUses {
    let mut edges = EdgeUses::new();
    for (b, ring) in rings.enumerate() {
        let m = ring.len();
        for k in 0..m {
            let (a, c) = (vertex_key(ring[k]), vertex_key(ring[(k + 1) % m]));
            edges.entry(if a <= c { (a, c) } else { (c, a) }).or_default().push((b as u32, k as u32));
        }
    }
    edges
}

/// Sets [`Blocker::closed`] on every component (blockers linked through shared edges) in
/// which every edge is shared and consistently oriented; the sign is that of the enclosed
/// volume Σ v₀·(v_k × v_{k+1})/6, positive when the normals point out.
fn mark_closed(blockers: &mut [Blocker], consistent: &[bool]) {
    let n = blockers.len();
    let mut component = vec![u32::MAX; n];
    let mut stack = Vec::new();
    for start in 0..n {
        if component[start] != u32::MAX {
            continue;
        }
        let mut members = vec![start];
        component[start] = start as u32;
        stack.push(start);
        let mut closed = true;
        while let Some(b) = stack.pop() {
            closed &= consistent[b];
            for c in &blockers[b].across {
                match *c {
                    None => closed = false,
                    Some(c) if component[c as usize] == u32::MAX => {
                        component[c as usize] = start as u32;
                        members.push(c as usize);
                        stack.push(c as usize);
                    }
                    Some(_) => {}
                }
            }
        }
        if !closed || members.len() < 4 {
            continue;
        }
        let volume: f64 = members
            .iter()
            .map(|&b| {
                let r = &blockers[b].ring;
                (1..r.len() - 1).map(|k| r[0].dot(r[k].cross(r[k + 1]))).sum::<f64>()
            })
            .sum();
        let sign = if volume > 0.0 {
            1
        } else if volume < 0.0 {
            -1
        } else {
            0
        };
        let convex = sign != 0 && is_convex_body(blockers, &members, f64::from(sign));
        for &b in &members {
            blockers[b].closed = sign;
            blockers[b].body = convex.then_some(start as u32);
            blockers[b].body_faces = if convex { members.len() as u32 } else { 0 };
        }
    }
}

/// True when the closed body of faces `members` (normals out when `sign` > 0) is convex: at
/// every shared edge the neighbour lies behind the face (a closed, locally convex surface
/// bounds a convex body), and, for bodies of moderate size, every vertex behind every face.
fn is_convex_body(blockers: &[Blocker], members: &[usize], sign: f64) -> bool {
    let (lo, hi) =
        members.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), &b| {
            let (bl, bh) = bounds(&blockers[b].ring);
            (l.min(bl), h.max(bh))
        });
    let tol = CONVEX_BODY_REL * (hi - lo).length();
    let behind = |b: usize, x: DVec3| sign * blockers[b].normal.dot(x - blockers[b].ring[0]) <= tol;
    let local = members.iter().all(|&b| {
        blockers[b].across.iter().flatten().all(|&c| blockers[c as usize].ring.iter().all(|&x| behind(b, x)))
    });
    let vertices: usize = members.iter().map(|&b| blockers[b].ring.len()).sum();
    local
        && (members.len() * vertices > CONVEX_BODY_FULL_CHECK
            || members
                .iter()
                .all(|&b| members.iter().all(|&c| blockers[c].ring.iter().all(|&x| behind(b, x)))))
}

/// The polygon itself when convex, else its triangles.
fn push_convex(p: &Polygon, source: BlockerSource, out: &mut Vec<Blocker>) {
    if p.is_convex() {
        out.push(Blocker {
            ring: p.vertices().to_vec(),
            normal: p.normal(),
            source,
            across: Vec::new(),
            closed: 0,
            body: None,
            body_faces: 0,
            also: Vec::new(),
        });
    } else {
        for t in p.triangulate() {
            out.push(Blocker {
                ring: t.to_vec(),
                normal: p.normal(),
                source,
                across: Vec::new(),
                closed: 0,
                body: None,
                body_faces: 0,
                also: Vec::new(),
            });
        }
    }
}

/// The convex hull of coplanar polygons when their areas add up to the hull's: they tile it.
fn tiled_outline<'a>(polys: impl Iterator<Item = &'a Polygon> + Clone, area: f64) -> Option<Vec<DVec3>> {
    let first = polys.clone().next()?;
    let (n, o) = (first.normal(), first.centroid());
    let (e1, _) = n.any_orthonormal_pair();
    let e2 = n.cross(e1);
    let mut pts: Vec<DVec2> = polys
        .flat_map(|p| p.vertices().iter())
        .map(|&v| DVec2::new((v - o).dot(e1), (v - o).dot(e2)))
        .collect();
    let mut hull = Vec::new();
    convex_hull(&mut pts, &mut hull);
    let hull_area = 0.5 * twice_area(&hull);
    ((hull_area - area).abs() <= TILE_AREA_REL * area)
        .then(|| hull.iter().map(|q| o + q.x * e1 + q.y * e2).collect())
}

/// The box (lo, hi) of points `v`.
pub fn bounds(v: &[DVec3]) -> (DVec3, DVec3) {
    v.iter().fold((DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)), |(l, h), p| {
        (l.min(*p), h.max(*p))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::subdivide::parallelogram_grid;

    /// The six faces of the box [lo, lo + size]³, split n×n, facing out (or in).
    fn cube_faces(lo: DVec3, size: f64, n: usize, inward: bool) -> Vec<Vec<Polygon>> {
        let (x, y, z) = (DVec3::X * size, DVec3::Y * size, DVec3::Z * size);
        let faces = [(lo, y, x), (lo + z, x, y), (lo, x, z), (lo + y, z, x), (lo, z, y), (lo + x, y, z)];
        faces
            .iter()
            .map(|&(o, u, v)| {
                let (u, v) = if inward { (v, u) } else { (u, v) };
                parallelogram_grid(o, u, v, n, n).unwrap()
            })
            .collect()
    }

    #[test]
    fn room_walls_never_block_and_a_tiled_block_face_is_one_outline() {
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::ZERO, 3.0, 6, true).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 0.9, None);
        }
        let room = b.build();
        assert!(Blockers::new(&room).is_empty(), "a convex room has no blockers");
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::ZERO, 3.0, 6, true).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 0.9, None);
        }
        for (k, f) in cube_faces(DVec3::ONE, 1.0, 4, false).into_iter().enumerate() {
            b = b.surface(&format!("block{k}"), f, 0.9, None);
        }
        let scene = b.build();
        let blockers = Blockers::new(&scene);
        assert_eq!(blockers.len(), 6, "one outline per block face");
        for k in 0..6 {
            let bl = blockers.get(k);
            assert!(matches!(bl.source, BlockerSource::Surface(s) if s >= 6));
            assert_eq!(bl.ring.len(), 4);
            let area = 0.5 * newell(&bl.ring).length();
            assert!((area - 1.0).abs() < 1e-12, "outline area {area}");
            assert!(newell(&bl.ring).normalize().dot(bl.normal) > 0.999_999);
        }
        // Blockers in front of the floor's plane: all six block faces.
        let mut found = Vec::new();
        let floor = DVec3::Z;
        blockers.blockers_where(
            |lo, hi| floor.dot(0.5 * (lo + hi)) + floor.abs().dot(0.5 * (hi - lo)) > 0.0,
            &mut found,
        );
        assert_eq!(found.len(), 6);
        // Patches touching the box x ≥ 2.9: the wall x = 3 (36) plus the y/z wall columns (4·6).
        let mut near = Vec::new();
        blockers.patches_where(|_, hi| hi.x >= 2.9, &mut near);
        near.retain(|&p| scene.patches[p as usize].polygon.vertices().iter().any(|v| v.x >= 2.9));
        assert_eq!(near.len(), 36 + 4 * 6);
    }

    #[test]
    fn a_tree_without_the_room_walls_answers_every_occlusion_query_alike() {
        use crate::visibility::Visibility;
        use rand::{Rng, SeedableRng};
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::ZERO, 3.0, 6, true).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 0.9, None);
        }
        for (k, f) in cube_faces(DVec3::new(0.8, 1.1, 0.9), 1.2, 4, false).into_iter().enumerate() {
            b = b.surface(&format!("block{k}"), f, 0.9, None);
        }
        let scene = b
            .obstruction(
                "plate",
                vec![Polygon::new(vec![
                    DVec3::new(0.2, 0.2, 2.5),
                    DVec3::new(2.0, 0.2, 2.5),
                    DVec3::new(2.0, 1.5, 2.5),
                    DVec3::new(0.2, 1.5, 2.5),
                ])
                .unwrap()],
            )
            .build();
        let blockers = Blockers::new(&scene);
        let full = Visibility::new(&scene);
        let cut = Visibility::occluding_only(&scene, blockers.splits_patches(&scene));
        // A run's answers, some taken from the polygon before, are each polygon's own.
        let mut run = blockers.splits_patches(&scene);
        for p in &scene.patches {
            assert_eq!(run(&p.polygon), blockers.splits_patches(&scene)(&p.polygon));
        }
        // Walls 6·36 quads, block 6·16, plate 1, two triangles each: only block and plate stay.
        assert_eq!(full.stats().triangles, 2 * (6 * 36 + 6 * 16 + 1));
        assert_eq!(cut.stats().triangles, 2 * (6 * 16 + 1));
        let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(11);
        let n = scene.patches.len();
        let mut point = |p: usize| {
            let v = scene.patches[p].polygon.vertices();
            let (a, b): (f64, f64) = (rng.random(), rng.random());
            v[0] + a * (v[1] - v[0]) + b * (v[3] - v[0])
        };
        let (mut hidden, mut clear) = (0, 0);
        for k in 0..20_000u64 {
            let (i, j) = ((k * 7919 % n as u64) as usize, (k * 104_729 % n as u64) as usize);
            if i == j {
                continue;
            }
            let (x, y) = (point(i), point(j));
            let o = full.occluded(x, y, i, j);
            assert_eq!(cut.occluded(x, y, i, j), o, "patches {i} and {j}");
            if o {
                hidden += 1;
            } else {
                clear += 1;
            }
        }
        assert!(hidden > 2_000 && clear > 2_000, "{hidden} hidden, {clear} clear");
    }

    /// Faces of the box [lo, lo + 1]³ facing out, as triangles; the top face as a fan about
    /// its centre, lowered by `dent` (a dent makes the closed body non-convex).
    fn dented_block(lo: DVec3, dent: f64) -> Vec<Polygon> {
        let c = |i: usize| lo + DVec3::new((i & 1) as f64, (i >> 1 & 1) as f64, (i >> 2) as f64);
        let quads = [[0, 2, 3, 1], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let mut out: Vec<Polygon> = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .map(|t| Polygon::new(t.iter().map(|&i| c(i)).collect()).unwrap())
            .collect();
        let m = lo + DVec3::new(0.5, 0.5, 1.0 - dent);
        for (a, b) in [(4, 5), (5, 7), (7, 6), (6, 4)] {
            out.push(Polygon::new(vec![c(a), c(b), m]).unwrap());
        }
        out
    }

    fn room_with(block: Vec<Polygon>) -> Scene {
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::ZERO, 3.0, 2, true).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 0.9, None);
        }
        b.obstruction("block", block).build()
    }

    #[test]
    fn the_tree_hash_tells_equal_trees_from_different_ones() {
        let a = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.0)));
        let again = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.0)));
        assert_eq!(a.tree_hash(), again.tree_hash(), "the same scene builds the same trees");
        // The block moved by a hundredth: other node boxes, another hash.
        let moved = Blockers::new(&room_with(dented_block(DVec3::splat(1.01), 0.0)));
        assert_ne!(a.tree_hash(), moved.tree_hash());
        // The same boxes in another primitive order (a tree built differently): another hash.
        let mut swapped = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.0)));
        swapped.blocker_tree.swap_primitives_for_test();
        assert_ne!(a.tree_hash(), swapped.tree_hash());
    }

    #[test]
    fn closed_and_convex_bodies_are_recognised_from_shared_edges() {
        // A closed convex block: every edge linked, normals out, one convex body; each face's
        // triangles (four on the flat top) one square blocker.
        let blockers = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.0)));
        assert_eq!(blockers.len(), 6);
        for b in 0..blockers.len() {
            let bl = blockers.get(b);
            assert_eq!(bl.ring.len(), 4, "{bl:?}");
            assert!(bl.across.iter().all(Option::is_some), "{bl:?}");
            assert_eq!((bl.closed, bl.body), (1, Some(0)), "{bl:?}");
        }
        // The top face dented: still closed, no longer convex.
        let blockers = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.2)));
        assert!((0..blockers.len()).all(|b| blockers.get(b).closed == 1 && blockers.get(b).body.is_none()));
        // Without the top: an open box, nothing closed.
        let mut open = dented_block(DVec3::ONE, 0.0);
        open.truncate(10);
        let blockers = Blockers::new(&room_with(open));
        assert!((0..blockers.len()).all(|b| blockers.get(b).closed == 0 && blockers.get(b).body.is_none()));
        assert!((0..blockers.len()).any(|b| blockers.get(b).across.iter().any(Option::is_none)));
        // One top triangle wound against its neighbours: linked to none of them (an outline
        // must keep its edges), and the body is no longer closed.
        let mut flipped = dented_block(DVec3::ONE, 0.2);
        let last = flipped.pop().unwrap();
        flipped.push(Polygon::new(last.vertices().iter().rev().copied().collect()).unwrap());
        let blockers = Blockers::new(&room_with(flipped));
        let m = DVec3::new(1.5, 1.5, 1.8);
        let f = (0..blockers.len())
            .find(|&b| blockers.get(b).normal.z < 0.0 && blockers.get(b).ring.contains(&m))
            .expect("the flipped top triangle");
        assert!(blockers.get(f).across.iter().all(Option::is_none), "{:?}", blockers.get(f));
        assert!((0..blockers.len()).all(|b| !blockers.get(b).across.contains(&Some(f as u32))));
        assert!((0..blockers.len()).all(|b| blockers.get(b).closed == 0));
    }

    #[test]
    fn a_mesh_s_coplanar_neighbours_are_one_blocker_only_where_they_tile_a_convex_face() {
        // A cube whose faces are 2 × 2 squares, each split into two triangles: six squares,
        // their corners the mesh's own vertices (bit for bit), linked along every edge.
        let cube: Vec<Polygon> = cube_faces(DVec3::ONE, 1.0, 2, false)
            .into_iter()
            .flatten()
            .flat_map(|q| {
                let v = q.vertices().to_vec();
                [vec![v[0], v[1], v[2]], vec![v[0], v[2], v[3]]]
            })
            .map(|t| Polygon::new(t).unwrap())
            .collect();
        let corners: Vec<DVec3> = cube.iter().flat_map(|p| p.vertices().iter().copied()).collect();
        let blockers = Blockers::new(&room_with(cube.clone()));
        assert_eq!(blockers.len(), 6);
        for b in 0..6 {
            let bl = blockers.get(b);
            assert_eq!(bl.ring.len(), 4, "{bl:?}");
            assert!(bl.ring.iter().all(|v| corners.contains(v)), "{bl:?}");
            assert!((bl.ring[1] - bl.ring[0]).cross(bl.ring[2] - bl.ring[0]).dot(bl.normal) > 0.0, "{bl:?}");
            assert!(bl.across.iter().all(Option::is_some) && bl.closed == 1 && bl.body.is_some(), "{bl:?}");
        }
        // The same cube as the patches of one surface: six blockers, each patch in one of them.
        let mut b = Scene::builder();
        for (k, f) in cube_faces(DVec3::ZERO, 3.0, 2, true).into_iter().enumerate() {
            b = b.surface(&format!("wall{k}"), f, 0.9, None);
        }
        let scene = b.surface("cube", cube.clone(), 0.9, None).build();
        let blockers = Blockers::new(&scene);
        let mut covered: Vec<usize> = Vec::new();
        for k in 0..blockers.len() {
            let bl = blockers.get(k);
            if let BlockerSource::Patch(p) = bl.source {
                assert_eq!(bl.ring.len(), 4, "{bl:?}");
                covered.push(p);
                covered.extend(bl.also.iter().map(|&q| q as usize));
            }
        }
        covered.sort_unstable();
        let first = scene.surfaces[6].patches.start;
        assert_eq!(covered, (first..first + 48).collect::<Vec<_>>());
        assert_eq!(blockers.len(), 6, "the cube's faces (the room's walls never block)");
        // An L of three unit squares in one plane (six triangles, non-convex): kept as they are.
        let d = DVec3::new;
        let sq = |x: f64, y: f64| {
            let (a, b, c, e) =
                (d(x, y, 1.5), d(x + 0.5, y, 1.5), d(x + 0.5, y + 0.5, 1.5), d(x, y + 0.5, 1.5));
            [Polygon::new(vec![a, b, c]).unwrap(), Polygon::new(vec![a, c, e]).unwrap()]
        };
        let l: Vec<Polygon> =
            [(1.0, 1.0), (1.5, 1.0), (1.0, 1.5)].iter().flat_map(|&(x, y)| sq(x, y)).collect();
        assert_eq!(Blockers::new(&room_with(l.clone())).len(), 6);
        // Two of them (a rectangle) merge; folded along their shared edge (the second square
        // tilted by 2e-6 rad) they are one blocker per square.
        assert_eq!(Blockers::new(&room_with(l[..4].to_vec())).len(), 1);
        let mut folded = l[..4].to_vec();
        let v = folded[3].vertices().to_vec();
        let lifted = |x: DVec3| if x.x > 1.75 { x + d(0.0, 0.0, 1e-6) } else { x };
        folded[3] = Polygon::new(v.iter().map(|&x| lifted(x)).collect()).unwrap();
        folded[2] = Polygon::new(folded[2].vertices().iter().map(|&x| lifted(x)).collect()).unwrap();
        assert_eq!(Blockers::new(&room_with(folded)).len(), 2);
    }

    #[test]
    fn only_faces_of_a_non_convex_solid_turned_away_from_every_point_are_left_out() {
        let above = [DVec3::new(1.2, 1.3, 2.9), DVec3::new(1.8, 1.3, 2.9), DVec3::new(1.5, 1.8, 2.9)];
        let bottom = |b: &Blockers| (0..b.len()).find(|&k| b.get(k).normal.z < -0.9).expect("a bottom face");
        // Dented (non-convex, closed): the bottom faces away from points above the block, the
        // dent's faces turn towards them, and a point below turns the bottom towards itself.
        let dented = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.2)));
        assert!(dented.turned_from(bottom(&dented), &above));
        let dent: Vec<usize> = (0..dented.len()).filter(|&k| dented.get(k).normal.z > 0.1).collect();
        assert_eq!(dent.len(), 4);
        assert!(dent.iter().all(|&k| !dented.turned_from(k, &above)));
        let mixed = [above[0], DVec3::new(1.5, 1.5, 0.5)];
        assert!(!dented.turned_from(bottom(&dented), &mixed));
        // A convex solid keeps every face (its facet sum needs them), an open box too.
        let convex = Blockers::new(&room_with(dented_block(DVec3::ONE, 0.0)));
        assert!(!convex.turned_from(bottom(&convex), &above));
        let mut open = dented_block(DVec3::ONE, 0.0);
        open.truncate(10);
        let open = Blockers::new(&room_with(open));
        assert!(!open.turned_from(bottom(&open), &above));
    }

    fn newell(v: &[DVec3]) -> DVec3 {
        (0..v.len()).map(|k| v[k].cross(v[(k + 1) % v.len()])).sum()
    }
}
