//! STEP files: the conversion's errors (with stand-in Pythons, so no cascadio is needed) and
//! the assembly read from AS1's conversion (`tests/data/step/as1-oc-214.glb`, cascadio's GLB
//! with `TM_brep_faces` and the product tree).

use asp_geom::io::step::{assemble, convert_with, length_unit, INSTALL};
use asp_geom::io::{LoadOptions, Tessellation};
use asp_geom::math::Axis;
use asp_geom::surface::{Surface, SurfaceSource};
use asp_geom::Units;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/step");

fn data(name: &str) -> PathBuf {
    Path::new(DATA).join(name)
}

fn as1() -> asp_geom::Assembly {
    let step = std::fs::read(data("as1-oc-214.stp")).unwrap();
    let glb = std::fs::read(data("as1-oc-214.glb")).unwrap();
    assemble(&data("as1-oc-214.stp"), &step, &glb, &LoadOptions::default()).unwrap()
}

/// A stand-in for Python: a shell script that prints `stderr` and exits with `code`.
fn fake_python(dir: &Path, code: i32, stderr: &str) -> String {
    let path = dir.join(format!("python-{code}"));
    std::fs::write(&path, format!("#!/bin/sh\ncat > /dev/null\nprintf '%s\\n' '{stderr}' >&2\nexit {code}\n")).unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o755)).unwrap();
    path.display().to_string()
}

#[test]
fn conversion_failures_are_one_line_naming_the_file_and_the_cure() {
    let dir = tempfile::tempdir().unwrap();
    let model = Path::new("model.step");
    let t = Tessellation::default();
    let missing = convert_with(&fake_python(dir.path(), 3, "No module named 'cascadio'"), model, b"x", &t).unwrap_err().to_string();
    assert!(missing.starts_with("model.step: ") && missing.contains(INSTALL) && !missing.contains('\n'), "{missing}");
    let unreadable = convert_with(
        &fake_python(dir.path(), 4, "\u{1b}[31;1m**** ERR StepFile : Undefined Parsing: Line 2: Incorrect syntax ****"),
        model,
        b"x",
        &t,
    )
    .unwrap_err()
    .to_string();
    assert_eq!(unreadable, "model.step: OpenCASCADE cannot read it as STEP: line 2: Incorrect syntax");
    let absent = convert_with("/no/such/python3", model, b"x", &t).unwrap_err().to_string();
    assert!(absent.contains("was not found") && absent.contains(INSTALL) && absent.contains("ASP_PYTHON"), "{absent}");
    let bad = convert_with("python3", model, b"x", &Tessellation { relative: 2.0, ..t }).unwrap_err().to_string();
    assert!(bad.contains("between 0 and 1"), "{bad}");
}

#[test]
fn as1_keeps_its_names_tree_unit_and_exact_surfaces() {
    let a = as1();
    assert_eq!(a.len(), 18);
    assert_eq!(a.units, Units { name: "mm".into(), metres: 1e-3 });
    assert_eq!(a.up, Axis::Z, "STEP is taken as Z up");
    assert!(a.warnings.iter().any(|w| w.contains("+z is assumed")));
    let names: Vec<&str> = a.parts.iter().map(|p| p.name.as_str()).collect();
    // the file's instance names; two instances of one bolt are told apart by their subassemblies
    for name in
        ["nut_1", "nut_2", "rod_1", "plate_1", "l-bracket-assembly_1/l-bracket_1", "l-bracket-assembly_2/nut-bolt-assembly_3/bolt_1"]
    {
        assert!(names.contains(&name), "{name} not in {names:?}");
    }
    let bolt = &a.parts[a.part_index("l-bracket-assembly_2/nut-bolt-assembly_3/bolt_1").unwrap()];
    assert_eq!(bolt.path, ["as1", "l-bracket-assembly_2", "nut-bolt-assembly_3"]);
    assert_eq!(a.parts.iter().filter(|p| p.path.get(1).is_some_and(|s| s.starts_with("l-bracket-assembly"))).count(), 14);
    // every triangle has its face; AS1's planes are exact, its round faces b-splines (no surface)
    for p in &a.parts {
        let faces = p.faces.as_ref().expect("faces");
        assert!(faces.fits(p.mesh.triangles.len()), "{}", p.name);
        assert!(faces.faces.iter().all(|f| f.source == SurfaceSource::Exact));
        assert_eq!(p.tessellation, Some(Tessellation::default()));
    }
    let plate = &a.parts[a.part_index("plate_1").unwrap()];
    let faces = plate.faces.as_ref().unwrap();
    let top = faces.faces.iter().find_map(|f| match f.surface {
        Some(Surface::Plane { point, normal }) if normal.z > 0.99 => Some(point.z),
        _ => None,
    });
    assert!(top.is_some_and(|z| (z - 0.02).abs() < 1e-6), "the plate's top at 20 mm: {top:?}");
    // each triangle lies on its plane
    for (t, &f) in plate.mesh.triangles.iter().zip(&faces.triangle_face) {
        if let Some(s @ Surface::Plane { .. }) = faces.faces[f as usize].surface {
            for &v in t {
                assert!(s.distance(plate.mesh.vertices[v as usize]) < 1e-6);
            }
        }
    }
}

#[test]
fn a_step_file_names_its_unit_and_refuses_another() {
    let step = std::fs::read(data("inch_bracket.step")).unwrap();
    assert_eq!(length_unit(&step).unwrap().name, "in");
    assert_eq!(length_unit(&std::fs::read(data("shaft_bearings.step")).unwrap()).unwrap().name, "mm");
    let glb = std::fs::read(data("as1-oc-214.glb")).unwrap();
    let options = LoadOptions { unit: Units::parse("in"), ..LoadOptions::default() };
    let e = assemble(&data("as1-oc-214.stp"), &step, &glb, &options).unwrap_err().to_string();
    assert!(e.contains("names its own unit") && e.contains("as1-oc-214.stp"), "{e}");
    let up = LoadOptions { up: Some(Axis::Y), ..LoadOptions::default() };
    let a = assemble(&data("as1-oc-214.stp"), &std::fs::read(data("as1-oc-214.stp")).unwrap(), &glb, &up).unwrap();
    assert_eq!(a.up, Axis::Y);
    assert!(!a.warnings.iter().any(|w| w.contains("is assumed")));
}

#[test]
fn a_gltf_with_brep_faces_loads_its_faces_and_tree() {
    // cascadio's GLB read as any glTF (metres, +y unless told)
    let a = asp_geom::io::load(&data("as1-oc-214.glb"), &LoadOptions::default()).unwrap();
    assert_eq!((a.len(), a.units.name.as_str(), a.up), (18, "m", Axis::Y));
    assert!(a.parts.iter().all(|p| p.faces.as_ref().is_some_and(|f| f.fits(p.mesh.triangles.len())) && p.tessellation.is_none()));
    assert!(a.parts.iter().any(|p| p.name == "l-bracket-assembly_1/nut-bolt-assembly_1/bolt_1"));
    // the shaft's bearings: cylinders with their radii, in metres, about the z axis
    let b = asp_geom::io::load(&data("shaft_bearings.glb"), &LoadOptions::default()).unwrap();
    let race = &b.parts[b.part_index("bearing_1/outer_race").unwrap()];
    assert_eq!(race.path, ["shaft_bearings", "spindle", "bearing_1"]);
    let radii: Vec<f32> = race
        .faces
        .as_ref()
        .unwrap()
        .faces
        .iter()
        .filter_map(|f| match f.surface {
            Some(Surface::Cylinder { radius, axis, .. }) if axis.z.abs() > 0.999 => Some(radius),
            _ => None,
        })
        .collect();
    assert!(radii.iter().any(|r| (r - 0.016).abs() < 1e-7) && radii.iter().any(|r| (r - 0.011).abs() < 1e-7), "{radii:?}");
}
