//! Graph features (thesis 3.4, `docs/learning.md`): descriptor invariance, the graphs of fixture
//! assemblies and their invariance under moving the whole model with its up axis, state graphs
//! against a naive induced subgraph, and finite features on every shipped model.

use asp_geom::fixtures::{self, assemble, box_part, part, voxel_part};
use asp_geom::graph::{sample_surface, sh_descriptor, AssemblyGraph, GraphConfig, StateGraph};
use asp_geom::io::{load, LoadOptions};
use asp_geom::math::{Axis, Rot, Vec3};
use asp_geom::{Assembly, Mesh, PartSet, Units, World, WorldConfig};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");

fn z_up() -> LoadOptions {
    LoadOptions { up: Some(Axis::Z), ..LoadOptions::default() }
}

fn pump() -> Assembly {
    let mm = LoadOptions { unit: Units::parse("mm"), up: Some(Axis::Z), ..LoadOptions::default() };
    load(&Path::new(DATA).join("pump"), &mm).expect("pump loads")
}

fn chair() -> Assembly {
    load(&Path::new(DATA).join("ikea/chair_bertil_0148.glb"), &z_up()).expect("chair loads")
}

/// A rigid motion and uniform scale: `x ↦ s R x + t`.
#[derive(Clone, Copy, Debug)]
struct Similarity {
    rot: Rot,
    scale: f32,
    shift: Vec3,
}

impl Similarity {
    fn apply(&self, v: Vec3) -> Vec3 {
        self.scale * (self.rot * v) + self.shift
    }

    fn mesh(&self, m: &Mesh) -> Mesh {
        Mesh::new(m.vertices.iter().map(|v| self.apply(*v)).collect(), m.triangles.clone())
    }

    /// The axis `up` turns into (the rotation must map axes to axes).
    fn axis(&self, up: Axis) -> Axis {
        let v = self.rot * up.vector();
        let index = v.abs().max_position();
        assert!(v[index].abs() > 0.9999, "{v:?} is not an axis");
        Axis { index: index as u8, negative: v[index] < 0.0 }
    }

    fn assembly(&self, a: &Assembly) -> Assembly {
        let mut b = a.clone();
        for p in &mut b.parts {
            p.mesh = self.mesh(&p.mesh);
        }
        b.up = self.axis(a.up);
        b
    }
}

fn random_rotation(rng: &mut ChaCha8Rng) -> Rot {
    loop {
        let q = [0; 4].map(|_| rng.random_range(-1.0f32..1.0));
        let n = q.iter().map(|c| c * c).sum::<f32>().sqrt();
        if n > 0.1 && n <= 1.0 {
            return Rot::from_xyzw(q[0] / n, q[1] / n, q[2] / n, q[3] / n);
        }
    }
}

/// A random similarity with scale in 0.01..100 (log-uniform) and a shift of up to 10 times
/// `size` (the model's size: f32 coordinates far from the model lose its details).
fn random_similarity(rng: &mut ChaCha8Rng, rot: Rot, size: f32) -> Similarity {
    let scale = 10f32.powf(rng.random_range(-2.0..2.0));
    let shift = Vec3::new(rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0), rng.random_range(-10.0..10.0));
    Similarity { rot, scale, shift: shift * scale * size }
}

/// A random rotation that maps `up` to an axis: a turn about `up`, then one of the 24 rotations
/// of the cube.
fn random_up_rotation(rng: &mut ChaCha8Rng, up: Axis) -> Rot {
    let turn = Rot::from_axis_angle(up.vector(), rng.random_range(0.0..std::f32::consts::TAU));
    let quarter = |axis: Vec3, k: u32| Rot::from_axis_angle(axis, k as f32 * std::f32::consts::FRAC_PI_2);
    let cube =
        quarter(Vec3::X, rng.random_range(0..4)) * quarter(Vec3::Y, rng.random_range(0..4)) * quarter(Vec3::Z, rng.random_range(0..4));
    cube * turn
}

fn descriptor_of(mesh: &Mesh, config: &GraphConfig) -> Vec<f32> {
    let s = sample_surface(mesh, config.points_per_part);
    sh_descriptor(&s.points, &s.weights, config)
}

/// Largest entry-wise difference relative to the largest entry.
fn relative_gap(a: &[f32], b: &[f32]) -> f32 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f32, |m, v| m.max(v.abs())).max(1e-6);
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f32::max) / scale
}

fn l_shape() -> Mesh {
    voxel_part("l", &[[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 2, 0], [0, 0, 1]], 0.5).mesh
}

fn test_meshes() -> Vec<(&'static str, Mesh)> {
    let pump = pump();
    let screw = pump.parts.iter().find(|p| p.name.contains("Screw1")).expect("a screw in the pump").mesh.clone();
    let lid = pump.parts.iter().find(|p| p.name.contains("- Lid")).expect("the pump's lid").mesh.clone();
    vec![
        ("l_voxels", l_shape()),
        ("box_1x2x3", Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0))),
        ("cube", Mesh::cuboid(Vec3::ZERO, Vec3::ONE)),
        ("pump_screw", screw),
        ("pump_lid", lid),
    ]
}

#[test]
fn descriptors_are_invariant_to_rotation_translation_and_scale() {
    let config = GraphConfig::default();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for (name, mesh) in test_meshes() {
        let h = descriptor_of(&mesh, &config);
        assert_eq!(h.len(), 72);
        assert!(h.iter().all(|v| v.is_finite() && (0.0..=1.0 + 1e-6).contains(v)), "{name}: {h:?}");
        let mut worst = 0.0f32;
        for _ in 0..6 {
            let rot = random_rotation(&mut rng);
            let size = mesh.aabb().map_or(1.0, |b| (b.maxs - b.mins).length());
            let sim = random_similarity(&mut rng, rot, size);
            let g = descriptor_of(&sim.mesh(&mesh), &config);
            let gap = relative_gap(&h, &g);
            worst = worst.max(gap);
            assert!(gap < 1e-4, "{name} under {sim:?}: relative gap {gap}");
        }
        eprintln!("{name}: worst relative gap {worst:.2e}");
    }
}

#[test]
fn different_shapes_have_different_descriptors() {
    let config = GraphConfig::default();
    let shapes = test_meshes();
    let hs: Vec<Vec<f32>> = shapes.iter().map(|(_, m)| descriptor_of(m, &config)).collect();
    for i in 0..hs.len() {
        for j in (i + 1)..hs.len() {
            let gap = relative_gap(&hs[i], &hs[j]);
            assert!(gap > 0.02, "{} and {} differ by only {gap}", shapes[i].0, shapes[j].0);
        }
    }
    // a mirror image is a different point set but the same descriptor (rotation invariance does
    // not tell chirality apart); a stretched box is a different shape
    let stretched = Mesh::cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 6.0));
    assert!(relative_gap(&hs[1], &descriptor_of(&stretched, &config)) > 0.02);
}

fn world(a: Assembly, config: &WorldConfig) -> World {
    World::new(a, config).expect("world builds")
}

fn graph(w: &World) -> AssemblyGraph {
    AssemblyGraph::build(w, &GraphConfig::default()).expect("graph builds")
}

#[test]
fn stacked_boxes_have_the_expected_edges_and_gravity_attributes() {
    let w = world(fixtures::stacked_boxes(), &WorldConfig::default());
    let g = graph(&w);
    assert_eq!(g.features(), "asp-graph/2 radius_bins=8 degree=8 points=2048");
    assert_eq!((g.num_parts(), g.node_dim(), g.edge_dim()), (3, 74, 152));
    // base 0, lower 1, top 2: sorted by (source, target)
    assert_eq!(g.edges(), &[(0, 1), (1, 0), (1, 2), (2, 1)]);
    let d = 72;
    let above = |k: usize| g.edge_attr(k)[2 * d + 6];
    let normal_up = |k: usize| g.edge_attr(k)[2 * d + 7];
    let directions = |k: usize| &g.edge_attr(k)[2 * d..2 * d + 6];
    // 0 → 1: the base is below the lower box, whose contact region is its bottom (a ceiling)
    assert_eq!((above(0), normal_up(0)), (-1.0, -1.0));
    // 1 → 0: the lower box is above the base, which receives it on its top face (a floor)
    assert_eq!((above(1), normal_up(1)), (1.0, 1.0));
    assert_eq!((above(2), normal_up(2)), (-1.0, -1.0));
    assert_eq!((above(3), normal_up(3)), (1.0, 1.0));
    // contact directions (+u1, +u2, -u1, -u2, +up, -up): a ceiling faces down, a floor up
    assert_eq!(directions(0), &[0.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
    assert_eq!(directions(1), &[0.0, 0.0, 0.0, 0.0, 1.0, 0.0]);
    // fixed, on_base
    let flags = |i: usize| (g.node_attr(i)[d], g.node_attr(i)[d + 1]);
    assert_eq!(flags(0), (1.0, 0.0));
    assert_eq!(flags(1), (0.0, 1.0));
    assert_eq!(flags(2), (0.0, 0.0));
    // the two boxes are congruent, and so are their contact regions with each other (unit
    // squares), while the lower box's region on the base is also a unit square
    assert!(relative_gap(&g.node_attr(1)[..d], &g.node_attr(2)[..d]) < 1e-5);
    let (h01, h12) = (g.edge_attr(2), g.edge_attr(1));
    assert!(relative_gap(&h01[..d], &h01[d..2 * d]) < 1e-5, "the two faces of the box-box contact");
    // the base's footprint is sampled by its own (coarser) triangles: close, not equal
    let footprint = relative_gap(&h12[..d], &h12[d..2 * d]);
    assert!(footprint < 0.2, "the base's footprint and the box's bottom differ by {footprint}");
    // edge s → t and t → s carry the same two regions, swapped
    assert_eq!(&g.edge_attr(0)[..d], &g.edge_attr(1)[d..2 * d]);
    assert_eq!(&g.edge_attr(0)[d..2 * d], &g.edge_attr(1)[..d]);
    // a region is not the whole part
    assert!(relative_gap(&g.node_attr(1)[..d], &h01[..d]) > 0.02);
    // flat accessors agree with the rows
    assert_eq!(&g.nodes_flat()[74..148], g.node_attr(1));
    assert_eq!(&g.edge_attr_flat()[152 * 3..], g.edge_attr(3));
}

/// Distance from `p` to the surface of the box `[lo, hi]`, for `p` outside or on it.
fn box_distance(p: Vec3, lo: Vec3, hi: Vec3) -> f32 {
    (lo - p).max(p - hi).max(Vec3::ZERO).length()
}

#[test]
fn edge_attributes_follow_the_contract_order_computed_naively() {
    // a small box on a big one, with a wide contact distance so the two regions differ: the
    // top box's region includes bands of its sides, the lower one's a patch of its top face
    let (lo_a, hi_a) = (Vec3::ZERO, Vec3::ONE);
    let (lo_b, hi_b) = (Vec3::new(0.2, 0.3, 1.0), Vec3::new(0.7, 0.6, 1.4));
    let a = assemble(
        "small_on_big",
        vec![part("big", Mesh::cuboid(lo_a, hi_a), true), part("small", Mesh::cuboid(lo_b, hi_b), false)],
        Axis::Z,
    );
    let eps = 0.15;
    let w = world(a, &WorldConfig { contact_distance: Some(eps), ..WorldConfig::default() });
    let config = GraphConfig::default();
    let g = AssemblyGraph::build(&w, &config).unwrap();
    assert_eq!(g.edges(), &[(0, 1), (1, 0)]);
    let samples: Vec<_> = (0..2)
        .map(|i| asp_geom::graph::sample::sample_triangles(w.shapes().mesh(i).vertices(), w.shapes().mesh(i).indices(), 2048))
        .collect();
    let boxes = [(lo_a, hi_a), (lo_b, hi_b)];
    // Q_i^j, the naive way, as (points, weights, normals)
    let region = |i: usize, j: usize| {
        let s = &samples[i];
        let keep: Vec<usize> = (0..s.len()).filter(|&k| box_distance(s.points[k], boxes[j].0, boxes[j].1) < eps).collect();
        let pts: Vec<Vec3> = keep.iter().map(|&k| s.points[k]).collect();
        let wts: Vec<f32> = keep.iter().map(|&k| s.weights[k]).collect();
        let up: f32 = keep.iter().map(|&k| s.weights[k] * s.normals[k].z).sum::<f32>() / wts.iter().sum::<f32>();
        (sh_descriptor(&pts, &wts, &config), up, pts.len())
    };
    let (h01, up01, n01) = region(0, 1); // on the big box, near the small one
    let (h10, up10, n10) = region(1, 0);
    assert!(n01 > 10 && n10 > 10 && relative_gap(&h01, &h10) > 0.02, "the regions must differ");
    let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-5);
    let c = [samples[0].centroid().unwrap(), samples[1].centroid().unwrap()];
    // edge 0 → 1: [h(Q_1^0), h(Q_0^1), up · unit(c_0 − c_1), normal_up over Q_1^0]
    let e = g.edge_attr(0);
    assert!(close(&e[..72], &h10) && close(&e[72..144], &h01));
    assert!((e[150] - (c[0] - c[1]).normalize().z).abs() < 1e-6 && e[150] < -0.5);
    assert!((e[151] - up10).abs() < 1e-5, "{} vs {up10}", e[151]);
    // its bottom faces down, its side bands sideways
    assert!(e[151] < -0.2 && e[151] > -0.6, "the small box's region: {}", e[151]);
    // the contact directions: the bottom's share faces -up, the side bands' shares face the four
    // horizontal ways (the frame of boxes is their axes), and the shares sum to one
    assert!((e[149] - (-up10)).abs() < 1e-5 && e[148] == 0.0, "{:?}", &e[144..150]);
    assert!(e[144..148].iter().all(|v| *v > 0.02), "{:?}", &e[144..150]);
    assert!((e[144..150].iter().sum::<f32>() - 1.0).abs() < 1e-5, "{:?}", &e[144..150]);
    // edge 1 → 0: [h(Q_0^1), h(Q_1^0), up · unit(c_1 − c_0), normal_up over Q_0^1]
    let e = g.edge_attr(1);
    assert!(close(&e[..72], &h01) && close(&e[72..144], &h10));
    assert!((e[150] - (c[1] - c[0]).normalize().z).abs() < 1e-6 && e[150] > 0.5);
    assert!((e[151] - up01).abs() < 1e-5 && e[151] > 0.99, "the big box's region is a floor: {}", e[151]);
    assert!((e[148] - up01).abs() < 1e-5, "{:?}", &e[144..150]);
    // node attributes are the whole part's descriptor, fixed and on_base
    for (i, s) in samples.iter().enumerate() {
        assert!(close(&g.node_attr(i)[..72], &sh_descriptor(&s.points, &s.weights, &config)));
    }
    assert_eq!(&g.node_attr(0)[72..], &[1.0, 0.0]);
    assert_eq!(&g.node_attr(1)[72..], &[0.0, 1.0]);
}

#[test]
fn without_a_fixed_part_the_ground_is_the_base_but_no_node() {
    let a = assemble(
        "free_stack",
        vec![box_part("lower", [0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), box_part("top", [0.0, 0.0, 1.0], [1.0, 1.0, 2.0])],
        Axis::Z,
    );
    let w = world(a, &WorldConfig::default());
    assert_eq!(w.shapes().ground(), Some(2));
    let g = graph(&w);
    assert_eq!(g.num_parts(), 2);
    assert_eq!(g.edges(), &[(0, 1), (1, 0)]);
    assert_eq!(&g.node_attr(0)[72..], &[0.0, 1.0]);
    assert_eq!(&g.node_attr(1)[72..], &[0.0, 0.0]);
}

/// Every attribute of `g` and `h` within `tol` (absolute: every entry is in [-1, 1]), except
/// that the horizontal contact directions (`+u1, +u2, -u1, -u2`) of `h` may be those of `g`
/// turned by the same number of quarter turns on every edge: the model's horizontal frame turns
/// with the model only up to a quarter turn (`asp_geom::graph::horizontal_frame`).
fn assert_same_graph(g: &AssemblyGraph, h: &AssemblyGraph, tol: f32, what: &str) {
    assert_eq!(g.edges(), h.edges(), "{what}: edges");
    let gap = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(x, y)| (x - y).abs()).fold(0.0f32, f32::max);
    let nodes = gap(g.nodes_flat(), h.nodes_flat());
    let d = 2 * g.config().descriptor_dim();
    let turned = |k: usize, q: usize| -> Vec<f32> {
        let mut e = g.edge_attr(k).to_vec();
        e[d..d + 4].rotate_right(q);
        e
    };
    let edges =
        (0..4).map(|q| (0..g.num_edges()).map(|k| gap(&turned(k, q), h.edge_attr(k))).fold(0.0f32, f32::max)).fold(f32::INFINITY, f32::min);
    assert!(nodes < tol && edges < tol, "{what}: node gap {nodes}, edge gap {edges}");
}

#[test]
fn graph_attributes_are_invariant_when_the_model_moves_with_its_up_axis() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let tilted_stack = {
        // the stack with its up axis along -y
        let sim = Similarity { rot: Rot::from_rotation_x(std::f32::consts::FRAC_PI_2), scale: 1.0, shift: Vec3::ZERO };
        sim.assembly(&fixtures::stacked_boxes())
    };
    assert_eq!(tilted_stack.up, Axis { index: 1, negative: true });
    let models = [
        fixtures::stacked_boxes(),
        tilted_stack,
        fixtures::tube(),
        fixtures::arch(),
        fixtures::figure_6_2(0.1),
        assemble(
            "l_on_box",
            vec![part("slab", Mesh::cuboid(Vec3::new(-1.0, -1.0, -0.2), Vec3::new(2.0, 2.0, 0.0)), true), {
                let mut l = voxel_part("l", &[[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [0, 0, 1]], 0.5);
                l.fixed = false;
                l
            }],
            Axis::Z,
        ),
    ];
    for a in models {
        let name = a.source.display().to_string();
        let base_world = world(a.clone(), &WorldConfig::default());
        let (tol, eps) = (base_world.shapes().tolerance(), base_world.contacts().distance());
        let g = graph(&base_world);
        assert!(!g.edges().is_empty(), "{name}");
        for _ in 0..4 {
            let rot = random_up_rotation(&mut rng, a.up);
            let sim = random_similarity(&mut rng, rot, a.diagonal());
            let moved = sim.assembly(&a);
            let config =
                WorldConfig { tolerance: Some(tol * sim.scale), contact_distance: Some(eps * sim.scale), ..WorldConfig::default() };
            let h = graph(&world(moved, &config));
            assert_same_graph(&g, &h, 1e-4, &format!("{name} under {sim:?}"));
        }
    }
}

#[test]
fn a_real_model_keeps_its_part_features_when_moved_with_its_up_axis() {
    // the pump (mm, z up): 15 parts of curved, finely meshed surfaces
    let a = pump();
    let base_world = world(a.clone(), &WorldConfig::default());
    let (tol, eps) = (base_world.shapes().tolerance(), base_world.contacts().distance());
    let g = graph(&base_world);
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    for _ in 0..2 {
        let rot = random_up_rotation(&mut rng, a.up);
        let sim = random_similarity(&mut rng, rot, a.diagonal());
        let config = WorldConfig { tolerance: Some(tol * sim.scale), contact_distance: Some(eps * sim.scale), ..WorldConfig::default() };
        let h = graph(&world(sim.assembly(&a), &config));
        // the part descriptors and flags move with the model (on_base may not: see below)
        for i in 0..g.num_parts() {
            let gap = relative_gap(&g.node_attr(i)[..73], &h.node_attr(i)[..73]);
            assert!(gap < 1e-4, "pump part {i} under {sim:?}: {gap}");
        }
        // the world's contact graph (parry's closest points within ε_c) flips for screws that
        // sit about ε_c from a neighbour, so compare the edges both graphs have
        let mut differ = 0;
        for (k, e) in g.edges().iter().enumerate() {
            match h.edges().binary_search(e) {
                Ok(j) => {
                    let (ga, ha) = (g.edge_attr(k), h.edge_attr(j));
                    assert!((ga[150] - ha[150]).abs() < 1e-4, "pump edge {e:?}: above {} vs {}", ga[150], ha[150]);
                }
                Err(_) => differ += 1,
            }
        }
        differ += h.edges().iter().filter(|e| g.edges().binary_search(e).is_err()).count();
        assert!(differ <= 6, "pump under {sim:?}: {differ} edges differ");
    }
}

/// The induced subgraph the slow way: the contract's words, literally.
fn naive_state(g: &AssemblyGraph, present: &PartSet) -> StateGraph {
    let nodes: Vec<usize> = (0..g.num_parts()).filter(|&i| present.contains(i)).collect();
    let pos = |i: usize| nodes.iter().position(|&n| n == i).map(|p| p as i64);
    let mut x = Vec::new();
    for &i in &nodes {
        x.extend_from_slice(g.node_attr(i));
    }
    let (mut src, mut dst, mut attr) = (Vec::new(), Vec::new(), Vec::new());
    for (k, &(s, t)) in g.edges().iter().enumerate() {
        if let (Some(a), Some(b)) = (pos(s), pos(t)) {
            src.push(a);
            dst.push(b);
            attr.extend_from_slice(g.edge_attr(k));
        }
    }
    src.extend(dst);
    StateGraph { nodes, x, edge_index: src, edge_attr: attr, node_dim: g.node_dim(), edge_dim: g.edge_dim() }
}

/// Checks `state` and `state_into` against [`naive_state`] on `count` random subsets.
fn check_states(g: &AssemblyGraph, seed: u64, count: usize) {
    let n = g.num_parts();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut reused = StateGraph::default();
    for k in 0..count {
        let keep = [0.0, 1.0, 0.2, 0.5, 0.8][k % 5];
        let mut present = PartSet::from_indices(n, (0..n).filter(|_| rng.random_bool(keep)));
        if k % 7 == 0 {
            // the virtual ground (or any index beyond the parts) is no node
            present.insert(n);
        }
        let expect = naive_state(g, &present);
        let got = g.state(&present);
        assert_eq!(got, expect, "state {present:?}");
        assert_eq!(got.num_nodes(), expect.nodes.len());
        assert_eq!(got.num_edges() * 2, expect.edge_index.len());
        assert_eq!(got.x.len(), got.num_nodes() * g.node_dim());
        assert_eq!(got.edge_attr.len(), got.num_edges() * g.edge_dim());
        assert!(got.sources().iter().chain(got.targets()).all(|&p| (p as usize) < got.num_nodes()));
        g.state_into(&present, &mut reused);
        assert_eq!(reused, expect, "reused buffers, state {present:?}");
    }
    // the full state is the whole graph, the empty state is empty
    let full = g.state(&PartSet::full(n));
    assert_eq!(full.x, g.nodes_flat());
    assert_eq!(full.edge_attr, g.edge_attr_flat());
    let e = g.num_edges();
    for (k, &(s, t)) in g.edges().iter().enumerate() {
        assert_eq!((full.edge_index[k], full.edge_index[e + k]), (s as i64, t as i64));
    }
    let empty = StateGraph { node_dim: g.node_dim(), edge_dim: g.edge_dim(), ..StateGraph::default() };
    assert_eq!(g.state(&PartSet::empty(n)), empty);
}

#[test]
fn state_graphs_are_the_induced_subgraphs() {
    for a in [pump(), chair()] {
        let g = graph(&world(a, &WorldConfig::default()));
        assert!(g.num_parts() >= 5 && g.num_edges() >= 16, "{} parts, {} edges", g.num_parts(), g.num_edges());
        check_states(&g, 3, 60);
    }
    // a large random graph: bitsets of several words, beyond the inline 256 parts
    let config = GraphConfig::builder().radius_bins(2).degree(1).build().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let n = 300;
    let mut edges: Vec<(usize, usize)> = Vec::new();
    for _ in 0..1200 {
        let (s, t) = (rng.random_range(0..n), rng.random_range(0..n));
        if s != t {
            edges.extend([(s, t), (t, s)]);
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let nodes: Vec<f32> = (0..n * config.node_dim()).map(|_| rng.random_range(0.0..1.0)).collect();
    let attr: Vec<f32> = (0..edges.len() * config.edge_dim()).map(|_| rng.random_range(0.0..1.0)).collect();
    let g = AssemblyGraph::from_parts(&config, nodes, edges, attr).unwrap();
    check_states(&g, 5, 40);
}

#[test]
fn every_shipped_model_has_finite_consistent_features() {
    let data = Path::new(DATA);
    let mut models: Vec<(String, Assembly)> = vec![("pump".into(), pump())];
    models.push(("beam".into(), load(&data.join("beam/beam.glb"), &z_up()).expect("beam")));
    let mut ikea: Vec<_> = std::fs::read_dir(data.join("ikea")).expect("ikea folder").map(|e| e.unwrap().path()).collect();
    ikea.sort();
    assert!(ikea.len() >= 8);
    for p in ikea {
        models.push((p.display().to_string(), load(&p, &z_up()).expect("ikea model")));
    }
    // bed_dalselv has grossly overlapping boards
    let lenient = WorldConfig { overlaps: asp_geom::OverlapPolicy::Lenient, ..WorldConfig::default() };
    for (name, a) in models {
        let w = world(a, &lenient);
        let started = std::time::Instant::now();
        let g = graph(&w);
        eprintln!("{name}: {} parts, {} edges, built in {:?}", g.num_parts(), g.num_edges(), started.elapsed());
        // deterministic under rayon: a second build is bit-identical
        assert_eq!(graph(&w), g, "{name}: two builds differ");
        let n = g.num_parts();
        assert_eq!(g.nodes_flat().len(), n * 74);
        assert_eq!(g.edge_attr_flat().len(), g.num_edges() * 152);
        assert!(g.nodes_flat().iter().chain(g.edge_attr_flat()).all(|v| v.is_finite() && (-1.0 - 1e-5..=1.0 + 1e-5).contains(v)), "{name}");
        // edges are the world's contacts between real parts, both ways, sorted
        let expect: Vec<(usize, usize)> =
            (0..n).flat_map(|s| w.contacts().of(s).iter().filter(move |&t| t < n).map(move |t| (s, t))).collect();
        assert_eq!(g.edges(), &expect[..], "{name}");
        for &(s, t) in g.edges() {
            assert!(g.edges().binary_search(&(t, s)).is_ok(), "{name}: {s}->{t} without {t}->{s}");
        }
        // every part has a non-zero descriptor; touching parts mostly have a contact region
        for i in 0..n {
            assert!(g.node_attr(i)[..72].iter().sum::<f32>() > 0.0, "{name}: part {i}");
        }
        let nonempty = (0..g.num_edges()).filter(|&k| g.edge_attr(k)[..72].iter().any(|v| *v > 0.0)).count();
        assert!(nonempty * 2 >= g.num_edges(), "{name}: only {nonempty} of {} contact regions have points", g.num_edges());
    }
}

#[test]
fn bad_configuration_is_an_error() {
    let w = world(fixtures::stacked_boxes(), &WorldConfig::default());
    let bad = GraphConfig { degree: 21, ..GraphConfig::default() };
    let e = AssemblyGraph::build(&w, &bad).unwrap_err().to_string();
    assert!(e.contains("degree"), "{e}");
    let c = GraphConfig::default();
    assert!(AssemblyGraph::from_parts(&c, vec![0.0; 74 * 2], vec![(1, 0), (0, 1)], vec![0.0; 152 * 2]).is_err());
    assert!(AssemblyGraph::from_parts(&c, vec![0.0; 74 * 2], vec![(0, 2)], vec![0.0; 152]).is_err());
    assert!(AssemblyGraph::from_parts(&c, vec![0.0; 75], vec![], vec![]).is_err());
    let g = AssemblyGraph::from_parts(&c, vec![0.5; 74 * 2], vec![(0, 1), (1, 0)], vec![0.25; 152 * 2]).unwrap();
    assert_eq!(g.edges_from(1), 1..2);
    assert_eq!(g.edges_from(5), 0..0);
}
