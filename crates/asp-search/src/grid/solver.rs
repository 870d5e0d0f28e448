//! Interlocking voxel puzzles by an exact search over grid moves.
//!
//! When every part of an assembly is a set of cells on ONE common grid ([`VoxelModel::of`](asp_geom::grid::VoxelModel::of): from
//! `extras.asp.cells`, or voxelised from a polycube mesh), a BurrTools-style search is exact and
//! complete: a state is the integer offset of every part of the (sub)assembly, a move is a
//! *group* of parts sliding `k` cells along one of `±x, ±y, ±z` with no cell of the group ever
//! overlapping a cell of the others, and a group that can slide to infinity is a *separation*
//! into two subassemblies, each then solved the same way from its current offsets.
//! Breadth-first search over states (no state twice) makes the first separation of every
//! (sub)assembly use the fewest moves.
//!
//! The groups are the closed sets of the one-step blocking relation: for a direction, the
//! closure of a seed part under "would overlap after one step" (the least group containing the
//! seed that can move at all), and unions of such closures (every closed set is one; capped at
//! [`GridConfig::max_groups`] per direction). One part of each (sub)assembly, its *reference*,
//! never moves: the fixed parts (merged) at the top level, else the largest part. A move of a
//! group that holds the reference is the same relative move as its complement moving the other
//! way, which is a closed set too, so nothing is lost.
//!
//! Gravity is not checked: the puzzle is taken apart in the hand, as a subassembly is planned on
//! its base (no ground plane, no stability test).

use crate::problem::{Status, Stuck, StuckReason};
use asp_geom::grid::{Cell, VoxelModel};
use asp_geom::PartSet;
use std::collections::HashSet;
use std::time::Instant;

/// The most entries of the pair tables of a solve (beyond: the search gives up at once).
const MAX_PAIR_TABLE: usize = 100_000_000;

/// The six grid directions, in the order the search tries them.
pub const DIRECTIONS: [Cell; 6] = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]];

/// Limits of a grid search.
#[derive(Clone, Copy, Debug)]
pub struct GridConfig {
    /// The most states visited in all (every BFS of every subassembly).
    pub max_states: u64,
    /// The most groups tried per state and direction (closures of single parts always; unions
    /// of them up to this count).
    pub max_groups: usize,
    /// Stop after the model's first separation (its plan then ends `BudgetExhausted` with one step):
    /// a cheap probe of whether parts must move before anything can leave.
    pub first_only: bool,
}

impl Default for GridConfig {
    fn default() -> Self {
        GridConfig { max_states: 1_000_000, max_groups: 64, first_only: false }
    }
}

/// A move of a group of parts by a whole number of cells.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GridMove {
    /// The parts that move (part indices, ascending).
    pub parts: Vec<usize>,
    /// The translation in cells (along one axis).
    pub delta: Cell,
}

/// One separation: the moves made before it, then `parts` leave along `direction`.
#[derive(Clone, Debug, PartialEq)]
pub struct GridStep {
    /// The moves before the separation, in order.
    pub moves: Vec<GridMove>,
    /// The parts that leave (ascending).
    pub parts: Vec<usize>,
    /// The leaving group's base: its largest part (most cells; lowest index on ties).
    pub base: usize,
    /// The unit grid direction of the removal.
    pub direction: Cell,
    /// Cells of travel until the group's bounds clear the bounds of the parts that stay.
    pub clearance: i32,
    /// For a group of several parts: its own disassembly on its base.
    pub plan: Option<Box<GridPlan>>,
}

/// How a (sub)assembly comes apart.
#[derive(Clone, Debug, PartialEq)]
pub struct GridPlan {
    /// The separations in disassembly order.
    pub steps: Vec<GridStep>,
    /// The reference parts that stay (the fixed parts, or the base) and, when not
    /// [`Status::Found`], the parts that could not be separated.
    pub remaining: Vec<usize>,
    /// How the search ended, in every planner's vocabulary: `Found` (taken apart down to the
    /// reference), `NoPlan` (every reachable state was visited and none separates `remaining`:
    /// each of them blocked by the others) or `BudgetExhausted` (the state budget or the stop
    /// condition ended it).
    pub status: Status,
}

impl GridPlan {
    /// A plan of a model of `n` parts that ended `how`, with `remaining` left.
    fn ended(steps: Vec<GridStep>, remaining: Vec<usize>, n: usize, how: Ended) -> GridPlan {
        let status = match how {
            Ended::Found => Status::Found,
            Ended::Budget => Status::BudgetExhausted,
            Ended::Stuck => {
                let state = PartSet::from_indices(n, remaining.iter().copied());
                let stuck = remaining.iter().map(|&p| Stuck { part: p, reason: StuckReason::Blocked(state.without(p)) }).collect();
                Status::NoPlan { stuck, state }
            }
        };
        GridPlan { steps, remaining, status }
    }
}

/// How a (sub)assembly's search ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ended {
    Found,
    Stuck,
    Budget,
}

/// A grid search's answer and effort.
#[derive(Clone, Debug)]
pub struct GridSolution {
    /// The plan of the whole model.
    pub plan: GridPlan,
    /// States visited (all searches).
    pub states: u64,
    /// Moves before the model's first separation (`None`: none found).
    pub first_separation_moves: Option<usize>,
    /// Wall time, seconds.
    pub seconds: f64,
}

impl GridSolution {
    /// Whether the whole model was taken apart (every subassembly included).
    pub fn complete(&self) -> bool {
        fn ok(p: &GridPlan) -> bool {
            p.status == Status::Found && p.steps.iter().all(|s| s.plan.as_ref().is_none_or(|q| ok(q)))
        }
        ok(&self.plan)
    }
}

/// The pairwise overlap sets: `o_q - o_p ∈ D[p][q]` iff parts p and q overlap.
struct Pair {
    lo: Cell,
    dims: [i32; 3],
    bits: Vec<bool>,
}

impl Pair {
    fn new(p: &[Cell], q: &[Cell]) -> Pair {
        let (pl, ph) = bounds(p);
        let (ql, qh) = bounds(q);
        let lo = [pl[0] - qh[0], pl[1] - qh[1], pl[2] - qh[2]];
        let dims = [ph[0] - ql[0] - lo[0] + 1, ph[1] - ql[1] - lo[1] + 1, ph[2] - ql[2] - lo[2] + 1];
        let mut bits = vec![false; (dims[0] * dims[1] * dims[2]) as usize];
        for a in p {
            for b in q {
                let r = [a[0] - b[0] - lo[0], a[1] - b[1] - lo[1], a[2] - b[2] - lo[2]];
                bits[((r[0] * dims[1] + r[1]) * dims[2] + r[2]) as usize] = true;
            }
        }
        Pair { lo, dims, bits }
    }

    #[inline]
    fn overlaps(&self, r: Cell) -> bool {
        let x = [r[0] - self.lo[0], r[1] - self.lo[1], r[2] - self.lo[2]];
        if (0..3).any(|k| x[k] < 0 || x[k] >= self.dims[k]) {
            return false;
        }
        self.bits[((x[0] * self.dims[1] + x[1]) * self.dims[2] + x[2]) as usize]
    }

    /// The least `k >= 1` with `r - k d` an overlap, or `None`.
    fn first_hit(&self, r: Cell, d: Cell) -> Option<i32> {
        let a = (0..3).find(|&k| d[k] != 0).unwrap();
        let s = d[a];
        // r[a] - k s must lie in [lo, lo + dims)
        let mut k = 1;
        loop {
            let x = r[a] - k * s - self.lo[a];
            if (s > 0 && x < 0) || (s < 0 && x >= self.dims[a]) {
                return None;
            }
            let mut q = r;
            q[a] -= k * s;
            if self.overlaps(q) {
                return Some(k);
            }
            k += 1;
        }
    }
}

fn bounds(cells: &[Cell]) -> (Cell, Cell) {
    let mut lo = [i32::MAX; 3];
    let mut hi = [i32::MIN; 3];
    for c in cells {
        for k in 0..3 {
            lo[k] = lo[k].min(c[k]);
            hi[k] = hi[k].max(c[k]);
        }
    }
    (lo, hi)
}

fn add(a: Cell, b: Cell) -> Cell {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn sub(a: Cell, b: Cell) -> Cell {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn scale(a: Cell, k: i32) -> Cell {
    [a[0] * k, a[1] * k, a[2] * k]
}

/// The solver over one voxel model: the pair tables of every unit (a part, or the fixed parts
/// merged into one).
struct Solver<'a> {
    /// Unit u's global part indices.
    units: Vec<Vec<usize>>,
    /// Unit u's cells.
    cells: Vec<Vec<Cell>>,
    pairs: Vec<Vec<Pair>>,
    config: GridConfig,
    stop: &'a dyn Fn() -> bool,
    states: u64,
    expanded: u64,
    /// The model's part count.
    parts: usize,
}

/// A search's local view: the units of the (sub)assembly, their offsets, its reference.
#[derive(Clone)]
struct Local {
    units: Vec<usize>,
    offsets: Vec<Cell>,
    reference: usize,
    /// The reference may change (the top level without fixed parts): the smaller side of a
    /// separation leaves, and the larger keeps its largest part as the reference.
    free: bool,
}

enum Bfs {
    /// Moves (local group mask, delta), then the separating group and direction.
    Separated(Vec<(u64, Cell)>, u64, Cell, Vec<Cell>),
    Stuck,
    Budget,
}

/// Takes `model` apart by grid moves (see the module docs). `stop` is polled every few thousand
/// states (a deadline, a cancel token).
pub fn solve(model: &VoxelModel, config: &GridConfig, stop: &dyn Fn() -> bool) -> GridSolution {
    let started = Instant::now();
    let mut units: Vec<Vec<usize>> = Vec::new();
    let fixed: Vec<usize> = (0..model.len()).filter(|&p| model.fixed[p]).collect();
    if !fixed.is_empty() {
        units.push(fixed.clone());
    }
    units.extend((0..model.len()).filter(|&p| !model.fixed[p]).map(|p| vec![p]));
    let cells: Vec<Vec<Cell>> = units.iter().map(|u| u.iter().flat_map(|&p| model.cells[p].iter().copied()).collect()).collect();
    let spans: Vec<[i64; 3]> = cells
        .iter()
        .map(|c| {
            let (lo, hi) = bounds(c);
            std::array::from_fn(|k| (hi[k] - lo[k] + 1) as i64)
        })
        .collect();
    let table: i64 = spans.iter().flat_map(|a| spans.iter().map(move |b| (0..3).map(|k| a[k] + b[k]).product::<i64>())).sum();
    if table > MAX_PAIR_TABLE as i64 {
        let plan = GridPlan::ended(Vec::new(), (0..model.len()).collect(), model.len(), Ended::Budget);
        return GridSolution { plan, states: 0, first_separation_moves: None, seconds: started.elapsed().as_secs_f64() };
    }
    let pairs = (0..units.len()).map(|p| (0..units.len()).map(|q| Pair::new(&cells[p], &cells[q])).collect()).collect();
    let mut solver = Solver { units, cells, pairs, config: *config, stop, states: 0, expanded: 0, parts: model.len() };
    let n = solver.units.len();
    let reference = if fixed.is_empty() { solver.base(&(0..n).collect::<Vec<_>>()) } else { 0 };
    let local = Local { units: (0..n).collect(), offsets: vec![[0; 3]; n], reference, free: fixed.is_empty() };
    let mut first = None;
    let plan = solver.plan(local, &mut first);
    GridSolution { plan, states: solver.states, first_separation_moves: first, seconds: started.elapsed().as_secs_f64() }
}

impl Solver<'_> {
    /// The unit with the most cells among `units` (lowest index on ties).
    fn base(&self, units: &[usize]) -> usize {
        *units.iter().max_by_key(|&&u| (self.cells[u].len(), std::cmp::Reverse(u))).unwrap()
    }

    fn parts_of(&self, units: impl IntoIterator<Item = usize>) -> Vec<usize> {
        let mut v: Vec<usize> = units.into_iter().flat_map(|u| self.units[u].iter().copied()).collect();
        v.sort_unstable();
        v
    }

    /// Takes the local (sub)assembly apart down to its reference.
    fn plan(&mut self, mut local: Local, first: &mut Option<usize>) -> GridPlan {
        let mut steps = Vec::new();
        while local.units.len() > 1 {
            match self.bfs(&local) {
                Bfs::Separated(moves, group, dir, offsets) => {
                    if first.is_none() {
                        *first = Some(moves.len());
                    }
                    let ids = |mask: u64| (0..local.units.len()).filter(move |&i| mask >> i & 1 == 1);
                    let gmoves: Vec<GridMove> =
                        moves.iter().map(|&(m, delta)| GridMove { parts: self.parts_of(ids(m).map(|i| local.units[i])), delta }).collect();
                    // the side without the reference leaves (the smaller side, when it may)
                    let mut leaving: Vec<usize> = ids(group).collect();
                    let mut staying: Vec<usize> = (0..local.units.len()).filter(|i| group >> i & 1 == 0).collect();
                    let mut dir = dir;
                    if local.free && leaving.len() > staying.len() {
                        std::mem::swap(&mut leaving, &mut staying);
                        dir = scale(dir, -1);
                        let stay_units: Vec<usize> = staying.iter().map(|&i| local.units[i]).collect();
                        let base = self.base(&stay_units);
                        // an index into `local.units` (as `bfs` and the next `Local` read it),
                        // not a position within `staying` (else a panic, or a wrong reference)
                        local.reference = staying.iter().copied().find(|&i| local.units[i] == base).unwrap();
                    }
                    let clearance = self.clearance(&local, &offsets, &leaving, &staying, dir);
                    let leave_units: Vec<usize> = leaving.iter().map(|&i| local.units[i]).collect();
                    let base_unit = self.base(&leave_units);
                    let sub = (leaving.len() > 1).then(|| {
                        let sub = Local {
                            units: leave_units.clone(),
                            offsets: leaving.iter().map(|&i| offsets[i]).collect(),
                            reference: leaving.iter().position(|&i| local.units[i] == base_unit).unwrap(),
                            free: false,
                        };
                        let mut ignore = Some(0);
                        Box::new(self.plan(sub, &mut ignore))
                    });
                    steps.push(GridStep {
                        moves: gmoves,
                        parts: self.parts_of(leave_units.iter().copied()),
                        base: self.units[base_unit][0],
                        direction: dir,
                        clearance,
                        plan: sub,
                    });
                    if self.config.first_only {
                        return GridPlan::ended(steps, self.parts_of(local.units.iter().copied()), self.parts, Ended::Budget);
                    }
                    let reference_unit = local.units[local.reference];
                    local = Local {
                        units: staying.iter().map(|&i| local.units[i]).collect(),
                        offsets: staying.iter().map(|&i| offsets[i]).collect(),
                        reference: staying.iter().position(|&i| local.units[i] == reference_unit).unwrap(),
                        free: local.free,
                    };
                }
                Bfs::Stuck => {
                    return GridPlan::ended(steps, self.parts_of(local.units.iter().copied()), self.parts, Ended::Stuck);
                }
                Bfs::Budget => {
                    return GridPlan::ended(steps, self.parts_of(local.units.iter().copied()), self.parts, Ended::Budget);
                }
            }
        }
        GridPlan::ended(steps, self.parts_of(local.units.iter().copied()), self.parts, Ended::Found)
    }

    /// Cells the leaving units travel along `dir` until their bounds clear the staying ones'.
    fn clearance(&self, local: &Local, offsets: &[Cell], leaving: &[usize], staying: &[usize], dir: Cell) -> i32 {
        let a = (0..3).find(|&k| dir[k] != 0).unwrap();
        let span = |set: &[usize]| {
            let mut lo = i32::MAX;
            let mut hi = i32::MIN;
            for &i in set {
                for c in &self.cells[local.units[i]] {
                    let x = c[a] + offsets[i][a];
                    lo = lo.min(x);
                    hi = hi.max(x + 1);
                }
            }
            (lo, hi)
        };
        let (gl, gh) = span(leaving);
        let (sl, sh) = span(staying);
        if dir[a] > 0 {
            (sh - gl).max(0)
        } else {
            (gh - sl).max(0)
        }
    }

    /// Breadth-first search from the local state to the first state with a separation.
    fn bfs(&mut self, local: &Local) -> Bfs {
        let n = local.units.len();
        let width = 3 * n;
        let flat = |offsets: &[Cell]| -> Vec<i32> { offsets.iter().flat_map(|o| o.iter().copied()).collect() };
        // every state's offsets, flat, in BFS order; the seen set holds the same keys
        let mut arena: Vec<i32> = flat(&local.offsets);
        let mut seen: HashSet<Box<[i32]>, Fx> = HashSet::with_hasher(Fx);
        seen.insert(arena.clone().into_boxed_slice());
        // per state: parent, the move that led here
        let mut links: Vec<(usize, u64, Cell)> = vec![(usize::MAX, 0, [0; 3])];
        self.states += 1;
        let mut head = 0;
        let mut hit = vec![None; n * n];
        let mut groups: Vec<u64> = Vec::new();
        let mut successors: Vec<(u64, Cell)> = Vec::new();
        let mut next = vec![0i32; width];
        while head < links.len() {
            self.expanded += 1;
            if self.states >= self.config.max_states || (self.expanded.is_multiple_of(1024) && (self.stop)()) {
                return Bfs::Budget;
            }
            let offsets: Vec<Cell> = arena[head * width..(head + 1) * width].chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
            successors.clear();
            let mut separation: Option<(u64, Cell)> = None;
            for dir in DIRECTIONS {
                // hit[i * n + j]: the first step at which unit i, moving along dir, meets unit j
                let mut block = [0u64; 64];
                for i in 0..n {
                    for j in 0..n {
                        hit[i * n + j] = if i == j {
                            None
                        } else {
                            self.pairs[local.units[i]][local.units[j]].first_hit(sub(offsets[j], offsets[i]), dir)
                        };
                        if hit[i * n + j] == Some(1) {
                            block[i] |= 1 << j;
                        }
                    }
                }
                groups.clear();
                for seed in 0..n {
                    if seed == local.reference {
                        continue;
                    }
                    let mut g = 1u64 << seed;
                    loop {
                        let mut grown = g;
                        for (i, b) in block.iter().enumerate().take(n) {
                            if g >> i & 1 == 1 {
                                grown |= b;
                            }
                        }
                        if grown == g {
                            break;
                        }
                        g = grown;
                    }
                    if g >> local.reference & 1 == 0 && !groups.contains(&g) {
                        groups.push(g);
                    }
                }
                let closures = groups.len();
                let mut at = 0;
                while at < groups.len() && groups.len() < self.config.max_groups {
                    for c in 0..closures {
                        let u = groups[at] | groups[c];
                        if !groups.contains(&u) && groups.len() < self.config.max_groups {
                            groups.push(u);
                        }
                    }
                    at += 1;
                }
                for &g in &groups {
                    // the first blocked step of the group
                    let mut limit: Option<i32> = None;
                    for i in (0..n).filter(|i| g >> i & 1 == 1) {
                        for j in (0..n).filter(|j| g >> j & 1 == 0) {
                            if let Some(k) = hit[i * n + j] {
                                limit = Some(limit.map_or(k, |l: i32| l.min(k)));
                            }
                        }
                    }
                    match limit {
                        None => {
                            if separation.is_none_or(|(s, _)| g.count_ones() < s.count_ones()) {
                                separation = Some((g, dir));
                            }
                        }
                        Some(l) => {
                            for k in 1..l {
                                successors.push((g, scale(dir, k)));
                            }
                        }
                    }
                }
            }
            if let Some((g, dir)) = separation {
                let mut moves = Vec::new();
                let mut at = head;
                while links[at].0 != usize::MAX {
                    moves.push((links[at].1, links[at].2));
                    at = links[at].0;
                }
                moves.reverse();
                return Bfs::Separated(moves, g, dir, offsets);
            }
            for &(g, delta) in &successors {
                for i in 0..n {
                    let o = if g >> i & 1 == 1 { add(offsets[i], delta) } else { offsets[i] };
                    next[3 * i..3 * i + 3].copy_from_slice(&o);
                }
                if !seen.contains(&next[..]) {
                    seen.insert(next.clone().into_boxed_slice());
                    arena.extend_from_slice(&next);
                    links.push((head, g, delta));
                    self.states += 1;
                }
            }
            head += 1;
        }
        Bfs::Stuck
    }
}

/// A fast hasher for the search's keys (FxHash: multiply and rotate; not DoS-resistant, and
/// need not be).
#[derive(Clone, Copy, Default)]
struct Fx;

impl std::hash::BuildHasher for Fx {
    type Hasher = FxHasher;
    fn build_hasher(&self) -> FxHasher {
        FxHasher(0)
    }
}

struct FxHasher(u64);

impl std::hash::Hasher for FxHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut w = [0u8; 8];
            w[..chunk.len()].copy_from_slice(chunk);
            self.add(u64::from_le_bytes(w));
        }
    }
    fn write_i32(&mut self, v: i32) {
        self.add(v as u32 as u64);
    }
    fn write_usize(&mut self, v: usize) {
        self.add(v as u64);
    }
}

impl FxHasher {
    #[inline]
    fn add(&mut self, w: u64) {
        self.0 = (self.0.rotate_left(5) ^ w).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}
