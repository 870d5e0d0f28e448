//! Learned Q-functions (thesis 5.4.4-5.4.5, 6.4.4): ONNX Q models (`docs/learning.md`, "Q
//! models") run by tract as asp-search [`QFunction`]s, and the ε-greedy rollout policy over them
//! that `asp plan --objective ... --q MODEL[,MODEL]` uses.
//!
//! Each search thread gets its own [`QWorker`], which builds the graph builder of the model's
//! maps on its first call and reuses its buffers; the model's plans are shared (one per padded
//! size, see [`GraphModel`]). The values of every feasible action of a state come from one
//! inference.

use crate::error::{LearnError, Result};
use crate::model::{GraphModel, ModelKind};
use asp_search::policy::{EpsilonGreedy, Policy, PolicyContext, QFunction, QUse, QWorker};
use asp_search::qgraph::{self, QGraph, QGraphBuilder, QGraphConfig};
use asp_search::SearchError;
use std::path::Path;
use std::sync::Arc;

/// The smallest value a learned Q-function reports: the product over several objectives
/// (thesis 6.4.4) needs positive factors.
pub const MIN_Q: f64 = 1e-6;

/// A Q model as a [`QFunction`].
#[derive(Debug, Clone)]
pub struct OnnxQ {
    model: Arc<GraphModel>,
    config: QGraphConfig,
    objective: String,
}

impl OnnxQ {
    /// Loads the Q model at `path` for maps with `directions` directions (the square of the
    /// maps' resolution): its features must be `asp-q/1` with that many directions.
    pub fn load(path: impl AsRef<Path>, directions: usize) -> Result<Self> {
        Self::new(Arc::new(GraphModel::open_kind(path, ModelKind::Q)?), directions)
    }

    /// A Q-function of a loaded Q model (see [`load`](Self::load)).
    pub fn new(model: Arc<GraphModel>, directions: usize) -> Result<Self> {
        let mismatch = |m: String| LearnError::Mismatch { path: model.path().to_string(), mismatch: m };
        let config = parse_features(model.features())
            .ok_or_else(|| mismatch(format!("features '{}' are not {} features", model.features(), qgraph::FEATURES)))?;
        if config.directions != directions {
            return Err(mismatch(format!(
                "trained on maps with {} directions, these maps have {directions} (use the resolution it was trained with)",
                config.directions
            )));
        }
        model.check_features(&config.features(), config.node_dim(), config.edge_dim())?;
        let objective = model
            .metadata()
            .get("asp.objective")
            .cloned()
            .ok_or_else(|| mismatch("no metadata property 'asp.objective' (the objective the model estimates)".into()))?;
        Ok(OnnxQ { model, config, objective })
    }

    /// The objective whose return the model estimates (`asp.objective`).
    pub fn objective(&self) -> &str {
        &self.objective
    }

    /// The model.
    pub fn model(&self) -> &Arc<GraphModel> {
        &self.model
    }

    /// The graph features the model reads.
    pub fn config(&self) -> QGraphConfig {
        self.config
    }
}

/// `asp-q/1 directions=D neighbours=K` into its parameters.
pub fn parse_features(features: &str) -> Option<QGraphConfig> {
    let mut words = features.split_whitespace();
    if words.next()? != qgraph::FEATURES {
        return None;
    }
    let (mut directions, mut neighbours) = (None, None);
    for w in words {
        let (key, value) = w.split_once('=')?;
        let v: usize = value.parse().ok()?;
        match key {
            "directions" => directions = Some(v),
            "neighbours" => neighbours = Some(v),
            _ => return None,
        }
    }
    let config = QGraphConfig { directions: directions?, neighbours: neighbours? };
    (config.neighbours > 0).then_some(config)
}

impl QFunction for OnnxQ {
    fn q_values(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        self.worker().q_values(ctx, actions, out)
    }

    fn for_worker(&self, _thread: usize) -> asp_search::Result<Box<dyn QWorker + '_>> {
        Ok(Box::new(self.worker()))
    }
}

impl OnnxQ {
    fn worker(&self) -> OnnxQWorker<'_> {
        OnnxQWorker { q: self, builder: None, graph: QGraph::default() }
    }
}

/// One thread's evaluator: the graph builder of the maps it met first, and reused buffers.
struct OnnxQWorker<'q> {
    q: &'q OnnxQ,
    builder: Option<QGraphBuilder>,
    graph: QGraph,
}

impl QWorker for OnnxQWorker<'_> {
    fn q_values(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        let plugin = |reason: String| SearchError::plugin(format!("Q-function {}", self.q.model.path()), reason);
        let maps = ctx.maps();
        if maps.num_directions() != self.q.config.directions {
            return Err(plugin(format!(
                "trained on maps with {} directions, the search's have {}",
                self.q.config.directions,
                maps.num_directions()
            )));
        }
        let builder = self.builder.get_or_insert_with(|| QGraphBuilder::new(maps, self.q.config.neighbours));
        let history = qgraph::direction_history(ctx.problem, ctx.memory);
        builder.build(ctx.state, history, actions, &mut self.graph);
        let g = &self.graph;
        let (n, e) = (g.num_nodes(), g.num_edges());
        let scores = self.q.model.score(&g.x, n, &g.edge_index, e, &g.edge_attr).map_err(|err| plugin(err.to_string()))?;
        let parts = &g.nodes[..n - 1];
        for (o, &a) in out.iter_mut().zip(actions) {
            let k = parts.binary_search(&(a as i64)).map_err(|_| plugin(format!("action {a} is not a present part")))?;
            let v = f64::from(scores[k]);
            if !v.is_finite() {
                return Err(plugin(format!("the model gave {v} for part {a}")));
            }
            *o = v.max(MIN_Q);
        }
        Ok(())
    }
}

/// The ε-greedy rollout policy (thesis 5.4.5, 6.4.4) over the Q models at `paths`, one per
/// objective in `objectives`' order (each model's `asp.objective` must be that objective), for
/// maps with `directions` directions, evaluated where `uses` says (rollouts, expansions or both).
pub fn epsilon_greedy(paths: &[impl AsRef<Path>], objectives: &[&str], epsilon: f64, directions: usize, uses: QUse) -> Result<Arc<dyn Policy>> {
    let label = |p: &dyn AsRef<Path>| p.as_ref().display().to_string();
    if paths.len() != objectives.len() {
        let names = paths.iter().map(|p| label(p)).collect::<Vec<_>>().join(",");
        return Err(LearnError::Mismatch {
            path: names,
            mismatch: format!("{} Q models for {} objectives ({}): give one per objective, in their order", paths.len(), objectives.len(), objectives.join(",")),
        });
    }
    let mut qs: Vec<Arc<dyn QFunction>> = Vec::with_capacity(paths.len());
    for (path, objective) in paths.iter().zip(objectives) {
        let q = OnnxQ::load(path, directions)?;
        if q.objective() != *objective {
            return Err(LearnError::Mismatch {
                path: label(path),
                mismatch: format!("estimates objective '{}', but its place in the list is that of '{objective}'", q.objective()),
            });
        }
        qs.push(Arc::new(q));
    }
    let policy = EpsilonGreedy::new(epsilon, qs).map_err(|e| LearnError::Input { path: "epsilon".into(), reason: e.to_string() })?;
    Ok(Arc::new(policy.using(uses)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn features_parse_and_refuse() {
        assert_eq!(parse_features("asp-q/1 directions=81 neighbours=8"), Some(QGraphConfig { directions: 81, neighbours: 8 }));
        assert_eq!(parse_features("asp-q/1 directions=25 neighbours=3").map(|c| c.features()).as_deref(), Some("asp-q/1 directions=25 neighbours=3"));
        assert_eq!(parse_features("asp-graph/2 radius_bins=8"), None);
        assert_eq!(parse_features("asp-q/1 directions=81"), None);
        assert_eq!(parse_features("asp-q/1 directions=81 neighbours=0"), None);
        assert_eq!(parse_features("asp-q/1 directions=x neighbours=8"), None);
    }
}
