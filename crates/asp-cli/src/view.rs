//! `asp view` and `asp render`: the viewer page and the storyboard of a plan JSON.

use asp_viz::instructions::InstructionOptions;
use asp_viz::render::RenderOptions;
use asp_viz::Scene;
use clap::{Args, Subcommand};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// Flags of `asp view`.
#[derive(Args, Debug)]
pub struct ViewArgs {
    /// The plan JSON (`asp plan --out`).
    pub plan: PathBuf,
    /// The HTML file to write: one self-contained page that works offline.
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
    /// The model [default: the plan's `model` field].
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
}

/// Flags of `asp render`.
#[derive(Args, Debug)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct RenderArgs {
    /// What else to render than the storyboard.
    #[command(subcommand)]
    pub what: Option<RenderWhat>,
    /// The plan JSON (`asp plan --out`).
    #[arg(required = true)]
    pub plan: Option<PathBuf>,
    /// The storyboard to write: `.png`, or `.svg` (shaded panels embedded, titles and arrows
    /// as vectors).
    #[arg(long, value_name = "FILE", required = true)]
    pub out: Option<PathBuf>,
    /// The model [default: the plan's `model` field].
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Width and height of one panel in pixels.
    #[arg(long, default_value_t = 320)]
    pub panel: u32,
    /// Panels per row [default: about the square root of the number of steps, at most 6].
    #[arg(long)]
    pub columns: Option<u32>,
}

/// What `asp render` renders besides the storyboard.
#[derive(Subcommand, Debug)]
pub enum RenderWhat {
    /// Work instructions for an assembly line: the steps grouped into stations of about equal
    /// work on the plan's precedence graph (`asp plan --precedence`), one HTML page and one PNG
    /// per station (parts to take, steps and motions, fasteners, pictures) and an index.html.
    Instructions(InstructionArgs),
}

/// Flags of `asp render instructions`.
#[derive(Args, Debug)]
pub struct InstructionArgs {
    /// The plan JSON (`asp plan --out`; with `--precedence`, steps may move between stations).
    pub plan: PathBuf,
    /// The folder to write into (made if missing): index.html, station-NN.html, station-NN.png.
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// How many stations the line has.
    #[arg(long, value_name = "N")]
    pub stations: usize,
    /// Seconds per part: a CSV file of `name,seconds` lines (`#` starts a comment); parts not
    /// named take --default-time. Without it, stations get equal numbers of parts.
    #[arg(long, value_name = "FILE")]
    pub times: Option<PathBuf>,
    /// Seconds of a part the times file does not name.
    #[arg(long, value_name = "SECONDS", default_value_t = 1.0)]
    pub default_time: f64,
    /// The model [default: the plan's `model` field].
    #[arg(long, value_name = "FILE")]
    pub model: Option<PathBuf>,
    /// Width and height of one picture in pixels.
    #[arg(long, default_value_t = 320)]
    pub panel: u32,
}

/// Reads a times file: `name,seconds` per line, `#` comments, blank lines skipped.
fn read_times(path: &Path) -> anyhow::Result<BTreeMap<String, f64>> {
    let text = std::fs::read_to_string(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let mut out = BTreeMap::new();
    for (k, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let bad = |why: &str| anyhow::anyhow!("{}:{}: {why} (expected `name,seconds`)", path.display(), k + 1);
        let (name, seconds) = line.rsplit_once(',').ok_or_else(|| bad("no comma"))?;
        let seconds: f64 = seconds.trim().parse().map_err(|_| bad("the time is not a number"))?;
        if !(seconds.is_finite() && seconds > 0.0) {
            return Err(bad("the time must be a positive number of seconds"));
        }
        out.insert(name.trim().to_string(), seconds);
    }
    Ok(out)
}

/// Runs `asp render instructions`.
fn instructions(args: &InstructionArgs) -> anyhow::Result<ExitCode> {
    if !(32..=4096).contains(&args.panel) {
        anyhow::bail!("--panel must be between 32 and 4096 pixels, got {}", args.panel);
    }
    if args.stations == 0 {
        anyhow::bail!("--stations must be at least 1");
    }
    if !(args.default_time.is_finite() && args.default_time > 0.0) {
        anyhow::bail!("--default-time must be a positive number of seconds, got {}", args.default_time);
    }
    let times = args.times.as_deref().map(read_times).transpose()?.unwrap_or_default();
    let scene = Scene::from_plan_file(&args.plan, args.model.as_deref())?;
    let options = InstructionOptions { stations: args.stations, times, default_time: args.default_time, panel: args.panel };
    let made = asp_viz::instructions::write(&args.out, &scene, &options)?;
    let fewer = if made.stations.len() < args.stations {
        format!(" ({} asked: more would not shorten the cycle, which no step can be split below)", args.stations)
    } else {
        String::new()
    };
    eprintln!(
        "{} stations{fewer}, cycle {:.1} s ({}); wrote {}",
        made.stations.len(),
        made.cycle,
        if made.from_precedence { "on the precedence graph" } else { "in the plan's order: plan with --precedence to balance better" },
        args.out.join("index.html").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Runs `asp view`.
pub fn view(args: &ViewArgs) -> anyhow::Result<ExitCode> {
    let scene = Scene::from_plan_file(&args.plan, args.model.as_deref())?;
    asp_viz::view::write_html(&args.out, &scene)?;
    Ok(ExitCode::SUCCESS)
}

/// Runs `asp render`.
pub fn render(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    if let Some(RenderWhat::Instructions(i)) = &args.what {
        return instructions(i);
    }
    let (Some(plan), Some(out)) = (&args.plan, &args.out) else { anyhow::bail!("asp render needs a plan and --out") };
    if !(32..=4096).contains(&args.panel) {
        anyhow::bail!("--panel must be between 32 and 4096 pixels, got {}", args.panel);
    }
    if args.columns == Some(0) {
        anyhow::bail!("--columns must be at least 1");
    }
    let ext = out.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png") | Some("svg")) {
        anyhow::bail!("{}: unknown picture type (use .png or .svg)", out.display());
    }
    let scene = Scene::from_plan_file(plan, args.model.as_deref())?;
    asp_viz::render::write(out, &scene, &RenderOptions { panel: args.panel, columns: args.columns })?;
    Ok(ExitCode::SUCCESS)
}
