//! Graph models: ONNX files of the contracts in docs/learning.md, run with tract.
//!
//! A model takes one state graph (`x [n, node_dim]`, `edge_index [2, e]`, `edge_attr
//! [e, edge_dim]`) and returns one value per node: a removability in (0, 1)
//! ([`ModelKind::Removability`], output `removability`) or the Q-value of removing the node's
//! part ([`ModelKind::Q`], output `q`). Loading checks every part of the contract (input and
//! output names, element types, ranks, dimensions, the `asp.kind` and `asp.features` metadata)
//! and runs the model once, so a file that loads also runs.
//!
//! tract runs a plan with symbolic `n` and `e` several times slower than a plan whose shapes are
//! known. [`ShapePolicy::Buckets`] (the default) therefore pads every graph up to a bucket of
//! sizes (powers of two and their halves in between: 8, 12, 16, 24, 32, 48, ...) and keeps one
//! optimised plan per bucket. Padding nodes are isolated from the real ones: padded edges join
//! the first padding node to itself, so messages never reach a real node and the real outputs
//! are those of the unpadded graph.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;
use std::sync::{Arc, Mutex};

use tract_onnx::pb;
use tract_onnx::prelude::*;

use crate::error::{one_line, LearnError, Result};
use crate::qnet::{OnnxWeights, QNet};

mod contract;
use contract::{bool_initializer, check_signature, float_initializer};

/// The value of the `asp.kind` metadata property of a removability model.
pub const KIND: &str = "removability";
/// The input names, in contract order.
pub const INPUTS: [&str; 3] = ["x", "edge_index", "edge_attr"];
/// The output name of a removability model.
pub const OUTPUT: &str = "removability";

/// The metadata property naming the removal checker whose labels a removability model was
/// trained on.
pub const CHECKER_KEY: &str = "asp.checker";

/// The removal checker whose labels a removability model ranks for (`asp.checker`): the same
/// part can be removable under one and not under another (a part that slides out without
/// collision may leave the rest toppling in the simulation, or have no grasp for the arm).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Hash)]
pub enum Checker {
    /// Straight-line removal tests with the contact-graph stability check (`--stability
    /// contact`, no robot). A model without `asp.checker` is one of these.
    #[default]
    Default,
    /// The same removal tests with the physics stability check (`--stability physics`).
    Physics,
    /// Removals the robot arm performs (`--robot`).
    Robot,
}

impl Checker {
    /// Every checker, in the order the docs list them.
    pub const ALL: [Checker; 3] = [Checker::Default, Checker::Physics, Checker::Robot];

    /// The `asp.checker` value (and the data set's `checker`).
    pub fn name(self) -> &'static str {
        match self {
            Checker::Default => "default",
            Checker::Physics => "physics",
            Checker::Robot => "robot",
        }
    }

    /// The checker called `name`.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.name() == name)
    }
}

impl std::fmt::Display for Checker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// What a graph model computes per node.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelKind {
    /// The removability of each part (output `removability`, in (0, 1)).
    Removability,
    /// The Q-value of removing each part (output `q`).
    Q,
}

impl ModelKind {
    /// The `asp.kind` metadata value.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Removability => KIND,
            ModelKind::Q => "q",
        }
    }

    /// The output's name.
    pub fn output(self) -> &'static str {
        match self {
            ModelKind::Removability => OUTPUT,
            ModelKind::Q => "q",
        }
    }
}

/// Graphs larger than this (nodes) run on the symbolic plan instead of a padded bucket.
const MAX_BUCKET_NODES: usize = 4096;
/// Graphs larger than this (edges) run on the symbolic plan instead of a padded bucket.
const MAX_BUCKET_EDGES: usize = 65536;

/// How a model's plans treat the dynamic sizes `n` and `e`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShapePolicy {
    /// One plan with symbolic `n` and `e`, for every graph (no padding; slower per call).
    Symbolic,
    /// Pad `n` and `e` up to buckets and keep one optimised plan per bucket (default).
    #[default]
    Buckets,
}

type Plan = TypedRunnableModel;

/// A plan with its idle run states (reused: spawning a state per call allocates per node).
struct Pooled {
    plan: Arc<Plan>,
    idle: Mutex<Vec<TypedSimpleState>>,
}

impl Pooled {
    fn new(plan: Arc<Plan>) -> Arc<Self> {
        Arc::new(Pooled { plan, idle: Mutex::new(Vec::new()) })
    }

    fn run(&self, inputs: TVec<TValue>) -> TractResult<TVec<TValue>> {
        let state = self.idle.lock().unwrap_or_else(|p| p.into_inner()).pop();
        let mut state = match state {
            Some(s) => s,
            None => self.plan.spawn()?,
        };
        let out = state.run(inputs)?;
        self.idle.lock().unwrap_or_else(|p| p.into_inner()).push(state);
        Ok(out)
    }
}

/// A loaded graph model (thread-safe: plans are shared, every call has its own state).
pub struct GraphModel {
    path: String,
    kind: ModelKind,
    metadata: BTreeMap<String, String>,
    features: String,
    /// The checker of its labels (`asp.checker`; [`Checker::Default`] when the file has none).
    checker: Checker,
    node_dim: usize,
    edge_dim: usize,
    /// The decluttered model with symbolic `n` and `e`.
    typed: TypedModel,
    /// The tract input slot of `x`, `edge_index`, `edge_attr`.
    slots: [usize; 3],
    /// The symbols of `n` and `e`, when the inputs declare them as plain symbols.
    symbols: Option<(Symbol, Symbol)>,
    policy: ShapePolicy,
    symbolic: Mutex<Option<Arc<Pooled>>>,
    buckets: Mutex<HashMap<(usize, usize), Arc<Pooled>>>,
    /// The file's float32 initialisers in file order: name, shape, values (the Rust forward
    /// pass of Q models reads its weights here, `qnet/`).
    initializers: Vec<(String, Vec<usize>, Vec<f32>)>,
    /// The file's boolean initialisers: name and values (the `log1p` column masks of the
    /// encoder, read by the Rust forward pass).
    bool_initializers: Vec<(String, Vec<bool>)>,
    /// The Rust forward pass of a removability model (`qnet/`), built on first use; `None`
    /// when the file is not the trainer's architecture (tract then runs every state).
    fast: std::sync::OnceLock<Option<Arc<QNet>>>,
}

/// A removability model (the graph model of `--order gnn`).
pub type RemovabilityModel = GraphModel;

impl std::fmt::Debug for GraphModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GraphModel")
            .field("path", &self.path)
            .field("kind", &self.kind)
            .field("features", &self.features)
            .field("node_dim", &self.node_dim)
            .field("edge_dim", &self.edge_dim)
            .field("policy", &self.policy)
            .finish_non_exhaustive()
    }
}

impl GraphModel {
    /// Load a removability model and check it against the features asp computes: the
    /// `asp.features` string and the node and edge attribute widths of the graph.
    pub fn load(path: impl AsRef<Path>, features: &str, node_dim: usize, edge_dim: usize) -> Result<Self> {
        let model = Self::open(path)?;
        model.check_features(features, node_dim, edge_dim)?;
        Ok(model)
    }

    /// Load a removability model, checking the contract's names, types, ranks and metadata but
    /// not which features it was trained on (see [`check_features`](Self::check_features)).
    pub fn open(path: impl AsRef<Path>) -> Result<Self> {
        Self::open_kind(path, ModelKind::Removability)
    }

    /// Load a model of `kind` (see [`open`](Self::open)).
    pub fn open_kind(path: impl AsRef<Path>, kind: ModelKind) -> Result<Self> {
        let path = path.as_ref();
        let label = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| LearnError::Read { path: label.clone(), reason: format!("cannot read: {e}") })?;
        Self::from_bytes_kind(&bytes, &label, kind)
    }

    /// Load a removability model from the bytes of an ONNX file; `label` names it in errors.
    pub fn from_bytes(bytes: &[u8], label: &str) -> Result<Self> {
        Self::from_bytes_kind(bytes, label, ModelKind::Removability)
    }

    /// Load a model of `kind` from the bytes of an ONNX file; `label` names it in errors.
    pub fn from_bytes_kind(bytes: &[u8], label: &str, kind: ModelKind) -> Result<Self> {
        let proto = onnx()
            .proto_model_for_read(&mut &bytes[..])
            .map_err(|e| LearnError::Read { path: label.to_string(), reason: format!("not an ONNX model: {}", one_line(&e)) })?;
        Self::from_proto(&proto, label, kind)
    }

    fn from_proto(proto: &pb::ModelProto, label: &str, expected: ModelKind) -> Result<Self> {
        let mismatch = |m: String| LearnError::Mismatch { path: label.to_string(), mismatch: m };
        let metadata: BTreeMap<String, String> = proto.metadata_props.iter().map(|p| (p.key.clone(), p.value.clone())).collect();
        let meta = |key: &str| {
            metadata.get(key).ok_or_else(|| mismatch(format!("no metadata property '{key}' (not an asp {} model)", expected.name())))
        };
        let kind = meta("asp.kind")?;
        if kind != expected.name() {
            return Err(mismatch(format!("asp.kind is '{kind}', expected '{}'", expected.name())));
        }
        let features = meta("asp.features")?.clone();
        let meta_dim = |key: &str| -> Result<usize> {
            let v = meta(key)?;
            v.parse::<usize>().ok().filter(|d| *d > 0).ok_or_else(|| mismatch(format!("{key} is '{v}', expected a positive integer")))
        };
        let node_dim = meta_dim("asp.node_dim")?;
        let edge_dim = meta_dim("asp.edge_dim")?;
        let checker = match metadata.get(CHECKER_KEY) {
            None => Checker::Default,
            Some(v) => Checker::parse(v).ok_or_else(|| {
                let names: Vec<&str> = Checker::ALL.iter().map(|c| c.name()).collect();
                mismatch(format!("{CHECKER_KEY} is '{v}', expected one of {}", names.join(", ")))
            })?,
        };
        let graph = proto.graph.as_ref().ok_or_else(|| mismatch("has no graph".into()))?;
        check_signature(graph, node_dim, edge_dim, expected.output()).map_err(mismatch)?;

        let read = |e: TractError| LearnError::Read { path: label.to_string(), reason: one_line(&e) };
        let inference = onnx().model_for_proto_model(proto).map_err(read)?;
        let typed = inference.into_typed().and_then(|m| m.into_decluttered()).map_err(read)?;
        let mut slots = [0; 3];
        for (k, name) in INPUTS.iter().enumerate() {
            slots[k] = typed
                .input_outlets()
                .map_err(read)?
                .iter()
                .position(|o| typed.node(o.node).name == *name)
                .ok_or_else(|| mismatch(format!("tract lost input '{name}'")))?;
        }
        let symbol = |slot: usize, axis: usize| -> Option<Symbol> {
            match &typed.input_fact(slot).ok()?.shape.dims()[axis] {
                TDim::Sym(s) => Some(s.clone()),
                _ => None,
            }
        };
        let symbols = match (symbol(slots[0], 0), symbol(slots[2], 0), symbol(slots[1], 1)) {
            (Some(n), Some(e), Some(e2)) if e == e2 && n != e => Some((n, e)),
            _ => None,
        };
        let model = GraphModel {
            path: label.to_string(),
            kind: expected,
            metadata,
            features,
            checker,
            node_dim,
            edge_dim,
            typed,
            slots,
            symbols,
            policy: ShapePolicy::default(),
            symbolic: Mutex::new(None),
            buckets: Mutex::new(HashMap::new()),
            initializers: graph.initializer.iter().filter_map(float_initializer).collect(),
            bool_initializers: graph.initializer.iter().filter_map(bool_initializer).collect(),
            fast: std::sync::OnceLock::new(),
        };
        // run once, so a model tract cannot execute fails here and not in the middle of a search
        let x = vec![0.0; 2 * node_dim];
        let attr = vec![0.0; edge_dim];
        let out = model.score_with(ShapePolicy::Symbolic, &x, 2, &[0, 1], 1, &attr)?;
        if out.len() != 2 || !out.iter().all(|v| v.is_finite()) {
            return Err(mismatch(format!("a test graph of 2 nodes gave {out:?}, expected 2 finite values")));
        }
        Ok(model)
    }

    /// Choose how plans treat the dynamic sizes (default [`ShapePolicy::Buckets`]).
    pub fn with_policy(mut self, policy: ShapePolicy) -> Self {
        self.policy = policy;
        self
    }

    /// Check that the model was trained on `features` with these attribute widths.
    pub fn check_features(&self, features: &str, node_dim: usize, edge_dim: usize) -> Result<()> {
        let mismatch = |m: String| Err(LearnError::Mismatch { path: self.path.clone(), mismatch: m });
        if self.node_dim != node_dim {
            return mismatch(format!("input 'x' has {} features, the graph has {node_dim}", self.node_dim));
        }
        if self.edge_dim != edge_dim {
            return mismatch(format!("input 'edge_attr' has {} features, the graph has {edge_dim}", self.edge_dim));
        }
        if self.features != features {
            return mismatch(format!("trained on features '{}', asp computes '{features}'", self.features));
        }
        Ok(())
    }

    /// Check that the model was trained on the labels of `run`, the checker of the run that
    /// would use it: a one-line error naming the file and both checkers otherwise.
    pub fn check_checker(&self, run: Checker) -> Result<()> {
        if self.checker == run {
            return Ok(());
        }
        Err(LearnError::Mismatch {
            path: self.path.clone(),
            mismatch: format!("trained on labels of the {} checker, this run uses the {run} checker", self.checker),
        })
    }

    /// The checker whose labels the model was trained on (`asp.checker`; [`Checker::Default`]
    /// for a file without the property).
    pub fn checker(&self) -> Checker {
        self.checker
    }

    /// What the model computes.
    pub fn kind(&self) -> ModelKind {
        self.kind
    }

    /// The file the model came from (as given).
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The features string the model was trained on (`asp.features`).
    pub fn features(&self) -> &str {
        &self.features
    }

    /// Floats per node attribute.
    pub fn node_dim(&self) -> usize {
        self.node_dim
    }

    /// Floats per edge attribute.
    pub fn edge_dim(&self) -> usize {
        self.edge_dim
    }

    /// Every metadata property of the file.
    pub fn metadata(&self) -> &BTreeMap<String, String> {
        &self.metadata
    }

    /// The shape policy in use.
    pub fn policy(&self) -> ShapePolicy {
        self.policy
    }

    /// Score every node of one state graph: `x` is `[n, node_dim]` row-major, `edge_index` is
    /// `[2, e]` (the `e` sources, then the `e` targets, positions in `x`), `edge_attr` is
    /// `[e, edge_dim]`. Returns the `n` removabilities.
    pub fn score(&self, x: &[f32], n: usize, edge_index: &[i64], e: usize, edge_attr: &[f32]) -> Result<Vec<f32>> {
        self.score_with(self.policy, x, n, edge_index, e, edge_attr)
    }

    fn score_with(&self, policy: ShapePolicy, x: &[f32], n: usize, edge_index: &[i64], e: usize, edge_attr: &[f32]) -> Result<Vec<f32>> {
        self.check_input(x, n, edge_index, e, edge_attr)?;
        if n == 0 {
            return Ok(Vec::new());
        }
        let fail = |err: TractError| LearnError::Inference { path: self.path.clone(), reason: one_line(&err) };
        let bucket = match (policy, &self.symbols) {
            (ShapePolicy::Buckets, Some(_)) => padded_sizes(n, e),
            _ => None,
        };
        let (plan, np, ep) = match bucket {
            Some((np, ep)) => (self.bucket_plan(np, ep).map_err(fail)?, np, ep),
            None => (self.symbolic_plan().map_err(fail)?, n, e),
        };
        let mut xs = Vec::with_capacity(np * self.node_dim);
        xs.extend_from_slice(x);
        xs.resize(np * self.node_dim, 0.0);
        let mut index = Vec::with_capacity(2 * ep);
        let pad = n as i64; // the first padding node; padded edges are its self loops
        index.extend_from_slice(&edge_index[..e]);
        index.resize(ep, pad);
        index.extend_from_slice(&edge_index[e..]);
        index.resize(2 * ep, pad);
        let mut attr = Vec::with_capacity(ep * self.edge_dim);
        attr.extend_from_slice(edge_attr);
        attr.resize(ep * self.edge_dim, 0.0);
        let tensors = [
            Tensor::from_shape(&[np, self.node_dim], &xs).map_err(fail)?,
            Tensor::from_shape(&[2, ep], &index).map_err(fail)?,
            Tensor::from_shape(&[ep, self.edge_dim], &attr).map_err(fail)?,
        ];
        let mut inputs: TVec<TValue> = tvec![TValue::from(Tensor::default()); 3];
        for (k, t) in tensors.into_iter().enumerate() {
            inputs[self.slots[k]] = t.into_tvalue();
        }
        let outputs = plan.run(inputs).map_err(fail)?;
        let view = outputs[0].to_plain_array_view::<f32>().map_err(fail)?;
        if view.len() != np {
            return Err(LearnError::Inference {
                path: self.path.clone(),
                reason: format!("output '{}' has {} values for {np} nodes", self.kind.output(), view.len()),
            });
        }
        Ok(view.iter().take(n).copied().collect())
    }

    fn check_input(&self, x: &[f32], n: usize, edge_index: &[i64], e: usize, edge_attr: &[f32]) -> Result<()> {
        let bad = |reason: String| Err(LearnError::Input { path: self.path.clone(), reason });
        if x.len() != n * self.node_dim {
            return bad(format!("x has {} floats, expected n × node_dim = {n} × {}", x.len(), self.node_dim));
        }
        if edge_index.len() != 2 * e {
            return bad(format!("edge_index has {} entries, expected 2 × e = {}", edge_index.len(), 2 * e));
        }
        if edge_attr.len() != e * self.edge_dim {
            return bad(format!("edge_attr has {} floats, expected e × edge_dim = {e} × {}", edge_attr.len(), self.edge_dim));
        }
        if let Some(k) = edge_index.iter().position(|&v| v < 0 || v as u64 >= n as u64) {
            let (row, col) = (k / e.max(1), k % e.max(1));
            return bad(format!("edge_index[{row}][{col}] = {} is not a node (n = {n})", edge_index[k]));
        }
        Ok(())
    }

    fn symbolic_plan(&self) -> TractResult<Arc<Pooled>> {
        let mut slot = self.symbolic.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(plan) = &*slot {
            return Ok(plan.clone());
        }
        let plan = Pooled::new(self.typed.clone().into_optimized()?.into_runnable()?);
        *slot = Some(plan.clone());
        Ok(plan)
    }

    fn bucket_plan(&self, n: usize, e: usize) -> TractResult<Arc<Pooled>> {
        let mut plans = self.buckets.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(plan) = plans.get(&(n, e)) {
            return Ok(plan.clone());
        }
        let (sn, se) = self.symbols.clone().ok_or_else(|| TractError::msg("the model's sizes are not plain symbols"))?;
        let subs = HashMap::from([(sn, TDim::Val(n as i64)), (se, TDim::Val(e as i64))]);
        let plan = Pooled::new(self.typed.set_symbols(&subs)?.into_optimized()?.into_runnable()?);
        plans.insert((n, e), plan.clone());
        Ok(plan)
    }

    /// The Rust forward pass of this removability model ([`QNet::removability`]),
    /// built and checked against tract on first use; `None` when the file is not the trainer's
    /// architecture or is a Q model.
    pub fn fast_net(&self) -> Option<&Arc<QNet>> {
        self.fast
            .get_or_init(|| match self.kind {
                ModelKind::Removability => QNet::removability(self).ok().map(Arc::new),
                ModelKind::Q => None,
            })
            .as_ref()
    }

    /// How many padded-size plans are cached (for tests and benchmarks).
    pub fn cached_plans(&self) -> usize {
        self.buckets.lock().map(|p| p.len()).unwrap_or(0)
    }
}

/// The bucket of a size: the smallest of 8, 12, 16, 24, 32, 48, ... that is at least `v`.
pub fn bucket(v: usize) -> usize {
    let mut b = 8usize;
    loop {
        if v <= b {
            return b;
        }
        if v <= b + b / 2 {
            return b + b / 2;
        }
        b *= 2;
    }
}

/// Padded `(n, e)` of a graph, or `None` when it is too large for a bucket. Edges are padded to
/// at least one (no zero-sized tensors in a concrete plan); when edges are padded, at least one
/// padding node exists to carry them.
fn padded_sizes(n: usize, e: usize) -> Option<(usize, usize)> {
    if n > MAX_BUCKET_NODES || e > MAX_BUCKET_EDGES {
        return None;
    }
    let ep = bucket(e.max(1));
    let np = bucket(if ep > e { n + 1 } else { n });
    Some((np, ep))
}

impl OnnxWeights for GraphModel {
    fn node_dim(&self) -> usize {
        self.node_dim
    }

    fn edge_dim(&self) -> usize {
        self.edge_dim
    }

    fn metadata_value(&self, key: &str) -> Option<&str> {
        self.metadata.get(key).map(String::as_str)
    }

    fn initializer(&self, name: &str) -> Option<(&[usize], &[f32])> {
        self.initializers.iter().find(|(n, _, _)| n == name).map(|(_, s, v)| (s.as_slice(), v.as_slice()))
    }

    fn bool_initializer(&self, name: &str) -> Option<&[bool]> {
        self.bool_initializers.iter().find(|(n, _)| n == name).map(|(_, v)| v.as_slice())
    }

    fn scalar_initializers(&self) -> Vec<f32> {
        self.initializers.iter().filter(|(_, s, _)| s.is_empty()).map(|(_, _, v)| v[0]).collect()
    }

    fn reference_scores(
        &self,
        x: &[f32],
        n: usize,
        edge_index: &[i64],
        e: usize,
        edge_attr: &[f32],
    ) -> std::result::Result<Vec<f32>, String> {
        self.score(x, n, edge_index, e, edge_attr).map_err(|err| err.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tract_onnx::pb::{tensor_shape_proto::dimension, type_proto};

    fn fixture(name: &str) -> std::path::PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
    }

    fn proto() -> pb::ModelProto {
        onnx().proto_model_for_path(fixture("random_gnn.onnx")).expect("fixture parses")
    }

    fn error_of(proto: &pb::ModelProto) -> String {
        RemovabilityModel::from_proto(proto, "models/x.onnx", ModelKind::Removability).expect_err("must be refused").to_string()
    }

    fn set_meta(proto: &mut pb::ModelProto, key: &str, value: Option<&str>) {
        proto.metadata_props.retain(|p| p.key != key);
        if let Some(v) = value {
            proto.metadata_props.push(pb::StringStringEntryProto { key: key.into(), value: v.into() });
        }
    }

    fn input_dims<'a>(proto: &'a mut pb::ModelProto, name: &str) -> &'a mut Vec<pb::tensor_shape_proto::Dimension> {
        let input = proto.graph.as_mut().unwrap().input.iter_mut().find(|i| i.name == name).unwrap();
        match input.r#type.as_mut().unwrap().value.as_mut().unwrap() {
            type_proto::Value::TensorType(t) => &mut t.shape.as_mut().unwrap().dim,
        }
    }

    #[test]
    fn buckets_are_monotone_and_tight() {
        let sizes: Vec<usize> = [1, 8, 9, 12, 13, 17, 40, 100, 160, 500].iter().map(|&v| bucket(v)).collect();
        assert_eq!(sizes, [8, 8, 12, 12, 16, 24, 48, 128, 192, 512]);
        for v in 1..5000 {
            assert!(bucket(v) >= v && bucket(v) <= v * 2 + 8 && bucket(v) >= bucket(v - 1));
        }
        assert_eq!(padded_sizes(40, 160), Some((48, 192)));
        assert_eq!(padded_sizes(8, 8), Some((8, 8)));
        assert_eq!(padded_sizes(8, 0), Some((12, 8)));
        assert_eq!(padded_sizes(MAX_BUCKET_NODES + 1, 0), None);
    }

    #[test]
    fn the_fixture_passes_every_check() {
        let m = RemovabilityModel::from_proto(&proto(), "random_gnn.onnx", ModelKind::Removability).unwrap();
        assert_eq!((m.node_dim(), m.edge_dim()), (74, 152));
        assert!(m.symbols.is_some(), "n and e should be plain symbols");
        m.check_features("asp-graph/2 radius_bins=8 degree=8 points=2048", 74, 152).unwrap();
    }

    #[test]
    fn wrong_metadata_is_refused_in_one_line() {
        let mut p = proto();
        set_meta(&mut p, "asp.kind", Some("qvalue"));
        assert_eq!(error_of(&p), "models/x.onnx: asp.kind is 'qvalue', expected 'removability'");
        let mut p = proto();
        set_meta(&mut p, "asp.features", None);
        assert_eq!(error_of(&p), "models/x.onnx: no metadata property 'asp.features' (not an asp removability model)");
        let mut p = proto();
        set_meta(&mut p, "asp.node_dim", Some("70"));
        assert_eq!(error_of(&p), "models/x.onnx: input 'x' has 74 features, its asp.node_dim says 70");
        let mut p = proto();
        set_meta(&mut p, "asp.edge_dim", Some("many"));
        assert_eq!(error_of(&p), "models/x.onnx: asp.edge_dim is 'many', expected a positive integer");
    }

    #[test]
    fn the_checker_of_the_labels_is_read_and_must_match_the_run() {
        // no `asp.checker` (every model written before it): the default checker's
        let m = RemovabilityModel::from_proto(&proto(), "models/x.onnx", ModelKind::Removability).unwrap();
        assert_eq!(m.checker(), Checker::Default);
        m.check_checker(Checker::Default).unwrap();
        let mut p = proto();
        set_meta(&mut p, CHECKER_KEY, Some("physics"));
        let m = RemovabilityModel::from_proto(&p, "models/x.onnx", ModelKind::Removability).unwrap();
        assert_eq!(m.checker(), Checker::Physics);
        m.check_checker(Checker::Physics).unwrap();
        assert_eq!(
            m.check_checker(Checker::Default).unwrap_err().to_string(),
            "models/x.onnx: trained on labels of the physics checker, this run uses the default checker"
        );
        assert_eq!(
            m.check_checker(Checker::Robot).unwrap_err().to_string(),
            "models/x.onnx: trained on labels of the physics checker, this run uses the robot checker"
        );
        set_meta(&mut p, CHECKER_KEY, Some("Physics"));
        assert_eq!(error_of(&p), "models/x.onnx: asp.checker is 'Physics', expected one of default, physics, robot");
        for c in Checker::ALL {
            assert_eq!(Checker::parse(c.name()), Some(c));
        }
    }

    #[test]
    fn wrong_names_are_refused() {
        let mut p = proto();
        p.graph.as_mut().unwrap().input[0].name = "nodes".into();
        assert_eq!(error_of(&p), "models/x.onnx: inputs are 'nodes', 'edge_index', 'edge_attr', expected 'x', 'edge_index', 'edge_attr'");
        let mut p = proto();
        p.graph.as_mut().unwrap().output[0].name = "y".into();
        assert_eq!(error_of(&p), "models/x.onnx: outputs are 'y', expected 'removability'");
    }

    #[test]
    fn wrong_types_and_shapes_are_refused() {
        let mut p = proto();
        let input = p.graph.as_mut().unwrap().input.iter_mut().find(|i| i.name == "edge_index").unwrap();
        if let Some(type_proto::Value::TensorType(t)) = input.r#type.as_mut().unwrap().value.as_mut() {
            t.elem_type = 6;
        }
        assert_eq!(error_of(&p), "models/x.onnx: input 'edge_index' is int32, expected int64");
        let mut p = proto();
        input_dims(&mut p, "x").push(pb::tensor_shape_proto::Dimension::default());
        assert_eq!(error_of(&p), "models/x.onnx: input 'x' has rank 3, expected 2 ([n, node_dim])");
        let mut p = proto();
        input_dims(&mut p, "x")[0].value = Some(dimension::Value::DimValue(5));
        assert_eq!(error_of(&p), "models/x.onnx: input 'x' has a fixed size 5 on axis 0; n must be dynamic");
        let mut p = proto();
        input_dims(&mut p, "edge_attr")[1].value = Some(dimension::Value::DimValue(140));
        assert_eq!(error_of(&p), "models/x.onnx: input 'edge_attr' has 140 features, its asp.edge_dim says 152");
    }

    #[test]
    fn garbage_is_not_a_model() {
        let err = RemovabilityModel::from_bytes(b"\x08\x07garbage", "models/x.onnx").unwrap_err().to_string();
        assert!(err.starts_with("models/x.onnx: "), "{err}");
        assert!(!err.contains('\n'), "{err}");
    }
}
