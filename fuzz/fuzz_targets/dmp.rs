//! DMP fit and integration on arbitrary demonstrations, gains, goals,
//! durations and steps: no panic; a fit succeeds only on valid input and
//! then gives bounded, finite weights, the demo's start, goal and
//! duration; every integration the DMP accepts is finite throughout,
//! starts at the start and ends at `τ`.
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::dmp::{
    Dmp, Execution, FinalVelocity, FitOptions, MAX_ABS_POSITION, MAX_ABS_WEIGHT, Margin, Scaling,
    Shape,
};
use primo_fuzz::{num, positive};

const D: usize = 3;
const K: usize = 10;
/// Longer integrations are cut here: the property is per sample.
const MAX_STEPS: usize = 3000;

fn demo(u: &mut Unstructured, dof: usize) -> Result<(Vec<f32>, Vec<f32>)> {
    let n = u.int_in_range(0..=40)?;
    let scale = *u.choose(&[1.0, 1e3, MAX_ABS_POSITION])?;
    let raw_times = u.ratio(1, 8)?;
    let mut t = num(u, 10.0)?;
    let mut times = Vec::with_capacity(n);
    for _ in 0..n {
        times.push(t);
        t = if raw_times {
            num(u, 10.0)?
        } else {
            t + positive(u, 1.0)?
        };
    }
    let positions = (0..n * dof).map(|_| num(u, scale)).collect::<Result<_>>()?;
    Ok((times, positions))
}

fn options(u: &mut Unstructured) -> Result<FitOptions> {
    Ok(FitOptions {
        alpha: positive(u, 100.0)?,
        overlap: positive(u, 10.0)?,
        ridge: *u.choose(&[0.0, 1e-6, 1e-2])?,
        scaling: match u.int_in_range(0..=4)? {
            0 => Scaling::Auto,
            1 => Scaling::Always,
            2 => Scaling::Never,
            3 => Scaling::AutoWhere(u.arbitrary()?),
            _ => Scaling::Mask(u.arbitrary()?),
        },
        margin: match u.int_in_range(0..=1)? {
            0 => Margin::Auto,
            _ => Margin::Spacings(margin(u)?),
        },
        final_velocity: match u.arbitrary()? {
            true => FinalVelocity::Demonstrated,
            false => FinalVelocity::AtRest,
        },
    })
}

/// Kernel spacings beyond each end: none, the automatic one, or any
/// (negative, too wide and non-finite ones too: they must be refused).
fn margin(u: &mut Unstructured) -> Result<f32> {
    Ok(match u.int_in_range(0..=2)? {
        0 => 0.0,
        1 => 1.0,
        _ => f32::from_bits(u.arbitrary()?),
    })
}

fn valid_demo(times: &[f32], positions: &[f32]) -> bool {
    times.len() >= 3
        && times.iter().all(|t| t.is_finite())
        && times.windows(2).all(|w| w[0] < w[1])
        && positions
            .iter()
            .all(|p| p.is_finite() && p.abs() <= MAX_ABS_POSITION)
}

fn fitted(u: &mut Unstructured) -> Result<Option<Dmp<D, K>>> {
    let dof = u.int_in_range(1..=D)?;
    let kernels = u.int_in_range(1..=K + 1)?;
    let (times, positions) = demo(u, dof)?;
    let opts = options(u)?;
    let Ok(dmp) = Dmp::<D, K>::fit(&times, &positions, dof, kernels, &opts) else {
        return Ok(None);
    };
    assert!(valid_demo(&times, &positions) && (2..=K).contains(&kernels));
    assert_eq!((dmp.dof(), dmp.kernels()), (dof, kernels));
    assert_eq!(dmp.start_position(), &positions[..dof]);
    assert_eq!(dmp.goal(), &positions[positions.len() - dof..]);
    assert_eq!(dmp.tau(), times[times.len() - 1] - times[0]);
    for d in 0..dof {
        assert!(
            dmp.weights(d)
                .iter()
                .all(|w| w.is_finite() && w.abs() <= MAX_ABS_WEIGHT)
        );
    }
    Ok(Some(dmp))
}

/// A DMP from an arbitrary shape and θ (what the coprocessor builds).
fn shaped(u: &mut Unstructured) -> Result<Option<Dmp<D, K>>> {
    let shape = Shape {
        alpha: positive(u, 100.0)?,
        width: positive(u, 1000.0)?,
        margin: margin(u)?,
        scaled: u.arbitrary()?,
    };
    let (dof, kernels) = (u.int_in_range(0..=D + 1)?, u.int_in_range(0..=K + 1)?);
    let start: Vec<f32> = (0..dof).map(|_| num(u, 10.0)).collect::<Result<_>>()?;
    let len = dof * kernels + dof + 1;
    let theta: Vec<f32> = (0..len).map(|_| num(u, 100.0)).collect::<Result<_>>()?;
    Ok(Dmp::from_shape(&shape, dof, kernels, &start, &theta).ok())
}

fn integrate(u: &mut Unstructured, dmp: &mut Dmp<D, K>) -> Result<()> {
    let mut exec: Execution<D> = dmp.execution();
    for v in exec.start.iter_mut().chain(exec.goal.iter_mut()) {
        if u.ratio(1, 2)? {
            *v = num(u, 10.0)?;
        }
    }
    if u.ratio(1, 2)? {
        exec.tau = positive(u, 10.0)?;
    }
    if u.ratio(1, 4)? {
        // A hit or a throw: the goal moving at some velocity until τ.
        exec.goal_velocity.clear();
        for _ in 0..u.int_in_range(0..=dmp.dof() + 1)? {
            let _ = exec.goal_velocity.push(num(u, 10.0)?);
        }
    }
    if u.ratio(1, 4)? {
        // New weights, goals and τ: a learner's θ.
        let mut theta = vec![0.0; dmp.param_len()];
        dmp.params(&mut theta).expect("param_len fits");
        for v in &mut theta {
            if u.ratio(1, 2)? {
                *v = num(u, 1e3)?;
            }
        }
        if dmp.set_params(&theta).is_ok() {
            let mut back = vec![0.0; theta.len()];
            dmp.params(&mut back).expect("param_len fits");
            assert_eq!(back, theta);
        }
    }
    let dt = positive(u, 0.1)?;
    let Ok(trajectory) = dmp.trajectory(&exec, dt) else {
        return Ok(());
    };
    let dof = dmp.dof();
    let mut last = None;
    for (i, s) in trajectory.take(MAX_STEPS).enumerate() {
        if i == 0 {
            assert_eq!(s.time, 0.0);
            assert_eq!(&s.position[..dof], &exec.start[..]);
        }
        assert!(s.time.is_finite() && s.time <= exec.tau, "t = {}", s.time);
        for v in [&s.position, &s.velocity, &s.acceleration] {
            assert!(
                v[..dof].iter().all(|x| x.is_finite()),
                "{s:?} with {exec:?}, dt {dt}, {dmp:?}"
            );
        }
        last = Some((i, s.time));
    }
    if let Some((i, t)) = last
        && i + 1 < MAX_STEPS
    {
        assert_eq!(t, exec.tau, "a whole trajectory ends at τ");
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let _ = (|| -> Result<()> {
        let dmp = if u.arbitrary()? {
            fitted(&mut u)?
        } else {
            shaped(&mut u)?
        };
        if let Some(mut dmp) = dmp {
            integrate(&mut u, &mut dmp)?;
        }
        Ok(())
    })();
});
