//! The generators: which kind of assembly, with its parameters, and what one generated
//! assembly holds (its part counts and the generator's own checks, as the manifest records them).

use crate::check::DisassemblyCheck;
use crate::error::Result;
use crate::profiles::{ConnectorShape, ProfileAssembly, ProfileParams};
use crate::soma::{validate_cell, SomaCube, SomaParams};
use crate::stress::{StressCase, StressParams};
use asp_geom::Assembly;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

/// What to generate, with all parameters.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Generator {
    /// Random Soma cubes (Algorithm 1).
    Soma(SomaParams),
    /// The classic 7-piece 3×3×3 Soma cube (the same cube for every seed).
    ClassicSoma {
        /// Edge length of one cell in metres.
        cell: f64,
    },
    /// Every solution of the classic Soma cube up to symmetry
    /// ([`SomaCube::classic_solutions`]: assembly `index` of a batch is solution `index`, of 240).
    ClassicSomaAll {
        /// Edge length of one cell in metres.
        cell: f64,
    },
    /// Aluminium profile assemblies.
    Profiles(ProfileParams),
    /// Stress cases for the planner: chairs, dowelled carcasses, bolted plates
    /// ([`crate::stress`]).
    Stress(StressParams),
}

/// One generated assembly with what its checks found.
#[derive(Clone, Debug)]
pub struct Generated {
    /// The assembly, ready to write.
    pub assembly: Assembly,
    /// Part counts by kind.
    pub counts: PartCounts,
    /// The generator's own checks.
    pub checks: Checks,
}

impl Generator {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        match self {
            Generator::Soma(p) => p.validate(),
            Generator::ClassicSoma { cell } | Generator::ClassicSomaAll { cell } => validate_cell(*cell),
            Generator::Profiles(p) => p.validate(),
            Generator::Stress(_) => Ok(()),
        }
    }

    /// The start of every file name: `soma5`, `soma_classic`, `profiles`.
    pub fn file_stem(&self) -> String {
        match self {
            Generator::Soma(p) => format!("soma{}", p.size),
            Generator::ClassicSoma { .. } => "soma_classic".into(),
            Generator::ClassicSomaAll { .. } => "soma_classic_all".into(),
            Generator::Profiles(_) => "profiles".into(),
            Generator::Stress(p) => p.stress.name().into(),
        }
    }

    /// Generates the assembly of `seed`; `source` names it (e.g. its file name). The classic
    /// cube's solutions are chosen by their index, not a seed: see [`Generator::generate_item`].
    pub fn generate(&self, seed: u64, source: &str) -> Result<Generated> {
        self.generate_item(0, seed, source)
    }

    /// Generates assembly `index` of a batch, of `seed`; `source` names it (e.g. its file name).
    /// Only [`Generator::ClassicSomaAll`] reads the index (solution `index`; an index beyond
    /// the 240 solutions is an error).
    pub fn generate_item(&self, index: usize, seed: u64, source: &str) -> Result<Generated> {
        match self {
            Generator::Soma(p) => {
                p.validate()?;
                let cube = SomaCube::random(p.size, &mut ChaCha8Rng::seed_from_u64(seed))?;
                Ok(soma_generated(&cube, p.cell, source))
            }
            Generator::ClassicSoma { cell } => {
                validate_cell(*cell)?;
                Ok(soma_generated(&SomaCube::classic(), *cell, source))
            }
            Generator::ClassicSomaAll { cell } => {
                validate_cell(*cell)?;
                let all = classic_solutions();
                let cube = all.get(index).ok_or_else(|| {
                    crate::error::GenError::parameter(
                        "count",
                        format!("the classic cube has {} solutions, asked for number {}", all.len(), index + 1),
                    )
                })?;
                Ok(soma_generated(cube, *cell, source))
            }
            Generator::Profiles(p) => {
                let profiles = ProfileAssembly::generate(p, seed)?;
                let assembly = profiles.to_assembly(source);
                let shapes = |s| profiles.connectors.iter().filter(|c| c.shape == s).count();
                let counts = PartCounts::Profiles {
                    profiles: profiles.profiles.len(),
                    removable_profiles: profiles.profiles.iter().filter(|p| !p.fixed).count(),
                    u_connectors: shapes(ConnectorShape::U),
                    o_connectors: shapes(ConnectorShape::O),
                    grasp_points: (0..profiles.profiles.len()).map(|i| profiles.grasp_points(i).len()).sum(),
                };
                let checks = checks(&assembly, &profiles.check_disassembly(), profiles.max_penetration().max(0.0));
                Ok(Generated { assembly, counts, checks })
            }
            Generator::Stress(p) => {
                let case = StressCase::generate(p.stress, &mut ChaCha8Rng::seed_from_u64(seed));
                let assembly = case.to_assembly(source);
                let counts = PartCounts::Stress {
                    legs: case.count("leg"),
                    rungs: case.count("rung"),
                    panels: case.count("side") + case.count("shelf") + case.count("plate"),
                    dowels: case.count("dowel"),
                    bolts: case.count("bolt"),
                };
                let checks = Checks { straight_line_required: false, ..checks(&assembly, &case.check(), case.max_penetration) };
                Ok(Generated { assembly, counts, checks })
            }
        }
    }
}

/// The classic cube's solutions, enumerated once per process.
fn classic_solutions() -> &'static [SomaCube] {
    static ALL: std::sync::OnceLock<Vec<SomaCube>> = std::sync::OnceLock::new();
    ALL.get_or_init(SomaCube::classic_solutions)
}

fn soma_generated(cube: &SomaCube, cell: f64, source: &str) -> Generated {
    let assembly = cube.to_assembly(cell, source);
    let counts = PartCounts::Soma { pieces: cube.pieces().len(), piece_sizes: cube.piece_sizes() };
    let checks = checks(&assembly, &cube.check_disassembly(), 0.0);
    Generated { assembly, counts, checks }
}

fn checks(assembly: &Assembly, check: &DisassemblyCheck, max_penetration: f64) -> Checks {
    Checks {
        contact_linked: check.linked,
        straight_line_disassemblable: check.straight_line,
        stuck_parts: check.stuck.iter().map(|&i| assembly.parts[i].name.clone()).collect(),
        stable_order_found: check.stable_order,
        max_penetration,
        straight_line_required: true,
    }
}

/// Part counts by kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum PartCounts {
    /// A Soma cube.
    Soma {
        /// Pieces (parts other than the floor).
        pieces: usize,
        /// How many pieces have 1, 2, 3 and 4 cells.
        piece_sizes: [usize; 4],
    },
    /// An aluminium profile assembly.
    Profiles {
        /// All profiles.
        profiles: usize,
        /// Profiles that are not fixed.
        removable_profiles: usize,
        /// U-shaped connectors (under horizontal profiles).
        u_connectors: usize,
        /// O-shaped connectors (around vertical profiles).
        o_connectors: usize,
        /// Grasp points over all profiles.
        grasp_points: usize,
    },
    /// A stress case.
    Stress {
        /// Chair legs.
        legs: usize,
        /// Chair rungs.
        rungs: usize,
        /// Panels, shelves and plates.
        panels: usize,
        /// Dowels.
        dowels: usize,
        /// Bolts (each with its nut).
        bolts: usize,
    },
}

/// What the generator verified on its own geometry (voxels or boxes), before any planner.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Checks {
    /// The assembled state is contact-linked to the fixed parts.
    pub contact_linked: bool,
    /// Every non-fixed part comes out along a ±axis straight line, one after the other (exact).
    pub straight_line_disassemblable: bool,
    /// Parts that no ±axis motion frees once everything else that can leave has left.
    pub stuck_parts: Vec<String>,
    /// A top-down removal order was found in which every state stays contact-linked.
    pub stable_order_found: bool,
    /// Deepest interpenetration of two parts in metres (boxes of profile assemblies; 0 for
    /// Soma cubes, whose cells cannot overlap).
    pub max_penetration: f64,
    /// Whether the generator promises that single parts along ±axes take the assembly apart
    /// (Soma cubes, profiles); stress cases need groups, screw motions or fits on purpose, so
    /// only their contact linkage must pass. Absent in older manifests: true.
    #[serde(default = "yes")]
    pub straight_line_required: bool,
}

fn yes() -> bool {
    true
}

impl Checks {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.contact_linked && (!self.straight_line_required || (self.straight_line_disassemblable && self.stable_order_found))
    }
}
