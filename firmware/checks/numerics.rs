// The core's numerics on fixed inputs, folded into 64-bit digests of
// every result's bits. Compiled twice: by build.rs on the host (the expected
// value) and by tests/numerics.rs on the Cortex-M4F (the value under test).
// Items only, no allocation, no std.

use primo_core::dmp::{Dmp, FitOptions};
use primo_core::generalize::{Generalizer, Method, PROMP_RIDGE};
use primo_core::golden::{ErrorLearner, GoldenSection, SearchConfig};
use primo_core::illinois::Illinois;
use primo_core::orientation::OrientationDmp;
use primo_core::quaternion::Quaternion;
use primo_core::power::{Block, Power, PowerConfig};
use primo_core::secant::{Rule, Secant, SecantConfig};
use primo_protocol::frame::{self as wire, MAX_FRAME};
use primo_protocol::learner::{self, Outcome, Query, Request};

/// FNV-1a over 32-bit words.
pub struct Digest(u64);

impl Digest {
    fn word(&mut self, w: u32) {
        for b in w.to_le_bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn floats(&mut self, v: &[f32]) {
        for x in v {
            self.word(x.to_bits());
        }
    }
}

const DOF: usize = 7;
const KERNELS: usize = 30;
const SAMPLES: usize = 200;
const THETA: usize = DOF * KERNELS + DOF + 1;

/// A 7-DoF, 2-second demonstration whose shape depends on `k`.
fn demo(k: f32, t: &mut [f32; SAMPLES], y: &mut [f32; SAMPLES * DOF]) {
    for (i, (ti, row)) in t.iter_mut().zip(y.chunks_exact_mut(DOF)).enumerate() {
        let s = i as f32 / (SAMPLES - 1) as f32;
        *ti = 2.0 * s;
        for (d, v) in row.iter_mut().enumerate() {
            let a = 0.3 + 0.1 * d as f32 + k;
            *v = a * s * s * (3.0 - 2.0 * s) + 0.05 * libm::sinf(7.0 * s + d as f32);
        }
    }
}

/// The DMP part of [`digest`]: two fits, their parameters into `thetas`,
/// and a run. A function of its own, so that its buffers and the fit's
/// are not on the stack with the generalizer's and the learners' (on the
/// M4F's 32 KiB the three did not fit together: 7.4 + 10.3 + 15.2 KiB).
#[inline(never)]
fn dmps(h: &mut Digest, thetas: &mut [[f32; THETA]; 2]) -> Result<(), u64> {
    let (mut t, mut y) = ([0.0f32; SAMPLES], [0.0f32; SAMPLES * DOF]);
    let mut template = None;
    for (k, theta) in thetas.iter_mut().enumerate() {
        demo(0.2 * k as f32, &mut t, &mut y);
        let Ok(dmp) = Dmp::<DOF, KERNELS>::fit(&t, &y, DOF, KERNELS, &FitOptions::default()) else {
            return Err(1);
        };
        if dmp.params(theta).is_err() {
            return Err(2);
        }
        h.floats(theta);
        template.get_or_insert(dmp);
    }
    let Some(dmp) = template else { return Err(3) };
    let Ok(mut run) = dmp.start(&dmp.execution()) else {
        return Err(4);
    };
    for _ in 0..2000 {
        if run.step(&dmp, 0.001).is_err() {
            return Err(5);
        }
        h.floats(run.position());
    }
    Ok(())
}

/// Fits, integrates, generalizes, searches and explores; returns the digest.
pub fn digest() -> u64 {
    let mut h = Digest(0xcbf2_9ce4_8422_2325);
    // libm on a spread of arguments.
    for i in 0..64 {
        let x = -8.0 + 0.25 * i as f32;
        h.floats(&[libm::expf(x), libm::sinf(x), libm::cosf(x), libm::sqrtf(x * x + 1.0)]);
    }
    // DMP fit and integration, 7 × 30, two demonstrations.
    let mut thetas = [[0.0f32; THETA]; 2];
    if let Err(code) = dmps(&mut h, &mut thetas) {
        return code;
    }
    learners(h, &thetas)
}

/// The rest of [`digest`] after the DMPs: generalization between them and
/// the learners. Its own function for the same reason as [`dmps`].
#[inline(never)]
fn learners(mut h: Digest, thetas: &[[f32; THETA]; 2]) -> u64 {
    // Generalization between the two: LWR, GPR and the ProMP's.
    for method in [
        Method::Lwr { bandwidth: None },
        Method::Gpr {
            length_scale: None,
            noise: 0.0,
        },
        Method::ProMp { ridge: PROMP_RIDGE },
    ] {
        let mut g = Generalizer::<2, 1, THETA>::new(1, THETA, method);
        for (q, theta) in [0.3f32, 1.0].iter().zip(thetas) {
            if g.add_example(&[*q], theta).is_err() {
                return 6;
            }
        }
        if g.build().is_err() {
            return 7;
        }
        let mut out = [0.0f32; THETA];
        for q in [0.1f32, 0.45, 0.8, 1.3] {
            if g.generalize(&[q], &mut out).is_err() {
                return 8;
            }
            h.floats(&out);
        }
    }
    // The error learners on a nonlinear "cell".
    let cfg = SearchConfig {
        low: 0.1,
        high: 1.5,
        desired: 0.5,
        precision: 1e-5,
        max_rollouts: 40,
    };
    let cell = |q: f32| 0.2 - 0.35 * libm::expf(-1.5 * q) * (1.0 + q);
    if let (Ok(mut golden), Ok(mut illinois)) = (GoldenSection::new(cfg), Illinois::new(cfg)) {
        while let Some(q) = golden.ask() {
            h.floats(&[q]);
            let _ = golden.tell(cell(q));
        }
        while let Some(q) = illinois.ask() {
            h.floats(&[q]);
            let _ = illinois.tell(cell(q));
        }
    }
    // The secant learner on a 2-D linear "cell", measured = A q + b, with
    // A so far from I that K = I would diverge.
    let v = |s: &[f32]| Query::from_slice(s).unwrap_or_default();
    let cfg = SecantConfig {
        low: v(&[-2.0, -2.0]),
        high: v(&[2.0, 2.0]),
        desired: v(&[0.5, 0.3]),
        precision: 1e-6,
        max_rollouts: 30,
        gain: 1.0,
        rule: Rule::Broyden,
    };
    let Ok(mut secant) = Secant::<{ learner::MAX_QUERY }>::new(cfg) else {
        return 14;
    };
    while let Some(q) = secant.ask() {
        h.floats(q);
        let (q0, q1) = (q.first().copied().unwrap_or(0.0), q.get(1).copied().unwrap_or(0.0));
        let measured = [2.5 * q0 + 0.5 * q1 + 0.1, -0.4 * q0 + 0.7 * q1 - 0.05];
        let _ = secant.tell(&[0.5 - measured[0], 0.3 - measured[1]]);
    }
    h.floats(&[secant.rollouts() as f32]);
    for row in secant.gain() {
        h.floats(row);
    }
    // PoWER over 219 parameters, 10 updates.
    let blocks = [
        Block { len: 1, variance: 0.05, decay: 0.9 },
        Block { len: THETA, variance: 0.5, decay: 1.0 },
    ];
    let Ok(cfg) = PowerConfig::paper(&blocks) else { return 9 };
    let mut start = [0.0f32; THETA + 1];
    start[0] = 0.5;
    let Ok(mut power) = Power::<{ THETA + 1 }, 3>::new(&start, cfg.clone(), 7) else {
        return 10;
    };
    for _ in 0..40 {
        let theta = power.ask();
        h.floats(theta);
        let cost: f32 = theta.iter().map(|x| (x - 0.1) * (x - 0.1)).sum();
        let _ = power.tell(1.0 / (1.0 + cost));
    }
    h.floats(power.mean());
    // The same with the query learned from the error (power-el).
    let cfg = PowerConfig { query_gain: 0.8, ..cfg };
    let Ok(()) = power.reset(&start, cfg, 8) else { return 15 };
    for _ in 0..40 {
        let theta = power.ask();
        h.floats(theta);
        let error = 0.3 - theta.first().copied().unwrap_or(0.0);
        let cost: f32 = theta.iter().skip(1).map(|x| (x - 0.1) * (x - 0.1)).sum();
        let _ = power.tell_outcome(1.0 / (1.0 + cost), &[error]);
    }
    h.floats(power.mean());
    // A frame: postcard, CRC-32C, COBS.
    let mut buf = [0u8; MAX_FRAME];
    let tell = Request::Tell(Outcome { error: v(&[-0.25, 0.5]), reward: 0.75 });
    if let Ok(bytes) = wire::encode(0x1234_5678, &tell, &mut buf) {
        for b in bytes {
            h.word(u32::from(*b));
        }
    }
    h.0
}

/// An orientation DMP fitted and run; its own digest (its own test binary:
/// with the rest it would not fit the 64 KiB of flash).
pub fn orientation_digest() -> u64 {
    let mut h = Digest(0xcbf2_9ce4_8422_2325);
    // An orientation DMP: a 250° turn about a tilting axis, 30 kernels.
    let mut t = [0.0f32; SAMPLES];
    let mut q = [0.0f32; SAMPLES * 4];
    for (i, row) in q.chunks_exact_mut(4).enumerate() {
        let s = i as f32 / (SAMPLES - 1) as f32;
        t[i] = 2.0 * s;
        let turn = 4.36 * s * s * (3.0 - 2.0 * s);
        let wobble = libm::sinf(core::f32::consts::PI * s);
        let tilt = 0.4 * wobble * wobble;
        let o = Quaternion::exp([0.0, 0.0, turn]).mul(&Quaternion::exp([tilt, 0.0, 0.0]));
        row.copy_from_slice(&o.to_array());
    }
    let Ok(orientation) = OrientationDmp::<KERNELS>::fit(&t, &q, KERNELS, &FitOptions::default())
    else {
        return 11;
    };
    let Ok(mut turn) = orientation.start(&orientation.execution()) else {
        return 12;
    };
    for _ in 0..2000 {
        if turn.step(&orientation, 0.001).is_err() {
            return 13;
        }
        h.floats(&turn.orientation().to_array());
    }
    h.0
}
