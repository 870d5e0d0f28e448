//! Monte Carlo tree search: [`Mcts`] (one objective, [`uct`]) and [`ParetoMcts`] (a Pareto front,
//! [`pareto`]) and the machinery they share: settings and their
//! validating builder, the search graph, episodes with a search budget per step (thesis 5.4.2),
//! root-parallel threads, and the outcome with its trace.
//!
//! # Episodes and steps
//! An *episode* walks from the root to a complete disassembly. At each *search step* it runs
//! `budget` *iterations* from the current node — selection by the tree policy, expansion of one
//! untried removal (chosen by the policy's [`crate::PolicyWorker::expand`]: at random by default), a
//! rollout with the rollout policy until no part can be removed, and backpropagation along the
//! path to the root — and then moves to the child the tree policy picks. The next episode
//! starts again at the root.
//!
//! # Transpositions
//! Removing A then B leaves the same state as B then A. By default every state (present parts
//! and the objectives' memories, e.g. the direction-change objective's `H`) has one node, so the
//! search runs on a graph: node values hold *suffix* returns (from the state to the end, which do
//! not depend on the path), selection adds the edge's reward and the path's returns so far, and
//! at the end the answer is read off the graph's complete paths by dynamic programming and merged
//! with the best complete sequences sampled. `transpositions(false)` grows the thesis' plain tree
//! instead (there a node's suffix values equal its whole returns less a constant).
//!
//! # Solved and dead nodes
//! A node whose removals have all been expanded and whose children are all finished is
//! *solved* (everything below it has been explored) or *dead* (no complete sequence below it).
//! Selection skips finished children; when the root is finished the search stops early and its
//! answer is exact.
//!
//! # Threads
//! Root parallelism: each thread grows its own graph with its own random stream
//! (`seed`, thread index) and its share of the episodes; the answers are merged in thread order.
//! The output depends only on the seed, the settings and the thread count (not on timing)
//! unless a time limit or a [`crate::StopToken`] stops the search. `threads = 1` runs on the calling
//! thread.
//!
//! # Recording transitions
//! With [`SearchBuilder::record_transitions`] every removal step the search simulates — at an
//! expansion or in a rollout — is kept as a [`Transition`] `(s, a, r, s')` for learning
//! Q-functions offline (thesis 5.5.2, 6.5.1). Selection walks edges that were recorded when
//! they were expanded, so expansions and rollouts cover every distinct step. Recording computes
//! the feasible actions of each step's states (with the step's [`crate::StepKind`]) and nothing else
//! that the search reads: the search takes the same steps with or without it. Only
//! [`SearchStats`]' test counters also count the tests recording runs. The outcome holds the
//! transitions per thread in order, threads in order, up to
//! [`SearchBuilder::record_transitions_limit`] (split among the threads).
//!
//! # Stepping
//! `solve_stepped` runs the same loop on one thread with an [`EpisodeHook`] called between
//! episodes: it gets each episode's [`EpisodeEnd`] (its recorded transitions, the front so far)
//! and may go on, swap the policy ([`Next::Policy`]: the tree stays, the thread's
//! [`crate::PolicyWorker`] is rebuilt) or stop. A hook that always goes on changes nothing: the answer
//! is `solve`'s. `asp_app::stepped::SteppedSearch` drives it from another thread (Python's
//! `Assembly.search`, the online Q-learning of thesis 6.5).
//!
//! # Plug-ins
//! The rollout and expansion policy ([`crate::Policy`], one [`crate::PolicyWorker`] per thread), the
//! objectives and the feasibility filters of the [`crate::Mdp`] are the search's plug-ins. One that
//! fails or breaks its contract (a rollout index outside the actions offered) stops the search
//! with an error; a panic in one is reported as an error too, not re-raised.
//!
//! # Files
//! [`settings`] (the builder), [`outcome`] (what a search gives back; its
//! [`SearchOutcome::plan`] in every planner's vocabulary), `planner` (the searches behind
//! [`crate::Planner`], [`MapPlanner`]), `graph` (nodes, edges,
//! the variants' seam), `worker` (one thread's search: select, expand, rollout, backup),
//! `record` (recording transitions), `run` (threads and the merged answer); the variants in
//! [`uct`] and [`pareto`].

mod graph;
pub mod outcome;
pub mod pareto;
mod planner;
mod record;
mod run;
pub mod settings;
pub mod uct;
mod worker;

pub use outcome::{EpisodeEnd, EpisodeHook, Next, SearchOutcome, SearchStats, Solution, TracePoint, Transition};
pub use pareto::{ParetoMcts, ParetoMctsBuilder};
pub use planner::{MapPlanner, TreeSearch};
pub use settings::{
    SearchBuilder, SearchSettings, DEFAULT_BUDGET, DEFAULT_EPISODES, DEFAULT_EXPLORATION, DEFAULT_MAX_NODES, DEFAULT_POLISH,
    DEFAULT_RECORD_LIMIT,
};
pub use uct::{Mcts, MctsBuilder};
