//! Inverse kinematics for the tool centre: damped least squares (Levenberg-Marquardt damping)
//! with joint limits, restarted from seeded random configurations.

use asp_geom::math::Pose;
use nalgebra::{Isometry3, Matrix6, Matrix6xX, Vector6};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use crate::convert::pose_to_na;
use crate::robot::{JointKind, Robot};

/// Settings of [`Robot::ik`].
#[derive(Clone, Debug)]
pub struct IkConfig {
    /// Iterations per attempt.
    pub max_iterations: usize,
    /// Attempts from random configurations after the first (which starts from the given start, or
    /// the middle of the limits).
    pub restarts: usize,
    /// Position error that counts as reached, metres.
    pub position_tolerance: f64,
    /// Orientation error that counts as reached, radians.
    pub rotation_tolerance: f64,
    /// Initial damping λ of the damped least squares step.
    pub damping: f64,
    /// Seed of the random restarts: the same seed gives the same solution.
    pub seed: u64,
}

impl Default for IkConfig {
    fn default() -> Self {
        IkConfig { max_iterations: 100, restarts: 40, position_tolerance: 1e-5, rotation_tolerance: 1e-4, damping: 0.01, seed: 0 }
    }
}

/// A configuration that places the tool centre at the target.
#[derive(Clone, Debug, PartialEq)]
pub struct IkSolution {
    /// Joint values (within the limits), in configuration order.
    pub joints: Vec<f64>,
    /// Remaining position error, metres.
    pub position_error: f64,
    /// Remaining orientation error, radians.
    pub rotation_error: f64,
    /// Attempts used (1 = the first start converged).
    pub attempts: usize,
}

/// The answer of [`Robot::ik`]: reached, or unreachable with the best errors found.
#[derive(Clone, Debug, PartialEq)]
pub enum IkOutcome {
    /// The target was reached within the tolerances.
    Reached(IkSolution),
    /// No attempt reached the target.
    Unreachable {
        /// The smallest position error of any attempt, metres (the distance beyond the reach
        /// bound when the target was rejected without trying).
        position_error: f64,
        /// The orientation error of that attempt, radians.
        rotation_error: f64,
        /// Attempts made (0 when the target lies beyond the arm's reach bound).
        attempts: usize,
    },
}

impl IkOutcome {
    /// The solution, if reached.
    pub fn solution(&self) -> Option<&IkSolution> {
        match self {
            IkOutcome::Reached(s) => Some(s),
            IkOutcome::Unreachable { .. } => None,
        }
    }
}

/// The 6-vector error (position, rotation as axis·angle) from `current` to `target`, world frame.
fn pose_error(target: &Isometry3<f64>, current: &Isometry3<f64>) -> Vector6<f64> {
    let dp = target.translation.vector - current.translation.vector;
    let dr = (target.rotation * current.rotation.inverse()).scaled_axis();
    Vector6::new(dp.x, dp.y, dp.z, dr.x, dr.y, dr.z)
}

impl Robot {
    /// The geometric Jacobian (6 × dof, world frame, linear rows first) of the tool centre at the
    /// given link frames, and the tool-centre frame.
    fn jacobian(&self, frames: &[Isometry3<f64>]) -> Matrix6xX<f64> {
        let tool = frames.last().expect("links").translation.vector;
        let mut jac = Matrix6xX::zeros(self.dof());
        for (c, &ji) in self.movable.iter().enumerate() {
            let joint = &self.joints[ji];
            // joint ji's frame after its motion is the child link frame ji + 1; the axis is the same
            let f = &frames[ji + 1];
            let axis = f.rotation * joint.axis;
            match joint.kind {
                JointKind::Revolute => {
                    let v = axis.cross(&(tool - f.translation.vector));
                    jac.fixed_view_mut::<3, 1>(0, c).copy_from(&v);
                    jac.fixed_view_mut::<3, 1>(3, c).copy_from(&axis);
                }
                JointKind::Prismatic => jac.fixed_view_mut::<3, 1>(0, c).copy_from(&axis),
                JointKind::Fixed => {}
            }
        }
        jac
    }

    /// One damped-least-squares descent from `q`. Returns the final configuration and errors.
    fn ik_descend(&self, target: &Isometry3<f64>, mut q: Vec<f64>, cfg: &IkConfig) -> (Vec<f64>, f64, f64) {
        let limits = self.limits();
        let mut frames = self.link_frames(&q);
        let mut e = pose_error(target, frames.last().expect("links"));
        let mut cost = e.norm_squared();
        let mut lambda = cfg.damping;
        for _ in 0..cfg.max_iterations {
            if e.fixed_rows::<3>(0).norm() <= cfg.position_tolerance && e.fixed_rows::<3>(3).norm() <= cfg.rotation_tolerance {
                break;
            }
            let jac = self.jacobian(&frames);
            let jjt: Matrix6<f64> = &jac * jac.transpose() + Matrix6::identity() * (lambda * lambda);
            let Some(y) = jjt.cholesky().map(|c| c.solve(&e)) else {
                lambda *= 4.0;
                continue;
            };
            let mut dq = jac.transpose() * y;
            let n = dq.norm();
            if n > 0.5 {
                dq *= 0.5 / n;
            }
            let trial: Vec<f64> = q.iter().zip(dq.iter()).zip(&limits).map(|((v, d), (lo, hi))| (v + d).clamp(*lo, *hi)).collect();
            let tf = self.link_frames(&trial);
            let te = pose_error(target, tf.last().expect("links"));
            let tc = te.norm_squared();
            if tc < cost {
                q = trial;
                frames = tf;
                e = te;
                cost = tc;
                lambda = (lambda * 0.5).max(1e-6);
            } else {
                lambda *= 4.0;
                if lambda > 1e3 {
                    break;
                }
            }
        }
        let pe = e.fixed_rows::<3>(0).norm();
        let re = e.fixed_rows::<3>(3).norm();
        (q, pe, re)
    }

    /// Inverse kinematics: a configuration within the joint limits that puts the tool centre at
    /// `target` (world frame). The first attempt starts from `start` (the middle of the limits when
    /// `None`), further ones from random configurations drawn from `cfg.seed`. Unreachable targets
    /// are a value, not an error; a target beyond [`Robot::reach_bound`] is rejected at once.
    pub fn ik(&self, target: &Pose, start: Option<&[f64]>, cfg: &IkConfig) -> IkOutcome {
        let t = pose_to_na(target);
        let distance = (t.translation.vector - self.shoulder()).norm();
        let bound = self.reach_bound();
        if !distance.is_finite() || distance > bound {
            return IkOutcome::Unreachable { position_error: distance - bound, rotation_error: f64::NAN, attempts: 0 };
        }
        if let Some((wrist, bound)) = self.wrist_reach(&t) {
            if wrist > bound {
                return IkOutcome::Unreachable { position_error: wrist - bound, rotation_error: f64::NAN, attempts: 0 };
            }
        }
        let limits = self.limits();
        let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
        let mut best = (f64::INFINITY, f64::INFINITY);
        let first = match start {
            Some(s) if s.len() == self.dof() => s.iter().zip(&limits).map(|(v, (lo, hi))| v.clamp(*lo, *hi)).collect(),
            _ => self.mid_configuration(),
        };
        for attempt in 0..=cfg.restarts {
            let q0 = if attempt == 0 {
                first.clone()
            } else {
                limits.iter().map(|&(lo, hi)| if hi > lo { rng.random_range(lo..=hi) } else { lo }).collect()
            };
            let (q, pe, re) = self.ik_descend(&t, q0, cfg);
            if pe <= cfg.position_tolerance && re <= cfg.rotation_tolerance {
                return IkOutcome::Reached(IkSolution { joints: q, position_error: pe, rotation_error: re, attempts: attempt + 1 });
            }
            if pe + re < best.0 + best.1 {
                best = (pe, re);
            }
        }
        IkOutcome::Unreachable { position_error: best.0, rotation_error: best.1, attempts: cfg.restarts + 1 }
    }

    /// For a tool target, the distance from the shoulder to the last revolute joint's origin
    /// that the target implies (the links after it are rigid with the tool, so the target fixes
    /// that point), and the farthest the chain can put that point from the shoulder. `None` when
    /// the last movable joint is prismatic or is the first one.
    fn wrist_reach(&self, target: &Isometry3<f64>) -> Option<(f64, f64)> {
        let last = *self.movable.last()?;
        let first = self.movable[0];
        if last == first || self.joints[last].kind != JointKind::Revolute {
            return None;
        }
        // link last + 1's frame (its origin lies on the joint's axis) in the tool frame
        let mut tip = Isometry3::identity();
        for j in &self.joints[last + 1..] {
            tip *= j.origin;
        }
        let wrist = (target * tip.inverse()).translation.vector;
        let bound: f64 = self.joints[first + 1..=last]
            .iter()
            .map(|j| {
                j.origin.translation.vector.norm()
                    + if j.kind == JointKind::Prismatic { j.limits.0.abs().max(j.limits.1.abs()) } else { 0.0 }
            })
            .sum();
        Some(((wrist - self.shoulder()).norm(), bound + 1e-9))
    }

    /// A configuration drawn uniformly within the joint limits.
    pub fn random_configuration(&self, rng: &mut impl rand::Rng) -> Vec<f64> {
        self.limits().iter().map(|&(lo, hi)| if hi > lo { rng.random_range(lo..=hi) } else { lo }).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        let r = Robot::panda();
        let q = vec![0.3, -0.4, 0.2, -1.5, 0.1, 1.2, -0.3];
        let frames = r.link_frames(&q);
        let jac = r.jacobian(&frames);
        let p0 = frames.last().unwrap();
        for c in 0..7 {
            let mut q2 = q.clone();
            q2[c] += 1e-6;
            let p1 = *r.link_frames(&q2).last().unwrap();
            let d = pose_error(&p1, p0) / 1e-6;
            for row in 0..6 {
                assert!((d[row] - jac[(row, c)]).abs() < 1e-4, "joint {c} row {row}: {} vs {}", d[row], jac[(row, c)]);
            }
        }
    }
}
