//! Disjoint groups of the indices 0..n, joined pair by pair (union–find with path halving); the
//! root of a group is its smallest member, so labels do not depend on the order of the joins.

/// Disjoint groups of 0..n; the root of a group is its smallest member.
#[derive(Debug, Clone)]
pub(crate) struct Groups(Vec<usize>);

impl Groups {
    /// n groups of one.
    pub(crate) fn new(n: usize) -> Self {
        Self((0..n).collect())
    }
    /// The smallest member of x's group.
    pub(crate) fn root(&mut self, mut x: usize) -> usize {
        let p = &mut self.0;
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    /// Puts u and v in one group.
    pub(crate) fn join(&mut self, u: usize, v: usize) {
        let (a, b) = (self.root(u), self.root(v));
        self.0[a.max(b)] = a.min(b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_join_pairs_and_root_at_their_smallest_member() {
        let mut g = Groups::new(6);
        g.join(4, 2);
        g.join(5, 4);
        g.join(3, 1);
        assert_eq!((0..6).map(|u| g.root(u)).collect::<Vec<_>>(), [0, 1, 2, 1, 2, 2]);
        g.join(5, 3);
        assert_eq!((0..6).map(|u| g.root(u)).collect::<Vec<_>>(), [0, 1, 1, 1, 1, 1]);
    }
}
