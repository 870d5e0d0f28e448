//! Reading a given sequence: lines of part names and groups with optional insertion directions,
//! or a plan JSON's `assembly_sequence`; names matched to the model's parts (unknown names get
//! the nearest ones as a hint).

use super::*;

/// One step of a given sequence, as written: part names (one, or a group's) and an optional
/// insertion direction in the model's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct GivenStep {
    /// The part names (several: a subassembly that goes in as one rigid body).
    pub names: Vec<String>,
    /// The assembly (insertion) direction, as given (not normalised).
    pub direction: Option<[f64; 3]>,
    /// The line of the sequence file it came from (1-based; the step's number for a plan JSON).
    pub line: usize,
    /// For a step read from a plan JSON: the line as its text would read, for messages.
    pub text: String,
}

/// Reads a sequence: a plan JSON (text starting with `{`) or the line format of
/// docs/check-format.md. Errors are [`AppError::Setting`]s of the key `sequence`.
pub fn parse_sequence(text: &str) -> Result<Vec<GivenStep>> {
    if text.trim_start().starts_with('{') {
        return parse_plan_json(text);
    }
    let mut steps = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = strip_comment(raw).trim();
        if line.is_empty() {
            continue;
        }
        let bad = |why: &str| AppError::setting("sequence", format!("line {}: {why}: {line}", i + 1));
        let (names, rest) = if let Some(inner) = line.strip_prefix('[') {
            let Some(end) = inner.find(']') else { return Err(bad("a group opened with `[` is not closed")) };
            let names: Vec<String> = inner[..end].split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect();
            if names.is_empty() {
                return Err(bad("an empty group"));
            }
            (names, inner[end + 1..].trim())
        } else {
            // the direction is the last word when it reads as one; a name may hold spaces
            match line.rsplit_once(char::is_whitespace) {
                Some((name, last)) if parse_direction(last).is_some() => (vec![name.trim().to_string()], last),
                _ => (vec![line.to_string()], ""),
            }
        };
        let direction = if rest.is_empty() {
            None
        } else {
            Some(
                parse_direction(rest)
                    .ok_or_else(|| bad("not a direction (write an axis such as -z or three numbers such as 0,0,-1 after the part)"))?,
            )
        };
        steps.push(GivenStep { names, direction, line: i + 1, text: line.to_string() });
    }
    if steps.is_empty() {
        return Err(AppError::setting("sequence", "names no part (one part per line, in assembly order)"));
    }
    Ok(steps)
}

/// A line without its comment: `#` at the start or after whitespace (a `#` inside a name, as in
/// `--split-bodies`' `NAME#1`, stays).
pub(super) fn strip_comment(line: &str) -> &str {
    let bytes = line.as_bytes();
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'#' && (i == 0 || bytes[i - 1].is_ascii_whitespace()) {
            return &line[..i];
        }
    }
    line
}

/// An axis (`x`, `+x`, `-z`, ...) or three comma-separated numbers; `None` for the zero vector.
pub fn parse_direction(text: &str) -> Option<[f64; 3]> {
    let t = text.trim().to_ascii_lowercase();
    let axis = |c: &str| match c {
        "x" => Some([1.0, 0.0, 0.0]),
        "y" => Some([0.0, 1.0, 0.0]),
        "z" => Some([0.0, 0.0, 1.0]),
        _ => None,
    };
    let v = (if let Some(a) = t.strip_prefix('-') {
        axis(a).map(|v| v.map(|x: f64| -x))
    } else if let Some(a) = t.strip_prefix('+') {
        axis(a)
    } else if let Some(v) = axis(&t) {
        Some(v)
    } else {
        let nums: Vec<f64> = t.split(',').map(|s| s.trim().parse::<f64>()).collect::<std::result::Result<_, _>>().ok()?;
        (nums.len() == 3 && nums.iter().all(|x| x.is_finite())).then(|| [nums[0], nums[1], nums[2]])
    })?;
    (v.iter().map(|x| x * x).sum::<f64>() > 1e-18).then_some(v)
}

/// The `assembly_sequence` of a plan JSON as given steps: each step's part (a subassembly's
/// parts) by name, with the insertion direction of a linear or screw motion.
pub(super) fn parse_plan_json(text: &str) -> Result<Vec<GivenStep>> {
    let bad = |why: String| AppError::setting("sequence", format!("plan JSON: {why}"));
    let v: serde_json::Value = serde_json::from_str(text).map_err(|e| bad(format!("not JSON: {e}")))?;
    let names: Vec<String> =
        v["parts"].as_array().map(|ps| ps.iter().map(|p| p["name"].as_str().unwrap_or_default().to_string()).collect()).unwrap_or_default();
    let Some(seq) = v["assembly_sequence"].as_array().filter(|s| !s.is_empty()) else {
        return Err(bad(format!("no assembly_sequence (status {})", v["status"])));
    };
    let name_of = |i: &serde_json::Value| -> Result<String> {
        i.as_u64().and_then(|i| names.get(i as usize)).cloned().ok_or_else(|| bad(format!("part {i} is not in its `parts`")))
    };
    let mut steps = Vec::new();
    for (k, s) in seq.iter().enumerate() {
        let group = s["subassembly"]["parts"].as_array();
        let names: Vec<String> = match group {
            Some(ps) => ps.iter().map(&name_of).collect::<Result<_>>()?,
            None => vec![s["name"].as_str().map(str::to_string).map_or_else(|| name_of(&s["part"]), Ok)?],
        };
        let direction = match s["motion"]["kind"].as_str() {
            Some("linear" | "screw") => s["motion"]["direction"]
                .as_array()
                .and_then(|d| (d.len() == 3).then(|| [d[0].as_f64(), d[1].as_f64(), d[2].as_f64()]))
                .and_then(|[x, y, z]| Some([x?, y?, z?])),
            _ => None,
        };
        let text = if names.len() == 1 { names[0].clone() } else { format!("[{}]", names.join(", ")) };
        steps.push(GivenStep { names, direction, line: k + 1, text });
    }
    Ok(steps)
}

/// The edit (Levenshtein) distance of two strings, by characters.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// The (at most three) part names nearest to `name` by edit distance (case-insensitive), nearest
/// first.
pub fn nearest_names<'a>(name: &str, names: impl Iterator<Item = &'a str>) -> Vec<String> {
    let lower = name.to_lowercase();
    let mut scored: Vec<(usize, &str)> = names.map(|n| (edit_distance(&lower, &n.to_lowercase()), n)).collect();
    scored.sort();
    scored.into_iter().take(3).map(|(_, n)| n.to_string()).collect()
}

/// A step of the sequence resolved on the model: its parts (the first is the one the report
/// names a subassembly by) and its unit insertion direction.
#[derive(Clone, Debug)]
pub(super) struct Unit {
    pub(super) parts: Vec<usize>,
    pub(super) direction: Option<Vec3>,
}

/// The steps' names as part indices, the base parts listed dropped (with a note). Unknown names,
/// a part named twice and parts left out are errors (one line: the unknown names with their
/// nearest names).
pub(super) fn resolve_units(assembly: &Assembly, steps: &[GivenStep], notes: &mut Vec<String>) -> Result<Vec<Unit>> {
    let index = |name: &str| assembly.part_index(name);
    // a one-name step whose "direction" is part of a name with spaces (`bolt x`)
    let mut steps = steps.to_vec();
    for s in &mut steps {
        if s.names.len() == 1 && index(&s.names[0]).is_none() && index(&s.text).is_some() {
            s.names = vec![s.text.clone()];
            s.direction = None;
        }
    }
    let unknown: Vec<&str> = steps.iter().flat_map(|s| &s.names).map(String::as_str).filter(|&n| index(n).is_none()).collect();
    if !unknown.is_empty() {
        let names = || assembly.parts.iter().map(|p| p.name.as_str());
        let listed: Vec<String> = unknown.iter().map(|n| format!("'{n}' (nearest: {})", nearest_names(n, names()).join(", "))).collect();
        return Err(AppError::setting("sequence", format!("no part is named {}", listed.join("; "))));
    }
    let mut seen = vec![false; assembly.len()];
    let mut units = Vec::new();
    for s in &steps {
        let mut parts = Vec::new();
        for n in &s.names {
            let p = index(n).expect("names checked");
            if std::mem::replace(&mut seen[p], true) {
                return Err(AppError::setting("sequence", format!("line {}: part '{n}' is placed twice", s.line)));
            }
            if assembly.parts[p].fixed {
                notes.push(format!("'{n}' is a base part: it is in place from the start, not a step"));
            } else {
                parts.push(p);
            }
        }
        if parts.is_empty() {
            continue;
        }
        let direction = s.direction.map(|d| {
            let v = Vec3::new(d[0] as f32, d[1] as f32, d[2] as f32);
            v / v.length()
        });
        units.push(Unit { parts, direction });
    }
    let missing: Vec<&str> =
        assembly.parts.iter().enumerate().filter(|(p, part)| !part.fixed && !seen[*p]).map(|(_, part)| part.name.as_str()).collect();
    if !missing.is_empty() {
        return Err(AppError::setting(
            "sequence",
            format!("leaves out {}: {} (every part that is not a base part goes in once)", missing.len(), missing.join(", ")),
        ));
    }
    Ok(units)
}
