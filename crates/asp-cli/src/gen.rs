//! `asp gen`: generate training assemblies — Soma cubes (thesis 4.2) and 3D aluminium profile
//! assemblies (thesis 4.1) — in batches: one GLB per assembly plus `manifest.json`
//! (docs/generators.md).

use anyhow::bail;
use asp_gen::batch::{write_batch, Batch, Generator};
use asp_gen::{ConnectorMode, ProfileParams, SomaParams, StressKind, StressParams};
use clap::{Args, Subcommand, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

/// How many solved arrangements the classic Soma cube has up to symmetry (`--classic --all`).
const CLASSIC_SOLUTIONS: usize = 240;

/// Flags of `asp gen`.
#[derive(Args, Debug)]
pub struct GenArgs {
    /// What to generate.
    #[command(subcommand)]
    pub kind: GenKind,
}

/// The generators.
#[derive(Subcommand, Debug)]
pub enum GenKind {
    /// Soma cubes of any size: random pieces of 1-4 cells filling an S×S×S cube on a fixed floor.
    Soma(SomaArgs),
    /// 3D assemblies of 20 mm aluminium profiles with U and O connectors and grasp points.
    Profiles(ProfilesArgs),
    /// Stress cases for the planner: chairs with rungs in pockets of two legs, carcasses of
    /// panels joined by dowels, plates clamped by threaded bolts and nuts (sizes, counts and fits
    /// drawn from the seed).
    Stress(StressArgs),
}

/// Which stress case (`asp gen stress --kind`).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum StressKindArg {
    /// Four legs, a seat on tenons, rungs on two or four sides whose ends sit in the legs.
    Chair,
    /// Two side panels and two or three shelves joined by round dowels (holes modelled or not).
    Carcass,
    /// Two plates clamped by one to four threaded bolts with nuts.
    Bolted,
}

/// Flags of `asp gen stress`.
#[derive(Args, Debug)]
pub struct StressArgs {
    /// Which stress case.
    #[arg(long, value_enum)]
    pub kind: StressKindArg,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub batch: BatchArgs,
}

/// Flags every generator has.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// How many assemblies to generate (in parallel).
    #[arg(long, default_value_t = 1)]
    pub count: usize,
    /// Seed of the batch: the same seed gives byte-identical files.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Output folder, created when missing; files of the same names are overwritten.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// No progress bar and no summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Flags of `asp gen soma`.
#[derive(Args, Debug)]
pub struct SomaArgs {
    /// Cells along each edge of the cube, 2 or more (5 gives about 38 pieces).
    #[arg(long, default_value_t = 5)]
    pub size: usize,
    /// The classic 7-piece 3×3×3 Soma cube in one of its solved arrangements.
    #[arg(long, conflicts_with = "size")]
    pub classic: bool,
    /// With --classic: all 240 solved arrangements of the classic cube, distinct up to the
    /// cube's 48 symmetries (soma_classic_all_000.glb to _239.glb).
    #[arg(long, requires = "classic")]
    pub all: bool,
    /// Edge length of one cell in metres.
    #[arg(long, default_value_t = 0.05)]
    pub cell: f64,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub batch: BatchArgs,
}

/// The thesis' data sets (5.5.1).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Preset {
    /// 1 layer of 4 back and 3 front profiles: 21 removable profiles.
    SingleLayer,
    /// 2 layers of 3 back and 3 front profiles: 30 removable profiles.
    DoubleLayer,
}

/// How connectors become parts (`--connectors`).
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum Connectors {
    /// Every connector is a part of its own.
    Separate,
    /// Every connector is merged into the profile it holds: only profiles are parts (the
    /// thesis' 21- and 30-part assemblies).
    Attached,
}

/// Flags of `asp gen profiles`; each flag overrides the preset.
#[derive(Args, Debug)]
pub struct ProfilesArgs {
    /// Start from a thesis data set [default: single-layer].
    #[arg(long, value_enum)]
    pub preset: Option<Preset>,
    /// W, extent along y in metres [preset: 0.4].
    #[arg(long)]
    pub width: Option<f64>,
    /// L, extent along x (away from the pick-up position) in metres [preset: 0.4].
    #[arg(long)]
    pub length: Option<f64>,
    /// H, extent along z in metres [preset: 0.6].
    #[arg(long)]
    pub height: Option<f64>,
    /// Layers of profiles between bottom and top [preset: 1 or 2].
    #[arg(long)]
    pub layers: Option<usize>,
    /// Vertical support profiles, one per strip of the width [preset: 2].
    #[arg(long)]
    pub supports: Option<usize>,
    /// Front profiles per layer [preset: 3].
    #[arg(long)]
    pub front: Option<usize>,
    /// Back profiles per layer [preset: 4 single-layer, 3 double-layer].
    #[arg(long)]
    pub back: Option<usize>,
    /// ε_p, the shortest profile in metres [default: 0.08].
    #[arg(long)]
    pub min_length: Option<f64>,
    /// ε_g, the least distance between parallel profiles for the gripper, metres [default: 0.06].
    #[arg(long)]
    pub grasp_clearance: Option<f64>,
    /// Connectors as parts of their own, or attached to the profile they hold.
    #[arg(long, value_enum, default_value = "separate")]
    pub connectors: Connectors,
    #[command(flatten)]
    #[allow(missing_docs)]
    pub batch: BatchArgs,
}

/// Runs `asp gen`: exit 0 when every assembly passed the generator's checks, 1 when some did
/// not (they are still written and listed in the manifest); errors are the caller's exit 2.
pub fn run(args: &GenArgs) -> anyhow::Result<ExitCode> {
    let (generator, preset, batch_args) = match &args.kind {
        GenKind::Soma(a) => {
            let generator = if a.all {
                if a.batch.count != 1 {
                    bail!("--classic --all makes the 240 solutions; leave out --count");
                }
                Generator::ClassicSomaAll { cell: a.cell }
            } else if a.classic {
                if a.batch.count != 1 {
                    bail!("--classic makes the one classic cube; leave out --count");
                }
                Generator::ClassicSoma { cell: a.cell }
            } else {
                Generator::Soma(SomaParams { size: a.size, cell: a.cell })
            };
            (generator, None, &a.batch)
        }
        GenKind::Profiles(a) => {
            let preset = a.preset.unwrap_or(Preset::SingleLayer);
            let name = preset.to_possible_value().map(|v| v.get_name().to_string()).unwrap_or_default();
            let Some(mut p) = ProfileParams::preset(&name) else { bail!("no preset '{name}'") };
            let set = |field: &mut f64, v: Option<f64>| *field = v.unwrap_or(*field);
            set(&mut p.width, a.width);
            set(&mut p.length, a.length);
            set(&mut p.height, a.height);
            set(&mut p.min_length, a.min_length);
            set(&mut p.grasp_clearance, a.grasp_clearance);
            let count = |field: &mut usize, v: Option<usize>| *field = v.unwrap_or(*field);
            count(&mut p.layers, a.layers);
            count(&mut p.supports, a.supports);
            count(&mut p.front, a.front);
            count(&mut p.back, a.back);
            p.connectors = match a.connectors {
                Connectors::Separate => ConnectorMode::Separate,
                Connectors::Attached => ConnectorMode::Attached,
            };
            (Generator::Profiles(p), a.preset.and(Some(name)), &a.batch)
        }
        GenKind::Stress(a) => {
            let stress = match a.kind {
                StressKindArg::Chair => StressKind::Chair,
                StressKindArg::Carcass => StressKind::Carcass,
                StressKindArg::Bolted => StressKind::Bolted,
            };
            (Generator::Stress(StressParams { stress }), None, &a.batch)
        }
    };
    let count = if matches!(generator, Generator::ClassicSomaAll { .. }) { CLASSIC_SOLUTIONS } else { batch_args.count };
    let batch = Batch { generator, preset, count, seed: batch_args.seed };
    let bar = if batch_args.quiet || !std::io::stderr().is_terminal() {
        ProgressBar::hidden()
    } else {
        let style =
            ProgressStyle::with_template("{bar:30} {pos}/{len} assemblies {elapsed}").unwrap_or_else(|_| ProgressStyle::default_bar());
        ProgressBar::new(batch.count as u64).with_style(style)
    };
    let manifest = write_batch(&batch, &batch_args.out, &|| bar.inc(1))?;
    bar.finish_and_clear();
    let failed: Vec<&str> = manifest.assemblies.iter().filter(|e| !e.checks.passed()).map(|e| e.file.as_str()).collect();
    if !batch_args.quiet {
        let noun = if manifest.count == 1 { "assembly" } else { "assemblies" };
        eprintln!("wrote {} {noun} and manifest.json to {}", manifest.count, batch_args.out.display());
        if !failed.is_empty() {
            eprintln!("warning: {} failed the generator's checks (see manifest.json): {}", failed.len(), failed.join(", "));
        }
    }
    Ok(if failed.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(subcommand)]
        kind: GenKind,
    }

    fn parse(args: &[&str]) -> Result<GenArgs, clap::Error> {
        Cli::try_parse_from(std::iter::once("gen").chain(args.iter().copied())).map(|c| GenArgs { kind: c.kind })
    }

    #[test]
    fn parses_the_issue_examples() {
        let a = parse(&["soma", "--size", "5", "--count", "8", "--seed", "0", "--out", "data/soma5/"]).unwrap();
        assert!(matches!(a.kind, GenKind::Soma(SomaArgs { size: 5, classic: false, .. })));
        assert!(parse(&["soma", "--classic", "--out", "data/"]).is_ok());
        assert!(parse(&["soma", "--classic", "--size", "4", "--out", "x"]).is_err(), "conflicting flags");
        assert!(matches!(parse(&["soma", "--classic", "--all", "--out", "x"]).unwrap().kind, GenKind::Soma(SomaArgs { all: true, .. })));
        assert!(parse(&["soma", "--all", "--out", "x"]).is_err(), "--all needs --classic");
        let a = parse(&["profiles", "--preset", "double-layer", "--count", "7", "--out", "d"]).unwrap();
        assert!(matches!(a.kind, GenKind::Profiles(ProfilesArgs { preset: Some(Preset::DoubleLayer), .. })));
        let custom = [
            "profiles",
            "--width",
            "0.4",
            "--length",
            "0.4",
            "--height",
            "0.6",
            "--layers",
            "3",
            "--supports",
            "3",
            "--front",
            "3",
            "--back",
            "4",
            "--out",
            "d",
        ];
        assert!(parse(&custom).is_ok());
        assert!(parse(&["soma"]).is_err(), "--out is required");
    }

    #[test]
    fn writes_a_batch_twice_byte_identically() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("soma3");
        let out_s = out.to_str().unwrap();
        let args = parse(&["soma", "--size", "3", "--count", "3", "--seed", "5", "--out", out_s, "--quiet"]).unwrap();
        assert_eq!(run(&args).unwrap(), ExitCode::SUCCESS);
        let read = |f: &str| std::fs::read(out.join(f)).unwrap();
        let first: Vec<Vec<u8>> = ["soma3_000.glb", "soma3_001.glb", "soma3_002.glb", "manifest.json"].map(read).into();
        assert_eq!(run(&args).unwrap(), ExitCode::SUCCESS);
        let second: Vec<Vec<u8>> = ["soma3_000.glb", "soma3_001.glb", "soma3_002.glb", "manifest.json"].map(read).into();
        assert!(first == second, "same seed, same bytes");
        assert_ne!(first[0], first[1]);
    }

    #[test]
    fn bad_arguments_are_errors_not_panics() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().to_str().unwrap();
        for args in [
            vec!["soma", "--size", "1", "--out", out, "-q"],
            vec!["soma", "--classic", "--count", "2", "--out", out, "-q"],
            vec!["soma", "--classic", "--all", "--count", "2", "--out", out, "-q"],
            vec!["soma", "--count", "0", "--out", out, "-q"],
            vec!["profiles", "--height", "0.05", "--out", out, "-q"],
            vec!["profiles", "--width", "nan", "--out", out, "-q"],
        ] {
            let err = run(&parse(&args).unwrap()).unwrap_err();
            assert!(!err.to_string().is_empty());
        }
    }
}
