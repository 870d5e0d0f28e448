//! Learned Q-functions (thesis 5.4.4-5.4.5, 6.4.4): ONNX Q models (`docs/learning.md`, "Q
//! models") run by tract as asp-search [`QFunction`]s, and the ε-greedy rollout policy over them
//! that `asp plan --objective ... --q MODEL[,MODEL]` uses.
//!
//! Each search thread gets its own [`QWorker`], which builds the graph builder of the model's
//! maps on its first call and reuses its buffers. The values of every feasible action of a state
//! come from one inference: by default the Rust forward pass of [`QNet`] (when the file holds the
//! trainer's architecture and agrees with tract at load), with each part pair's edge encoding
//! cached in the worker, so a state costs its nodes and the per-edge layers only; otherwise, or
//! with [`OnnxQ::tract_only`], the graph with its edge attributes run by tract (one plan per
//! padded size, see [`GraphModel`]).

use crate::error::{LearnError, Result};
use crate::model::{GraphModel, ModelKind};
use crate::qnet::{GraphView, QNet, Scratch};
use asp_geom::distmap::{DirMask, MapState};
use asp_search::policy::{EpsilonGreedy, Policy, PolicyContext, QFunction, QUse, QWorker};
use asp_search::qgraph::{self, QGraph, QGraphBuilder, QGraphConfig};
use asp_search::SearchError;
use std::path::Path;
use std::sync::Arc;

/// The smallest value a learned Q-function reports: the product over several objectives
/// (thesis 6.4.4) needs positive factors.
pub const MIN_Q: f64 = 1e-6;

/// `values` (one per action) into `out`, each at least [`MIN_Q`]; a value that is not finite is
/// the model's error, naming the part.
fn checked_values(
    out: &mut [f64],
    values: impl Iterator<Item = f32>,
    actions: &[usize],
    plugin: impl Fn(String) -> SearchError,
) -> asp_search::Result<()> {
    for (o, (v, &a)) in out.iter_mut().zip(values.zip(actions)) {
        let v = f64::from(v);
        if !v.is_finite() {
            return Err(plugin(format!("the model gave {v} for part {a}")));
        }
        *o = v.max(MIN_Q);
    }
    Ok(())
}

/// A Q model as a [`QFunction`].
#[derive(Debug, Clone)]
pub struct OnnxQ {
    model: Arc<GraphModel>,
    config: QGraphConfig,
    objective: String,
    /// The Rust forward pass, or why the model has none.
    net: std::result::Result<Arc<QNet>, String>,
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
        let net = QNet::from_model(model.as_ref()).map(Arc::new);
        Ok(OnnxQ { model, config, objective, net })
    }

    /// The same Q-function evaluated by tract on the full graph (edge attributes rebuilt per
    /// state) instead of the Rust forward pass: the reference of the parity tests and benchmarks.
    pub fn tract_only(mut self) -> Self {
        self.net = Err("tract_only".into());
        self
    }

    /// Whether states are scored by the Rust forward pass ([`QNet`]); `Err` says why not.
    pub fn rust_forward(&self) -> std::result::Result<(), &str> {
        self.net.as_ref().map(|_| ()).map_err(String::as_str)
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
        GraphWorker::new(std::slice::from_ref(self)).q_values(ctx, actions, out)
    }

    fn for_worker(&self, _thread: usize) -> asp_search::Result<Box<dyn QWorker + '_>> {
        Ok(Box::new(GraphWorker::new(std::slice::from_ref(self))))
    }
}

/// The product of several Q models' values (one per objective, thesis 6.4.4: the hypervolume of
/// one point against the origin), evaluated on one state graph per state: models that read the
/// same features share the graph's nodes and edge list, and each runs its own forward pass on
/// them. Each value is clamped to at least [`MIN_Q`] before the product, so the product equals
/// that of the models evaluated one by one, to the bit.
#[derive(Debug, Clone)]
pub struct QProduct {
    models: Vec<OnnxQ>,
}

impl QProduct {
    /// The product over `models` (at least one).
    pub fn new(models: Vec<OnnxQ>) -> Result<Self> {
        if models.is_empty() {
            return Err(LearnError::Input { path: "q".into(), reason: "a product of Q models needs at least one model".into() });
        }
        Ok(QProduct { models })
    }

    /// The models, in the product's order.
    pub fn models(&self) -> &[OnnxQ] {
        &self.models
    }
}

impl QFunction for QProduct {
    fn q_values(&self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        GraphWorker::new(&self.models).q_values(ctx, actions, out)
    }

    fn for_worker(&self, _thread: usize) -> asp_search::Result<Box<dyn QWorker + '_>> {
        Ok(Box::new(GraphWorker::new(&self.models)))
    }
}

/// One thread's evaluator of one or more Q models: per distinct feature set a graph builder (made
/// on the first call, for the maps it meets) and its reused graph, and per model its pair cache.
struct GraphWorker<'q> {
    groups: Vec<Group<'q>>,
    values: Vec<f64>,
}

/// The models of one feature set (`K` neighbours): they share the state graph.
struct Group<'q> {
    config: QGraphConfig,
    builder: Option<QGraphBuilder>,
    graph: QGraph,
    members: Vec<Member<'q>>,
}

/// One model of a group and its per-thread caches.
struct Member<'q> {
    q: &'q OnnxQ,
    fast: PairCache,
    nodes: NodeCache,
}

/// Ways per part of [`NodeCache`].
const NODE_WAYS: usize = 4;

/// The node encodings (the first layer's output) of one model, per part: a part node's
/// attributes are a function of the part, its [`MapState::row_key`] and whether it is asked
/// about, so each part keeps the encodings of its last [`NODE_WAYS`] keys. The encoding of one
/// row is the same bits as that row encoded among others, so the values do not depend on what
/// the cache held.
#[derive(Default)]
struct NodeCache {
    parts: usize,
    keys: Vec<([u64; 4], bool)>,
    filled: Vec<bool>,
    next: Vec<u8>,
    encodings: Vec<f32>,
    /// The encoded nodes of the current state, and scratch.
    h0: Vec<f32>,
    asked: Vec<bool>,
    row: Vec<f32>,
    scratch: Vec<f32>,
}

impl NodeCache {
    /// The slot of part `i`'s encoding for `key`, encoding it when it is not kept.
    fn slot(&mut self, net: &QNet, builder: &QGraphBuilder, state: &mut MapState<'_>, i: usize, key: ([u64; 4], bool)) -> usize {
        let first = i * NODE_WAYS;
        if let Some(w) = (first..first + NODE_WAYS).find(|&s| self.filled[s] && self.keys[s] == key) {
            return w;
        }
        let s = first + self.next[i] as usize;
        self.next[i] = ((self.next[i] as usize + 1) % NODE_WAYS) as u8;
        self.row.resize(builder.config().node_dim(), 0.0);
        builder.node_row(state, i, key.1, &mut self.row);
        let w = net.width();
        net.encode_nodes(&self.row, 1, &mut self.encodings[s * w..(s + 1) * w], &mut self.scratch);
        self.keys[s] = key;
        self.filled[s] = true;
        s
    }
}

impl<'q> GraphWorker<'q> {
    fn new(models: &'q [OnnxQ]) -> Self {
        let mut groups: Vec<Group<'q>> = Vec::new();
        for q in models {
            let member = Member { q, fast: PairCache::default(), nodes: NodeCache::default() };
            match groups.iter_mut().find(|g| g.config == q.config) {
                Some(g) => g.members.push(member),
                None => groups.push(Group { config: q.config, builder: None, graph: QGraph::default(), members: vec![member] }),
            }
        }
        GraphWorker { groups, values: Vec::new() }
    }
}
/// The Rust forward pass's per-thread state: each part pair's edge encoding, computed the first
/// time the pair is an edge (an edge's attributes depend on its two parts only), and buffers.
#[derive(Default)]
struct PairCache {
    /// Parts of the maps (the slot table is `parts × parts`, target-major).
    parts: usize,
    /// Per `(target, source)`: the offset of its encoding in `encodings`, `u32::MAX` until known.
    slot: Vec<u32>,
    encodings: Vec<f32>,
    /// The context node's edge encoding (the same for every target).
    context: Vec<f32>,
    row: Vec<f32>,
    row_scratch: Vec<f32>,
    edges: Vec<f32>,
    sources: Vec<u32>,
    targets: Vec<u32>,
    wanted: Vec<usize>,
    values: Vec<f32>,
    scratch: Scratch,
}

impl PairCache {
    fn prepare(&mut self, net: &QNet, builder: &QGraphBuilder, maps: &asp_geom::distmap::DistanceMaps) {
        let n = maps.num_parts();
        if self.parts == n && !self.context.is_empty() {
            return;
        }
        self.parts = n;
        self.slot = vec![u32::MAX; n * n];
        self.encodings.clear();
        self.row.resize(net.edge_dim(), 0.0);
        self.context = vec![0.0; net.width()];
        builder.edge_attributes(maps, 0, None, &mut self.row);
        net.encode_edge(&self.row, &mut self.context, &mut self.row_scratch);
    }

    /// The edges of the state graph `g` (its last node the context) as the forward pass reads
    /// them: `sources`, `targets` and each edge's encoding in `edges`, from the cache.
    fn encode_edges(&mut self, net: &QNet, builder: &QGraphBuilder, maps: &asp_geom::distmap::DistanceMaps, g: &QGraph) {
        self.prepare(net, builder, maps);
        let (n, e, w) = (g.num_nodes(), g.num_edges(), net.width());
        let context = n - 1;
        self.edges.clear();
        self.sources.clear();
        self.targets.clear();
        for k in 0..e {
            let (s_pos, t_pos) = (g.edge_index[k] as usize, g.edge_index[e + k] as usize);
            self.sources.push(s_pos as u32);
            self.targets.push(t_pos as u32);
            if s_pos == context {
                self.edges.extend_from_slice(&self.context);
            } else {
                let at = self.pair(net, builder, maps, g.nodes[t_pos] as usize, g.nodes[s_pos] as usize);
                self.edges.extend_from_slice(&self.encodings[at..at + w]);
            }
        }
    }

    /// The offset of the encoding of the edge from part `s` to part `t` in `encodings`.
    fn pair(&mut self, net: &QNet, builder: &QGraphBuilder, maps: &asp_geom::distmap::DistanceMaps, t: usize, s: usize) -> usize {
        let key = t * self.parts + s;
        if self.slot[key] == u32::MAX {
            let at = self.encodings.len();
            self.encodings.resize(at + net.width(), 0.0);
            builder.edge_attributes(maps, t, Some(s), &mut self.row);
            net.encode_edge(&self.row, &mut self.encodings[at..], &mut self.row_scratch);
            self.slot[key] = at as u32;
        }
        self.slot[key] as usize
    }
}

impl QWorker for GraphWorker<'_> {
    fn q_values(&mut self, ctx: &mut PolicyContext<'_, '_>, actions: &[usize], out: &mut [f64]) -> asp_search::Result<()> {
        let maps = ctx.maps();
        let history = qgraph::direction_history(ctx.problem, ctx.memory);
        out.fill(1.0);
        self.values.resize(actions.len(), 0.0);
        for group in &mut self.groups {
            if maps.num_directions() != group.config.directions {
                let q = group.members[0].q;
                return Err(SearchError::plugin(
                    format!("Q-function {}", q.model.path()),
                    format!("trained on maps with {} directions, the search's have {}", group.config.directions, maps.num_directions()),
                ));
            }
            let builder = group.builder.get_or_insert_with(|| QGraphBuilder::new(maps, group.config.neighbours));
            let fast = group.members.iter().all(|m| m.q.net.is_ok());
            // the Rust forward passes need the nodes and edges only (node encodings are cached by
            // part and row key); tract needs the edge attributes too
            if fast {
                builder.build_edges(ctx.state, &mut group.graph);
            } else {
                builder.build(ctx.state, history, actions, &mut group.graph);
            }
            for member in &mut group.members {
                if fast {
                    member.encoded_values(builder, &group.graph, ctx.state, history, actions, &mut self.values)?;
                } else {
                    member.values(builder, &group.graph, maps, actions, &mut self.values)?;
                }
                for (o, v) in out.iter_mut().zip(&self.values) {
                    *o *= v;
                }
            }
        }
        Ok(())
    }
}

impl Member<'_> {
    /// [`values`](Self::values) from the state's nodes and edges only (`g` by
    /// [`QGraphBuilder::build_edges`]): part nodes' encodings come from the node cache, the
    /// context node's is made for `history`.
    #[allow(clippy::too_many_arguments)]
    fn encoded_values(
        &mut self,
        builder: &QGraphBuilder,
        g: &QGraph,
        state: &mut MapState<'_>,
        history: Option<DirMask>,
        actions: &[usize],
        out: &mut [f64],
    ) -> asp_search::Result<()> {
        let plugin = |reason: String| SearchError::plugin(format!("Q-function {}", self.q.model.path()), reason);
        let Ok(net) = &self.q.net else { return Err(plugin("no Rust forward pass".into())) };
        let maps = state.maps();
        let n = g.num_nodes();
        let parts = &g.nodes[..n - 1];
        let w = net.width();
        let cache = &mut self.nodes;
        if cache.parts != maps.num_parts() {
            let slots = maps.num_parts() * NODE_WAYS;
            *cache = NodeCache {
                parts: maps.num_parts(),
                keys: vec![([0; 4], false); slots],
                filled: vec![false; slots],
                next: vec![0; maps.num_parts()],
                encodings: vec![0.0; slots * w],
                ..NodeCache::default()
            };
        }
        self.fast.wanted.clear();
        for &a in actions {
            let k = parts.binary_search(&(a as i64)).map_err(|_| plugin(format!("action {a} is not a present part")))?;
            self.fast.wanted.push(k);
        }
        cache.h0.resize(n * w, 0.0);
        cache.asked.clear();
        cache.asked.resize(n, false);
        for &k in &self.fast.wanted {
            cache.asked[k] = true;
        }
        for (k, &i) in parts.iter().enumerate() {
            let flag = cache.asked[k];
            let i = i as usize;
            let s = cache.slot(net, builder, state, i, (state.row_key(i), flag));
            cache.h0[k * w..(k + 1) * w].copy_from_slice(&cache.encodings[s * w..(s + 1) * w]);
        }
        cache.row.resize(builder.config().node_dim(), 0.0);
        builder.context_row(history, &mut cache.row);
        net.encode_nodes(&cache.row, 1, &mut cache.h0[(n - 1) * w..n * w], &mut cache.scratch);
        let c = &mut self.fast;
        c.encode_edges(net, builder, maps, g);
        c.values.resize(actions.len(), 0.0);
        let graph = GraphView { x: &[], h0: Some(&cache.h0), n, sources: &c.sources, targets: &c.targets, edges: &c.edges };
        net.forward(graph, &c.wanted, &mut c.values, &mut c.scratch);
        checked_values(out, c.values.iter().copied(), actions, plugin)
    }

    /// The model's values of `actions` in the state whose graph is `g` (its structure; with edge
    /// attributes when the model runs on tract), each at least [`MIN_Q`].
    fn values(
        &mut self,
        builder: &QGraphBuilder,
        g: &QGraph,
        maps: &asp_geom::distmap::DistanceMaps,
        actions: &[usize],
        out: &mut [f64],
    ) -> asp_search::Result<()> {
        let plugin = |reason: String| SearchError::plugin(format!("Q-function {}", self.q.model.path()), reason);
        let (n, e) = (g.num_nodes(), g.num_edges());
        let parts = &g.nodes[..n - 1];
        if let Ok(net) = &self.q.net {
            let c = &mut self.fast;
            c.encode_edges(net, builder, maps, g);
            c.wanted.clear();
            for &a in actions {
                let k = parts.binary_search(&(a as i64)).map_err(|_| plugin(format!("action {a} is not a present part")))?;
                c.wanted.push(k);
            }
            c.values.resize(actions.len(), 0.0);
            let graph = GraphView { x: &g.x, h0: None, n, sources: &c.sources, targets: &c.targets, edges: &c.edges };
            net.forward(graph, &c.wanted, &mut c.values, &mut c.scratch);
            return checked_values(out, c.values.iter().copied(), actions, plugin);
        }
        let scores = self.q.model.score(&g.x, n, &g.edge_index, e, &g.edge_attr).map_err(|err| plugin(err.to_string()))?;
        let mut wanted = Vec::with_capacity(actions.len());
        for &a in actions {
            let k = parts.binary_search(&(a as i64)).map_err(|_| plugin(format!("action {a} is not a present part")))?;
            wanted.push(scores[k]);
        }
        checked_values(out, wanted.into_iter(), actions, plugin)
    }
}

/// The ε-greedy rollout policy (thesis 5.4.5, 6.4.4) over the Q models at `paths`, one per
/// objective in `objectives`' order (each model's `asp.objective` must be that objective), for
/// maps with `directions` directions, evaluated where `uses` says (rollouts, expansions or both).
pub fn epsilon_greedy(
    paths: &[impl AsRef<Path>],
    objectives: &[&str],
    epsilon: f64,
    directions: usize,
    uses: QUse,
) -> Result<Arc<dyn Policy>> {
    let models = open_q_models(paths, objectives)?;
    epsilon_greedy_models(&models, objectives, epsilon, directions, uses)
}

/// The Q models at `paths`, one per objective in `objectives`' order, opened and checked to be
/// Q models (their objectives and directions are checked by [`epsilon_greedy_models`], when the
/// maps are known).
///
/// A path spelled [`SHIPPED_Q_NAME`] (`shipped`) stands for the shipped Q of the objective in its
/// place ([`SHIPPED_Q`]); `shipped` alone stands for the shipped Q of every objective.
pub fn open_q_models(paths: &[impl AsRef<Path>], objectives: &[&str]) -> Result<Vec<Arc<GraphModel>>> {
    let is_shipped = |p: &Path| p.as_os_str() == SHIPPED_Q_NAME;
    if paths.len() == 1 && is_shipped(paths[0].as_ref()) && objectives.len() > 1 {
        return objectives.iter().map(|o| shipped_q(o).map(Arc::new)).collect();
    }
    if paths.len() != objectives.len() {
        let names = paths.iter().map(|p| p.as_ref().display().to_string()).collect::<Vec<_>>().join(",");
        return Err(LearnError::Mismatch {
            path: names,
            mismatch: format!(
                "{} Q models for {} objectives ({}): give one per objective, in their order",
                paths.len(),
                objectives.len(),
                objectives.join(",")
            ),
        });
    }
    paths
        .iter()
        .zip(objectives)
        .map(|(p, o)| if is_shipped(p.as_ref()) { shipped_q(o) } else { GraphModel::open_kind(p, ModelKind::Q) }.map(Arc::new))
        .collect()
}

/// The word that names the shipped Q-functions where a Q model's path is asked for.
pub const SHIPPED_Q_NAME: &str = "shipped";

/// The shipped Q-functions of the sequence objectives: (objective, file in the repository, the
/// ONNX bytes). Students (width 16, one layer) distilled from teachers trained on 11 generated
/// assemblies; `scripts/train-q-sequence` rebuilds them byte for byte (docs/learning.md,
/// "Shipped Q-functions"). The robot's is a file, `models/q-robot-path.onnx`, not built in.
pub const SHIPPED_Q: &[(&str, &str, &[u8])] = &[
    ("access", "models/q-access.onnx", include_bytes!("../../../models/q-access.onnx")),
    ("dirchange", "models/q-dirchange.onnx", include_bytes!("../../../models/q-dirchange.onnx")),
    ("pathlen", "models/q-pathlen.onnx", include_bytes!("../../../models/q-pathlen.onnx")),
];

/// The shipped Q-function of `objective` (see [`SHIPPED_Q`]), or an error naming those there are.
pub fn shipped_q(objective: &str) -> Result<GraphModel> {
    let Some((_, file, bytes)) = SHIPPED_Q.iter().find(|(o, _, _)| *o == objective) else {
        let names: Vec<&str> = SHIPPED_Q.iter().map(|(o, _, _)| *o).collect();
        return Err(LearnError::Mismatch {
            path: SHIPPED_Q_NAME.into(),
            mismatch: format!(
                "no Q-function is shipped for objective '{objective}' (shipped: {}; the robot's is the file models/q-robot-path.onnx)",
                names.join(", ")
            ),
        });
    };
    GraphModel::from_bytes_kind(bytes, &format!("{SHIPPED_Q_NAME}:{file}"), ModelKind::Q)
}

/// [`epsilon_greedy`] over models opened by [`open_q_models`].
pub fn epsilon_greedy_models(
    models: &[Arc<GraphModel>],
    objectives: &[&str],
    epsilon: f64,
    directions: usize,
    uses: QUse,
) -> Result<Arc<dyn Policy>> {
    let mut qs = Vec::with_capacity(models.len());
    for (model, objective) in models.iter().zip(objectives) {
        let q = OnnxQ::new(model.clone(), directions)?;
        if q.objective() != *objective {
            return Err(LearnError::Mismatch {
                path: model.path().to_string(),
                mismatch: format!("estimates objective '{}', but its place in the list is that of '{objective}'", q.objective()),
            });
        }
        qs.push(q);
    }
    // one product over one state graph per state: the same values as one Q-function per model
    let product: Arc<dyn QFunction> = Arc::new(QProduct::new(qs)?);
    let policy =
        EpsilonGreedy::new(epsilon, vec![product]).map_err(|e| LearnError::Input { path: "epsilon".into(), reason: e.to_string() })?;
    Ok(Arc::new(policy.using(uses)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn features_parse_and_refuse() {
        assert_eq!(parse_features("asp-q/1 directions=81 neighbours=8"), Some(QGraphConfig { directions: 81, neighbours: 8 }));
        assert_eq!(
            parse_features("asp-q/1 directions=25 neighbours=3").map(|c| c.features()).as_deref(),
            Some("asp-q/1 directions=25 neighbours=3")
        );
        assert_eq!(parse_features("asp-graph/2 radius_bins=8"), None);
        assert_eq!(parse_features("asp-q/1 directions=81"), None);
        assert_eq!(parse_features("asp-q/1 directions=81 neighbours=0"), None);
        assert_eq!(parse_features("asp-q/1 directions=x neighbours=8"), None);
    }

    /// `shipped` stands for the built-in model of each objective in its place, alone for all of
    /// them; each built-in model loads as the Q of its own objective on the default maps (81
    /// directions) and scores through the Rust forward pass.
    #[test]
    fn shipped_names_the_built_in_q_of_each_objective() {
        let objectives = ["access", "dirchange", "pathlen"];
        let all = open_q_models(&[SHIPPED_Q_NAME], &objectives).unwrap();
        assert_eq!(all.len(), 3);
        for (model, objective) in all.iter().zip(objectives) {
            let q = OnnxQ::new(model.clone(), 81).unwrap();
            assert_eq!(q.objective(), objective);
            assert_eq!(model.path(), format!("shipped:models/q-{objective}.onnx"));
            assert!(q.rust_forward().is_ok(), "{objective}: {:?}", q.rust_forward());
        }
        // in place of one file of a list: the objective of that place
        let one = open_q_models(&["shipped"], &["dirchange"]).unwrap();
        assert_eq!(OnnxQ::new(one[0].clone(), 81).unwrap().objective(), "dirchange");
        let e = open_q_models(&["no/such/q_access.onnx", "shipped"], &["access", "dirchange"]).unwrap_err().to_string();
        assert!(e.contains("no/such/q_access.onnx"), "{e}");
        let e = open_q_models(&["shipped"], &["robot-path"]).unwrap_err().to_string();
        assert!(e.contains("no Q-function is shipped for objective 'robot-path'") && e.contains("access, dirchange, pathlen"), "{e}");
    }
}
