//! What a pour learns and how: the learner, the bottle, the target, the
//! budget and the search, checked before anything runs; and the
//! learner's setup for them.

use primo_core::power::{PAPER_SAMPLER, PowerConfig};
use primo_protocol::learner::{LearnerSetup, Setup};
use primo_skill::Skill;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;
use crate::error::Setting;
use crate::learner::{QUERY_DECAY, power_blocks, setup as learner_setup, wire_query};
use crate::rollouts::MAX_ROLLOUTS;

/// What to learn and how.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    /// The learner.
    pub method: Algorithm,
    /// Liquid in the bottle, l.
    pub bottle: f64,
    /// Volume to pour, l.
    pub target: f64,
    /// Seed of exploration and of the scale's noise.
    pub seed: u64,
    /// Roll-out budget.
    pub max_rollouts: u32,
    /// Error learning stops at |error| < precision, l.
    pub precision: f64,
    /// Query search limits for error learning, l.
    pub search: [f32; 2],
    /// What the glass holds, l, if known: error learning then tries no
    /// query that would let more than that leave the bottle
    /// ([`Settings::search_bounds`]).
    #[serde(default)]
    pub glass_holds: Option<f64>,
    /// The error learners' first (fixed-gain: only) gain `K = gain · I`.
    pub gain: f32,
    /// PoWER exploration scales s1 (query; 0 is ordinary PoWER) and s2 (Δθ).
    pub s1: f32,
    /// See `s1`.
    pub s2: f32,
    /// PoWER's importance sampler length (runs logged before it was a
    /// setting had the paper's 3).
    #[serde(default = "paper_sampler")]
    pub sampler: usize,
}

fn paper_sampler() -> usize {
    PAPER_SAMPLER
}

impl Settings {
    /// The paper's settings for `method`: golden section from the bottle's
    /// volume within [0.1, 1.5] l to 2 ml; PoWER with s1 = 0.2, s2 = 0.05
    /// (with an error-learned query s1 = 0: the error moves the query).
    pub fn paper(method: Algorithm, bottle: f64, target: f64, seed: u64) -> Self {
        Settings {
            method,
            bottle,
            target,
            seed,
            max_rollouts: match method.is_power() {
                true => 200,
                false => 30,
            },
            precision: 0.002,
            search: [0.1, 1.5],
            glass_holds: None,
            gain: 1.0,
            s1: method.default_s1(),
            s2: 0.05,
            sampler: method.default_sampler(),
        }
    }

    /// The queries error learning may try: `search`, its low end raised
    /// so that the glass does not overflow. The skill pours what the
    /// demonstrations poured (the target) from a bottle holding `q̂`: it
    /// tilts until `q̂ − target` would remain, so from the bottle's actual
    /// volume `bottle − q̂ + target` leaves it, which the glass holds while
    /// `q̂ ≥ bottle + target − glass_holds`.
    pub fn search_bounds(&self) -> [f32; 2] {
        let [low, high] = self.search;
        match self.glass_holds {
            Some(holds) => [low.max((self.bottle + self.target - holds) as f32), high],
            None => [low, high],
        }
    }

    /// Checks every setting before anything runs; the error names the
    /// setting and what it must be.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |setting, value: &dyn std::fmt::Display, why: String| {
            Err(Error::setting(setting, value, why))
        };
        if self.method.learns_goals() {
            return bad(
                Setting::Method,
                &self.method,
                "learns the goals of a task file's demonstrations; the pour learns the bottle's \
                 volume (golden, illinois, secant, fixed-gain, weighted-gain, power, power-el)"
                    .into(),
            );
        }
        let [low, high] = self.search;
        if !(low.is_finite() && high.is_finite() && 0.0 < low && low < high) {
            return bad(
                Setting::Search,
                &format_args!("{low},{high}"),
                "must be two volumes in litres, 0 < low < high".into(),
            );
        }
        if !(self.bottle.is_finite() && self.bottle > 0.0) {
            return bad(
                Setting::Bottle,
                &self.bottle,
                "must be a positive volume in litres".into(),
            );
        }
        let bracket = f64::from(low)..f64::from(high);
        let inside = bracket.contains(&self.bottle) && self.bottle > f64::from(low);
        if !(self.method.is_power() || inside) {
            return bad(
                Setting::Bottle,
                &self.bottle,
                format!(
                    "error learning searches the query within ({low}, {high}) l, and starts \
                     from the bottle's volume: it must lie inside"
                ),
            );
        }
        check_target(self.bottle, self.target)?;
        if let Some(holds) = self.glass_holds {
            if !(holds.is_finite() && holds > 0.0) {
                return bad(
                    Setting::GlassHolds,
                    &holds,
                    "must be a positive volume in litres".into(),
                );
            }
            // The learner's bounds are f32: there the raised low end must
            // stay below the bottle too.
            let raised = (self.bottle + self.target - holds) as f32;
            if holds <= self.target || raised >= self.bottle as f32 {
                return Err(Error::Conflict {
                    setting: Setting::Target,
                    value: self.target.to_string(),
                    other: Setting::GlassHolds,
                    other_value: format!("{holds:.3}"),
                    why: "the glass holds no more than the target".into(),
                });
            }
        }
        // The glass raises the search's low end to bottle + target − holds,
        // below the bottle (the glass holds more than the target): the
        // bottle, where error learning starts, stays inside.
        // The learners take it as f32: it must stay positive and finite there.
        let precision = self.precision as f32;
        if !(precision.is_finite() && precision > 0.0) {
            return bad(
                Setting::Precision,
                &self.precision,
                "must be a positive volume in litres".into(),
            );
        }
        if !(1..=MAX_ROLLOUTS).contains(&self.max_rollouts) {
            return bad(
                Setting::MaxRollouts,
                &self.max_rollouts,
                format!("must be from 1 to {MAX_ROLLOUTS} roll-outs"),
            );
        }
        if !(self.gain.is_finite() && self.gain != 0.0) {
            return bad(
                Setting::Gain,
                &self.gain,
                "must be a finite number other than 0".into(),
            );
        }
        if !(1..=primo_learner::SAMPLER).contains(&self.sampler) {
            return bad(
                Setting::Sampler,
                &self.sampler,
                format!(
                    "must be from 1 to {} roll-outs in PoWER's importance sampler",
                    primo_learner::SAMPLER
                ),
            );
        }
        for (flag, s) in [("s1", self.s1), ("s2", self.s2)] {
            if !(s.is_finite() && s >= 0.0) {
                return Err(Error::Invalid(format!(
                    "PoWER's {flag} {s}: must be finite and >= 0"
                )));
            }
        }
        Ok(())
    }
}

/// The volume to pour: above 0 and below what the bottle holds.
pub fn check_target(bottle: f64, target: f64) -> Result<(), Error> {
    if !(target.is_finite() && target > 0.0 && target < bottle) {
        return Err(Error::setting(
            Setting::Target,
            target,
            format!("must be above 0 and below the bottle's {bottle} l"),
        ));
    }
    Ok(())
}

/// The learner's setup for a pouring run of `s` on `skill`.
pub fn setup(skill: &Skill, s: &Settings) -> Result<Setup, Error> {
    let bottle = [s.bottle as f32];
    let bounds = s.search_bounds();
    let search = (&bounds[..1], &bounds[1..], &bottle[..]);
    let learner = match s
        .method
        .search(search, s.precision as f32, s.max_rollouts, s.gain)?
    {
        Some(learner) => learner,
        None => LearnerSetup::Power {
            config: PowerConfig {
                query_gain: s.method.query_gain(s.gain),
                sampler: s.sampler,
                ..PowerConfig::paper(&power_blocks(skill, s.s1, s.s2, QUERY_DECAY)?)
                    .map_err(|e| Error::Invalid(format!("PoWER: {e}")))?
            },
            query: wire_query(&bottle)?,
        },
    };
    learner_setup(skill, learner, s.seed)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pour::skill::Space;
    use crate::pour::skill::built_in_skill;
    use primo_sim::cell::CellConfig;
    use primo_sim::cell::GlassKind;

    /// Secant-goals learns a task file's goals; the pour has none to offer.
    #[test]
    fn the_pour_refuses_secant_goals_by_its_setting() {
        let e = Settings::paper(Algorithm::SecantGoals, 0.5, 0.2, 1)
            .validate()
            .unwrap_err();
        assert!(
            matches!(
                e,
                Error::Setting {
                    setting: Setting::Method,
                    ..
                }
            ),
            "{e}"
        );
        assert!(
            e.to_string()
                .starts_with("method secant-goals: learns the goals"),
            "{e}"
        );
    }

    /// A glass that holds more than the target by less than f32 resolves
    /// is refused, not by the learner once the run has started.
    #[test]
    fn a_glass_that_holds_the_target_but_for_f32_rounding_is_refused() {
        let mut s = Settings::paper(Algorithm::Golden, 0.5, 1e-41, 1);
        s.glass_holds = Some(1e-40);
        let e = s.validate().unwrap_err();
        assert!(
            matches!(
                e,
                Error::Conflict {
                    setting: Setting::Target,
                    other: Setting::GlassHolds,
                    ..
                }
            ),
            "{e}"
        );
    }

    /// PoWER averages the paper's 3 best roll-outs, power-el its 2 best
    /// unless told otherwise; the setup carries what the settings say.
    #[test]
    fn the_importance_sampler_follows_the_method_and_the_setting() {
        let cell = CellConfig::standard(GlassKind::Small);
        let skill = built_in_skill(&cell, Space::Joint, 10).unwrap();
        let sampler = |s: &Settings| match setup(&skill, s).unwrap().learner {
            LearnerSetup::Power { config, .. } => config.sampler,
            other => panic!("{other:?}"),
        };
        let power = Settings::paper(Algorithm::Power, 0.5, 0.2, 1);
        let mut el = Settings::paper(Algorithm::PowerEl, 0.5, 0.2, 1);
        assert_eq!((sampler(&power), sampler(&el)), (3, 2));
        el.sampler = 3;
        assert_eq!(sampler(&el), 3);
        el.sampler = 0;
        let e = el.validate().unwrap_err();
        assert!(
            e.to_string().starts_with("sampler 0: must be from 1 to 3"),
            "{e}"
        );
        // A run logged before the sampler was a setting ran the paper's 3.
        let mut logged =
            serde_json::to_value(Settings::paper(Algorithm::PowerEl, 0.5, 0.2, 1)).unwrap();
        logged.as_object_mut().unwrap().remove("sampler");
        let resumed: Settings = serde_json::from_value(logged).unwrap();
        assert_eq!(resumed.sampler, 3);
    }

    #[test]
    fn power_blocks_explore_a_fraction_of_each_blocks_spread() {
        let cell = CellConfig::standard(GlassKind::Small);
        let skill = built_in_skill(&cell, Space::Joint, 10).unwrap();
        let blocks = power_blocks(&skill, 0.2, 0.05, QUERY_DECAY).unwrap();
        assert_eq!(blocks.len(), 1 + skill.dof() + 2);
        let lens: Vec<usize> = blocks.iter().map(|b| b.len).collect();
        assert_eq!(lens[1..=skill.dof()], vec![skill.kernels(); skill.dof()]);
        assert_eq!(lens.iter().sum::<usize>(), skill.param_len() + 1);
        // The query: σ1 = s1·|1.0 l − 0.3 l|, decaying.
        assert!((blocks[0].variance.sqrt() - 0.14).abs() < 1e-6);
        assert_eq!(blocks[0].decay, QUERY_DECAY);
        // Every other block: σ = s2 × the examples' RMS difference over it.
        let ex: Vec<&[f32]> = skill.examples().map(|(_, t)| t).collect();
        let mut start = 0;
        for b in &blocks[1..] {
            let rms = ((start..start + b.len)
                .map(|j| (ex[0][j] - ex[1][j]).powi(2))
                .sum::<f32>()
                / b.len as f32)
                .sqrt();
            assert!(
                (b.variance.sqrt() - 0.05 * rms).abs() <= 1e-5 * rms,
                "{b:?}"
            );
            assert_eq!(b.decay, 1.0);
            start += b.len;
        }
        // Ordinary PoWER explores no query.
        assert_eq!(
            power_blocks(&skill, 0.0, 0.05, QUERY_DECAY).unwrap()[0].variance,
            0.0
        );
    }
}
