//! Inverse kinematics per pose on the shipped panda: targets are tool poses of random
//! configurations, solved from the middle of the limits with the default settings.

use asp_robot::{IkConfig, Robot};
use criterion::{criterion_group, criterion_main, Criterion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn ik(c: &mut Criterion) {
    let robot = Robot::panda();
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let targets: Vec<_> = (0..64).map(|_| robot.tool_pose(&robot.random_configuration(&mut rng))).collect();
    let cfg = IkConfig::default();
    let mut i = 0;
    c.bench_function("ik_panda_random_pose", |b| {
        b.iter(|| {
            i = (i + 1) % targets.len();
            std::hint::black_box(robot.ik(&targets[i], None, &cfg))
        })
    });
    let far = asp_geom::math::Pose::from_translation(asp_geom::math::Vec3::new(2.0, 0.0, 0.3));
    c.bench_function("ik_panda_unreachable_2m", |b| b.iter(|| std::hint::black_box(robot.ik(&far, None, &cfg))));
}

criterion_group!(benches, ik);
criterion_main!(benches);
