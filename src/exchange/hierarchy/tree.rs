//! The cluster tree of the hierarchical exchange: a binary tree over the patches whose leaves
//! are single patches. A node whose normals spread more than [`SPLIT_CONE_COS`] is split by
//! orientation first (at the widest gap of the normals along their spread direction, so that
//! surfaces facing different ways part early); a node of nearly parallel normals is split in
//! space at the median of the patch centroids along its longest box axis. Each node keeps what
//! the link estimates and bounds need: area, area-weighted centroid, bounding radius, box,
//! second moment of area, vector area Σ A_i n_i, normal cone and, when every normal is the same, its plane offsets.
use crate::geometry::polygon::outer;
use crate::scene::Scene;
use glam::{DMat3, DVec3};

/// Nodes whose normals all lie within this cosine of their mean axis are split in space, the
/// others by orientation (about 45°: a planar or gently curved cluster stays spatial).
pub const SPLIT_CONE_COS: f64 = std::f64::consts::FRAC_1_SQRT_2;
/// Normals this close (1 − cos) count as one direction: the node is planar-parallel.
pub const PARALLEL_TOL: f64 = 1e-12;
/// No child index: the node is a leaf.
pub const NONE: u32 = u32::MAX;

/// One cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Range of [`Tree::order`] holding this node's patches.
    pub lo: u32,
    /// End of the range (exclusive).
    pub hi: u32,
    /// Children, or [`NONE`] for a leaf.
    pub kids: [u32; 2],
    /// Total area, m².
    pub area: f64,
    /// Area-weighted centroid.
    pub centroid: DVec3,
    /// Radius of a sphere about `centroid` holding every patch.
    pub radius: f64,
    /// Axis-aligned box of the patches.
    pub lo_box: DVec3,
    /// Upper corner of the box.
    pub hi_box: DVec3,
    /// Second moment of area about `centroid`, ∫ (x − c)(x − c)ᵀ dA, m⁴ (the weights of the
    /// second-order link estimate).
    pub second_moment: DMat3,
    /// Vector area Σ A_i n_i (its projection on a direction is the projected area when every
    /// patch faces that direction).
    pub vector_area: DVec3,
    /// Unit mean normal (axis of the normal cone).
    pub axis: DVec3,
    /// Cosine of the normal cone's half-angle: min_i n_i · axis.
    pub cone_cos: f64,
    /// When every normal equals `axis` (within [`PARALLEL_TOL`]): (min, max) of axis·x over
    /// the patches' planes.
    pub planes: Option<(f64, f64)>,
    /// Smallest area of a surface with a patch in this node, m².
    pub min_surface_area: f64,
    /// The one surface of every patch in this node, or [`NONE`] for a node across surfaces.
    pub surface: u32,
}

impl Node {
    /// True for a single patch.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.kids[0] == NONE
    }

    /// Patch count.
    #[inline]
    pub fn len(&self) -> usize {
        (self.hi - self.lo) as usize
    }

    /// Never empty (every node holds a patch); for clippy's `len` rule.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.hi == self.lo
    }

    /// Index (0, 1, 2) of the longest side of the node's box.
    pub fn longest_axis(&self) -> usize {
        let ext = self.hi_box - self.lo_box;
        if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        }
    }

    /// Largest value of `dir · x` over the node's box.
    #[inline]
    pub fn support(&self, dir: DVec3) -> f64 {
        let c = 0.5 * (self.lo_box + self.hi_box);
        let h = 0.5 * (self.hi_box - self.lo_box);
        dir.dot(c) + dir.abs().dot(h)
    }
}

/// Per-patch geometry the tree and the links read.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PatchGeom {
    /// Centroid.
    pub centroid: DVec3,
    /// Unit normal.
    pub normal: DVec3,
    /// Area, m².
    pub area: f64,
    /// Second moment of area about the centroid, m⁴.
    pub second_moment: DMat3,
    /// Bounding radius about the centroid.
    pub radius: f64,
    /// Box of the vertices.
    pub lo: DVec3,
    /// Upper corner.
    pub hi: DVec3,
}

/// The cluster tree: nodes (root first) and the patch order.
#[derive(Debug, Clone, PartialEq)]
pub struct Tree {
    /// Nodes; index 0 is the root.
    pub nodes: Vec<Node>,
    /// Patch ids in tree order: node k holds `order[lo..hi]`.
    pub order: Vec<u32>,
    /// Tree node of each patch's leaf.
    pub leaf_of: Vec<u32>,
    /// Patch geometry, by patch id.
    pub geom: Vec<PatchGeom>,
}

impl Tree {
    /// Builds the tree over the patches of `scene` (at least one).
    pub fn new(scene: &Scene) -> Self {
        let geom: Vec<PatchGeom> = scene
            .patches
            .iter()
            .map(|p| {
                let poly = &p.polygon;
                let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
                for v in poly.vertices() {
                    (lo, hi) = (lo.min(*v), hi.max(*v));
                }
                PatchGeom {
                    centroid: poly.centroid(),
                    normal: poly.normal(),
                    area: poly.area(),
                    second_moment: poly.second_moment(),
                    radius: poly.bounding_radius(),
                    lo,
                    hi,
                }
            })
            .collect();
        let surface_area: Vec<f64> = {
            let mut a = vec![0.0; scene.surfaces.len()];
            for (p, g) in scene.patches.iter().zip(&geom) {
                a[p.surface] += g.area;
            }
            scene.patches.iter().map(|p| a[p.surface]).collect()
        };
        let n = geom.len();
        let surface: Vec<u32> = scene.patches.iter().map(|p| p.surface as u32).collect();
        let mut order: Vec<u32> = (0..n as u32).collect();
        let mut nodes = Vec::with_capacity(2 * n);
        let ctx = Build { geom: &geom, surface_area: &surface_area, surface: &surface };
        build(&ctx, &mut order, 0, &mut nodes);
        let mut leaf_of = vec![0u32; n];
        for (k, node) in nodes.iter().enumerate() {
            if node.is_leaf() {
                leaf_of[order[node.lo as usize] as usize] = k as u32;
            }
        }
        Tree { nodes, order, leaf_of, geom }
    }

    /// Per node: (min, max) over its patches of the leaf ranges `leaf(patch)`.
    pub fn ranges(&self, leaf: impl Fn(usize) -> (f64, f64)) -> Vec<(f64, f64)> {
        let mut out = vec![(0.0, 0.0); self.nodes.len()];
        for k in (0..self.nodes.len()).rev() {
            let n = &self.nodes[k];
            out[k] = if n.is_leaf() {
                leaf(self.order[n.lo as usize] as usize)
            } else {
                let (l, r) = (out[n.kids[0] as usize], out[n.kids[1] as usize]);
                (l.0.min(r.0), l.1.max(r.1))
            };
        }
        out
    }

    /// Patch ids of node `k`.
    #[inline]
    pub fn patches(&self, k: u32) -> &[u32] {
        let n = &self.nodes[k as usize];
        &self.order[n.lo as usize..n.hi as usize]
    }
}

/// What the recursive build reads.
struct Build<'a> {
    geom: &'a [PatchGeom],
    surface_area: &'a [f64],
    surface: &'a [u32],
}

/// Builds the node over `order[..]` (global offset `base`), pushing it and its subtree; returns
/// its index. Nodes across surfaces are split between whole surfaces first.
fn build(ctx: &Build, order: &mut [u32], base: u32, nodes: &mut Vec<Node>) -> u32 {
    let geom = ctx.geom;
    let node = summarise(ctx, order, base);
    let k = nodes.len() as u32;
    if order.len() == 1 {
        nodes.push(node);
        return k;
    }
    let mid = if node.surface == NONE {
        split_surfaces(ctx, order, &node)
    } else if node.cone_cos < SPLIT_CONE_COS {
        split_orientation(geom, order, &node).unwrap_or_else(|| split_space(geom, order, &node))
    } else {
        split_space(geom, order, &node)
    };
    nodes.push(node);
    let (left, right) = order.split_at_mut(mid);
    let l = build(ctx, left, base, nodes);
    let r = build(ctx, right, base + mid as u32, nodes);
    nodes[k as usize].kids = [l, r];
    k
}

/// Keeps surfaces whole: orders the patches by (surface centroid along the longest axis,
/// surface) and cuts at the surface boundary nearest the middle.
fn split_surfaces(ctx: &Build, order: &mut [u32], node: &Node) -> usize {
    let axis = node.longest_axis();
    let mut sums: std::collections::BTreeMap<u32, (f64, f64)> = std::collections::BTreeMap::new();
    for &p in order.iter() {
        let g = &ctx.geom[p as usize];
        let e = sums.entry(ctx.surface[p as usize]).or_insert((0.0, 0.0));
        (e.0, e.1) = (e.0 + g.area * g.centroid[axis], e.1 + g.area);
    }
    let key = |p: u32| {
        let s = ctx.surface[p as usize];
        let (m, a) = sums[&s];
        (if a > 0.0 { m / a } else { 0.0 }, s)
    };
    order.sort_by(|&a, &b| {
        let (ka, kb) = (key(a), key(b));
        ka.0.total_cmp(&kb.0).then(ka.1.cmp(&kb.1)).then(a.cmp(&b))
    });
    let n = order.len();
    let half = n / 2;
    (1..n)
        .filter(|&m| ctx.surface[order[m] as usize] != ctx.surface[order[m - 1] as usize])
        .min_by_key(|&m| m.abs_diff(half))
        .unwrap_or(half)
}

/// The node's summary without children.
fn summarise(ctx: &Build, order: &[u32], base: u32) -> Node {
    let (geom, surface_area) = (ctx.geom, ctx.surface_area);
    let first = ctx.surface[order[0] as usize];
    let surface = if order.iter().all(|&p| ctx.surface[p as usize] == first) { first } else { NONE };
    let (mut area, mut moment, mut vector_area) = (0.0, DVec3::ZERO, DVec3::ZERO);
    let (mut lo_box, mut hi_box) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    let mut min_surface_area = f64::INFINITY;
    for &p in order {
        let g = &geom[p as usize];
        area += g.area;
        moment += g.area * g.centroid;
        vector_area += g.area * g.normal;
        (lo_box, hi_box) = (lo_box.min(g.lo), hi_box.max(g.hi));
        min_surface_area = min_surface_area.min(surface_area[p as usize]);
    }
    let centroid = if area > 0.0 { moment / area } else { 0.5 * (lo_box + hi_box) };
    // Parallel axes: each patch's own moment plus its area at its centroid's offset.
    let second_moment = order.iter().fold(DMat3::ZERO, |m, &p| {
        let g = &geom[p as usize];
        let d = g.centroid - centroid;
        m + g.second_moment + outer(d) * g.area
    });
    let radius = order
        .iter()
        .map(|&p| geom[p as usize].centroid.distance(centroid) + geom[p as usize].radius)
        .fold(0.0, f64::max);
    // A closed body's vector area vanishes: any axis then serves, the cone is the sphere.
    let axis = vector_area.try_normalize().unwrap_or(geom[order[0] as usize].normal);
    let cone_cos = order.iter().map(|&p| geom[p as usize].normal.dot(axis)).fold(1.0, f64::min);
    let planes = (1.0 - cone_cos <= PARALLEL_TOL).then(|| {
        order.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &p| {
            let o = axis.dot(geom[p as usize].centroid);
            (lo.min(o), hi.max(o))
        })
    });
    Node {
        lo: base,
        hi: base + order.len() as u32,
        kids: [NONE, NONE],
        area,
        centroid,
        second_moment,
        radius,
        lo_box,
        hi_box,
        vector_area,
        axis,
        cone_cos,
        planes,
        min_surface_area,
        surface,
    }
}

/// Orders `order` by the normals' component along their widest spread and cuts at the largest
/// gap between the outer eighths; `None` when the normals do not separate.
fn split_orientation(geom: &[PatchGeom], order: &mut [u32], node: &Node) -> Option<usize> {
    let far = order
        .iter()
        .map(|&p| geom[p as usize].normal)
        .min_by(|a, b| a.dot(node.axis).total_cmp(&b.dot(node.axis)))?;
    let dir = (far - node.axis * far.dot(node.axis)).try_normalize().unwrap_or(far);
    let key = |p: u32| geom[p as usize].normal.dot(dir);
    order.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    let n = order.len();
    let (lo, hi) = ((n / 8).max(1), (n - n / 8).min(n - 1).max(1));
    let (mut best, mut gap) = (n / 2, -1.0);
    for m in lo..=hi {
        let g = key(order[m]) - key(order[m - 1]);
        if g > gap {
            (best, gap) = (m, g);
        }
    }
    (gap > 0.0).then_some(best)
}

/// Cuts at the median centroid along the longest box axis.
fn split_space(geom: &[PatchGeom], order: &mut [u32], node: &Node) -> usize {
    let axis = node.longest_axis();
    let mid = order.len() / 2;
    let key = |p: u32| geom[p as usize].centroid[axis];
    order.select_nth_unstable_by(mid, |&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    mid
}
