//! The learner's messages: the learning run's setup, training examples in
//! chunks, ask/tell of roll-outs, the streamed movement, and the version
//! handshake ([`Request::Hello`]). The learning coprocessor serves these
//! alone ([`crate::endpoint::Learner`]); the scale serves them besides its
//! own ([`crate::scale::Request`]), with the same bytes.
//!
//! Vectors longer than a frame (training examples, a roll-out's `Δθ`)
//! travel in [`CHUNK`]-value pieces, so that every frame stays small: on a
//! line that corrupts 1 % of its bytes a 40-byte frame still arrives
//! intact two times in three, a 900-byte one almost never.
//!
//! The handshake keeps its bytes in every version: [`Request::Hello`] is
//! variant 0 followed by the version, answered by [`Reply::Hello`]
//! (variant 0, the version first) or [`Reply::Error`] (variant 7) with
//! [`FaultKind::Version`], so that a host refuses a device of another
//! version with a clear message, whichever is older.

use heapless::Vec;
use primo_core::dmp::Shape;
use primo_core::generalize::Method as Regression;
use primo_core::golden::{SearchConfig, Status as SearchStatus};
use primo_core::power::PowerConfig;
use primo_core::secant::SecantConfig;
use serde::{Deserialize, Serialize};

use crate::fault::Fault;
#[cfg(doc)]
use crate::fault::FaultKind;

/// Values per chunk of a long vector.
pub const CHUNK: usize = 8;
/// Largest DoF count a DMP on the wire has.
pub const MAX_DOF: usize = 7;
/// Largest dimension of a task query: of the learners behind the wire and
/// of the host's skills.
pub const MAX_QUERY: usize = 4;

/// A task query `q` (or an error vector `ε` over one), of the setup's
/// `query_dim` values.
pub type Query = Vec<f32, MAX_QUERY>;

/// What the host asks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Request {
    /// Who are you? Answered with [`Reply::Hello`] whatever the version.
    Hello {
        /// The host's protocol version.
        version: u16,
    },
    /// Starts a new learning run and forgets the old one; the examples
    /// follow as [`Request::Example`] chunks.
    Configure(Setup),
    /// A chunk of training example `index`'s `θ_i`, from value `offset`.
    Example {
        /// Which example (0-based, in order).
        index: u8,
        /// Its query `q_i` (`query_dim` values).
        query: Query,
        /// Where in `θ_i` the values go.
        offset: u16,
        /// The values.
        values: Vec<f32, CHUNK>,
    },
    /// The next roll-out: answered with [`Reply::Rollout`] or, once a
    /// search has ended, [`Reply::Finished`]. Asking again before
    /// [`Request::Tell`] gives the same roll-out.
    Ask,
    /// A chunk of the asked roll-out's `Δθ`, from value `offset`.
    Fetch {
        /// First value wanted.
        offset: u16,
    },
    /// The asked roll-out's outcome.
    Tell(Outcome),
    /// Where the learning stands.
    Status,
    /// Starts integrating the asked roll-out's movement `θ = G(q̂) + Δθ`.
    DmpStart(DmpStart),
    /// The next setpoint of the movement.
    DmpNext,
    /// The asked roll-out could not be made or measured (the robot's
    /// limits rejected its movement, the task failed): an error learner
    /// takes its query as a bound of the search. PoWER learns from such a
    /// roll-out's reward: tell it with [`Request::Tell`].
    Infeasible,
}

/// A learning run's settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Setup {
    /// The learner.
    pub learner: LearnerSetup,
    /// Number of training examples that follow.
    pub examples: u8,
    /// Length of every `θ_i`.
    pub theta_len: u16,
    /// How `θ = G(q)` is computed from the examples.
    pub regression: Regression,
    /// Seed of the learner's random generator.
    pub seed: u64,
    /// Dimension of the task query, 1..=[`MAX_QUERY`]: every example's
    /// query and the learner's start and limits have this many values.
    pub query_dim: u8,
}

/// Which learner, with its settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum LearnerSetup {
    /// The paper's golden-section error learning on a 1-D query.
    Golden(SearchConfig),
    /// Illinois error learning on a 1-D query.
    Illinois(SearchConfig),
    /// Secant error learning (the paper's eq. 10 with a learned gain) on a
    /// query of any dimension.
    Secant(SecantConfig<MAX_QUERY>),
    /// PoWER over `[q̂, Δθ]` starting from `[query, 0, …, 0]`; the blocks'
    /// lengths add up to `theta_len + query_dim`.
    Power {
        /// Its settings.
        config: PowerConfig,
        /// The starting query `q̂`.
        query: Query,
    },
    /// Secant error learning on a change of the generalized movement's
    /// goals instead of its query: `q̂` stays `query`, and the learner's
    /// values are `Δθ[first_goal..]`, one goal per error value (the rest
    /// of `Δθ` is 0). Few examples generalize poorly beyond themselves:
    /// where no query takes the movement to the outcome, its goals can.
    SecantGoals {
        /// Its settings: its values are the changes of the goals.
        config: SecantConfig<MAX_QUERY>,
        /// The query the movement is generalized at (`query_dim` values).
        query: Query,
        /// The first changed goal's index in `θ` (after the weights: DoFs
        /// × kernels).
        first_goal: u16,
    },
}

/// A roll-out's measured outcome: error learners use the error, PoWER the
/// reward.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// The error vector `ε = desired − measured` (`ε_i > 0`: component `i`
    /// of the query must increase): one value for golden section and
    /// Illinois, `query_dim` for the secant learner and for PoWER with a
    /// query gain (plain PoWER ignores it).
    pub error: Query,
    /// The reward (finite, ≥ 0).
    pub reward: f32,
}

/// What the movement of the asked roll-out starts from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DmpStart {
    /// Gains, width and amplitude scaling of the DMP.
    pub shape: Shape,
    /// Kernels per DoF.
    pub kernels: u8,
    /// Start position, one value per DoF.
    pub start: Vec<f32, MAX_DOF>,
    /// Control step, s.
    pub dt: f32,
}

/// What the learner answers.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Reply {
    /// Its version and sizes.
    Hello {
        /// The coprocessor's protocol version.
        version: u16,
        /// What fits in it.
        capacities: Capacities,
    },
    /// Done; nothing to report.
    Ok,
    /// The next roll-out.
    Rollout(Rollout),
    /// The search has ended; nothing more to roll out.
    Finished(SearchStatus),
    /// A chunk of the asked roll-out's `Δθ`.
    Chunk {
        /// Where the values start.
        offset: u16,
        /// The values.
        values: Vec<f32, CHUNK>,
    },
    /// Where the learning stands.
    Status(Status),
    /// A setpoint of the movement.
    Setpoint {
        /// Time since the start, s.
        time: f32,
        /// Position, one value per DoF.
        position: Vec<f32, MAX_DOF>,
        /// The movement has reached its duration `τ`.
        done: bool,
    },
    /// The request failed and changed nothing.
    Error(Fault),
}

/// What fits in the coprocessor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capacities {
    /// Largest `θ` length.
    pub theta: u16,
    /// Most training examples.
    pub examples: u8,
    /// Most DoF of a streamed DMP.
    pub dof: u8,
    /// Most kernels per DoF of a streamed DMP.
    pub kernels: u8,
    /// Largest importance sampler of PoWER.
    pub sampler: u8,
}

/// A roll-out to execute.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Rollout {
    /// Roll-outs asked before this one.
    pub number: u32,
    /// The query `q̂` to generalize to.
    pub query: Query,
    /// Length of `Δθ` to fetch (0 for the error learners).
    pub delta_len: u16,
    /// PoWER: the unperturbed mean of this update.
    pub mean: bool,
    /// PoWER: updates completed before it.
    pub update: u32,
}

/// Where the learning stands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Status {
    /// Roll-outs told.
    pub rollouts: u32,
    /// PoWER updates completed (0 for the error learners).
    pub updates: u32,
    /// The error learners' state (PoWER is always running).
    pub search: SearchStatus,
    /// The best roll-out's query, if any was told ([`LearnerSetup::SecantGoals`]:
    /// its change of the goals).
    pub best_query: Option<Query>,
    /// Its error (golden section, Illinois), its error's size `max_i |ε_i|`
    /// (secant) or its reward (PoWER).
    pub best: Option<f32>,
}

impl From<Fault> for Reply {
    fn from(fault: Fault) -> Self {
        Reply::Error(fault)
    }
}
