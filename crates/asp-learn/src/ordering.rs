//! The learned part ordering of thesis 3.5.3: in every state, test the parts in order of
//! descending predicted removability.
//!
//! [`GnnSource`] is the [`OrderingSource`] of `--order gnn`: it holds the loaded model and the
//! graph configuration, computes the [`AssemblyGraph`] of a model once in
//! [`prepare`](OrderingSource::prepare), and hands out [`GnnOrdering`]s, one per search, each with
//! its own scratch buffers. Ties (equal scores) keep the order of the thesis' initial ordering:
//! the parts are first put in the search's `shuffled` order of its seed, then sorted stably, so
//! `gnn` and `shuffled` runs of one seed start from the same predefined order (thesis 3.6.4).

use std::sync::Arc;

use asp_geom::graph::{AssemblyGraph, GraphConfig, StateGraph};
use asp_geom::{PartSet, World};
use asp_search::ordering::Shuffled;
use asp_search::{OrderingFactory, OrderingSource, PartOrdering, SearchError};

use crate::error::Result;
use crate::model::RemovabilityModel;

impl RemovabilityModel {
    /// Score every node of a state graph ([`AssemblyGraph::state`]); outputs follow
    /// `graph.nodes`.
    pub fn score_graph(&self, graph: &StateGraph) -> Result<Vec<f32>> {
        self.score(&graph.x, graph.num_nodes(), &graph.edge_index, graph.num_edges(), &graph.edge_attr)
    }

    /// Check that the model fits the features of `graph`.
    pub fn check_graph(&self, graph: &AssemblyGraph) -> Result<()> {
        self.check_features(&graph.features(), graph.node_dim(), graph.edge_dim())
    }
}

/// Orders the candidate parts of a state by descending predicted removability.
pub struct GnnOrdering {
    /// The initial ordering that breaks ties (`None`: the incoming order).
    tie: Option<Shuffled>,
    graph: Arc<AssemblyGraph>,
    model: Arc<RemovabilityModel>,
    scratch: StateGraph,
    /// Score of each part of the last scored state (`-inf` for parts not in it).
    by_part: Vec<f32>,
    failures: u64,
    first_failure: Option<String>,
}

impl std::fmt::Debug for GnnOrdering {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GnnOrdering").field("model", &self.model.path()).field("failures", &self.failures).finish_non_exhaustive()
    }
}

impl GnnOrdering {
    /// An ordering for the model whose graph is `graph`; fails when the model was trained on
    /// other features.
    pub fn new(graph: Arc<AssemblyGraph>, model: Arc<RemovabilityModel>) -> Result<Self> {
        model.check_graph(&graph)?;
        let parts = graph.num_parts();
        Ok(GnnOrdering {
            tie: None,
            graph,
            model,
            scratch: StateGraph::default(),
            by_part: vec![f32::NEG_INFINITY; parts],
            failures: 0,
            first_failure: None,
        })
    }

    /// The predicted removability of every part of the model in `state` (`-inf` for parts
    /// that are not present).
    pub fn scores(&mut self, state: &PartSet) -> Result<&[f32]> {
        self.graph.state_into(state, &mut self.scratch);
        let scores = self.model.score_graph(&self.scratch)?;
        self.by_part.fill(f32::NEG_INFINITY);
        for (&part, &p) in self.scratch.nodes.iter().zip(&scores) {
            self.by_part[part] = if p.is_nan() { f32::NEG_INFINITY } else { p };
        }
        Ok(&self.by_part)
    }

    /// How many states could not be scored (their parts kept the incoming order).
    pub fn failures(&self) -> u64 {
        self.failures
    }

    /// The error of the first state that could not be scored.
    pub fn first_failure(&self) -> Option<&str> {
        self.first_failure.as_deref()
    }
}

impl PartOrdering for GnnOrdering {
    /// Sorts `parts` by descending score, stably. The model was checked and run at load, so
    /// inference does not fail on valid state graphs; if it does, `parts` keeps its order and
    /// the failure is counted ([`GnnOrdering::failures`]).
    fn order(&mut self, state: &PartSet, parts: &mut Vec<usize>) {
        if let Some(tie) = &mut self.tie {
            tie.order(state, parts);
        }
        match self.scores(state) {
            Ok(_) => {
                let by_part = &self.by_part;
                let score = |p: usize| by_part.get(p).copied().unwrap_or(f32::NEG_INFINITY);
                parts.sort_by(|&a, &b| score(b).total_cmp(&score(a)));
            }
            Err(err) => {
                self.failures += 1;
                self.first_failure.get_or_insert_with(|| err.to_string());
            }
        }
    }
}

/// Makes a [`GnnOrdering`] per search for one model graph.
pub struct GnnFactory {
    graph: Arc<AssemblyGraph>,
    model: Arc<RemovabilityModel>,
}

impl std::fmt::Debug for GnnFactory {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GnnFactory").field("model", &self.model.path()).field("parts", &self.graph.num_parts()).finish()
    }
}

impl GnnFactory {
    /// A factory for `graph`; fails when the model was trained on other features.
    pub fn new(graph: Arc<AssemblyGraph>, model: Arc<RemovabilityModel>) -> Result<Self> {
        model.check_graph(&graph)?;
        Ok(GnnFactory { graph, model })
    }

    /// The model graph the orderings score.
    pub fn graph(&self) -> &Arc<AssemblyGraph> {
        &self.graph
    }
}

impl OrderingFactory for GnnFactory {
    fn name(&self) -> String {
        "gnn".into()
    }

    fn make(&self, num_parts: usize, seed: u64) -> Box<dyn PartOrdering> {
        let parts = self.graph.num_parts();
        Box::new(GnnOrdering {
            tie: Some(Shuffled::new(num_parts, seed)),
            graph: self.graph.clone(),
            model: self.model.clone(),
            scratch: StateGraph::default(),
            by_part: vec![f32::NEG_INFINITY; parts],
            failures: 0,
            first_failure: None,
        })
    }
}

/// The bytes of `models/removability.onnx`, the removability model shipped with asp.
pub const SHIPPED_MODEL: &[u8] = include_bytes!("../../../models/removability.onnx");

/// The `gnn` ordering source: a removability model and the graph features it expects.
#[derive(Debug)]
pub struct GnnSource {
    model: Arc<RemovabilityModel>,
    config: GraphConfig,
}

impl GnnSource {
    /// A source for `model`, computing graphs with `config`; fails when the model was trained
    /// on other features than `config` computes.
    pub fn new(model: Arc<RemovabilityModel>, config: GraphConfig) -> Result<Self> {
        model.check_features(&config.features(), config.node_dim(), config.edge_dim())?;
        Ok(GnnSource { model, config })
    }

    /// The model shipped with asp (`models/removability.onnx`, embedded in the binary; trained by
    /// `scripts/train-removability`), for graphs with the default features.
    pub fn shipped() -> Result<Self> {
        let model = RemovabilityModel::from_bytes(SHIPPED_MODEL, "models/removability.onnx (shipped)")?;
        let config = with_version_of(GraphConfig::default(), &model);
        Self::new(Arc::new(model), config)
    }

    /// Load the model at `path` for graphs computed with `config`; whether edges carry contact
    /// directions (`asp-graph/2`) or not (`asp-graph/1`) follows the model, so models trained on
    /// either feature set keep working.
    pub fn load(path: impl AsRef<std::path::Path>, config: GraphConfig) -> Result<Self> {
        let model = RemovabilityModel::open(path)?;
        let config = with_version_of(config, &model);
        model.check_features(&config.features(), config.node_dim(), config.edge_dim())?;
        Ok(GnnSource { model: Arc::new(model), config })
    }

    /// The model.
    pub fn model(&self) -> &Arc<RemovabilityModel> {
        &self.model
    }
}

/// `config` with the feature version (contact directions or not) of the model's features string.
fn with_version_of(config: GraphConfig, model: &RemovabilityModel) -> GraphConfig {
    match GraphConfig::from_features(model.features()) {
        Some(m) => GraphConfig { contact_directions: m.contact_directions, ..config },
        None => config,
    }
}

impl OrderingSource for GnnSource {
    fn name(&self) -> String {
        "gnn".into()
    }

    fn prepare(&self, world: &World) -> asp_search::Result<Arc<dyn OrderingFactory>> {
        let graph = Arc::new(AssemblyGraph::build(world, &self.config)?);
        let factory = GnnFactory::new(graph, self.model.clone()).map_err(|e| SearchError::Config { reason: e.to_string() })?;
        Ok(Arc::new(factory))
    }
}
