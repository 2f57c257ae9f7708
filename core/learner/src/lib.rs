//! # primo-learner
//!
//! The learner behind the wire, the handler of the learner endpoint
//! ([`primo_protocol::endpoint::Learner`]): what the coprocessor runs, what
//! the scale runs besides its own handler, and what the host runs
//! in-process when it has no coprocessor, so all give the same roll-outs
//! bit for bit. It is a crate of its own, between the learning core
//! (`primo-core`, math and learners only) and the protocol
//! (`primo-protocol`, the messages only), because it needs both and
//! neither needs it: the host talks to a device with the protocol alone,
//! and the core knows nothing of a wire.
//!
//! A [`Service`] holds the training examples, one learner (golden section
//! or Illinois on a 1-D query; secant error learning or PoWER on a query of
//! `query_dim` = 1..=[`MAX_QUERY`] values; secant error learning on up to
//! [`MAX_QUERY`] of the movement's goals) and the movement being streamed,
//! in fixed buffers; the coprocessor's, [`Coprocessor`], is sized for the
//! paper's arm: [`THETA`] = 7 DoF × 30 kernels + 7 goals + τ.
//! [`Service::respond`] answers one [`Request`]; [`Service::handle`] does
//! the same for a frame off the line, through the protocol's
//! [`Replay`], so a retransmitted frame gets the previous reply's bytes
//! again and changes nothing.
//!
//! ```
//! use heapless::Vec;
//! use primo_core::generalize::Method;
//! use primo_core::golden::Status as SearchStatus;
//! use primo_core::secant::{Rule, SecantConfig};
//! use primo_learner::Coprocessor;
//! use primo_protocol::learner::{LearnerSetup, Outcome, Reply, Request, Setup};
//! let v = |s: &[f32]| Vec::from_slice(s).unwrap();
//! let mut s = Coprocessor::new();
//! let cfg = SecantConfig {
//!     low: v(&[0.0, 0.0]),
//!     high: v(&[2.0, 2.0]),
//!     desired: v(&[1.0, 0.5]),
//!     precision: 1e-3,
//!     max_rollouts: 50,
//!     gain: 1.0,
//!     rule: Rule::Broyden,
//! };
//! let setup = Setup {
//!     learner: LearnerSetup::Secant(cfg),
//!     examples: 0,
//!     theta_len: 0,
//!     regression: Method::Lwr { bandwidth: None },
//!     seed: 1,
//!     query_dim: 2,
//! };
//! assert_eq!(s.respond(&Request::Configure(setup)), Reply::Ok);
//! // The "cell": the outcome is (q₀², q₀ q₁), and we want (1, 0.5).
//! while let Reply::Rollout(r) = s.respond(&Request::Ask) {
//!     let q = &r.query;
//!     let error = v(&[1.0 - q[0] * q[0], 0.5 - q[0] * q[1]]);
//!     assert_eq!(s.respond(&Request::Tell(Outcome { error, reward: 0.0 })), Reply::Ok);
//! }
//! let Reply::Status(status) = s.respond(&Request::Status) else { panic!() };
//! assert_eq!(status.search, SearchStatus::Converged);
//! ```
#![no_std]
#![deny(missing_docs)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]

use heapless::Vec;

use primo_core::dmp::{Dmp, Run};
use primo_core::generalize::{Generalizer, Method as Regression};
use primo_core::golden::{ErrorLearner, GoldenSection, Status as SearchStatus};
use primo_core::illinois::Illinois;
use primo_core::power::Power;
use primo_core::secant::Secant;
use primo_core::{Error, check_capacity, check_len};
use primo_protocol::VERSION;
use primo_protocol::endpoint::Learner as LearnerEndpoint;
use primo_protocol::fault::{Fault, FaultKind};
use primo_protocol::frame::{FrameError, MAX_FRAME};
use primo_protocol::learner::{
    CHUNK, Capacities, DmpStart, LearnerSetup, MAX_DOF, MAX_QUERY, Outcome, Query, Reply, Request,
    Rollout, Setup, Status,
};
use primo_protocol::replay::Replay;
pub use primo_protocol::replay::UNREAD;

/// The coprocessor's kernels per DoF.
pub const KERNELS: usize = 30;
/// The coprocessor's largest `θ`: [`MAX_DOF`] × [`KERNELS`] weights, the
/// goals and τ.
pub const THETA: usize = MAX_DOF * KERNELS + MAX_DOF + 1;
/// The coprocessor's most training examples.
pub const EXAMPLES: usize = 8;
/// The service the coprocessor runs: the paper's arm, 7 DoF × 30 kernels,
/// `[q̂, Δθ]` of up to 218 + [`MAX_QUERY`] values.
pub type Coprocessor = Service<{ THETA + MAX_QUERY }, EXAMPLES, KERNELS>;
/// Largest importance sampler of PoWER (the paper's 3).
pub const SAMPLER: usize = 3;

/// The learner in use; PoWER's state lives in [`Service`], configured in
/// place. `repr(u8)` makes `Idle` all zero bytes (see [`Service::new`]).
/// Its size is the secant learner's: the one learner lives in the
/// service's static memory, and boxing it would need a heap the M4F has
/// not.
#[derive(Debug, Clone)]
#[repr(u8)]
#[allow(clippy::large_enum_variant)]
enum Learner {
    Idle,
    Golden(GoldenSection),
    Illinois(Illinois),
    /// On the query, or on the goals ([`LearnerSetup::SecantGoals`]).
    Secant(Secant<MAX_QUERY>, Option<Goals>),
    Power,
}

/// Secant error learning on the goals: the query held, and where in `θ`
/// the changed goals begin.
#[derive(Debug, Clone)]
struct Goals {
    query: Query,
    first: usize,
}

/// A roll-out's `Δθ`: PoWER's, or the secant learner's changes of the
/// goals at `first` within zeros (`len` values in all).
#[derive(Debug, Clone, Copy)]
enum Delta<'a> {
    Values(&'a [f32]),
    Goals {
        len: usize,
        first: usize,
        change: &'a [f32],
    },
}

impl Delta<'_> {
    fn len(&self) -> usize {
        match self {
            Delta::Values(v) => v.len(),
            Delta::Goals { len, .. } => *len,
        }
    }

    /// Value `i`, 0 beyond the end.
    fn get(&self, i: usize) -> f32 {
        let value = match self {
            Delta::Values(v) => v.get(i),
            Delta::Goals { first, change, .. } => i.checked_sub(*first).and_then(|j| change.get(j)),
        };
        value.copied().unwrap_or(0.0)
    }
}

/// The movement being streamed, if any; `repr(u8)` as for [`Learner`].
#[derive(Debug, Clone)]
#[repr(u8)]
#[allow(clippy::large_enum_variant)] // it lives in the service, not on a stack
enum Stream<const K: usize> {
    Idle,
    Moving(Motion<K>),
}

/// A movement being integrated.
#[derive(Debug, Clone)]
struct Motion<const K: usize> {
    dmp: Dmp<MAX_DOF, K>,
    run: Run<MAX_DOF>,
    dt: f32,
    done: bool,
}

/// Examples received so far of those announced by the setup.
#[derive(Debug, Clone)]
struct Intake<const P: usize> {
    expected: u8,
    theta_len: usize,
    index: u8,
    query: Query,
    filled: usize,
    theta: [f32; P],
}

/// The learner behind the wire (see the module docs) for `[q̂, Δθ]` of up
/// to `P` values (θ of up to `P −` [`MAX_QUERY`]), `E` training examples
/// and DMPs of up to `K` kernels per DoF.
#[derive(Debug, Clone)]
pub struct Service<const P: usize, const E: usize, const K: usize> {
    examples: Generalizer<E, MAX_QUERY, P>,
    /// The setup's query dimension.
    query_dim: usize,
    intake: Intake<P>,
    learner: Learner,
    power: Power<P, SAMPLER>,
    /// A roll-out was asked and not yet told.
    in_flight: bool,
    asked: u32,
    motion: Stream<K>,
    /// The last frame's reply, for a retransmission.
    replay: Replay,
}

impl<const P: usize, const E: usize, const K: usize> Default for Service<P, E, K> {
    fn default() -> Self {
        Self::new()
    }
}

/// A core error as a fault.
fn fault(e: Error) -> Reply {
    let kind = match e {
        Error::Capacity { .. } => FaultKind::Capacity,
        Error::BadState(_) => FaultKind::BadState,
        _ => FaultKind::Invalid,
    };
    Reply::Error(Fault::new(kind, e))
}

fn bad_state(why: &str) -> Reply {
    Reply::Error(Fault::new(FaultKind::BadState, why))
}

/// The first [`MAX_QUERY`] values as a query.
fn query_of(values: &[f32]) -> Query {
    values.iter().take(MAX_QUERY).copied().collect()
}

/// The one error value of a 1-D error learner.
fn scalar(error: &[f32]) -> Result<f32, Error> {
    match error {
        [e] => Ok(*e),
        _ => Err(Error::Length {
            what: "error of a 1-D error learner",
            expected: 1,
            found: error.len(),
        }),
    }
}

/// Golden section and Illinois search a 1-D query.
fn one_dimensional(query_dim: usize) -> Result<(), Error> {
    check_len(
        "query dimension of golden section or Illinois",
        1,
        query_dim,
    )
}

impl<const P: usize, const E: usize, const K: usize> Service<P, E, K> {
    /// A service with no learner configured. Its bytes are all zero, so a
    /// static one costs RAM (.bss) but no flash; the coprocessor builds it
    /// in place because a 15 KiB temporary would not fit its stack.
    pub const fn new() -> Self {
        Self {
            examples: Generalizer::new(0, 0, Regression::Lwr { bandwidth: None }),
            query_dim: 0,
            intake: Intake {
                expected: 0,
                theta_len: 0,
                index: 0,
                query: Vec::new(),
                filled: 0,
                theta: [0.0; P],
            },
            learner: Learner::Idle,
            power: Power::idle(),
            in_flight: false,
            asked: 0,
            motion: Stream::Idle,
            replay: Replay::new(),
        }
    }

    /// What fits.
    pub fn capacities() -> Capacities {
        let clamp = |n: usize, max: usize| n.min(max);
        Capacities {
            theta: clamp(P.saturating_sub(MAX_QUERY), u16::MAX as usize) as u16,
            examples: clamp(E, u8::MAX as usize) as u8,
            dof: MAX_DOF as u8,
            kernels: clamp(K, u8::MAX as usize) as u8,
            sampler: SAMPLER as u8,
        }
    }

    /// Answers one frame off the line (`raw` as
    /// [`primo_protocol::frame::FrameReader`] gives it) and returns the
    /// reply frame, written into `out`. A frame that cannot be read gets a
    /// [`FaultKind::BadFrame`] reply numbered [`UNREAD`]; a repeated
    /// sequence number gets the previous reply again.
    pub fn handle<'a>(
        &mut self,
        raw: Result<&[u8], FrameError>,
        out: &'a mut [u8; MAX_FRAME],
    ) -> &'a [u8] {
        let len = self.reply_len(raw, out);
        out.get(..len).unwrap_or(&[])
    }

    /// [`Service::handle`], returning the reply's length in `out`.
    /// Never inlined: the firmware's loop inlined it with its callees
    /// whole, 8 KB more of flash.
    #[inline(never)]
    fn reply_len(&mut self, raw: Result<&[u8], FrameError>, out: &mut [u8; MAX_FRAME]) -> usize {
        match self.replay.open::<LearnerEndpoint>(raw, out) {
            Ok(request) => {
                let reply = self.respond(&request.body);
                self.replay.answer(request.seq, &reply, out)
            }
            Err(len) => len,
        }
    }

    /// Answers one request. Always inlined (into [`Service::handle`]'s
    /// frame handling, its one caller on the coprocessor): called from
    /// there, the optimizer had kept it apart, with its helpers split
    /// off, 900 B more of flash.
    #[inline(always)]
    pub fn respond(&mut self, request: &Request) -> Reply {
        match request {
            Request::Hello { version } if *version == VERSION => Reply::Hello {
                version: VERSION,
                capacities: Self::capacities(),
            },
            Request::Hello { version } => Reply::Error(Fault::new(
                FaultKind::Version,
                format_args!("coprocessor speaks version {VERSION}, host {version}"),
            )),
            Request::Configure(setup) => self.configure(setup).map_or_else(fault, |()| Reply::Ok),
            Request::Example {
                index,
                query,
                offset,
                values,
            } => self.example(*index, query, usize::from(*offset), values),
            Request::Ask => self.ask(),
            Request::Fetch { offset } => self.fetch(usize::from(*offset)),
            Request::Tell(outcome) => self.tell(outcome),
            Request::Infeasible => self.infeasible(),
            Request::Status => self.status(),
            Request::DmpStart(start) => self.dmp_start(start).unwrap_or_else(fault),
            Request::DmpNext => self.dmp_next(),
        }
    }

    fn configure(&mut self, setup: &Setup) -> Result<(), Error> {
        let theta_len = usize::from(setup.theta_len);
        check_capacity("θ length", theta_len, P.saturating_sub(MAX_QUERY))?;
        check_capacity("examples", usize::from(setup.examples), E)?;
        let query_dim = usize::from(setup.query_dim);
        if !(1..=MAX_QUERY).contains(&query_dim) {
            const _: () = assert!(MAX_QUERY == 4, "the message names the value");
            return Err(Error::OutOfRange("a query has 1 to 4 values"));
        }
        let learner = match &setup.learner {
            LearnerSetup::Golden(cfg) => {
                one_dimensional(query_dim)?;
                Learner::Golden(GoldenSection::new(*cfg)?)
            }
            LearnerSetup::Illinois(cfg) => {
                one_dimensional(query_dim)?;
                Learner::Illinois(Illinois::new(*cfg)?)
            }
            LearnerSetup::Secant(cfg) => {
                check_len("secant query", query_dim, cfg.dim())?;
                Learner::Secant(Secant::new(cfg.clone())?, None)
            }
            LearnerSetup::SecantGoals {
                config,
                query,
                first_goal,
            } => {
                check_len("secant goals' query", query_dim, query.len())?;
                let first = usize::from(*first_goal);
                check_capacity("changed goals' end in θ", first + config.dim(), theta_len)?;
                let goals = Goals {
                    query: query.clone(),
                    first,
                };
                Learner::Secant(Secant::new(config.clone())?, Some(goals))
            }
            LearnerSetup::Power { config, query } => {
                check_len("PoWER start query", query_dim, query.len())?;
                let mut start = [0.0f32; P];
                let start = start
                    .get_mut(..theta_len + query_dim)
                    .ok_or(Error::Capacity {
                        what: "θ length",
                        requested: theta_len,
                        capacity: P.saturating_sub(MAX_QUERY),
                    })?;
                start.iter_mut().zip(query).for_each(|(s, q)| *s = *q);
                self.power.reset(start, config.clone(), setup.seed)?;
                Learner::Power
            }
        };
        // Field by field: a fresh Service would be a second 15 KiB on the
        // coprocessor's stack.
        self.examples.reset(query_dim, theta_len, setup.regression);
        self.query_dim = query_dim;
        self.intake.expected = setup.examples;
        self.intake.theta_len = theta_len;
        self.intake.index = 0;
        self.intake.filled = 0;
        self.learner = learner;
        self.in_flight = false;
        self.asked = 0;
        self.motion = Stream::Idle;
        Ok(())
    }

    /// Examples arrive in order, each in consecutive chunks.
    fn example(&mut self, index: u8, query: &Query, offset: usize, values: &[f32]) -> Reply {
        let i = &mut self.intake;
        if matches!(self.learner, Learner::Idle) {
            return bad_state("example before configure");
        }
        if index >= i.expected {
            return Reply::Error(Fault::new(
                FaultKind::BadState,
                format_args!("example {index} not announced ({} expected)", i.expected),
            ));
        }
        if query.len() != self.query_dim {
            return Reply::Error(Fault::new(
                FaultKind::Invalid,
                format_args!(
                    "example query of {} values, query_dim is {}",
                    query.len(),
                    self.query_dim
                ),
            ));
        }
        let same_query = query
            .iter()
            .zip(&i.query)
            .all(|(a, b)| a.to_bits() == b.to_bits());
        if index != i.index || offset != i.filled || (offset > 0 && !same_query) {
            return Reply::Error(Fault::new(
                FaultKind::BadState,
                format_args!("expected example {} from value {}", i.index, i.filled),
            ));
        }
        let end = offset + values.len();
        let Some(dst) = i.theta.get_mut(offset..end).filter(|_| end <= i.theta_len) else {
            return Reply::Error(Fault::new(
                FaultKind::Capacity,
                format_args!("example values up to {end}, θ has {}", i.theta_len),
            ));
        };
        dst.copy_from_slice(values);
        i.query.clone_from(query);
        i.filled = end;
        if end < i.theta_len {
            return Reply::Ok;
        }
        let theta = i.theta.get(..i.theta_len).unwrap_or(&[]);
        if let Err(e) = self.examples.add_example(query, theta) {
            return fault(e);
        }
        i.index += 1;
        i.filled = 0;
        if i.index == i.expected
            && let Err(e) = self.examples.build()
        {
            return fault(e);
        }
        Reply::Ok
    }

    fn ask(&mut self) -> Reply {
        let number = self.asked.wrapping_sub(u32::from(self.in_flight));
        let (search, mean, update) = match &self.learner {
            Learner::Idle => return bad_state("ask before configure"),
            Learner::Golden(l) => (l.status(), true, 0),
            Learner::Illinois(l) => (l.status(), true, 0),
            Learner::Secant(l, _) => (l.status(), true, 0),
            Learner::Power => (
                SearchStatus::Running,
                self.power.next_is_mean(),
                self.power.updates(),
            ),
        };
        let Some((query, delta)) = self.next_rollout() else {
            return Reply::Finished(search);
        };
        let rollout = Rollout {
            number,
            query,
            delta_len: delta.len() as u16,
            mean,
            update,
        };
        if !self.in_flight {
            self.asked = self.asked.wrapping_add(1);
            self.in_flight = true;
        }
        Reply::Rollout(rollout)
    }

    /// The query and `Δθ` (empty for the error learners on the query) of
    /// the roll-out to execute: PoWER draws it at the first call after a
    /// tell, and every call until the next tell gives the same. `None` once
    /// the search has finished.
    fn next_rollout(&mut self) -> Option<(Query, Delta<'_>)> {
        let none = Delta::Values(&[]);
        match &self.learner {
            Learner::Idle => None,
            Learner::Golden(l) => l.ask().map(|q| (query_of(&[q]), none)),
            Learner::Illinois(l) => l.ask().map(|q| (query_of(&[q]), none)),
            Learner::Secant(l, None) => l.ask().map(|q| (query_of(q), none)),
            Learner::Secant(l, Some(goals)) => l.ask().map(|change| {
                let delta = Delta::Goals {
                    len: self.intake.theta_len,
                    first: goals.first,
                    change,
                };
                (goals.query.clone(), delta)
            }),
            Learner::Power => {
                let (query, delta) = self.power.ask().split_at_checked(self.query_dim)?;
                Some((query_of(query), Delta::Values(delta)))
            }
        }
    }

    /// `Δθ` of the roll-out in flight (PoWER's, or the changed goals').
    fn delta(&mut self) -> Option<Delta<'_>> {
        match self.learner {
            Learner::Power | Learner::Secant(_, Some(_)) if self.in_flight => {
                self.next_rollout().map(|(_, delta)| delta)
            }
            _ => None,
        }
    }

    fn fetch(&mut self, offset: usize) -> Reply {
        let Some(delta) = self.delta() else {
            return bad_state("fetch without a roll-out with Δθ in flight");
        };
        if offset > delta.len() {
            return Reply::Error(Fault::new(
                FaultKind::Invalid,
                format_args!("offset {offset} beyond Δθ of {}", delta.len()),
            ));
        }
        let values = (offset..delta.len())
            .take(CHUNK)
            .map(|i| delta.get(i))
            .collect();
        Reply::Chunk {
            offset: offset as u16,
            values,
        }
    }

    fn tell(&mut self, outcome: &Outcome) -> Reply {
        if !self.in_flight {
            return bad_state("tell without a roll-out in flight");
        }
        let told = match &mut self.learner {
            Learner::Idle => return bad_state("tell before configure"),
            Learner::Golden(l) => scalar(&outcome.error).and_then(|e| l.tell(e)).map(drop),
            Learner::Illinois(l) => scalar(&outcome.error).and_then(|e| l.tell(e)).map(drop),
            Learner::Secant(l, _) => l.tell(&outcome.error).map(drop),
            // No error (nothing measured): nothing to correct the query by.
            Learner::Power if self.power.query_gain() != 0.0 && !outcome.error.is_empty() => {
                check_len("PoWER error", self.query_dim, outcome.error.len())
                    .and_then(|()| self.power.tell_outcome(outcome.reward, &outcome.error))
                    .map(drop)
            }
            Learner::Power => self.power.tell(outcome.reward).map(drop),
        };
        match told {
            Ok(()) => {
                self.in_flight = false;
                Reply::Ok
            }
            Err(e) => fault(e),
        }
    }

    fn infeasible(&mut self) -> Reply {
        if !self.in_flight {
            return bad_state("infeasible without a roll-out in flight");
        }
        let told = match &mut self.learner {
            Learner::Idle => return bad_state("infeasible before configure"),
            Learner::Golden(l) => l.tell_infeasible().map(drop),
            Learner::Illinois(l) => l.tell_infeasible().map(drop),
            Learner::Secant(l, _) => l.tell_infeasible().map(drop),
            Learner::Power => {
                return bad_state("PoWER is told an infeasible roll-out's reward (Tell)");
            }
        };
        match told {
            Ok(()) => {
                self.in_flight = false;
                Reply::Ok
            }
            Err(e) => fault(e),
        }
    }

    fn status(&self) -> Reply {
        let search = |l: &dyn ErrorLearner| Status {
            rollouts: l.rollouts(),
            updates: 0,
            search: l.status(),
            best_query: l.best().map(|b| query_of(&[b.query])),
            best: l.best().map(|b| b.error),
        };
        Reply::Status(match &self.learner {
            Learner::Idle => return bad_state("status before configure"),
            Learner::Golden(l) => search(l),
            Learner::Illinois(l) => search(l),
            Learner::Secant(l, _) => Status {
                rollouts: l.rollouts(),
                updates: 0,
                search: l.status(),
                best_query: l.best().map(|b| query_of(b.query)),
                best: l.best().map(|b| b.size),
            },
            Learner::Power => Status {
                rollouts: self.asked.wrapping_sub(u32::from(self.in_flight)),
                updates: self.power.updates(),
                search: SearchStatus::Running,
                best_query: self
                    .power
                    .best()
                    .and_then(|b| b.params.get(..self.query_dim))
                    .map(query_of),
                best: self.power.best().map(|b| b.reward),
            },
        })
    }

    /// Builds the in-flight roll-out's DMP, `θ = G(q̂) + Δθ`.
    fn dmp_start(&mut self, start: &DmpStart) -> Result<Reply, Error> {
        if !self.in_flight {
            return Ok(bad_state("movement without a roll-out in flight"));
        }
        if self.intake.index != self.intake.expected || self.examples.is_empty() {
            return Ok(bad_state("movement before all examples arrived"));
        }
        let Some((query, _)) = self.next_rollout() else {
            return Ok(bad_state("movement after the search finished"));
        };
        // θ = G(q̂) + Δθ in one buffer: the M4F's stack has no room for a
        // second. Asking again gives the same Δθ (empty for the error
        // learners), and + commutes, so the bits are those of Δθ + G(q̂).
        let mut theta = [0.0f32; P];
        let theta = theta.get_mut(..self.intake.theta_len).unwrap_or(&mut []);
        self.examples.generalize(&query, theta)?;
        if let Some((_, delta)) = self.next_rollout() {
            let len = delta.len();
            for (i, t) in theta.iter_mut().enumerate().take(len) {
                *t += delta.get(i);
            }
        }
        let dmp = Dmp::from_shape(
            &start.shape,
            start.start.len(),
            usize::from(start.kernels),
            &start.start,
            theta,
        )?;
        let run = dmp.start(&dmp.execution())?;
        if !(start.dt.is_finite() && start.dt > 0.0) {
            return Err(Error::OutOfRange("dt must be finite and > 0"));
        }
        self.motion = Stream::Moving(Motion {
            dmp,
            run,
            dt: start.dt,
            done: false,
        });
        Ok(Reply::Ok)
    }

    /// One control step; `done` once the step reaches τ (within half a
    /// step).
    fn dmp_next(&mut self) -> Reply {
        let Stream::Moving(m) = &mut self.motion else {
            return bad_state("setpoint before the movement started");
        };
        if m.done {
            return bad_state("the movement has finished");
        }
        if let Err(e) = m.run.step(&m.dmp, m.dt) {
            return fault(e);
        }
        let time = m.run.time();
        m.done = time + 0.5 * m.dt >= m.dmp.tau();
        Reply::Setpoint {
            time,
            position: m.run.position().iter().copied().collect(),
            done: m.done,
        }
    }
}
