//! The forward pass of the trainer's Q network (`py/asp/train/q.py`, `QNetwork`) written out in
//! Rust, for the Q-function's inner loop (one inference per guided rollout step), and
//! of the removability GNN (`py/asp/train/gnn.py`, the same encoder with `log1p` input columns
//! and a sigmoid head; [`QNet::removability`]) for `--order gnn`.
//!
//! Why not tract: the exported graph (docs/learning.md, "Q models") costs about 22 M
//! multiply-adds per state at 40 parts (81 directions, width 64), and tract runs it near the
//! machine's speed (2 ms). Most of that work does not depend on the state: an edge's attributes
//! are a function of its two parts only (`QGraphBuilder::edge_attributes`), so their encoding and
//! the first layer's projection of it are cached per part pair; the dense one-hot aggregation of
//! the export (`[n, e]` matrix products) becomes a sum over each node's incoming edges; the first
//! linear map of `phi_e` is applied to nodes instead of edges (`W(h_t + a + h_s) = W h_t + W a +
//! W h_s`) and, for the next layer, folded into the second (`W1 (W2 z + b2)`); and `phi_Q` runs on
//! the asked nodes only. What is left per state is two `[e, w] × [w, w]` products per layer.
//!
//! Those products and the per-edge loops (messages, a branch-free `exp` for the softmax) are
//! written row-major over contiguous features so that they vectorise, and are compiled once per
//! instruction set `pulp` knows (AVX-512, AVX2 with FMA, plain); the widest the CPU has is chosen
//! at run time, without `unsafe` code here. The products fuse multiply-adds on the SIMD paths, so
//! two machines with different instruction sets may differ in the last bits; one machine always
//! gives the same values (the searches' same-seed determinism holds).
//!
//! The weights are read from the ONNX file's initialisers by the PyTorch parameter names the
//! exporter keeps (`node_encoder.weight`, `phi_e.0.weight`, ...) and the per-layer softmax
//! temperatures (the file's scalar initialisers, in order). [`QNet::from_model`] refuses a file
//! whose tensors do not have this shape, and then checks itself against tract on a generated
//! graph: a model that is not this architecture (or a future trainer's) falls back to tract
//! instead of giving other values.

use pulp::Simd;

mod kernels;
use kernels::{compose, exp, transpose, Dense};

/// What the Rust forward pass reads from a loaded ONNX graph model: its feature sizes, its
/// metadata, its initialisers by name, and the reference forward pass (tract) it checks itself
/// against. The model loader implements it, so this module depends on no loader.
pub trait OnnxWeights {
    /// Floats per node attribute.
    fn node_dim(&self) -> usize;
    /// Floats per edge attribute.
    fn edge_dim(&self) -> usize;
    /// The metadata property `key`.
    fn metadata_value(&self, key: &str) -> Option<&str>;
    /// The float32 initialiser `name`: its shape and values.
    fn initializer(&self, name: &str) -> Option<(&[usize], &[f32])>;
    /// The boolean initialiser `name`, flattened.
    fn bool_initializer(&self, name: &str) -> Option<&[bool]>;
    /// The values of the float32 initialisers of rank 0, in file order.
    fn scalar_initializers(&self) -> Vec<f32>;
    /// The reference forward pass: one score per node of the graph (`x` `[n, node_dim]`,
    /// `edge_index` `[2, e]`, `edge_attr` `[e, edge_dim]`).
    fn reference_scores(
        &self,
        x: &[f32],
        n: usize,
        edge_index: &[i64],
        e: usize,
        edge_attr: &[f32],
    ) -> std::result::Result<Vec<f32>, String>;
}

/// The constant added to messages (`asp.train.gnn.EPS`).
const EPS: f32 = 1e-7;
/// Shifted softmax scores are clamped here before `exp` (`asp.train.gnn.SCORE_CLAMP`).
const SCORE_CLAMP: f32 = 50.0;
/// Largest |fast − tract| / max(1, |tract|) the self-check at load accepts.
const SELF_CHECK_TOLERANCE: f32 = 1e-4;

/// One state graph as [`QNet::forward`] reads it.
#[derive(Clone, Copy, Debug)]
pub struct GraphView<'a> {
    /// The node attributes `[n, node_dim]`. With `h0` given, only a Q head's pooling reads them
    /// (their first column weighs each node; an empty `x` weighs every node 1), and they may be
    /// empty for a removability model.
    pub x: &'a [f32],
    /// The nodes' encodings `[n, width]` ([`QNet::encode_nodes`], cached per part by callers),
    /// or `None` to encode `x`.
    pub h0: Option<&'a [f32]>,
    /// Nodes.
    pub n: usize,
    /// Edge `k` runs from node `sources[k]`...
    pub sources: &'a [u32],
    /// ... to node `targets[k]`...
    pub targets: &'a [u32],
    /// ... and `edges[k * width..(k + 1) * width]` is its [`QNet::encode_edge`].
    pub edges: &'a [f32],
}

/// The Q network's weights (immutable, shared by every thread).
#[derive(Clone, Debug)]
pub struct QNet {
    width: usize,
    layers: usize,
    node_dim: usize,
    edge_dim: usize,
    node_mean: Vec<f32>,
    node_std: Vec<f32>,
    edge_mean: Vec<f32>,
    edge_std: Vec<f32>,
    node_encoder: Dense,
    /// `edge_encoder` followed by `phi_e`'s first map without its bias: an edge attribute row to
    /// its share of the first layer's pre-activation.
    edge_encoder: Dense,
    /// `phi_e.0` (the first linear map of the edge MLP).
    e1: Dense,
    /// `phi_e.2`, and next to it `phi_e.2` followed by `phi_e.0` (no bias of the latter): the new
    /// edge state and its share of the next layer's pre-activation in one product.
    e2_fused: Dense,
    /// `phi_e.2` alone (the last layer).
    e2: Dense,
    n1: Dense,
    n2: Dense,
    temperature: Vec<f32>,
    /// Which node and edge attribute columns get `log(1 + max(v, 0))` before standardising
    /// (the encoder's `node_log_mask`/`edge_log_mask`; all `false` for Q models).
    node_log: Vec<bool>,
    edge_log: Vec<bool>,
    head: Head,
}

/// What the network puts on the node embeddings.
#[derive(Clone, Debug)]
enum Head {
    /// The Q network's `phi_q` over `[h_i, hbar]`.
    Q {
        /// `phi_q.0`'s columns reading `h_i`.
        q1_node: Dense,
        /// `phi_q.0`'s columns reading the pooled embedding (with the bias).
        q1_pool: Dense,
        q2: Dense,
    },
    /// The removability GNN's `sigmoid(head(h_i))`.
    Removability(Dense),
}

/// Per-thread buffers of [`QNet::forward`] (reused; no allocation once warm).
#[derive(Clone, Debug, Default)]
pub struct Scratch {
    xs: Vec<f32>,
    h: Vec<f32>,
    p: Vec<f32>,
    z: Vec<f32>,
    a: Vec<f32>,
    m: Vec<f32>,
    mean: Vec<f32>,
    sums: Vec<f32>,
    u: Vec<f32>,
    inv_count: Vec<f32>,
    rows: Vec<f32>,
    enc: Vec<f32>,
    q_hidden: Vec<f32>,
}

fn grow(v: &mut Vec<f32>, len: usize) -> &mut [f32] {
    if v.len() < len {
        v.resize(len, 0.0);
    }
    &mut v[..len]
}

impl QNet {
    /// The network of a loaded Q model, if its file holds the trainer's architecture and the
    /// forward pass agrees with tract on a generated graph; `Err` says why not (the caller then
    /// keeps tract).
    pub fn from_model(model: &(impl OnnxWeights + ?Sized)) -> std::result::Result<Self, String> {
        let net = Self::read(model, false)?;
        net.self_check(model)?;
        Ok(net)
    }

    /// The network of a loaded removability model (`py/asp/train/gnn.py`, `RemovabilityGNN`:
    /// the same encoder with `log1p` input columns and a linear head with a sigmoid), if its
    /// file holds that architecture and agrees with tract on a generated graph (see
    /// [`from_model`](Self::from_model)). [`forward`](Self::forward) then gives removabilities.
    pub fn removability(model: &(impl OnnxWeights + ?Sized)) -> std::result::Result<Self, String> {
        let net = Self::read(model, true)?;
        net.self_check(model)?;
        Ok(net)
    }

    fn read(model: &(impl OnnxWeights + ?Sized), removability: bool) -> std::result::Result<Self, String> {
        const ENCODER_PREFIX: &str = "encoder.";
        let (node_dim, edge_dim) = (model.node_dim(), model.edge_dim());
        let meta = |key: &str| -> std::result::Result<usize, String> {
            model.metadata_value(key).and_then(|v| v.parse().ok()).ok_or_else(|| format!("no integer metadata '{key}'"))
        };
        let (width, layers) = (meta("asp.width")?, meta("asp.layers")?);
        if width == 0 || layers == 0 {
            return Err("asp.width and asp.layers must be positive".into());
        }
        // the trainer's names: the encoder's parameters at the top (the first trainers) or under
        // `encoder.` (`QNetwork` and `RemovabilityGNN` compose a `GraphEncoder`)
        let tensor = |name: &str, dims: &[usize]| -> std::result::Result<Vec<f32>, String> {
            let (shape, data) = model
                .initializer(name)
                .or_else(|| model.initializer(&format!("{ENCODER_PREFIX}{name}")))
                .ok_or_else(|| format!("no float tensor '{name}'"))?;
            if shape != dims {
                return Err(format!("tensor '{name}' has shape {shape:?}, expected {dims:?}"));
            }
            Ok(data.to_vec())
        };
        // a PyTorch Linear (weight [out, in]) as `x W + b`
        let linear = |name: &str, input: usize, output: usize| -> std::result::Result<Dense, String> {
            let w = tensor(&format!("{name}.weight"), &[output, input])?;
            let b = tensor(&format!("{name}.bias"), &[output])?;
            Ok(Dense { input, output, w: transpose(&w, output, input), b })
        };
        let node_encoder = linear("node_encoder", node_dim, width)?;
        let edge_encoder = linear("edge_encoder", edge_dim, width)?;
        let e1 = linear("phi_e.0", width, width)?;
        let e2 = linear("phi_e.2", width, width)?;
        let n1 = linear("phi_n.0", width, width)?;
        let n2 = linear("phi_n.2", width, width)?;
        let head = if removability {
            Head::Removability(linear("head", width, 1)?)
        } else {
            let q1 = linear("phi_q.0", 2 * width, width)?;
            let q2 = linear("phi_q.2", width, 1)?;
            let q1_node = Dense { input: width, output: width, w: q1.w[..width * width].to_vec(), b: vec![0.0; width] };
            let q1_pool = Dense { input: width, output: width, w: q1.w[width * width..].to_vec(), b: q1.b.clone() };
            Head::Q { q1_node, q1_pool, q2 }
        };
        // a missing mask is no log1p column (the exporter keeps the buffers; a file without
        // them and with Log ops fails the self-check)
        let mask = |name: &str, dim: usize| -> std::result::Result<Vec<bool>, String> {
            match model.bool_initializer(name).or_else(|| model.bool_initializer(&format!("{ENCODER_PREFIX}{name}"))) {
                None => Ok(vec![false; dim]),
                Some(m) if m.len() == dim => Ok(m.to_vec()),
                Some(m) => Err(format!("mask '{name}' has {} entries, expected {dim}", m.len())),
            }
        };
        let temperature = model.scalar_initializers();
        if temperature.len() != layers {
            return Err(format!("{} scalar tensors, expected one temperature per layer ({layers})", temperature.len()));
        }
        // edge_encoder then e1 (without e1's bias, added once per edge with the node terms)
        let edge_encoder = compose(&edge_encoder, &e1, false);
        // e2 next to (e2 then e1 without bias)
        let e2e1 = compose(&e2, &e1, false);
        let mut w = vec![0.0; width * 2 * width];
        for r in 0..width {
            w[r * 2 * width..r * 2 * width + width].copy_from_slice(&e2.w[r * width..(r + 1) * width]);
            w[r * 2 * width + width..(r + 1) * 2 * width].copy_from_slice(&e2e1.w[r * width..(r + 1) * width]);
        }
        let e2_fused = Dense { input: width, output: 2 * width, w, b: [e2.b.clone(), e2e1.b].concat() };
        Ok(QNet {
            width,
            layers,
            node_dim,
            edge_dim,
            node_mean: tensor("node_mean", &[node_dim])?,
            node_std: tensor("node_std", &[node_dim])?,
            edge_mean: tensor("edge_mean", &[edge_dim])?,
            edge_std: tensor("edge_std", &[edge_dim])?,
            node_encoder,
            edge_encoder,
            e1,
            e2_fused,
            e2,
            n1,
            n2,
            temperature,
            node_log: mask("node_log_mask", node_dim)?,
            edge_log: mask("edge_log_mask", edge_dim)?,
            head,
        })
    }

    /// Compares [`forward_graph`](Self::forward_graph) with tract on a generated graph of 13
    /// parts (values in the features' ranges, nearest-neighbour-like edges, a context node).
    fn self_check(&self, model: &(impl OnnxWeights + ?Sized)) -> std::result::Result<(), String> {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 40) as f32) / ((1u64 << 24) as f32)
        };
        let parts = 13;
        let n = parts + 1;
        let mut x: Vec<f32> = (0..n * self.node_dim).map(|_| uniform()).collect();
        for k in 0..n {
            x[k * self.node_dim] = 1.0;
        }
        let (mut sources, mut targets) = (Vec::new(), Vec::new());
        for t in 0..parts {
            for j in 1..=4 {
                sources.push(((t + j) % parts) as i64);
                targets.push(t as i64);
            }
            sources.push(parts as i64);
            targets.push(t as i64);
        }
        let e = sources.len();
        let attr: Vec<f32> = (0..e * self.edge_dim).map(|_| uniform()).collect();
        let index = [sources, targets].concat();
        let want = model.reference_scores(&x, n, &index, e, &attr)?;
        let nodes: Vec<usize> = (0..n).collect();
        let mut got = vec![0.0; n];
        self.forward_graph(&x, n, &index, &attr, &nodes, &mut got, &mut Scratch::default());
        for (k, (a, b)) in got.iter().zip(&want).enumerate() {
            let close = (a - b).abs() <= SELF_CHECK_TOLERANCE * b.abs().max(1.0);
            if !close {
                return Err(format!("the Rust forward pass gives {a} for node {k} of a test graph, tract {b}"));
            }
        }
        Ok(())
    }

    /// Hidden width.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Floats per edge attribute row.
    pub fn edge_dim(&self) -> usize {
        self.edge_dim
    }

    /// An edge attribute row (`edge_dim` floats) to what [`forward`](Self::forward) reads of
    /// that edge (`width` floats: the first layer's share of it). Depends only on the row, so
    /// callers cache it per part pair. `scratch` holds `edge_dim` floats.
    pub fn encode_edge(&self, attr: &[f32], out: &mut [f32], scratch: &mut Vec<f32>) {
        self.encode_edges(attr, 1, out, scratch);
    }

    fn encode_edges(&self, attr: &[f32], rows: usize, out: &mut [f32], scratch: &mut Vec<f32>) {
        let d = self.edge_dim;
        let xs = grow(scratch, rows * d);
        for (o, row) in xs.chunks_exact_mut(d).zip(attr.chunks_exact(d)) {
            for (k, (o, &v)) in o.iter_mut().zip(row).enumerate() {
                let v = if self.edge_log[k] { (1.0 + v.max(0.0)).ln() } else { v };
                *o = (v - self.edge_mean[k]) / self.edge_std[k];
            }
        }
        self.edge_encoder.apply(pulp::Scalar::new(), xs, rows, true, out);
    }

    /// The Q-values of the `wanted` nodes of a graph in the model's input layout (`x [n,
    /// node_dim]`, `edge_index [2, e]`, `edge_attr [e, edge_dim]`), into `out`.
    #[allow(clippy::too_many_arguments)]
    pub fn forward_graph(
        &self,
        x: &[f32],
        n: usize,
        edge_index: &[i64],
        edge_attr: &[f32],
        wanted: &[usize],
        out: &mut [f32],
        s: &mut Scratch,
    ) {
        let e = edge_index.len() / 2;
        let mut enc = std::mem::take(&mut s.enc);
        let mut rows = std::mem::take(&mut s.rows);
        grow(&mut enc, e * self.width);
        self.encode_edges(edge_attr, e, &mut enc, &mut rows);
        let sources: Vec<u32> = edge_index[..e].iter().map(|&v| v as u32).collect();
        let targets: Vec<u32> = edge_index[e..].iter().map(|&v| v as u32).collect();
        let graph = GraphView { x, h0: None, n, sources: &sources, targets: &targets, edges: &enc[..e * self.width] };
        self.forward(graph, wanted, out, s);
        s.enc = enc;
        s.rows = rows;
    }

    /// The Q-values (or removabilities) of the `wanted` nodes of `graph` into `out`.
    ///
    /// Runs on the widest SIMD instruction set the CPU has (`pulp`, see the module's notes).
    pub fn forward(&self, graph: GraphView<'_>, wanted: &[usize], out: &mut [f32], s: &mut Scratch) {
        pulp::Arch::new().dispatch(Forward { net: self, graph, wanted, out, s });
    }

    /// Node attribute rows (`x [rows, node_dim]`) to what [`GraphView::h0`] holds of each node (`width` floats: the node encoder's output). Depends only on the row,
    /// so callers cache it per part.
    pub fn encode_nodes(&self, x: &[f32], rows: usize, out: &mut [f32], scratch: &mut Vec<f32>) {
        let nd = self.node_dim;
        let xs = grow(scratch, rows * nd);
        self.normalise_nodes(x, xs);
        // the instruction set of forward's own node encoding, so both give the same bits
        struct Encode<'a>(&'a Dense, &'a [f32], usize, &'a mut [f32]);
        impl pulp::WithSimd for Encode<'_> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) {
                let Encode(dense, xs, rows, out) = self;
                dense.apply(simd, xs, rows, true, out);
            }
        }
        pulp::Arch::new().dispatch(Encode(&self.node_encoder, xs, rows, &mut out[..rows * self.width]));
    }

    fn normalise_nodes(&self, x: &[f32], xs: &mut [f32]) {
        let nd = self.node_dim;
        if !self.node_log.contains(&true) {
            // no log1p column (every Q model): a loop the compiler vectorises without `ln`
            for (o, row) in xs.chunks_exact_mut(nd).zip(x.chunks_exact(nd)) {
                for (((o, &v), &mean), &std) in o.iter_mut().zip(row).zip(&self.node_mean).zip(&self.node_std) {
                    *o = (v - mean) / std;
                }
            }
            return;
        }
        for (o, row) in xs.chunks_exact_mut(nd).zip(x.chunks_exact(nd)) {
            for (k, (o, &v)) in o.iter_mut().zip(row).enumerate() {
                let v = if self.node_log[k] { (1.0 + v.max(0.0)).ln() } else { v };
                *o = (v - self.node_mean[k]) / self.node_std[k];
            }
        }
    }

    /// The forward pass, row-major throughout (node `t`'s or edge `k`'s `width` features are
    /// contiguous), so every per-edge loop runs over contiguous features and vectorises.
    #[inline(always)]
    fn forward_any<S: Simd>(&self, simd: S, graph: GraphView<'_>, wanted: &[usize], out: &mut [f32], s: &mut Scratch) {
        let GraphView { x, h0, n, sources, targets, edges } = graph;
        let w = self.width;
        let e = sources.len();
        let nd = self.node_dim;
        // standardised node attributes, encoded (or their cached encodings)
        let mut h = std::mem::take(&mut s.h);
        grow(&mut h, n * w);
        match h0 {
            Some(h0) => h[..n * w].copy_from_slice(&h0[..n * w]),
            None => {
                let xs = grow(&mut s.xs, n * nd);
                self.normalise_nodes(x, xs);
                self.node_encoder.apply(simd, &s.xs, n, true, &mut h);
            }
        }
        let inv_count = grow(&mut s.inv_count, n);
        inv_count.fill(0.0);
        for &t in targets {
            inv_count[t as usize] += 1.0;
        }
        for c in inv_count.iter_mut() {
            *c = 1.0 / c.max(1.0);
        }
        grow(&mut s.p, n * w);
        grow(&mut s.z, e * w);
        grow(&mut s.a, e * 2 * w);
        grow(&mut s.m, e * w);
        grow(&mut s.mean, n * w);
        grow(&mut s.sums, n * 2 * w);
        grow(&mut s.u, n * w);
        for layer in 0..self.layers {
            let last = layer + 1 == self.layers;
            // this layer's edge share of the pre-activation: the cached encodings first, then
            // columns w..2w of the previous layer's fused product
            let (a_in, stride): (&[f32], usize) = if layer == 0 { (&edges[..e * w], w) } else { (&s.a[..e * 2 * w], 2 * w) };
            // z = relu(W1 h_t + W1 a + W1 h_s + b1)
            self.e1.apply(simd, &h, n, false, &mut s.p);
            let (p, b1) = (&s.p[..n * w], &self.e1.b[..w]);
            for (k, z) in s.z[..e * w].chunks_exact_mut(w).enumerate() {
                let (t, src) = (targets[k] as usize, sources[k] as usize);
                let (pt, ps, a) =
                    (&p[t * w..(t + 1) * w], &p[src * w..(src + 1) * w], &a_in[k * stride + (stride - w)..k * stride + stride]);
                for ((((z, &pt), &a), &ps), &b1) in z.iter_mut().zip(pt).zip(a).zip(ps).zip(b1) {
                    *z = (pt + a + ps + b1).max(0.0);
                }
            }
            // the new edge state a' (columns 0..w of a row) and, but for the last layer, W1 a'
            // for the next (columns w..2w)
            let stride = if last {
                self.e2.apply(simd, &s.z, e, true, &mut s.a);
                w
            } else {
                self.e2_fused.apply(simd, &s.z, e, true, &mut s.a);
                2 * w
            };
            // messages m = relu(h_t + a') + eps and the learned softmax over each target's edges
            let tau = self.temperature[layer];
            let mean = &mut s.mean[..n * w];
            mean.fill(0.0);
            for (k, m) in s.m[..e * w].chunks_exact_mut(w).enumerate() {
                let t = targets[k] as usize;
                let (ht, a, mt) = (&h[t * w..(t + 1) * w], &s.a[k * stride..k * stride + w], &mut mean[t * w..(t + 1) * w]);
                for (((m, mt), &ht), &a) in m.iter_mut().zip(mt.iter_mut()).zip(ht).zip(a) {
                    *m = (ht + a).max(0.0) + EPS;
                    *mt += *m * tau;
                }
            }
            for (t, row) in mean.chunks_exact_mut(w).enumerate() {
                let c = s.inv_count[t];
                for v in row {
                    *v *= c;
                }
            }
            let sums = &mut s.sums[..n * 2 * w];
            sums.fill(0.0);
            for (k, m) in s.m[..e * w].chunks_exact(w).enumerate() {
                let t = targets[k] as usize;
                let (mt, st) = (&mean[t * w..(t + 1) * w], &mut sums[t * 2 * w..(t + 1) * 2 * w]);
                let (num, den) = st.split_at_mut(w);
                for (((num, den), &m), &mt) in num.iter_mut().zip(den.iter_mut()).zip(m).zip(mt) {
                    let weight = exp((m * tau - mt).min(SCORE_CLAMP));
                    *num += weight * m;
                    *den += weight;
                }
            }
            // h = phi_n(h + aggregate)
            for t in 0..n {
                let st = &sums[t * 2 * w..(t + 1) * 2 * w];
                let (ht, u) = (&h[t * w..(t + 1) * w], &mut s.u[t * w..(t + 1) * w]);
                let (num, den) = st.split_at(w);
                for (((u, &ht), &num), &den) in u.iter_mut().zip(ht).zip(num).zip(den) {
                    *u = ht + num / den.max(1.0);
                }
            }
            self.n1.apply(simd, &s.u, n, true, &mut s.p);
            for v in &mut s.p[..n * w] {
                *v = v.max(0.0);
            }
            self.n2.apply(simd, &s.p, n, true, &mut h);
        }
        let (q1_node, q1_pool, q2) = match &self.head {
            Head::Q { q1_node, q1_pool, q2 } => (q1_node, q1_pool, q2),
            Head::Removability(head) => {
                // p_i = sigmoid(head(h_i))
                for (o, &k) in out.iter_mut().zip(wanted) {
                    let mut v = head.b[0];
                    for (&a, &b) in h[k * w..(k + 1) * w].iter().zip(&head.w) {
                        v += a * b;
                    }
                    *o = 1.0 / (1.0 + (-v).exp());
                }
                s.h = h;
                return;
            }
        };
        // q_i = phi_Q([h_i, hbar]), hbar the mean of the real nodes (x[:, 0] = 1)
        let mut weight = 0.0f32;
        let pooled = grow(&mut s.u, w);
        pooled.fill(0.0);
        for t in 0..n {
            let r = x.get(t * nd).copied().unwrap_or(1.0);
            weight += r;
            for j in 0..w {
                pooled[j] += r * h[t * w + j];
            }
        }
        let norm = weight.max(1.0);
        for v in pooled.iter_mut() {
            *v /= norm;
        }
        let pool = grow(&mut s.mean, w);
        q1_pool.apply(simd, &s.u[..w], 1, true, pool);
        let rows = grow(&mut s.z, wanted.len() * w);
        for (r, &k) in rows.chunks_exact_mut(w).zip(wanted) {
            r.copy_from_slice(&h[k * w..(k + 1) * w]);
        }
        let hidden = grow(&mut s.q_hidden, wanted.len() * w);
        q1_node.apply(simd, &s.z, wanted.len(), false, hidden);
        for (o, row) in out.iter_mut().zip(hidden.chunks_exact(w)) {
            let mut q = q2.b[0];
            for ((r, p), v) in row.iter().zip(&s.mean[..w]).zip(&q2.w) {
                q += (r + p).max(0.0) * v;
            }
            *o = q;
        }
        s.h = h;
    }
}

/// [`QNet::forward`]'s arguments, for `pulp`'s dispatch: its `with_simd` is compiled once per
/// instruction set with [`QNet::forward_any`] inlined.
struct Forward<'a> {
    net: &'a QNet,
    graph: GraphView<'a>,
    wanted: &'a [usize],
    out: &'a mut [f32],
    s: &'a mut Scratch,
}

impl pulp::WithSimd for Forward<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let Forward { net, graph, wanted, out, s } = self;
        net.forward_any(simd, graph, wanted, out, s);
    }
}

#[cfg(test)]
mod tests {
    use super::kernels::gemm;
    use super::*;

    /// [`gemm`] on the widest instruction set of this CPU (what the forward pass runs).
    struct Gemm<'a> {
        x: &'a [f32],
        rows: usize,
        k: usize,
        w: &'a [f32],
        cols: usize,
        bias: Option<&'a [f32]>,
        out: &'a mut [f32],
    }

    impl pulp::WithSimd for Gemm<'_> {
        type Output = ();

        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) {
            gemm(simd, self.x, self.rows, self.k, self.w, self.cols, self.bias, self.out);
        }
    }

    fn values(count: usize, seed: u32) -> Vec<f32> {
        (0..count as u32).map(|i| ((i.wrapping_mul(2_654_435_761).wrapping_add(seed) >> 8) % 2001) as f32 / 1000.0 - 1.0).collect()
    }

    #[test]
    fn gemm_equals_the_plain_product_on_every_tile_and_tail_shape() {
        // rows around the 4-row tiles, columns around the two-vector tiles of 8 and 16 lanes
        // (and tails past them), with and without bias, on this CPU's SIMD path and the scalar one
        for rows in [1, 3, 4, 5, 9] {
            for k in [1, 7, 32, 190] {
                for cols in [1, 5, 16, 32, 33, 64, 100, 128] {
                    let (x, w, b) = (values(rows * k, 1), values(k * cols, 2), values(cols, 3));
                    for bias in [None, Some(&b[..])] {
                        let want: Vec<f64> = (0..rows * cols)
                            .map(|i| {
                                let (r, c) = (i / cols, i % cols);
                                let sum: f64 = (0..k).map(|j| f64::from(x[r * k + j]) * f64::from(w[j * cols + c])).sum();
                                sum + bias.map_or(0.0, |b| f64::from(b[c]))
                            })
                            .collect();
                        let mut simd = vec![f32::NAN; rows * cols];
                        pulp::Arch::new().dispatch(Gemm { x: &x, rows, k, w: &w, cols, bias, out: &mut simd });
                        let mut scalar = vec![f32::NAN; rows * cols];
                        gemm(pulp::Scalar::new(), &x, rows, k, &w, cols, bias, &mut scalar);
                        for (path, got) in [("simd", &simd), ("scalar", &scalar)] {
                            for (i, (g, v)) in got.iter().zip(&want).enumerate() {
                                let err = (f64::from(*g) - v).abs();
                                assert!(
                                    err <= 1e-5 * (k as f64),
                                    "{path} rows {rows} k {k} cols {cols} bias {}: [{i}] {g} vs {v}",
                                    bias.is_some()
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn exp_is_within_a_few_ulp_of_the_library() {
        // the softmax's range: scores clamped at SCORE_CLAMP above, anything below
        let mut worst = 0.0f64;
        let mut x = -80.0f32;
        while x <= SCORE_CLAMP {
            let (got, want) = (f64::from(exp(x)), f64::from(x).exp());
            worst = worst.max((got - want).abs() / want);
            x += 0.013;
        }
        assert!(worst <= 4.0 * f64::from(f32::EPSILON), "relative error {worst}");
        assert_eq!(exp(0.0), 1.0);
        // far below the range: tiny and finite, never NaN or negative
        for x in [-88.0f32, -100.0, -1e6, f32::MIN] {
            let v = exp(x);
            assert!((0.0..1e-37).contains(&v), "exp({x}) = {v}");
        }
    }
}
