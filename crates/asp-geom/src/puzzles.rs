//! Interlocking voxel puzzles with known answers, for the grid search's tests
//! and benchmarks: six-piece burrs and a small puzzle that no straight-line or group removal
//! takes apart. All in 1 cm cells, +Z up, no fixed part; every piece carries its cells
//! (`extras.asp.voxels`). The piece shapes were found by a seeded search over notched sticks
//! (`asp-geom/tests/grid`, `find_puzzles`, ignored) and are stored as literal cells.

use crate::assembly::Assembly;
use crate::fixtures::{assemble, voxel_part};
use crate::grid::Cell;
use crate::math::Axis;

/// The cell size of the puzzles, metres.
pub const CELL: f32 = 0.01;

/// The six unnotched 2 × 2 × 6 sticks of a six-piece burr, around the 4 × 4 × 4 core
/// `[0, 4)³`: two along x (z low, z high), two along y (x low, x high), two along z (y low,
/// y high). Each orthogonal pair meets in 4 cells; a burr keeps each such cell in at most one
/// stick.
pub fn burr_sticks() -> [Vec<Cell>; 6] {
    let block = |x: (i32, i32), y: (i32, i32), z: (i32, i32)| {
        let mut v = Vec::new();
        for i in x.0..x.1 {
            for j in y.0..y.1 {
                for k in z.0..z.1 {
                    v.push([i, j, k]);
                }
            }
        }
        v
    };
    [
        block((-1, 5), (1, 3), (0, 2)),
        block((-1, 5), (1, 3), (2, 4)),
        block((0, 2), (-1, 5), (1, 3)),
        block((2, 4), (-1, 5), (1, 3)),
        block((1, 3), (0, 2), (-1, 5)),
        block((1, 3), (2, 4), (-1, 5)),
    ]
}

/// A closed box (5 × 3 × 6 cells) whose five loose unit cubes slide around a 3 × 4 cavity
/// without ever getting out: the frame first, then the cubes. A grid search visits all 95,040
/// states before it is stuck.
pub fn closed_box_cells() -> Vec<Vec<Cell>> {
    let mut frame = Vec::new();
    for x in 0..5 {
        for y in 0..3 {
            for z in 0..6 {
                if !(y == 1 && (1..4).contains(&x) && (1..5).contains(&z)) {
                    frame.push([x, y, z]);
                }
            }
        }
    }
    let mut pieces = vec![frame];
    pieces.extend([[1, 1, 1], [2, 1, 1], [3, 1, 1], [1, 1, 2], [2, 1, 2]].map(|c| vec![c]));
    pieces
}

/// An assembly of voxel pieces named `piece0`, `piece1`, ... in [`CELL`] cells.
pub fn voxel_puzzle(name: &str, pieces: &[Vec<Cell>]) -> Assembly {
    assemble(name, pieces.iter().enumerate().map(|(i, c)| voxel_part(&format!("piece{i}"), c, CELL)).collect(), Axis::Z)
}

/// The sticks of [`burr_sticks`] with the listed cells taken out of each.
fn notched(notches: [&[Cell]; 6]) -> Vec<Vec<Cell>> {
    burr_sticks().into_iter().zip(notches).map(|(s, n)| s.into_iter().filter(|c| !n.contains(c)).collect()).collect()
}

/// A six-piece burr with a key: one piece slides out at once (level 1), then the rest comes
/// apart.
pub fn burr_key() -> Assembly {
    voxel_puzzle("burr_key", &notched(BURR_KEY))
}

/// A six-piece burr whose first separation needs [`BURR_LEVEL_MOVES`] moves of pieces before
/// any piece or group can leave: no straight line, group or single path frees anything.
pub fn burr_level() -> Assembly {
    voxel_puzzle("burr_level", &notched(BURR_LEVEL))
}

/// Moves before [`burr_level`]'s first separation (its level is this plus one).
pub const BURR_LEVEL_MOVES: usize = 3;

/// A small voxel puzzle of three pieces: a frame (7 × 3 × 7: two full plates and a middle
/// layer with a cavity opening through its right side), a hook whose arm comes out through the
/// opening while its hook catches behind the lip below it, and a latch above the arm whose tail
/// keeps it inside. The hook must lift before it slides out, and it cannot lift until the latch
/// has slid three cells left; the latch leaves only after the hook (down one, then out). No
/// straight line, group or single-part path frees anything: the first separation needs
/// [`SMALL_PUZZLE_MOVES`] moves of two different pieces. Pieces: 0 frame, 1 hook, 2 latch.
pub fn small_puzzle() -> Assembly {
    // the middle layer (y = 1) in (x, z): the cavity and the opening at x = 6
    let cavity: [[i32; 2]; 15] =
        [[3, 2], [3, 3], [4, 3], [5, 3], [6, 3], [1, 4], [2, 4], [3, 4], [4, 4], [5, 4], [6, 4], [1, 5], [2, 5], [3, 5], [4, 5]];
    let hook: Vec<Cell> = [[3, 2], [3, 3], [4, 3], [5, 3], [6, 3]].iter().map(|c| [c[0], 1, c[1]]).collect();
    let latch: Vec<Cell> = [[4, 4], [5, 4], [4, 5]].iter().map(|c| [c[0], 1, c[1]]).collect();
    let mut frame = Vec::new();
    for x in 0..7 {
        for y in 0..3 {
            for z in 0..7 {
                if !(y == 1 && cavity.contains(&[x, z])) {
                    frame.push([x, y, z]);
                }
            }
        }
    }
    voxel_puzzle("small_puzzle", &[frame, hook, latch])
}

/// Moves before [`small_puzzle`]'s first separation.
pub const SMALL_PUZZLE_MOVES: usize = 2;

/// The notches of [`burr_key`]'s sticks; the second stick (x, high) is the unnotched key.
const BURR_KEY: [&[Cell]; 6] = [
    &[[0, 1, 1], [0, 2, 1], [1, 1, 0], [1, 1, 1], [2, 1, 0], [2, 1, 1], [3, 1, 1], [3, 2, 1]],
    &[],
    &[[0, 1, 2], [0, 2, 2], [1, 0, 1], [1, 0, 2], [1, 1, 2], [1, 2, 1], [1, 2, 2], [1, 3, 1], [1, 3, 2]],
    &[[2, 0, 1], [2, 0, 2], [2, 1, 1], [2, 1, 2], [2, 2, 1], [2, 2, 2], [2, 3, 1], [2, 3, 2], [3, 1, 2], [3, 2, 2]],
    &[[1, 0, 1], [1, 0, 2], [1, 1, 0], [1, 1, 1], [1, 1, 2], [1, 1, 3], [2, 1, 1], [2, 1, 2], [2, 1, 3]],
    &[[1, 2, 0], [1, 2, 1], [1, 2, 2], [1, 2, 3], [2, 2, 0], [2, 2, 1], [2, 2, 2], [2, 2, 3]],
];
/// The notches of [`burr_level`]'s sticks.
const BURR_LEVEL: [&[Cell]; 6] = [
    &[[0, 1, 1], [0, 2, 1], [1, 1, 0], [1, 1, 1], [2, 1, 0], [2, 1, 1], [3, 1, 1], [3, 2, 1]],
    &[[0, 1, 2], [0, 2, 2], [1, 1, 2], [1, 2, 2], [2, 1, 2], [2, 2, 2], [3, 1, 2], [3, 2, 2]],
    &[[0, 1, 2], [0, 2, 2], [1, 0, 1], [1, 0, 2], [1, 1, 2], [1, 2, 1], [1, 2, 2], [1, 3, 1], [1, 3, 2]],
    &[[2, 0, 1], [2, 0, 2], [2, 1, 1], [2, 1, 2], [2, 2, 1], [2, 2, 2], [2, 3, 1], [2, 3, 2], [3, 2, 2]],
    &[[1, 0, 1], [1, 0, 2], [1, 1, 0], [1, 1, 1], [1, 1, 2], [1, 1, 3], [2, 1, 1], [2, 1, 2], [2, 1, 3]],
    &[[1, 2, 0], [1, 2, 1], [1, 2, 2], [1, 2, 3], [2, 2, 0], [2, 2, 1], [2, 2, 3]],
];

/// Two [`small_puzzle`]s side by side along y, touching: they come apart as two subassemblies
/// first (no moves), and each then needs its own moves on its frame. Pieces 0-2 the first
/// puzzle, 3-5 the second (shifted by 3 cells along +y).
pub fn two_small_puzzles() -> Assembly {
    let one = small_puzzle();
    let mut pieces: Vec<Vec<Cell>> = Vec::new();
    for shift in [0, 3] {
        for p in &one.parts {
            let cells = p.meta.cells.clone().expect("voxel pieces");
            pieces.push(cells.iter().map(|c| [c[0], c[1] + shift, c[2]]).collect());
        }
    }
    voxel_puzzle("two_small_puzzles", &pieces)
}
