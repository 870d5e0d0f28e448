//! A robot arm loaded from URDF: the serial chain from a base link to a tool link, its joints and
//! limits, forward kinematics, the collision shapes of its links and its parallel gripper.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use asp_geom::math::{Pose, Vec3};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion, Vector3};

use crate::convert::{pose_from_na, pose_to_na};
use crate::error::{one_line, Result, RobotError};
use crate::shape::{LinkShape, ShapeKind};

/// How a joint moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rotates about its axis (URDF `revolute`, or `continuous` with limits ±π).
    Revolute,
    /// Slides along its axis.
    Prismatic,
    /// Does not move.
    Fixed,
}

/// One joint of the chain.
#[derive(Clone, Debug)]
pub struct Joint {
    /// The URDF name.
    pub name: String,
    /// How it moves.
    pub kind: JointKind,
    /// Lower and upper limit (radians or metres; `(0, 0)` for fixed joints).
    pub limits: (f64, f64),
    /// The joint frame in the parent link's frame (URDF `origin`).
    pub(crate) origin: Isometry3<f64>,
    /// The unit axis in the joint frame.
    pub(crate) axis: Vector3<f64>,
}

impl Joint {
    /// The joint's axis in its own frame.
    pub fn axis(&self) -> Vec3 {
        crate::convert::vec_from_na(&self.axis)
    }

    /// The joint frame in the parent link's frame.
    pub fn origin(&self) -> Pose {
        pose_from_na(&self.origin)
    }

    /// The transform this joint adds at value `q`.
    pub(crate) fn motion(&self, q: f64) -> Isometry3<f64> {
        match self.kind {
            JointKind::Revolute => Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_unchecked(self.axis), q),
            ),
            JointKind::Prismatic => Isometry3::from_parts(Translation3::from(self.axis * q), UnitQuaternion::identity()),
            JointKind::Fixed => Isometry3::identity(),
        }
    }
}

/// A link of the chain with its collision shapes.
#[derive(Clone, Debug)]
pub struct Link {
    /// The URDF name.
    pub name: String,
    /// The primitive collision shapes, in the link frame.
    pub shapes: Vec<LinkShape>,
}

/// One finger of the parallel gripper: a prismatic joint hanging off the tool end of the chain.
#[derive(Clone, Debug)]
pub struct Finger {
    /// The finger's joint.
    pub joint: Joint,
    /// The finger link.
    pub link: Link,
    /// The joint frame in the tool-centre frame.
    pub(crate) origin_in_tool: Isometry3<f64>,
}

/// Which links bound the kinematic chain. `None` picks a default: the root link as base; as tip a
/// link whose name ends in `tcp` or `tool0`, else the leaf at the end of the longest chain.
#[derive(Clone, Debug, Default)]
pub struct ChainSpec {
    /// The base link.
    pub base_link: Option<String>,
    /// The tool-centre link (IK places this frame).
    pub tip_link: Option<String>,
}

/// Where the files a URDF names (its meshes) may lie: beside the URDF, in the folders of the
/// ROS packages the user names (`package://NAME/...` → `DIR/...`), or anywhere when allowed.
#[derive(Clone, Debug, Default)]
pub struct RobotFiles {
    /// `NAME=DIR` pairs resolving `package://NAME/` (`--package-path`).
    pub package_paths: Vec<(String, PathBuf)>,
    /// Accept absolute mesh paths and paths that leave their folder (`--allow-outside-files`).
    pub allow_outside_files: bool,
}

impl RobotFiles {
    /// Parses a `NAME=DIR` package path.
    pub fn parse_package_path(text: &str) -> std::result::Result<(String, PathBuf), String> {
        match text.split_once('=') {
            Some((name, dir)) if !name.is_empty() && !dir.is_empty() => Ok((name.to_string(), PathBuf::from(dir))),
            _ => Err(format!("--package-path '{text}' is not NAME=DIR")),
        }
    }
}

/// Checks every mesh a link names (collision and visual): resolved inside the URDF's folder or
/// the named package's folder, and present.
fn check_meshes(urdf: &urdf_rs::Robot, path: &Path, files: &RobotFiles) -> Result<()> {
    let folder = path.parent().unwrap_or(Path::new(""));
    let err = |message: String| RobotError::Reference { path: path.to_path_buf(), message };
    for link in &urdf.links {
        let geometries = link.collision.iter().map(|c| &c.geometry).chain(link.visual.iter().map(|v| &v.geometry));
        for geometry in geometries {
            let urdf_rs::Geometry::Mesh { filename, .. } = geometry else { continue };
            let what = format!("link '{}': mesh", link.name);
            let (base, reference): (&Path, PathBuf) = if let Some(rest) = filename.strip_prefix("package://") {
                let (package, inner) = rest.split_once('/').unwrap_or((rest, ""));
                let Some((_, dir)) = files.package_paths.iter().find(|(name, _)| name == package) else {
                    return Err(err(format!(
                        "{what} '{filename}' is in package '{package}', which is not known (give --package-path {package}=DIR)"
                    )));
                };
                (dir.as_path(), PathBuf::from(inner))
            } else if let Some(rest) = filename.strip_prefix("file://") {
                (folder, PathBuf::from(rest))
            } else {
                (folder, PathBuf::from(filename))
            };
            let resolved = asp_geom::io::resolve_inside(base, &reference, &[], files.allow_outside_files)
                .map_err(|refused| err(refused.describe(&what, filename)))?;
            if !resolved.is_file() {
                return Err(err(format!("{what} '{filename}' is missing (looked for {})", resolved.display())));
            }
        }
    }
    Ok(())
}

/// A serial-chain robot arm with a parallel gripper.
#[derive(Clone, Debug)]
pub struct Robot {
    /// The URDF robot name.
    pub name: String,
    /// The file it came from (or a label for embedded robots).
    pub source: PathBuf,
    /// Links from base (index 0) to tool centre (last); link `i + 1` is the child of joint `i`.
    pub(crate) links: Vec<Link>,
    /// The joints of the chain, fixed ones included.
    pub(crate) joints: Vec<Joint>,
    /// Indices into `joints` of the movable joints, in chain order.
    pub(crate) movable: Vec<usize>,
    /// The fingers of the gripper (possibly none).
    pub(crate) fingers: Vec<Finger>,
    /// The base link's pose in the world.
    pub(crate) base: Isometry3<f64>,
    /// Things in the file that were not used (mesh collision geometry, side branches).
    pub notes: Vec<String>,
}

fn iso(p: &urdf_rs::Pose) -> Isometry3<f64> {
    let [x, y, z] = p.xyz.0;
    let [r, pi, ya] = p.rpy.0;
    Isometry3::from_parts(Translation3::new(x, y, z), Rotation3::from_euler_angles(r, pi, ya).into())
}

fn shapes_of(link: &urdf_rs::Link, notes: &mut Vec<String>) -> Vec<LinkShape> {
    let mut out = Vec::new();
    for c in &link.collision {
        let kind = match &c.geometry {
            urdf_rs::Geometry::Box { size } => {
                ShapeKind::Box { half_extents: Vec3::new(size.0[0] as f32, size.0[1] as f32, size.0[2] as f32) * 0.5 }
            }
            urdf_rs::Geometry::Cylinder { radius, length } => {
                ShapeKind::Cylinder { radius: *radius as f32, half_length: *length as f32 * 0.5 }
            }
            urdf_rs::Geometry::Capsule { radius, length } => {
                ShapeKind::Capsule { radius: *radius as f32, half_length: *length as f32 * 0.5 }
            }
            urdf_rs::Geometry::Sphere { radius } => ShapeKind::Sphere { radius: *radius as f32 },
            urdf_rs::Geometry::Mesh { filename, .. } => {
                notes.push(format!(
                    "link '{}': mesh collision geometry '{filename}' is not used (only box, cylinder, capsule and sphere are)",
                    link.name
                ));
                continue;
            }
        };
        out.push(LinkShape { local_pose: pose_from_na(&iso(&c.origin)), kind });
    }
    out
}

fn joint_of(j: &urdf_rs::Joint, path: &Path) -> Result<Joint> {
    let kind = match j.joint_type {
        urdf_rs::JointType::Revolute | urdf_rs::JointType::Continuous => JointKind::Revolute,
        urdf_rs::JointType::Prismatic => JointKind::Prismatic,
        urdf_rs::JointType::Fixed => JointKind::Fixed,
        ref other => {
            return Err(RobotError::chain(
                path.to_path_buf(),
                format!("joint '{}' has type {other:?}; only revolute, continuous, prismatic and fixed are supported", j.name),
            ))
        }
    };
    let limits = match (kind, &j.joint_type) {
        (JointKind::Fixed, _) => (0.0, 0.0),
        (_, urdf_rs::JointType::Continuous) => (-std::f64::consts::PI, std::f64::consts::PI),
        _ => (j.limit.lower, j.limit.upper),
    };
    if kind != JointKind::Fixed && !(limits.0.is_finite() && limits.1.is_finite() && limits.0 <= limits.1) {
        return Err(RobotError::chain(
            path.to_path_buf(),
            format!("joint '{}' has limits [{}, {}]; need finite lower ≤ upper", j.name, limits.0, limits.1),
        ));
    }
    let a = Vector3::from(j.axis.xyz.0);
    if kind != JointKind::Fixed && !(a.norm() > 1e-9 && a.iter().all(|v| v.is_finite())) {
        return Err(RobotError::chain(path.to_path_buf(), format!("joint '{}' has a zero or non-finite axis", j.name)));
    }
    let axis = if a.norm() > 1e-9 { a.normalize() } else { Vector3::z() };
    Ok(Joint { name: j.name.clone(), kind, limits, origin: iso(&j.origin), axis })
}

impl Robot {
    /// The default robot: the Franka-Panda-like arm shipped in `robots/panda.urdf` (see that file
    /// for its modified-DH parameters and how they map onto URDF joints).
    pub fn panda() -> Robot {
        Robot::from_urdf_str(crate::PANDA_URDF, Path::new("<builtin panda>"), &ChainSpec::default())
            .expect("the shipped panda.urdf loads (tested)")
    }

    /// Loads a URDF file with the default chain ends.
    pub fn from_urdf_file(path: &Path) -> Result<Robot> {
        Robot::from_urdf_file_with(path, &ChainSpec::default())
    }

    /// Loads a URDF file with the given chain ends (meshes beside the file only).
    pub fn from_urdf_file_with(path: &Path, spec: &ChainSpec) -> Result<Robot> {
        Robot::from_urdf_file_checked(path, spec, &RobotFiles::default())
    }

    /// Loads a URDF file with the given chain ends, its meshes resolved by `files`.
    pub fn from_urdf_file_checked(path: &Path, spec: &ChainSpec, files: &RobotFiles) -> Result<Robot> {
        let text =
            std::fs::read_to_string(path).map_err(|e| RobotError::Read { path: path.to_path_buf(), message: one_line(&e.to_string()) })?;
        Robot::from_urdf_str_with(&text, path, spec, files)
    }

    /// Parses URDF text; `path` names it in error messages and locates its meshes.
    pub fn from_urdf_str(text: &str, path: &Path, spec: &ChainSpec) -> Result<Robot> {
        Robot::from_urdf_str_with(text, path, spec, &RobotFiles::default())
    }

    /// [`Robot::from_urdf_str`] with the meshes resolved by `files`.
    pub fn from_urdf_str_with(text: &str, path: &Path, spec: &ChainSpec, files: &RobotFiles) -> Result<Robot> {
        let p = || path.to_path_buf();
        let urdf = urdf_rs::read_from_string(text).map_err(|e| RobotError::parse(p(), e))?;
        let max_links = asp_geom::io::DEFAULT_MAX_PARTS;
        if urdf.links.len() > max_links || urdf.joints.len() > max_links {
            return Err(RobotError::chain(p(), format!("more than {max_links} links or joints")));
        }
        check_meshes(&urdf, path, files)?;
        let link_index: HashMap<&str, usize> = urdf.links.iter().enumerate().map(|(i, l)| (l.name.as_str(), i)).collect();
        if link_index.len() != urdf.links.len() {
            return Err(RobotError::chain(p(), "two links share a name"));
        }
        // parent joint of every link
        let mut parent_joint: HashMap<&str, usize> = HashMap::new();
        for (ji, j) in urdf.joints.iter().enumerate() {
            for (role, link) in [("parent", &j.parent.link), ("child", &j.child.link)] {
                if !link_index.contains_key(link.as_str()) {
                    return Err(RobotError::UnknownLink { path: p(), joint: j.name.clone(), role, link: link.clone() });
                }
            }
            if parent_joint.insert(j.child.link.as_str(), ji).is_some() {
                return Err(RobotError::chain(p(), format!("link '{}' is the child of two joints", j.child.link)));
            }
        }
        let roots: Vec<&str> = urdf.links.iter().map(|l| l.name.as_str()).filter(|n| !parent_joint.contains_key(n)).collect();
        let base = match &spec.base_link {
            Some(b) if link_index.contains_key(b.as_str()) => b.clone(),
            Some(b) => return Err(RobotError::chain(p(), format!("no base link named '{b}'"))),
            None if roots.len() == 1 => roots[0].to_string(),
            None => return Err(RobotError::chain(p(), format!("expected one root link, found {}", roots.len()))),
        };
        // the chain from a link up to base, as joint indices from base to the link
        let chain_to = |tip: &str| -> Option<Vec<usize>> {
            let mut js = Vec::new();
            let mut cur = tip;
            let mut guard = 0;
            while cur != base {
                let ji = *parent_joint.get(cur)?;
                js.push(ji);
                cur = urdf.joints[ji].parent.link.as_str();
                guard += 1;
                if guard > urdf.joints.len() {
                    return None;
                }
            }
            js.reverse();
            Some(js)
        };
        let tip = match &spec.tip_link {
            Some(t) if link_index.contains_key(t.as_str()) => t.clone(),
            Some(t) => return Err(RobotError::chain(p(), format!("no tip link named '{t}'"))),
            None => {
                let named = urdf.links.iter().map(|l| l.name.as_str()).find(|n| {
                    let l = n.to_ascii_lowercase();
                    (l.ends_with("tcp") || l.ends_with("tool0")) && chain_to(n).is_some()
                });
                match named {
                    Some(n) => n.to_string(),
                    None => {
                        let has_child: std::collections::HashSet<&str> = urdf.joints.iter().map(|j| j.parent.link.as_str()).collect();
                        let mut best: Option<(usize, &str)> = None;
                        for l in urdf.links.iter().map(|l| l.name.as_str()).filter(|n| !has_child.contains(n)) {
                            if let Some(c) = chain_to(l) {
                                let movable = c.iter().filter(|&&j| urdf.joints[j].joint_type != urdf_rs::JointType::Fixed).count();
                                if best.is_none_or(|(m, _)| movable > m) {
                                    best = Some((movable, l));
                                }
                            }
                        }
                        best.map(|(_, l)| l.to_string()).ok_or_else(|| RobotError::chain(p(), "no tip link below the base"))?
                    }
                }
            }
        };
        let chain = chain_to(&tip).ok_or_else(|| RobotError::chain(p(), format!("link '{tip}' does not hang below base link '{base}'")))?;
        let mut notes = Vec::new();
        let mut links = vec![Link { name: base.clone(), shapes: shapes_of(&urdf.links[link_index[base.as_str()]], &mut notes) }];
        let mut joints = Vec::new();
        for &ji in &chain {
            let j = &urdf.joints[ji];
            joints.push(joint_of(j, path)?);
            let l = &urdf.links[link_index[j.child.link.as_str()]];
            links.push(Link { name: l.name.clone(), shapes: shapes_of(l, &mut notes) });
        }
        let movable: Vec<usize> = (0..joints.len()).filter(|&i| joints[i].kind != JointKind::Fixed).collect();
        if movable.is_empty() {
            return Err(RobotError::chain(p(), format!("the chain from '{base}' to '{tip}' has no movable joint")));
        }
        // fingers: prismatic joints hanging off links after the last movable joint
        let first_tool_link = movable.last().map_or(0, |&m| m + 1);
        let mut fingers = Vec::new();
        let chain_links: Vec<&str> = links.iter().map(|l| l.name.as_str()).collect();
        // pose of every chain link after the last movable joint, in the tool-centre frame
        let mut in_link: Vec<Isometry3<f64>> = vec![Isometry3::identity(); links.len()];
        for i in first_tool_link + 1..links.len() {
            in_link[i] = in_link[i - 1] * joints[i - 1].origin;
        }
        let tool_in_first = in_link[links.len() - 1];
        for j in &urdf.joints {
            let Some(pi) = chain_links.iter().position(|&n| n == j.parent.link) else { continue };
            if chain_links.contains(&j.child.link.as_str()) {
                continue;
            }
            if j.joint_type == urdf_rs::JointType::Prismatic && pi >= first_tool_link {
                let joint = joint_of(j, path)?;
                let origin_in_tool = tool_in_first.inverse() * in_link[pi] * joint.origin;
                let l = &urdf.links[link_index[j.child.link.as_str()]];
                fingers.push(Finger { joint, link: Link { name: l.name.clone(), shapes: shapes_of(l, &mut notes) }, origin_in_tool });
            } else {
                notes.push(format!("joint '{}' branches off the chain and is not used", j.name));
            }
        }
        Ok(Robot {
            name: urdf.name.clone(),
            source: path.to_path_buf(),
            links,
            joints,
            movable,
            fingers,
            base: Isometry3::identity(),
            notes,
        })
    }

    /// Checks that the robot can carry a part out at all: it needs a parallel gripper (prismatic
    /// finger joints after the last arm joint) that opens. Called before planning with it.
    pub fn check_can_grasp(&self) -> Result<()> {
        let tip = self.links.last().map_or("", |l| l.name.as_str());
        if self.fingers.is_empty() {
            return Err(RobotError::Unusable {
                path: self.source.clone(),
                message: format!(
                    "no gripper below tool link '{tip}' (asp needs prismatic finger joints after the last arm joint to hold a part); add fingers or name another tool link"
                ),
            });
        }
        if self.max_opening() <= 0.0 {
            return Err(RobotError::Unusable {
                path: self.source.clone(),
                message: format!("the gripper below tool link '{tip}' does not open (its finger joints have no travel)"),
            });
        }
        Ok(())
    }

    /// The number of movable joints (degrees of freedom of the arm).
    pub fn dof(&self) -> usize {
        self.movable.len()
    }

    /// All joints of the chain from base to tool centre, fixed ones included.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The movable joints, in the order of a configuration vector.
    pub fn movable_joints(&self) -> impl Iterator<Item = &Joint> {
        self.movable.iter().map(|&i| &self.joints[i])
    }

    /// The limits of the movable joints, in configuration order.
    pub fn limits(&self) -> Vec<(f64, f64)> {
        self.movable_joints().map(|j| j.limits).collect()
    }

    /// The links of the chain from base (first) to tool centre (last).
    pub fn links(&self) -> &[Link] {
        &self.links
    }

    /// The gripper's fingers.
    pub fn fingers(&self) -> &[Finger] {
        &self.fingers
    }

    /// The widest opening of the gripper (sum of the fingers' travel), metres; 0 without fingers.
    pub fn max_opening(&self) -> f32 {
        self.fingers.iter().map(|f| (f.joint.limits.1 - f.joint.limits.0) as f32).sum()
    }

    /// The base link's pose in the world.
    pub fn base_pose(&self) -> Pose {
        pose_from_na(&self.base)
    }

    /// Places the base link at `pose` (world frame).
    pub fn set_base_pose(&mut self, pose: Pose) {
        self.base = pose_to_na(&pose);
    }

    /// The same robot with its base at `pose`.
    pub fn with_base_pose(mut self, pose: Pose) -> Robot {
        self.set_base_pose(pose);
        self
    }

    /// True when `q` has one finite value per movable joint, each within its limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.len() == self.dof() && self.movable_joints().zip(q).all(|(j, &v)| v.is_finite() && v >= j.limits.0 && v <= j.limits.1)
    }

    /// The configuration halfway between every joint's limits.
    pub fn mid_configuration(&self) -> Vec<f64> {
        self.limits().iter().map(|(l, u)| 0.5 * (l + u)).collect()
    }

    /// World frames of all chain links at `q` (nalgebra). Panics if `q.len() != dof()`.
    pub(crate) fn link_frames(&self, q: &[f64]) -> Vec<Isometry3<f64>> {
        assert_eq!(q.len(), self.dof(), "configuration length");
        let mut out = Vec::with_capacity(self.links.len());
        let mut t = self.base;
        out.push(t);
        let mut k = 0;
        for j in &self.joints {
            t *= j.origin;
            if j.kind != JointKind::Fixed {
                t *= j.motion(q[k]);
                k += 1;
            }
            out.push(t);
        }
        out
    }

    /// The world pose of every chain link at configuration `q` (base first, tool centre last).
    /// Panics if `q.len() != dof()`.
    pub fn link_poses(&self, q: &[f64]) -> Vec<Pose> {
        self.link_frames(q).iter().map(pose_from_na).collect()
    }

    /// The tool centre's world pose at `q` (forward kinematics). Panics if `q.len() != dof()`.
    pub fn tool_pose(&self, q: &[f64]) -> Pose {
        pose_from_na(self.link_frames(q).last().expect("a chain has links"))
    }

    /// Index of the first link that moves rigidly with the tool centre (after the last movable joint).
    pub(crate) fn first_tool_link(&self) -> usize {
        self.movable.last().map_or(0, |&m| m + 1)
    }

    /// The arm's collision shapes at `q`: each link shape with its link's world pose, for the
    /// links up to and including the last movable joint's child. Use [`LinkShape::world`] for parry.
    pub fn arm_shapes(&self, q: &[f64]) -> Vec<(Pose, LinkShape)> {
        let frames = self.link_frames(q);
        let end = self.first_tool_link();
        let mut out = Vec::new();
        for (i, l) in self.links.iter().enumerate().take(end) {
            let pose = pose_from_na(&frames[i]);
            out.extend(l.shapes.iter().map(|s| (pose, *s)));
        }
        out
    }

    /// The gripper's collision shapes (the links rigid with the tool centre and the fingers set to
    /// `opening`, clamped to `0..=max_opening`), with poses in the world for a tool centre at `tool`.
    pub fn gripper_shapes(&self, tool: &Pose, opening: f32) -> Vec<(Pose, LinkShape)> {
        let tool = pose_to_na(tool);
        let n = self.links.len();
        let start = self.first_tool_link();
        let mut out = Vec::new();
        // chain links rigid with the tool: walk back from the tool centre
        let mut t = tool;
        for i in (start..n).rev() {
            let pose = pose_from_na(&t);
            out.extend(self.links[i].shapes.iter().map(|s| (pose, *s)));
            if i > start {
                t *= self.joints[i - 1].origin.inverse();
            }
        }
        let max = self.max_opening().max(f32::MIN_POSITIVE) as f64;
        let frac = (opening as f64 / max).clamp(0.0, 1.0);
        for f in &self.fingers {
            let (lo, hi) = f.joint.limits;
            let q = lo + frac * (hi - lo);
            let pose = pose_from_na(&(tool * f.origin_in_tool * f.joint.motion(q)));
            out.extend(f.link.shapes.iter().map(|s| (pose, *s)));
        }
        out
    }

    /// All collision shapes of arm and gripper at `q` with the gripper opened to `opening`.
    pub fn collision_shapes(&self, q: &[f64], opening: f32) -> Vec<(Pose, LinkShape)> {
        let mut out = self.arm_shapes(q);
        out.extend(self.gripper_shapes(&self.tool_pose(q), opening));
        out
    }

    /// The world pose of the link of every collision shape at `q` with the gripper opened to
    /// `opening`, in [`Robot::collision_shapes`] order, and the tool centre's pose: the same
    /// poses from one forward kinematics pass (the planners' inner loop).
    pub(crate) fn collision_link_poses(&self, q: &[f64], opening: f32, out: &mut Vec<Pose>) -> Pose {
        out.clear();
        let frames = self.link_frames(q);
        let end = self.first_tool_link();
        for (i, l) in self.links.iter().enumerate().take(end) {
            let pose = pose_from_na(&frames[i]);
            out.extend(l.shapes.iter().map(|_| pose));
        }
        let tool_na = *frames.last().expect("a chain has links");
        let n = self.links.len();
        let mut t = tool_na;
        for i in (end..n).rev() {
            let pose = pose_from_na(&t);
            out.extend(self.links[i].shapes.iter().map(|_| pose));
            if i > end {
                t *= self.joints[i - 1].origin.inverse();
            }
        }
        let max = self.max_opening().max(f32::MIN_POSITIVE) as f64;
        let frac = (opening as f64 / max).clamp(0.0, 1.0);
        for f in &self.fingers {
            let (lo, hi) = f.joint.limits;
            let pose = pose_from_na(&(tool_na * f.origin_in_tool * f.joint.motion(lo + frac * (hi - lo))));
            out.extend(f.link.shapes.iter().map(|_| pose));
        }
        pose_from_na(&tool_na)
    }

    /// Per movable joint (configuration order), a bound on the distance from the joint's origin
    /// to any point of the links after it and to any point within `tool_reach` of the tool
    /// centre, in every configuration: moving the joints linearly by `Δq` moves no such point
    /// farther than `Σ levers[i] |Δq_i|` (revolute joints; a prismatic joint moves them by its
    /// travel, and its bound is 1).
    pub fn lever_arms(&self, tool_reach: f64) -> Vec<f64> {
        let n = self.links.len();
        // chain[m]: the farthest link m's frame can be from the previous joint's origin, summed
        let step = |t: usize| {
            let j = &self.joints[t];
            j.origin.translation.vector.norm() + if j.kind == JointKind::Prismatic { j.limits.0.abs().max(j.limits.1.abs()) } else { 0.0 }
        };
        self.movable
            .iter()
            .map(|&j| {
                if self.joints[j].kind == JointKind::Prismatic {
                    return 1.0;
                }
                // joint j's origin is link j + 1's frame origin
                let mut dist = 0.0;
                let mut best: f64 = 0.0;
                for m in j + 1..n {
                    if m > j + 1 {
                        dist += step(m - 1);
                    }
                    let reach = self.links[m].shapes.iter().map(|s| s.reach() as f64).fold(0.0, f64::max);
                    best = best.max(dist + reach);
                }
                best.max(dist + tool_reach)
            })
            .collect()
    }

    /// The farthest a point of the gripper (links rigid with the tool centre, fingers at any
    /// opening) lies from the tool centre.
    pub fn gripper_reach(&self) -> f64 {
        [0.0, self.max_opening()]
            .iter()
            .flat_map(|&o| self.gripper_shapes(&Pose::IDENTITY, o))
            .map(|(pose, s)| (pose.translation.length() + s.reach()) as f64)
            .fold(0.0, f64::max)
    }

    /// An upper bound on the distance from the first movable joint's origin to the tool centre.
    pub fn reach_bound(&self) -> f64 {
        let first = self.movable[0];
        self.joints[first + 1..]
            .iter()
            .map(|j| {
                j.origin.translation.vector.norm()
                    + if j.kind == JointKind::Prismatic { j.limits.0.abs().max(j.limits.1.abs()) } else { 0.0 }
            })
            .sum::<f64>()
            + if self.joints[first].kind == JointKind::Prismatic {
                self.joints[first].limits.0.abs().max(self.joints[first].limits.1.abs())
            } else {
                0.0
            }
    }

    /// The world position of the first movable joint (it does not move with any joint).
    pub(crate) fn shoulder(&self) -> Vector3<f64> {
        let mut t = self.base;
        for j in &self.joints[..=self.movable[0]] {
            t *= j.origin;
        }
        t.translation.vector
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panda_has_seven_joints_and_an_eight_centimetre_gripper() {
        let r = Robot::panda();
        assert_eq!(r.dof(), 7);
        assert_eq!(r.links().last().unwrap().name, "panda_tcp");
        assert!((r.max_opening() - 0.08).abs() < 1e-6);
        assert_eq!(r.fingers().len(), 2);
        assert!(r.notes.is_empty(), "{:?}", r.notes);
        let p = r.tool_pose(&r.mid_configuration());
        assert!(p.translation.is_finite());
        assert!(((p.translation - Vec3::new(0.0, 0.0, 0.333)).length() as f64) < r.reach_bound() + 1e-6);
    }

    #[test]
    fn fingers_open_to_the_requested_width() {
        let r = Robot::panda();
        let shapes = r.gripper_shapes(&Pose::IDENTITY, 0.06);
        let fingers: Vec<_> =
            shapes.iter().filter(|(_, s)| matches!(s.kind, ShapeKind::Box { half_extents } if half_extents.x < 0.011)).collect();
        assert_eq!(fingers.len(), 2);
        // inner faces 0.06 apart along the tool's y axis
        let inner: Vec<f32> = fingers
            .iter()
            .map(|(pose, s)| {
                let c = pose.transform_point(s.local_pose.translation);
                c.y.abs() - 0.01
            })
            .collect();
        for v in inner {
            assert!((v - 0.03).abs() < 1e-5, "{v}");
        }
    }
}
