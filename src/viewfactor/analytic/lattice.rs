//! Reuse across translated patch pairs.
//!
//! A surface whose patches are translates of one parallelogram laid out on a full integer
//! grid (what `subdivide` and `max_patch_size` make of a rectangle) is a *lattice*: patch
//! (x, y) = template + o + x·u + y·v. Between lattices S and T, the unobstructed pair
//! ((a, b), (c, d)) depends only on the offset Δ = o_T − o_S + c·u_T + d·v_T − a·u_S − b·v_S.
//! Where T's grid steps equal ±S's (boxes, rooms, parallel plates), Δ takes far fewer values
//! than there are pairs: the exchange area of each offset is computed once, from a fixed
//! representative pair, and looked up for every other pair with that offset.
//!
//! Detection holds to [`LATTICE_TOL`] of the grid step (grids computed in f64 are exact to
//! ~1e-15), so a looked-up value differs from a direct evaluation by the effect of that shift:
//! round-off, except for a pair sitting on a ladder rung threshold, where congruent pairs may
//! take different rungs, both within the ladder's error bound. Values are the same on any thread
//! count: the representative is fixed by the offset alone.
use crate::geometry::Polygon;
use crate::scene::Scene;
use glam::DVec3;
use rayon::prelude::*;

/// Relative tolerance (of the grid step) for "translate of the template" and "on the grid":
/// f64 grids built as o + x·u are exact to ~1e-15 of the step; f32 CAD grids (1e-7) are
/// rejected and evaluated pair by pair.
pub const LATTICE_TOL: f64 = 1e-10;
/// A table is built only when it holds at most this fraction of the pairs it serves.
const MIN_GAIN: usize = 2;
/// Total table entries over all lattice pairs (8 bytes each: 512 MB, enough for every table
/// of a 100k-patch gridded box); the tables with the largest gain are built first.
const MAX_ENTRIES: usize = 64 << 20;
/// Lattices with fewer patches are not worth a table.
const MIN_PATCHES: usize = 4;

/// A surface whose patches form a full grid of translates.
#[derive(Debug, Clone)]
struct Lattice {
    /// Grid steps u, v (the template's edges).
    basis: [DVec3; 2],
    /// Grid size along u and v.
    dims: [usize; 2],
    /// Patch at grid point (x, y): `first + grid[y·dims[0] + x]`.
    grid: Vec<u32>,
}

/// Lookup of one ordered lattice pair (S, T): entry index = `base + Σ coef·(a, b, c, d)`.
#[derive(Debug, Clone)]
struct PairTable {
    base: i64,
    coef: [i64; 4],
    values: Vec<f64>,
}

/// Lattices of a scene and the exchange-area tables between them.
#[derive(Debug, Clone, Default)]
pub struct Reuse {
    /// Per patch: (lattice id, x, y), lattice id `u32::MAX` for none.
    at: Vec<(u32, u32, u32)>,
    /// Per lattice s: (t, index into `tables`) for its tables with lattices t > s, by t.
    partners: Vec<Vec<(u32, u32)>>,
    /// The tables.
    tables: Vec<PairTable>,
    /// Table entries (unique pairs evaluated).
    entries: usize,
    /// Pairs served by the tables.
    served: u64,
}

const NONE: u32 = u32::MAX;

impl Reuse {
    /// Finds the scene's lattices and fills the tables worth having with `pair(i, j)`, the
    /// unobstructed exchange area A_i F_ij (evaluated in parallel, once per offset).
    /// `same_plane(i, j)` skips lattice pairs that lie in one plane (they exchange nothing).
    pub fn new<W: Default + Send>(
        scene: &Scene,
        same_plane: impl Fn(usize, usize) -> bool,
        pair: impl Fn(&mut W, usize, usize) -> f64 + Sync,
    ) -> Self {
        Self::with_budget(scene, MAX_ENTRIES, same_plane, pair)
    }

    /// As [`Self::new`], with at most `budget` table entries.
    fn with_budget<W: Default + Send>(
        scene: &Scene,
        budget: usize,
        same_plane: impl Fn(usize, usize) -> bool,
        pair: impl Fn(&mut W, usize, usize) -> f64 + Sync,
    ) -> Self {
        let mut at = vec![(NONE, 0, 0); scene.patches.len()];
        let mut lattices: Vec<(usize, Lattice)> = Vec::new();
        for surface in &scene.surfaces {
            let polys: Vec<&Polygon> =
                scene.patches[surface.patches.clone()].iter().map(|p| &p.polygon).collect();
            if let Some(l) = detect(&polys) {
                let id = lattices.len() as u32;
                for (k, &p) in l.grid.iter().enumerate() {
                    let (x, y) = (k % l.dims[0], k / l.dims[0]);
                    at[surface.patches.start + p as usize] = (id, x as u32, y as u32);
                }
                lattices.push((surface.patches.start, l));
            }
        }
        let count = lattices.len();
        let mut candidates = Vec::new();
        for s in 0..count {
            for t in s + 1..count {
                let ((fs, ls), (ft, lt)) = (&lattices[s], &lattices[t]);
                if same_plane(*fs + ls.grid[0] as usize, *ft + lt.grid[0] as usize) {
                    continue;
                }
                let Some(plan) = Plan::new(ls, lt) else { continue };
                let pairs = ls.grid.len() * lt.grid.len();
                if plan.size * MIN_GAIN <= pairs {
                    candidates.push((pairs, s, t, plan));
                }
            }
        }
        // Within the memory budget, the tables that save the most evaluations per entry first.
        candidates.sort_by(|x, y| {
            let (gx, gy) = (x.0 as u128 * y.3.size as u128, y.0 as u128 * x.3.size as u128);
            gy.cmp(&gx).then((x.1, x.2).cmp(&(y.1, y.2)))
        });
        let mut budget = budget;
        let mut plans = Vec::new();
        for (_, s, t, plan) in candidates {
            if plan.size <= budget {
                budget -= plan.size;
                plans.push((s, t, plan));
            }
        }
        plans.sort_by_key(|p| (p.0, p.1));
        let mut partners = vec![Vec::new(); count];
        let mut tables = Vec::with_capacity(plans.len());
        let (mut entries, mut served) = (0, 0u64);
        for (s, t, plan) in plans {
            let ((fs, ls), (ft, lt)) = (&lattices[s], &lattices[t]);
            let values: Vec<f64> = (0..plan.size)
                .into_par_iter()
                .with_min_len(64)
                .map_init(W::default, |work, k| {
                    let [a, b, c, d] = plan.representative(k);
                    let i = fs + ls.grid[b * ls.dims[0] + a] as usize;
                    let j = ft + lt.grid[d * lt.dims[0] + c] as usize;
                    pair(work, i, j)
                })
                .collect();
            entries += values.len();
            served += (ls.grid.len() * lt.grid.len()) as u64;
            partners[s].push((t as u32, tables.len() as u32));
            tables.push(PairTable { base: plan.base, coef: plan.coef, values });
        }
        Reuse { at, partners, tables, entries, served }
    }

    /// The lookup for row `i` (pairs (i, j), j > i).
    pub fn row(&self, i: usize) -> RowLookup<'_> {
        let (s, a, b) = self.at.get(i).copied().unwrap_or((NONE, 0, 0));
        let partners = self.partners.get(s as usize).map_or(&[][..], Vec::as_slice);
        RowLookup { reuse: self, partners, a, b, lattice: NONE, table: None }
    }

    /// Unique pairs evaluated for the tables, and the pairs they serve.
    pub fn stats(&self) -> (usize, u64) {
        (self.entries, self.served)
    }
}

/// Table lookups of one row, remembering the last receiving lattice (columns come in runs).
pub struct RowLookup<'r> {
    reuse: &'r Reuse,
    /// Tables of the row's lattice, by partner lattice.
    partners: &'r [(u32, u32)],
    /// The row patch's grid point.
    a: u32,
    b: u32,
    /// Last receiving lattice looked up, and its table with the row's lattice (partial index
    /// base + a, b terms folded in).
    lattice: u32,
    table: Option<(&'r PairTable, i64)>,
}

impl RowLookup<'_> {
    /// A_i F_ij from a table, when (i, j) is a lattice pair that has one.
    #[inline]
    pub fn get(&mut self, j: usize) -> Option<f64> {
        if self.partners.is_empty() {
            return None;
        }
        let (t, c, d) = self.reuse.at[j];
        if t != self.lattice {
            self.lattice = t;
            self.table = self.partners.binary_search_by_key(&t, |p| p.0).ok().map(|k| {
                let table = &self.reuse.tables[self.partners[k].1 as usize];
                (table, table.base + table.coef[0] * self.a as i64 + table.coef[1] * self.b as i64)
            });
        }
        let (table, base) = self.table?;
        let k = base + table.coef[2] * c as i64 + table.coef[3] * d as i64;
        Some(table.values[k as usize])
    }
}

/// Recognises a full grid of translates of a parallelogram template.
fn detect(polys: &[&Polygon]) -> Option<Lattice> {
    if polys.len() < MIN_PATCHES {
        return None;
    }
    let t = polys[0].vertices();
    if t.len() != 4 {
        return None;
    }
    let (u, v) = (t[1] - t[0], t[3] - t[0]);
    let step = u.length().min(v.length());
    let tol = LATTICE_TOL * u.length().max(v.length());
    if (t[2] - t[1] - v).length() > tol || !(step > 0.0) {
        return None;
    }
    // Grid coordinates from the dual basis of (u, v) in their plane.
    let n = u.cross(v);
    let nn = n.length_squared();
    let mut coords = Vec::with_capacity(polys.len());
    for p in polys {
        let w = p.vertices();
        if w.len() != 4 || w.iter().zip(t).any(|(q, r)| (*q - w[0] - (*r - t[0])).length() > tol) {
            return None;
        }
        let rel = w[0] - t[0];
        let (x, y) = (rel.cross(v).dot(n) / nn, u.cross(rel).dot(n) / nn);
        let (xr, yr) = (x.round(), y.round());
        if (rel - xr * u - yr * v).length() > tol || xr.abs() > 1e6 || yr.abs() > 1e6 {
            return None;
        }
        coords.push((xr as i64, yr as i64));
    }
    let (x0, y0) = coords.iter().fold((i64::MAX, i64::MAX), |(x, y), c| (x.min(c.0), y.min(c.1)));
    let (x1, y1) = coords.iter().fold((i64::MIN, i64::MIN), |(x, y), c| (x.max(c.0), y.max(c.1)));
    let dims = [(x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize];
    if dims[0] * dims[1] != polys.len() {
        return None;
    }
    let mut grid = vec![NONE; polys.len()];
    for (k, &(x, y)) in coords.iter().enumerate() {
        let cell = &mut grid[(y - y0) as usize * dims[0] + (x - x0) as usize];
        if *cell != NONE {
            return None;
        }
        *cell = k as u32;
    }
    Some(Lattice { basis: [u, v], dims, grid })
}

/// The offset key of a lattice pair: per S axis s, k_s = −x_s (+ σ·y_t when T's axis t steps
/// by σ·S's axis s); per unmatched T axis, y_t itself.
#[derive(Debug, Clone)]
struct Plan {
    /// T axis matched to each S axis, with its sign.
    matched: [Option<(usize, i64)>; 2],
    /// T axes not matched (their coordinates are key components).
    free: Vec<usize>,
    /// Per key component: lowest value and count; S axes first, then the free T axes.
    ranges: Vec<(i64, usize)>,
    dims_s: [usize; 2],
    dims_t: [usize; 2],
    size: usize,
    base: i64,
    coef: [i64; 4],
}

impl Plan {
    /// The key of (S, T) when at least one of T's steps is ± one of S's.
    fn new(s: &Lattice, t: &Lattice) -> Option<Self> {
        let tol = LATTICE_TOL * s.basis[0].length().max(s.basis[1].length());
        let mut matched = [None; 2];
        let mut free = Vec::new();
        for (ta, w) in t.basis.iter().enumerate() {
            let hit = (0..2).find_map(|sa| {
                [1i64, -1]
                    .into_iter()
                    .find(|&sg| (*w - sg as f64 * s.basis[sa]).length() <= tol)
                    .map(|sg| (sa, sg))
            });
            match hit {
                Some((sa, sg)) if matched[sa].is_none() => matched[sa] = Some((ta, sg)),
                _ => free.push(ta),
            }
        }
        if free.len() == 2 {
            return None;
        }
        let (ds, dt) = (s.dims, t.dims);
        let mut ranges = Vec::new();
        for sa in 0..2 {
            let lo = -(ds[sa] as i64 - 1);
            ranges.push(match matched[sa] {
                None => (lo, ds[sa]),
                Some((ta, 1)) => (lo, ds[sa] + dt[ta] - 1),
                Some((ta, _)) => (lo - (dt[ta] as i64 - 1), ds[sa] + dt[ta] - 1),
            });
        }
        for &ta in &free {
            ranges.push((0, dt[ta]));
        }
        let size = ranges.iter().map(|r| r.1).product();
        // Row-major strides, last component fastest.
        let mut stride = vec![0i64; ranges.len()];
        let mut acc = 1i64;
        for k in (0..ranges.len()).rev() {
            stride[k] = acc;
            acc *= ranges[k].1 as i64;
        }
        // index = Σ stride_k (comp_k − lo_k); comp_k is linear in (a, b, c, d).
        let mut coef = [0i64; 4];
        let mut base = 0i64;
        for sa in 0..2 {
            coef[sa] -= stride[sa];
            if let Some((ta, sg)) = matched[sa] {
                coef[2 + ta] += sg * stride[sa];
            }
            base -= stride[sa] * ranges[sa].0;
        }
        for (k, &ta) in free.iter().enumerate() {
            coef[2 + ta] += stride[2 + k];
        }
        Some(Plan { matched, free, ranges, dims_s: ds, dims_t: dt, size, base, coef })
    }

    /// A fixed pair (a, b, c, d) with key number `k` (the smallest matched T coordinate).
    fn representative(&self, mut k: usize) -> [usize; 4] {
        let mut comp = vec![0i64; self.ranges.len()];
        for (slot, &(lo, n)) in comp.iter_mut().zip(&self.ranges).rev() {
            *slot = lo + (k % n) as i64;
            k /= n;
        }
        let mut st = [0usize; 4];
        for sa in 0..2 {
            let ks = comp[sa];
            match self.matched[sa] {
                None => st[sa] = (-ks) as usize,
                Some((ta, 1)) => {
                    let y = ks.max(0);
                    st[2 + ta] = y as usize;
                    st[sa] = (y - ks) as usize;
                }
                Some((ta, _)) => {
                    let y = (-ks - self.dims_s[sa] as i64 + 1).max(0);
                    st[2 + ta] = y as usize;
                    st[sa] = (-y - ks) as usize;
                }
            }
        }
        for (k, &ta) in self.free.iter().enumerate() {
            st[2 + ta] = comp[2 + k] as usize;
        }
        debug_assert!(st[0] < self.dims_s[0] && st[1] < self.dims_s[1]);
        debug_assert!(st[2] < self.dims_t[0] && st[3] < self.dims_t[1]);
        st
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::subdivide::parallelogram_grid;

    fn grid(o: DVec3, u: DVec3, v: DVec3, n: usize, m: usize) -> Vec<Polygon> {
        parallelogram_grid(o, u * n as f64, v * m as f64, n, m).unwrap()
    }

    #[test]
    fn a_subdivided_parallelogram_is_a_lattice_in_any_order() {
        let (u, v) = (DVec3::new(0.3, 0.1, 0.0), DVec3::new(-0.05, 0.2, 0.4));
        let mut polys = grid(DVec3::new(5.0, -2.0, 1.0), u, v, 5, 3);
        polys.reverse();
        polys.swap(2, 9);
        let refs: Vec<&Polygon> = polys.iter().collect();
        let l = detect(&refs).expect("a full grid of translates");
        assert_eq!(l.dims, [5, 3]);
        // Grid point (x, y) holds the patch whose first vertex is o + x·u + y·v from the corner.
        let corner = polys[l.grid[0] as usize].vertices()[0];
        for y in 0..3 {
            for x in 0..5 {
                let p = polys[l.grid[y * 5 + x] as usize].vertices()[0];
                assert!((p - corner - (x as f64 * l.basis[0] + y as f64 * l.basis[1])).length() < 1e-14);
            }
        }
    }

    #[test]
    fn grids_that_are_not_exact_lattices_are_refused() {
        let (u, v) = (DVec3::X * 0.25, DVec3::Y * 0.5);
        let base = grid(DVec3::ZERO, u, v, 4, 3);
        let refs = |p: &[Polygon]| detect(&p.iter().collect::<Vec<_>>()).is_some();
        assert!(refs(&base));
        // One patch moved by 1e-7 of its size (f32 CAD round-off): not a translate within tolerance.
        let mut moved = base.clone();
        let w: Vec<DVec3> = moved[5].vertices().iter().map(|p| *p + DVec3::X * 2.5e-8).collect();
        moved[5] = Polygon::new(w).unwrap();
        assert!(!refs(&moved), "a shifted patch");
        // A missing patch: not a full grid.
        assert!(!refs(&base[..11]), "a missing patch");
        // A repeated patch in place of another.
        let mut twice = base.clone();
        twice[3] = twice[2].clone();
        assert!(!refs(&twice), "two patches on one grid point");
        // Trapezoids (not parallelograms), and triangles.
        let trap: Vec<Polygon> = (0..4)
            .map(|k| {
                let o = DVec3::X * k as f64;
                Polygon::new(vec![
                    o,
                    o + DVec3::X,
                    o + DVec3::new(0.8, 1.0, 0.0),
                    o + DVec3::new(0.2, 1.0, 0.0),
                ])
                .unwrap()
            })
            .collect();
        assert!(!refs(&trap), "trapezoids");
        let tri: Vec<Polygon> = (0..4)
            .map(|k| {
                let o = DVec3::X * k as f64;
                Polygon::new(vec![o, o + DVec3::X, o + DVec3::Y]).unwrap()
            })
            .collect();
        assert!(!refs(&tri), "triangles");
        // Too few patches to be worth a table.
        assert!(!refs(&base[..3]));
    }

    /// The closed box [0,2]×[0,1]×[0,1.5] with faces split into 0.25 m squares (grid steps of
    /// mixed signs and orders; 8, 4 and 6 patches along x, y and z).
    fn gridded_box() -> Scene {
        let (x, y, z) = (DVec3::X * 2.0, DVec3::Y, DVec3::Z * 1.5);
        let faces =
            [(DVec3::ZERO, x, y), (z, y, x), (DVec3::ZERO, y, z), (x, z, y), (DVec3::ZERO, z, x), (y, x, z)];
        let mut s = Scene::builder();
        for (k, (o, u, v)) in faces.into_iter().enumerate() {
            let (nu, nv) = ((u.length() * 4.0) as usize, (v.length() * 4.0) as usize);
            s = s.surface(&format!("f{k}"), parallelogram_grid(o, u, v, nu, nv).unwrap(), 1.0, None);
        }
        s.build()
    }

    /// Every served pair gets the value of a pair between the same two surfaces with the same
    /// offset; the budget keeps the tables of largest gain.
    #[test]
    fn lookups_return_a_congruent_pair_and_the_budget_keeps_the_best_tables() {
        let scene = gridded_box();
        let n = scene.patches.len();
        let same_plane = |i: usize, j: usize| scene.patches[i].surface == scene.patches[j].surface;
        // The "exchange area" of the representative pair encodes it: i·n + j.
        let encode = |_: &mut (), i: usize, j: usize| (i * n + j) as f64;
        let centroid = |p: usize| scene.patches[p].polygon.centroid();
        for budget in [MAX_ENTRIES, 165, 164, 0] {
            let reuse = Reuse::with_budget(&scene, budget, same_plane, encode);
            let mut served = 0u64;
            for i in 0..n {
                let mut row = reuse.row(i);
                for j in i + 1..n {
                    let Some(v) = row.get(j) else { continue };
                    served += 1;
                    let (i0, j0) = (v as usize / n, v as usize % n);
                    assert_eq!(scene.patches[i0].surface, scene.patches[i].surface);
                    assert_eq!(scene.patches[j0].surface, scene.patches[j].surface);
                    let (d, d0) = (centroid(j) - centroid(i), centroid(j0) - centroid(i0));
                    assert!((d - d0).length() < 1e-14, "pair ({i}, {j}) served by ({i0}, {j0})");
                }
            }
            assert_eq!(served, reuse.stats().1, "budget {budget}");
            match budget {
                // All 15 face pairs are worth a table (gain ≥ 2.29): every cross-face pair,
                // ((Σ faces)² − Σ faces²)/2 with faces of 32, 32, 24, 24, 48 and 48 patches.
                MAX_ENTRIES => assert_eq!(served, 17_728),
                // Room for one table: south–north, the largest gain (2,304 pairs from 11·15 offsets).
                165 => assert_eq!(reuse.stats(), (165, 2_304)),
                // One short of it: the next best that fits, floor–ceiling (1,024 pairs, 7·15).
                164 => assert_eq!(reuse.stats(), (105, 1_024)),
                _ => assert_eq!(served, 0),
            }
        }
    }

    /// Every (a, b, c, d) of a plan maps into the table; two pairs share an entry exactly when
    /// their offsets Δ are equal; the representative of each entry maps back to it.
    #[test]
    fn the_table_index_is_a_bijection_onto_offsets() {
        // Exactly representable steps, so equal offsets compare equal in floating point.
        let (x, y, z) = (DVec3::X * 0.5, DVec3::Y * 0.25, DVec3::Z * 0.125);
        let s = detect(&grid(DVec3::ZERO, x, y, 4, 3).iter().collect::<Vec<_>>()).unwrap();
        let t_bases = [(x, y), (y, x), (-x, y), (y, -x), (-y, -x), (x, z), (z, -y), (-x, z), (z, y)];
        for (k, &(tu, tv)) in t_bases.iter().enumerate() {
            for dims in [(2usize, 5usize), (3, 1), (4, 4)] {
                let o = DVec3::new(3.0, 2.0, 1.0);
                let polys = grid(o, tu, tv, dims.0, dims.1);
                if polys.len() < MIN_PATCHES {
                    continue;
                }
                let t = detect(&polys.iter().collect::<Vec<_>>()).unwrap();
                let plan = Plan::new(&s, &t).expect("T shares a step with S");
                let index =
                    |q: [usize; 4]| plan.base + (0..4).map(|m| plan.coef[m] * q[m] as i64).sum::<i64>();
                let offset = |q: [usize; 4]| {
                    t.basis[0] * q[2] as f64 + t.basis[1] * q[3] as f64
                        - s.basis[0] * q[0] as f64
                        - s.basis[1] * q[1] as f64
                };
                let mut seen: Vec<Option<DVec3>> = vec![None; plan.size];
                for q in (0..s.dims[0] * s.dims[1] * t.dims[0] * t.dims[1]).map(|mut r| {
                    let mut q = [0; 4];
                    for (m, n) in [s.dims[0], s.dims[1], t.dims[0], t.dims[1]].into_iter().enumerate() {
                        q[m] = r % n;
                        r /= n;
                    }
                    q
                }) {
                    let i = index(q);
                    assert!((0..plan.size as i64).contains(&i), "basis {k} dims {dims:?}: {q:?} → {i}");
                    let slot = &mut seen[i as usize];
                    match slot {
                        Some(d) => {
                            assert_eq!(*d, offset(q), "basis {k}: {q:?} shares entry {i} with another offset")
                        }
                        None => *slot = Some(offset(q)),
                    }
                }
                let mut distinct: Vec<[i64; 3]> =
                    seen.iter().flatten().map(|d| [d.x, d.y, d.z].map(|c| (c * 64.0) as i64)).collect();
                let used = distinct.len();
                distinct.sort_unstable();
                distinct.dedup();
                assert_eq!(distinct.len(), used, "basis {k}: two entries with one offset");
                for e in 0..plan.size {
                    let q = plan.representative(e);
                    assert!(q[0] < s.dims[0] && q[1] < s.dims[1] && q[2] < t.dims[0] && q[3] < t.dims[1]);
                    assert_eq!(index(q), e as i64, "basis {k} dims {dims:?}");
                }
            }
        }
        // No shared step: no plan.
        let (p, q) = (DVec3::new(0.5, 0.5, 0.0), DVec3::new(0.0, 0.5, 0.5));
        let t = detect(&grid(DVec3::Z, p, q, 2, 2).iter().collect::<Vec<_>>()).unwrap();
        assert!(Plan::new(&s, &t).is_none());
    }
}
