//! Direction sets: [`DirMask`] (up to 256 sampled directions) and the part bitset [`Bits`].

use crate::partset::PartSet;

/// A set of sampled directions (bit `d` = direction index `d`), up to 256.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DirMask {
    words: [u64; 4],
}

impl DirMask {
    /// No direction.
    pub const EMPTY: DirMask = DirMask { words: [0; 4] };

    /// The set whose direction `64 k + b` is bit `b` of `words[k]` (the inverse of
    /// [`DirMask::words`]; e.g. a mask kept in an objective's memory words).
    pub const fn from_words(words: [u64; 4]) -> DirMask {
        DirMask { words }
    }

    /// The set as four words: direction `64 k + b` is bit `b` of word `k`.
    pub const fn words(&self) -> [u64; 4] {
        self.words
    }

    /// The directions `0..count`.
    pub fn first(count: usize) -> DirMask {
        let mut m = DirMask::EMPTY;
        for (k, w) in m.words.iter_mut().enumerate() {
            let lo = k * 64;
            if count >= lo + 64 {
                *w = u64::MAX;
            } else if count > lo {
                *w = (1u64 << (count - lo)) - 1;
            }
        }
        m
    }

    /// Adds direction `d`.
    #[inline]
    pub fn insert(&mut self, d: usize) {
        self.words[d / 64] |= 1 << (d % 64);
    }

    /// Whether direction `d` is in the set.
    #[inline]
    pub fn contains(&self, d: usize) -> bool {
        self.words[d / 64] & (1 << (d % 64)) != 0
    }

    /// Whether the set is empty.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.words == [0; 4]
    }

    /// Number of directions in the set.
    #[inline]
    pub fn len(&self) -> usize {
        self.words.iter().map(|w| w.count_ones() as usize).sum()
    }

    /// Directions in both sets.
    #[inline]
    pub fn and(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a &= b;
        }
        DirMask { words: w }
    }

    /// Directions in either set.
    #[inline]
    pub fn or(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a |= b;
        }
        DirMask { words: w }
    }

    /// Directions of `self` not in `other`.
    #[inline]
    pub fn and_not(self, other: DirMask) -> DirMask {
        let mut w = self.words;
        for (a, b) in w.iter_mut().zip(other.words) {
            *a &= !b;
        }
        DirMask { words: w }
    }

    /// The smallest direction in the set.
    #[inline]
    pub(super) fn lowest(&self) -> Option<usize> {
        self.words.iter().enumerate().find(|(_, w)| **w != 0).map(|(k, w)| k * 64 + w.trailing_zeros() as usize)
    }

    /// The directions in increasing index order.
    pub fn iter(&self) -> impl Iterator<Item = usize> + '_ {
        crate::partset::set_bits(self.words.iter().copied())
    }
}

/// A fixed-width set of part indices (up to 256) for the hot loop of [`MapState`]: the same
/// idea as [`PartSet`], without its heap fallback, so every operation is a few word operations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Bits(pub(super) [u64; 4]);

impl Bits {
    pub(super) const EMPTY: Bits = Bits([0; 4]);
    /// Every index: the key of a row not yet computed (a part never blocks itself, so no
    /// part's present blockers are all indices).
    pub(super) const NO_KEY: Bits = Bits([u64::MAX; 4]);

    /// The parts of `s` below 256.
    pub(super) fn from_set(s: &PartSet) -> Bits {
        let mut b = Bits::EMPTY;
        for (w, v) in b.0.iter_mut().zip(s.words()) {
            *w = *v;
        }
        b
    }

    pub(super) fn to_set(self, n: usize) -> PartSet {
        PartSet::from_words(n, &self.0)
    }

    #[inline]
    pub(super) fn insert(&mut self, i: usize) {
        self.0[i >> 6] |= 1 << (i & 63);
    }

    #[inline]
    pub(super) fn remove(&mut self, i: usize) {
        self.0[i >> 6] &= !(1 << (i & 63));
    }

    #[inline]
    pub(super) fn contains(&self, i: usize) -> bool {
        self.0[i >> 6] & (1 << (i & 63)) != 0
    }

    #[inline]
    pub(super) fn is_empty(&self) -> bool {
        self.0 == [0; 4]
    }

    #[inline]
    pub(super) fn len(&self) -> usize {
        self.0.iter().map(|w| w.count_ones() as usize).sum()
    }

    #[inline]
    pub(super) fn or(&self, o: &Bits) -> Bits {
        Bits([self.0[0] | o.0[0], self.0[1] | o.0[1], self.0[2] | o.0[2], self.0[3] | o.0[3]])
    }

    #[inline]
    pub(super) fn and(&self, o: &Bits) -> Bits {
        Bits([self.0[0] & o.0[0], self.0[1] & o.0[1], self.0[2] & o.0[2], self.0[3] & o.0[3]])
    }

    #[inline]
    pub(super) fn and_not(&self, o: &Bits) -> Bits {
        Bits([self.0[0] & !o.0[0], self.0[1] & !o.0[1], self.0[2] & !o.0[2], self.0[3] & !o.0[3]])
    }

    #[inline]
    pub(super) fn iter(self) -> impl Iterator<Item = usize> {
        crate::partset::set_bits(self.0)
    }
}
