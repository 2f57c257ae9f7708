//! ProMPs: the fit's mean and spread, conditioning, blending, refusals.

use primo_core::Error;
use primo_core::promp::{Observation, ProMp, blend};

/// Reaches of two DoFs: `x` to `h`, `y` a bump of `0.2 h`; 101 samples
/// over `duration` s.
fn reach(h: f32, duration: f32) -> (Vec<f32>, Vec<f32>) {
    let t: Vec<f32> = (0..=100).map(|i| duration * i as f32 / 100.0).collect();
    let y = (0..=100)
        .flat_map(|i| {
            let z = i as f32 / 100.0;
            [
                h * z * z * (3.0 - 2.0 * z),
                0.2 * h * (std::f32::consts::PI * z).sin(),
            ]
        })
        .collect();
    (t, y)
}

fn fitted(heights: &[f32]) -> ProMp<2, 20> {
    let demos: Vec<_> = heights.iter().map(|&h| reach(h, 1.0 + 0.1 * h)).collect();
    let refs: Vec<(&[f32], &[f32])> = demos.iter().map(|(t, y)| (&t[..], &y[..])).collect();
    ProMp::fit(&refs, 2, 20, 1e-6).unwrap()
}

#[test]
fn the_mean_and_spread_are_the_demonstrations() {
    let heights = [0.8, 0.9, 1.0, 1.1, 1.2];
    let p = fitted(&heights);
    for z in [0.0, 0.25, 0.5, 0.75, 1.0] {
        // The demonstrations at this phase, and their mean and variance.
        let at: Vec<f64> = heights
            .iter()
            .map(|&h| f64::from(h) * z * z * (3.0 - 2.0 * z))
            .collect();
        let mean = at.iter().sum::<f64>() / 5.0;
        let var = at.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / 4.0;
        println!(
            "z {z}: mean {} vs {mean}, var {} vs {var}",
            p.mean(z, 0),
            p.variance(z, 0)
        );
        assert!(
            (p.mean(z, 0) - mean).abs() < 2e-3,
            "z {z}: {} vs {mean}",
            p.mean(z, 0)
        );
        assert!(
            (p.variance(z, 0) - var).abs() < 0.1 * var + 1e-5,
            "z {z}: {} vs {var}",
            p.variance(z, 0)
        );
    }
    // x and y move together: correlated at mid-movement.
    let r = p.covariance(0.5, 0, 1) / (p.covariance(0.5, 0, 0) * p.covariance(0.5, 1, 1)).sqrt();
    assert!(r > 0.99, "{r}");
    assert!((p.duration() - (1.0 + 0.1 * 1.0)).abs() < 1e-6);
}

/// Conditioning on one DoF at one phase is the Gaussian formula in
/// trajectory space: every other phase's and DoF's mean moves by
/// `C(·, z₁)(y* − μ(z₁))/(V(z₁) + r)` and its variance drops by
/// `C(·, z₁)²/(V(z₁) + r)`; exactly through the observation with `r = 0`.
#[test]
fn conditioning_is_the_gaussian_update() {
    let p = fitted(&[0.8, 0.9, 1.0, 1.1, 1.2]);
    for (z1, dof, target, r) in [
        (1.0, 0, 1.05, 0.0),
        (0.5, 1, 0.25, 1e-4),
        (0.3, 0, 0.1, 1e-3),
    ] {
        let mut q = p.clone();
        q.condition(
            z1,
            &[Observation {
                dof,
                position: target,
            }],
            r,
        )
        .unwrap();
        let v1 = p.covariance(z1, dof, dof) + r;
        for z2 in [0.0, 0.2, 0.5, 0.8, 1.0] {
            for b in 0..2 {
                let c = p.covariance_between(z2, b, z1, dof);
                let mean = p.mean(z2, b) + c * (f64::from(target) - p.mean(z1, dof)) / v1;
                let var = p.covariance(z2, b, b) - c * c / v1;
                assert!(
                    (q.mean(z2, b) - mean).abs() < 1e-9,
                    "{z2} {b}: {} vs {mean}",
                    q.mean(z2, b)
                );
                assert!(
                    (q.covariance(z2, b, b) - var).abs() < 1e-9 * p.covariance(z2, b, b).max(1e-6)
                );
            }
        }
        if r == 0.0 {
            assert!((q.mean(z1, dof) - f64::from(target)).abs() < 1e-9);
        }
    }
    // Two DoFs at once: both passed; their correlation moves the rest.
    let mut q = p.clone();
    let both = [
        Observation {
            dof: 0,
            position: 0.6,
        },
        Observation {
            dof: 1,
            position: 0.22,
        },
    ];
    q.condition(0.5, &both, 0.0).unwrap();
    assert!((q.mean(0.5, 0) - 0.6).abs() < 1e-6 && (q.mean(0.5, 1) - 0.22).abs() < 1e-6);
}

/// Blending: all `a` at 1, all `b` at 0, between in between (its mean
/// nearer the surer one).
#[test]
fn blending_weighs_each_by_its_activation_and_precision() {
    let (a, b) = (fitted(&[0.5, 0.6, 0.7]), fitted(&[1.0, 1.5, 2.0]));
    let z = 0.8;
    let (m1, v1) = blend(&a, &b, 1.0, z, 0).unwrap();
    assert!((m1 - a.mean(z, 0)).abs() < 1e-12 && (v1 - a.variance(z, 0)).abs() < 1e-12);
    let (m0, v0) = blend(&a, &b, 0.0, z, 0).unwrap();
    assert!((m0 - b.mean(z, 0)).abs() < 1e-12 && (v0 - b.variance(z, 0)).abs() < 1e-12);
    let (mh, _) = blend(&a, &b, 0.5, z, 0).unwrap();
    let middle = 0.5 * (a.mean(z, 0) + b.mean(z, 0));
    // a's demonstrations agree more: the blend leans to a.
    assert!(a.variance(z, 0) < b.variance(z, 0));
    assert!(mh > a.mean(z, 0) && mh < middle, "{mh}");
    assert_eq!(
        blend(&a, &b, 1.5, z, 0),
        Err(Error::OutOfRange("an activation must lie in [0, 1]"))
    );
}

/// One demonstration, demonstrations of different lengths, a phase
/// outside the movement, a DoF observed twice, a singular covariance:
/// each refused.
#[test]
fn what_a_promp_cannot_take_is_refused() {
    let (t, y) = reach(1.0, 1.0);
    let one: [(&[f32], &[f32]); 1] = [(&t, &y)];
    assert!(
        matches!(ProMp::<2, 20>::fit(&one, 2, 20, 1e-6), Err(Error::OutOfRange(m)) if m.contains("at least two demonstrations"))
    );
    let (t2, y2) = (t[..50].to_vec(), y[..100].to_vec());
    let uneven: [(&[f32], &[f32]); 2] = [(&t, &y), (&t2, &y2)];
    assert!(
        matches!(ProMp::<2, 20>::fit(&uneven, 2, 20, 1e-6), Err(Error::OutOfRange(m)) if m.contains("different lengths"))
    );
    let mut p = fitted(&[0.9, 1.1]);
    let o = Observation {
        dof: 0,
        position: 1.0,
    };
    assert_eq!(
        p.condition(1.5, &[o], 0.0),
        Err(Error::OutOfRange("a phase must lie in [0, 1]"))
    );
    assert!(p.condition(0.5, &[o, o], 0.0).is_err());
    assert!(
        p.condition(
            0.5,
            &[Observation {
                dof: 2,
                position: 1.0
            }],
            0.0
        )
        .is_err()
    );
    assert!(p.condition(0.5, &[o], -1.0).is_err());
    // Identical demonstrations and no ridge: no spread to move by, a
    // singular system for an exact observation.
    let same: [(&[f32], &[f32]); 2] = [(&t, &y), (&t, &y)];
    let mut rigid = ProMp::<2, 20>::fit(&same, 2, 20, 0.0).unwrap();
    assert!(matches!(
        rigid.condition(0.5, &[o], 0.0),
        Err(Error::Singular(_))
    ));
}

/// Its values rebuild it exactly; bent values are refused.
#[test]
fn values_rebuild_it_and_bad_ones_are_refused() {
    let mut p = fitted(&[0.8, 1.0, 1.2]);
    p.condition(
        0.5,
        &[Observation {
            dof: 1,
            position: 0.21,
        }],
        1e-4,
    )
    .unwrap();
    let values: Vec<f64> = p.values().collect();
    assert_eq!(values.len(), 4 + 40 + 40 * 40);
    assert_eq!(ProMp::<2, 20>::from_values(&values).unwrap(), p);
    // Too big for a smaller ProMP, cut short, asymmetric, not finite.
    assert!(ProMp::<2, 10>::from_values(&values).is_err());
    assert!(ProMp::<2, 20>::from_values(&values[..100]).is_err());
    let mut skew = values.clone();
    skew[4 + 40 + 1] += 1.0;
    assert!(ProMp::<2, 20>::from_values(&skew).is_err());
    let mut nan = values;
    nan[10] = f64::NAN;
    assert!(ProMp::<2, 20>::from_values(&nan).is_err());
}

/// The mean's velocity is the derivative of its position in time: a
/// finite difference of `mean` agrees, and the demonstrations' own
/// smoothstep slope `6z(1 − z)h / T` comes out at mid-movement.
#[test]
fn the_velocity_is_the_means_slope_per_second() {
    let p = fitted(&[0.8, 0.9, 1.0, 1.1, 1.2]);
    let (t, h) = (p.duration(), 1e-6);
    for z in [0.0f64, 0.1, 0.37, 0.5, 0.9, 1.0] {
        let (a, b) = ((z - h).max(0.0), (z + h).min(1.0));
        for d in 0..2 {
            let numeric = (p.mean(b, d) - p.mean(a, d)) / ((b - a) * t);
            let v = p.velocity(z, d);
            assert!(
                (v - numeric).abs() < 1e-5 * (1.0 + numeric.abs()),
                "z {z} dof {d}: {v} vs {numeric}"
            );
        }
    }
    let expected = 6.0 * 0.5 * 0.5 / t;
    assert!((p.velocity(0.5, 0) - expected).abs() < 0.02 * expected);
    // Before and after the movement, and beyond its DoFs: still.
    assert_eq!((p.velocity(-0.1, 0), p.velocity(1.1, 0)), (0.0, 0.0));
    assert_eq!(p.velocity(f64::NAN, 0), 0.0);
    assert_eq!(p.velocity(0.5, 2), 0.0);
}

/// The weights are the mean's: set back they give the same ProMP; moved,
/// the mean moves with them and the spread stays; a wrong count or a
/// value that is not finite is refused and changes nothing.
#[test]
fn weights_move_the_mean_and_keep_the_spread() {
    let mut p = fitted(&[0.9, 1.0, 1.1]);
    let before = p.clone();
    let w: Vec<f64> = p.weights().collect();
    assert_eq!(w.len(), 2 * 20);
    p.set_weights(&w).unwrap();
    assert_eq!(p, before);
    let raised: Vec<f64> = w
        .iter()
        .enumerate()
        .map(|(i, w)| if i < 20 { w + 0.25 } else { *w })
        .collect();
    p.set_weights(&raised).unwrap();
    for z in [0.0, 0.5, 1.0] {
        // The kernels are normalized: the same change of every weight
        // shifts the position by it.
        assert!((p.mean(z, 0) - before.mean(z, 0) - 0.25).abs() < 1e-12);
        assert_eq!(p.mean(z, 1), before.mean(z, 1));
        assert_eq!(p.variance(z, 0), before.variance(z, 0));
    }
    let kept = p.clone();
    assert!(matches!(
        p.set_weights(&w[1..]),
        Err(Error::Length {
            expected: 40,
            found: 39,
            ..
        })
    ));
    let mut bad = w.clone();
    bad[3] = f64::NAN;
    assert!(matches!(p.set_weights(&bad), Err(Error::NotFinite(_))));
    assert_eq!(p, kept);
}
