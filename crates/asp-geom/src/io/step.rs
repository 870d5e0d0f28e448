//! STEP (`.step`, `.stp`; AP203, AP214, AP242): read and tessellated by OpenCASCADE, the
//! industry's kernel, through the `cascadio` Python wheel, which writes the product as GLB
//! with its tree of subassembly instances (node names are the file's instance names) and the
//! `TM_brep_faces` extension (each triangle's B-rep face, each face's analytic surface).
//!
//! asp links no C++: [`convert`] runs the small converter `step_convert.py` in a Python that
//! has cascadio ([`python`]: `ASP_PYTHON`, else `python3`), STEP bytes in, GLB bytes out, and
//! [`assemble`] reads the GLB with the glTF reader. Python's `asp.load` calls cascadio in its own
//! process and hands both byte strings to [`assemble`]. The length unit is read from the STEP
//! file itself ([`length_unit`]): cascadio writes metres, reports stay in the file's unit.
//! STEP has no up axis; +Z (most CAD) is assumed unless the caller says otherwise.

use super::{gltf_read, LoadOptions};
use crate::assembly::{Assembly, Units};
use crate::error::{GeomError, Result};
use crate::math::Axis;
use std::collections::HashMap;
use std::io::Write;
use std::path::Path;
use std::process::{Command, Stdio};

/// The converter the Rust loader runs (`python -c`), arguments: relative and angular deflection.
pub const CONVERTER: &str = include_str!("step_convert.py");

/// The environment variable naming the Python that has cascadio (default `python3`).
pub const PYTHON_VAR: &str = "ASP_PYTHON";

/// The command that installs what reading STEP needs (named in the error when it is missing).
pub const INSTALL: &str = "pip install cascadio";

pub use crate::assembly::{Tessellation, DEFAULT_ANGULAR, DEFAULT_RELATIVE};

/// Whether `path` names a STEP file by its extension.
pub fn is_step(path: &Path) -> bool {
    matches!(path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(), Some("step" | "stp"))
}

/// The Python that runs the converter: `ASP_PYTHON`, else `python3`.
pub fn python() -> String {
    std::env::var(PYTHON_VAR).ok().filter(|p| !p.trim().is_empty()).unwrap_or_else(|| "python3".into())
}

/// The GLB (with `TM_brep_faces`) of the STEP file `path` whose bytes are `step`, from the
/// converter run in [`python`]. Errors name the file and the cause: no Python, no cascadio (with
/// [`INSTALL`]), or OpenCASCADE's own words on a file it cannot read.
pub fn convert(path: &Path, step: &[u8], tessellation: &Tessellation) -> Result<Vec<u8>> {
    convert_with(&python(), path, step, tessellation)
}

/// [`convert`] in the Python `python`.
pub fn convert_with(python: &str, path: &Path, step: &[u8], tessellation: &Tessellation) -> Result<Vec<u8>> {
    tessellation.validate().map_err(|reason| GeomError::format(path, reason))?;
    let fail = |reason: String| GeomError::format(path, reason);
    let mut child = Command::new(python)
        .arg("-c")
        .arg(CONVERTER)
        .arg(tessellation.relative.to_string())
        .arg(tessellation.angular.to_string())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => fail(format!(
                "reading STEP needs Python 3 with the package cascadio (OpenCASCADE), and '{python}' was not found: install Python 3, then `{INSTALL}` (or set {PYTHON_VAR} to a Python that has it)"
            )),
            _ => fail(format!("cannot run '{python}' to read STEP: {}", super::lowercase_first(&e.to_string()))),
        })?;
    // feed stdin from a thread while this one reads stdout, so that neither pipe fills up
    let mut stdin = child.stdin.take().expect("stdin is piped");
    let output = std::thread::scope(|s| {
        s.spawn(move || {
            // a converter that exits early closes its stdin; its exit code says why
            let _ = stdin.write_all(step);
        });
        child.wait_with_output()
    })
    .map_err(|e| fail(format!("the STEP converter ('{python}') failed: {}", super::lowercase_first(&e.to_string()))))?;
    let stderr = String::from_utf8_lossy(&output.stderr);
    match output.status.code() {
        Some(0) if output.stdout.starts_with(b"glTF") => Ok(output.stdout),
        Some(3) => Err(fail(format!(
            "reading STEP needs the Python package cascadio (OpenCASCADE), which '{python}' does not have: `{INSTALL}` (or set {PYTHON_VAR} to a Python that has it)"
        ))),
        Some(4) => Err(fail(format!("OpenCASCADE cannot read it as STEP: {}", occt_reason(&stderr)))),
        _ => Err(fail(format!("the STEP converter ('{python}') failed: {}", occt_reason(&stderr)))),
    }
}

/// The most telling line of what OpenCASCADE (or Python) printed: its first error, without the
/// terminal colours and asterisks.
fn occt_reason(stderr: &str) -> String {
    let clean: Vec<String> = stderr
        .lines()
        .map(|l| {
            let mut out = String::new();
            let mut chars = l.chars().peekable();
            while let Some(c) = chars.next() {
                if c == '\u{1b}' {
                    // skip an escape sequence up to its final letter
                    for d in chars.by_ref() {
                        if d.is_ascii_alphabetic() {
                            break;
                        }
                    }
                } else {
                    out.push(c);
                }
            }
            out.trim().trim_matches('*').trim().to_string()
        })
        .filter(|l| !l.is_empty())
        .collect();
    let first_error = clean.iter().find(|l| l.starts_with("ERR")).map(|l| {
        let l = l.trim_start_matches("ERR").trim();
        // "StepFile : Undefined Parsing: Line 6: ..." -> "Line 6: ..."
        l.split_once("Parsing:").map_or(l, |(_, rest)| rest.trim()).to_string()
    });
    let text = first_error.or_else(|| clean.last().cloned()).unwrap_or_else(|| "no message".into());
    super::lowercase_first(&text.split_whitespace().collect::<Vec<_>>().join(" "))
}

/// The assembly of a STEP file `path` (its bytes `step`) from the GLB `glb` cascadio made of
/// it: parts named by their instances, with their subassembly paths and faces; the file's
/// length unit ([`length_unit`]); up +Z unless `options` say otherwise. `options.unit` must not
/// be given (the file names its unit).
pub fn assemble(path: &Path, step: &[u8], glb: &[u8], options: &LoadOptions) -> Result<Assembly> {
    if let Some(unit) = &options.unit {
        return Err(GeomError::format(
            path,
            format!("a STEP file names its own unit; the unit '{}' does not apply (leave it out)", unit.name),
        ));
    }
    let (units, unit_warning) = match length_unit(step) {
        Ok(units) => (units, None),
        Err(warning) => (Units::metres(), Some(warning)),
    };
    // cascadio writes metres whatever the file's unit; the assembly reports in the file's
    let read = LoadOptions { unit: Some(Units::metres()), up: Some(options.up.unwrap_or(Axis::Z)), ..options.clone() };
    let mut assembly = gltf_read::read_gltf_bytes(path, glb, &read, &|file| {
        Err(std::io::Error::new(std::io::ErrorKind::NotFound, format!("{} is not part of a STEP conversion", file.display())))
    })?;
    assembly.units = units;
    assembly.warnings.extend(unit_warning);
    if options.up.is_none() {
        assembly.warnings.push("a STEP file has no up axis: +z is assumed, as most CAD draws; --up overrides".into());
    }
    for part in &mut assembly.parts {
        part.tessellation = Some(options.tessellation);
    }
    super::finish(assembly, options)
}

/// The length unit of a STEP file: the one its representation contexts assign
/// (`GLOBAL_UNIT_ASSIGNED_CONTEXT`), an SI unit with its prefix (`mm`, `m`, ...) or a
/// conversion-based one (`in`, `ft`, ...) with its factor. Several contexts that disagree give
/// the most used; an error (a warning for the caller, who then reports in metres) when the
/// file names none.
pub fn length_unit(step: &[u8]) -> std::result::Result<Units, String> {
    let text = String::from_utf8_lossy(step);
    let entities = entities(&text);
    let mut counts: Vec<(Units, usize)> = Vec::new();
    for body in entities.values().filter(|b| b.contains("GLOBAL_UNIT_ASSIGNED_CONTEXT")) {
        let Some(list) = body.split("GLOBAL_UNIT_ASSIGNED_CONTEXT").nth(1) else { continue };
        let list = list.split(')').next().unwrap_or("");
        for id in references(list) {
            if let Some(unit) = entities.get(&id).and_then(|b| length(b, &entities, 0)) {
                match counts.iter_mut().find(|(u, _)| *u == unit) {
                    Some((_, n)) => *n += 1,
                    None => counts.push((unit, 1)),
                }
            }
        }
    }
    counts.sort_by_key(|c| std::cmp::Reverse(c.1));
    counts.into_iter().next().map(|(u, _)| u).ok_or_else(|| "the STEP file names no length unit; lengths are reported in metres".into())
}

/// The entities of a STEP file's DATA section by id (`#12 = ...;` → 12 → `...`), strings and
/// comments respected.
fn entities(text: &str) -> HashMap<u64, String> {
    let mut map = HashMap::new();
    let data = text.find("DATA;").map_or(text, |i| &text[i + 5..]);
    let mut current = String::new();
    let mut chars = data.chars().peekable();
    let mut in_string = false;
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_string = !in_string;
                current.push(c);
            }
            '/' if !in_string && chars.peek() == Some(&'*') => {
                // a comment: skip to its end
                let mut last = ' ';
                for d in chars.by_ref() {
                    if last == '*' && d == '/' {
                        break;
                    }
                    last = d;
                }
            }
            ';' if !in_string => {
                let statement = std::mem::take(&mut current);
                if let Some((id, body)) = statement.trim().strip_prefix('#').and_then(|s| s.split_once('=')) {
                    if let Ok(id) = id.trim().parse::<u64>() {
                        map.insert(id, body.split_whitespace().collect::<Vec<_>>().join(" "));
                    }
                }
            }
            _ => current.push(c),
        }
    }
    map
}

/// The `#id`s named in `text`.
fn references(text: &str) -> Vec<u64> {
    text.split('#').skip(1).filter_map(|s| s.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok()).collect()
}

/// The length unit an entity body defines, if it is one.
fn length(body: &str, entities: &HashMap<u64, String>, depth: usize) -> Option<Units> {
    let upper = body.to_ascii_uppercase();
    if !upper.contains("LENGTH_UNIT") || depth > 4 {
        return None;
    }
    if let Some(si) = upper.split("SI_UNIT(").nth(1) {
        let args: Vec<&str> = si.split(')').next()?.split(',').map(str::trim).collect();
        let (prefix, name) = match args[..] {
            [prefix, name] => (prefix, name),
            _ => return None,
        };
        if name != ".METRE." {
            return None;
        }
        let (short, factor) = match prefix {
            "$" => ("m", 1.0),
            ".MILLI." => ("mm", 1e-3),
            ".CENTI." => ("cm", 1e-2),
            ".DECI." => ("dm", 1e-1),
            ".MICRO." => ("um", 1e-6),
            ".KILO." => ("km", 1e3),
            _ => return None,
        };
        return Some(Units { name: short.into(), metres: factor });
    }
    // CONVERSION_BASED_UNIT('INCH', #m) with #m = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4), #mm)
    let rest = body.split("CONVERSION_BASED_UNIT(").nth(1)?;
    let name = rest.split('\'').nth(1)?.trim().to_ascii_lowercase();
    // the measure: LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4), #mm) or (25.4, #mm)
    let measure = entities.get(references(rest).first()?)?;
    let args = measure.split("MEASURE_WITH_UNIT(").nth(1)?;
    let number = args.trim_start().trim_start_matches("LENGTH_MEASURE(").trim_start_matches("POSITIVE_LENGTH_MEASURE(");
    let value: f64 = number.split([')', ',']).next()?.trim().parse().ok()?;
    let base = references(args).into_iter().find_map(|id| length(entities.get(&id)?, entities, depth + 1))?;
    let metres = value * base.metres;
    if !(metres.is_finite() && metres > 0.0) {
        return None;
    }
    let short = match name.as_str() {
        "inch" | "in" => "in".to_string(),
        "foot" | "ft" => "ft".to_string(),
        _ => name,
    };
    Some(Units { name: short, metres })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn si_and_conversion_based_units() {
        let mm = b"DATA;\n#1 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#2 = ( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) );\n#3 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#9)) GLOBAL_UNIT_ASSIGNED_CONTEXT((#1,#2)) REPRESENTATION_CONTEXT('',''));\nENDSEC;";
        assert_eq!(length_unit(mm).unwrap(), Units { name: "mm".into(), metres: 1e-3 });
        let inch = b"DATA;\n#10 = ( CONVERSION_BASED_UNIT('INCH',#11) LENGTH_UNIT() NAMED_UNIT(#12) );\n#11 = LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#13);\n#12 = DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.);\n#13 = ( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) );\n#14 = ( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT(\n(#10)) REPRESENTATION_CONTEXT('Context #1','3D Context; with a semicolon'));\nENDSEC;";
        let u = length_unit(inch).unwrap();
        assert_eq!(u.name, "in");
        assert!((u.metres - 0.0254).abs() < 1e-12);
        // OpenCASCADE writes the measure without its type
        let bare = String::from_utf8_lossy(inch).replace("LENGTH_MEASURE(25.4)", "25.4");
        assert!((length_unit(bare.as_bytes()).unwrap().metres - 0.0254).abs() < 1e-12);
        assert!(length_unit(b"DATA;\n#1 = CARTESIAN_POINT('',(0.,0.,0.));\nENDSEC;").is_err());
    }

    #[test]
    fn opencascade_messages_lose_their_colours() {
        let stderr = "\u{1b}[31;1m**** ERR StepFile : Undefined Parsing: Line 6: Incorrect syntax: unexpected ';'    ****\n\u{1b}[0m\nError: Failed to read STEP data from memory\n";
        assert_eq!(occt_reason(stderr), "line 6: Incorrect syntax: unexpected ';'");
        assert_eq!(occt_reason("Error: Failed to read STEP data from memory\n"), "error: Failed to read STEP data from memory");
    }

    #[test]
    fn tessellation_tolerances_are_checked() {
        assert!(Tessellation::default().validate().is_ok());
        assert!(Tessellation { relative: 0.0, ..Tessellation::default() }.validate().is_err());
        assert!(Tessellation { angular: f64::NAN, ..Tessellation::default() }.validate().is_err());
    }
}
