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
    Part::new(name, Mesh::from_voxels(cells, Vec3::splat(cell), Vec3::ZERO), false, serde_json::json!({ "asp": { "voxels": cells } }))
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
        vec![voxel_part("base", &base, cell), voxel_part("top", &[[1, 1, 1]], cell), voxel_part("ball", &[[2, 1, 1]], cell)],
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
    let plate: Vec<[i32; 3]> =
        (0..3).flat_map(|x| (0..3).flat_map(move |y| (0..2).map(move |z| [x, y, z]))).filter(|c| *c != [1, 1, 1]).collect();
    assembly("peg_in_hole", vec![part("plate", voxels(&plate), true), part("peg", voxels(&[[1, 1, 1], [1, 1, 2]]), false)])
}

/// The four-part tube of the seed's figure 2.1, from boxes: a fixed receptacle (a square tube
/// along Z), a stick through it with zero clearance, a handle resting on the stick's top and a
/// cap closing the receptacle's bottom. The stick can never leave first: it leaves up after the
/// handle is gone, or down after the cap is gone (along ±Z only); handle and cap also slide off
/// sideways.
pub fn tube() -> Assembly {
    let ring: Vec<[i32; 3]> =
        (0..3).flat_map(|x| (0..3).flat_map(move |y| (0..4).map(move |z| [x, y, z]))).filter(|c| !(c[0] == 1 && c[1] == 1)).collect();
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
    let housing: Vec<[i32; 3]> =
        (0..5).flat_map(|x| (0..3).flat_map(move |y| (0..5).map(move |z| [x, y, z]))).filter(|c| !channel.contains(c)).collect();
    assembly("l_path", vec![part("housing", voxels(&housing), true), part("block", cuboid([1.2, 1.2, 1.2], [1.8, 1.8, 1.8]), false)])
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

/// Issue 9's locked core, in 1 cm voxels on the ground (no fixed part): a post whose foot is
/// caught in a cavity of the base (the shaft leaves through a hole narrower than the foot), a
/// ring around the shaft between the base and the post's head, and a cap lying on the head.
/// The cap lifts off; then ring, post and base hold each other in every direction (a locked
/// core). Together they can leave the ground as one subassembly, which cannot be taken apart.
/// Parts: 0 base, 1 post, 2 ring, 3 cap.
pub fn ring_on_locked_post() -> Assembly {
    let layer = |lo: i32, hi: i32, z: i32| (lo..hi).flat_map(move |x| (lo..hi).map(move |y| [x, y, z]));
    let foot: Vec<[i32; 3]> = layer(1, 4, 1).collect();
    let base: Vec<[i32; 3]> = (0..3).flat_map(|z| layer(0, 5, z)).filter(|c| !foot.contains(c) && *c != [2, 2, 2]).collect();
    let post: Vec<[i32; 3]> = foot.iter().copied().chain((2..6).map(|z| [2, 2, z])).chain(layer(1, 4, 6)).collect();
    let ring: Vec<[i32; 3]> = layer(1, 4, 3).filter(|c| *c != [2, 2, 3]).collect();
    let cap: Vec<[i32; 3]> = layer(1, 4, 7).collect();
    assembly(
        "ring_on_locked_post",
        vec![
            voxel_part("base", &base, 0.01),
            voxel_part("post", &post, 0.01),
            voxel_part("ring", &ring, 0.01),
            voxel_part("cap", &cap, 0.01),
        ],
    )
}

/// Issue 9's hooked shelf bracket, in 5 mm voxels: a fixed wall with a pocket whose opening
/// has a lip at its bottom, and a bracket whose hook hangs down behind the lip while its arm
/// comes out through the opening. No straight line frees it (the hook catches on the lip, the
/// pocket's roof stops it above); lifted by 10 mm until the hook clears the lip, it slides out.
/// Parts: 0 wall (fixed), 1 bracket.
pub fn hooked_bracket() -> Assembly {
    let cube = |x: std::ops::Range<i32>, y: std::ops::Range<i32>, z: std::ops::Range<i32>| {
        let mut cells = Vec::new();
        for i in x {
            for j in y.clone() {
                for k in z.clone() {
                    cells.push([i, j, k]);
                }
            }
        }
        cells
    };
    // pocket: a chamber behind the face (x 2..3, z 2..10) and its opening (x 3..4, z 6..10)
    let pocket: Vec<[i32; 3]> = [cube(2..3, 2..4, 2..10), cube(3..4, 2..4, 6..10)].concat();
    let wall: Vec<[i32; 3]> = cube(0..4, 0..6, 0..14).into_iter().filter(|c| !pocket.contains(c)).collect();
    // the hook (x 2..3, z 4..8) behind the lip (x 3..4, z 2..6), the arm out through the opening
    let bracket: Vec<[i32; 3]> = [cube(2..3, 2..4, 4..8), cube(3..10, 2..4, 6..8)].concat();
    let mut wall = voxel_part("wall", &wall, 0.005);
    wall.fixed = true;
    assembly("hooked_bracket", vec![wall, voxel_part("bracket", &bracket, 0.005)])
}

/// A closed prism along Z with a regular `sides`-gon of circumradius `radius` around `(x, y)`,
/// from `z0` to `z1` (a round peg or dowel, faceted), outward wound.
pub fn prism(x: f32, y: f32, radius: f32, z0: f32, z1: f32, sides: u32) -> Mesh {
    let mut vertices = Vec::with_capacity(2 * sides as usize + 2);
    for z in [z0, z1] {
        for i in 0..sides {
            let a = std::f32::consts::TAU * i as f32 / sides as f32;
            vertices.push(Vec3::new(x + radius * a.cos(), y + radius * a.sin(), z));
        }
    }
    vertices.push(Vec3::new(x, y, z0));
    vertices.push(Vec3::new(x, y, z1));
    let (bottom, top) = (2 * sides, 2 * sides + 1);
    let mut triangles = Vec::new();
    for i in 0..sides {
        let j = (i + 1) % sides;
        triangles.push([i, j, sides + j]);
        triangles.push([i, sides + j, sides + i]);
        triangles.push([bottom, j, i]);
        triangles.push([top, sides + i, sides + j]);
    }
    let mut m = Mesh::new(vertices, triangles);
    m.orient_outward();
    m
}

/// Issue 9's press fit: a fixed plate (3 × 3 × 1) and a round peg (radius 0.3, 16 facets)
/// pushed 0.5 deep into it with no modelled hole — an input overlap no shrinking separates.
/// Physically the peg leaves along its axis (+Z) only; sliding sideways would cut the plate.
/// Parts: 0 plate (fixed), 1 peg.
pub fn pressed_peg() -> Assembly {
    let mut plate = box_part("plate", [0.0, 0.0, 0.0], [3.0, 3.0, 1.0]);
    plate.fixed = true;
    assembly("pressed_peg", vec![plate, part("peg", prism(1.5, 1.5, 0.3, 0.5, 2.0, 16), false)])
}

/// A dowel pressed into two boards: a fixed lower board (3 × 3 × 1), an upper board on it
/// (3 × 3 × 1) and a round dowel (radius 0.3) from z 0.5 to 1.5, half in each, no holes
/// modelled. The upper board pulls off the dowel upward (only); the dowel then leaves upward
/// (only). Parts: 0 lower (fixed), 1 upper, 2 dowel.
pub fn dowel_in_two_boards() -> Assembly {
    let mut lower = box_part("lower", [0.0, 0.0, 0.0], [3.0, 3.0, 1.0]);
    lower.fixed = true;
    assembly(
        "dowel_in_two_boards",
        vec![lower, box_part("upper", [0.0, 0.0, 1.0], [3.0, 3.0, 2.0]), part("dowel", prism(1.5, 1.5, 0.3, 0.5, 1.5, 16), false)],
    )
}

/// Facets around a fastener (a multiple of 6, so the hexagons' corners are vertices).
const THREAD_FACETS: u32 = 12;

/// The triangles joining two closed rings of equal length, `a` to `b`: for rings running
/// counter-clockwise about +Z, outward (away from the axis) when `b` lies above `a`, facing -Z
/// when `b` lies outside `a` at the same height.
fn ring_strip(a: &[u32], b: &[u32], triangles: &mut Vec<[u32; 3]>) {
    let n = a.len();
    for i in 0..n {
        let j = (i + 1) % n;
        triangles.push([a[i], a[j], b[j]]);
        triangles.push([a[i], b[j], b[i]]);
    }
}

/// The radius of a regular hexagon of circumradius `r` (corners at 0°, 60°, ...) at angle `a`.
fn hexagon_radius(r: f32, a: f32) -> f32 {
    let sector = std::f32::consts::FRAC_PI_3;
    let off = a.rem_euclid(sector) - 0.5 * sector;
    r * (0.5 * sector).cos() / off.cos()
}

/// A metric-like thread: the radius at angle index `i` (of [`THREAD_FACETS`]) and height `z`,
/// for a right-handed helical V-thread of major radius `major`, depth `depth` and `pitch`, its
/// crest at height 0 on angle 0: the profile at `z - pitch·θ/2π`, a triangle wave.
fn thread_radius(major: f32, depth: f32, pitch: f32, i: u32, z: f32) -> f32 {
    let u = (z / pitch - i as f32 / THREAD_FACETS as f32).rem_euclid(1.0);
    major - depth * (1.0 - (2.0 * u - 1.0).abs())
}

/// The vertex rings of a helical surface about the Z axis through `(x, y)`: rows `z0 + k·dz`
/// for `k` in `rows`, each [`THREAD_FACETS`] vertices at `radius(i, z)`, counter-clockwise.
fn helical_rows(
    vertices: &mut Vec<Vec3>,
    (x, y): (f32, f32),
    z0: f32,
    dz: f32,
    rows: std::ops::RangeInclusive<u32>,
    radius: impl Fn(u32, f32) -> f32,
) -> Vec<Vec<u32>> {
    rows.map(|k| {
        let z = z0 + k as f32 * dz;
        (0..THREAD_FACETS)
            .map(|i| {
                let a = std::f32::consts::TAU * i as f32 / THREAD_FACETS as f32;
                let r = radius(i, z);
                vertices.push(Vec3::new(x + r * a.cos(), y + r * a.sin(), z));
                (vertices.len() - 1) as u32
            })
            .collect()
    })
    .collect()
}

/// A hexagonal ring of circumradius `r` at height `z` (one vertex per facet angle).
fn hexagon_ring(vertices: &mut Vec<Vec3>, centre: (f32, f32), r: f32, z: f32) -> Vec<u32> {
    let angle = |i: u32| std::f32::consts::TAU * i as f32 / THREAD_FACETS as f32;
    helical_rows(vertices, centre, z, 0.0, 0..=0, |i, _| hexagon_radius(r, angle(i))).remove(0)
}

/// The bolt and nut of [`bolt_and_nut`] for a clamped stack `grip` thick (metres), about the Z
/// axis: the head's bearing face at the top of the stack (`grip`, rounded to the thread's rows),
/// the nut's top face at z = 0, the shank 3 mm below the nut; `interference` as there. Returns
/// (bolt, nut), outward wound.
pub fn threaded_bolt_and_nut(grip: f32, interference: f32) -> (Mesh, Mesh) {
    let (major, depth, pitch) = (0.005f32, 0.0008f32, 0.0015f32);
    let (head_r, head_h, nut_h, below) = (0.009f32, 0.006f32, 0.006f32, 0.003f32);
    let dz = pitch / THREAD_FACETS as f32;
    let z0 = -(nut_h + below);
    let rows = |h: f32| (h / dz).round() as u32;
    let centre = (0.0, 0.0);
    // bolt: shank rows from z0 to the plate's top, head above
    let mut v = Vec::new();
    let mut t = Vec::new();
    let shank = helical_rows(&mut v, centre, z0, dz, 0..=rows(grip - z0), |i, z| thread_radius(major, depth, pitch, i, z));
    for w in shank.windows(2) {
        ring_strip(&w[0], &w[1], &mut t);
    }
    let top_z = z0 + rows(grip - z0) as f32 * dz;
    let head_lo = hexagon_ring(&mut v, centre, head_r, top_z);
    let head_hi = hexagon_ring(&mut v, centre, head_r, top_z + head_h);
    ring_strip(&shank[shank.len() - 1], &head_lo, &mut t); // the bearing face, facing -Z
    ring_strip(&head_lo, &head_hi, &mut t);
    v.push(Vec3::new(0.0, 0.0, top_z + head_h));
    let top = (v.len() - 1) as u32;
    v.push(Vec3::new(0.0, 0.0, z0));
    let bottom = (v.len() - 1) as u32;
    let n = THREAD_FACETS as usize;
    for i in 0..n {
        let j = (i + 1) % n;
        t.push([top, head_hi[i], head_hi[j]]);
        t.push([bottom, shank[0][j], shank[0][i]]);
    }
    let mut bolt = Mesh::new(v, t);
    bolt.orient_outward();
    // nut: the bore on the same helix (rows aligned with the bolt's), a hexagon outside
    let mut v = Vec::new();
    let mut t = Vec::new();
    let first = rows(below);
    let bore =
        helical_rows(&mut v, centre, z0, dz, first..=first + rows(nut_h), |i, z| thread_radius(major, depth, pitch, i, z) - interference);
    for w in bore.windows(2) {
        ring_strip(&w[1], &w[0], &mut t); // facing the axis
    }
    let (nut_lo, nut_hi) = (z0 + first as f32 * dz, z0 + (first + rows(nut_h)) as f32 * dz);
    let out_lo = hexagon_ring(&mut v, centre, head_r, nut_lo);
    let out_hi = hexagon_ring(&mut v, centre, head_r, nut_hi);
    ring_strip(&bore[0], &out_lo, &mut t);
    ring_strip(&out_lo, &out_hi, &mut t);
    ring_strip(&out_hi, &bore[bore.len() - 1], &mut t);
    let mut nut = Mesh::new(v, t);
    nut.orient_outward();
    (bolt, nut)
}

/// Issue 9's bolt and nut, in metres: a fixed plate (33 × 33 × 4 mm, a square clearance hole of
/// 11 mm around the Z axis), a hexagon-head bolt (major radius 5 mm, pitch 1.5 mm, a real helical
/// V-thread of depth 0.8 mm meshed with 12 facets per turn and rows a facet's rise
/// apart) whose head bears on the plate's top and whose shank reaches 3 mm below the nut, and a
/// hexagon nut (6 mm) under the plate with the matching internal thread, its bore drawn
/// `interference` inside the bolt's thread (0: the thread surfaces coincide, as they touch in
/// CAD; more: they overlap). Physically the bolt leaves only by unscrewing upward (+Z: its head
/// stops it downward, its thread sideways) and the nut only by unscrewing downward.
/// Parts: 0 plate (fixed), 1 bolt, 2 nut.
pub fn bolt_and_nut(interference: f32) -> Assembly {
    let plate_t = 0.004f32;
    let (bolt, nut) = threaded_bolt_and_nut(plate_t, interference);
    // the plate: 3 × 3 cells of 11 mm, the middle one open
    let cells: Vec<[i32; 3]> = (0..3).flat_map(|x| (0..3).map(move |y| [x, y, 0])).filter(|c| *c != [1, 1, 0]).collect();
    let cell = 0.011f32;
    let plate = Mesh::from_voxels(&cells, Vec3::new(cell, cell, plate_t), Vec3::new(-1.5 * cell, -1.5 * cell, 0.0));
    assembly("bolt_and_nut", vec![part("plate", plate, true), part("bolt", bolt, false), part("nut", nut, false)])
}
