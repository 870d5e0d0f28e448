//! `PartSet`: which parts are present in a disassembly state (a bitset, cheap to copy and hash).

use smallvec::SmallVec;

/// A set of part indices. Inline up to 256 parts, heap beyond.
#[derive(Clone, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PartSet {
    words: SmallVec<[u64; 4]>,
}

impl PartSet {
    /// The empty set with room for `n` parts.
    pub fn empty(n: usize) -> Self {
        PartSet { words: smallvec::smallvec![0; n.div_ceil(64).max(1)] }
    }

    /// The set {0, 1, ..., n-1}.
    pub fn full(n: usize) -> Self {
        let mut s = Self::empty(n);
        for i in 0..n {
            s.insert(i);
        }
        s
    }

    /// A set of the given indices, with room for `n` parts.
    pub fn from_indices(n: usize, indices: impl IntoIterator<Item = usize>) -> Self {
        let mut s = Self::empty(n);
        for i in indices {
            s.insert(i);
        }
        s
    }

    /// The set with room for `n` parts whose bit `i` is bit `i % 64` of `words[i / 64]` (bits at
    /// or beyond `n` must be 0; missing words are 0).
    pub fn from_words(n: usize, words: &[u64]) -> Self {
        let mut s = Self::empty(n);
        let len = s.words.len().min(words.len());
        s.words[..len].copy_from_slice(&words[..len]);
        debug_assert!(words[len..].iter().all(|&w| w == 0), "bits beyond the set's room");
        s
    }

    /// The bits as 64-bit words (bit `i` is bit `i % 64` of word `i / 64`).
    pub fn words(&self) -> &[u64] {
        &self.words
    }

    fn grow(&mut self, i: usize) {
        if i / 64 >= self.words.len() {
            self.words.resize(i / 64 + 1, 0);
        }
    }

    /// Adds part `i`.
    pub fn insert(&mut self, i: usize) {
        self.grow(i);
        self.words[i / 64] |= 1 << (i % 64);
    }

    /// Removes part `i`.
    pub fn remove(&mut self, i: usize) {
        if let Some(w) = self.words.get_mut(i / 64) {
            *w &= !(1 << (i % 64));
        }
    }

    /// This set without part `i`.
    pub fn without(&self, i: usize) -> Self {
        let mut s = self.clone();
        s.remove(i);
        s
    }

    /// Whether part `i` is in the set.
    pub fn contains(&self, i: usize) -> bool {
        self.words.get(i / 64).is_some_and(|w| w & (1 << (i % 64)) != 0)
    }

    /// Number of parts in the set.
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Whether the set is empty.
    pub fn is_empty(&self) -> bool {
        self.words.iter().all(|w| *w == 0)
    }

    /// Whether the two sets share a part.
    pub fn intersects(&self, other: &PartSet) -> bool {
        self.words.iter().zip(&other.words).any(|(a, b)| a & b != 0)
    }

    /// Whether every part of `self` is in `other`.
    pub fn is_subset(&self, other: &PartSet) -> bool {
        self.words.iter().enumerate().all(|(k, a)| a & !other.words.get(k).copied().unwrap_or(0) == 0)
    }

    /// Parts in both sets.
    pub fn intersection(&self, other: &PartSet) -> PartSet {
        let mut s = self.clone();
        for (k, w) in s.words.iter_mut().enumerate() {
            *w &= other.words.get(k).copied().unwrap_or(0);
        }
        s
    }

    /// Adds every part of `other`.
    pub fn union_with(&mut self, other: &PartSet) {
        if other.words.len() > self.words.len() {
            self.words.resize(other.words.len(), 0);
        }
        for (k, w) in other.words.iter().enumerate() {
            self.words[k] |= w;
        }
    }

    /// The parts in increasing index order.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        set_bits(self.words.iter().copied())
    }

    /// The contact-graph search shared by the world's stability and the generators' check:
    /// the parts of `within` reached from this set (the seeds, kept whether or not in
    /// `within`) through `neighbours`. The result is the set of reachable parts, so it does not
    /// depend on the order of the search.
    pub fn reached_within<I: IntoIterator<Item = usize>>(&self, within: &PartSet, neighbours: impl Fn(usize) -> I) -> PartSet {
        let mut reached = self.clone();
        let mut frontier: Vec<usize> = reached.iter().collect();
        while let Some(i) = frontier.pop() {
            for j in neighbours(i) {
                if within.contains(j) && !reached.contains(j) {
                    reached.insert(j);
                    frontier.push(j);
                }
            }
        }
        reached
    }
}

/// The indices of the set bits of a bitset given as 64-bit words (word `k` holds bits
/// `64k..64k+63`), in increasing order. Shared by every bitset in asp.
pub fn set_bits(words: impl IntoIterator<Item = u64>) -> impl Iterator<Item = usize> {
    words.into_iter().enumerate().flat_map(|(k, mut w)| {
        std::iter::from_fn(move || {
            (w != 0).then(|| {
                let b = w.trailing_zeros() as usize;
                w &= w - 1;
                k * 64 + b
            })
        })
    })
}

impl std::fmt::Debug for PartSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_set().entries(self.iter()).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_operations() {
        let mut s = PartSet::full(70);
        assert_eq!(s.len(), 70);
        s.remove(3);
        s.remove(65);
        assert!(!s.contains(3) && s.contains(64) && !s.contains(65));
        let t = PartSet::from_indices(70, [3, 65, 69]);
        assert!(t.intersects(&s));
        assert_eq!(t.intersection(&s).iter().collect::<Vec<_>>(), vec![69]);
        assert!(!t.is_subset(&s));
        assert!(PartSet::from_indices(70, [69]).is_subset(&s));
        assert_eq!(PartSet::from_words(70, &[1 << 3, (1 << 1) | (1 << 5), 0]), t);
        assert_eq!(t.words(), &[1 << 3, (1 << 1) | (1 << 5)]);
        let mut u = PartSet::empty(1);
        u.union_with(&t);
        assert_eq!(u, t);
        assert_eq!(s.iter().count(), 68);
    }

    #[test]
    fn reached_within_follows_neighbours_inside_the_set_only() {
        // a chain 0-1-2-3 and 4 alone; 2 is not in `within`, so 3 is cut off from the seed 0
        let edges = [vec![1], vec![0, 2], vec![1, 3], vec![2], vec![]];
        let all = PartSet::full(5);
        let seeds = PartSet::from_indices(5, [0]);
        assert_eq!(seeds.reached_within(&all, |i| edges[i].clone()), PartSet::from_indices(5, [0, 1, 2, 3]));
        let without_2 = PartSet::from_indices(5, [0, 1, 3, 4]);
        assert_eq!(seeds.reached_within(&without_2, |i| edges[i].clone()), PartSet::from_indices(5, [0, 1]));
        // seeds outside `within` are kept
        assert_eq!(PartSet::from_indices(5, [4]).reached_within(&PartSet::empty(5), |i| edges[i].clone()), PartSet::from_indices(5, [4]));
    }
}
