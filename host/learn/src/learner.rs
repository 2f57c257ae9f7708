//! The learner of a run: the core's ask/tell state machines behind the
//! wire protocol's [`Service`], in this process or on a coprocessor
//! ([`Learner`]), and how a skill becomes its setup.

use std::path::Path;

use primo_core::power::{Block, widest_distance};
use primo_learner::Service;
use primo_protocol::learner::{CHUNK, LearnerSetup, MAX_QUERY, Query, Reply, Request, Setup};
use primo_skill::MAX_KERNELS;
use primo_skill::Skill;
use primo_skill::skill::{MAX_EXAMPLES, MAX_PARAMS};

use crate::Error;
use crate::coprocessor::Link;

/// Capacity of the extended parameter vector `[q̂, Δθ]`.
pub const MAX_EXTENDED: usize = MAX_PARAMS + 1;
/// Per-update decay of the query's exploration variance σ1² (the paper
/// decays it "with time" without a number).
pub const QUERY_DECAY: f32 = 0.9;

/// PoWER's exploration blocks for `skill`, in the order of the extended
/// vector: the query, the kernel weights of each DoF (one block per DoF),
/// the goals, τ. Each block explores with the standard deviation
/// `σ = s·max_ij ‖x_i − x_j‖/√len`, `s` times the examples' RMS spread over
/// the block (`s1` for the query, its variance decaying by `decay` per
/// update, the pour's [`QUERY_DECAY`]; `s2` for the rest).
///
/// The paper writes `σ² = s·max‖θ_i − θ_j‖` with one `σ2` for all of Δθ,
/// and calls `s` the span of exploration. Three departures, each measured
/// on the cell (joint space, small glass, 219 parameters; bench/results):
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
    for (name, s) in [("s1", s1), ("s2", s2)] {
        if !(s.is_finite() && s >= 0.0) {
            return Err(Error::Invalid(format!(
                "PoWER's {name} {s}: must be finite and >= 0"
            )));
        }
    }
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
    pub(crate) fn call(&mut self, request: &Request) -> Result<Reply, Error> {
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
    pub(crate) fn configure(&mut self, skill: &Skill, setup: Setup) -> Result<(), Error> {
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
    pub(crate) fn delta(&mut self, len: u16) -> Result<Vec<f32>, Error> {
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
