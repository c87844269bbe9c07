//! Mesh hygiene: what is wrong with a model file's triangles, as data ([`MeshReport`]) and as
//! one warning line per kind of finding ([`warnings`]).
//!
//! The checks run on the welded mesh of the whole file (all its surfaces together, so a box
//! whose faces are separate glTF nodes is one closed body):
//! - open (boundary) edges, used by one triangle, less the seams of faces meshed apart
//!   (T-junctions, tjunction.rs); non-manifold edges, used by more than two;
//! - duplicate faces (the same three vertices, in either order);
//! - winding: edges whose two triangles run them the same way, and per component the
//!   triangles against its majority (the ones [`repair`] flips);
//! - orientation: the signed volume of each closed, consistently wound component
//!   (V > 0 outward, a body; V < 0 inward, seen from inside as an enclosure is);
//! - slivers: aspect ratio √3·L²/(4A) (longest edge L over the height on it, scaled to 1 for
//!   an equilateral triangle) above [`SLIVER_ASPECT`];
//! - self-intersections (intersect.rs): triangle pairs that cross, found through a BVH, pairs
//!   sharing a vertex left out.
//!
//! - [`repair`]: weld, drop duplicates and slivers, orient consistently and outward;
//! - [`warnings`]: the findings as stderr lines for the user.
use super::mesh::{Edge, Tag, TriMesh, WeldInfo};
use glam::DVec3;
use std::path::PathBuf;
use tjunction::Link;

pub(crate) mod intersect;
pub(crate) mod repair;
pub(crate) mod tjunction;
pub(crate) mod warn;

pub use warn::warnings;

/// Aspect ratio above which a triangle is a sliver. CAD strips along a long cylinder reach a
/// few hundred; beyond 1e3 a triangle is near-collinear (its height is 0.1 % of its length),
/// too thin for a patch whose samples and quadrature points should cover it.
pub const SLIVER_ASPECT: f64 = 1e3;

/// Default weld tolerance as a fraction of the model's bounding-box diagonal: far below any
/// feature of a part (1 µm on a 1 m part), far above f32 round-off of its coordinates.
pub const WELD_REL: f64 = 1e-6;

/// A triangle named by surface (index into [`MeshReport::surfaces`]) and index as read, with
/// the finding's value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Example {
    /// Where.
    pub at: Tag,
    /// The finding's measure (see each finding).
    pub value: f64,
    /// A second triangle when the finding is about a pair (duplicates, intersections).
    pub other: Option<Tag>,
}

/// One kind of finding: how many, and the worst example (largest value).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Finding {
    /// Count (edges, faces, triangles or pairs, see each field of [`MeshReport`]).
    pub count: usize,
    /// The example with the largest value.
    pub worst: Option<Example>,
}

impl Finding {
    fn add(&mut self, at: Tag, value: f64, other: Option<Tag>) {
        self.count += 1;
        if self.worst.is_none_or(|w| value > w.value) {
            self.worst = Some(Example { at, value, other });
        }
    }
}

/// A connected component of the welded mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Surfaces (indices into [`MeshReport::surfaces`]) that have triangles in it.
    pub surfaces: Vec<usize>,
    /// Its triangles.
    pub triangles: usize,
    /// No boundary and no non-manifold edge.
    pub closed: bool,
    /// Every edge shared by two triangles is run in opposite senses.
    pub consistent: bool,
    /// Signed enclosed volume, m³ (meaningful when closed and consistent): > 0 outward.
    pub volume: f64,
    /// Bounding box.
    pub lo: DVec3,
    /// Bounding box.
    pub hi: DVec3,
}

impl Component {
    /// Closed, consistently wound and facing outward: a body.
    pub fn is_outward_body(&self) -> bool {
        self.closed && self.consistent && self.volume > 0.0
    }
    /// Closed, consistently wound and facing inward: seen from inside.
    pub fn is_inward(&self) -> bool {
        self.closed && self.consistent && self.volume < 0.0
    }
}

/// Per-surface counts.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SurfaceCheck {
    /// Surface name.
    pub name: String,
    /// Triangles checked.
    pub triangles: usize,
    /// Boundary edges of its triangles.
    pub boundary_edges: usize,
    /// Triangles wound against the majority of their component.
    pub against: usize,
}

/// Everything the checks found in one model file.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshReport {
    /// The model file.
    pub file: PathBuf,
    /// Its surfaces in model order.
    pub surfaces: Vec<SurfaceCheck>,
    /// Weld tolerance used, m.
    pub weld_tol: f64,
    /// Bounding-box diagonal, m.
    pub diag: f64,
    /// Boundary edges covered by collinear edges of other triangles (T-junction seams).
    pub seams: usize,
    /// What welding did.
    pub weld: WeldInfo,
    /// Boundary edges; value: edge length, m.
    pub boundary: Finding,
    /// Non-manifold edges; value: triangles on the edge.
    pub nonmanifold: Finding,
    /// Duplicate faces beyond the first copy; value: copies of that face.
    pub duplicates: Finding,
    /// Edges whose two triangles run them the same way; value: 1.
    pub inconsistent_edges: Finding,
    /// Triangles against their component's majority; value: the component's triangle count.
    pub against: Finding,
    /// Slivers; value: aspect ratio.
    pub slivers: Finding,
    /// Crossing triangle pairs; value: length of the crossing segment, m (0 for coplanar
    /// overlaps).
    pub intersections: Finding,
    /// Connected components.
    pub components: Vec<Component>,
    /// What `repair` changed, when it ran.
    pub repair: Option<repair::RepairLog>,
}

impl MeshReport {
    /// Name of the surface of a tag.
    pub fn name(&self, t: Tag) -> &str {
        &self.surfaces[t.surface as usize].name
    }
}

/// Aspect ratio √3·L²/(4A): 1 for an equilateral triangle, ≈ L/h for a thin one; ∞ when flat.
pub fn aspect(t: [DVec3; 3]) -> f64 {
    let [a, b, c] = t;
    let l2 = (b - a).length_squared().max((c - b).length_squared()).max((a - c).length_squared());
    let area = 0.5 * (b - a).cross(c - a).length();
    if area > 0.0 {
        3f64.sqrt() * l2 / (4.0 * area)
    } else {
        f64::INFINITY
    }
}

/// Runs every check on a welded mesh whose surfaces are `names`; `weld` says what welding did.
pub fn check(file: PathBuf, names: &[String], mesh: &TriMesh, weld_tol: f64, weld: WeldInfo) -> MeshReport {
    let mut r = MeshReport {
        file,
        surfaces: names.iter().map(|n| SurfaceCheck { name: n.clone(), ..SurfaceCheck::default() }).collect(),
        weld_tol,
        weld,
        ..MeshReport::default()
    };
    for tag in &mesh.tags {
        r.surfaces[tag.surface as usize].triangles += 1;
    }
    let lo = mesh.vertices.iter().fold(DVec3::INFINITY, |a, &b| a.min(b));
    let hi = mesh.vertices.iter().fold(DVec3::NEG_INFINITY, |a, &b| a.max(b));
    r.diag = (hi - lo).length();
    let edges = mesh.edges();
    let (covered, links) = tjunction::seams(mesh, &edges, weld_tol);
    r.seams = covered.iter().filter(|&&c| c).count();
    edge_findings(&mut r, mesh, &edges, &covered);
    duplicate_faces(&mut r, mesh);
    let (ids, n) = linked_components(mesh, &edges, &links);
    r.components = components(mesh, &edges, &covered, &links, &ids, n);
    for (t, flip) in majority_flips(mesh, &edges, &links).into_iter().enumerate() {
        if flip {
            let tag = mesh.tags[t];
            let size = r.components[ids[t] as usize].triangles;
            r.against.add(tag, size as f64, None);
            r.surfaces[tag.surface as usize].against += 1;
        }
    }
    for (t, tag) in mesh.tags.iter().enumerate() {
        let q = aspect(mesh.corners(t));
        if q > SLIVER_ASPECT {
            r.slivers.add(*tag, q, None);
        }
    }
    r.intersections = intersect::self_intersections(mesh, weld_tol);
    r
}

fn edge_findings(r: &mut MeshReport, mesh: &TriMesh, edges: &[Edge], covered: &[bool]) {
    for (k, e) in edges.iter().enumerate() {
        let tag = mesh.tags[e.uses[0].0 as usize];
        if e.is_boundary() && !covered[k] {
            let len = mesh.vertices[e.a as usize].distance(mesh.vertices[e.b as usize]);
            r.boundary.add(tag, len, None);
            r.surfaces[tag.surface as usize].boundary_edges += 1;
        } else if e.is_nonmanifold() {
            r.nonmanifold.add(tag, e.uses.len() as f64, None);
        } else if e.is_inconsistent() {
            r.inconsistent_edges.add(tag, 1.0, Some(mesh.tags[e.uses[1].0 as usize]));
        }
    }
}

fn duplicate_faces(r: &mut MeshReport, mesh: &TriMesh) {
    for group in duplicate_groups(mesh) {
        let first = mesh.tags[group[0]];
        for &t in &group[1..] {
            r.duplicates.add(mesh.tags[t], group.len() as f64, Some(first));
        }
    }
}

/// Triangles on the same three vertices (whatever their order), as groups of two or more
/// indices, ascending within a group.
pub fn duplicate_groups(mesh: &TriMesh) -> Vec<Vec<usize>> {
    let mut keys: Vec<([u32; 3], usize)> = mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let mut k = *tri;
            k.sort_unstable();
            (k, t)
        })
        .collect();
    keys.sort_unstable();
    keys.chunk_by(|a, b| a.0 == b.0)
        .filter(|g| g.len() > 1)
        .map(|g| g.iter().map(|&(_, t)| t).collect())
        .collect()
}

/// Orientation patches: triangles joined through edges shared by exactly two triangles (and
/// across seams).
/// Per triangle, its patch and its parity (1 = wound against the patch's first triangle);
/// where a patch is not orientable the first assignment stays.
pub fn orientation_parity(mesh: &TriMesh, edges: &[Edge], links: &[Link]) -> (Vec<u8>, Vec<u32>, usize) {
    let n = mesh.triangles.len();
    let mut nbrs: Vec<Vec<(u32, bool)>> = vec![Vec::new(); n];
    for e in edges.iter().filter(|e| e.uses.len() == 2) {
        let ((s, ds), (t, dt)) = (e.uses[0], e.uses[1]);
        // Same direction: the two disagree, so their parities differ.
        nbrs[s as usize].push((t, ds == dt));
        nbrs[t as usize].push((s, ds == dt));
    }
    for &(s, t, same) in links {
        nbrs[s as usize].push((t, same));
        nbrs[t as usize].push((s, same));
    }
    let (mut parity, mut patch) = (vec![u8::MAX; n], vec![0u32; n]);
    let mut patches = 0;
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..n {
        if parity[seed] != u8::MAX {
            continue;
        }
        parity[seed] = 0;
        patch[seed] = patches as u32;
        queue.push_back(seed);
        while let Some(s) = queue.pop_front() {
            for &(t, differ) in &nbrs[s] {
                if parity[t as usize] == u8::MAX {
                    parity[t as usize] = parity[s] ^ u8::from(differ);
                    patch[t as usize] = patches as u32;
                    queue.push_back(t as usize);
                }
            }
        }
        patches += 1;
    }
    (parity, patch, patches)
}

/// Per triangle, `true` when it is wound against the majority of its orientation patch (ties:
/// the half that does not hold the patch's first triangle).
pub fn majority_flips(mesh: &TriMesh, edges: &[Edge], links: &[Link]) -> Vec<bool> {
    let (parity, patch, n) = orientation_parity(mesh, edges, links);
    let (mut ones, mut size) = (vec![0usize; n], vec![0usize; n]);
    for (t, &p) in patch.iter().enumerate() {
        ones[p as usize] += usize::from(parity[t] == 1);
        size[p as usize] += 1;
    }
    patch
        .iter()
        .enumerate()
        .map(|(t, &p)| {
            let minority = u8::from(2 * ones[p as usize] <= size[p as usize]);
            ones[p as usize] > 0 && parity[t] == minority
        })
        .collect()
}

/// Components through shared edges and seam links.
fn linked_components(mesh: &TriMesh, edges: &[Edge], links: &[Link]) -> (Vec<u32>, usize) {
    let mut all: Vec<Edge> = edges.to_vec();
    all.extend(links.iter().map(|&(s, t, _)| Edge {
        a: u32::MAX,
        b: u32::MAX,
        uses: vec![(s, true), (t, false)],
    }));
    mesh.components(&all)
}

fn components(
    mesh: &TriMesh,
    edges: &[Edge],
    covered: &[bool],
    links: &[Link],
    ids: &[u32],
    n: usize,
) -> Vec<Component> {
    let mut out: Vec<Component> = (0..n)
        .map(|_| Component {
            surfaces: Vec::new(),
            triangles: 0,
            closed: true,
            consistent: true,
            volume: 0.0,
            lo: DVec3::INFINITY,
            hi: DVec3::NEG_INFINITY,
        })
        .collect();
    let mut origin = vec![None; n];
    for (t, &c) in ids.iter().enumerate() {
        let c = c as usize;
        let comp = &mut out[c];
        comp.triangles += 1;
        let s = mesh.tags[t].surface as usize;
        if !comp.surfaces.contains(&s) {
            comp.surfaces.push(s);
        }
        let [a, b, p] = mesh.corners(t);
        comp.lo = comp.lo.min(a.min(b).min(p));
        comp.hi = comp.hi.max(a.max(b).max(p));
        // Volume about the component's first vertex keeps the sum free of large offsets.
        let o = *origin[c].get_or_insert(a);
        comp.volume += (a - o).dot((b - o).cross(p - o)) / 6.0;
    }
    for (k, e) in edges.iter().enumerate() {
        let c = &mut out[ids[e.uses[0].0 as usize] as usize];
        if e.is_nonmanifold() || (e.is_boundary() && !covered[k]) {
            c.closed = false;
        } else if e.is_inconsistent() {
            c.consistent = false;
        }
    }
    for &(s, _, same) in links {
        if same {
            out[ids[s as usize] as usize].consistent = false;
        }
    }
    out
}

#[cfg(test)]
mod tests;
