//! DMP costs: one integration step (7 DoF × 30 kernels, 2 × 10) and a fit to
//! 1001 samples. Target: ≤ 150 ns for the 7×30 step.
use criterion::{Criterion, criterion_group, criterion_main};
use primo_core::dmp::{Dmp, FitOptions};
use std::hint::black_box;

fn demo(dof: usize) -> (Vec<f32>, Vec<f32>) {
    let t: Vec<f32> = (0..1001).map(|i| i as f32 / 1000.0).collect();
    let y = t
        .iter()
        .flat_map(|&t| {
            (0..dof).map(move |d| {
                let mj = t * t * t * (10.0 - 15.0 * t + 6.0 * t * t);
                (d as f32 + 1.0) * mj + 0.3 * (std::f32::consts::PI * t).sin().powi(2)
            })
        })
        .collect();
    (t, y)
}

fn step<const D: usize, const K: usize>(c: &mut Criterion, name: &str) {
    let (t, y) = demo(D);
    let dmp = Dmp::<D, K>::fit(&t, &y, D, K, &FitOptions::default()).unwrap();
    let exec = dmp.execution();
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
            run.step(black_box(&dmp), black_box(0.001)).unwrap();
            black_box(run.position()[0]);
        })
    });
}

fn benches(c: &mut Criterion) {
    step::<7, 30>(c, "dmp step 7x30");
    step::<2, 10>(c, "dmp step 2x10");
    let (t, y) = demo(7);
    c.bench_function("dmp fit 7x30, 1001 samples", |b| {
        b.iter(|| {
            Dmp::<7, 30>::fit(black_box(&t), black_box(&y), 7, 30, &FitOptions::default()).unwrap()
        })
    });
}

criterion_group!(dmp_benches, benches);
criterion_main!(dmp_benches);
