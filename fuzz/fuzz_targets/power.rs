//! PoWER fed arbitrary settings, starting points and rewards (NaN, ±∞,
//! negative, huge): no panic; it starts only on valid settings; every
//! roll-out it asks for is finite and repeated until told; an invalid
//! reward or a tell without an ask is an error that changes nothing; the
//! importance sampler is the best rewards so far, sorted.
#![no_main]

use arbitrary::{Result, Unstructured};
use libfuzzer_sys::fuzz_target;
use primo_core::power::{Block, MAX_ABS_PARAM, MAX_BLOCKS, MAX_VARIANCE, Power, PowerConfig};
use primo_fuzz::num;

const P: usize = 6;
const L: usize = 4;

fn config(u: &mut Unstructured) -> Result<PowerConfig> {
    let mut blocks = heapless::Vec::new();
    for _ in 0..u.int_in_range(0..=MAX_BLOCKS.min(4))? {
        let block = Block {
            len: u.int_in_range(0..=P)?,
            variance: num(u, 2.0)?.abs(),
            decay: num(u, 1.0)?,
        };
        blocks.push(block).expect("at most MAX_BLOCKS");
    }
    Ok(PowerConfig {
        blocks,
        rollouts_per_update: *u.choose(&[0, 1, 2, 3, u16::MAX])?,
        roll_out_mean: u.arbitrary()?,
        sampler: u.int_in_range(0..=L + 1)?,
        query_gain: *u.choose(&[0.0, 1.0, -0.5, 1e30, f32::NAN])?,
    })
}

/// The settings PoWER documents as valid, spelled out independently.
fn valid(initial: &[f32], cfg: &PowerConfig) -> bool {
    !initial.is_empty()
        && initial.len() <= P
        && initial
            .iter()
            .all(|v| v.is_finite() && v.abs() <= MAX_ABS_PARAM)
        && cfg.blocks.iter().map(|b| b.len).sum::<usize>() == initial.len()
        && cfg
            .blocks
            .iter()
            .all(|b| (0.0..=MAX_VARIANCE).contains(&b.variance))
        && cfg.blocks.iter().all(|b| b.decay > 0.0 && b.decay <= 1.0)
        && cfg.rollouts_per_update >= 1
        && (1..=L).contains(&cfg.sampler)
        && cfg.query_gain.is_finite()
}

fn run(u: &mut Unstructured) -> Result<()> {
    let n = u.int_in_range(0..=P + 1)?;
    let initial: Vec<f32> = (0..n).map(|_| num(u, 10.0)).collect::<Result<_>>()?;
    let cfg = config(u)?;
    let made = Power::<P, L>::new(&initial, cfg.clone(), u.arbitrary()?);
    assert_eq!(made.is_ok(), valid(&initial, &cfg), "{initial:?} {cfg:?}");
    let Ok(mut power) = made else {
        return Ok(());
    };
    let mut rewards = Vec::new();
    // An invalid reward leaves the roll-out asked; a valid one ends it.
    let mut asked_untold = false;
    for _ in 0..100 {
        if !asked_untold && u.ratio(1, 16)? {
            let before = power.clone();
            assert!(power.tell(1.0).is_err(), "a tell without an ask");
            assert_eq!(power, before);
        }
        let asked = power.ask().to_vec();
        asked_untold = true;
        assert_eq!(asked.len(), n);
        assert!(asked.iter().all(|v| v.is_finite()), "{asked:?}");
        assert_eq!(power.ask(), &asked[..], "asking again gives the same");
        let reward = num(u, 10.0)?;
        let error: Vec<f32> = (0..u.int_in_range(0..=2)?)
            .map(|_| num(u, 10.0))
            .collect::<Result<_>>()?;
        let before = power.clone();
        let corrected = error.len() <= n
            && error.iter().zip(&asked).all(|(e, q)| {
                let c = q + cfg.query_gain * e;
                e.is_finite() && c.is_finite() && c.abs() <= MAX_ABS_PARAM
            });
        let taken = reward.is_finite() && reward >= 0.0 && (cfg.query_gain == 0.0 || corrected);
        if !taken {
            assert!(
                power.tell_outcome(reward, &error).is_err(),
                "reward {reward}, error {error:?} taken"
            );
            assert_eq!(power, before);
            continue;
        }
        power
            .tell_outcome(reward, &error)
            .expect("a valid outcome is taken");
        asked_untold = false;
        rewards.push(reward);
        assert!(power.mean().iter().all(|v| v.is_finite()));
        let kept: Vec<f32> = power.sampler().map(|(_, r)| r).collect();
        let mut best = rewards.clone();
        best.sort_by(|a, b| b.total_cmp(a));
        best.truncate(cfg.sampler);
        assert_eq!(kept, best);
        assert_eq!(power.best().map(|b| b.reward), best.first().copied());
    }
    Ok(())
}

fuzz_target!(|data: &[u8]| {
    let _ = run(&mut Unstructured::new(data));
});
