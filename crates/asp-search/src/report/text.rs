//! The plan as text: the table `asp plan` prints and the optimiser's summary under it
//! ([`PlanReport::write_text`]; Python's `Plan.table()`).

use super::{
    AssemblyStep, CoreGridReason, CoreWhy, ExplanationReason, LenientStatus, LockedCore, MotionEntry, OptimisationEntry, ParetoEntry,
    PlanReport, PlanStatus, SubassemblyStatus,
};
use crate::problem::StopReason;
use std::io::Write;

impl PlanReport {
    /// Writes the plan as `asp plan` prints it: the table, then (optimising runs) the
    /// optimiser's summary.
    pub fn write_text(&self, out: &mut impl Write) -> std::io::Result<()> {
        write_table(out, self)?;
        if let Some(summary) = &self.optimisation {
            write_summary(out, summary, self.pareto_front.as_deref())?;
        }
        Ok(())
    }

    /// [`PlanReport::write_text`] into a string.
    pub fn to_text(&self) -> String {
        let mut out = Vec::new();
        self.write_text(&mut out).expect("writing to memory does not fail");
        String::from_utf8(out).expect("the plan text is UTF-8")
    }
}

/// The human-readable plan: a header, the assembly sequence, and the explanation when stuck.
fn write_table(out: &mut impl Write, r: &PlanReport) -> std::io::Result<()> {
    let s = &r.stats;
    writeln!(
        out,
        "{}: {} in {:.3} s — {} removal tests ({} failed by collision, {} by gravity), {} path planner calls",
        r.model,
        r.status.as_str().replace('_', " "),
        s.seconds,
        s.removal_tests,
        s.failed_collision,
        s.failed_gravity,
        s.path_planner_calls
    )?;
    if !r.locked_cores.is_empty() {
        let locked: usize = r.locked_cores.iter().map(|c| c.parts.len()).sum();
        let n = r.locked_cores.len();
        let names: Vec<String> = r.locked_cores.iter().map(|c| c.names.join(", ")).collect();
        writeln!(
            out,
            "planned {} of {} parts; {locked} stay in {n} locked core{}: {}",
            r.parts.len().saturating_sub(locked),
            r.parts.len(),
            if n == 1 { "" } else { "s" },
            names.join("; ")
        )?;
        for core in &r.locked_cores {
            if let Some(why) = &core.why {
                write_why(out, r, core, why)?;
            }
        }
    }
    let width = r.parts.iter().map(|p| p.name.len()).max().unwrap_or(4).max(4);
    let fixed: Vec<&str> = r.parts.iter().filter(|p| p.fixed).map(|p| p.name.as_str()).collect();
    if !fixed.is_empty() {
        writeln!(out, "base (fixed): {}", fixed.join(", "))?;
    } else if r.grid.is_some() {
        writeln!(
            out,
            "base: none (taken apart in the hand, no gravity; the last part goes down first along -{})",
            r.up.trim_start_matches(['+', '-'])
        )?;
    } else {
        writeln!(out, "base: ground plane under the lowest point (up {})", r.up)?;
    }
    if let Some(g) = &r.grid {
        let first = g.first_separation_moves.map_or("-".to_string(), |m| m.to_string());
        writeln!(
            out,
            "grid plan ({}): cells of {:.4} x {:.4} x {:.4} {}, {} states in {:.3} s, {first} moves before the first separation",
            g.reason.as_str().replace('_', " "),
            g.cell[0],
            g.cell[1],
            g.cell[2],
            r.units,
            g.states,
            g.seconds
        )?;
    }
    if let Some(o) = &r.overlaps {
        writeln!(out, "overlapping in the input ({} pairs, policy {}):", o.pairs.len(), o.policy.name())?;
        for p in &o.pairs {
            let bound = if p.depth_bound { "more than " } else { "" };
            let class = match (p.class, p.normal) {
                (Some(c), Some(n)) => format!(", {} (normal {:.3}, {:.3}, {:.3})", c.describe(), n[0], n[1], n[2]),
                (Some(c), None) => format!(", {}", c.describe()),
                (None, _) => String::new(),
            };
            writeln!(out, "  {} / {}: {}, {bound}{} deep{class}, {}", p.names[0], p.names[1], p.kind, sig(p.depth), p.handling.name())?;
        }
    }
    if !r.fits.is_empty() {
        writeln!(out, "fits ({}; a shaft in a hole about one axis, taken apart along it):", r.fits.len())?;
        for f in &r.fits {
            let turns = match f.turns {
                Some(t) if t == f.parts[0] => format!(", {} turns out", f.names[0]),
                Some(_) => format!(", {} turns off", f.names[1]),
                None => String::new(),
            };
            writeln!(
                out,
                "  {} ({}) in {} ({}): {}, radii {} / {}{turns}",
                f.names[0],
                f.roles[0].name(),
                f.names[1],
                f.roles[1].name(),
                f.class.describe(),
                sig(f.radii[0]),
                sig(f.radii[1])
            )?;
        }
    }
    for b in &r.bearings {
        writeln!(
            out,
            "rolling bearing: {} in {}, {} {} in {} row{} (pitch radius {}, {} radius {}), goes in as one unit",
            b.names[0],
            b.names[1],
            b.balls.len(),
            b.rolling_elements,
            b.rows,
            if b.rows == 1 { "" } else { "s" },
            sig(b.pitch_radius),
            b.rolling_elements.trim_end_matches('s'),
            sig(b.ball_radius)
        )?;
    }
    if !r.assembly_sequence.is_empty() {
        write_steps(out, r, &r.assembly_sequence, width, "")?;
    }
    if !r.partial_assembly_sequence.is_empty() {
        let remaining = r.remaining.as_ref().map_or(0, Vec::len);
        writeln!(
            out,
            "partial plan: {} steps; in assembly order onto the {remaining} parts that stay:",
            r.partial_assembly_sequence.len()
        )?;
        write_steps(out, r, &r.partial_assembly_sequence, width, "")?;
    }
    if !r.file_subassemblies.is_empty() {
        writeln!(out, "subassemblies of the file, each planned on its own base:")?;
        for g in &r.file_subassemblies {
            let how = match g.status {
                SubassemblyStatus::Found => "found".to_string(),
                SubassemblyStatus::Partial => "partial (a group in it is not taken apart)".to_string(),
                SubassemblyStatus::NoPlan => "no plan (nothing more comes off its base)".to_string(),
                other => other.as_str().replace('_', " "),
            };
            writeln!(out, "  {} ({} parts): {how}", g.name.as_deref().unwrap_or("?"), g.parts.len())?;
            if !g.assembly_sequence.is_empty() {
                write_steps(out, r, &g.assembly_sequence, width, "    ")?;
            }
            for e in &g.explanation {
                let others: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
                writeln!(out, "      {} {} {}", e.name, e.reason.as_str().replace('_', " "), others.join(", "))?;
            }
        }
    }
    if let Some(robot) = &r.robot {
        writeln!(out, "robot {}: total path length {:.3} {}", robot.name, robot.total_path_length, r.units)?;
    }
    if !r.explanation.is_empty() {
        writeln!(out, "stuck with {} parts left; none can leave:", r.explanation.len())?;
        for e in &r.explanation {
            let others: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
            let why = match (e.reason, &e.robot) {
                (_, Some(r)) => format!("arm: {} ({})", r.reason.words(), r.detail),
                (ExplanationReason::Blocked, None) => format!("blocked by {}", others.join(", ")),
                (ExplanationReason::Unsupported, None) => format!("would leave {} unsupported", others.join(", ")),
                (ExplanationReason::DeadEnd, None) => "can leave, but every state after that is a dead end".into(),
            };
            writeln!(out, "  {:<width$}  {why}", e.name)?;
        }
    }
    if r.status == PlanStatus::BudgetExhausted {
        match r.stats.stopped_by {
            Some(StopReason::Interrupted) => {
                writeln!(out, "interrupted (Ctrl-C) before a plan was found; the best partial plan so far is above")?
            }
            _ if r.optimisation.is_some() => {
                writeln!(out, "the optimiser's budget ran out (--episodes / --time-limit) before a complete sequence was found")?
            }
            _ => writeln!(out, "the budget ran out (--max-tests / --timeout) before a plan was found")?,
        }
    }
    Ok(())
}

/// Assembly steps as table rows; a subassembly's own steps follow it, indented.
fn write_steps(out: &mut dyn Write, r: &PlanReport, sequence: &[AssemblyStep], width: usize, indent: &str) -> std::io::Result<()> {
    let name = |i: usize| r.parts.get(i).map_or("?", |p| p.name.as_str());
    let label = |step: &AssemblyStep| match &step.subassembly {
        None => step.name.clone(),
        Some(g) if g.status == SubassemblyStatus::Unit => format!("{} + {} more (unit)", step.name, g.parts.len() - 1),
        Some(g) => format!("{} + {} more (subassembly)", step.name, g.parts.len() - 1),
    };
    let width = sequence.iter().map(|s| label(s).len()).fold(width, usize::max);
    // the file's product tree: where each part sits, when the file has one
    let tree = r.parts.iter().any(|p| !p.path.is_empty());
    let place = |step: &AssemblyStep| match (&step.subassembly, r.parts.get(step.part)) {
        (Some(g), _) if g.name.is_some() => format!("{}  ", g.name.as_deref().unwrap_or_default()),
        (_, Some(p)) if tree => format!("{}  ", if p.path.is_empty() { "-".to_string() } else { p.path.join("/") }),
        _ => String::new(),
    };
    let place_width = sequence.iter().map(|s| place(s).len()).max().unwrap_or(0).max(if tree { 16 } else { 0 });
    if indent.is_empty() {
        let header = if tree { "in (file tree)" } else { "" };
        writeln!(out, "{:>4}  {:<width$}  {header:<place_width$}motion (insertion, {})", "step", "part", r.units)?;
    }
    for (k, step) in sequence.iter().enumerate() {
        let motion = match &step.motion {
            MotionEntry::Linear { direction: d, distance } => {
                format!("straight along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
            }
            MotionEntry::Path { poses, .. } => format!("path of {} poses", poses.len()),
            MotionEntry::Screw { direction: d, distance, .. } => {
                format!("screw along ({:+.3}, {:+.3}, {:+.3}) over {:.4}", d[0], d[1], d[2], distance)
            }
        };
        let robot = step.robot.as_ref().map_or(String::new(), |rs| format!("; robot path {:.3}", rs.path_length));
        let robot = if step.held.is_empty() {
            robot
        } else {
            format!("{robot}; holding {}", step.held.iter().map(|&p| name(p)).collect::<Vec<_>>().join(", "))
        };
        writeln!(out, "{indent}{:>4}  {:<width$}  {:<place_width$}{motion}{robot}", k + 1, label(step), place(step))?;
        if let Some(g) = &step.subassembly {
            let inner = format!("{indent}      ");
            let members: Vec<&str> = g.parts.iter().map(|&p| name(p)).collect();
            let how = match g.status {
                SubassemblyStatus::Found => "built on its base in this order:".to_string(),
                SubassemblyStatus::Partial => "built on its base in this order, but not all of it part by part:".to_string(),
                SubassemblyStatus::NoPlan => "cannot be taken apart (it goes in as one unit):".to_string(),
                SubassemblyStatus::Unplanned => "not planned".to_string(),
                SubassemblyStatus::Unit => match r.bearings.iter().find(|b| b.parts == sorted(&g.parts)) {
                    Some(b) => format!("a rolling bearing ({} captive between two rings), one unit, not taken apart", b.rolling_elements),
                    None if r.components.iter().any(|c| c.parts == sorted(&g.parts)) => {
                        "one component drawn as several interpenetrating solids, one unit, not taken apart".to_string()
                    }
                    None => "declared one unit (--unit-group), not taken apart".to_string(),
                },
                other => format!("{} before its own plan was found; the parts that come off:", other.as_str().replace('_', " ")),
            };
            writeln!(out, "{inner}subassembly {} on base {}: {how}", members.join(", "), step.name)?;
            write_steps(out, r, &g.assembly_sequence, width.saturating_sub(6), &inner)?;
            for e in &g.explanation {
                let others: Vec<&str> = e.parts.iter().map(|p| p.name.as_str()).collect();
                writeln!(out, "{inner}  {} {} {}", e.name, e.reason.as_str().replace('_', " "), others.join(", "))?;
            }
        }
        if !step.moves.is_empty() {
            writeln!(out, "{indent}      then {} moves:", step.moves.len())?;
        }
        for m in &step.moves {
            let t = m.translation;
            let parts: Vec<&str> = m.parts.iter().map(|&p| name(p)).collect();
            writeln!(out, "{indent}        move {} by ({:+.4}, {:+.4}, {:+.4})", parts.join(" + "), t[0], t[1], t[2])?;
        }
    }
    Ok(())
}

/// Prints the Pareto front (or the best value) under the plan table.
fn write_summary(out: &mut impl std::io::Write, summary: &OptimisationEntry, front: Option<&[ParetoEntry]>) -> std::io::Result<()> {
    let names = summary.objectives.join(", ");
    writeln!(
        out,
        "{}: {} episodes, {} iterations in {:.3} s ({} threads){}",
        summary.method.as_str().replace('_', "-"),
        summary.episodes,
        summary.iterations,
        summary.search_seconds,
        summary.threads,
        match (summary.exhaustive, summary.values.is_empty()) {
            (true, false) => "; the search space was exhausted: the answer is exact",
            (true, true) => "; the search space was exhausted: no complete sequence exists",
            (false, _) => "",
        }
    )?;
    match front {
        Some(front) => {
            writeln!(out, "Pareto front ({names}): {} sequences, hypervolume {:.6}", front.len(), summary.hypervolume.unwrap_or(0.0))?;
            for (k, e) in front.iter().enumerate() {
                let v: Vec<String> = e.objectives.iter().map(|x| format!("{x:.4}")).collect();
                writeln!(out, "{:>4}  ({})  removal order {:?}", k + 1, v.join(", "), e.disassembly_sequence)?;
            }
        }
        None => {
            if summary.values.is_empty() {
                writeln!(out, "best {names}: none (no complete sequence)")?;
            } else {
                let v: Vec<String> = summary.values.iter().map(|x| format!("{x:.4}")).collect();
                writeln!(out, "best {names}: {}", v.join(", "))?;
            }
        }
    }
    Ok(())
}

/// The most parts of a core whose blockers the table lists (the JSON lists all).
const WHY_PARTS: usize = 6;
/// The most blockers the table lists per part, and overlapping pairs per core.
const WHY_ITEMS: usize = 4;

/// A few lines under the locked-core line: why `core` is locked.
fn write_why(out: &mut impl Write, r: &PlanReport, core: &LockedCore, why: &CoreWhy) -> std::io::Result<()> {
    let base = r.parts.get(core.base).map_or("?", |p| p.name.as_str());
    writeln!(out, "  why the core on {base} ({} parts) is locked:", core.parts.len())?;
    // the deepest first
    let mut overlaps: Vec<_> = why.overlaps.iter().collect();
    overlaps.sort_by(|a, b| b.gross.cmp(&a.gross).then(b.depth.total_cmp(&a.depth)));
    for o in overlaps.into_iter().take(WHY_ITEMS) {
        let bound = if o.depth_bound { "more than " } else { "" };
        let class = o.class.map_or(String::new(), |c| format!(" ({})", c.describe()));
        let verdict = if o.artefact {
            format!("deeper than {}: a modelling artefact, not an interlock", sig(why.artefact_depth))
        } else {
            format!("within {}: a fit, not an artefact", sig(why.artefact_depth))
        };
        writeln!(out, "    overlap {} / {}{class}: {bound}{} deep, {verdict}", o.names[0], o.names[1], sig(o.depth))?;
    }
    if why.overlaps.len() > WHY_ITEMS {
        writeln!(out, "    ... and {} more overlapping pairs", why.overlaps.len() - WHY_ITEMS)?;
    }
    let on_grid = |g: Option<bool>| match g {
        Some(true) => "; the core's own parts are",
        Some(false) => "; nor are the core's own parts",
        None => "",
    };
    let grid = match why.grid.reason {
        CoreGridReason::Stuck => "tried: no moves on the grid take it apart".to_string(),
        CoreGridReason::Budget => "tried: its budget ran out first".to_string(),
        CoreGridReason::Off => "not tried (--no-grid)".to_string(),
        CoreGridReason::Robot => "not tried (planned with a robot)".to_string(),
        CoreGridReason::UnitGroups => "not tried (units declared with --unit-group)".to_string(),
        CoreGridReason::TooManyParts => format!("not tried (more than 64 parts){}", on_grid(why.grid.core_on_grid)),
        CoreGridReason::NotOnGrid => format!("not tried (the model's parts are not all on one grid){}", on_grid(why.grid.core_on_grid)),
    };
    writeln!(out, "    grid planner: {grid}")?;
    let others = core.parts.len().saturating_sub(1);
    let l = &why.lenient;
    let lenient = match l.status {
        LenientStatus::Unchanged if why.overlaps.is_empty() => "changes nothing (no two of its parts overlap)".to_string(),
        LenientStatus::Unchanged => "changes nothing (its overlaps are already tested that way)".to_string(),
        LenientStatus::Found if others == 1 => "would free its other part".to_string(),
        LenientStatus::Found => format!("would free all {others} of its other parts"),
        LenientStatus::Partial | LenientStatus::NoPlan => format!("would free {} of its {others} other parts", l.frees),
        LenientStatus::BudgetExhausted => {
            format!("would free at least {} of its {others} other parts (the rerun ran out of budget)", l.frees)
        }
        LenientStatus::Unknown => "not known (the rerun could not be set up)".to_string(),
    };
    writeln!(out, "    --overlaps lenient: {lenient}")?;
    writeln!(out, "    if it is one component (bought or pressed together), declare it one unit: --unit-group NAME,NAME,...")?;
    let d = why.directions;
    for b in why.blocks.iter().take(WHY_PARTS) {
        let by: Vec<String> =
            b.by.iter()
                .take(WHY_ITEMS)
                .map(|q| {
                    let alone = if q.only > 0 { format!(" (alone along {})", q.only) } else { String::new() };
                    format!("{} along {}{alone}", q.name, q.directions)
                })
                .collect();
        let more = if b.by.len() > WHY_ITEMS { format!(" and {} more", b.by.len() - WHY_ITEMS) } else { String::new() };
        let held =
            if b.free == 0 { format!("blocked along all {d} directions") } else { format!("free along {} of {d} directions", b.free) };
        if by.is_empty() {
            writeln!(out, "    {}: {held}", b.name)?;
        } else {
            writeln!(out, "    {}: {held}; by {}{more}", b.name, by.join(", "))?;
        }
    }
    if why.blocks.len() > WHY_PARTS {
        writeln!(out, "    ... and {} more parts (the plan JSON lists them)", why.blocks.len() - WHY_PARTS)?;
    }
    Ok(())
}

/// `x` with three significant digits and no exponent (0.0000412, 1.25, 1250): lengths in any unit.
fn sig(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    format!("{x:.decimals$}")
}

/// `parts` ascending.
fn sorted(parts: &[usize]) -> Vec<usize> {
    let mut v = parts.to_vec();
    v.sort_unstable();
    v
}
