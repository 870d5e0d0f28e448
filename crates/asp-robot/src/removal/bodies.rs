//! The robot as the sphere check sees it: a chain of bodies carrying spheres, placed by forward
//! kinematics in `f32`.
//!
//! The bodies are the base, then one per movable joint (the links after it up to the next
//! movable joint; the last body carries the gripper, its fingers at the grasp's opening, and the
//! held part). Every body frame is turned so that its joint moves along or about its z axis, so a
//! revolute joint costs one sine and cosine and four products per column. Each collision shape
//! (shrunk by the margin, as in the exact test) has an enclosing sphere and a cover of small
//! spheres ([`crate::spheres`]) in its body's frame.

use super::*;
use crate::robot::JointKind;
use crate::spheres::{cover, enclosing, Sphere, SPHERE_PIECE};
use nalgebra::{Isometry3, Rotation3, UnitQuaternion, Vector3};
use parry3d::math::Mat3;

/// A rigid transform in `f32`: rotation columns then translation.
#[derive(Clone, Copy, Debug)]
pub(super) struct Frame([f32; 12]);

impl Frame {
    pub(super) const IDENTITY: Frame = Frame([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]);

    fn from_iso(iso: &Isometry3<f64>) -> Frame {
        let r = iso.rotation.to_rotation_matrix();
        let m = r.matrix();
        let t = iso.translation.vector;
        Frame(std::array::from_fn(|i| if i < 9 { m[(i % 3, i / 3)] as f32 } else { t[i - 9] as f32 }))
    }

    pub(super) fn from_pose(p: &Pose) -> Frame {
        let (x, y, z) = (p.rotation * Vec3::X, p.rotation * Vec3::Y, p.rotation * Vec3::Z);
        let t = p.translation;
        Frame([x.x, x.y, x.z, y.x, y.y, y.z, z.x, z.y, z.z, t.x, t.y, t.z])
    }

    /// The point `p` of this frame in the parent frame.
    #[inline(always)]
    pub(super) fn point(&self, p: [f32; 3]) -> [f32; 3] {
        let m = &self.0;
        [
            m[0] * p[0] + m[3] * p[1] + m[6] * p[2] + m[9],
            m[1] * p[0] + m[4] * p[1] + m[7] * p[2] + m[10],
            m[2] * p[0] + m[5] * p[1] + m[8] * p[2] + m[11],
        ]
    }

    #[inline(always)]
    fn vector(&self, v: [f32; 3]) -> [f32; 3] {
        let m = &self.0;
        [m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2], m[2] * v[0] + m[5] * v[1] + m[8] * v[2]]
    }

    #[inline(always)]
    pub(super) fn mul(&self, o: &Frame) -> Frame {
        let c0 = self.vector([o.0[0], o.0[1], o.0[2]]);
        let c1 = self.vector([o.0[3], o.0[4], o.0[5]]);
        let c2 = self.vector([o.0[6], o.0[7], o.0[8]]);
        let t = self.point([o.0[9], o.0[10], o.0[11]]);
        Frame([c0[0], c0[1], c0[2], c1[0], c1[1], c1[2], c2[0], c2[1], c2[2], t[0], t[1], t[2]])
    }

    /// This frame turned by `angle` about its z axis (cosine and sine given).
    #[inline(always)]
    fn turned(mut self, c: f32, s: f32) -> Frame {
        for k in 0..3 {
            let (x, y) = (self.0[k], self.0[3 + k]);
            self.0[k] = c * x + s * y;
            self.0[3 + k] = c * y - s * x;
        }
        self
    }

    /// This frame moved by `d` along its z axis.
    #[inline(always)]
    fn slid(mut self, d: f32) -> Frame {
        for k in 0..3 {
            self.0[9 + k] += d * self.0[6 + k];
        }
        self
    }

    pub(super) fn translation(&self) -> Vec3 {
        Vec3::new(self.0[9], self.0[10], self.0[11])
    }

    pub(super) fn to_pose(self) -> Pose {
        let m = &self.0;
        let r = Mat3::from_cols(Vec3::new(m[0], m[1], m[2]), Vec3::new(m[3], m[4], m[5]), Vec3::new(m[6], m[7], m[8]));
        Pose::from_parts(self.translation(), Rot::from_mat3(&r).normalize())
    }
}

/// One movable joint: the constant transform from the previous body frame to the joint's frame
/// (its axis turned onto z) and how it moves.
#[derive(Clone, Copy, Debug)]
pub(super) struct Step {
    fixed: Frame,
    prismatic: bool,
}

/// A collision shape for the sphere test: its body, its pose in the body frame, its enclosing
/// sphere and its cover (a range of the sphere arrays).
#[derive(Clone, Debug)]
pub(super) struct Shape {
    pub(super) body: usize,
    pub(super) local: Frame,
    pub(super) bound: Sphere,
    pub(super) spheres: std::ops::Range<usize>,
}

/// Sphere centres (body frame) and radii, structure of arrays, with each sphere's distance
/// from the centre of its shape's enclosing sphere.
#[derive(Clone, Debug, Default)]
pub(super) struct Spheres {
    pub(super) x: Vec<f32>,
    pub(super) y: Vec<f32>,
    pub(super) z: Vec<f32>,
    pub(super) r: Vec<f32>,
    pub(super) off: Vec<f32>,
}

impl Spheres {
    pub(super) fn push(&mut self, s: Sphere, bound: &Sphere) {
        self.set(self.len(), s, bound);
    }

    /// Sphere `i` (one more than there are: a new one) of the shape enclosed by `bound`.
    pub(super) fn set(&mut self, i: usize, s: Sphere, bound: &Sphere) {
        let off = (s.centre - bound.centre).length();
        if i == self.len() {
            self.x.push(s.centre.x);
            self.y.push(s.centre.y);
            self.z.push(s.centre.z);
            self.r.push(s.radius);
            self.off.push(off);
        } else {
            (self.x[i], self.y[i], self.z[i], self.r[i], self.off[i]) = (s.centre.x, s.centre.y, s.centre.z, s.radius, off);
        }
    }

    pub(super) fn len(&self) -> usize {
        self.r.len()
    }
}

/// The robot as bodies of spheres, built once per planner from its collision shapes.
#[derive(Clone, Debug)]
pub(super) struct ArmModel {
    base: Frame,
    pub(super) steps: Vec<Step>,
    /// Per shape of the planner's `arm` (same order): the shape in its body frame.
    pub(super) shapes: Vec<Shape>,
    pub(super) spheres: Spheres,
    /// The tool centre in the last body's frame.
    pub(super) tool: Frame,
    /// Per finger shape (index into `shapes`): the finger's joint and the shape's pose in the
    /// finger link.
    pub(super) fingers: Vec<(usize, usize, Pose)>,
    /// The largest radius of a small sphere (the grid must list every box this close).
    pub(super) largest: f32,
}

/// Rotation taking z onto `axis`.
fn align(axis: &Vector3<f64>) -> Isometry3<f64> {
    let r = Rotation3::rotation_between(&Vector3::z(), axis)
        .unwrap_or_else(|| Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI));
    Isometry3::from_parts(nalgebra::Translation3::identity(), UnitQuaternion::from_rotation_matrix(&r))
}

impl ArmModel {
    /// The model of `robot` whose shapes, prepared by the planner, are `arm` (in
    /// [`Robot::collision_shapes`] order: the arm's links base first, the links rigid with the
    /// tool from the tool centre back, the fingers).
    pub(super) fn new(robot: &Robot, arm: &[Prepared]) -> ArmModel {
        let links = robot.links();
        let joints = robot.joints();
        let n = links.len();
        // body of every link: the number of movable joints above it
        let body: Vec<usize> = (0..n).map(|i| robot.movable.iter().filter(|&&m| m < i).count()).collect();
        let aligned: Vec<Isometry3<f64>> =
            std::iter::once(Isometry3::identity()).chain(robot.movable.iter().map(|&m| align(&joints[m].axis))).collect();
        // each link in its body's (unturned) frame
        let mut in_body = vec![Isometry3::<f64>::identity(); n];
        for i in 1..n {
            if body[i] == body[i - 1] {
                in_body[i] = in_body[i - 1] * joints[i - 1].origin;
            }
        }
        let steps = robot
            .movable
            .iter()
            .enumerate()
            .map(|(k, &m)| {
                let c = in_body[m] * joints[m].origin;
                Step {
                    fixed: Frame::from_iso(&(aligned[k].inverse() * c * aligned[k + 1])),
                    prismatic: joints[m].kind == JointKind::Prismatic,
                }
            })
            .collect();
        // each link in its body's turned frame
        let offset: Vec<Isometry3<f64>> = (0..n).map(|i| aligned[body[i]].inverse() * in_body[i]).collect();
        let start = robot.first_tool_link();
        let order: Vec<usize> = (0..start).chain((start..n).rev()).collect();
        let mut shapes = Vec::new();
        let mut spheres = Spheres::default();
        let add = |body: usize, link_to_body: Pose, link_shape: LinkShape, p: &Prepared, spheres: &mut Spheres| {
            let first = spheres.len();
            let bound = enclosing(&link_shape).transformed(&link_to_body);
            for s in cover(&link_shape, SPHERE_PIECE) {
                spheres.push(s.transformed(&link_to_body), &bound);
            }
            Shape { body, local: Frame::from_pose(&(link_to_body * p.local)), bound, spheres: first..spheres.len() }
        };
        let mut k = 0;
        for &i in &order {
            let to_body = crate::convert::pose_from_na(&offset[i]);
            for _ in &links[i].shapes {
                let p = &arm[k];
                let shape = LinkShape { local_pose: p.link_pose, kind: p.kind };
                shapes.push(add(body[i], to_body, shape, p, &mut spheres));
                k += 1;
            }
        }
        let dof = robot.dof();
        let mut fingers = Vec::new();
        for (f, finger) in robot.fingers().iter().enumerate() {
            for _ in &finger.link.shapes {
                let p = &arm[k];
                let shape = LinkShape { local_pose: p.link_pose, kind: p.kind };
                // placed at the opening of each check space; here at the closed gripper
                shapes.push(add(dof, Pose::IDENTITY, shape, p, &mut spheres));
                fingers.push((k, f, p.link_pose));
                k += 1;
            }
        }
        debug_assert_eq!(k, arm.len());
        let largest = spheres.r.iter().copied().fold(0.0, f32::max);
        ArmModel { base: Frame::from_iso(&robot.base), steps, shapes, spheres, tool: Frame::from_iso(&offset[n - 1]), fingers, largest }
    }

    /// The body frames at `q` into `frames` (base first): forward kinematics in `f32`.
    #[inline]
    pub(super) fn body_frames(&self, q: &[f64], frames: &mut Vec<Frame>) {
        frames.clear();
        frames.push(self.base);
        for (step, &v) in self.steps.iter().zip(q) {
            let f = frames[frames.len() - 1].mul(&step.fixed);
            let v = v as f32;
            frames.push(if step.prismatic {
                f.slid(v)
            } else {
                let (s, c) = v.sin_cos();
                f.turned(c, s)
            });
        }
    }

    /// The tool centre at `q`.
    pub(super) fn tool_position(&self, q: &[f64], frames: &mut Vec<Frame>) -> Vec3 {
        self.body_frames(q, frames);
        frames[frames.len() - 1].mul(&self.tool).translation()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    /// The `f32` body frames put every shape where the `f64` forward kinematics does.
    #[test]
    fn body_frames_place_every_shape_as_the_kinematics_do() {
        let robot = Robot::panda().with_base_pose(Pose::from_parts(Vec3::new(0.3, -0.2, 0.1), Rot::from_rotation_z(0.4)));
        let arm: Vec<Prepared> = {
            let q = robot.mid_configuration();
            let n = robot.collision_shapes(&q, 0.0).len();
            let links = robot.links();
            let start = robot.first_tool_link();
            let mut out: Vec<Prepared> = links[..start]
                .iter()
                .chain(links[start..].iter().rev())
                .flat_map(|l| l.shapes.iter().map(|s| Prepared::new(s, 0.001)))
                .collect();
            out.extend(robot.fingers().iter().flat_map(|f| f.link.shapes.iter().map(|s| Prepared::new(s, 0.001))));
            assert_eq!(out.len(), n);
            out
        };
        let model = ArmModel::new(&robot, &arm);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
        let mut frames = Vec::new();
        let mut poses = Vec::new();
        for _ in 0..50 {
            let q = robot.random_configuration(&mut rng);
            model.body_frames(&q, &mut frames);
            robot.collision_link_poses(&q, 0.0, &mut poses);
            let fingers = model.fingers.iter().map(|f| f.0).collect::<Vec<_>>();
            for (k, shape) in model.shapes.iter().enumerate() {
                if fingers.contains(&k) {
                    continue;
                }
                let fast = frames[shape.body].mul(&shape.local).to_pose();
                let exact = poses[k] * arm[k].local;
                assert!((fast.translation - exact.translation).length() < 1e-5, "shape {k}: {} vs {}", fast.translation, exact.translation);
                for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
                    assert!((fast.rotation * axis - exact.rotation * axis).length() < 1e-5, "shape {k}: {axis}");
                }
            }
        }
    }
}
