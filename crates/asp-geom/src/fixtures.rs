//! Hand-built assemblies with known answers, for tests, benchmarks and examples.
//! All are in metres, +Z up.

use crate::assembly::{Assembly, Part, Units};
use crate::math::{Axis, Vec3};
use crate::mesh::Mesh;

/// A part with no metadata.
pub fn part(name: &str, mesh: Mesh, fixed: bool) -> Part {
    Part::new(name, mesh, fixed, serde_json::Value::Null)
}

/// A movable axis-aligned box from `mins` to `maxs`.
pub fn box_part(name: &str, mins: [f32; 3], maxs: [f32; 3]) -> Part {
    part(name, cuboid(mins, maxs), false)
}

/// A movable part made of the unit voxels `cells` scaled by `cell` (metres), carrying them in
/// its metadata (`extras.asp.voxels`) so distance maps sweep them exactly.
pub fn voxel_part(name: &str, cells: &[[i32; 3]], cell: f32) -> Part {
    Part::new(
        name,
        Mesh::from_voxels(cells, Vec3::splat(cell), Vec3::ZERO),
        false,
        serde_json::json!({ "asp": { "voxels": cells } }),
    )
}

/// An assembly in metres with `up` as the up axis; its source reads `fixture:{name}`.
pub fn assemble(name: &str, parts: Vec<Part>, up: Axis) -> Assembly {
    Assembly { parts, units: Units::metres(), up, source: format!("fixture:{name}").into(), warnings: Vec::new() }
}

fn assembly(name: &str, parts: Vec<Part>) -> Assembly {
    assemble(name, parts, Axis::Z)
}

fn cuboid(mins: [f32; 3], maxs: [f32; 3]) -> Mesh {
    Mesh::cuboid(Vec3::from_array(mins), Vec3::from_array(maxs))
}

fn voxels(cells: &[[i32; 3]]) -> Mesh {
    Mesh::from_voxels(cells, Vec3::ONE, Vec3::ZERO)
}

/// The thesis' figure 6.2 in voxels of `cell` metres, on the floor: a base cup (part 0), a top
/// part inside it that only leaves upward (part 1), and a ball in a side notch under an
/// overhang that only leaves along +x (part 2).
pub fn figure_6_2(cell: f32) -> Assembly {
    let mut base = Vec::new();
    for x in 0..3 {
        for y in 0..3 {
            base.push([x, y, 0]);
        }
    }
    base.extend([[0, 0, 1], [1, 0, 1], [2, 0, 1], [0, 1, 1], [0, 2, 1], [1, 2, 1], [2, 2, 1]]);
    base.extend([[2, 0, 2], [2, 1, 2], [2, 2, 2]]);
    assembly(
        "figure_6_2",
        vec![
            voxel_part("base", &base, cell),
            voxel_part("top", &[[1, 1, 1]], cell),
            voxel_part("ball", &[[2, 1, 1]], cell),
        ],
    )
}

/// A fixed base slab with two unit boxes stacked on it, same footprint. The top box leaves up or
/// sideways (sliding along the box below), never down; the lower box can slide out sideways but
/// that leaves the top box floating.
pub fn stacked_boxes() -> Assembly {
    assembly(
        "stacked_boxes",
        vec![
            part("base", cuboid([-1.0, -1.0, -0.5], [2.0, 2.0, 0.0]), true),
            part("lower", cuboid([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]), false),
            part("top", cuboid([0.0, 0.0, 1.0], [1.0, 1.0, 2.0]), false),
        ],
    )
}

/// A fixed plate (3 × 3 × 2) with a 1 × 1 blind hole of depth 1 and a peg of 1 × 1 × 2 in it
/// with zero clearance: the peg leaves only along +Z, the hole's axis.
pub fn peg_in_hole() -> Assembly {
    let plate: Vec<[i32; 3]> = (0..3)
        .flat_map(|x| (0..3).flat_map(move |y| (0..2).map(move |z| [x, y, z])))
        .filter(|c| *c != [1, 1, 1])
        .collect();
    assembly(
        "peg_in_hole",
        vec![part("plate", voxels(&plate), true), part("peg", voxels(&[[1, 1, 1], [1, 1, 2]]), false)],
    )
}

/// The four-part tube of the seed's figure 2.1, from boxes: a fixed receptacle (a square tube
/// along Z), a stick through it with zero clearance, a handle resting on the stick's top and a
/// cap closing the receptacle's bottom. The stick can never leave first: it leaves up after the
/// handle is gone, or down after the cap is gone (along ±Z only); handle and cap also slide off
/// sideways.
pub fn tube() -> Assembly {
    let ring: Vec<[i32; 3]> = (0..3)
        .flat_map(|x| (0..3).flat_map(move |y| (0..4).map(move |z| [x, y, z])))
        .filter(|c| !(c[0] == 1 && c[1] == 1))
        .collect();
    assembly(
        "tube",
        vec![
            part("receptacle", voxels(&ring), true),
            part("stick", cuboid([1.0, 1.0, 0.0], [2.0, 2.0, 5.0]), false),
            part("handle", cuboid([0.0, 0.0, 5.0], [3.0, 3.0, 5.5]), false),
            part("cap", cuboid([0.0, 0.0, -0.5], [3.0, 3.0, 0.0]), false),
        ],
    )
}

/// A fixed housing (5 × 3 × 5 cells) with an L-shaped channel: a 0.6 cube sits at the channel's
/// closed end and must move 2 along +X, then 3.5 up +Z to get out — no straight line works, a
/// path planner must find the L.
pub fn l_path() -> Assembly {
    let channel = [[1, 1, 1], [2, 1, 1], [3, 1, 1], [3, 1, 2], [3, 1, 3], [3, 1, 4]];
    let housing: Vec<[i32; 3]> = (0..5)
        .flat_map(|x| (0..3).flat_map(move |y| (0..5).map(move |z| [x, y, z])))
        .filter(|c| !channel.contains(c))
        .collect();
    assembly(
        "l_path",
        vec![
            part("housing", voxels(&housing), true),
            part("block", cuboid([1.2, 1.2, 1.2], [1.8, 1.8, 1.8]), false),
        ],
    )
}

/// A fixed base, two pillars and a keystone lying across both. Either pillar may slide out
/// first (the keystone still rests on the other), but the keystone must leave before the last
/// pillar: in assembly order, the keystone cannot be placed before its support.
pub fn arch() -> Assembly {
    assembly(
        "arch",
        vec![
            part("base", cuboid([-3.0, -1.0, -0.5], [3.0, 1.0, 0.0]), true),
            part("pillar_a", cuboid([-2.0, -0.5, 0.0], [-1.0, 0.5, 2.0]), false),
            part("pillar_b", cuboid([1.0, -0.5, 0.0], [2.0, 0.5, 2.0]), false),
            part("keystone", cuboid([-2.0, -0.5, 2.0], [2.0, 0.5, 2.5]), false),
        ],
    )
}
