//! The input overlaps, the world's third component: the pairs of parts that overlap in the
//! input beyond the tolerance, how deep and how they lie ([`OverlapNote`]), what the policy makes
//! of each (shrink one part by the pair's erosion, test it by the strict sample rule, ignore it),
//! the parts drawn as one component of several solids, and the fits, threads and bearings the
//! world found among the parts in contact ([`Fits`]: they say which overlaps are meant).
//!
//! The component holds decisions, not geometry: the pair tests read these answers together with
//! the shapes ([`super::Pairs`]), so the overlap policy is decided once, when the world is
//! measured, and a lenient copy of the world differs from the strict one here alone.

use super::fits::Fits;
use super::shapes::Shapes;
use crate::math::Vec3;
use crate::overlap::{OverlapHandling, OverlapNote, OverlapPolicy};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

/// The overlapping pairs and what the policy does with them.
pub struct Overlaps {
    /// Unordered pair (low, high) → (the part shrunk in their tests, its extra erosion).
    pub(super) pairs: BTreeMap<(usize, usize), (usize, f32)>,
    pub(super) ignored: BTreeSet<(usize, usize)>,
    /// Ordered pairs (both orders) tested by the strict overlap rule.
    pub(super) strict: BTreeSet<(usize, usize)>,
    /// Per ordered strict pair `(p, q)` that no shrinking separates (tested by the strict rule
    /// alone): `p`'s samples for their strict test, its whole-surface samples and dense ones near
    /// `q` (made the first time the pair is tested).
    pub(super) strict_samples: BTreeMap<(usize, usize), OnceLock<Vec<Vec3>>>,
    pub(super) notes: Vec<OverlapNote>,
    pub(super) policy: OverlapPolicy,
    pub(super) tolerance: f32,
    /// The groups of parts drawn as one component ([`Overlaps::fused_components`]).
    pub(super) fused: Vec<Vec<usize>>,
    pub(super) fits: Fits,
}

impl Overlaps {
    /// No overlaps yet, under `policy`, for parts shrunk by `tolerance` in their tests.
    pub(super) fn new(policy: OverlapPolicy, tolerance: f32, parts: usize) -> Overlaps {
        Overlaps {
            pairs: BTreeMap::new(),
            ignored: BTreeSet::new(),
            strict: BTreeSet::new(),
            strict_samples: BTreeMap::new(),
            notes: Vec::new(),
            policy,
            tolerance,
            fused: Vec::new(),
            fits: Fits::new(parts),
        }
    }

    /// These overlaps under the lenient policy: a pair some shrinking separates is shrunk, a
    /// gross pair ignores their collisions (strict tests it by its rule).
    pub(super) fn lenient(&self) -> Overlaps {
        let notes = self
            .notes
            .iter()
            .map(|n| OverlapNote { handling: if n.gross { OverlapHandling::Ignored } else { OverlapHandling::Shrunk }, ..n.clone() })
            .collect();
        Overlaps {
            pairs: self.pairs.clone(),
            // gross pairs ignore each other under both policies (strict tests them by its rule)
            ignored: self.notes.iter().filter(|n| n.gross).flat_map(|n| [n.parts, (n.parts.1, n.parts.0)]).collect(),
            strict: BTreeSet::new(),
            strict_samples: BTreeMap::new(),
            notes,
            policy: OverlapPolicy::Lenient,
            tolerance: self.tolerance,
            fused: self.fused.clone(),
            fits: self.fits.share(),
        }
    }

    /// Pairs (low index, high index) that overlap in the input, with the part their tests shrink
    /// and its extra erosion in metres.
    pub fn pairs(&self) -> &BTreeMap<(usize, usize), (usize, f32)> {
        &self.pairs
    }

    /// Every pair that overlaps in the input beyond the tolerance: how they lie, the measured
    /// depth and how their tests treat them (one entry per pair, in pair order).
    pub fn notes(&self) -> &[OverlapNote] {
        &self.notes
    }

    /// The overlap policy the world was built with.
    pub fn policy(&self) -> OverlapPolicy {
        self.policy
    }

    /// Whether the pair (`p`, `q`) is tested by the strict overlap rule (it overlaps in the input
    /// and the policy is strict).
    pub fn is_strict(&self, p: usize, q: usize) -> bool {
        self.strict.contains(&(p, q))
    }

    /// Whether collisions between `p` and `q` are ignored by the shrunk tests (a pair no
    /// shrinking separates, under the lenient policy; under the strict one such a pair is tested
    /// by the strict rule alone).
    pub fn ignores(&self, p: usize, q: usize) -> bool {
        self.ignored.contains(&(p, q))
    }

    /// Which part the tests of the pair (`p`, `q`) shrink, and by how much (metres): normally the
    /// moving part `p` by the tolerance; for parts overlapping in the input, the one that
    /// separates with the least shrinking, by the tolerance plus that.
    pub fn erosion(&self, p: usize, q: usize) -> (usize, f32) {
        match self.pairs.get(&(p.min(q), p.max(q))) {
            Some(&(k, extra)) => (k, self.tolerance + extra),
            None => (p, self.tolerance),
        }
    }

    /// The groups of parts drawn as one component of several interpenetrating solids (two
    /// parts of one product of the file's tree whose overlap is interpenetration, linked
    /// pairwise; a bearing's parts never), each ascending, in the order of their first part.
    pub fn fused_components(&self) -> &[Vec<usize>] {
        &self.fused
    }

    /// The fits, threads and bearings among the parts in contact.
    pub fn fits(&self) -> &Fits {
        &self.fits
    }

    /// Part `p`'s samples for its strict test with `q`: its whole-surface samples (about
    /// [`super::shapes::STRICT_SAMPLES`], spread over the whole part: centimetres apart on a
    /// large panel, where a dowel drawn into it could slide sideways between them), and, when no
    /// shrinking separates the pair (so no shrunk sweep guards it), its surface near `q`
    /// sampled densely.
    pub(super) fn strict_pair_samples<'a>(&'a self, shapes: &'a Shapes, p: usize, q: usize) -> &'a [Vec3] {
        let Some(cell) = self.strict_samples.get(&(p, q)) else { return shapes.strict_samples(p) };
        cell.get_or_init(|| shapes.dense_samples(p, q))
    }

    /// Part `p`'s samples for its fit tests with `q`: its whole-surface samples and dense ones
    /// near `q` (made once per pair); a pair without fit samples uses its strict ones.
    pub(super) fn fit_pair_samples<'a>(&'a self, shapes: &'a Shapes, p: usize, q: usize) -> &'a [Vec3] {
        let Some(cell) = self.fits.samples.get(&(p, q)) else { return self.strict_pair_samples(shapes, p, q) };
        cell.get_or_init(|| shapes.dense_samples(p, q))
    }

    /// The shrunk meshes the removal tests will ask for, as (part, amount bits): each mesh part
    /// by the tolerance, and the part an overlapping pair's tests shrink by the pair's erosion.
    pub(super) fn wanted_erosions(&self, shapes: &Shapes, parts: usize) -> BTreeSet<(usize, u32)> {
        let mut wanted: BTreeSet<(usize, u32)> = BTreeSet::new();
        for i in (0..parts).filter(|&i| shapes.boxes(i).is_none()) {
            wanted.insert((i, self.tolerance.to_bits()));
        }
        for &(k, extra) in self.pairs.values() {
            wanted.insert((k, (self.tolerance + extra).to_bits()));
        }
        wanted
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::overlap::{OverlapClass, OverlapKind};

    fn note(parts: (usize, usize), gross: bool, handling: OverlapHandling) -> OverlapNote {
        let class = OverlapClass::Interpenetration;
        OverlapNote { parts, kind: OverlapKind::Crossing, depth: 0.1, gross, bound: false, handling, class, normal: None }
    }

    /// A strict world with a shallow pair (0, 1), shrinking 1, and a gross pair (1, 2).
    fn strict() -> Overlaps {
        let mut o = Overlaps::new(OverlapPolicy::Strict, 0.25, 3);
        o.pairs.insert((0, 1), (1, 0.5));
        o.notes.push(note((0, 1), false, OverlapHandling::Strict));
        o.notes.push(note((1, 2), true, OverlapHandling::Strict));
        o.strict.extend([(0, 1), (1, 0), (1, 2), (2, 1)]);
        o.ignored.extend([(1, 2), (2, 1)]);
        o
    }

    #[test]
    fn a_pair_shrinks_the_part_measured_to_separate_by_the_tolerance_and_its_depth() {
        let o = strict();
        assert_eq!(o.erosion(0, 1), (1, 0.75));
        assert_eq!(o.erosion(1, 0), (1, 0.75));
        // no overlap: the moving part by the tolerance
        assert_eq!(o.erosion(2, 0), (2, 0.25));
        assert!(o.is_strict(0, 1) && o.is_strict(2, 1) && !o.is_strict(0, 2));
    }

    #[test]
    fn the_lenient_copy_shrinks_shallow_pairs_and_ignores_gross_ones() {
        let o = strict().lenient();
        assert_eq!(o.policy(), OverlapPolicy::Lenient);
        assert!(!o.is_strict(0, 1) && !o.is_strict(1, 2));
        assert!(o.ignores(1, 2) && o.ignores(2, 1) && !o.ignores(0, 1));
        let handling: Vec<OverlapHandling> = o.notes().iter().map(|n| n.handling).collect();
        assert_eq!(handling, [OverlapHandling::Shrunk, OverlapHandling::Ignored]);
        assert_eq!(o.erosion(0, 1), (1, 0.75));
    }
}
