use asp_check::robot as recheck;

mod fk;
mod grasp;
mod ik;
mod load;
mod removal;
mod reuse;
mod spheres;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// Deterministic random configurations of the robot within its limits.
pub fn configurations(robot: &asp_robot::Robot, n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n).map(|_| robot.random_configuration(&mut rng)).collect()
}
