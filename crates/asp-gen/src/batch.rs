//! Batches: which generator, the seed of each assembly, generating in parallel and writing one
//! GLB per assembly plus `manifest.json`.

use crate::check::DisassemblyCheck;
use crate::error::{GenError, Result};
use crate::manifest::{Checks, Manifest, ManifestEntry, PartCounts, FORMAT_VERSION};
use crate::profiles::{ConnectorShape, ProfileAssembly, ProfileParams};
use crate::soma::{validate_cell, SomaCube, SomaParams};
use asp_geom::Assembly;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

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
    /// Aluminium profile assemblies.
    Profiles(ProfileParams),
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
            Generator::ClassicSoma { cell } => validate_cell(*cell),
            Generator::Profiles(p) => p.validate(),
        }
    }

    /// The start of every file name: `soma5`, `soma_classic`, `profiles`.
    pub fn file_stem(&self) -> String {
        match self {
            Generator::Soma(p) => format!("soma{}", p.size),
            Generator::ClassicSoma { .. } => "soma_classic".into(),
            Generator::Profiles(_) => "profiles".into(),
        }
    }

    /// Generates the assembly of `seed`; `source` names it (e.g. its file name).
    pub fn generate(&self, seed: u64, source: &str) -> Result<Generated> {
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
        }
    }
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
    }
}

/// The seed of assembly `index` of a batch: SplitMix64 of the pair, so neighbouring batch
/// seeds and indices give unrelated streams and any assembly can be made on its own.
pub fn assembly_seed(batch_seed: u64, index: usize) -> u64 {
    let mut z = batch_seed ^ (index as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The file name of assembly `index` in a batch of `count`: `soma5_000.glb`, or just
/// `soma_classic.glb` for the classic cube.
pub fn file_name(generator: &Generator, index: usize, count: usize) -> String {
    let stem = generator.file_stem();
    if matches!(generator, Generator::ClassicSoma { .. }) && count == 1 {
        return format!("{stem}.glb");
    }
    let width = count.saturating_sub(1).to_string().len().max(3);
    format!("{stem}_{index:0width$}.glb")
}

/// Generates assembly `index` of a batch of `count` with batch seed `seed`: the assembly, and
/// its manifest entry (its file name and seed are [`file_name`] and [`assembly_seed`]). Depends
/// on nothing else, so batches can be split over threads, processes or machines (`asp.batch`)
/// and still give the same files.
pub fn generate_item(generator: &Generator, index: usize, count: usize, seed: u64) -> Result<(Generated, ManifestEntry)> {
    let file = file_name(generator, index, count);
    let seed = assembly_seed(seed, index);
    let generated = generator.generate(seed, &file)?;
    let parts = &generated.assembly.parts;
    let entry = ManifestEntry {
        file,
        index,
        seed,
        parts: parts.len(),
        fixed_parts: parts.iter().filter(|p| p.fixed).count(),
        counts: generated.counts.clone(),
        checks: generated.checks.clone(),
    };
    Ok((generated, entry))
}

/// Generates assemblies `0..count` of a batch in parallel (rayon), calling `done` after each
/// and `sink` with each assembly and its entry (e.g. to write it); returns the entries in index
/// order. Stops at the first error.
pub fn generate_batch(
    generator: &Generator,
    count: usize,
    seed: u64,
    sink: &(dyn Fn(&Generated, &ManifestEntry) -> Result<()> + Sync),
    done: &(dyn Fn() + Sync),
) -> Result<Vec<ManifestEntry>> {
    generator.validate()?;
    if count == 0 {
        return Err(GenError::parameter("count", "must be at least 1"));
    }
    (0..count)
        .into_par_iter()
        .map(|index| {
            let (generated, entry) = generate_item(generator, index, count, seed)?;
            sink(&generated, &entry)?;
            done();
            Ok(entry)
        })
        .collect()
}

/// A batch to generate: the generator, where its parameters came from, how many, which seed.
#[derive(Clone, Debug, PartialEq)]
pub struct Batch {
    /// What to generate.
    pub generator: Generator,
    /// The preset the parameters started from, recorded in the manifest.
    pub preset: Option<String>,
    /// Number of assemblies (≥ 1).
    pub count: usize,
    /// The batch seed.
    pub seed: u64,
}

/// Generates `batch` into folder `out` (created when missing): one GLB per assembly, loadable
/// with no extra options (fixed parts and the +Z up axis are in the file), and
/// `manifest.json`. Calls `done` after each assembly. Files of the same names are overwritten.
pub fn write_batch(batch: &Batch, out: &Path, done: &(dyn Fn() + Sync)) -> Result<Manifest> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| GenError::Io { path, source }
    };
    batch.generator.validate()?;
    std::fs::create_dir_all(out).map_err(io(out))?;
    let write = |g: &Generated, e: &ManifestEntry| Ok(asp_geom::io::write_glb(&g.assembly, &out.join(&e.file))?);
    let assemblies = generate_batch(&batch.generator, batch.count, batch.seed, &write, done)?;
    write_manifest(batch, assemblies, out)
}

/// The manifest of `batch` from the entries of all its assemblies (in any order), written to
/// `out/manifest.json` (through a temporary file, so a reader never sees half of it).
pub fn write_manifest(batch: &Batch, mut assemblies: Vec<ManifestEntry>, out: &Path) -> Result<Manifest> {
    assemblies.sort_by_key(|e| e.index);
    let expected = (0..batch.count).collect::<Vec<_>>();
    if assemblies.iter().map(|e| e.index).collect::<Vec<_>>() != expected {
        return Err(GenError::parameter("count", format!("the manifest needs one entry for each of the {} assemblies", batch.count)));
    }
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        generator: batch.generator.clone(),
        preset: batch.preset.clone(),
        seed: batch.seed,
        count: batch.count,
        failed_checks: assemblies.iter().filter(|e| !e.checks.passed()).count(),
        assemblies,
    };
    let path = out.join("manifest.json");
    let json =
        serde_json::to_string_pretty(&manifest).map_err(|e| GenError::Io { path: path.clone(), source: e.into() })?;
    let tmp = out.join(".manifest.json.tmp");
    std::fs::write(&tmp, format!("{json}\n"))
        .and_then(|()| std::fs::rename(&tmp, &path))
        .map_err(|source| GenError::Io { path: path.clone(), source })?;
    Ok(manifest)
}
