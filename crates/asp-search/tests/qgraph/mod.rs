//! The state graph of learned Q-functions (`asp_search::qgraph`, features `asp-q/1`): the
//! layout of docs/learning.md, checked column by column against the distance maps, the
//! neighbours against a brute-force search, the history against the objective's memory, and
//! invariance under the model's scale.

use crate::fixtures::{maps, problem, soma};
use asp_geom::distmap::MapState;
use asp_search::qgraph::{direction_history, QGraph, QGraphBuilder, QGraphConfig};
use asp_search::StepKind;
use rand::{RngExt, SeedableRng};

const K: usize = 4;

#[test]
fn every_column_follows_the_contract() {
    let assembly = soma(4, 3);
    let maps = maps(&assembly, 5);
    let p = problem(&maps, "access,dirchange");
    let mut builder = QGraphBuilder::new(&maps, K);
    let config = builder.config();
    assert_eq!(config, QGraphConfig { directions: 25, neighbours: K });
    let (nd, ed, d) = (config.node_dim(), config.edge_dim(), 25);
    let n_parts = maps.num_parts();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut state = MapState::new(&maps);
    let mut memory = p.initial_memory();
    let mut rewards = vec![0.0; 2];
    let mut graph = QGraph::default();
    let mut actions = Vec::new();
    let mut steps = 0;
    loop {
        state.feasible_actions(&mut actions);
        let history = direction_history(&p, &memory);
        builder.build(&mut state, history, &actions, &mut graph);
        let present: Vec<usize> = (0..n_parts).filter(|&i| state.contains(i)).collect();
        let n = present.len() + 1;
        assert_eq!(graph.num_nodes(), n);
        assert_eq!(graph.x.len(), n * nd);
        assert_eq!(&graph.nodes[..n - 1], &present.iter().map(|&i| i as i64).collect::<Vec<_>>()[..]);
        assert_eq!(graph.nodes[n - 1], -1);
        let state_set = state.present();
        for (k, &i) in present.iter().enumerate() {
            let row = &graph.x[k * nd..(k + 1) * nd];
            assert_eq!(row[0], 1.0);
            assert_eq!(row[1], 0.0);
            assert_eq!(row[2], f32::from(u8::from(maps.is_fixed(i))));
            assert_eq!(row[3], f32::from(u8::from(actions.contains(&i))), "action flag of part {i}");
            let b = maps.part_aabb(i);
            // corner 7 is the box's max corner, corner 0 its min: their difference is the box's size / L
            for axis in 0..3 {
                let size = (row[4 + 21 + axis] - row[4 + axis]) * maps_diagonal(&maps);
                let want = [b.maxs.x - b.mins.x, b.maxs.y - b.mins.y, b.maxs.z - b.mins.z][axis];
                assert!((size - want).abs() < 1e-4 * want.max(1e-3), "corner extent {size} vs {want}");
            }
            let min_map = maps.min_map(i, &state_set);
            for dir in 0..d {
                let want = (min_map[dir] / maps.d_max()).clamp(0.0, 1.0);
                assert!((row[28 + dir] - want).abs() < 1e-6, "min map of {i} at {dir}");
                let free = maps.free_mask(i, &state_set).contains(dir);
                assert_eq!(row[28 + d + dir], f32::from(u8::from(free)), "free direction {dir} of {i}");
            }
        }
        let ctx = &graph.x[(n - 1) * nd..n * nd];
        assert_eq!((ctx[0], ctx[1], ctx[2], ctx[3]), (1.0, 1.0, 0.0, 0.0));
        for dir in 0..d {
            let want = history.is_some_and(|h| h.contains(dir));
            assert_eq!(ctx[28 + d + dir], f32::from(u8::from(want)), "history direction {dir}");
        }
        assert!(ctx[4..28 + d].iter().all(|&v| v == 0.0));

        // edges: per target in node order, its K nearest present parts, then the context edge
        let e = graph.num_edges();
        assert_eq!(graph.edge_attr.len(), e * ed);
        let (sources, targets) = graph.edge_index.split_at(e);
        let mut k = 0;
        for (t_pos, &t) in present.iter().enumerate() {
            let centre = |i: usize| {
                let b = maps.part_aabb(i);
                (b.mins + b.maxs) * 0.5
            };
            let mut others: Vec<usize> = present.iter().copied().filter(|&s| s != t).collect();
            others.sort_by(|&a, &b| centre(t).distance_squared(centre(a)).total_cmp(&centre(t).distance_squared(centre(b))).then(a.cmp(&b)));
            others.truncate(K);
            for &s in &others {
                assert_eq!(targets[k], t_pos as i64);
                assert_eq!(present[sources[k] as usize], s, "neighbour of {t}");
                let row = &graph.edge_attr[k * ed..(k + 1) * ed];
                assert_eq!(row[0], 0.0);
                let v = centre(s) - centre(t);
                assert!((row[4] * maps_diagonal(&maps) - v.length()).abs() < 1e-5);
                for dir in 0..d {
                    assert!((row[5 + dir] - (maps.map(t, s)[dir] / maps.d_max()).clamp(0.0, 1.0)).abs() < 1e-6);
                    assert_eq!(row[5 + d + dir], f32::from(u8::from(!maps.blocked(t, s).contains(dir))));
                }
                k += 1;
            }
            assert_eq!((sources[k], targets[k]), ((n - 1) as i64, t_pos as i64), "context edge of {t}");
            let row = &graph.edge_attr[k * ed..(k + 1) * ed];
            assert_eq!(row[0], 1.0);
            assert!(row[1..].iter().all(|&v| v == 0.0));
            k += 1;
        }
        assert_eq!(k, e);

        if actions.is_empty() {
            break;
        }
        let a = actions[rng.random_range(0..actions.len())];
        p.step(&mut state, &mut memory, a, StepKind::Simulation, &mut rewards);
        steps += 1;
        // after a removal the history is the objective's
        assert!(direction_history(&p, &memory).is_some());
    }
    assert!(steps >= 5, "the walk removed {steps} parts");
    // without a dirchange objective there is no history
    let access = problem(&maps, "access");
    assert_eq!(direction_history(&access, &access.initial_memory()), None);
}

fn maps_diagonal(maps: &asp_geom::distmap::DistanceMaps) -> f32 {
    let (mut lo, mut hi) = (asp_geom::math::Vec3::splat(f32::INFINITY), asp_geom::math::Vec3::splat(f32::NEG_INFINITY));
    for i in 0..maps.num_parts() {
        lo = lo.min(maps.part_aabb(i).mins);
        hi = hi.max(maps.part_aabb(i).maxs);
    }
    (hi - lo).length()
}

#[test]
fn graphs_do_not_depend_on_the_model_scale() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let cube = asp_gen::SomaCube::random(4, &mut rng).unwrap();
    let small = cube.to_assembly(0.05, "small");
    let large = cube.to_assembly(0.5, "large");
    let (ms, ml) = (maps(&small, 5), maps(&large, 5));
    let (mut bs, mut bl) = (QGraphBuilder::new(&ms, 8), QGraphBuilder::new(&ml, 8));
    let (mut ss, mut sl) = (MapState::new(&ms), MapState::new(&ml));
    let (mut gs, mut gl) = (QGraph::default(), QGraph::default());
    let (mut actions, mut other) = (Vec::new(), Vec::new());
    loop {
        ss.feasible_actions(&mut actions);
        sl.feasible_actions(&mut other);
        assert_eq!(actions, other);
        bs.build(&mut ss, None, &actions, &mut gs);
        bl.build(&mut sl, None, &actions, &mut gl);
        assert_eq!(gs.nodes, gl.nodes);
        assert_eq!(gs.edge_index, gl.edge_index);
        let worst = gs.x.iter().zip(&gl.x).chain(gs.edge_attr.iter().zip(&gl.edge_attr)).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
        assert!(worst < 1e-4, "scaled graphs differ by {worst}");
        let Some(&a) = actions.first() else { break };
        ss.remove(a);
        sl.remove(a);
    }
}
