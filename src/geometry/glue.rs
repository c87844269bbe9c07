//! Gluing the convex pieces of one grid cell back into as few simple rings as possible
//! (used by [`super::grid_clip`]): shared edges cancel exactly, the remaining boundary is
//! traced into rings.
use std::collections::HashMap;

/// A 2-D point in a polygon's plane frame.
pub(super) type P = [f64; 2];

/// Twice the signed area of a 2-D ring.
pub(super) fn area2(r: &[P]) -> f64 {
    (0..r.len())
        .map(|k| {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum()
}

/// The rings of one glued group (`None` when tracing failed), and the convex pieces it was
/// glued from.
pub(super) type Group = (Option<Vec<Vec<P>>>, Vec<Vec<P>>);

/// Relative mismatch between a glued group's ring area and its pieces' area that sends the
/// group back to its pieces (gluing only reorders exact points, so it is round-off).
const GLUE_AREA_TOL: f64 = 1e-13;

/// Glues the pieces of one cell along exactly shared edges (O(E log E)): opposite directed
/// edges cancel, pieces that share one form a group (union–find), and each group's remaining
/// edges are traced into rings, turning as far left as possible at a vertex with several
/// exits, so pieces that only touch at a vertex become separate simple rings. Returns each
/// group's rings with the pieces it came from.
pub(super) fn glue_all(pieces: Vec<Vec<P>>) -> Vec<Group> {
    let mut parent: Vec<usize> = (0..pieces.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    // Directed edges by (from, to); an edge whose reverse exists is interior.
    let mut edges: HashMap<(Key, Key), (usize, P, P)> = HashMap::new();
    for (i, r) in pieces.iter().enumerate() {
        for k in 0..r.len() {
            let (a, b) = (r[k], r[(k + 1) % r.len()]);
            edges.insert((key(a), key(b)), (i, a, b));
        }
    }
    let mut boundary: Vec<(usize, P, P)> = Vec::new();
    for (&(ka, kb), &(i, a, b)) in &edges {
        match edges.get(&(kb, ka)) {
            Some(&(j, ..)) => {
                let (ri, rj) = (find(&mut parent, i), find(&mut parent, j));
                parent[ri] = rj;
            }
            None => boundary.push((i, a, b)),
        }
    }
    // Deterministic order (the map's iteration order is not).
    boundary.sort_by_key(|x| (x.0, key(x.1), key(x.2)));
    let roots: Vec<usize> = (0..pieces.len()).map(|i| find(&mut parent, i)).collect();
    // Per union–find root: its boundary edges and its pieces.
    type Members = (Vec<(P, P)>, Vec<usize>);
    let mut groups: HashMap<usize, Members> = HashMap::new();
    for (i, &root) in roots.iter().enumerate() {
        groups.entry(root).or_default().1.push(i);
    }
    for &(i, a, b) in &boundary {
        groups.entry(roots[i]).or_default().0.push((a, b));
    }
    // Groups in the order of their first piece: root ids depend on the map's union order.
    let mut order: Vec<usize> = Vec::new();
    for &root in &roots {
        if !order.contains(&root) {
            order.push(root);
        }
    }
    order
        .into_iter()
        .map(|root| {
            let (edges, members) = groups.remove(&root).unwrap_or_default();
            let parts: Vec<Vec<P>> = members.into_iter().map(|i| pieces[i].clone()).collect();
            let whole: f64 = parts.iter().map(|r| area2(r)).sum();
            let rings = trace(&edges)
                .map(|rs| rs.into_iter().map(clean).filter(|r| r.len() >= 3).collect::<Vec<_>>())
                .filter(|rs| {
                    (rs.iter().map(|r| area2(r)).sum::<f64>() - whole).abs() <= GLUE_AREA_TOL * whole
                });
            (rings, parts)
        })
        .collect()
}

/// Bit pattern of a point, for exact matching.
type Key = (u64, u64);

fn key(p: P) -> Key {
    (p[0].to_bits(), p[1].to_bits())
}

/// Traces directed boundary edges into closed rings, taking the leftmost exit at vertices
/// with several; `None` if a chain does not close.
fn trace(edges: &[(P, P)]) -> Option<Vec<Vec<P>>> {
    let mut out_of: HashMap<Key, Vec<usize>> = HashMap::new();
    for (k, (a, _)) in edges.iter().enumerate() {
        out_of.entry(key(*a)).or_default().push(k);
    }
    let mut used = vec![false; edges.len()];
    let mut rings = Vec::new();
    for start in 0..edges.len() {
        if used[start] {
            continue;
        }
        let mut ring = Vec::new();
        let mut e = start;
        loop {
            used[e] = true;
            let (a, b) = edges[e];
            ring.push(a);
            let d_in = [b[0] - a[0], b[1] - a[1]];
            let turn = |c: usize| {
                let w = edges[c].1;
                let d = [w[0] - b[0], w[1] - b[1]];
                (d_in[0] * d[1] - d_in[1] * d[0]).atan2(d_in[0] * d[0] + d_in[1] * d[1])
            };
            let next = out_of.get(&key(b)).and_then(|cands| {
                cands.iter().copied().filter(|&c| !used[c]).max_by(|&x, &y| turn(x).total_cmp(&turn(y)))
            });
            match next {
                Some(n) => e = n,
                None if b == ring[0] => break,
                None => return None,
            }
        }
        rings.push(ring);
    }
    Some(rings)
}

/// Removes duplicates, spikes (x, y, x) and points strictly inside an axis-parallel straight
/// run (left where glued edges met a cell line), until nothing changes.
fn clean(mut r: Vec<P>) -> Vec<P> {
    loop {
        let n = r.len();
        if n < 3 {
            return r;
        }
        let mut removed = false;
        for k in 0..n {
            let (a, b, c) = (r[(k + n - 1) % n], r[k], r[(k + 1) % n]);
            if a == b {
                r.remove(k);
                removed = true;
                break;
            }
            if a == c {
                // Spike a → b → a: drop b and the repeated a.
                let (hi, lo) = (k.max((k + 1) % n), k.min((k + 1) % n));
                r.remove(hi);
                r.remove(lo);
                removed = true;
                break;
            }
            let between = |ax: usize| {
                a[ax] == b[ax] && b[ax] == c[ax] && {
                    let o = 1 - ax;
                    (a[o] < b[o] && b[o] < c[o]) || (a[o] > b[o] && b[o] > c[o])
                }
            };
            if between(0) || between(1) {
                r.remove(k);
                removed = true;
                break;
            }
        }
        if !removed {
            return r;
        }
    }
}
