//! `asp view` and `asp render`: the viewer page and the storyboard of a plan JSON.

use asp_viz::render::RenderOptions;
use asp_viz::Scene;
use clap::Args;
use std::path::PathBuf;
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
pub struct RenderArgs {
    /// The plan JSON (`asp plan --out`).
    pub plan: PathBuf,
    /// The storyboard to write: `.png`, or `.svg` (shaded panels embedded, titles and arrows
    /// as vectors).
    #[arg(long, value_name = "FILE")]
    pub out: PathBuf,
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

/// Runs `asp view`.
pub fn view(args: &ViewArgs) -> anyhow::Result<ExitCode> {
    let scene = Scene::from_plan_file(&args.plan, args.model.as_deref())?;
    asp_viz::view::write_html(&args.out, &scene)?;
    Ok(ExitCode::SUCCESS)
}

/// Runs `asp render`.
pub fn render(args: &RenderArgs) -> anyhow::Result<ExitCode> {
    if !(32..=4096).contains(&args.panel) {
        anyhow::bail!("--panel must be between 32 and 4096 pixels, got {}", args.panel);
    }
    if args.columns == Some(0) {
        anyhow::bail!("--columns must be at least 1");
    }
    let ext = args.out.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase());
    if !matches!(ext.as_deref(), Some("png") | Some("svg")) {
        anyhow::bail!("{}: unknown picture type (use .png or .svg)", args.out.display());
    }
    let scene = Scene::from_plan_file(&args.plan, args.model.as_deref())?;
    asp_viz::render::write(&args.out, &scene, &RenderOptions { panel: args.panel, columns: args.columns })?;
    Ok(ExitCode::SUCCESS)
}
