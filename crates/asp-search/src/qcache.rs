//! A search thread's cache of Q-values by state ([`QCache`]): guided searches meet the same
//! states again — a node's state at each of its expansions, and the greedy rollouts of
//! [`crate::EpsilonGreedy`] that, from nearby states, take the same removals and reach the same
//! states in another order (transpositions) — and a Q-function's values of a state's actions are
//! a function of the state, so they are kept instead of evaluated again.
//!
//! The key is the state (present parts and the objectives' memory key words, as the search's
//! transposition index has it) and the actions asked about (a Q model flags them in its input),
//! hashed twice with independent mixes into 128 bits; values are kept as the `f64`s the
//! Q-function gave, so a search with the cache takes the same steps as one without. The table is
//! direct-mapped (a new state replaces the one in its slot), allocated on the first insertion, and
//! bounded in bytes.

use crate::mdp::Mdp;
use asp_geom::PartSet;
use std::hash::{Hash, Hasher};

/// Default bytes of a thread's cache (values and keys).
pub const DEFAULT_QCACHE_BYTES: usize = 32 << 20;

/// Q-values of states, by state and asked actions (see the module's notes).
#[derive(Debug, Default)]
pub struct QCache {
    /// Actions per slot at most (the parts of the problem).
    width: usize,
    /// Slots (a power of two), 0 until the first insertion.
    slots: usize,
    bytes: usize,
    keys: Vec<[u64; 2]>,
    /// Per slot: how many values it holds (0: empty).
    lens: Vec<u16>,
    values: Vec<f64>,
    hits: u64,
    lookups: u64,
}

/// A state's key (two independent 64-bit hashes).
pub type QKey = [u64; 2];

/// A multiply-rotate mix of words (one instance per hash, with its own constant).
struct Mix(u64, u64);

impl Hasher for Mix {
    fn finish(&self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut word = [0u8; 8];
            word[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(word));
        }
    }

    fn write_u64(&mut self, x: u64) {
        self.0 = (self.0.rotate_left(23) ^ x).wrapping_mul(self.1);
    }

    fn write_usize(&mut self, x: usize) {
        self.write_u64(x as u64);
    }
}

impl QCache {
    /// A cache for a problem of `parts` parts within about `bytes` bytes (nothing is allocated
    /// before the first insertion; 0 bytes: a cache that keeps nothing).
    pub fn new(parts: usize, bytes: usize) -> Self {
        QCache { width: parts.max(1), bytes, ..QCache::default() }
    }

    /// The key of `present` with the objectives' `memory` (their key words count) and the asked
    /// `actions`.
    pub fn key(problem: &Mdp, present: &PartSet, memory: &[u64], actions: &[usize]) -> QKey {
        let mut a = Mix(0x243f_6a88_85a3_08d3, 0x9e37_79b9_7f4a_7c15);
        let mut b = Mix(0x1319_8a2e_0370_7344, 0xd6e8_feb8_6659_fd93);
        for h in [&mut a, &mut b] {
            present.hash(h);
            problem.hash_key(memory, h);
            h.write_usize(actions.len());
            for &x in actions {
                h.write_usize(x);
            }
        }
        [a.finish(), b.finish()]
    }

    fn slot(&self, key: &QKey) -> usize {
        key[0] as usize & (self.slots - 1)
    }

    /// The values kept for `key`, written to `out` (as long as the actions of the key); false
    /// when none are kept.
    pub fn get(&mut self, key: &QKey, out: &mut [f64]) -> bool {
        self.lookups += 1;
        if self.slots == 0 {
            return false;
        }
        let s = self.slot(key);
        let len = self.lens[s] as usize;
        if len == 0 || len != out.len() || self.keys[s] != *key {
            return false;
        }
        out.copy_from_slice(&self.values[s * self.width..s * self.width + len]);
        self.hits += 1;
        true
    }

    /// Keeps `values` under `key` (replacing what its slot held).
    pub fn put(&mut self, key: &QKey, values: &[f64]) {
        if self.slots == 0 {
            let per_slot = self.width * std::mem::size_of::<f64>() + std::mem::size_of::<QKey>() + 2;
            let fit = self.bytes / per_slot;
            if fit == 0 {
                return;
            }
            // the largest power of two that fits
            self.slots = 1 << (usize::BITS - 1 - fit.leading_zeros());
            self.keys = vec![[0; 2]; self.slots];
            self.lens = vec![0; self.slots];
            self.values = vec![0.0; self.slots * self.width];
        }
        if values.is_empty() || values.len() > self.width {
            return;
        }
        let s = self.slot(key);
        self.keys[s] = *key;
        self.lens[s] = values.len() as u16;
        self.values[s * self.width..s * self.width + values.len()].copy_from_slice(values);
    }

    /// Lookups that found their values.
    pub fn hits(&self) -> u64 {
        self.hits
    }

    /// Lookups.
    pub fn lookups(&self) -> u64 {
        self.lookups
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_values_by_key_and_replaces_by_slot() {
        let mut c = QCache::new(4, 1 << 12);
        let (k1, k2) = ([5, 7], [5, 8]);
        let mut out = [0.0; 2];
        assert!(!c.get(&k1, &mut out));
        c.put(&k1, &[1.5, 2.5]);
        assert!(c.get(&k1, &mut out));
        assert_eq!(out, [1.5, 2.5]);
        // same slot, other key: not served, and it replaces the first
        assert!(!c.get(&k2, &mut out));
        c.put(&k2, &[3.0, 4.0]);
        assert!(!c.get(&k1, &mut out));
        assert!(c.get(&k2, &mut out));
        // a length that differs from the kept one is not served
        assert!(!c.get(&k2, &mut [0.0; 3]));
        assert_eq!((c.hits(), c.lookups()), (2, 6));
        // a zero-byte cache keeps nothing
        let mut none = QCache::new(4, 0);
        none.put(&k1, &[1.0, 2.0]);
        assert!(!none.get(&k1, &mut out));
    }
}
