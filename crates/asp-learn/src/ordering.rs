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
use crate::model::{Checker, RemovabilityModel};
use crate::qnet::{GraphView, QNet};

impl RemovabilityModel {
    /// Score every node of a state graph ([`AssemblyGraph::state`]); outputs follow
    /// `graph.nodes`. Runs the Rust forward pass ([`RemovabilityModel::fast_net`]) when the model has
    /// one, tract otherwise ([`score_graph_tract`](Self::score_graph_tract)).
    pub fn score_graph(&self, graph: &StateGraph) -> Result<Vec<f32>> {
        let mut out = Vec::new();
        self.score_graph_into(graph, &mut out, &mut Scratch::default())?;
        Ok(out)
    }

    /// [`score_graph`](Self::score_graph) into `out`, with reusable buffers.
    pub fn score_graph_into(&self, graph: &StateGraph, out: &mut Vec<f32>, scratch: &mut Scratch) -> Result<()> {
        match self.fast_net() {
            Some(net) => {
                let n = graph.num_nodes();
                out.clear();
                out.resize(n, 0.0);
                if n > 0 {
                    scratch.wanted.clear();
                    scratch.wanted.extend(0..n);
                    net.forward_graph(&graph.x, n, &graph.edge_index, &graph.edge_attr, &scratch.wanted, out, &mut scratch.net);
                }
                Ok(())
            }
            None => {
                *out = self.score_graph_tract(graph)?;
                Ok(())
            }
        }
    }

    /// Score every node of a state graph with tract (the reference the Rust forward pass is
    /// checked against).
    pub fn score_graph_tract(&self, graph: &StateGraph) -> Result<Vec<f32>> {
        self.score(&graph.x, graph.num_nodes(), &graph.edge_index, graph.num_edges(), &graph.edge_attr)
    }

    /// Check that the model fits the features of `graph`.
    pub fn check_graph(&self, graph: &AssemblyGraph) -> Result<()> {
        self.check_features(&graph.features(), graph.node_dim(), graph.edge_dim())
    }
}

/// Reusable buffers of [`RemovabilityModel::score_graph_into`].
#[derive(Debug, Default)]
pub struct Scratch {
    net: crate::qnet::Scratch,
    wanted: Vec<usize>,
}

/// What the Rust forward pass reads of one model graph that no state changes: every part's
/// node encoding and every edge's encoding (node and edge attributes are functions of the part
/// and the pair alone), computed once per graph and shared by its orderings.
struct Encoded {
    net: Arc<QNet>,
    /// `[num_parts, width]`.
    nodes: Vec<f32>,
    /// `[graph edges, width]`, in the graph's edge order.
    edges: Vec<f32>,
}

impl Encoded {
    /// The encodings of `graph` when `model` has a Rust forward pass.
    fn of(graph: &AssemblyGraph, model: &RemovabilityModel) -> Option<Arc<Self>> {
        let net = model.fast_net()?.clone();
        let w = net.width();
        let mut scratch = Vec::new();
        let mut nodes = vec![0.0; graph.num_parts() * w];
        net.encode_nodes(graph.nodes_flat(), graph.num_parts(), &mut nodes, &mut scratch);
        let mut edges = vec![0.0; graph.num_edges() * w];
        for (k, out) in edges.chunks_exact_mut(w).enumerate() {
            net.encode_edge(graph.edge_attr(k), out, &mut scratch);
        }
        Some(Arc::new(Encoded { net, nodes, edges }))
    }
}

/// The per-state buffers of the cached forward pass.
#[derive(Default)]
struct StateBuffers {
    /// Position of each present part among the state's nodes.
    rank: Vec<u32>,
    nodes: Vec<usize>,
    h0: Vec<f32>,
    sources: Vec<u32>,
    targets: Vec<u32>,
    edges: Vec<f32>,
    wanted: Vec<usize>,
    out: Vec<f32>,
    net: crate::qnet::Scratch,
}

/// Orders the candidate parts of a state by descending predicted removability.
pub struct GnnOrdering {
    /// The initial ordering that breaks ties (`None`: the incoming order).
    tie: Option<Shuffled>,
    graph: Arc<AssemblyGraph>,
    model: Arc<RemovabilityModel>,
    scratch: StateGraph,
    buffers: Scratch,
    out: Vec<f32>,
    /// The cached encodings of the Rust forward pass (`None`: tract on every state).
    encoded: Option<Arc<Encoded>>,
    state: StateBuffers,
    /// Score of each part of the last scored state (`-inf` for parts not in it).
    by_part: Vec<f32>,
    failures: u64,
    first_failure: Option<String>,
    /// States with at most one candidate part, ordered without an inference.
    skipped: u64,
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
        let encoded = Encoded::of(&graph, &model);
        Ok(GnnOrdering::with(graph, model, encoded, None))
    }

    /// An ordering on `graph` with the model's node and edge encodings `encoded` (shared by the
    /// orderings of one factory) and ties broken by `tie` (else by index).
    fn with(graph: Arc<AssemblyGraph>, model: Arc<RemovabilityModel>, encoded: Option<Arc<Encoded>>, tie: Option<Shuffled>) -> Self {
        let parts = graph.num_parts();
        GnnOrdering {
            tie,
            encoded,
            state: StateBuffers::default(),
            graph,
            model,
            scratch: StateGraph::default(),
            buffers: Scratch::default(),
            out: Vec::new(),
            by_part: vec![f32::NEG_INFINITY; parts],
            failures: 0,
            first_failure: None,
            skipped: 0,
        }
    }

    /// The predicted removability of every part of the model in `state` (`-inf` for parts
    /// that are not present).
    pub fn scores(&mut self, state: &PartSet) -> Result<&[f32]> {
        if let Some(encoded) = &self.encoded {
            self.score_cached(&encoded.clone(), state);
            return Ok(&self.by_part);
        }
        self.graph.state_into(state, &mut self.scratch);
        self.model.score_graph_into(&self.scratch, &mut self.out, &mut self.buffers)?;
        self.by_part.fill(f32::NEG_INFINITY);
        for (&part, &p) in self.scratch.nodes.iter().zip(&self.out) {
            self.by_part[part] = if p.is_nan() { f32::NEG_INFINITY } else { p };
        }
        Ok(&self.by_part)
    }

    /// [`scores`](Self::scores) by the Rust forward pass from the cached encodings: the state's
    /// nodes and edges are gathered in the order of [`AssemblyGraph::state_into`] (so the sums
    /// run in the same order as on a built state graph and give the same bits).
    fn score_cached(&mut self, encoded: &Encoded, state: &PartSet) {
        let (graph, b, w) = (&self.graph, &mut self.state, encoded.net.width());
        let parts = graph.num_parts();
        b.rank.resize(parts, 0);
        b.nodes.clear();
        b.nodes.extend(state.iter().take_while(|&i| i < parts));
        b.h0.clear();
        for (r, &i) in b.nodes.iter().enumerate() {
            b.rank[i] = r as u32;
            b.h0.extend_from_slice(&encoded.nodes[i * w..(i + 1) * w]);
        }
        b.sources.clear();
        b.targets.clear();
        b.edges.clear();
        let edges = graph.edges();
        for &s in &b.nodes {
            for k in graph.edges_from(s) {
                let t = edges[k].1;
                if state.contains(t) {
                    b.sources.push(b.rank[s]);
                    b.targets.push(b.rank[t]);
                    b.edges.extend_from_slice(&encoded.edges[k * w..(k + 1) * w]);
                }
            }
        }
        let n = b.nodes.len();
        b.wanted.clear();
        b.wanted.extend(0..n);
        b.out.clear();
        b.out.resize(n, 0.0);
        if n > 0 {
            let graph = GraphView { x: &[], h0: Some(&b.h0), n, sources: &b.sources, targets: &b.targets, edges: &b.edges };
            encoded.net.forward(graph, &b.wanted, &mut b.out, &mut b.net);
        }
        self.by_part.fill(f32::NEG_INFINITY);
        for (&part, &p) in b.nodes.iter().zip(&b.out) {
            self.by_part[part] = if p.is_nan() { f32::NEG_INFINITY } else { p };
        }
    }

    /// Whether states are scored by the Rust forward pass from cached encodings (`false`: tract).
    pub fn is_fast(&self) -> bool {
        self.encoded.is_some()
    }

    /// How many states had at most one candidate part and were ordered without an inference.
    pub fn skipped(&self) -> u64 {
        self.skipped
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
        if parts.len() <= 1 {
            // one candidate: no ranking to pay an inference for
            self.skipped += 1;
            return;
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
    encoded: Option<Arc<Encoded>>,
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
        let encoded = Encoded::of(&graph, &model);
        Ok(GnnFactory { graph, model, encoded })
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
        Box::new(GnnOrdering::with(self.graph.clone(), self.model.clone(), self.encoded.clone(), Some(Shuffled::new(num_parts, seed))))
    }
}

/// The bytes of `models/removability.onnx`, the removability model shipped with asp.
pub const SHIPPED_MODEL: &[u8] = include_bytes!("../../../models/removability.onnx");

/// One removability model shipped with asp (embedded in the binary).
#[derive(Debug, Clone, Copy)]
pub struct ShippedModel {
    /// The checker whose labels it was trained on (its `asp.checker`).
    pub checker: Checker,
    /// The ONNX file's bytes.
    pub bytes: &'static [u8],
    /// Its file in the repository, as errors name it.
    pub file: &'static str,
}

/// The shipped removability models, one per checker that has its own; the first (the default
/// checker's) ranks for every checker without one ([`shipped_model`]).
pub const SHIPPED_MODELS: &[ShippedModel] = &[
    ShippedModel { checker: Checker::Default, bytes: SHIPPED_MODEL, file: "models/removability.onnx" },
    ShippedModel { checker: Checker::Physics, bytes: SHIPPED_PHYSICS_MODEL, file: "models/removability-physics.onnx" },
    ShippedModel { checker: Checker::Robot, bytes: SHIPPED_ROBOT_MODEL, file: "models/removability-robot.onnx" },
];

/// The bytes of `models/removability-robot.onnx`, the shipped model of the robot checker
/// (`asp.checker` = robot; trained by `scripts/train-removability-robot`).
pub const SHIPPED_ROBOT_MODEL: &[u8] = include_bytes!("../../../models/removability-robot.onnx");

/// The bytes of `models/removability-physics.onnx`, the shipped model of the physics checker
/// (`asp.checker` = physics; trained by `scripts/train-removability-physics`).
pub const SHIPPED_PHYSICS_MODEL: &[u8] = include_bytes!("../../../models/removability-physics.onnx");

/// The shipped model `--order gnn` uses under `checker`: the one trained on that checker's
/// labels, else the default checker's.
pub fn shipped_model(checker: Checker) -> &'static ShippedModel {
    SHIPPED_MODELS.iter().find(|m| m.checker == checker).unwrap_or(&SHIPPED_MODELS[0])
}

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
        Self::shipped_for(Checker::Default)
    }

    /// The shipped model for runs under `checker` ([`shipped_model`]), for graphs with the
    /// default features.
    pub fn shipped_for(checker: Checker) -> Result<Self> {
        let shipped = shipped_model(checker);
        let model = RemovabilityModel::from_bytes(shipped.bytes, &format!("{} (shipped)", shipped.file))?;
        let config = with_version_of(GraphConfig::default(), &model);
        Self::new(Arc::new(model), config)
    }

    /// [`load`](Self::load) for a run under `checker`: also fails, with one line naming the file
    /// and both checkers, when the model was trained on another checker's labels
    /// ([`RemovabilityModel::check_checker`]).
    pub fn load_for(path: impl AsRef<std::path::Path>, config: GraphConfig, checker: Checker) -> Result<Self> {
        let source = Self::load(path, config)?;
        source.model.check_checker(checker)?;
        Ok(source)
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
