//! PoWER (Kober & Peters 2009) over the paper's extended parameter set
//! `θ* = [q̂, Δθ]` (Sec. V), as an ask/tell state machine.
//!
//! - **Blocks.** The parameter vector is split into contiguous blocks, each
//!   with its own exploration variance `σ_b²` and per-update decay factor.
//!   The paper uses two: the query `q̂` (`σ1² = s1·max|q_i − q_j|`, decaying)
//!   and `Δθ` (`σ2² = s2·max‖θ_i − θ_j‖`); [`exploration_variance`] computes
//!   `s·max_ij ‖x_i − x_j‖` from the training examples, [`widest_distance`]
//!   the distance alone (for callers that scale it differently). Ordinary
//!   PoWER is the same with `s1 = 0`.
//! - **Roll-outs.** Each update rolls out the current mean once (optional:
//!   it measures the policy being learned and feeds the sampler like any
//!   roll-out), then `rollouts_per_update` explorations
//!   `θ*_i = θ*_m + ε_i`, `ε_i ~ N(0, diag σ_b²)`.
//! - **Update.** Over the importance sampler, the best `sampler` roll-outs
//!   seen so far (ties keep the older), `θ*_{m+1} = θ*_m + Σ (θ*_i − θ*_m) r_i
//!   / Σ r_i`. This is the paper's rule: rewards enter linearly (no
//!   exponent), the sampler keeps the best L = 3 rather than Kober's best 10,
//!   and variances follow the fixed schedule rather than being re-estimated.
//! - **Error-learned query** (optional, `query_gain ≠ 0`): the paper's
//!   error learning (Sec. IV, eq. 10) inside PoWER. A roll-out told with
//!   its error `ε` ([`Power::tell_outcome`]) enters the sampler with its
//!   query entries corrected to `q̂ + K ε`, the query that would have
//!   given the right outcome to first order, so the update moves `q̂` by
//!   what the error says rather than by what exploring `q̂` happened to
//!   find. The reward still ranks and weights the roll-outs.
//! - **Rewards** must be finite and ≥ 0; anything else is an error that
//!   changes nothing. If every reward in the sampler is 0 the mean stays.
//!   The weights are the rewards divided by the best one, so no sum
//!   overflows whatever their scale.
//! - **Bounds**: initial parameters within ±[`MAX_ABS_PARAM`], variances
//!   within [`MAX_VARIANCE`], so exploration never overflows `f32`.
//!
//! The learner's state serializes (for logs); it is rebuilt, not
//! deserialized: the same settings, seed and rewards give the same state.
//!
//! The same seed and the same rewards give the same bits on every target.
//!
//! ```
//! use primo_core::power::{Block, Power, PowerConfig};
//! let cfg = PowerConfig::paper(&[Block { len: 2, variance: 0.04, decay: 1.0 }])?;
//! let mut power = Power::<2, 3>::new(&[1.0, -1.0], cfg, 42)?;
//! for _ in 0..200 {
//!     let theta = power.ask();
//!     let cost = theta[0] * theta[0] + theta[1] * theta[1];
//!     power.tell(1.0 / (1.0 + cost))?;
//! }
//! assert!(power.mean()[0].abs() < 0.3 && power.mean()[1].abs() < 0.3);
//! # Ok::<(), primo_core::Error>(())
//! ```

use heapless::Vec;
use rand_core::SeedableRng;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::error::{check_bounded, check_capacity, check_finite, check_len};
use crate::normal::StandardNormal;
use crate::rng::Xoshiro128PlusPlus;

/// At most this many exploration blocks: room for the query, one block of
/// kernel weights per joint of a 7-DoF arm, the goals and τ. Kept small:
/// the coprocessor holds the configuration and receives it in one frame.
pub const MAX_BLOCKS: usize = 10;
/// Largest |initial parameter|.
pub const MAX_ABS_PARAM: f32 = 1e9;
/// Largest block variance.
pub const MAX_VARIANCE: f32 = 1e12;
/// The paper's importance sampler length L.
pub const PAPER_SAMPLER: usize = 3;

/// One contiguous block of the parameter vector.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Block {
    /// Number of parameters in the block.
    pub len: usize,
    /// Exploration variance `σ²` at the first update (≥ 0).
    pub variance: f32,
    /// Factor applied to the variance after each update, in (0, 1].
    pub decay: f32,
}

/// PoWER settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PowerConfig {
    /// Blocks in order; their lengths add up to the parameter count.
    pub blocks: Vec<Block, MAX_BLOCKS>,
    /// Exploration roll-outs per update (≥ 1); the paper uses 3.
    pub rollouts_per_update: u16,
    /// Also roll out the unperturbed mean once per update (the paper's 4th).
    pub roll_out_mean: bool,
    /// Importance sampler length L (1 ≤ L ≤ the capacity); the paper uses 3.
    pub sampler: usize,
    /// The error-learning gain `K` on the query entries (finite; 0: off,
    /// the paper's PoWER).
    pub query_gain: f32,
}

impl PowerConfig {
    /// The paper's settings for these blocks: 3 exploration roll-outs plus
    /// the mean per update, importance sampler of 3.
    pub fn paper(blocks: &[Block]) -> Result<Self, Error> {
        Ok(Self {
            blocks: Vec::from_slice(blocks).map_err(|_| Error::Capacity {
                what: "blocks",
                requested: blocks.len(),
                capacity: MAX_BLOCKS,
            })?,
            rollouts_per_update: 3,
            roll_out_mean: true,
            sampler: PAPER_SAMPLER,
            query_gain: 0.0,
        })
    }
}

/// `s · max_ij ‖x_i − x_j‖` over the examples, each restricted to
/// `range`: the paper's exploration variance for a block.
pub fn exploration_variance<'a>(
    s: f32,
    examples: impl Iterator<Item = &'a [f32]> + Clone,
    range: core::ops::Range<usize>,
) -> Result<f32, Error> {
    if !(s >= 0.0 && s.is_finite()) {
        return Err(Error::OutOfRange(
            "exploration scale s must be finite and >= 0",
        ));
    }
    let v = s * widest_distance(examples, range)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(Error::NotFinite("exploration variance"))
    }
}

/// `max_ij ‖x_i − x_j‖` over the examples, each restricted to `range`
/// (0 for fewer than two examples).
pub fn widest_distance<'a>(
    examples: impl Iterator<Item = &'a [f32]> + Clone,
    range: core::ops::Range<usize>,
) -> Result<f32, Error> {
    let mut widest = 0.0f32;
    for (i, a) in examples.clone().enumerate() {
        let a = a
            .get(range.clone())
            .ok_or(Error::OutOfRange("block range beyond an example"))?;
        check_finite(a, "example parameters")?;
        for b in examples.clone().skip(i + 1) {
            let b = b
                .get(range.clone())
                .ok_or(Error::OutOfRange("block range beyond an example"))?;
            let d2: f32 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
            widest = widest.max(libm::sqrtf(d2));
        }
    }
    if widest.is_finite() {
        Ok(widest)
    } else {
        Err(Error::NotFinite("distance between examples"))
    }
}

/// A past roll-out in the importance sampler.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct Rollout<const P: usize> {
    #[serde(with = "serde_array")]
    params: [f32; P],
    reward: f32,
}

/// The best roll-out so far.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BestRollout<'a> {
    /// Its parameters.
    pub params: &'a [f32],
    /// Its reward.
    pub reward: f32,
}

/// PoWER with capacity `P` parameters and an importance sampler of at most
/// `L` roll-outs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Power<const P: usize, const L: usize> {
    cfg: PowerConfig,
    n: usize,
    #[serde(with = "serde_array")]
    mean: [f32; P],
    #[serde(with = "serde_array")]
    current: [f32; P],
    /// Whether `current` has been drawn and not yet told.
    pending: bool,
    /// Current variance per block (decayed).
    variance: Vec<f32, MAX_BLOCKS>,
    /// Roll-outs told in the current update.
    in_update: u32,
    updates: u32,
    sampler: Vec<Rollout<P>, L>,
    best: Option<Rollout<P>>,
    rng: Xoshiro128PlusPlus,
    normal: StandardNormal,
}

impl<const P: usize, const L: usize> Power<P, L> {
    /// Starts from `initial` (e.g. `[q0, 0, …, 0]`) with a seeded generator.
    pub fn new(initial: &[f32], cfg: PowerConfig, seed: u64) -> Result<Self, Error> {
        let mut power = Self::idle();
        power.reset(initial, cfg, seed)?;
        Ok(power)
    }

    /// A learner with no parameters, all zero bytes: a static holding it
    /// needs no flash image. [`Power::reset`] configures it.
    pub const fn idle() -> Self {
        Self {
            cfg: PowerConfig {
                blocks: Vec::new(),
                rollouts_per_update: 0,
                roll_out_mean: false,
                sampler: 0,
                query_gain: 0.0,
            },
            n: 0,
            mean: [0.0; P],
            current: [0.0; P],
            pending: false,
            variance: Vec::new(),
            in_update: 0,
            updates: 0,
            sampler: Vec::new(),
            best: None,
            rng: Xoshiro128PlusPlus::unseeded(),
            normal: StandardNormal::new(),
        }
    }

    /// [`Power::new`] in place, without a second copy of the buffers (a
    /// coprocessor's stack has no room for one). On error nothing changes.
    pub fn reset(&mut self, initial: &[f32], cfg: PowerConfig, seed: u64) -> Result<(), Error> {
        let n = initial.len();
        if n == 0 {
            return Err(Error::OutOfRange("PoWER needs at least one parameter"));
        }
        check_capacity("parameters", n, P)?;
        check_bounded(
            initial,
            MAX_ABS_PARAM,
            "initial parameters beyond ±1e9, the bound on any parameter",
        )?;
        let total = cfg
            .blocks
            .iter()
            .try_fold(0usize, |acc, b| acc.checked_add(b.len));
        check_len("sum of block lengths", n, total.unwrap_or(usize::MAX))?;
        for b in &cfg.blocks {
            if !(b.variance >= 0.0 && b.variance <= MAX_VARIANCE) {
                return Err(Error::OutOfRange("block variance must be in [0, 1e12]"));
            }
            if !(b.decay > 0.0 && b.decay <= 1.0) {
                return Err(Error::OutOfRange("block decay must be in (0, 1]"));
            }
        }
        if cfg.rollouts_per_update == 0 {
            return Err(Error::OutOfRange("rollouts_per_update must be >= 1"));
        }
        if cfg.sampler == 0 {
            return Err(Error::OutOfRange("sampler length must be >= 1"));
        }
        check_capacity("sampler length", cfg.sampler, L)?;
        if !cfg.query_gain.is_finite() {
            return Err(Error::NotFinite("query gain"));
        }
        self.mean = [0.0; P];
        self.mean.iter_mut().zip(initial).for_each(|(m, v)| *m = *v);
        self.current = self.mean;
        self.variance = cfg.blocks.iter().map(|b| b.variance).collect();
        self.cfg = cfg;
        self.n = n;
        self.pending = false;
        self.in_update = 0;
        self.updates = 0;
        self.sampler.clear();
        self.best = None;
        self.rng = Xoshiro128PlusPlus::seed_from_u64(seed);
        self.normal = StandardNormal::new();
        Ok(())
    }

    /// Roll-outs per update, counting the mean's.
    fn per_update(&self) -> u32 {
        u32::from(self.cfg.rollouts_per_update) + u32::from(self.cfg.roll_out_mean)
    }

    /// Whether the next roll-out of this update is the unperturbed mean.
    pub fn next_is_mean(&self) -> bool {
        self.cfg.roll_out_mean && self.in_update == 0
    }

    /// The parameters to roll out next. Asking again before
    /// [`Power::tell`] returns the same vector.
    pub fn ask(&mut self) -> &[f32] {
        if !self.pending {
            self.current = self.mean;
            if !self.next_is_mean() {
                let mut start = 0;
                for (block, var) in self.cfg.blocks.iter().zip(&self.variance) {
                    let sigma = libm::sqrtf(*var);
                    let end = (start + block.len).min(P);
                    for c in self.current.get_mut(start..end).unwrap_or(&mut []) {
                        *c += sigma * self.normal.sample(&mut self.rng);
                    }
                    start = end;
                }
            }
            self.pending = true;
        }
        self.current.get(..self.n).unwrap_or(&[])
    }

    /// Reports the reward of the asked roll-out: finite and ≥ 0, otherwise
    /// an error and nothing changes. Returns `true` when this completed an
    /// update (the mean moved).
    pub fn tell(&mut self, reward: f32) -> Result<bool, Error> {
        self.tell_outcome(reward, &[])
    }

    /// [`Power::tell`] with the roll-out's error `ε` on its first
    /// `error.len()` parameters (the query; `ε_i > 0` asks for a larger
    /// `q_i`), which the query gain corrects (none when the gain is 0).
    /// An error that is not finite, longer than the parameters, or
    /// corrects a parameter beyond ±[`MAX_ABS_PARAM`] changes nothing.
    pub fn tell_outcome(&mut self, reward: f32, error: &[f32]) -> Result<bool, Error> {
        if !self.pending {
            return Err(Error::BadState("tell() without a preceding ask()"));
        }
        if !reward.is_finite() {
            return Err(Error::NotFinite("reward"));
        }
        if reward < 0.0 {
            return Err(Error::OutOfRange("reward must be >= 0"));
        }
        let mut params = self.current;
        if self.cfg.query_gain != 0.0 {
            check_capacity("error values", error.len(), self.n)?;
            check_finite(error, "error")?;
            for (p, e) in params.iter_mut().zip(error) {
                *p += self.cfg.query_gain * e;
            }
            check_bounded(
                params.get(..error.len()).unwrap_or(&[]),
                MAX_ABS_PARAM,
                "corrected query beyond ±1e9, the bound on any parameter",
            )?;
        }
        self.pending = false;
        let rollout = Rollout { params, reward };
        if self.best.as_ref().is_none_or(|b| reward > b.reward) {
            self.best = Some(rollout.clone());
        }
        self.insert(rollout);
        self.in_update += 1;
        if self.in_update < self.per_update() {
            return Ok(false);
        }
        self.in_update = 0;
        self.update();
        Ok(true)
    }

    /// Keeps the sampler sorted by descending reward, at most `cfg.sampler`
    /// long; an equal reward goes after the older ones.
    fn insert(&mut self, rollout: Rollout<P>) {
        let at = self
            .sampler
            .iter()
            .position(|r| rollout.reward > r.reward)
            .unwrap_or(self.sampler.len());
        if at >= self.cfg.sampler {
            return;
        }
        if self.sampler.len() >= self.cfg.sampler {
            self.sampler.pop();
        }
        // Cannot fail: a slot was freed above if the sampler was full.
        let _ = self.sampler.insert(at, rollout);
    }

    fn update(&mut self) {
        // The sampler is sorted: its first reward is the largest.
        let best = self.sampler.first().map_or(0.0, |r| r.reward);
        if best > 0.0 {
            let total: f32 = self.sampler.iter().map(|r| r.reward / best).sum();
            let mut step = [0.0f32; P];
            for r in &self.sampler {
                let w = r.reward / best;
                for ((s, p), m) in step.iter_mut().zip(&r.params).zip(&self.mean).take(self.n) {
                    *s += (p - m) * w;
                }
            }
            for (m, s) in self.mean.iter_mut().zip(step).take(self.n) {
                *m += s / total;
            }
        }
        for (v, b) in self.variance.iter_mut().zip(&self.cfg.blocks) {
            *v *= b.decay;
        }
        self.updates = self.updates.saturating_add(1);
    }

    /// The current mean `θ*_m`.
    pub fn mean(&self) -> &[f32] {
        self.mean.get(..self.n).unwrap_or(&[])
    }

    /// The error-learning gain on the query (0: off).
    pub fn query_gain(&self) -> f32 {
        self.cfg.query_gain
    }

    /// Completed updates.
    pub fn updates(&self) -> u32 {
        self.updates
    }

    /// Current exploration variance of each block.
    pub fn variances(&self) -> &[f32] {
        &self.variance
    }

    /// The importance sampler, best first: `(parameters, reward)`.
    pub fn sampler(&self) -> impl Iterator<Item = (&[f32], f32)> {
        self.sampler
            .iter()
            .map(|r| (r.params.get(..self.n).unwrap_or(&[]), r.reward))
    }

    /// The best roll-out so far (with a query gain, its query corrected).
    pub fn best(&self) -> Option<BestRollout<'_>> {
        self.best.as_ref().map(|r| BestRollout {
            params: r.params.get(..self.n).unwrap_or(&[]),
            reward: r.reward,
        })
    }
}

/// Serializes `[f32; P]` of any `P` (serde's derive stops at 32) as a tuple,
/// so postcard writes no length.
mod serde_array {
    use serde::Serializer;
    use serde::ser::SerializeTuple;

    pub fn serialize<S: Serializer, const P: usize>(a: &[f32; P], s: S) -> Result<S::Ok, S::Error> {
        let mut t = s.serialize_tuple(P)?;
        for v in a {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(blocks: &[Block], sampler: usize) -> PowerConfig {
        PowerConfig {
            sampler,
            ..PowerConfig::paper(blocks).unwrap()
        }
    }

    #[test]
    fn converges_on_a_quadratic_bowl() {
        let optimum = [0.7f32, -0.4, 0.2, 1.1];
        let reward = |t: &[f32]| {
            let c: f32 = t.iter().zip(&optimum).map(|(a, b)| (a - b) * (a - b)).sum();
            libm::expf(-4.0 * c)
        };
        let c = cfg(
            &[Block {
                len: 4,
                variance: 0.05,
                decay: 0.98,
            }],
            3,
        );
        let mut p = Power::<4, 3>::new(&[0.0; 4], c, 9).unwrap();
        let start = reward(p.mean());
        for _ in 0..400 {
            let r = reward(p.ask());
            p.tell(r).unwrap();
        }
        let end = reward(p.mean());
        assert_eq!(p.updates(), 100);
        assert!(
            end > 0.97 && end > start,
            "reward {start} -> {end}, mean {:?}",
            p.mean()
        );
    }

    #[test]
    fn sampler_keeps_exactly_the_best_l() {
        let c = cfg(
            &[Block {
                len: 1,
                variance: 1.0,
                decay: 1.0,
            }],
            3,
        );
        let mut p = Power::<1, 4>::new(&[0.0], c, 1).unwrap();
        let rewards = [0.5, 0.1, 0.9, 0.3, 0.9, 0.2, 0.7, 0.05];
        let mut seen = std::vec::Vec::new();
        for r in rewards {
            let theta = p.ask()[0];
            p.tell(r).unwrap();
            seen.push((r, theta));
        }
        // Stable sort by descending reward: ties keep the older first.
        seen.sort_by(|a, b| b.0.partial_cmp(&a.0).unwrap());
        let kept: std::vec::Vec<(f32, f32)> = p.sampler().map(|(t, r)| (r, t[0])).collect();
        assert_eq!(kept, seen[..3].to_vec());
    }

    #[test]
    fn blocks_explore_with_their_own_variance() {
        let c = PowerConfig {
            blocks: Vec::from_slice(&[
                Block {
                    len: 1,
                    variance: 0.25,
                    decay: 1.0,
                },
                Block {
                    len: 3,
                    variance: 0.0004,
                    decay: 1.0,
                },
            ])
            .unwrap(),
            rollouts_per_update: 3,
            roll_out_mean: false,
            sampler: 3,
            query_gain: 0.0,
        };
        let mut p = Power::<4, 3>::new(&[0.0; 4], c, 5).unwrap();
        let (mut s_q, mut s_w, mut count) = (0.0f64, 0.0f64, 0);
        for _ in 0..6000 {
            let t = p.ask();
            s_q += (t[0] as f64).powi(2);
            s_w += t[1..].iter().map(|v| (*v as f64).powi(2)).sum::<f64>() / 3.0;
            count += 1;
            // Reward 0 keeps the mean at the origin: pure exploration noise.
            p.tell(0.0).unwrap();
        }
        assert_eq!(p.mean(), &[0.0; 4]);
        let (vq, vw) = (s_q / count as f64, s_w / count as f64);
        assert!((vq / 0.25 - 1.0).abs() < 0.06, "query block variance {vq}");
        assert!((vw / 0.0004 - 1.0).abs() < 0.06, "Δθ block variance {vw}");
    }

    #[test]
    fn mean_rollout_comes_first_and_variance_decays() {
        let c = cfg(
            &[Block {
                len: 2,
                variance: 1.0,
                decay: 0.5,
            }],
            3,
        );
        let mut p = Power::<2, 3>::new(&[3.0, 4.0], c, 2).unwrap();
        assert!(p.next_is_mean());
        assert_eq!(p.ask(), &[3.0, 4.0]);
        assert_eq!(
            p.ask(),
            &[3.0, 4.0],
            "asking twice returns the same roll-out"
        );
        for _ in 0..4 {
            p.ask();
            p.tell(0.5).unwrap();
        }
        assert_eq!(p.updates(), 1);
        assert_eq!(p.variances(), &[0.5]);
    }

    #[test]
    fn invalid_rewards_are_errors_and_change_nothing() {
        let c = cfg(
            &[Block {
                len: 2,
                variance: 1.0,
                decay: 1.0,
            }],
            3,
        );
        let mut p = Power::<2, 3>::new(&[1.0, 2.0], c, 3).unwrap();
        assert!(p.tell(1.0).is_err(), "tell before ask");
        p.ask();
        p.ask();
        let before = p.clone();
        for r in [-0.1, f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
            assert!(p.tell(r).is_err());
            assert_eq!(p, before);
        }
    }

    #[test]
    fn extreme_settings_are_errors_or_work_without_overflow() {
        let huge = [
            Block {
                len: usize::MAX,
                variance: 1.0,
                decay: 1.0,
            },
            Block {
                len: 2,
                variance: 1.0,
                decay: 1.0,
            },
        ];
        assert!(Power::<2, 3>::new(&[0.0; 2], cfg(&huge, 3), 0).is_err());
        let mut c = cfg(
            &[Block {
                len: 1,
                variance: 1.0,
                decay: 1.0,
            }],
            3,
        );
        c.rollouts_per_update = u16::MAX;
        let mut p = Power::<1, 3>::new(&[0.0], c, 0).unwrap();
        for _ in 0..10 {
            p.ask();
            p.tell(1.0).unwrap();
        }
        assert_eq!(p.updates(), 0);
    }

    #[test]
    fn huge_rewards_do_not_overflow() {
        let c = cfg(
            &[Block {
                len: 2,
                variance: 1.0,
                decay: 1.0,
            }],
            3,
        );
        let mut p = Power::<2, 3>::new(&[1.0, 2.0], c, 6).unwrap();
        for _ in 0..8 {
            p.ask();
            p.tell(3e38).unwrap();
        }
        assert!(p.mean().iter().all(|v| v.is_finite()), "{:?}", p.mean());
        assert!(
            Power::<2, 3>::new(
                &[2e9, 0.0],
                cfg(
                    &[Block {
                        len: 2,
                        variance: 1.0,
                        decay: 1.0
                    }],
                    3
                ),
                0
            )
            .is_err()
        );
        assert!(
            Power::<2, 3>::new(
                &[0.0, 0.0],
                cfg(
                    &[Block {
                        len: 2,
                        variance: 1e13,
                        decay: 1.0
                    }],
                    3
                ),
                0
            )
            .is_err()
        );
    }

    #[test]
    fn all_zero_rewards_leave_the_mean() {
        let c = cfg(
            &[Block {
                len: 2,
                variance: 1.0,
                decay: 1.0,
            }],
            3,
        );
        let mut p = Power::<2, 3>::new(&[1.0, 2.0], c, 4).unwrap();
        for _ in 0..40 {
            p.ask();
            p.tell(0.0).unwrap();
        }
        assert_eq!(p.updates(), 10);
        assert_eq!(p.mean(), &[1.0, 2.0]);
    }

    #[test]
    fn same_seed_same_sequence_and_state_serializes() {
        let run = |seed| {
            let c = cfg(
                &[Block {
                    len: 3,
                    variance: 0.1,
                    decay: 0.9,
                }],
                3,
            );
            let mut p = Power::<3, 3>::new(&[0.0; 3], c, seed).unwrap();
            let mut out = std::vec::Vec::new();
            for i in 0..20 {
                let t = p.ask().to_vec();
                p.tell(1.0 / (1.0 + t.iter().map(|v| v * v).sum::<f32>() + i as f32 * 0.01))
                    .unwrap();
                out.extend(t.iter().map(|v| v.to_bits()));
            }
            (out, p)
        };
        let (a, pa) = run(11);
        let (b, _) = run(11);
        let (c, _) = run(12);
        assert_eq!(a, b);
        assert_ne!(a, c);
        let json = serde_json::to_string(&pa).unwrap();
        assert!(json.contains("\"updates\":5"), "{json}");
    }

    #[test]
    fn exploration_variance_is_s_times_widest_distance() {
        let ex: [&[f32]; 3] = [&[0.0, 0.0, 5.0], &[3.0, 4.0, 5.0], &[1.0, 1.0, -5.0]];
        let v = exploration_variance(0.05, ex.iter().copied(), 0..2).unwrap();
        assert!((v - 0.25).abs() < 1e-6);
        let d = widest_distance(ex.iter().copied(), 0..2).unwrap();
        assert!((d - 5.0).abs() < 1e-6);
        let one: [&[f32]; 1] = [&[1.0, 2.0]];
        assert_eq!(widest_distance(one.iter().copied(), 0..2), Ok(0.0));
        let far: [&[f32]; 2] = [&[3e38, 0.0], &[-3e38, 0.0]];
        assert!(widest_distance(far.iter().copied(), 0..2).is_err());
        assert!(exploration_variance(0.2, ex.iter().copied(), 2..5).is_err());
        let nan: [&[f32]; 2] = [&[0.0, f32::NAN], &[1.0, 2.0]];
        assert!(exploration_variance(1.0, nan.iter().copied(), 0..2).is_err());
    }

    /// A task whose outcome is `q + d` (d: a disturbance Δθ cannot see)
    /// and whose reward only sees Δθ: with a query gain the mean's query
    /// goes where the error says, without exploring it.
    #[test]
    fn query_gain_moves_the_query_by_the_error() {
        let blocks = [
            Block {
                len: 1,
                variance: 0.0,
                decay: 1.0,
            },
            Block {
                len: 2,
                variance: 0.01,
                decay: 1.0,
            },
        ];
        let c = PowerConfig {
            query_gain: 1.0,
            ..cfg(&blocks, 3)
        };
        let mut p = Power::<3, 3>::new(&[0.0; 3], c, 3).unwrap();
        let (desired, disturbance) = (0.5f32, 0.2f32);
        for _ in 0..40 {
            let t = p.ask().to_vec();
            // ε = desired − outcome: > 0 asks for a larger query.
            let error = desired - (t[0] + disturbance);
            let reward = libm::expf(-(t[1] * t[1] + t[2] * t[2]));
            p.tell_outcome(reward, &[error]).unwrap();
        }
        assert!(
            (p.mean()[0] - (desired - disturbance)).abs() < 1e-5,
            "query {}",
            p.mean()[0]
        );
    }

    #[test]
    fn a_bad_error_changes_nothing() {
        let blocks = [Block {
            len: 2,
            variance: 0.1,
            decay: 1.0,
        }];
        let c = PowerConfig {
            query_gain: 2.0,
            ..cfg(&blocks, 3)
        };
        let mut p = Power::<2, 3>::new(&[0.0; 2], c, 3).unwrap();
        p.ask();
        let before = p.clone();
        for error in [&[f32::NAN][..], &[1.0, 2.0, 3.0], &[1e38]] {
            assert!(p.tell_outcome(0.5, error).is_err(), "{error:?}");
            assert_eq!(p, before);
        }
        assert!(p.tell_outcome(0.5, &[0.1]).is_ok());
    }
}
