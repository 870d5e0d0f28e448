//! The blocker, dominator, support and dependency indexes built from the maps.

use super::{Bits, DistanceMaps};
use rayon::prelude::*;

impl DistanceMaps {
    /// Builds the blocker, support and dependency indexes from the maps.
    pub(super) fn index(&mut self) {
        let n = self.n;
        let up = self.hemisphere.up_index();
        let support_tol = 2.0 * self.tolerance;
        // Blockers that block the most directions first (a part's blocked directions fill up
        // after few of them when they are ORed in this order).
        self.blockers = (0..n)
            .map(|i| {
                let mut b: Vec<u16> = (0..n).filter(|&j| j != i && !self.blocked(i, j).is_empty()).map(|j| j as u16).collect();
                b.sort_by_key(|&j| std::cmp::Reverse(self.blocked(i, j as usize).len()));
                b
            })
            .collect();
        self.blocker_set = (0..n)
            .map(|i| {
                let mut b = Bits::EMPTY;
                for &j in &self.blockers[i] {
                    b.insert(j as usize);
                }
                b
            })
            .collect();
        self.init_row = vec![0.0; self.stride];
        self.init_row[..self.hemisphere.len()].fill(self.d_max);
        let this = &*self;
        let dominators: Vec<Vec<Bits>> = (0..n)
            .into_par_iter()
            .map(|i| {
                let mut row = vec![Bits::EMPTY; n];
                for &j in &this.blockers[i] {
                    let j = j as usize;
                    let (mj, bj) = (this.map(i, j), this.blocked(i, j));
                    for &k in &this.blockers[i] {
                        let k = k as usize;
                        // a dominator blocks at least where j does
                        if k == j || !bj.and_not(this.blocked(i, k)).is_empty() {
                            continue;
                        }
                        let mk = this.map(i, k);
                        if mk.iter().zip(mj).all(|(a, b)| a <= b) && (k < j || mk != mj) {
                            row[j].insert(k);
                        }
                    }
                }
                row
            })
            .collect();
        let words = self.words;
        self.dominators = dominators.iter().flatten().flat_map(|b| b.0[..words].to_vec()).collect();
        self.blocker_masks = (0..n).map(|i| self.blockers[i].iter().map(|&j| self.blocked(i, j as usize)).collect()).collect();
        let dcount = self.hemisphere.len();
        self.along = vec![0; n * dcount * words];
        for i in 0..n {
            for &j in &self.blockers[i] {
                let j = j as usize;
                for d in self.blocked(i, j).iter() {
                    self.along[(i * dcount + d) * words + j / 64] |= 1 << (j % 64);
                }
            }
        }
        self.blocks = vec![Bits::EMPTY; n];
        for i in 0..n {
            for &j in &self.blockers[i] {
                self.blocks[j as usize].insert(i);
            }
        }
        self.supporters =
            (0..n).map(|i| (0..n).filter(|&j| j != i && self.map(j, i)[up] <= support_tol).map(|j| j as u16).collect()).collect();
        self.dependents = vec![Vec::new(); n];
        for i in 0..n {
            for &j in &self.supporters[i] {
                self.dependents[j as usize].push(i as u16);
            }
        }
        self.on_floor = (0..n).map(|i| self.map(n, i)[up] <= support_tol).collect();
    }
}
