//! DMP costs: one integration step (7 DoF × 30 kernels, the same with one
//! obstacle's coupling term on its first three DoFs, 2 × 10, an
//! orientation DMP of 30 kernels) and fits
//! to 1 s at 1 kHz and to 10 s at 1 kHz. Targets: ≤ 150 ns for the 7×30
//! and the orientation step, ≤ 5 ms for the 10 s fit.
use criterion::{Criterion, criterion_group, criterion_main};
use primo_core::coupling::{Coupling, Obstacles, Sphere};
use primo_core::dmp::{Dmp, FitOptions};
use primo_core::orientation::OrientationDmp;
use primo_core::quaternion::Quaternion;
use std::hint::black_box;

/// `seconds` of a `dof`-DoF movement sampled at 1 kHz.
fn demo(dof: usize, seconds: usize) -> (Vec<f32>, Vec<f32>) {
    let n = 1000 * seconds;
    let t: Vec<f32> = (0..=n).map(|i| i as f32 / 1000.0).collect();
    let y = t
        .iter()
        .map(|&t| t / seconds as f32)
        .flat_map(|t| {
            (0..dof).map(move |d| {
                let mj = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
                (d as f32 + 1.0) * mj + 0.3 * (std::f32::consts::PI * t).sin().powi(2)
            })
        })
        .collect();
    (t, y)
}

/// One step of a `D`×`K` DMP; with `ball`, stepped with one obstacle's
/// coupling term (Park et al.'s potential) on DoFs 0–2 as x, y, z, a
/// 5 cm ball 5 cm beside the middle of their straight start–goal line
/// (the M4F probe, firmware/src/bin/footprint.rs, counts the same term on
/// its own reach).
fn step<const D: usize, const K: usize>(c: &mut Criterion, name: &str, ball: bool) {
    let (t, y) = demo(D, 1);
    let dmp = Dmp::<D, K>::fit(&t, &y, D, K, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
    let mid = |d: usize| 0.5 * (exec.start[d] + exec.goal[d]);
    let obstacles = ball.then(|| {
        let sphere = Sphere {
            center: [mid(0) + 0.05, mid(1) - 0.05, mid(2)],
            radius: 0.05,
        };
        Obstacles::<1>::new([0, 1, 2], &[sphere], &exec.start, &exec.goal).unwrap()
    });
    let terms: &[&dyn Coupling] = match &obstacles {
        Some(o) => &[o],
        None => &[],
    };
    let mut run = dmp.start(&exec).unwrap();
    let mut n = 0u32;
    c.bench_function(name, |b| {
        b.iter(|| {
            // Restart every second of simulated time so the phase sweeps
            // the whole movement, not only the settled tail.
            n += 1;
            if n == 1000 {
                n = 0;
                run = dmp.start(&exec).unwrap();
            }
            if ball {
                run.step_with(black_box(&dmp), black_box(0.001), terms)
            } else {
                run.step(black_box(&dmp), black_box(0.001))
            }
            .unwrap();
            black_box(run.position()[0]);
        })
    });
}

/// One step of a 30-kernel orientation DMP (a 250° turn, 1 s), with the
/// quaternion it gives. Target: ≤ 150 ns.
fn orientation_step(c: &mut Criterion) {
    let t: Vec<f32> = (0..=1000).map(|i| i as f32 / 1000.0).collect();
    let q: Vec<f32> = t
        .iter()
        .flat_map(|&t| {
            let turn = 4.36 * t * t * (3.0 - 2.0 * t);
            Quaternion::exp([0.1 * t, 0.0, turn]).to_array()
        })
        .collect();
    let dmp = OrientationDmp::<30>::fit(&t, &q, 30, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
    let mut run = dmp.start(&exec).unwrap();
    let mut n = 0u32;
    c.bench_function("orientation step 3x30", |b| {
        b.iter(|| {
            n += 1;
            if n == 1000 {
                n = 0;
                run = dmp.start(&exec).unwrap();
            }
            run.step(black_box(&dmp), black_box(0.001)).unwrap();
            black_box(run.orientation());
        })
    });
}

fn benches(c: &mut Criterion) {
    orientation_step(c);
    step::<7, 30>(c, "dmp step 7x30", false);
    step::<7, 30>(c, "dmp step 7x30 with one obstacle", true);
    step::<2, 10>(c, "dmp step 2x10", false);
    for seconds in [1, 10] {
        let (t, y) = demo(7, seconds);
        let name = format!("dmp fit 7x30, {seconds} s at 1 kHz");
        c.bench_function(&name, |b| {
            b.iter(|| {
                Dmp::<7, 30>::fit(black_box(&t), black_box(&y), 7, 30, &FitOptions::default())
                    .unwrap()
            })
        });
    }
}

criterion_group!(dmp_benches, benches);
criterion_main!(dmp_benches);
