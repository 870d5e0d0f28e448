//! Stress cases for the planner: small furniture and machine joints that a
//! person takes apart without thinking, but that single parts on straight lines cannot.
//!
//! - [`StressKind::Chair`]: four legs standing on the floor, a seat on tenons at the legs' tops,
//!   and rungs whose ends sit in blind pockets of two legs each. With rungs on two opposite
//!   sides a leg slides off its rung; with rungs on all four sides every leg and rung is held
//!   along every axis, and a leg pair leaves with the rung between them (a group), which is then
//!   taken apart in the hand.
//! - [`StressKind::Carcass`]: two side panels standing on the floor and two or three shelves
//!   between them, each shelf end joined to its side by round dowels along the shelf. The dowels
//!   sit in square pockets of both panels (holes modelled) or are drawn into solid panels (no
//!   holes, as many CAD exports do: an overlap that only leaves along the dowel's axis).
//! - [`StressKind::Bolted`]: two plates standing face to face on the floor, clamped by one to
//!   four bolts with helical threads through square clearance holes and nuts on the far side
//!   (the nut's thread touching the bolt's, or overlapping it by 0.1 mm): a nut turns off, then
//!   its bolt, then the plates part.
//!
//! Every variation (sizes, how many rungs, shelves, dowels or bolts, fits) is drawn from the seed.
//! Parts are closed meshes in metres, +Z up, on a fixed floor (the last part). Each part's boxes
//! (its exact shape for legs, rungs, panels and plates; the bounding box of a round dowel, a bolt
//! or a nut) feed the generator's own contact check; straight-line disassembly is not promised
//! (see [`crate::generator::Checks::straight_line_required`]).

use crate::check::{check_disassembly, BoxModel};
use crate::cuboid::{grid_union, Cuboid};
use asp_geom::fixtures::{prism, threaded_bolt_and_nut};
use asp_geom::math::{Axis, Vec3};
use asp_geom::{Assembly, Mesh, Part, Units};
use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};
use serde_json::json;

/// Which stress case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StressKind {
    /// A chair: legs, a seat on tenons, rungs in pockets of two legs each.
    Chair,
    /// Two side panels and shelves joined by dowels.
    Carcass,
    /// Two plates clamped by threaded bolts and nuts.
    Bolted,
}

impl StressKind {
    /// The kind's name in file names and the manifest.
    pub fn name(self) -> &'static str {
        match self {
            StressKind::Chair => "chair",
            StressKind::Carcass => "carcass",
            StressKind::Bolted => "bolted",
        }
    }
}

/// Parameters of the stress generator: only the kind; everything else comes from the seed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct StressParams {
    /// Which stress case.
    pub stress: StressKind,
}

/// One part under construction: its name, mesh, boxes (for the generator's check) and metadata.
struct Piece {
    name: String,
    mesh: Mesh,
    boxes: Vec<Cuboid>,
    meta: serde_json::Value,
}

/// A generated stress case.
pub struct StressCase {
    /// The kind.
    pub kind: StressKind,
    pieces: Vec<Piece>,
    /// The deepest designed overlap between two parts in metres (a press fit, a thread drawn
    /// into its mate, a dowel drawn into a solid panel); 0 when every part only touches.
    pub max_penetration: f64,
}

/// The union of the boxes `bodies` minus the boxes `pockets`, as one closed mesh and its cells:
/// every distinct box coordinate cuts a grid line, and a cell is kept when its centre lies in a
/// body and in no pocket.
fn pocketed(bodies: &[Cuboid], pockets: &[Cuboid]) -> (Mesh, Vec<Cuboid>) {
    let lines: [Vec<f64>; 3] = std::array::from_fn(|a| {
        let mut v: Vec<f64> = bodies.iter().chain(pockets).flat_map(|b| [b.mins[a], b.maxs[a]]).collect();
        v.sort_by(f64::total_cmp);
        v.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
        v
    });
    let inside = |b: &Cuboid, c: [f64; 3]| (0..3).all(|a| c[a] > b.mins[a] && c[a] < b.maxs[a]);
    let mut cells = Vec::new();
    for i in 0..lines[0].len() - 1 {
        for j in 0..lines[1].len() - 1 {
            for k in 0..lines[2].len() - 1 {
                let idx = [i, j, k];
                let centre: [f64; 3] = std::array::from_fn(|a| 0.5 * (lines[a][idx[a]] + lines[a][idx[a] + 1]));
                if bodies.iter().any(|b| inside(b, centre)) && !pockets.iter().any(|p| inside(p, centre)) {
                    cells.push([i as i32, j as i32, k as i32]);
                }
            }
        }
    }
    grid_union([&lines[0], &lines[1], &lines[2]], &cells)
}

/// A mesh whose vertex `(x, y, z)` becomes `map(x, y, z)`, re-wound outward (an axis swap
/// mirrors the winding).
fn mapped(mesh: &Mesh, map: impl Fn(Vec3) -> Vec3) -> Mesh {
    let mut m = Mesh::new(mesh.vertices.iter().map(|&v| map(v)).collect(), mesh.triangles.clone());
    m.orient_outward();
    m
}

/// The bounding box of a mesh.
fn bounds(mesh: &Mesh) -> Cuboid {
    let b = mesh.aabb().expect("a generated part has vertices");
    Cuboid::new([b.mins.x, b.mins.y, b.mins.z].map(f64::from), [b.maxs.x, b.maxs.y, b.maxs.z].map(f64::from))
}

fn b(mins: [f64; 3], maxs: [f64; 3]) -> Cuboid {
    Cuboid::new(mins, maxs)
}

impl StressCase {
    /// Generates the case of `kind`, its sizes, counts and fits drawn from `rng`.
    pub fn generate(kind: StressKind, rng: &mut impl Rng) -> StressCase {
        match kind {
            StressKind::Chair => chair(rng),
            StressKind::Carcass => carcass(rng),
            StressKind::Bolted => bolted(rng),
        }
    }

    /// Number of parts, the floor included.
    pub fn num_parts(&self) -> usize {
        self.pieces.len()
    }

    /// How many parts have names starting with `prefix` (e.g. `rung`, `dowel`, `bolt`).
    pub fn count(&self, prefix: &str) -> usize {
        self.pieces.iter().filter(|p| p.name.starts_with(prefix)).count()
    }

    /// The assembly: every part a closed mesh with its kind in the metadata, the floor fixed.
    pub fn to_assembly(&self, source: &str) -> Assembly {
        let last = self.pieces.len() - 1;
        let parts =
            self.pieces.iter().enumerate().map(|(i, p)| Part::new(p.name.clone(), p.mesh.clone(), i == last, p.meta.clone())).collect();
        Assembly { parts, units: Units::metres(), up: Axis::Z, source: source.into(), warnings: Vec::new() }
    }

    /// The generator's check on the parts' boxes (contacts within 1 µm, overlapping boxes
    /// included: fits and threads hold what they join): whether everything is linked to the
    /// floor, and whether single parts along ±axes would take it apart.
    pub fn check(&self) -> crate::check::DisassemblyCheck {
        let last = self.pieces.len() - 1;
        let parts = self.pieces.iter().map(|p| p.boxes.clone()).collect();
        let fixed = (0..self.pieces.len()).map(|i| i == last).collect();
        check_disassembly(&BoxModel::with_contacts(parts, fixed, 1e-6, true))
    }

    fn push(&mut self, name: String, (mesh, boxes): (Mesh, Vec<Cuboid>), meta: serde_json::Value) {
        self.pieces.push(Piece { name, mesh, boxes, meta });
    }

    fn floor(&mut self, lo: [f64; 2], hi: [f64; 2]) {
        let floor = b([lo[0] - 0.05, lo[1] - 0.05, -0.02], [hi[0] + 0.05, hi[1] + 0.05, 0.0]);
        self.push("floor".into(), (floor.mesh(), vec![floor]), json!({"kind": "floor"}));
    }
}

/// A chair (see the module's documentation). Legs `a` square, rungs half as thick, their ends
/// `0.4 a` deep in the legs; the seat's pockets take the legs' tenons.
fn chair(rng: &mut impl Rng) -> StressCase {
    let a = [0.035, 0.04, 0.045][rng.random_range(0..3)];
    let height = rng.random_range(0.40..0.46f64);
    let (width, depth) = (rng.random_range(0.40..0.44f64), rng.random_range(0.38..0.42f64));
    let seat_t = 0.02;
    let tenon = (0.6 * a, 0.012); // not as wide as the rungs: no face of one in a plane of the other
                                  // 0: rungs on the left and right sides; 1: on all four; 2: all four, the sides twice
    let layout = rng.random_range(0..3);
    // 0.1 mm press fit of the rung ends in half the chairs
    let press = if rng.random_bool(0.5) { 1e-4 } else { 0.0 };
    let inset = 0.01;
    let x = [inset, width - inset - a];
    let y = [inset, depth - inset - a];
    let (rt, end) = (0.5 * a, 0.4 * a);
    let mut rungs: Vec<(usize, f64)> = vec![(1, 0.15)]; // (axis the rung runs along, height of its centre)
    if layout >= 1 {
        rungs.push((0, 0.22));
    }
    if layout == 2 {
        rungs.push((1, 0.32));
    }
    let mut case = StressCase { kind: StressKind::Chair, pieces: Vec::new(), max_penetration: press };
    // legs: index (i, j) at x[i], y[j]
    let mut pockets: Vec<Vec<Cuboid>> = vec![Vec::new(); 4];
    let mut rung_parts = Vec::new();
    for &(along, z) in &rungs {
        let across = 1 - along;
        // one rung on each side: between legs (0, j)-(1, j) when along x, (i, 0)-(i, 1) along y
        for side in 0..2 {
            let (first, second) = if along == 0 { (side * 2, 1 + side * 2) } else { (side, 2 + side) };
            let pos = [x, y];
            let c_across = pos[across][side] + 0.5 * a;
            let inner_lo = pos[along][0] + a; // the first leg's inner face
            let inner_hi = pos[along][1]; // the second leg's inner face
            let mut lo = [0.0; 3];
            let mut hi = [0.0; 3];
            lo[along] = inner_lo - end;
            hi[along] = inner_hi + end;
            lo[across] = c_across - 0.5 * rt;
            hi[across] = c_across + 0.5 * rt;
            lo[2] = z - 0.5 * rt;
            hi[2] = z + 0.5 * rt;
            let rung = b(lo, hi);
            // the pockets are the rung's ends, shrunk by the press fit across the rung
            for (leg, range) in [(first, (inner_lo - end, inner_lo)), (second, (inner_hi, inner_hi + end))] {
                let mut p = rung;
                p.mins[along] = range.0;
                p.maxs[along] = range.1;
                for k in [across, 2] {
                    p.mins[k] += press;
                    p.maxs[k] -= press;
                }
                pockets[leg].push(p);
            }
            let name = format!("rung_{}", rung_parts.len());
            rung_parts.push((name, rung, along));
        }
    }
    let leg_names = ["leg_front_left", "leg_front_right", "leg_back_left", "leg_back_right"];
    let mut seat_pockets = Vec::new();
    for (leg, name) in leg_names.iter().enumerate() {
        let (lx, ly) = (x[leg % 2], y[leg / 2]);
        let body = b([lx, ly, 0.0], [lx + a, ly + a, height]);
        let c = (lx + 0.5 * a, ly + 0.5 * a);
        let t = b([c.0 - 0.5 * tenon.0, c.1 - 0.5 * tenon.0, height], [c.0 + 0.5 * tenon.0, c.1 + 0.5 * tenon.0, height + tenon.1]);
        seat_pockets.push(t);
        case.push(name.to_string(), pocketed(&[body, t], &pockets[leg]), json!({"kind": "leg"}));
    }
    for (name, rung, along) in rung_parts {
        case.push(name, (rung.mesh(), vec![rung]), json!({"kind": "rung", "along": if along == 0 { "x" } else { "y" }}));
    }
    let seat = b([0.0, 0.0, height], [width, depth, height + seat_t]);
    case.push("seat".into(), pocketed(&[seat], &seat_pockets), json!({"kind": "seat"}));
    case.floor([0.0, 0.0], [width, depth]);
    case
}

/// A carcass (see the module's documentation): sides `t` thick, shelves between them, two
/// dowels of radius 4 mm (16 facets) per shelf end, 15 mm in each panel.
fn carcass(rng: &mut impl Rng) -> StressCase {
    let t = 0.018;
    let width = rng.random_range(0.5..0.8f64);
    let depth = rng.random_range(0.28..0.4f64);
    let height = rng.random_range(0.5..0.75f64);
    let shelves = rng.random_range(2..=3usize);
    let holes = rng.random_bool(0.5);
    let (r, half) = (0.004, 0.015);
    let mut case = StressCase { kind: StressKind::Carcass, pieces: Vec::new(), max_penetration: if holes { 0.0 } else { r } };
    let shelf_z: Vec<f64> = (0..shelves).map(|k| 0.06 + (height - 0.06 - t) * k as f64 / (shelves - 1) as f64).collect();
    let dowel_y = [0.25 * depth, 0.75 * depth];
    let sides = [(0.0, t), (width - t, width)];
    // dowels: along x, centred on each joint plane (x = t and x = width - t)
    let mut dowels = Vec::new();
    for &z in &shelf_z {
        for (s, &plane) in [t, width - t].iter().enumerate() {
            for &y in &dowel_y {
                dowels.push((s, plane, y, z + 0.5 * t));
            }
        }
    }
    // a square pocket around each dowel (its bounding box) in the panels it enters
    let pocket = |plane: f64, y: f64, z: f64, lo: f64, hi: f64| b([plane + lo, y - r, z - r], [plane + hi, y + r, z + r]);
    for (s, &(x0, x1)) in sides.iter().enumerate() {
        let pockets: Vec<Cuboid> = if holes {
            dowels
                .iter()
                .filter(|d| d.0 == s)
                .map(|&(_, p, y, z)| if s == 0 { pocket(p, y, z, -half, 0.0) } else { pocket(p, y, z, 0.0, half) })
                .collect()
        } else {
            Vec::new()
        };
        let name = ["side_left", "side_right"][s];
        case.push(name.into(), pocketed(&[b([x0, 0.0, 0.0], [x1, depth, height])], &pockets), json!({"kind": "panel"}));
    }
    for (k, &z) in shelf_z.iter().enumerate() {
        let pockets: Vec<Cuboid> = if holes {
            dowels
                .iter()
                .filter(|d| (d.3 - (z + 0.5 * t)).abs() < 1e-9)
                .map(|&(s, p, y, zc)| if s == 0 { pocket(p, y, zc, 0.0, half) } else { pocket(p, y, zc, -half, 0.0) })
                .collect()
        } else {
            Vec::new()
        };
        case.push(format!("shelf_{k}"), pocketed(&[b([t, 0.0, z], [width - t, depth, z + t])], &pockets), json!({"kind": "panel"}));
    }
    for (k, &(_, plane, y, z)) in dowels.iter().enumerate() {
        // a prism along z around (y, z) mapped onto the x axis: (u, v, w) -> (w, u, v)
        let along_z = prism(y as f32, z as f32, r as f32, (plane - half) as f32, (plane + half) as f32, 16);
        let mesh = mapped(&along_z, |v| Vec3::new(v.z, v.x, v.y));
        let bx = bounds(&mesh);
        case.push(format!("dowel_{k}"), (mesh, vec![bx]), json!({"kind": "dowel", "holes_modelled": holes}));
    }
    case.floor([0.0, 0.0], [width, depth]);
    case
}

/// Bolted plates (see the module's documentation): plates 4-6 mm thick standing at x ∈ [-t, 0]
/// and [0, t]; bolts along x with their heads on the first plate and nuts on the second, in
/// square clearance holes of 11 mm.
fn bolted(rng: &mut impl Rng) -> StressCase {
    let t = [0.004, 0.005, 0.006][rng.random_range(0..3)];
    let bolts = rng.random_range(1..=4usize);
    // bolt centres on a row or a 2 × 2 grid, 25-45 mm apart (heads and nuts are 18 mm across
    // corners), at least 25 mm from the floor and the edges
    let cols = if bolts <= 2 { bolts } else { 2 };
    let rows = bolts.div_ceil(cols);
    let width = 0.05 + cols as f64 * rng.random_range(0.025..0.045f64);
    let height = 0.05 + rows as f64 * rng.random_range(0.025..0.04f64);
    let interference = if rng.random_bool(0.5) { 1e-4 } else { 0.0 };
    let mut case = StressCase { kind: StressKind::Bolted, pieces: Vec::new(), max_penetration: interference };
    let centres: Vec<(f64, f64)> = (0..bolts)
        .map(|k| {
            let (i, j) = (k % cols, k / cols);
            let y = 0.025 + (width - 0.05) * (i as f64 + 0.5) / cols as f64;
            let z = 0.025 + (height - 0.05) * (j as f64 + 0.5) / rows as f64;
            ((y * 1e4).round() / 1e4, (z * 1e4).round() / 1e4)
        })
        .collect();
    let hole = 0.0055;
    for (p, (x0, x1)) in [(-t, 0.0), (0.0, t)].into_iter().enumerate() {
        let pockets: Vec<Cuboid> = centres.iter().map(|&(y, z)| b([x0, y - hole, z - hole], [x1, y + hole, z + hole])).collect();
        let name = ["plate_a", "plate_b"][p];
        case.push(name.into(), pocketed(&[b([x0, 0.0, 0.0], [x1, width, height])], &pockets), json!({"kind": "plate"}));
    }
    let (bolt, nut) = threaded_bolt_and_nut((2.0 * t) as f32, interference as f32);
    for (k, &(y, z)) in centres.iter().enumerate() {
        // the fixture's +Z axis onto -X (a quarter turn about Y), its z = 0 (the nut's top) at x = t
        let place = |m: &Mesh| mapped(m, |v| Vec3::new(t as f32 - v.z, y as f32 + v.y, z as f32 + v.x));
        let (bm, nm) = (place(&bolt), place(&nut));
        // the bolt's boxes: its head (beyond the first plate) and its shank (within and beyond)
        let part_of = |keep: &dyn Fn(f32) -> bool| {
            let v: Vec<Vec3> = bm.vertices.iter().copied().filter(|v| keep(v.x)).collect();
            bounds(&Mesh::new(v, Vec::new()))
        };
        let head = part_of(&|x| x <= (-t) as f32);
        let mut shank = part_of(&|x| x > (-t + 1e-4) as f32);
        shank.mins[0] = -t;
        let nb = bounds(&nm);
        case.push(format!("bolt_{k}"), (bm, vec![head, shank]), json!({"kind": "bolt"}));
        case.push(format!("nut_{k}"), (nm, vec![nb]), json!({"kind": "nut"}));
    }
    case.floor([-t, 0.0], [t, width]);
    case
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn case(kind: StressKind, seed: u64) -> StressCase {
        StressCase::generate(kind, &mut ChaCha8Rng::seed_from_u64(seed))
    }

    #[test]
    fn every_part_is_closed_and_everything_stands_on_the_floor() {
        for kind in [StressKind::Chair, StressKind::Carcass, StressKind::Bolted] {
            for seed in 0..12 {
                let c = case(kind, seed);
                for p in &c.pieces {
                    assert!(p.mesh.topology().is_closed_manifold(), "{kind:?} {seed} {}", p.name);
                    assert!(p.mesh.signed_volume() > 0.0, "{kind:?} {seed} {}: outward", p.name);
                }
                assert!(c.check().linked, "{kind:?} {seed}");
            }
        }
    }

    #[test]
    fn bolts_and_nuts_of_one_case_never_overlap_each_other() {
        for seed in 0..40 {
            let c = case(StressKind::Bolted, seed);
            let fasteners: Vec<&Piece> = c.pieces.iter().filter(|p| p.name.starts_with("bolt") || p.name.starts_with("nut")).collect();
            for (i, a) in fasteners.iter().enumerate() {
                for b in &fasteners[i + 1..] {
                    // a bolt and its own nut share the index and screw into each other
                    if a.name.rsplit('_').next() == b.name.rsplit('_').next() {
                        continue;
                    }
                    let overlap = a.boxes.iter().any(|x| b.boxes.iter().any(|y| x.overlaps(y, 1e-9)));
                    assert!(!overlap, "seed {seed}: {} and {}", a.name, b.name);
                }
            }
        }
    }

    #[test]
    fn a_chair_with_rungs_on_four_sides_needs_more_than_single_parts() {
        let (mut four, mut two) = (0, 0);
        for seed in 0..30 {
            let c = case(StressKind::Chair, seed);
            let rungs = c.count("rung");
            if rungs >= 4 {
                // every leg is held along every axis by its two rungs
                four += 1;
                assert!(!c.check().straight_line, "seed {seed}");
            } else if c.max_penetration == 0.0 {
                two += 1;
                assert!(c.check().straight_line, "seed {seed}: a leg slides off its one rung");
            }
        }
        assert!(four > 0 && two > 0);
    }

    #[test]
    fn the_same_seed_gives_the_same_case() {
        for kind in [StressKind::Chair, StressKind::Carcass, StressKind::Bolted] {
            let (a, b) = (case(kind, 5).to_assembly("a"), case(kind, 5).to_assembly("a"));
            assert_eq!(a.parts.len(), b.parts.len());
            for (p, q) in a.parts.iter().zip(&b.parts) {
                assert_eq!((&p.name, &p.mesh.vertices, &p.mesh.triangles), (&q.name, &q.mesh.vertices, &q.mesh.triangles));
            }
        }
    }
}
