//! The learning loop: the paper's learners (golden-section error learning,
//! its magnitude-using sibling Illinois, extended PoWER) driving roll-outs of
//! a [`Skill`] on a [`Rig`](crate::rig::Rig). The learners are the core's ask/tell state
//! machines behind the wire protocol's [`Service`], in this process or on a
//! coprocessor ([`Learner`]).
//!
//! Three separate pieces make a run: [`learn_on`] asks, rolls out (one
//! path: [`crate::rig::roll_out`]), tells; [`verify_replayed`] checks a
//! resumed run's learner against its log; and whoever calls [`learn_on`]
//! keeps each roll-out (the run log) as it comes.

use primo_core::golden::SearchConfig;
use primo_core::power::{Block, PowerConfig, widest_distance};
use primo_core::secant::{Rule, SecantConfig};
use primo_learner::Service;
use primo_protocol::learner::{
    CHUNK, LearnerSetup, MAX_QUERY, Outcome, Query, Reply, Request, Rollout, Setup, Status,
};
use std::path::Path;

use serde::{Deserialize, Serialize};

use primo_sim::cell::CellConfig;
use primo_skill::MAX_KERNELS;
use primo_skill::Skill;
use primo_skill::skill::{MAX_EXAMPLES, MAX_PARAMS};

use crate::Error;
use crate::coprocessor::Link;
use crate::rig::{Simulated, roll_out};
use crate::runlog::RunLog;
use crate::trial::Trial;

/// Capacity of the extended parameter vector `[q̂, Δθ]`.
pub const MAX_EXTENDED: usize = MAX_PARAMS + 1;
/// Per-update decay of the query's exploration variance σ1² (the paper
/// decays it "with time" without a number).
pub const QUERY_DECAY: f32 = 0.9;

/// The learning algorithm.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Algorithm {
    /// The paper's error learning with golden-section search on the query
    /// (one value).
    Golden,
    /// Error learning that also uses the error's magnitude (Illinois
    /// regula falsi), with the same bracket guarantee (one value).
    Illinois,
    /// Error learning on a query of any dimension, `q ← q + K ε` with the
    /// gain `K` learned from the roll-outs (Broyden; paper eq. 10).
    Secant,
    /// The paper's eq. 10 with a fixed gain `K = gain · I`.
    FixedGain,
    /// The paper's eq. 11, `q ← q + e^{−εᵀε} K ε`, `K = gain · I` fixed.
    WeightedGain,
    /// PoWER over the extended parameter set `[q̂, Δθ]`.
    Power,
    /// PoWER over `[q̂, Δθ]` whose query is learned from the error by the
    /// paper's eq. 10 (`K = gain`) instead of explored: error learning
    /// (Sec. IV) and PoWER (Sec. V) in one learner.
    PowerEl,
}

/// The error learners, in the order experiments report them.
pub const ERROR_LEARNERS: [Algorithm; 5] = [
    Algorithm::Golden,
    Algorithm::Illinois,
    Algorithm::Secant,
    Algorithm::FixedGain,
    Algorithm::WeightedGain,
];

impl Algorithm {
    /// How people call it.
    pub fn name(self) -> &'static str {
        match self {
            Algorithm::Golden => "golden-section error learning",
            Algorithm::Illinois => "Illinois error learning",
            Algorithm::Secant => "secant error learning",
            Algorithm::FixedGain => "fixed-gain error learning (eq. 10)",
            Algorithm::WeightedGain => "weighted fixed-gain error learning (eq. 11)",
            Algorithm::Power => "extended PoWER",
            Algorithm::PowerEl => "PoWER with error-learned query",
        }
    }

    /// PoWER (learns `Δθ` from rewards), not only the query.
    pub fn is_power(self) -> bool {
        matches!(self, Algorithm::Power | Algorithm::PowerEl)
    }

    /// Learns the query from the error (every learner but plain PoWER).
    pub fn uses_error(self) -> bool {
        self != Algorithm::Power
    }

    /// The space `primo pour` learns in by default: joint space for PoWER
    /// (the paper's second experiment), Cartesian for error learning.
    pub fn default_space(self) -> primo_skill::Space {
        match self.is_power() {
            true => primo_skill::Space::Joint,
            false => primo_skill::Space::Cartesian,
        }
    }

    /// PoWER's default query exploration scale s1: the paper's 0.2, and 0
    /// when the error moves the query instead.
    pub fn default_s1(self) -> f32 {
        match self {
            Algorithm::PowerEl => 0.0,
            _ => 0.2,
        }
    }

    /// PoWER's error-learning gain on the query for `gain` (0: plain PoWER).
    pub fn query_gain(self, gain: f32) -> f32 {
        match self {
            Algorithm::PowerEl => gain,
            _ => 0.0,
        }
    }

    /// Parameters it learns on `skill`: `[q̂, Δθ]` for PoWER, the query
    /// otherwise.
    pub fn learned_parameters(self, skill: &Skill) -> usize {
        match self {
            Algorithm::Power | Algorithm::PowerEl => skill.param_len() + skill.query_dim(),
            _ => skill.query_dim(),
        }
    }

    /// Its search core's setup, for the error learners over the bounds
    /// `low`, `high` from `desired` (one value each for golden section and
    /// Illinois); `None` for PoWER.
    pub fn search(
        self,
        (low, high, desired): (&[f32], &[f32], &[f32]),
        precision: f32,
        max_rollouts: u32,
        gain: f32,
    ) -> Result<Option<LearnerSetup>, Error> {
        let scalar = || SearchConfig {
            low: low.first().copied().unwrap_or(f32::NAN),
            high: high.first().copied().unwrap_or(f32::NAN),
            desired: desired.first().copied().unwrap_or(f32::NAN),
            precision,
            max_rollouts,
        };
        let secant = |rule| -> Result<LearnerSetup, Error> {
            Ok(LearnerSetup::Secant(SecantConfig {
                low: wire_query(low)?,
                high: wire_query(high)?,
                desired: wire_query(desired)?,
                precision,
                max_rollouts,
                gain,
                rule,
            }))
        };
        Ok(Some(match self {
            Algorithm::Golden => LearnerSetup::Golden(scalar()),
            Algorithm::Illinois => LearnerSetup::Illinois(scalar()),
            Algorithm::Secant => secant(Rule::Broyden)?,
            Algorithm::FixedGain => secant(Rule::Fixed)?,
            Algorithm::WeightedGain => secant(Rule::Weighted)?,
            Algorithm::Power | Algorithm::PowerEl => return Ok(None),
        }))
    }
}

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

    /// Checks every setting before anything runs; the message names the
    /// flag and what it must be.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |m: String| Err(Error::Invalid(m));
        let [low, high] = self.search;
        if !(low.is_finite() && high.is_finite() && 0.0 < low && low < high) {
            return bad(format!(
                "--search {low},{high}: must be two volumes in litres, 0 < low < high"
            ));
        }
        if !(self.bottle.is_finite() && self.bottle > 0.0) {
            return bad(format!(
                "--bottle {}: must be a positive volume in litres",
                self.bottle
            ));
        }
        let bracket = f64::from(low)..f64::from(high);
        let inside = bracket.contains(&self.bottle) && self.bottle > f64::from(low);
        if !(self.method.is_power() || inside) {
            return bad(format!(
                "--bottle {}: error learning searches the query within ({low}, {high}) l, \
                 and starts from the bottle's volume: it must lie inside",
                self.bottle
            ));
        }
        check_target(self.bottle, self.target)?;
        if let Some(holds) = self.glass_holds {
            if !(holds.is_finite() && holds > 0.0) {
                return bad(format!(
                    "--glass-holds {holds}: must be a positive volume in litres"
                ));
            }
            if holds <= self.target {
                return bad(format!(
                    "--target {} with --glass-holds {holds:.3}: the glass holds no more than \
                     the target",
                    self.target
                ));
            }
        }
        // The glass raises the search's low end to bottle + target − holds,
        // below the bottle (the glass holds more than the target): the
        // bottle, where error learning starts, stays inside.
        if !(self.precision.is_finite() && self.precision > 0.0) {
            return bad(format!(
                "--precision {}: must be a positive volume in litres",
                self.precision
            ));
        }
        if self.max_rollouts == 0 {
            return bad("--max-rollouts 0: must be at least 1".into());
        }
        if !(self.gain.is_finite() && self.gain != 0.0) {
            return bad(format!(
                "--gain {}: must be a finite number other than 0",
                self.gain
            ));
        }
        for (flag, s) in [("s1", self.s1), ("s2", self.s2)] {
            if !(s.is_finite() && s >= 0.0) {
                return bad(format!("PoWER's {flag} {s}: must be finite and >= 0"));
            }
        }
        Ok(())
    }
}

/// The volume to pour: above 0 and below what the bottle holds.
pub fn check_target(bottle: f64, target: f64) -> Result<(), Error> {
    if !(target.is_finite() && target > 0.0 && target < bottle) {
        return Err(Error::Invalid(format!(
            "--target {target}: must be above 0 and below the bottle's {bottle} l"
        )));
    }
    Ok(())
}

/// What a roll-out gave, as the learners see it.
pub trait Scored {
    /// The error `ε` told to the error learners, one value per query
    /// dimension; `ε_i > 0` asks for a larger `q_i`.
    fn error(&self) -> Vec<f32>;
    /// The reward, ≥ 0, told to PoWER.
    fn reward(&self) -> f64;
    /// Why the movement never left primo (the limits rejected it), if so.
    fn rejected(&self) -> Option<&str>;
    /// Drops what a run does not keep in memory (a recorded series).
    fn lighten(&mut self) {}
}

impl Scored for Trial {
    fn error(&self) -> Vec<f32> {
        vec![self.error as f32]
    }

    fn reward(&self) -> f64 {
        self.reward
    }

    fn rejected(&self) -> Option<&str> {
        self.rejected.as_deref()
    }

    fn lighten(&mut self) {
        self.series = None;
    }
}

/// One roll-out of a learning run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Record<T = Trial> {
    /// Roll-out number, from 1.
    pub rollout: u32,
    /// PoWER updates completed before this roll-out (0 for error learning).
    pub update: u32,
    /// This roll-out executed PoWER's current mean (no exploration).
    pub mean: bool,
    /// The query `q̂` rolled out.
    pub query: Vec<f32>,
    /// What happened.
    pub trial: T,
}

impl<T> Record<T> {
    /// The query's first value (a pouring run's query is one volume).
    pub fn volume(&self) -> f32 {
        self.query.first().copied().unwrap_or(f32::NAN)
    }
}

/// The query as people write it: `0.5`, or `[1.5, 0.3]`.
pub fn query_text(query: &[f32]) -> String {
    match query {
        [q] => q.to_string(),
        q => format!(
            "[{}]",
            q.iter().map(f32::to_string).collect::<Vec<_>>().join(", ")
        ),
    }
}

/// PoWER's exploration blocks for `skill`, in the order of the extended
/// vector: the query, the kernel weights of each DoF (one block per DoF),
/// the goals, τ. Each block explores with the standard deviation
/// `σ = s·max_ij ‖x_i − x_j‖/√len`, `s` times the examples' RMS spread over
/// the block (`s1` for the query, its variance decaying by `decay` per
/// update, the pour's [`QUERY_DECAY`]; `s2` for the rest).
///
/// The paper writes `σ² = s·max‖θ_i − θ_j‖` with one `σ2` for all of Δθ,
/// and calls `s` the span of exploration. Three departures, each measured
/// on the cell (joint space, small glass, 219 parameters; README):
/// - `s` scales the standard deviation, not the variance: a variance
///   proportional to a distance depends on the units (radians or degrees,
///   litres or millilitres). Read as a variance, the goals explored with
///   0.11 rad per joint and the query with 0.37 l, and 98–99 % of all
///   explorations spilled enough for reward 0, leaving PoWER nothing to
///   average. Read as a standard deviation: 0.013 rad and 0.14 l.
/// - Weights, goals (rad) and τ (s) each get their own spread.
/// - Each DoF's weights get their own spread: an amplitude-scaled DoF's
///   weights are per unit of its amplitude (a5 moves 0.07 rad, its weights
///   reach 2000), so one spread over all weights gave the unscaled joints
///   five times their own.
pub fn power_blocks(skill: &Skill, s1: f32, s2: f32, decay: f32) -> Result<Vec<Block>, Error> {
    let query: Vec<&[f32]> = skill.examples().map(|(q, _)| q).collect();
    let thetas: Vec<&[f32]> = skill.examples().map(|(_, t)| t).collect();
    let block = |s: f32, examples: &[&[f32]], range: std::ops::Range<usize>, decay: f32| {
        let len = range.len();
        let widest = widest_distance(examples.iter().copied(), range)
            .map_err(|e| Error::Invalid(format!("exploration of the examples: {e}")))?;
        let sigma = s * widest / (len as f32).sqrt();
        Ok::<_, Error>(Block {
            len,
            variance: sigma * sigma,
            decay,
        })
    };
    let (n, k) = (skill.dof(), skill.kernels());
    let mut blocks = vec![block(s1, &query, 0..skill.query_dim(), decay)?];
    for d in 0..n {
        blocks.push(block(s2, &thetas, d * k..(d + 1) * k, 1.0)?);
    }
    blocks.push(block(s2, &thetas, n * k..n * k + n, 1.0)?);
    blocks.push(block(s2, &thetas, n * k + n..n * k + n + 1, 1.0)?);
    Ok(blocks)
}

/// The in-process learner: room for any skill the host can fit.
pub type HostService = Service<MAX_EXTENDED, MAX_EXAMPLES, MAX_KERNELS>;

/// Where the learner runs. Both ends run the core's [`Service`], so with the
/// same settings, seed and outcomes they ask for the same roll-outs, bit
/// for bit.
#[allow(clippy::large_enum_variant)] // one per run
pub enum Learner {
    /// In this process.
    Local(Box<HostService>),
    /// On a coprocessor, over a serial line.
    Remote(Link),
}

impl Learner {
    /// An in-process learner.
    pub fn local() -> Self {
        Learner::Local(Box::new(HostService::new()))
    }

    /// One request; an error reply becomes an error.
    fn call(&mut self, request: &Request) -> Result<Reply, Error> {
        let reply = match self {
            Learner::Local(s) => s.respond(request),
            Learner::Remote(link) => link.learn(request)?,
        };
        match reply {
            Reply::Error(f) => Err(Error::Learner(format!("learner: {f}"))),
            reply => Ok(reply),
        }
    }

    /// Starts a run: the learner's `setup`, then the examples of `skill`.
    fn configure(&mut self, skill: &Skill, setup: Setup) -> Result<(), Error> {
        self.call(&Request::Configure(setup))?;
        for (index, (query, theta)) in skill.examples().enumerate() {
            for (c, values) in theta.chunks(CHUNK).enumerate() {
                self.call(&Request::Example {
                    index: index as u8,
                    query: wire_query(query)?,
                    offset: (c * CHUNK) as u16,
                    values: heapless::Vec::from_slice(values)
                        .map_err(|_| Error::Learner("chunk too long".into()))?,
                })?;
            }
        }
        Ok(())
    }

    /// The asked roll-out's `Δθ`, chunk by chunk.
    fn delta(&mut self, len: u16) -> Result<Vec<f32>, Error> {
        let mut delta = Vec::with_capacity(usize::from(len));
        while delta.len() < usize::from(len) {
            match self.call(&Request::Fetch {
                offset: delta.len() as u16,
            })? {
                Reply::Chunk { offset, values }
                    if usize::from(offset) == delta.len() && !values.is_empty() =>
                {
                    delta.extend_from_slice(&values)
                }
                other => {
                    return Err(Error::Learner(format!(
                        "learner: fetching Δθ got {other:?}"
                    )));
                }
            }
        }
        delta.truncate(usize::from(len));
        Ok(delta)
    }
}

/// The learner's setup for a pouring run of `s` on `skill`.
pub fn pour_setup(skill: &Skill, s: &Settings) -> Result<Setup, Error> {
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
                ..PowerConfig::paper(&power_blocks(skill, s.s1, s.s2, QUERY_DECAY)?)
                    .map_err(|e| Error::Invalid(format!("PoWER: {e}")))?
            },
            query: wire_query(&bottle)?,
        },
    };
    setup(skill, learner, s.seed)
}

/// The setup of `learner` over the examples of `skill`.
pub fn setup(skill: &Skill, learner: LearnerSetup, seed: u64) -> Result<Setup, Error> {
    Ok(Setup {
        learner,
        examples: u8::try_from(skill.examples().count())
            .map_err(|_| Error::Invalid("too many examples".into()))?,
        theta_len: u16::try_from(skill.param_len())
            .map_err(|_| Error::Invalid("θ too long".into()))?,
        regression: skill.regression(),
        seed,
        query_dim: u8::try_from(skill.query_dim())
            .map_err(|_| Error::Invalid("query too long".into()))?,
    })
}

/// CRC-32C of the examples `(q_i, θ_i)` of `skill`, bit for bit: a run
/// log keeps it, so changed demonstration files are caught on resume.
pub(crate) fn examples_crc(skill: &Skill) -> u32 {
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);
    let mut digest = crc.digest();
    for (q, theta) in skill.examples() {
        for v in q.iter().chain(theta) {
            digest.update(&v.to_le_bytes());
        }
    }
    digest.finalize()
}

/// The examples of `skill` are those a run logged in `dir` began with.
pub(crate) fn check_examples(skill: &Skill, logged: u32, dir: &Path) -> Result<(), Error> {
    if examples_crc(skill) != logged {
        return Err(Error::Log(format!(
            "the demonstrations of the run in {} have changed since it started: its examples \
             no longer fit to the same DMPs",
            dir.display()
        )));
    }
    Ok(())
}

/// A query (or an error over one) as the wire carries it.
pub fn wire_query(query: &[f32]) -> Result<Query, Error> {
    Query::from_slice(query).map_err(|_| {
        Error::Invalid(format!(
            "a query has at most {MAX_QUERY} values, not {}",
            query.len()
        ))
    })
}

/// Runs the learner of `s` on `skill` in the simulated `cell`, calling
/// `each` after every roll-out; returns all roll-outs.
pub fn learn(
    skill: &Skill,
    cell: &CellConfig,
    s: &Settings,
    learner: &mut Learner,
    mut each: impl FnMut(&Record),
) -> Result<Vec<Record>, Error> {
    let mut rig = Simulated::new(*cell, s.bottle, s.seed)?;
    let run = learn_on(
        skill,
        pour_setup(skill, s)?,
        s.max_rollouts,
        learner,
        &[],
        |i, query, delta| roll_out(&mut rig, skill, s.target, i, query, delta),
        |e, _| {
            each(&e.record);
            Ok(())
        },
    )?;
    Ok(run.into_iter().map(|e| e.record).collect())
}

/// A roll-out as the run log keeps it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Entry<T = Trial> {
    /// The roll-out and what happened.
    #[serde(flatten)]
    pub record: Record<T>,
    /// The learner's `Δθ` (empty for the error learners).
    pub delta: Vec<f32>,
    /// The learner's state after it was told the outcome.
    pub status: Status,
    /// CRC-32C of what the learner asked (the roll-out and `Δθ`) and of its
    /// status, bit for bit: a resumed run checks its learner against it.
    pub check: u32,
}

/// The CRC of [`Entry::check`].
fn check(asked: &Rollout, delta: &[f32], status: &Status) -> Result<u32, Error> {
    let bytes = postcard::to_allocvec(&(asked, delta, status))
        .map_err(|e| Error::Learner(format!("learner state: {e}")))?;
    Ok(crc::Crc::<u32>::new(&crc::CRC_32_ISCSI).checksum(&bytes))
}

/// Runs the learner of `setup` on `skill` for at most `max_rollouts`:
/// `roll(i, q̂, Δθ)` makes roll-out `i` (on a rig, through an evaluator),
/// and `each` is called after every roll-out (with `true` for a replayed
/// one) before the next begins; returns all roll-outs. An error from
/// `roll` (an instrument failed) or `each` (the run log could not be
/// written, the output closed) ends the run. An error learner cannot learn
/// from a movement the limits rejected: that ends the run too.
///
/// `logged` are the roll-outs of an interrupted run of the same settings:
/// the learner is told their outcomes again instead of rolling them out,
/// and [`verify_replayed`] checks it asks for exactly the logged roll-outs
/// and reaches exactly the logged states, so the run goes on as if it had
/// never stopped.
pub fn learn_on<T: Scored + Clone>(
    skill: &Skill,
    setup: Setup,
    max_rollouts: u32,
    learner: &mut Learner,
    logged: &[Entry<T>],
    mut roll: impl FnMut(u32, &[f32], &[f32]) -> Result<T, Error>,
    mut each: impl FnMut(&Entry<T>, bool) -> Result<(), Error>,
) -> Result<Vec<Entry<T>>, Error> {
    let error_learning = !matches!(setup.learner, LearnerSetup::Power { .. });
    learner.configure(skill, setup)?;
    let mut run = Vec::new();
    for i in 1..=max_rollouts {
        let asked = match learner.call(&Request::Ask)? {
            Reply::Rollout(r) => r,
            Reply::Finished(_) => break,
            other => {
                return Err(Error::Learner(format!(
                    "learner: asked for a roll-out, got {other:?}"
                )));
            }
        };
        let delta = learner.delta(asked.delta_len)?;
        let query = asked.query.to_vec();
        let before = logged.get(run.len());
        let trial = match before {
            Some(e) => e.record.trial.clone(),
            None => roll(i, &query, &delta)?,
        };
        if let (Some(why), true) = (trial.rejected(), error_learning) {
            return Err(Error::Invalid(format!(
                "roll-out {i} (q = {}) rejected: {why}",
                query_text(&query)
            )));
        }
        learner.call(&Request::Tell(Outcome {
            error: wire_query(&trial.error())?,
            reward: trial.reward() as f32,
        }))?;
        let status = match learner.call(&Request::Status)? {
            Reply::Status(status) => status,
            other => {
                return Err(Error::Learner(format!(
                    "learner: asked for its status, got {other:?}"
                )));
            }
        };
        let mut entry = Entry {
            check: check(&asked, &delta, &status)?,
            record: Record {
                rollout: i,
                update: asked.update,
                mean: asked.mean,
                query,
                trial,
            },
            delta,
            status,
        };
        if let Some(logged) = before {
            verify_replayed(logged, &entry)?;
        }
        each(&entry, before.is_some())?;
        // A series (megabytes) is not kept: the best one is replayed.
        entry.record.trial.lighten();
        run.push(entry);
    }
    if run.len() < logged.len() {
        return Err(Error::Log(format!(
            "the run log has {} roll-outs, the learner finished after {}: the log is of \
             another learner, seed or skill",
            logged.len(),
            run.len()
        )));
    }
    Ok(run)
}

/// [`learn_on`] for a logged run: every new roll-out is appended to the
/// `log` before `show` is told of it, and the log ended after the last;
/// a run whose log is already `ended` is only told again.
#[allow(clippy::too_many_arguments)]
pub(crate) fn learn_logged<T: Scored + Clone + Serialize>(
    skill: &Skill,
    setup: Setup,
    max_rollouts: u32,
    learner: &mut Learner,
    logged: &[Entry<T>],
    (log, ended): (&mut RunLog, bool),
    roll: impl FnMut(u32, &[f32], &[f32]) -> Result<T, Error>,
    mut show: impl FnMut(&Entry<T>, bool) -> Result<(), Error>,
) -> Result<Vec<Entry<T>>, Error> {
    let run = learn_on(
        skill,
        setup,
        max_rollouts,
        learner,
        logged,
        roll,
        |entry, replayed| {
            if !(replayed || ended) {
                log.append(entry)?;
            }
            show(entry, replayed)
        },
    )?;
    if !ended {
        log.end()?;
    }
    Ok(run)
}

/// A replayed roll-out must be the logged one: the learner asked for the
/// same roll-out and `Δθ` and reached the same state, bit for bit.
pub fn verify_replayed<T>(logged: &Entry<T>, replayed: &Entry<T>) -> Result<(), Error> {
    if logged.check != replayed.check || logged.record.rollout != replayed.record.rollout {
        return Err(Error::Log(format!(
            "the run log's roll-out {} is not what the learner asks for and reaches \
             as roll-out {} (q = {}, logged q = {}): the log is of another \
             learner, seed or skill",
            logged.record.rollout,
            replayed.record.rollout,
            query_text(&replayed.record.query),
            query_text(&logged.record.query)
        )));
    }
    Ok(())
}

/// The best executed roll-out: the highest reward, the later of equals
/// (the more learned).
pub fn best<T: Scored>(run: &[Entry<T>]) -> Option<&Entry<T>> {
    run.iter()
        .filter(|e| e.record.trial.rejected().is_none())
        .fold(None, |best: Option<&Entry<T>>, e| match best {
            Some(b) if b.record.trial.reward() > e.record.trial.reward() => Some(b),
            _ => Some(e),
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pouring::built_in_skill;
    use primo_sim::cell::GlassKind;
    use primo_skill::Space;

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
