//! `asp render instructions`: the plan as work instructions for an assembly line of a few
//! stations. The steps are grouped by a line-balancing heuristic on the plan's precedence graph
//! (`asp plan --precedence`; without one, the plan's own order is the only order): every station
//! gets about the same work (a time per part, one unit each by default), and no step goes to a
//! station before one of its predecessors. Each station gets one page: the parts to take, its
//! steps with their motions and pictures (the storyboard's panels), and the fasteners with how
//! they go in (screwed in or pushed in). Written as HTML pages (an index and one per station)
//! and one PNG per station.

use crate::error::{Result, VizError};
use crate::render::{png_bytes, storyboard, RenderOptions};
use crate::scene::Scene;
use asp_search::report::MotionEntry;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// What `asp render instructions` is asked.
#[derive(Clone, Debug)]
pub struct InstructionOptions {
    /// How many stations the line has (at least 1; fewer are used when there are fewer steps).
    pub stations: usize,
    /// Seconds per part by name; a part not named takes `default_time`.
    pub times: BTreeMap<String, f64>,
    /// Seconds of a part no time names (default 1: balancing by the number of parts).
    pub default_time: f64,
    /// Width and height of one picture, pixels.
    pub panel: u32,
}

impl Default for InstructionOptions {
    fn default() -> Self {
        InstructionOptions { stations: 1, times: BTreeMap::new(), default_time: 1.0, panel: 320 }
    }
}

/// One station of the line.
#[derive(Clone, Debug, PartialEq)]
pub struct Station {
    /// Its steps (indices into the plan's `assembly_sequence`), in the order they are done.
    pub steps: Vec<usize>,
    /// The work at the station, seconds (the sum of its steps' times).
    pub time: f64,
}

/// What [`write()`] made.
#[derive(Clone, Debug)]
pub struct Instructions {
    /// The stations, first to last.
    pub stations: Vec<Station>,
    /// The cycle time the balance reached: the most work at one station, seconds.
    pub cycle: f64,
    /// Whether the plan's precedence graph constrained the balance (else the plan's order).
    pub from_precedence: bool,
    /// The files written: `index.html`, then per station its page and its picture.
    pub files: Vec<PathBuf>,
}

/// Groups steps `0..times.len()` into at most `stations` stations so that every edge `(a, b)`
/// (step `a` before step `b`) keeps `a` at `b`'s station or an earlier one, with about equal
/// work per station: the smallest cycle time for which the largest-candidate rule (fill each
/// station with the longest step whose predecessors are all placed and that still fits, ties by
/// the plan's order) needs no more than `stations` stations, found by bisection. Returns each
/// station's steps in the order they are done. Steps on a cycle of edges (there are none in a
/// plan's graph) are placed in the plan's order.
pub fn balance(times: &[f64], edges: &[(usize, usize)], stations: usize) -> Vec<Vec<usize>> {
    let n = times.len();
    if n == 0 {
        return Vec::new();
    }
    let stations = stations.max(1);
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); n];
    for &(a, b) in edges {
        if a < n && b < n && a != b {
            preds[b].push(a);
        }
    }
    let total: f64 = times.iter().sum();
    let longest = times.iter().copied().fold(0.0, f64::max);
    let assign = |cycle: f64| -> Vec<Vec<usize>> {
        let mut done = vec![false; n];
        let mut out: Vec<Vec<usize>> = Vec::new();
        let mut left = n;
        while left > 0 {
            let mut station = Vec::new();
            let mut load = 0.0;
            loop {
                let ready = (0..n).filter(|&s| !done[s] && preds[s].iter().all(|&p| done[p]));
                let fits = ready.clone().filter(|&s| station.is_empty() || load + times[s] <= cycle + 1e-9);
                // the longest that fits; ties by the plan's order
                let pick = fits.fold(None, |best: Option<usize>, s| match best {
                    Some(b) if times[b] >= times[s] => Some(b),
                    _ => Some(s),
                });
                // a cycle of edges: the first step left, in the plan's order
                let pick = pick.or_else(|| (ready.count() == 0 && station.is_empty()).then(|| (0..n).find(|&s| !done[s])).flatten());
                let Some(s) = pick else { break };
                done[s] = true;
                left -= 1;
                load += times[s];
                station.push(s);
            }
            out.push(station);
        }
        out
    };
    let (mut lo, mut hi) = ((total / stations as f64).max(longest), total.max(longest));
    let tightest = assign(lo);
    if tightest.len() <= stations {
        return tightest;
    }
    let mut best = assign(hi);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        let a = assign(mid);
        if a.len() <= stations {
            hi = mid;
            best = a;
        } else {
            lo = mid;
        }
        if hi - lo <= 1e-6 * total.max(1e-12) {
            break;
        }
    }
    best
}

/// Writes the instructions of `scene`'s plan into the folder `dir` (made if missing).
pub fn write(dir: &Path, scene: &Scene, options: &InstructionOptions) -> Result<Instructions> {
    let report = &scene.report;
    if !report.status.has_sequence() {
        return Err(VizError::input(
            dir,
            format!("the plan is {}: instructions need an assembly sequence", report.status.as_str().replace('_', " ")),
        ));
    }
    if options.stations == 0 {
        return Err(VizError::input(dir, "--stations must be at least 1"));
    }
    if !(options.default_time.is_finite() && options.default_time > 0.0) {
        return Err(VizError::input(dir, "the default time per part must be a positive number of seconds"));
    }
    let steps = &report.assembly_sequence;
    for name in options.times.keys() {
        if !report.parts.iter().any(|p| &p.name == name) {
            return Err(VizError::input(dir, format!("a time is given for '{name}', which is no part of the plan")));
        }
    }
    let time_of = |p: usize| report.parts.get(p).and_then(|x| options.times.get(&x.name)).copied().unwrap_or(options.default_time);
    let parts_of = |k: usize| steps[k].subassembly.as_ref().map_or_else(|| vec![steps[k].part], |g| g.parts.clone());
    // a subassembly is built at the station that puts it in: its time is all its parts'
    let times: Vec<f64> = (0..steps.len()).map(|k| parts_of(k).into_iter().map(time_of).sum()).collect();
    let (edges, from_precedence): (Vec<(usize, usize)>, bool) = match &report.precedence {
        Some(p) => (p.edges.iter().map(|e| (e.before, e.after)).collect(), true),
        None => ((1..steps.len()).map(|k| (k - 1, k)).collect(), false),
    };
    let groups = balance(&times, &edges, options.stations);
    let stations: Vec<Station> = groups.iter().map(|g| Station { steps: g.clone(), time: g.iter().map(|&k| times[k]).sum() }).collect();
    let cycle = stations.iter().map(|s| s.time).fold(0.0, f64::max);
    std::fs::create_dir_all(dir).map_err(|e| VizError::io(dir, e))?;
    // the storyboard once; each step's panel is cut out of it
    let board = storyboard(scene, &RenderOptions { panel: options.panel, columns: None });
    let panel_of = |k: usize| board.panels.get(k);
    let roles = roles(report);
    let mut files = vec![dir.join("index.html")];
    let count = stations.len();
    for (i, station) in stations.iter().enumerate() {
        let png = dir.join(format!("station-{:02}.png", i + 1));
        let html = dir.join(format!("station-{:02}.html", i + 1));
        // the station's pictures side by side, up to 4 a row
        let size = board.panels.first().map_or(options.panel, |p| p.size);
        let columns = station.steps.len().clamp(1, 4) as u32;
        let rows = (station.steps.len() as u32).div_ceil(columns).max(1);
        let (w, h) = (columns * size, rows * size);
        let mut pixels = vec![255u8; (w * h * 3) as usize];
        for (j, &k) in station.steps.iter().enumerate() {
            let Some(p) = panel_of(k) else { continue };
            let (x, y) = ((j as u32 % columns) * size, (j as u32 / columns) * size);
            for row in 0..size {
                let src = (((p.y + row) * board.width + p.x) * 3) as usize;
                let dst = (((y + row) * w + x) * 3) as usize;
                pixels[dst..dst + (size * 3) as usize].copy_from_slice(&board.pixels[src..src + (size * 3) as usize]);
            }
        }
        asp_geom::io::write_atomic(&png, &png_bytes(&pixels, w, h, &png)?).map_err(|e| VizError::io(&png, e))?;
        let page = station_page(scene, station, i, count, cycle, &roles, &times, &png);
        asp_geom::io::write_atomic(&html, page.as_bytes()).map_err(|e| VizError::io(&html, e))?;
        files.push(html);
        files.push(png);
    }
    let index = index_page(scene, &stations, cycle, from_precedence);
    asp_geom::io::write_atomic(&files[0], index.as_bytes()).map_err(|e| VizError::io(&files[0], e))?;
    Ok(Instructions { stations, cycle, from_precedence, files })
}

/// Each part's role from the plan's fits (`bolt`, `nut`, `washer`, `pin`), parts in no fit or
/// of role `other` left out.
fn roles(report: &asp_search::report::PlanReport) -> BTreeMap<usize, &'static str> {
    let mut out = BTreeMap::new();
    for f in &report.fits {
        for (p, r) in f.parts.iter().zip(f.roles) {
            let name = r.name();
            if name != "other" {
                out.insert(*p, name);
            }
        }
    }
    out
}

/// `s` with `&`, `<`, `>` and `"` escaped for HTML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// How a step's motion reads on the shop floor.
fn motion_text(motion: &MotionEntry, units: &str) -> String {
    let dir = |d: &[f64; 3]| format!("({:+.2}, {:+.2}, {:+.2})", d[0], d[1], d[2]);
    match motion {
        MotionEntry::Linear { direction, distance } => format!("push in along {} over {distance:.4} {units}", dir(direction)),
        MotionEntry::Screw { direction, distance, .. } => format!("screw in along {} over {distance:.4} {units}", dir(direction)),
        MotionEntry::Path { poses, .. } => format!("guide in along a path of {} poses (see the viewer)", poses.len()),
    }
}

const STYLE: &str = "body{font-family:sans-serif;margin:2em;max-width:70em}table{border-collapse:collapse}\
td,th{border:1px solid #ccc;padding:.3em .6em;text-align:left;vertical-align:top}img{max-width:100%;border:1px solid #ddd}\
.time{color:#555}";

#[allow(clippy::too_many_arguments)] // one page: the station, its place on the line and the plan's facts
fn station_page(
    scene: &Scene,
    station: &Station,
    i: usize,
    count: usize,
    cycle: f64,
    roles: &BTreeMap<usize, &'static str>,
    times: &[f64],
    png: &Path,
) -> String {
    let report = &scene.report;
    let name = |p: usize| report.parts.get(p).map_or_else(|| format!("part {p}"), |x| x.name.clone());
    let mut h = String::new();
    let title = format!("Station {} of {count}", i + 1);
    let _ = write!(h, "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>{title}</title><style>{STYLE}</style></head><body>");
    let _ = write!(h, "<p><a href=\"index.html\">all stations</a></p><h1>{title}</h1>");
    let _ = write!(h, "<p class=\"time\">work {:.1} s of a cycle of {cycle:.1} s; model {}</p>", station.time, escape(&report.model));
    // the parts to take
    let _ = write!(h, "<h2>Parts to take</h2><ul>");
    for &k in &station.steps {
        let step = &report.assembly_sequence[k];
        match &step.subassembly {
            Some(g) => {
                let members: Vec<String> = g.parts.iter().map(|&p| escape(&name(p))).collect();
                let _ = write!(h, "<li>{} as one piece ({})</li>", escape(&step.name), members.join(", "));
            }
            None => {
                let _ = write!(h, "<li>{}</li>", escape(&step.name));
            }
        }
    }
    let _ = write!(h, "</ul><h2>Steps</h2><table><tr><th>step</th><th>part</th><th>motion</th><th>time</th></tr>");
    for &k in &station.steps {
        let step = &report.assembly_sequence[k];
        let what = match &step.subassembly {
            Some(g) if !g.assembly_sequence.is_empty() => {
                let inner: Vec<String> = g.assembly_sequence.iter().map(|s| escape(&s.name)).collect();
                format!("{} (built beforehand on it: {})", escape(&step.name), inner.join(", "))
            }
            Some(_) => format!("{} (one unit)", escape(&step.name)),
            None => escape(&step.name),
        };
        let _ = write!(
            h,
            "<tr><td>{}</td><td>{what}</td><td>{}</td><td>{:.1} s</td></tr>",
            k + 1,
            escape(&motion_text(&step.motion, &report.units)),
            times[k]
        );
    }
    let _ = write!(h, "</table>");
    // the fasteners: steps of a fastener's part, or screwed in
    let fasteners: Vec<String> = station
        .steps
        .iter()
        .filter_map(|&k| {
            let step = &report.assembly_sequence[k];
            let screw = matches!(step.motion, MotionEntry::Screw { .. });
            let role = roles.get(&step.part).copied();
            (screw || role.is_some()).then(|| {
                let how = if screw { "screw in (unscrews to take apart)" } else { "push in (pulls out along its axis)" };
                format!("<li>{} ({}): {how}</li>", escape(&step.name), role.unwrap_or("fastener"))
            })
        })
        .collect();
    if !fasteners.is_empty() {
        let _ = write!(h, "<h2>Fasteners</h2><ul>{}</ul>", fasteners.concat());
    }
    let file = png.file_name().map_or_else(String::new, |f| f.to_string_lossy().into_owned());
    let _ = writeln!(h, "<h2>Pictures</h2><img src=\"{}\" alt=\"the steps of {title}\"></body></html>", escape(&file));
    h
}

fn index_page(scene: &Scene, stations: &[Station], cycle: f64, from_precedence: bool) -> String {
    let report = &scene.report;
    let mut h = String::new();
    let _ = write!(
        h,
        "<!DOCTYPE html><html><head><meta charset=\"utf-8\"><title>Assembly line: {}</title><style>{STYLE}</style></head><body>",
        escape(&report.model)
    );
    let _ = write!(h, "<h1>Assembly line for {}</h1>", escape(&report.model));
    let by = if from_precedence {
        "balanced on the plan's precedence graph: steps of one station may be done in any order the graph allows"
    } else {
        "balanced on the plan's order (the plan has no precedence graph: plan with --precedence to let steps move between stations)"
    };
    let _ = write!(
        h,
        "<p>{} stations, cycle {cycle:.1} s; {by}.</p><table><tr><th>station</th><th>steps</th><th>work</th></tr>",
        stations.len()
    );
    for (i, s) in stations.iter().enumerate() {
        let names: Vec<String> = s.steps.iter().map(|&k| format!("{}. {}", k + 1, escape(&report.assembly_sequence[k].name))).collect();
        let _ = write!(
            h,
            "<tr><td><a href=\"station-{:02}.html\">Station {}</a></td><td>{}</td><td>{:.1} s</td></tr>",
            i + 1,
            i + 1,
            names.join("<br>"),
            s.time
        );
    }
    let _ = writeln!(h, "</table></body></html>");
    h
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chain_is_cut_into_equal_stations_in_order() {
        let t = vec![1.0; 6];
        let chain: Vec<(usize, usize)> = (1..6).map(|k| (k - 1, k)).collect();
        assert_eq!(balance(&t, &chain, 3), vec![vec![0, 1], vec![2, 3], vec![4, 5]]);
        assert_eq!(balance(&t, &chain, 1), vec![vec![0, 1, 2, 3, 4, 5]]);
        // more stations than steps: one step each
        assert_eq!(balance(&t, &chain, 9).len(), 6);
    }

    #[test]
    fn independent_steps_are_balanced_by_time_and_edges_are_kept() {
        // four steps, no edges: 3 + 1 and 2 + 2 balance two stations at 4 s
        let t = vec![3.0, 2.0, 2.0, 1.0];
        let s = balance(&t, &[], 2);
        let loads: Vec<f64> = s.iter().map(|g| g.iter().map(|&k| t[k]).sum()).collect();
        assert_eq!(loads, vec![4.0, 4.0], "{s:?}");
        // with 3 after 0 and 2 after 1, no step is ever at a station before its predecessor
        let edges = [(0, 3), (1, 2)];
        let s = balance(&t, &edges, 2);
        let station_of = |k: usize| s.iter().position(|g| g.contains(&k)).unwrap();
        for (a, b) in edges {
            let (sa, sb) = (station_of(a), station_of(b));
            assert!(sa < sb || (sa == sb && s[sa].iter().position(|&x| x == a) < s[sb].iter().position(|&x| x == b)), "{s:?}");
        }
        assert_eq!(s.iter().map(Vec::len).sum::<usize>(), 4);
    }
}
