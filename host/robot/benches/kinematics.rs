//! Kinematics costs of the 7-joint LWR 4 holding a tool, as the pour uses
//! it: forward kinematics, the Jacobian, and inverse kinematics along a
//! path, each sample solved from the previous sample's solution (the
//! gate's use). Targets (issue 26): IK median ≤ 50 µs per solve.
use criterion::{Criterion, criterion_group, criterion_main};
use primo_robot::{Arm, JOINTS, Pose, Robot};
use std::hint::black_box;

/// A smooth joint path of `n` samples through the workspace.
fn path(n: usize) -> Vec<[f64; JOINTS]> {
    (0..n)
        .map(|i| {
            let s = i as f64 / n as f64;
            std::array::from_fn(|j| {
                0.4 * (s * 6.0 + j as f64).sin() + [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0][j]
            })
        })
        .collect()
}

fn kinematics(c: &mut Criterion) {
    let arm = Arm::with_tool(Robot::lwr4(), &Pose::translation(0.0, 0.05, 0.12));
    let q = [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5];
    c.bench_function("lwr4 forward", |b| b.iter(|| arm.forward(black_box(&q))));
    c.bench_function("lwr4 jacobian", |b| b.iter(|| arm.jacobian(black_box(&q))));
    let samples = path(1000);
    let targets: Vec<Pose> = samples.iter().map(|q| arm.forward(q)).collect();
    let rest = [0.0, 0.5, 0.0, -1.2, 0.0, 0.6, 0.0];
    c.bench_function("lwr4 ik along a path (per solve)", |b| {
        let mut i = 0;
        let mut seed = samples[0];
        b.iter(|| {
            i = (i + 1) % targets.len();
            if i == 0 {
                seed = samples[0];
            }
            if let Ok(q) = arm.inverse(black_box(&targets[i]), &seed, &rest) {
                seed = q;
            }
        })
    });
}

criterion_group!(benches, kinematics);
criterion_main!(benches);
