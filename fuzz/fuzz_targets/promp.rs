//! ProMPs fitted to arbitrary demonstrations (times raw or increasing,
//! positions up to ±10, one value in eight any bit pattern), rebuilt from
//! arbitrary values, then asked, conditioned and given new weights: no
//! panic; a fit succeeds only on valid demonstrations; an accepted ProMP's
//! mean, velocity and variance are finite at any phase, its values rebuild
//! it, and new weights are taken exactly when they are `dof · kernels`
//! finite values (refused, nothing changes).
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::promp::{Observation, ProMp};
use primo_fuzz::num;

type P = ProMp<2, 8>;

fn phase(u: &mut Unstructured) -> Result<f64> {
    Ok(if u.ratio(1, 8)? {
        f64::from_bits(u.arbitrary()?)
    } else {
        f64::from(u.int_in_range(0..=1000u16)?) / 1000.0
    })
}

/// The ProMP's answers at any phase are finite.
fn check(p: &P, u: &mut Unstructured) -> Result<()> {
    for _ in 0..4 {
        let z = phase(u)?;
        for d in 0..3 {
            assert!(p.mean(z, d).is_finite(), "mean at {z}, DoF {d}");
            assert!(p.velocity(z, d).is_finite(), "velocity at {z}, DoF {d}");
            assert!(p.variance(z, d).is_finite(), "variance at {z}, DoF {d}");
        }
    }
    Ok(())
}

fn fitted(u: &mut Unstructured) -> Result<Option<P>> {
    let (demos, samples) = (u.int_in_range(1..=4usize)?, u.int_in_range(2..=20usize)?);
    let (dof, kernels) = (u.int_in_range(1..=3usize)?, u.int_in_range(1..=9usize)?);
    let raw = u.ratio(1, 8)?;
    let mut data = Vec::new();
    for _ in 0..demos {
        let mut t = Vec::with_capacity(samples);
        let mut now = 0.0f32;
        for _ in 0..samples {
            now = if raw {
                num(u, 10.0)?
            } else {
                now + primo_fuzz::positive(u, 0.1)?
            };
            t.push(now);
        }
        let y = (0..samples * dof)
            .map(|_| num(u, 10.0))
            .collect::<Result<Vec<f32>>>()?;
        data.push((t, y));
    }
    let refs: Vec<(&[f32], &[f32])> = data.iter().map(|(t, y)| (&t[..], &y[..])).collect();
    let ridge = f64::from(num(u, 1.0)?.abs());
    let valid = (2..=4).contains(&demos)
        && dof <= 2
        && (2..=8).contains(&kernels)
        && samples >= kernels
        && refs.iter().all(|(t, y)| {
            t.iter().chain(y.iter()).all(|v| v.is_finite()) && t.windows(2).all(|w| w[1] > w[0])
        });
    let p = P::fit(&refs, dof, kernels, ridge).ok();
    if p.is_some() {
        assert!(valid, "a fit of invalid demonstrations");
    }
    Ok(p)
}

fuzz_target!(|data: &[u8]| {
    let mut u = Unstructured::new(data);
    let _ = run(&mut u);
});

fn run(u: &mut Unstructured) -> Result<()> {
    let mut p = if u.arbitrary()? {
        let Some(p) = fitted(u)? else { return Ok(()) };
        p
    } else {
        let n = u.int_in_range(0..=80usize)?;
        let values = (0..n)
            .map(|_| num(u, 4.0).map(f64::from))
            .collect::<Result<Vec<f64>>>()?;
        let Ok(p) = P::from_values(&values) else {
            return Ok(());
        };
        p
    };
    check(&p, u)?;
    let values: Vec<f64> = p.values().collect();
    assert_eq!(
        P::from_values(&values).as_ref(),
        Ok(&p),
        "values rebuild it"
    );
    let size = p.dof() * p.kernels();
    for _ in 0..4 {
        if u.arbitrary()? {
            let n = if u.ratio(7, 8)? {
                size
            } else {
                u.int_in_range(0..=20usize)?
            };
            let w = (0..n)
                .map(|_| num(u, 10.0).map(f64::from))
                .collect::<Result<Vec<f64>>>()?;
            let before = p.clone();
            match p.set_weights(&w) {
                Ok(()) => {
                    assert!(n == size && w.iter().all(|v| v.is_finite()));
                    assert!(
                        p.weights().eq(w.iter().copied()),
                        "the weights set are the weights"
                    );
                }
                Err(_) => {
                    assert!(n != size || !w.iter().all(|v| v.is_finite()));
                    assert_eq!(p, before, "a refused weight changed the ProMP");
                }
            }
        } else {
            let observed = [Observation {
                dof: u.int_in_range(0..=2usize)?,
                position: num(u, 10.0)?,
            }];
            let variance = f64::from(num(u, 1.0)?);
            let mut q = p.clone();
            if q.condition(phase(u)?, &observed, variance).is_ok() {
                p = q; // a refused condition may leave its copy half-updated
            }
        }
        check(&p, u)?;
    }
    Ok(())
}
