//! Orientation DMPs on arbitrary quaternion recordings, starts, goals,
//! durations, steps and goal changes: no panic; a fit succeeds only on
//! valid input; every orientation an accepted run gives is a finite unit
//! quaternion, whatever happens.
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::dmp::FitOptions;
use primo_core::orientation::{OrientationDmp, OrientationExecution};
use primo_core::quaternion::Quaternion;
use primo_fuzz::{num, positive};

const K: usize = 10;
const MAX_STEPS: usize = 2000;

fn quaternion(u: &mut Unstructured) -> Result<Quaternion> {
    Ok(Quaternion {
        w: num(u, 1.0)?,
        x: num(u, 1.0)?,
        y: num(u, 1.0)?,
        z: num(u, 1.0)?,
    })
}

fn unit(q: Quaternion) -> bool {
    q.to_array().iter().all(|v| v.is_finite()) && (q.norm() - 1.0).abs() < 1e-4
}

fn run(u: &mut Unstructured) -> Result<()> {
    let n = u.int_in_range(0..=30)?;
    let mut times = Vec::with_capacity(n);
    let mut t = num(u, 10.0)?;
    let mut rows = Vec::with_capacity(4 * n);
    for _ in 0..n {
        times.push(t);
        t += positive(u, 1.0)?;
        rows.extend(quaternion(u)?.to_array());
    }
    let kernels = u.int_in_range(1..=K + 1)?;
    let options = FitOptions {
        alpha: positive(u, 100.0)?,
        ..FitOptions::default()
    };
    let Ok(dmp) = OrientationDmp::<K>::fit(&times, &rows, kernels, &options) else {
        return Ok(());
    };
    assert!(unit(dmp.goal()) && unit(dmp.start_orientation()));
    let exec = OrientationExecution {
        tau: positive(u, 5.0)?,
        start: quaternion(u)?,
        goal: quaternion(u)?,
    };
    let Ok(mut run) = dmp.start(&exec) else {
        return Ok(());
    };
    assert!(unit(run.orientation()));
    for _ in 0..u.int_in_range(0..=MAX_STEPS)? {
        if u.ratio(1, 100)? {
            let _ = run.set_goal(&dmp, quaternion(u)?);
        }
        if run.step(&dmp, positive(u, 0.1)?).is_err() {
            break;
        }
        assert!(unit(run.orientation()), "{:?}", run.orientation());
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
