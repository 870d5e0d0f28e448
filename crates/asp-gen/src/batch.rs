//! Batches: which generator, the seed of each assembly, generating in parallel and writing one
//! GLB per assembly plus `manifest.json`.

use crate::error::{GenError, Result};
pub use crate::generator::{Generated, Generator};
use crate::manifest::{Manifest, ManifestEntry, FORMAT_VERSION};
use rayon::prelude::*;
use std::path::Path;

/// The seed of assembly `index` of a batch: SplitMix64 of the pair, so neighbouring batch
/// seeds and indices give unrelated streams and any assembly can be made on its own.
pub fn assembly_seed(batch_seed: u64, index: usize) -> u64 {
    asp_geom::seed::finalise(batch_seed ^ (index as u64 + 1).wrapping_mul(0x9E37_79B9_7F4A_7C15))
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
    let generated = generator.generate_item(index, seed, &file)?;
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
    let json = serde_json::to_string_pretty(&manifest).map_err(|e| GenError::Io { path: path.clone(), source: e.into() })?;
    let tmp = out.join(".manifest.json.tmp");
    std::fs::write(&tmp, format!("{json}\n"))
        .and_then(|()| std::fs::rename(&tmp, &path))
        .map_err(|source| GenError::Io { path: path.clone(), source })?;
    Ok(manifest)
}
