//! Seeds derived from a run's seed: SplitMix64, and the one derivation every randomised choice
//! that depends on a disassembly state takes ([`derive()`]). A derived seed depends only on its
//! inputs (never on a search's history, thread or episode), so the same state gets the same
//! samples wherever it is reached.
//!
//! Each kind of randomised work draws from a stream of its own ([`Stream`]): the depth-first
//! search's orderings and path planner, the optimiser's steps and the robot's plans in the
//! depth-first search. So one (seed, state, part) gives the arm different samples in the
//! depth-first search and in the optimiser; making them one stream would change plans.

use crate::PartSet;

/// SplitMix64's increment (the golden ratio in 64 bits).
const GAMMA: u64 = 0x9e37_79b9_7f4a_7c15;

/// SplitMix64's output function: a cheap, well-mixed hash of one word.
pub fn finalise(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// One SplitMix64 step: `x` advanced by the increment, then [`finalise`]d.
pub fn splitmix(x: u64) -> u64 {
    finalise(x.wrapping_add(GAMMA))
}

/// The streams of derived seeds, one per kind of randomised work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stream {
    /// The depth-first search: its orderings' shuffles and its path planner calls.
    Search,
    /// The optimiser's steps (a planner's samples in one step of the tree search).
    Step,
    /// A robot's removal plans in the depth-first search.
    Robot,
}

impl Stream {
    /// The stream's key, mixed into the run's seed.
    fn key(self) -> u64 {
        match self {
            Stream::Search => 0x9e37_79b9_7f4a_7c15,
            Stream::Step => 0x6a09_e667_f3bc_c909,
            Stream::Robot => 0x243f_6a88_85a3_08d3,
        }
    }
}

/// The seed of the randomised work on `state` named by `salt` (a part index, or any word) in
/// `stream`, from the run's `seed`: the same inputs give the same seed, nearby inputs unrelated
/// ones.
pub fn derive(seed: u64, stream: Stream, state: &PartSet, salt: u64) -> u64 {
    let mut h = splitmix(seed ^ stream.key());
    for &w in state.words() {
        h = splitmix(h ^ w);
    }
    splitmix(h ^ salt)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The derived seeds every plan depends on, pinned: a change here changes path planner and
    /// robot plans and shuffled orderings.
    #[test]
    fn derived_seeds_are_pinned() {
        let state = PartSet::from_indices(70, [0, 3, 64, 69]);
        let got: Vec<u64> = [Stream::Search, Stream::Step, Stream::Robot].iter().map(|&s| derive(7, s, &state, 5)).collect();
        assert_eq!(got, PINNED);
        assert_eq!(splitmix(0), 0xe220_a839_7b1d_cdaf, "SplitMix64's first output from state 0");
    }

    const PINNED: [u64; 3] = [0x144b_2974_6b8b_d709, 0x4d79_e1df_ac2a_5740, 0xbdd7_3fda_d19f_d5f3];
}
