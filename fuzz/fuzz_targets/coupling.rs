//! Coupling terms on arbitrary scenes: obstacles (centres, radii, gains,
//! powers, bounds), joint limits (limits, margin, gain) and phase
//! stopping (gain, lags) against arbitrary positions and velocities, then
//! a short DMP run stepped with them. No panic; a term is built only from
//! valid settings; every acceleration it adds is finite and within its
//! bound; phase stopping's step is in (0, dt]; every position of a coupled
//! run the DMP accepts is finite.
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::coupling::{Coupling, JointLimits, Obstacles, PhaseStop, Sphere};
use primo_core::dmp::{Dmp, FitOptions};
use primo_fuzz::{num, positive};

const D: usize = 3;
const N: usize = 4;

fn vector(u: &mut Unstructured, scale: f32) -> Result<[f32; D]> {
    Ok([num(u, scale)?, num(u, scale)?, num(u, scale)?])
}

fn obstacles(
    u: &mut Unstructured,
    start: &[f32],
    goal: &[f32],
) -> Result<Option<(Obstacles<N>, f32)>> {
    let n = u.int_in_range(0..=N + 1)?;
    let spheres = (0..n)
        .map(|_| {
            Ok(Sphere {
                center: vector(u, 2.0)?,
                radius: num(u, 1.0)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let axes = [
        u.int_in_range(0..=D)?,
        u.int_in_range(0..=D)?,
        u.int_in_range(0..=D)?,
    ];
    let Ok(o) = Obstacles::<N>::new(axes, &spheres, start, goal) else {
        return Ok(None);
    };
    assert!(n <= N && spheres.iter().all(|s| s.radius >= 0.0));
    let (gain, power, max) = (positive(u, 10.0)?, positive(u, 20.0)?, positive(u, 1e5)?);
    Ok(Some(match o.clone().with_gains(gain, power, max) {
        Ok(o) => (o, max * n as f32),
        Err(_) => (o, 1e4 * n as f32),
    }))
}

fn check(term: &dyn Coupling, bound: f32, per_dof: bool, x: &[f32], v: &[f32]) {
    let mut a = [0.0f32; D];
    if term.add_to(x, v, &mut a).is_ok() {
        assert!(a.iter().all(|a| a.is_finite()), "{a:?}");
        let size = if per_dof {
            a.iter().fold(0.0f32, |m, a| m.max(a.abs()))
        } else {
            a.iter().map(|a| a * a).sum::<f32>().sqrt()
        };
        assert!(size <= bound * 1.001, "{a:?} beyond {bound}");
    }
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let _ = (|| -> Result<()> {
        let (start, goal) = (vector(&mut u, 1.0)?, vector(&mut u, 1.0)?);
        let obstacles = obstacles(&mut u, &start, &goal)?;
        let (low, high) = (vector(&mut u, 2.0)?, vector(&mut u, 2.0)?);
        let (margin, gain, max) = (num(&mut u, 1.0)?, num(&mut u, 100.0)?, num(&mut u, 1e4)?);
        let limits = JointLimits::<D>::new(&low, &high, margin, gain, max, &start, &goal).ok();
        let stop = PhaseStop::new(num(&mut u, 1e4)?).ok();
        for _ in 0..u.int_in_range(0..=8)? {
            let (x, v) = (vector(&mut u, 10.0)?, vector(&mut u, 100.0)?);
            if let Some((o, bound)) = &obstacles {
                check(o, *bound, false, &x, &v);
            }
            if let Some(l) = &limits {
                check(l, max, true, &x, &v);
            }
            if let Some(s) = stop {
                let dt = positive(&mut u, 0.1)?;
                if let Ok(step) = s.step(dt, &x, &v) {
                    assert!(step > 0.0 && step <= dt, "{step} for {dt}");
                }
            }
        }
        // A straight reach from start to goal, run with the terms.
        let t: Vec<f32> = (0..=20).map(|i| i as f32 / 20.0).collect();
        let y: Vec<f32> = t
            .iter()
            .flat_map(|&t| (0..D).map(move |i| start[i] + (goal[i] - start[i]) * t))
            .collect();
        let Ok(dmp) = Dmp::<D, 8>::fit(&t, &y, D, 8, &FitOptions::default()) else {
            return Ok(());
        };
        let Ok(mut run) = dmp.start(&dmp.execution()) else {
            return Ok(());
        };
        let mut terms: Vec<&dyn Coupling> = vec![];
        if let Some((o, _)) = &obstacles {
            terms.push(o);
        }
        if let Some(l) = &limits {
            terms.push(l);
        }
        let dt = positive(&mut u, 0.05)?;
        for _ in 0..200 {
            if run.step_with(&dmp, dt, &terms).is_err() {
                break;
            }
            assert!(run.position().iter().all(|p| p.is_finite()), "{run:?}");
        }
        Ok(())
    })();
});
