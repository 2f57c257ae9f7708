//! Rhythmic DMPs on arbitrary recordings, periods, kernels and gains, run
//! with arbitrary frequencies, amplitudes, anchors and steps: no panic; a
//! fit succeeds only on valid input and gives bounded finite weights; every
//! position of an accepted run within the bounds is finite.
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::dmp::{FitOptions, MAX_ABS_WEIGHT};
use primo_core::rhythmic::RhythmicDmp;
use primo_fuzz::{num, positive};

const D: usize = 2;
const K: usize = 12;
const MAX_STEPS: usize = 2000;

fn run(u: &mut Unstructured) -> Result<()> {
    let dof = u.int_in_range(1..=D)?;
    let n = u.int_in_range(0..=40)?;
    let mut t = num(u, 10.0)?;
    let mut times = Vec::with_capacity(n);
    for _ in 0..n {
        times.push(t);
        t += positive(u, 1.0)?;
    }
    let positions: Vec<f32> = (0..n * dof).map(|_| num(u, 1e3)).collect::<Result<_>>()?;
    let period = if u.arbitrary()? {
        Some(positive(u, 20.0)?)
    } else {
        None
    };
    let options = FitOptions {
        alpha: positive(u, 100.0)?,
        overlap: positive(u, 10.0)?,
        ..FitOptions::default()
    };
    let kernels = u.int_in_range(1..=K + 1)?;
    let Ok(dmp) = RhythmicDmp::<D, K>::fit(&times, &positions, dof, kernels, period, &options)
    else {
        return Ok(());
    };
    for d in 0..dof {
        assert!(
            dmp.weights(d)
                .iter()
                .all(|w| w.is_finite() && w.abs() <= MAX_ABS_WEIGHT)
        );
    }
    let Ok(mut run) = dmp.start() else {
        return Ok(());
    };
    for _ in 0..u.int_in_range(0..=MAX_STEPS)? {
        match u.int_in_range(0..=60)? {
            0 => drop(run.set_frequency(num(u, 100.0)?)),
            1 => drop(run.set_amplitude(&[num(u, 10.0)?, num(u, 10.0)?][..dof])),
            2 => drop(run.set_anchor(&[num(u, 1e3)?, num(u, 1e3)?][..dof])),
            _ => {}
        }
        if run.step(&dmp, positive(u, 0.1)?).is_err() {
            break;
        }
        assert!(
            run.position().iter().all(|v| v.is_finite()),
            "{:?}",
            run.position()
        );
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
