//! [`MapState`]: a disassembly state over the maps, updated incrementally as parts leave.

use super::*;
use crate::feasibility::Stability;
use crate::partset::PartSet;

/// Values per block of [`min_rows`]: 32 floats are eight SSE (or four AVX) registers, so the
/// running minimum of a block stays in registers while the rows stream past.
const MIN_BLOCK: usize = 32;

/// `out = min(init, rows...)` elementwise, where the rows are `values[r * s..(r + 1) * s]`
/// for each row index `r` and the stride `s = out.len()`, and the sum of `out` in f64 (over eight interleaved lanes: element `k` goes
/// to lane `k % 8`, the lanes are added in order at the end). `out.len()` (the stride) is a
/// multiple of 8. Blocks of [`MIN_BLOCK`] values are finished one at a time, in order: the
/// minimum is exact, so the order of the rows does not matter.
fn min_rows(values: &[f32], rows: &[usize], init: &[f32], out: &mut [f32]) -> f64 {
    let stride = out.len();
    let mut lanes = [0.0f64; 8];
    let mut at = 0;
    while at + MIN_BLOCK <= stride {
        min_block::<MIN_BLOCK>(values, rows, init, out, at, &mut lanes);
        at += MIN_BLOCK;
    }
    match stride - at {
        0 => {}
        8 => min_block::<8>(values, rows, init, out, at, &mut lanes),
        16 => min_block::<16>(values, rows, init, out, at, &mut lanes),
        24 => min_block::<24>(values, rows, init, out, at, &mut lanes),
        r => unreachable!("the stride is a multiple of 8, {r} values left"),
    }
    lanes.iter().sum()
}

#[inline(always)]
fn min_block<const W: usize>(values: &[f32], rows: &[usize], init: &[f32], out: &mut [f32], at: usize, lanes: &mut [f64; 8]) {
    let stride = out.len();
    let mut acc: [f32; W] = init[at..at + W].try_into().expect("W values");
    for &r in rows {
        let o = r * stride + at;
        let row: &[f32; W] = values[o..o + W].try_into().expect("W values");
        for (a, b) in acc.iter_mut().zip(row) {
            // a select, which vectorises to a packed minimum
            *a = if *b < *a { *b } else { *a };
        }
    }
    for chunk in acc.chunks_exact(8) {
        for (l, v) in lanes.iter_mut().zip(chunk) {
            *l += *v as f64;
        }
    }
    out[at..at + W].copy_from_slice(&acc);
}

/// A disassembly state over the distance maps, updated incrementally as parts leave: which
/// parts are present, which are collision-free (monotone: removals only free parts), the
/// minimum maps `M̄(p_i, s)`, and for the [`Support::Below`] rule how many present supports each
/// part has left.
///
/// A minimum map depends only on which of the part's blockers are present, so each computed
/// row is kept with that set as its key and reused — after later removals and across
/// [`MapState::reset`]s — while the part's present blockers are the same.
///
/// [`Clone::clone_from`] reuses the target's buffers and copies only the kept minimum maps
/// whose keys differ (a row is a function of its key), so copying a state each step of a local
/// search allocates nothing.
#[derive(Debug)]
pub struct MapState<'m> {
    maps: &'m DistanceMaps,
    all: DirMask,
    present: Bits,
    free: Bits,
    unchecked: Bits,
    /// Per part: its minimum map (padded to the maps' stride), computed for the present
    /// blockers in `row_keys` (a key no state has before the first computation).
    rows: Vec<f32>,
    row_keys: Vec<Bits>,
    /// The free directions of each part, computed with its row (valid when the row is).
    row_free: Vec<DirMask>,
    /// The sum of each row (valid with the row).
    row_sums: Vec<f64>,
    /// For each present part not known to be free: present blockers that together block every
    /// direction (a witness that it is stuck); it is re-checked only when one of them leaves.
    covers: Vec<Bits>,
    /// For each part `j`: the parts whose cover holds `j` (re-checked when `j` leaves).
    watchers: Vec<Bits>,
    /// Present supports of each present part ([`UNCOUNTED`] for fixed parts and parts on the
    /// floor, which always stand).
    supports: Vec<u16>,
    /// For each part: how many present parts rest on it alone.
    critical: Vec<u16>,
    /// The parts with `critical > 0` (their removal would drop another part).
    holding: Bits,
    /// The fixed parts.
    fixed: Bits,
    counters: MapCounters,
    /// Scratch (one slot per part): the rows (`i * (n + 1) + j`) of the blockers `j` that shape
    /// part `i`'s minimum map.
    kept: Vec<usize>,
    /// Beside the one kept row per part: the sums and free directions of its last
    /// [`SUM_WAYS`] computed rows, keyed like the rows (`SUM_WAYS` slots per part, the next to
    /// replace in `sum_next`). A rollout revisits a part's few blocker sets far more often than
    /// it needs a whole row.
    sum_keys: Vec<Bits>,
    sum_values: Vec<(f64, DirMask)>,
    sum_next: Vec<u8>,
}

/// Sums kept per part beside its row ([`MapState::min_map_sum`]).
const SUM_WAYS: usize = 4;

const UNCOUNTED: u16 = u16::MAX;

impl Clone for MapState<'_> {
    fn clone(&self) -> Self {
        MapState {
            maps: self.maps,
            all: self.all,
            present: self.present,
            free: self.free,
            unchecked: self.unchecked,
            rows: self.rows.clone(),
            row_keys: self.row_keys.clone(),
            row_free: self.row_free.clone(),
            row_sums: self.row_sums.clone(),
            covers: self.covers.clone(),
            watchers: self.watchers.clone(),
            supports: self.supports.clone(),
            critical: self.critical.clone(),
            holding: self.holding,
            fixed: self.fixed,
            counters: self.counters,
            kept: self.kept.clone(),
            sum_keys: self.sum_keys.clone(),
            sum_values: self.sum_values.clone(),
            sum_next: self.sum_next.clone(),
        }
    }

    /// Copies `source` into `self` without allocating when both are over the same maps: a kept
    /// minimum map is copied only when its key differs (equal keys mean equal rows, sums and
    /// free directions), the scratch and the kept sums (a cache valid in any state) are not
    /// copied.
    fn clone_from(&mut self, source: &Self) {
        if !std::ptr::eq(self.maps, source.maps) {
            *self = source.clone();
            return;
        }
        self.all = source.all;
        self.present = source.present;
        self.free = source.free;
        self.unchecked = source.unchecked;
        let stride = self.maps.stride;
        for (i, (mine, theirs)) in self.row_keys.iter_mut().zip(&source.row_keys).enumerate() {
            if *mine != *theirs {
                *mine = *theirs;
                self.rows[i * stride..(i + 1) * stride].copy_from_slice(&source.rows[i * stride..(i + 1) * stride]);
                self.row_free[i] = source.row_free[i];
                self.row_sums[i] = source.row_sums[i];
            }
        }
        self.covers.copy_from_slice(&source.covers);
        self.watchers.copy_from_slice(&source.watchers);
        self.supports.copy_from_slice(&source.supports);
        self.critical.copy_from_slice(&source.critical);
        self.holding = source.holding;
        self.fixed = source.fixed;
        self.counters = source.counters;
    }
}

/// The removability tests a [`MapState`] ran. Its answers are incremental: a part found free
/// stays free as parts leave and is not tested again, a stuck part is tested again only when a
/// part of its cover (blockers that together block every direction) leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MapCounters {
    /// Collision tests: whether a present part has a free direction (eq. 6.5).
    pub collision_tests: u64,
    /// Collision tests that found every direction blocked.
    pub blocked: u64,
    /// Gravity tests: a collision-free, non-fixed part's removal checked by the [`Support`]
    /// rule (once per part each time [`MapState::feasible_actions`] runs).
    pub gravity_tests: u64,
    /// Gravity tests that found the removal would leave a part without support.
    pub unsupported: u64,
}

impl<'m> MapState<'m> {
    /// The assembled state (every part present).
    pub fn new(maps: &'m DistanceMaps) -> Self {
        let n = maps.n;
        let mut s = MapState {
            maps,
            all: DirMask::first(maps.hemisphere.len()),
            present: Bits::EMPTY,
            free: Bits::EMPTY,
            unchecked: Bits::EMPTY,
            rows: vec![0.0; n * maps.stride],
            row_keys: vec![Bits::NO_KEY; n],
            row_free: vec![DirMask::EMPTY; n],
            row_sums: vec![0.0; n],
            covers: vec![Bits::EMPTY; n],
            watchers: vec![Bits::EMPTY; n],
            supports: vec![0; n],
            critical: vec![0; n],
            holding: Bits::EMPTY,
            fixed: Bits::from_set(&PartSet::from_indices(n, (0..n).filter(|&i| maps.fixed[i]))),
            kept: vec![0; n],
            counters: MapCounters::default(),
            sum_keys: vec![Bits::NO_KEY; n * SUM_WAYS],
            sum_values: vec![(0.0, DirMask::EMPTY); n * SUM_WAYS],
            sum_next: vec![0; n],
        };
        s.reset(&PartSet::full(n));
        s
    }

    /// Moves to `present` (which must only name parts of the assembly); no allocation.
    pub fn reset(&mut self, present: &PartSet) {
        self.reset_with_free(present, &PartSet::empty(self.maps.n));
    }

    /// Like [`MapState::reset`], with parts already known to be collision-free in `present` (or
    /// in a state it came from): they are not re-checked.
    pub fn reset_with_free(&mut self, present: &PartSet, free: &PartSet) {
        let p = Bits::from_set(present);
        self.present = p;
        self.free = Bits::from_set(free).and(&p);
        self.unchecked = p;
        // every stuck part is re-checked, and records its cover again
        self.watchers.fill(Bits::EMPTY);
        if self.maps.support == Support::Below {
            let maps = self.maps;
            self.critical.fill(0);
            self.holding = Bits::EMPTY;
            for i in p.iter() {
                self.supports[i] = if maps.fixed[i] || maps.on_floor[i] {
                    UNCOUNTED
                } else {
                    let mut count = 0;
                    let mut last = 0;
                    for &j in &maps.supporters[i] {
                        if p.contains(j as usize) {
                            count += 1;
                            last = j as usize;
                        }
                    }
                    if count == 1 {
                        self.critical[last] += 1;
                        self.holding.insert(last);
                    }
                    count
                };
            }
        }
    }

    /// The maps.
    pub fn maps(&self) -> &'m DistanceMaps {
        self.maps
    }

    /// The present parts.
    pub fn present(&self) -> PartSet {
        self.present.to_set(self.maps.n)
    }

    /// Whether part `i` is present.
    pub fn contains(&self, i: usize) -> bool {
        i < self.maps.n && self.present.contains(i)
    }

    /// Whether no part that can be removed (not fixed) is left.
    pub fn is_complete(&self) -> bool {
        self.present.iter().all(|i| self.maps.fixed[i])
    }

    /// Removes part `k`, marking the parts whose minimum maps it shaped, re-checking the stuck
    /// parts it helped block, and updating the support counts of the parts resting on it.
    pub fn remove(&mut self, k: usize) {
        let maps = self.maps;
        self.present.remove(k);
        self.free.remove(k);
        self.unchecked.remove(k);
        // re-check the stuck parts whose cover `k` was in
        self.unchecked = self.unchecked.or(&self.watchers[k].and(&self.present).and_not(&self.free));
        if maps.support == Support::Below {
            if self.supports[k] == 1 {
                if let Some(j) = self.single_support(k) {
                    self.critical[j] -= 1;
                    if self.critical[j] == 0 {
                        self.holding.remove(j);
                    }
                }
            }
            for &i in &maps.dependents[k] {
                let i = i as usize;
                if !self.present.contains(i) || self.supports[i] == UNCOUNTED {
                    continue;
                }
                self.supports[i] -= 1;
                if self.supports[i] == 1 {
                    if let Some(j) = self.single_support(i) {
                        self.critical[j] += 1;
                        self.holding.insert(j);
                    }
                }
            }
        }
    }

    /// The one present part that `i` rests on, if any.
    fn single_support(&self, i: usize) -> Option<usize> {
        self.maps.supporters[i].iter().map(|&j| j as usize).find(|&j| self.present.contains(j))
    }

    fn refresh_free(&mut self) {
        if self.unchecked.is_empty() {
            return;
        }
        let unchecked = std::mem::replace(&mut self.unchecked, Bits::EMPTY);
        for i in unchecked.and(&self.present).and_not(&self.free).iter() {
            if self.check_free(i) {
                self.free.insert(i);
            }
        }
    }

    /// Whether present part `i` has a free direction. When it has none, records as its cover
    /// present blockers that together block every direction.
    fn check_free(&mut self, i: usize) -> bool {
        // the bitsets in the loop have as many words as the part count needs
        match self.maps.words {
            1 => self.check_free_in::<1>(i),
            2 => self.check_free_in::<2>(i),
            3 => self.check_free_in::<3>(i),
            _ => self.check_free_in::<4>(i),
        }
    }

    fn check_free_in<const W: usize>(&mut self, i: usize) -> bool {
        self.counters.collision_tests += 1;
        let maps = self.maps;
        let first = i * (maps.n + 1);
        let dcount = maps.hemisphere.len();
        let along = &maps.along[i * dcount * W..(i + 1) * dcount * W];
        let present: [u64; W] = self.present.0[..W].try_into().expect("W words");
        // Start from the last cover's present members (they block where they blocked), then
        // take any direction still open: without a present blocker along it the part is free,
        // else the first such blocker joins the cover.
        let mut cover = self.covers[i];
        if !cover.is_empty() && cover.and_not(&self.present).is_empty() {
            // the whole last cover is present: it still blocks every direction
            for k in cover.iter() {
                self.watchers[k].insert(i);
            }
            self.counters.blocked += 1;
            return false;
        }
        let mut blocked = DirMask::EMPTY;
        cover = cover.and(&self.present);
        for j in cover.iter() {
            blocked = blocked.or(maps.blocked[first + j]);
        }
        while let Some(d) = self.all.and_not(blocked).lowest() {
            let mut j = None;
            for (k, (a, p)) in along[d * W..(d + 1) * W].iter().zip(&present).enumerate() {
                let w = a & p;
                if w != 0 {
                    j = Some(k * 64 + w.trailing_zeros() as usize);
                    break;
                }
            }
            let Some(j) = j else { return true };
            blocked = blocked.or(maps.blocked[first + j]);
            cover.insert(j);
        }
        for k in self.covers[i].iter() {
            self.watchers[k].remove(i);
        }
        for k in cover.iter() {
            self.watchers[k].insert(i);
        }
        self.covers[i] = cover;
        self.counters.blocked += 1;
        false
    }

    fn blocked_now(&self, i: usize) -> DirMask {
        let maps = self.maps;
        let mut blocked = DirMask::EMPTY;
        for (&j, &b) in maps.blockers[i].iter().zip(&maps.blocker_masks[i]) {
            if self.present.contains(j as usize) {
                blocked = blocked.or(b);
            }
        }
        blocked
    }

    /// `B^M̄(p_i, s)`: the free directions of present part `i`.
    pub fn free_mask(&self, i: usize) -> DirMask {
        let key = self.maps.blocker_set[i].and(&self.present);
        if key == self.row_keys[i] {
            self.row_free[i]
        } else if let Some(slot) = self.kept_sum(i, &key) {
            self.sum_values[slot].1
        } else {
            self.all.and_not(self.blocked_now(i))
        }
    }

    /// The slot of part `i`'s kept sum for present blockers `key`, if one is kept.
    #[inline]
    fn kept_sum(&self, i: usize, key: &Bits) -> Option<usize> {
        let first = i * SUM_WAYS;
        self.sum_keys[first..first + SUM_WAYS].iter().position(|k| k == key).map(|w| first + w)
    }

    /// A key of part `i`'s minimum map and free directions in this state: the set of its present
    /// blockers (parts whose maps are below `d_max` somewhere), as bit words. Over the same maps,
    /// equal keys of a part mean equal minimum maps and free directions, so callers cache what
    /// they derive from them by it.
    pub fn row_key(&self, i: usize) -> [u64; 4] {
        self.maps.blocker_set[i].and(&self.present).0
    }

    /// Whether the kept minimum map of part `i` was computed for its present blockers.
    #[inline]
    fn row_is_current(&self, i: usize) -> bool {
        self.maps.blocker_set[i].and(&self.present) == self.row_keys[i]
    }

    /// Whether present part `i` can leave without collision (eq. 6.5).
    pub fn is_collision_free(&mut self, i: usize) -> bool {
        self.refresh_free();
        self.free.contains(i)
    }

    /// The present parts that can leave without collision.
    pub fn collision_free(&mut self) -> PartSet {
        self.refresh_free();
        self.free.to_set(self.maps.n)
    }

    /// `M̄(p_i, s)` (eq. 6.4) of present part `i`, `N_M²` values.
    pub fn min_map(&mut self, i: usize) -> &[f32] {
        if !self.row_is_current(i) {
            self.refresh_row(i);
        }
        let stride = self.maps.stride;
        &self.rows[i * stride..i * stride + self.maps.hemisphere.len()]
    }

    /// Recomputes the minimum map of part `i` and its free directions from its present blockers.
    fn refresh_row(&mut self, i: usize) {
        // the bitsets in the loop have as many words as the part count needs
        match self.maps.words {
            1 => self.refresh_row_in::<1>(i),
            2 => self.refresh_row_in::<2>(i),
            3 => self.refresh_row_in::<3>(i),
            _ => self.refresh_row_in::<4>(i),
        }
    }

    fn refresh_row_in<const W: usize>(&mut self, i: usize) {
        let maps = self.maps;
        let stride = maps.stride;
        let first = i * (maps.n + 1);
        let key = maps.blocker_set[i].and(&self.present);
        let dominators = &maps.dominators[i * maps.n * W..(i + 1) * maps.n * W];
        let present: [u64; W] = self.present.0[..W].try_into().expect("W words");
        let mut count = 0;
        for (k, &word) in key.0[..W].iter().enumerate() {
            let mut w = word;
            while w != 0 {
                let j = k * 64 + w.trailing_zeros() as usize;
                w &= w - 1;
                // Skips (without a branch) blockers with a present dominator: its map is nowhere
                // larger, so the minimum is the same, and it blocks a subset of the directions.
                let d: &[u64; W] = dominators[j * W..(j + 1) * W].try_into().expect("W words");
                let mut shared = 0;
                for (a, b) in d.iter().zip(&present) {
                    shared |= a & b;
                }
                self.kept[count] = first + j;
                count += usize::from(shared == 0);
            }
        }
        let kept = &self.kept[..count];
        let mut blocked = DirMask::EMPTY;
        for &r in kept {
            blocked = blocked.or(maps.blocked[r]);
        }
        let row = &mut self.rows[i * stride..(i + 1) * stride];
        self.row_sums[i] = min_rows(&maps.values, kept, &maps.init_row, row);
        self.row_free[i] = self.all.and_not(blocked);
        self.row_keys[i] = key;
        let slot = i * SUM_WAYS + self.sum_next[i] as usize;
        self.sum_keys[slot] = key;
        self.sum_values[slot] = (self.row_sums[i], self.row_free[i]);
        self.sum_next[i] = ((self.sum_next[i] as usize + 1) % SUM_WAYS) as u8;
    }

    /// `Σ_{k,l} M̄_{k,l}(p_i, s)` of present part `i` (the accessibility reward, eq. 6.15),
    /// summed in eight interleaved lanes.
    pub fn min_map_sum(&mut self, i: usize) -> f64 {
        let key = self.maps.blocker_set[i].and(&self.present);
        if key == self.row_keys[i] {
            return self.row_sums[i];
        }
        if let Some(slot) = self.kept_sum(i, &key) {
            return self.sum_values[slot].0;
        }
        self.refresh_row(i);
        self.row_sums[i]
    }

    /// Whether removing `a` leaves a standing state (the gravity check). With
    /// [`Support::Below`] it assumes the current state stands: no present part may rest on `a`
    /// alone; with [`Support::ContactGraph`] it walks the contact graph.
    pub fn removal_keeps_stable(&self, a: usize) -> bool {
        match self.maps.support {
            Support::Below => self.critical[a] == 0,
            Support::ContactGraph => {
                let mut alive = self.present;
                alive.remove(a);
                alive.and_not(&self.maps.linked(alive)).is_empty()
            }
        }
    }

    /// Whether `i` is a feasible removal: present, not fixed, collision-free, and leaving a
    /// stable state (one part of [`MapState::feasible_actions`]).
    pub fn can_remove(&mut self, i: usize) -> bool {
        if i >= self.maps.n || !self.present.contains(i) || self.fixed.contains(i) || !self.is_collision_free(i) {
            return false;
        }
        self.counters.gravity_tests += 1;
        let stable = self.removal_keeps_stable(i);
        if !stable {
            self.counters.unsupported += 1;
        }
        stable
    }

    /// Whether every present part stands (by the maps' [`Support`] rule).
    pub fn is_stable(&self) -> bool {
        self.maps.stability(&self.present()) == Stability::Stable
    }

    /// The feasible removals: present, not fixed, collision-free, and leaving a stable state.
    /// Writes them to `out` (cleared first) in increasing order.
    pub fn feasible_actions(&mut self, out: &mut Vec<usize>) {
        out.clear();
        self.refresh_free();
        let candidates = self.free.and_not(&self.fixed);
        match self.maps.support {
            Support::Below => {
                for (k, &w) in candidates.and_not(&self.holding).0.iter().enumerate() {
                    let mut w = w;
                    while w != 0 {
                        out.push(k * 64 + w.trailing_zeros() as usize);
                        w &= w - 1;
                    }
                }
            }
            Support::ContactGraph => out.extend(candidates.iter().filter(|&a| self.removal_keeps_stable(a))),
        }
        let tested = candidates.len() as u64;
        self.counters.gravity_tests += tested;
        self.counters.unsupported += tested - out.len() as u64;
    }

    /// What this state has tested so far (over every [`MapState::reset`]).
    pub fn counters(&self) -> MapCounters {
        self.counters
    }

    /// The removal motion of present part `i` (see [`DistanceMaps::clearance`]) as a direction
    /// index and a travel, or `None` when it is blocked.
    pub fn clearance(&self, i: usize) -> Option<(usize, f32)> {
        self.maps.clearance_among(i, self.present.iter(), self.free_mask(i))
    }
}
