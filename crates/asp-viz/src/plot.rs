//! `asp plot`: the Pareto front of a plan JSON (a scatter with the front's staircase; three or
//! more objectives as pairwise panels) and the search's progress from `--trace` CSVs (the
//! hypervolume, or the best total, over seconds or episodes; several traces on one plot), or an
//! `asp bench mcts --csv` (one line per setting: its value over wall time as a fraction of the
//! best any setting reached on each model, averaged over the models).
//! SVG or PNG by the output's extension; PNG text uses the vendored DejaVu Sans.

use crate::error::{Result, VizError};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Draws `$f(&root, args..)` on an SVG or PNG (by `$out`'s extension) of `$size` and writes it.
macro_rules! render_to {
    ($out:expr, $size:expr, $f:ident ( $($arg:expr),* )) => {{
        let (out, size): (&Path, (u32, u32)) = ($out, $size);
        let fail = |e: String| VizError::output(out, e);
        // text is laid out with the vendored font in both formats
        crate::render::register_font();
        let bytes = if is_svg(out)? {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
                root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
                $f(&root, $($arg),*).map_err(fail)?;
                root.present().map_err(|e| fail(e.to_string()))?;
            }
            text.into_bytes()
        } else {
            let mut pixels = vec![255u8; (size.0 * size.1 * 3) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut pixels, size).into_drawing_area();
                root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
                $f(&root, $($arg),*).map_err(fail)?;
                root.present().map_err(|e| fail(e.to_string()))?;
            }
            crate::render::png_bytes(&pixels, size.0, size.1, out)?
        };
        asp_geom::io::write_atomic(out, &bytes).map_err(|e| VizError::io(out, e))?;
    }};
}

/// A Pareto front read from a plan JSON.
#[derive(Clone, Debug, PartialEq)]
pub struct Front {
    /// The objectives' names (from `optimisation.objectives`, else `objective 1`, ...).
    pub objectives: Vec<String>,
    /// The objective vectors of the front's points (all objectives maximised).
    pub points: Vec<Vec<f64>>,
}

/// Reads the `pareto_front` of a plan JSON.
pub fn read_front(path: &Path) -> Result<Front> {
    let report = crate::scene::read_plan(path)?;
    let front =
        report.pareto_front.ok_or_else(|| VizError::input(path, "the plan has no pareto_front (plan with --objective A,B --pareto)"))?;
    let dims = front.first().map(|p| p.objectives.len()).unwrap_or(0);
    if front.is_empty() || dims < 2 {
        return Err(VizError::input(path, "the pareto_front needs at least one point with two or more objectives"));
    }
    if let Some(bad) = front.iter().position(|p| p.objectives.len() != dims || p.objectives.iter().any(|v| !v.is_finite())) {
        return Err(VizError::input(path, format!("pareto_front point {bad} does not have {dims} finite objective values")));
    }
    let objectives = match report.optimisation {
        Some(o) if o.objectives.len() == dims => o.objectives,
        _ => (1..=dims).map(|k| format!("objective {k}")).collect(),
    };
    Ok(Front { objectives, points: front.into_iter().map(|p| p.objectives).collect() })
}

/// The points of `points` not dominated in objectives `(i, j)` (both maximised), by `i`
/// ascending: the corners of the staircase.
pub fn staircase(points: &[Vec<f64>], i: usize, j: usize) -> Vec<(f64, f64)> {
    let mut pairs: Vec<(f64, f64)> = points.iter().map(|p| (p[i], p[j])).collect();
    // by x descending, y descending: a point is on the front when its y beats every larger x's
    pairs.sort_by(|a, b| b.0.total_cmp(&a.0).then(b.1.total_cmp(&a.1)));
    let mut out: Vec<(f64, f64)> = Vec::new();
    for p in pairs {
        if out.last().is_none_or(|l| p.1 > l.1) {
            out.push(p);
        }
    }
    out.reverse();
    out
}

/// The path of the staircase through `corners` (x ascending, y descending): down, then right.
fn stair_path(corners: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut path = Vec::with_capacity(corners.len() * 2);
    for (k, c) in corners.iter().enumerate() {
        if k > 0 {
            path.push((corners[k - 1].0, c.1));
        }
        path.push(*c);
    }
    path
}

/// One `--trace` CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct Trace {
    /// The legend label (the file's name without extension).
    pub label: String,
    /// Episodes finished at each row.
    pub episodes: Vec<f64>,
    /// Seconds since the search started at each row.
    pub seconds: Vec<f64>,
    /// The hypervolume (Pareto) or best total (one objective) at each row.
    pub values: Vec<f64>,
    /// Whether `values` are fractions of the best reached (a bench CSV's settings).
    pub relative: bool,
}

/// The x axis of a progress plot.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TraceAxis {
    /// Seconds since the search started.
    Seconds,
    /// Episodes finished.
    Episodes,
}

/// Reads a `--trace` CSV (`episode,iterations,seconds,value,front_size`; see
/// docs/optimisation.md).
pub fn read_trace(path: &Path) -> Result<Trace> {
    let text = std::fs::read_to_string(path).map_err(|e| VizError::io(path, e))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().ok_or_else(|| VizError::input(path, "empty trace"))?.split(',').map(str::trim).collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| VizError::input(path, format!("the trace has no column '{name}' (columns: {})", header.join(","))))
    };
    let (ce, cs, cv) = (col("episode")?, col("seconds")?, col("value")?);
    let mut trace = Trace {
        label: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "trace".into()),
        episodes: Vec::new(),
        seconds: Vec::new(),
        values: Vec::new(),
        relative: false,
    };
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |c: usize| number(path, &cells, &header, k, c);
        trace.episodes.push(num(ce)?);
        trace.seconds.push(num(cs)?);
        trace.values.push(num(cv)?);
    }
    if trace.values.is_empty() {
        return Err(VizError::input(path, "the trace has no rows"));
    }
    Ok(trace)
}

/// The finite number in column `c` of data row `k` (0-based; the file's row `k + 2`) of a CSV.
fn number(path: &Path, cells: &[&str], header: &[&str], k: usize, c: usize) -> Result<f64> {
    cells.get(c).and_then(|s| s.parse::<f64>().ok()).filter(|v| v.is_finite()).ok_or_else(|| {
        VizError::input(path, format!("row {}: '{}' is not a number in column {}", k + 2, cells.get(c).unwrap_or(&""), header[c]))
    })
}

/// Reads an `asp bench mcts --csv` (`model,setting,seconds,mean,std,episodes`) as one trace per
/// setting, in the order the settings first appear: at each checkpoint the setting's mean value
/// divided by the best value any setting reached on that model (at any checkpoint), averaged
/// over the models; `episodes` the mean episodes of the run. Values must be positive (the
/// hypervolume, or an objective total of a maximised objective).
pub fn read_bench(path: &Path) -> Result<Vec<Trace>> {
    let text = std::fs::read_to_string(path).map_err(|e| VizError::io(path, e))?;
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    let header: Vec<&str> = lines.next().ok_or_else(|| VizError::input(path, "empty CSV"))?.split(',').map(str::trim).collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| VizError::input(path, format!("the bench CSV has no column '{name}' (columns: {})", header.join(","))))
    };
    let (cm, cset, cs, cv, ce) = (col("model")?, col("setting")?, col("seconds")?, col("mean")?, col("episodes")?);
    // (model, setting, seconds, value, episodes)
    let mut rows: Vec<(String, String, f64, f64, f64)> = Vec::new();
    for (k, line) in lines.enumerate() {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |c: usize| number(path, &cells, &header, k, c);
        let text = |c: usize| {
            cells.get(c).map(|s| s.to_string()).ok_or_else(|| VizError::input(path, format!("row {}: no column {}", k + 2, header[c])))
        };
        rows.push((text(cm)?, text(cset)?, num(cs)?, num(cv)?, num(ce)?));
    }
    if rows.is_empty() {
        return Err(VizError::input(path, "the bench CSV has no rows"));
    }
    let best = |model: &str| rows.iter().filter(|r| r.0 == model).map(|r| r.3).fold(f64::NEG_INFINITY, f64::max);
    if let Some(r) = rows.iter().find(|r| best(&r.0) <= 0.0) {
        return Err(VizError::input(path, format!("model {}: no positive value to compare the settings with", r.0)));
    }
    let mut settings: Vec<String> = Vec::new();
    for r in &rows {
        if !settings.contains(&r.1) {
            settings.push(r.1.clone());
        }
    }
    let mut traces = Vec::with_capacity(settings.len());
    for setting in settings {
        let mut seconds: Vec<f64> = rows.iter().filter(|r| r.1 == setting).map(|r| r.2).collect();
        seconds.sort_by(f64::total_cmp);
        seconds.dedup();
        let mut trace = Trace { label: setting.clone(), episodes: Vec::new(), seconds: Vec::new(), values: Vec::new(), relative: true };
        for t in seconds {
            let at: Vec<&(String, String, f64, f64, f64)> = rows.iter().filter(|r| r.1 == setting && r.2 == t).collect();
            let n = at.len() as f64;
            trace.seconds.push(t);
            trace.values.push(at.iter().map(|r| r.3 / best(&r.0)).sum::<f64>() / n);
            trace.episodes.push(at.iter().map(|r| r.4).sum::<f64>() / n);
        }
        traces.push(trace);
    }
    Ok(traces)
}

/// Whether the CSV at `path` is an `asp bench mcts --csv` (its header names `setting`), not a
/// `--trace`.
pub fn is_bench_csv(path: &Path) -> Result<bool> {
    let text = std::fs::read_to_string(path).map_err(|e| VizError::io(path, e))?;
    Ok(text.lines().next().is_some_and(|h| h.split(',').any(|c| c.trim() == "setting")))
}

/// Writes the front plot to `out` (SVG or PNG by extension). Returns the number of points drawn
/// per panel (one panel per pair of objectives).
pub fn write_front(out: &Path, front: &Front) -> Result<Vec<usize>> {
    let d = front.objectives.len();
    let pairs: Vec<(usize, usize)> = (0..d).flat_map(|i| (i + 1..d).map(move |j| (i, j))).collect();
    let columns = pairs.len().min(3) as u32;
    let rows = (pairs.len() as u32).div_ceil(columns);
    let size = (560 * columns, 480 * rows);
    render_to!(out, size, front_all(front, &pairs, rows as usize, columns as usize));
    Ok(pairs.iter().map(|_| front.points.len()).collect())
}

fn front_all<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    front: &Front,
    pairs: &[(usize, usize)],
    rows: usize,
    columns: usize,
) -> std::result::Result<(), String> {
    let areas = root.split_evenly((rows, columns));
    for (&(i, j), area) in pairs.iter().zip(areas.iter()) {
        front_panel(area, front, i, j)?;
    }
    Ok(())
}

fn front_panel<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, front: &Front, i: usize, j: usize) -> std::result::Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let xs: Vec<f64> = front.points.iter().map(|p| p[i]).collect();
    let ys: Vec<f64> = front.points.iter().map(|p| p[j]).collect();
    let (x0, x1) = padded(&xs);
    let (y0, y1) = padded(&ys);
    let mut chart = ChartBuilder::on(area)
        .caption(format!("Pareto front: {} vs {}", front.objectives[i], front.objectives[j]), ("sans-serif", 18))
        .margin(12)
        .x_label_area_size(42)
        .y_label_area_size(64)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(format!("{} (maximised)", front.objectives[i]))
        .y_desc(format!("{} (maximised)", front.objectives[j]))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    let stairs = stair_path(&staircase(&front.points, i, j));
    chart.draw_series(LineSeries::new(stairs, RGBColor(230, 81, 0).stroke_width(2))).map_err(e)?;
    chart.draw_series(xs.iter().zip(&ys).map(|(&x, &y)| Circle::new((x, y), 4, RGBColor(33, 90, 160).filled()))).map_err(e)?;
    Ok(())
}

/// Writes the progress plot of `traces` to `out` (SVG or PNG by extension), one step line with
/// a marker per row for each trace.
pub fn write_traces(out: &Path, traces: &[Trace], axis: TraceAxis) -> Result<()> {
    if traces.is_empty() {
        return Err(VizError::input(out, "no traces to plot"));
    }
    render_to!(out, (900, 560), traces_all(traces, axis));
    Ok(())
}

fn traces_all<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, traces: &[Trace], axis: TraceAxis) -> std::result::Result<(), String> {
    let e = |err: DrawingAreaErrorKind<DB::ErrorType>| err.to_string();
    let xs_of = |t: &Trace| match axis {
        TraceAxis::Seconds => t.seconds.clone(),
        TraceAxis::Episodes => t.episodes.clone(),
    };
    let all_x: Vec<f64> = traces.iter().flat_map(xs_of).collect();
    let all_y: Vec<f64> = traces.iter().flat_map(|t| t.values.iter().copied()).collect();
    let (x0, x1) = padded(&all_x);
    let (y0, y1) = padded(&all_y);
    let x_desc = match axis {
        TraceAxis::Seconds => "seconds",
        TraceAxis::Episodes => "episodes",
    };
    let mut chart = ChartBuilder::on(root)
        .caption("Search progress", ("sans-serif", 20))
        .margin(14)
        .x_label_area_size(44)
        .y_label_area_size(72)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(e)?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(if traces.iter().all(|t| t.relative) {
            "fraction of the best any setting reached"
        } else {
            "hypervolume (Pareto) or best total"
        })
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(e)?;
    for (k, t) in traces.iter().enumerate() {
        let c = series_colour(k);
        let xs = xs_of(t);
        let mut line = Vec::with_capacity(xs.len() * 2);
        for (n, (&x, &y)) in xs.iter().zip(&t.values).enumerate() {
            if n > 0 {
                line.push((x, t.values[n - 1]));
            }
            line.push((x, y));
        }
        chart
            .draw_series(LineSeries::new(line, c.stroke_width(2)))
            .map_err(e)?
            .label(t.label.clone())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(3)));
        chart.draw_series(xs.iter().zip(&t.values).map(|(&x, &y)| Circle::new((x, y), 3, c.filled()))).map_err(e)?;
    }
    chart
        .configure_series_labels()
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .position(SeriesLabelPosition::LowerRight)
        .draw()
        .map_err(e)?;
    Ok(())
}

fn series_colour(k: usize) -> RGBColor {
    const PALETTE: [(u8, u8, u8); 8] =
        [(33, 90, 160), (230, 81, 0), (46, 125, 50), (142, 36, 170), (198, 40, 40), (0, 131, 143), (109, 76, 65), (84, 110, 122)];
    let (r, g, b) = PALETTE[k % PALETTE.len()];
    RGBColor(r, g, b)
}

/// The range of `v` with 6 % room on each side (a unit range around a single value).
fn padded(v: &[f64]) -> (f64, f64) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() || !hi.is_finite() {
        return (0.0, 1.0);
    }
    let span = hi - lo;
    if span <= 0.0 {
        let pad = if lo == 0.0 { 1.0 } else { lo.abs() * 0.1 };
        return (lo - pad, hi + pad);
    }
    (lo - span * 0.06, hi + span * 0.06)
}

/// Whether `out` asks for SVG (else PNG); other extensions are an error.
pub(crate) fn is_svg(out: &Path) -> Result<bool> {
    match out.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).as_deref() {
        Some("svg") => Ok(true),
        Some("png") => Ok(false),
        _ => Err(VizError::output(out, "unknown picture type (use .svg or .png)")),
    }
}
