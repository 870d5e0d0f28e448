//! The tree searches behind [`Planner`]: [`MapPlanner`] is a search ([`Mcts`], [`ParetoMcts`])
//! made on its problem's MDP on the distance maps, as an OMPL planner is made on its space.

use super::outcome::SearchOutcome;
use super::pareto::ParetoMcts;
use super::settings::SearchSettings;
use super::uct::Mcts;
use crate::error::{Result, SearchError};
use crate::mdp::Mdp;
use crate::problem::{Budget, PlanOutcome, Planner, Problem, Spent};
use std::time::Instant;

/// A tree search that [`MapPlanner`] runs: [`Mcts`] or [`ParetoMcts`].
pub trait TreeSearch: From<SearchSettings> {
    /// The planner's name in reports.
    const NAME: &'static str;
    /// The search's settings.
    fn settings(&self) -> &SearchSettings;
    /// Searches `mdp` (the type's `solve`).
    fn search(&self, mdp: &Mdp) -> Result<SearchOutcome>;
}

impl TreeSearch for Mcts {
    const NAME: &'static str = "mcts";
    fn settings(&self) -> &SearchSettings {
        Mcts::settings(self)
    }
    fn search(&self, mdp: &Mdp) -> Result<SearchOutcome> {
        self.solve(mdp)
    }
}

impl TreeSearch for ParetoMcts {
    const NAME: &'static str = "pareto_mcts";
    fn settings(&self) -> &SearchSettings {
        ParetoMcts::settings(self)
    }
    fn search(&self, mdp: &Mdp) -> Result<SearchOutcome> {
        self.solve(mdp)
    }
}

/// A tree search on `mdp` behind [`Planner`]. The problem must be the whole assembly of the
/// MDP's maps (its checker's parts, all present): the tree searches start from the assembled
/// state. The budget caps the search's own settings: the fewer episodes
/// ([`Budget::max_episodes`]) and the shorter time limit ([`Budget::timeout`]) of the two; its
/// cancel token replaces the settings' own. Removal tests and states are not counted (the
/// maps' lookups are not a checker's tests; the node cap is no stop). The outcome is
/// [`SearchOutcome::plan`]; [`MapPlanner::search`] gives the whole [`SearchOutcome`] (the
/// front, the trace).
#[derive(Clone, Debug)]
pub struct MapPlanner<'m, S> {
    search: S,
    mdp: &'m Mdp,
}

impl<'m, S: TreeSearch> MapPlanner<'m, S> {
    /// `search` made on `mdp`.
    pub fn new(search: S, mdp: &'m Mdp) -> Self {
        MapPlanner { search, mdp }
    }

    /// The search within `budget` (as [`Planner::solve`] runs it), with all it found.
    pub fn search(&self, budget: &Budget) -> Result<SearchOutcome> {
        let mut settings = self.search.settings().clone();
        if let Some(e) = budget.max_episodes {
            settings.episodes = settings.episodes.min(usize::try_from(e).unwrap_or(usize::MAX));
        }
        if let Some(t) = budget.timeout {
            settings.time_limit = Some(settings.time_limit.map_or(t, |s| s.min(t)));
        }
        if let Some(token) = &budget.cancel {
            settings.stop = Some(token.clone());
        }
        S::from(settings).search(self.mdp)
    }
}

impl<S: TreeSearch> Planner for MapPlanner<'_, S> {
    fn name(&self) -> &'static str {
        S::NAME
    }

    fn solve(&self, problem: &Problem, budget: &Budget) -> Result<PlanOutcome> {
        let n = self.mdp.maps().num_parts();
        if problem.checker.num_parts() != n || !problem.start.iter().eq(0..n) {
            return Err(SearchError::config(format!(
                "a tree search takes the whole assembly of its distance maps apart ({n} parts), not this problem"
            )));
        }
        if let Some(reason) = budget.stop_reason(Spent::default(), Instant::now()) {
            return Ok(PlanOutcome::stopped_before_start(reason));
        }
        Ok(self.search(budget)?.into())
    }
}
