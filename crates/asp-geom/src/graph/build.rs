//! [`AssemblyGraph`]: the graph of the assembled model (thesis 3.4.1, eqs. 3.5-3.7) with its node
//! and edge attributes (3.4.2, eqs. 3.11-3.12), computed once per model.

use super::config::{GraphConfig, DIRECTION_BINS};
use super::descriptor::descriptor_into;
use crate::error::{GeomError, Result};
use crate::math::{Aabb, Vec3};
use crate::sample::{sample_triangles, SurfaceSample};
use crate::world::World;
use parry3d::query::PointQuery;
use parry3d::shape::TriMesh;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::ops::Range;

/// The graph of an assembled model: one node per real part (the virtual ground is not a node),
/// a directed edge `s → t` for every ordered pair of parts in contact (both directions), and
/// their attributes (`docs/learning.md`, "The graph of a state"). The graph of a disassembly
/// state is its induced subgraph ([`AssemblyGraph::state`]).
///
/// **Node `i`** (`node_dim = D + 2` floats): `h(Q_i)` (eq. 3.11, the descriptor of the part's
/// surface sample), `fixed` (1 for a base part), `on_base` (1 when the part touches a fixed part
/// or the ground).
///
/// **Edge `s → t`** (`edge_dim = 2D + 8` floats; `2D + 2` without contact directions): `h(Q_t^s)`, `h(Q_s^t)` (eq. 3.12 with `i = t`,
/// `j = s`: the contact region on the target, then on the source), the six **contact
/// directions** of `Q_t^s` (the area-weighted means of `max(0, ±n·u1)`, `max(0, ±n·u2)` in the
/// order `+u1, +u2, −u1, −u2`, then `max(0, ±n·up)`, `+up, −up`, with `n` the target's outward
/// normal: the share of the contact that faces each way, i.e. the directions in which the source
/// blocks the target; `u1, u2` the model's [`horizontal_frame`]), `above = up · unit(c_s − c_t)`
/// (`c` the area-weighted surface centroids) and `normal_up`, the area-weighted mean of `up · n`
/// over `Q_t^s` (outward normals: +1 the target is a floor under the source, −1 a ceiling, 0 a
/// wall or no region). `Q_i^j` is the sample points of part `i` closer than the world's contact
/// distance to the surface of part `j`; an empty region has the zero descriptor.
///
/// **Edge order**: by (source, target), ascending — the order of [`AssemblyGraph::edges`], of
/// the data set's `graph.json` and of every state's edges.
#[derive(Clone, Debug, PartialEq)]
pub struct AssemblyGraph {
    config: GraphConfig,
    num_parts: usize,
    nodes: Vec<f32>,
    edges: Vec<(usize, usize)>,
    edge_attr: Vec<f32>,
    /// `edges[offsets[s]..offsets[s + 1]]` leave `s`.
    offsets: Vec<usize>,
}

/// The features of one unordered contact pair `(i, j)`, `i < j`.
struct PairFeatures {
    /// `h(Q_i^j)` then `h(Q_j^i)`.
    h: [Vec<f32>; 2],
    /// `normal_up` over `Q_i^j` and over `Q_j^i`.
    normal_up: [f32; 2],
    /// The contact directions of `Q_i^j` and of `Q_j^i`.
    directions: [[f32; DIRECTION_BINS]; 2],
}

impl AssemblyGraph {
    /// The graph of the assembled model of `world`: samples and descriptors per part (in
    /// parallel), contacts from [`crate::world::Contacts::of`], contact regions within
    /// [`crate::world::Contacts::distance`], gravity from the assembly's up axis.
    pub fn build(world: &World, config: &GraphConfig) -> Result<AssemblyGraph> {
        config.validate()?;
        let n = world.num_parts();
        let eps = world.contacts().distance();
        let up = world.assembly().up.vector();
        let samples: Vec<SurfaceSample> = (0..n)
            .into_par_iter()
            .map(|i| {
                let m = world.shapes().mesh(i);
                sample_triangles(m.vertices(), m.indices(), config.points_per_part)
            })
            .collect();
        let centroids: Vec<Vec3> = samples.iter().map(|s| s.centroid().unwrap_or(Vec3::ZERO)).collect();
        let frame = horizontal_frame(&samples, up);
        let part_h: Vec<Vec<f32>> =
            samples.par_iter().map_init(Vec::new, |scratch, s| region_descriptor(s, None, config, scratch)).collect();
        let pairs: Vec<(usize, usize)> =
            (0..n).flat_map(|i| world.contacts().of(i).iter().filter(move |&j| j > i && j < n).map(move |j| (i, j))).collect();
        let pair_features: Vec<PairFeatures> = pairs
            .par_iter()
            .map(|&(i, j)| {
                let q_ij = contact_region(&samples[i], world.shapes().mesh(j), world.shapes().aabb(j), eps);
                let q_ji = contact_region(&samples[j], world.shapes().mesh(i), world.shapes().aabb(i), eps);
                let mut scratch = Vec::new();
                PairFeatures {
                    h: [
                        region_descriptor(&samples[i], Some(&q_ij), config, &mut scratch),
                        region_descriptor(&samples[j], Some(&q_ji), config, &mut scratch),
                    ],
                    normal_up: [normal_up(&samples[i], &q_ij, up), normal_up(&samples[j], &q_ji, up)],
                    directions: [contact_directions(&samples[i], &q_ij, frame, up), contact_directions(&samples[j], &q_ji, frame, up)],
                }
            })
            .collect();
        let by_pair: BTreeMap<(usize, usize), usize> = pairs.iter().enumerate().map(|(k, &p)| (p, k)).collect();

        let mut nodes = Vec::with_capacity(n * config.node_dim());
        for (i, h) in part_h.iter().enumerate() {
            nodes.extend_from_slice(h);
            nodes.push(world.assembly().parts[i].fixed as u8 as f32);
            nodes.push(world.contacts().of(i).intersects(world.contacts().fixed()) as u8 as f32);
        }
        let mut edges = Vec::with_capacity(2 * pairs.len());
        let mut edge_attr = Vec::with_capacity(2 * pairs.len() * config.edge_dim());
        for s in 0..n {
            for t in world.contacts().of(s).iter().filter(|&t| t < n && t != s) {
                let f = &pair_features[by_pair[&(s.min(t), s.max(t))]];
                // slot 0 is the region on the lower index, slot 1 on the higher
                let (on_t, on_s) = if s < t { (1, 0) } else { (0, 1) };
                edge_attr.extend_from_slice(&f.h[on_t]);
                edge_attr.extend_from_slice(&f.h[on_s]);
                if config.contact_directions {
                    edge_attr.extend_from_slice(&f.directions[on_t]);
                }
                edge_attr.push(up.dot((centroids[s] - centroids[t]).normalize_or_zero()));
                edge_attr.push(f.normal_up[on_t]);
                edges.push((s, t));
            }
        }
        debug_assert_eq!(edge_attr.len(), edges.len() * config.edge_dim());
        Self::from_parts(config, nodes, edges, edge_attr)
    }

    /// A graph from precomputed attributes (tests, data sets read back): `nodes` row-major
    /// `num_parts × node_dim`, `edges` sorted by (source, target) without repeats or loops,
    /// `edge_attr` row-major `edges.len() × edge_dim`. Errors name the first inconsistency.
    pub fn from_parts(config: &GraphConfig, nodes: Vec<f32>, edges: Vec<(usize, usize)>, edge_attr: Vec<f32>) -> Result<AssemblyGraph> {
        config.validate()?;
        let (nd, ed) = (config.node_dim(), config.edge_dim());
        if !nodes.len().is_multiple_of(nd) {
            return Err(GeomError::config(format!("graph nodes hold {} floats, not a multiple of node_dim {nd}", nodes.len())));
        }
        let n = nodes.len() / nd;
        if edge_attr.len() != edges.len() * ed {
            return Err(GeomError::config(format!(
                "graph edge_attr holds {} floats, {} edges need {}",
                edge_attr.len(),
                edges.len(),
                edges.len() * ed
            )));
        }
        for (k, &(s, t)) in edges.iter().enumerate() {
            if s >= n || t >= n || s == t {
                return Err(GeomError::config(format!("graph edge {k} ({s}, {t}) is a loop or names no part of {n}")));
            }
            if k > 0 && edges[k - 1] >= (s, t) {
                return Err(GeomError::config(format!("graph edges are not sorted by (source, target) at edge {k}")));
            }
        }
        let mut offsets = vec![0usize; n + 1];
        for &(s, _) in &edges {
            offsets[s + 1] += 1;
        }
        for i in 0..n {
            offsets[i + 1] += offsets[i];
        }
        Ok(AssemblyGraph { config: config.clone(), num_parts: n, nodes, edges, edge_attr, offsets })
    }

    /// The configuration the attributes were computed with.
    pub fn config(&self) -> &GraphConfig {
        &self.config
    }

    /// The features string ([`GraphConfig::features`]).
    pub fn features(&self) -> String {
        self.config.features()
    }

    /// Number of nodes: the real parts of the model.
    pub fn num_parts(&self) -> usize {
        self.num_parts
    }

    /// Number of directed edges.
    pub fn num_edges(&self) -> usize {
        self.edges.len()
    }

    /// Floats per node ([`GraphConfig::node_dim`]).
    pub fn node_dim(&self) -> usize {
        self.config.node_dim()
    }

    /// Floats per edge ([`GraphConfig::edge_dim`]).
    pub fn edge_dim(&self) -> usize {
        self.config.edge_dim()
    }

    /// The directed edges `(source, target)` as part indices, sorted by (source, target).
    pub fn edges(&self) -> &[(usize, usize)] {
        &self.edges
    }

    /// The positions in [`AssemblyGraph::edges`] of the edges leaving part `s` (empty when `s`
    /// is out of range).
    pub fn edges_from(&self, s: usize) -> Range<usize> {
        match (self.offsets.get(s), self.offsets.get(s + 1)) {
            (Some(&a), Some(&b)) => a..b,
            _ => 0..0,
        }
    }

    /// The attributes of part `i`. Panics when `i >= num_parts()`.
    pub fn node_attr(&self, i: usize) -> &[f32] {
        let nd = self.node_dim();
        &self.nodes[i * nd..(i + 1) * nd]
    }

    /// The attributes of edge `k` (of [`AssemblyGraph::edges`]). Panics when `k >= num_edges()`.
    pub fn edge_attr(&self, k: usize) -> &[f32] {
        let ed = self.edge_dim();
        &self.edge_attr[k * ed..(k + 1) * ed]
    }

    /// All node attributes, row-major `num_parts × node_dim` (the data set's `nodes.npy`).
    pub fn nodes_flat(&self) -> &[f32] {
        &self.nodes
    }

    /// All edge attributes, row-major `num_edges × edge_dim` (the data set's `edge_attr.npy`).
    pub fn edge_attr_flat(&self) -> &[f32] {
        &self.edge_attr
    }
}

/// The descriptor of `sample`, or of its points at `region` when given.
fn region_descriptor(sample: &SurfaceSample, region: Option<&[u32]>, config: &GraphConfig, scratch: &mut Vec<f64>) -> Vec<f32> {
    let mut h = vec![0.0; config.descriptor_dim()];
    match region {
        None => descriptor_into(|| sample.points.iter().copied().zip(sample.weights.iter().copied()), config, &mut h, scratch),
        Some(r) => descriptor_into(|| r.iter().map(|&k| (sample.points[k as usize], sample.weights[k as usize])), config, &mut h, scratch),
    }
    h
}

/// The indices of the points of `sample` closer than `eps` to the surface of `mesh`
/// (`Q_i^j` of eq. 3.12): a box test against `aabb` grown by `eps`, then a point projection on
/// the mesh's BVH bounded by `eps`.
fn contact_region(sample: &SurfaceSample, mesh: &TriMesh, aabb: &Aabb, eps: f32) -> Vec<u32> {
    let (lo, hi) = (aabb.mins - Vec3::splat(eps), aabb.maxs + Vec3::splat(eps));
    let candidates: Vec<u32> =
        sample.points.iter().enumerate().filter(|(_, p)| p.cmpge(lo).all() && p.cmple(hi).all()).map(|(k, _)| k as u32).collect();
    let near = |&k: &u32| {
        let p = sample.points[k as usize];
        mesh.project_local_point_with_max_dist(p, false, eps).is_some_and(|proj| (proj.point - p).length() < eps)
    };
    if candidates.len() < 512 {
        candidates.into_iter().filter(near).collect()
    } else {
        candidates.into_par_iter().with_min_len(256).filter(near).collect()
    }
}

/// The area-weighted mean of `up · n` over the points of `sample` at `region` (0 when empty).
fn normal_up(sample: &SurfaceSample, region: &[u32], up: Vec3) -> f32 {
    let (mut total, mut sum) = (0.0f64, 0.0f64);
    for &k in region {
        let w = sample.weights[k as usize] as f64;
        total += w;
        sum += w * up.dot(sample.normals[k as usize]) as f64;
    }
    if total > 0.0 {
        (sum / total) as f32
    } else {
        0.0
    }
}

/// The model's horizontal frame `(u1, u2)` (with `up`, right-handed), or `None` when the model
/// has no dominant horizontal directions.
///
/// Over every sample point of every part, with `(a, b)` the horizontal part of its normal in a
/// fixed basis `(e1, e2)` of the plane normal to `up`, `c = Σ w (a + ib)⁴`; `u1` is at angle
/// `arg(c) / 4` from `e1`. Faces at right angles reinforce each other, so for a model of
/// axis-aligned boxes `u1` is one of its horizontal axes. Turning the model about `up` by `ψ`
/// turns `c` by `4ψ`, so the frame turns with the model up to a quarter turn: the contact
/// directions of a turned model are those of the original with `+u1, +u2, −u1, −u2` shifted
/// cyclically. When `|c|` is below a tenth of `Σ w |(a, b)|⁴` (round or irregular models) the
/// frame is undefined and the horizontal directions are spread evenly (see
/// [`contact_directions`]).
pub fn horizontal_frame(samples: &[SurfaceSample], up: Vec3) -> Option<(Vec3, Vec3)> {
    let up = up.normalize_or_zero();
    // a basis that depends only on the up axis: the world axis after up's largest component
    let e1 = {
        let mut v = Vec3::ZERO;
        v[(up.abs().max_position() + 1) % 3] = 1.0;
        (v - up * up.dot(v)).normalize_or_zero()
    };
    let e2 = up.cross(e1);
    let (mut re, mut im, mut total) = (0.0f64, 0.0f64, 0.0f64);
    for s in samples {
        for (n, &w) in s.normals.iter().zip(&s.weights) {
            let (a, b, w) = (n.dot(e1) as f64, n.dot(e2) as f64, w as f64);
            let (a2, b2) = (a * a - b * b, 2.0 * a * b); // (a + ib)²
            re += w * (a2 * a2 - b2 * b2);
            im += w * 2.0 * a2 * b2;
            total += w * (a * a + b * b) * (a * a + b * b);
        }
    }
    if total <= 0.0 || (re * re + im * im).sqrt() < 0.1 * total {
        return None;
    }
    let alpha = (im.atan2(re) / 4.0) as f32;
    let u1 = e1 * alpha.cos() + e2 * alpha.sin();
    Some((u1, up.cross(u1)))
}

/// The contact directions of `region` of `sample` (zeros when empty): per point the positive
/// parts of `n·u1`, `n·u2`, `−n·u1`, `−n·u2`, `n·up`, `−n·up`, averaged with the area weights.
/// Without a frame, each horizontal entry is a quarter of the mean horizontal length of `n`.
pub fn contact_directions(sample: &SurfaceSample, region: &[u32], frame: Option<(Vec3, Vec3)>, up: Vec3) -> [f32; DIRECTION_BINS] {
    let mut sum = [0.0f64; DIRECTION_BINS];
    let mut total = 0.0f64;
    for &k in region {
        let (n, w) = (sample.normals[k as usize], sample.weights[k as usize] as f64);
        total += w;
        let v = up.dot(n);
        match frame {
            Some((u1, u2)) => {
                let (a, b) = (u1.dot(n), u2.dot(n));
                for (slot, c) in [a, b, -a, -b].into_iter().enumerate() {
                    sum[slot] += w * c.max(0.0) as f64;
                }
            }
            None => {
                let h = (n - up * v).length() as f64 / 4.0;
                for slot in sum.iter_mut().take(4) {
                    *slot += w * h;
                }
            }
        }
        sum[4] += w * v.max(0.0) as f64;
        sum[5] += w * (-v).max(0.0) as f64;
    }
    if total > 0.0 {
        sum.map(|v| (v / total) as f32)
    } else {
        [0.0; DIRECTION_BINS]
    }
}
