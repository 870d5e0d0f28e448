//! URDF loading: errors are one line naming the file; chains, fingers and shapes come through.

use std::path::Path;

use asp_robot::{ChainSpec, JointKind, Robot, RobotFiles, ShapeKind};

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> std::path::PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn one_line_naming(err: &asp_robot::RobotError, path: &Path) {
    let s = err.to_string();
    assert!(!s.contains('\n'), "not one line: {s}");
    assert!(s.contains(&path.display().to_string()), "does not name the file: {s}");
}

#[test]
fn missing_file_is_one_line_naming_it() {
    let p = Path::new("/nonexistent/arm.urdf");
    let e = Robot::from_urdf_file(p).unwrap_err();
    one_line_naming(&e, p);
}

#[test]
fn malformed_xml_is_one_line_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, "bad.urdf", "<robot name=\"x\"><link name=\"a\"></robot>\n<<<");
    let e = Robot::from_urdf_file(&p).unwrap_err();
    one_line_naming(&e, &p);
}

#[test]
fn a_joint_naming_an_unknown_link_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        &dir,
        "unknown.urdf",
        r#"<robot name="x"><link name="a"/><link name="b"/>
        <joint name="j1" type="revolute"><parent link="a"/><child link="ghost"/><axis xyz="0 0 1"/>
        <limit lower="-1" upper="1" effort="1" velocity="1"/></joint></robot>"#,
    );
    let e = Robot::from_urdf_file(&p).unwrap_err();
    one_line_naming(&e, &p);
    let s = e.to_string();
    assert!(s.contains("j1") && s.contains("ghost"), "{s}");
}

#[test]
fn the_shipped_urdf_text_loads_from_a_file_too() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(&dir, "panda.urdf", asp_robot::PANDA_URDF);
    let r = Robot::from_urdf_file(&p).unwrap();
    assert_eq!(r.dof(), 7);
    assert_eq!(r.movable_joints().filter(|j| j.kind == JointKind::Revolute).count(), 7);
    // every arm link has a shape, the fingers are boxes
    assert!(r.links().iter().filter(|l| l.name.starts_with("panda_link") && l.name != "panda_link8").all(|l| !l.shapes.is_empty()));
    assert!(r.fingers().iter().all(|f| f.link.shapes.iter().all(|s| matches!(s.kind, ShapeKind::Box { .. }))));
    let shapes = r.collision_shapes(&r.mid_configuration(), 0.04);
    assert!(shapes.len() >= 10);
}

#[test]
fn a_small_arm_with_prismatic_and_mesh_geometry() {
    let dir = tempfile::tempdir().unwrap();
    let p = write(
        &dir,
        "small.urdf",
        r#"<robot name="small">
          <link name="base"><collision><geometry><mesh filename="base.stl"/></geometry></collision></link>
          <link name="l1"><collision><origin xyz="0 0 0.1"/><geometry><cylinder radius="0.02" length="0.2"/></geometry></collision></link>
          <link name="l2"><collision><geometry><sphere radius="0.03"/></geometry></collision></link>
          <link name="tool0"/>
          <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
          <joint name="j2" type="prismatic"><origin xyz="0 0 0.2"/><parent link="l1"/><child link="l2"/><axis xyz="1 0 0"/>
            <limit lower="0" upper="0.3" effort="1" velocity="1"/></joint>
          <joint name="j3" type="fixed"><origin xyz="0 0 0.05"/><parent link="l2"/><child link="tool0"/></joint>
        </robot>"#,
    );
    // the mesh a link names must exist beside the file
    one_line_naming(&Robot::from_urdf_file(&p).unwrap_err(), &p);
    std::fs::write(dir.path().join("base.stl"), "solid x\nendsolid x\n").unwrap();
    let r = Robot::from_urdf_file(&p).unwrap();
    assert_eq!(r.dof(), 2);
    assert_eq!(r.links().last().unwrap().name, "tool0");
    assert_eq!(r.notes.len(), 1, "{:?}", r.notes);
    let t = r.tool_pose(&[std::f64::consts::FRAC_PI_2, 0.2]);
    assert!((t.translation - asp_geom::math::Vec3::new(0.0, 0.2, 0.25)).length() < 1e-5, "{:?}", t);
    // naming a tip that is not below the base is a one-line error
    let e = Robot::from_urdf_file_with(&p, &ChainSpec { base_link: Some("l2".into()), tip_link: Some("l1".into()) }).unwrap_err();
    one_line_naming(&e, &p);
}

/// A one-joint arm whose base link's collision mesh is `mesh`.
fn arm_with_mesh(mesh: &str) -> String {
    format!(
        r#"<robot name="m">
          <link name="base"><collision><geometry><mesh filename="{mesh}"/></geometry></collision></link>
          <link name="tool0"/>
          <joint name="j1" type="revolute"><parent link="base"/><child link="tool0"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        </robot>"#
    )
}

#[test]
fn meshes_stay_inside_the_robot_folder_or_a_named_package() {
    let dir = tempfile::tempdir().unwrap();
    let robot = dir.path().join("robot");
    let pkg = dir.path().join("pkg");
    std::fs::create_dir_all(robot.join("meshes")).unwrap();
    std::fs::create_dir_all(pkg.join("meshes")).unwrap();
    std::fs::write(robot.join("meshes/base.stl"), "solid x\nendsolid x\n").unwrap();
    std::fs::write(pkg.join("meshes/base.stl"), "solid x\nendsolid x\n").unwrap();
    std::fs::write(dir.path().join("secret.stl"), "solid x\nendsolid x\n").unwrap();
    let secret = dir.path().join("secret.stl").display().to_string();
    let load = |name: &str, mesh: &str, files: &RobotFiles| {
        let p = robot.join(name);
        std::fs::write(&p, arm_with_mesh(mesh)).unwrap();
        (Robot::from_urdf_file_checked(&p, &ChainSpec::default(), files), p)
    };
    let none = RobotFiles::default();
    let with_pkg = RobotFiles { package_paths: vec![("pkg".into(), pkg.clone())], allow_outside_files: false };
    for (name, mesh, files, cause) in [
        ("abs.urdf", secret.as_str(), &none, "is an absolute path"),
        ("up.urdf", "../secret.stl", &none, "points outside"),
        ("pkg_up.urdf", "package://pkg/../secret.stl", &with_pkg, "points outside"),
        ("unknown.urdf", "package://pkg/meshes/base.stl", &none, "--package-path pkg=DIR"),
        ("missing.urdf", "meshes/gone.stl", &none, "is missing"),
    ] {
        let (result, p) = load(name, mesh, files);
        let e = result.unwrap_err();
        one_line_naming(&e, &p);
        let s = e.to_string();
        assert!(s.contains(cause) && s.contains(mesh) && s.contains("link 'base'"), "{s}");
        if cause == "points outside" || cause == "is an absolute path" {
            assert!(s.contains("--allow-outside-files"), "{s}");
        }
    }
    assert!(load("ok.urdf", "meshes/base.stl", &none).0.is_ok());
    assert!(load("pkg.urdf", "package://pkg/meshes/base.stl", &with_pkg).0.is_ok());
    let allow = RobotFiles { allow_outside_files: true, ..RobotFiles::default() };
    assert!(load("abs_allowed.urdf", &secret, &allow).0.is_ok());
}

#[test]
fn robots_that_cannot_work_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    // no gripper: loads (asp robot check shows it) but cannot plan
    let p = write(&dir, "nogripper.urdf", &arm_with_mesh("m.stl"));
    std::fs::write(dir.path().join("m.stl"), "solid x\nendsolid x\n").unwrap();
    let e = Robot::from_urdf_file(&p).unwrap().check_can_grasp().unwrap_err();
    one_line_naming(&e, &p);
    assert!(e.to_string().contains("no gripper below tool link 'tool0'"), "{e}");
    Robot::panda().check_can_grasp().unwrap();
    // inverted limits, a loop of links, a missing link
    let inverted = arm_with_mesh("m.stl").replace(r#"lower="-1" upper="1""#, r#"lower="1" upper="-1""#);
    let looped = r#"<robot name="l"><link name="a"/><link name="b"/>
        <joint name="j1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        <joint name="j2" type="revolute"><parent link="b"/><child link="a"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
        </robot>"#;
    for (name, text, cause) in [("inverted.urdf", inverted.as_str(), "need finite lower"), ("loop.urdf", looped, "root link")] {
        let p = write(&dir, name, text);
        let e = Robot::from_urdf_file(&p).unwrap_err();
        one_line_naming(&e, &p);
        assert!(e.to_string().contains(cause), "{e}");
    }
}
