//! The wire protocol of primo's devices (the learning coprocessor and the
//! load-cell scale), shared by the host and the firmware so the two ends
//! cannot drift apart.
//!
//! **Messages** are serde types encoded with postcard: the host sends
//! [`Request`]s, the device answers each with exactly one [`Reply`]. A
//! scale's requests and replies ([`crate::scale`]) travel inside
//! [`Request::Scale`] and [`Reply::Scale`]; a scale that streams sends
//! replies numbered [`crate::scale::STREAM`] unasked, and answers a
//! weighing of the next stable reading only once it has one (and not at
//! all if another request comes first: the host gave up on it).
//! Vectors longer than a frame (training examples, a roll-out's `Δθ`) travel
//! in [`CHUNK`]-value pieces, so that every frame stays small: on a line that
//! corrupts 1 % of its bytes a 40-byte frame still arrives intact two times
//! in three, a 900-byte one almost never.
//!
//! **Frames**: `COBS(postcard(Frame) ‖ CRC-32C little-endian) ‖ 0x00`, at
//! most [`MAX_FRAME`] bytes with the delimiter. Every [`Frame`] carries the
//! request's sequence number; the reply repeats it. A repeated sequence
//! number is a retransmission: the coprocessor answers it with the same
//! reply bytes and changes nothing (see [`crate::service`]).
//!
//! **Decoding** ([`FrameReader`], [`decode`]) never panics and never
//! allocates. A frame that is too long, fails COBS, fails the CRC, does not
//! parse, has trailing bytes, or is not the canonical encoding of what it
//! parses to is rejected with a [`FrameError`], and the stream resynchronizes
//! at the next 0x00.
//!
//! ```
//! use primo_core::wire::{self, FrameReader, Request, MAX_FRAME};
//! let mut buf = [0u8; MAX_FRAME];
//! let bytes = wire::encode(7, &Request::Ask, &mut buf)?;
//! let mut reader = FrameReader::new();
//! let mut got = None;
//! for b in bytes {
//!     if let Some(frame) = reader.push(*b) {
//!         got = Some(wire::decode::<Request>(frame?)?);
//!     }
//! }
//! let frame = got.unwrap();
//! assert_eq!((frame.seq, frame.body), (7, Request::Ask));
//! # Ok::<(), wire::FrameError>(())
//! ```

use core::fmt;

use crc::{CRC_32_ISCSI, Crc};
use heapless::{String, Vec};
use postcard::ser_flavors::{Cobs, Slice};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::dmp::Shape;
use crate::generalize::Method as Regression;
use crate::golden::{SearchConfig, Status as SearchStatus};
use crate::power::PowerConfig;
use crate::scale::{ScaleReply, ScaleRequest};
use crate::secant::SecantConfig;

/// Protocol version; a coprocessor speaking another one refuses to work.
/// 3: the scale's messages; 4: the scale's weighing modes, among them the
/// next stable reading, answered when it is ready, and PoWER's
/// error-learned query (`PowerConfig::query_gain`); 5: the kernel margin
/// in a DMP's shape (`Shape::margin`).
pub const VERSION: u16 = 5;
/// Largest frame on the line, in bytes, the 0x00 delimiter included.
pub const MAX_FRAME: usize = 160;
/// Values per chunk of a long vector.
pub const CHUNK: usize = 8;
/// Largest DoF count a DMP on the wire has.
pub const MAX_DOF: usize = 7;
/// Length of the detail text of an error reply.
pub const DETAIL: usize = 64;
/// Largest dimension of a task query.
pub const MAX_QUERY: usize = 4;

/// A task query `q` (or an error vector `ε` over one), of the setup's
/// `query_dim` values.
pub type Query = Vec<f32, MAX_QUERY>;

/// CRC-32C (Castagnoli): better error detection than the Ethernet CRC at
/// the same cost.
static CRC: Crc<u32> = Crc::<u32>::new(&CRC_32_ISCSI);

/// A message with its sequence number.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Frame<T> {
    /// The request's sequence number, repeated in its reply.
    pub seq: u32,
    /// The message.
    pub body: T,
}

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
    /// A request to the scale (a device that is none answers
    /// [`FaultKind::BadState`]).
    Scale(ScaleRequest),
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

/// What the coprocessor answers.
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
    /// The scale's answer.
    Scale(ScaleReply),
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
    /// The best roll-out's query, if any was told.
    pub best_query: Option<Query>,
    /// Its error (golden section, Illinois), its error's size `max_i |ε_i|`
    /// (secant) or its reward (PoWER).
    pub best: Option<f32>,
}

/// A failed request: the kind, and a text saying what was wrong.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fault {
    /// What kind of failure.
    pub kind: FaultKind,
    /// What was wrong, in words (cut at [`DETAIL`] bytes).
    pub detail: String<DETAIL>,
}

/// Kinds of [`Fault`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FaultKind {
    /// The host speaks another protocol version.
    Version,
    /// More than the coprocessor holds.
    Capacity,
    /// The request does not fit the learning state (e.g. tell before ask).
    BadState,
    /// The frame was corrupt or oversized and was dropped.
    BadFrame,
    /// The values were rejected (not finite, out of range, …).
    Invalid,
    /// The scale's load is beyond its capacity (or its zero range).
    Overload,
    /// The scale's load is below its zero range.
    Underload,
    /// The scale's reading is not stable yet: ask again.
    NotSettled,
    /// The scale has no calibration.
    Uncalibrated,
}

impl Fault {
    /// A fault whose detail is `detail`, cut to [`DETAIL`] bytes.
    pub fn new(kind: FaultKind, detail: impl fmt::Display) -> Self {
        let mut text = Truncating(String::new());
        let _ = fmt::write(&mut text, format_args!("{detail}"));
        Fault {
            kind,
            detail: text.0,
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.kind {
            FaultKind::Version => "version mismatch",
            FaultKind::Capacity => "over capacity",
            FaultKind::BadState => "bad state",
            FaultKind::BadFrame => "bad frame",
            FaultKind::Invalid => "invalid",
            FaultKind::Overload => "overload",
            FaultKind::Underload => "underload",
            FaultKind::NotSettled => "not settled",
            FaultKind::Uncalibrated => "uncalibrated",
        };
        write!(f, "{kind}: {}", self.detail)
    }
}

/// Writes what fits and drops the rest, on a character boundary.
struct Truncating(String<DETAIL>);

impl fmt::Write for Truncating {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

/// Why a frame was rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FrameError {
    /// Longer than [`MAX_FRAME`]; dropped up to the next 0x00.
    TooLong,
    /// An empty frame (two 0x00 in a row).
    Empty,
    /// Not valid COBS.
    Cobs,
    /// The CRC does not match: corrupted on the line.
    Crc,
    /// The bytes do not parse as the expected message.
    Malformed,
    /// Parses, but is not the canonical encoding of what it parses to
    /// (trailing bytes, an over-long integer).
    NonCanonical,
    /// The message does not fit in [`MAX_FRAME`] (when encoding).
    Overflow,
}

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FrameError::TooLong => "frame longer than MAX_FRAME",
            FrameError::Empty => "empty frame",
            FrameError::Cobs => "invalid COBS encoding",
            FrameError::Crc => "CRC mismatch",
            FrameError::Malformed => "message does not parse",
            FrameError::NonCanonical => "non-canonical encoding",
            FrameError::Overflow => "message too long for a frame",
        })
    }
}

impl core::error::Error for FrameError {}

/// Encodes `body` with sequence number `seq` into `buf`; returns the frame,
/// 0x00 delimiter included.
pub fn encode<'a, T: Serialize>(
    seq: u32,
    body: &T,
    buf: &'a mut [u8; MAX_FRAME],
) -> Result<&'a [u8], FrameError> {
    let flavor = postcard::ser_flavors::crc::CrcModifier::new(
        Cobs::try_new(Slice::new(buf)).map_err(|_| FrameError::Overflow)?,
        CRC.digest(),
    );
    let out: &mut [u8] = postcard::serialize_with_flavor(&Frame { seq, body }, flavor)
        .map_err(|_| FrameError::Overflow)?;
    Ok(out)
}

/// Decodes one frame (its bytes without the 0x00 delimiter, as
/// [`FrameReader::push`] gives them).
pub fn decode<T: Serialize + DeserializeOwned>(raw: &[u8]) -> Result<Frame<T>, FrameError> {
    if raw.is_empty() {
        return Err(FrameError::Empty);
    }
    let mut plain = [0u8; MAX_FRAME];
    let plain = plain.get_mut(..raw.len()).ok_or(FrameError::TooLong)?;
    plain.copy_from_slice(raw);
    let len = cobs::decode_in_place(plain).map_err(|_| FrameError::Cobs)?;
    let plain = plain.get(..len).ok_or(FrameError::Cobs)?;
    let (body, rest) =
        postcard::take_from_bytes_crc32::<Frame<T>>(plain, CRC.digest()).map_err(|e| match e {
            postcard::Error::DeserializeBadCrc => FrameError::Crc,
            _ => FrameError::Malformed,
        })?;
    if !rest.is_empty() {
        return Err(FrameError::NonCanonical);
    }
    // postcard accepts over-long varints; only the canonical bytes count,
    // so that a frame has exactly one meaning and one encoding.
    let mut again = [0u8; MAX_FRAME];
    let canonical = encode(body.seq, &body.body, &mut again)?;
    if canonical.split_last().map(|(_, bytes)| bytes) != Some(raw) {
        return Err(FrameError::NonCanonical);
    }
    Ok(body)
}

/// Cuts a byte stream into frames at each 0x00, without allocating. A frame
/// longer than [`MAX_FRAME`] is dropped whole (reported once, at its end).
#[derive(Debug, Clone)]
pub struct FrameReader {
    buf: [u8; MAX_FRAME],
    len: usize,
    overflow: bool,
}

impl Default for FrameReader {
    fn default() -> Self {
        Self::new()
    }
}

impl FrameReader {
    /// An empty reader.
    pub const fn new() -> Self {
        Self {
            buf: [0; MAX_FRAME],
            len: 0,
            overflow: false,
        }
    }

    /// Feeds one byte; at a 0x00 returns the frame's bytes (without the
    /// delimiter) or why it was dropped. Empty frames (0x00 0x00) are
    /// skipped silently: a sender may flush the line with a 0x00.
    pub fn push(&mut self, byte: u8) -> Option<Result<&[u8], FrameError>> {
        if byte != 0 {
            match self.buf.get_mut(self.len) {
                // One byte short of MAX_FRAME: the delimiter counts too.
                Some(slot) if self.len + 1 < MAX_FRAME => {
                    *slot = byte;
                    self.len += 1;
                }
                _ => self.overflow = true,
            }
            return None;
        }
        let (len, overflow) = (self.len, self.overflow);
        self.len = 0;
        self.overflow = false;
        if overflow {
            return Some(Err(FrameError::TooLong));
        }
        if len == 0 {
            return None;
        }
        self.buf.get(..len).map(Ok)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::power::Block;
    use std::string::ToString;
    use std::vec::Vec as StdVec;

    fn frames<T: Serialize + DeserializeOwned>(
        bytes: &[u8],
    ) -> StdVec<Result<Frame<T>, FrameError>> {
        let mut reader = FrameReader::new();
        let mut out = StdVec::new();
        for b in bytes {
            if let Some(f) = reader.push(*b) {
                out.push(f.and_then(decode::<T>));
            }
        }
        out
    }

    fn biggest_setup() -> Request {
        let block = Block {
            len: 30,
            variance: 1e-3,
            decay: 0.9,
        };
        let mut config = PowerConfig::paper(&[block; crate::power::MAX_BLOCKS]).unwrap();
        config.sampler = usize::from(u8::MAX);
        setup(LearnerSetup::Power {
            config,
            query: full_query(),
        })
    }

    fn full_query() -> Query {
        Vec::from_slice(&[f32::MAX; MAX_QUERY]).unwrap()
    }

    fn setup(learner: LearnerSetup) -> Request {
        Request::Configure(Setup {
            learner,
            examples: u8::MAX,
            theta_len: u16::MAX,
            regression: Regression::Gpr {
                length_scale: Some(1.0),
                noise: 1e-3,
            },
            seed: u64::MAX,
            query_dim: u8::MAX,
        })
    }

    #[test]
    fn the_largest_messages_fit_a_frame() {
        let mut buf = [0u8; MAX_FRAME];
        let full = Vec::from_slice(&[f32::MAX; CHUNK]).unwrap();
        let messages = [
            biggest_setup(),
            setup(LearnerSetup::Secant(SecantConfig {
                low: full_query(),
                high: full_query(),
                desired: full_query(),
                precision: f32::MAX,
                max_rollouts: u32::MAX,
                gain: f32::MAX,
                rule: crate::secant::Rule::Weighted,
            })),
            Request::Tell(Outcome {
                error: full_query(),
                reward: f32::MAX,
            }),
            Request::Example {
                index: u8::MAX,
                query: full_query(),
                offset: u16::MAX,
                values: full.clone(),
            },
            Request::DmpStart(DmpStart {
                shape: Shape {
                    alpha: 25.0,
                    width: 1.0,
                    margin: 1.0,
                    scaled: u32::MAX,
                },
                kernels: u8::MAX,
                start: Vec::from_slice(&[1.0; MAX_DOF]).unwrap(),
                dt: 0.001,
            }),
            Request::Scale(crate::scale::ScaleRequest::Calibrate(
                crate::scale::CalibrationPoint::High { grams: f32::MAX },
            )),
            Request::Scale(crate::scale::ScaleRequest::Weigh {
                mode: crate::scale::WeighMode::Next { within: u16::MAX },
                unit: crate::scale::Unit::Kg,
            }),
        ];
        for m in &messages {
            encode(u32::MAX, m, &mut buf).unwrap();
        }
        let replies = [
            Reply::Rollout(Rollout {
                number: u32::MAX,
                query: full_query(),
                delta_len: u16::MAX,
                mean: true,
                update: u32::MAX,
            }),
            Reply::Status(Status {
                rollouts: u32::MAX,
                updates: u32::MAX,
                search: SearchStatus::BracketCollapsed,
                best_query: Some(full_query()),
                best: Some(f32::MAX),
            }),
            Reply::Chunk {
                offset: u16::MAX,
                values: full,
            },
            Reply::Error(Fault::new(FaultKind::Invalid, "é".repeat(100))),
            Reply::Setpoint {
                time: 1.0,
                position: Vec::from_slice(&[1.0; MAX_DOF]).unwrap(),
                done: true,
            },
            Reply::Scale(ScaleReply::Identity(crate::scale::Identity {
                model: String::try_from("é".repeat(8).as_str()).unwrap(),
                serial: u32::MAX,
                capacity: f32::MAX,
                decimals: u8::MAX,
                rate: u16::MAX,
                calibrated: true,
            })),
            Reply::Scale(ScaleReply::Reading(crate::scale::Reading {
                digits: i32::MIN,
                exponent: i8::MIN,
                unit: crate::scale::Unit::Mg,
                stable: true,
                net: true,
                sample: u32::MAX,
            })),
        ];
        for m in &replies {
            encode(u32::MAX, m, &mut buf).unwrap();
        }
    }

    #[test]
    fn round_trip_through_the_reader() {
        let mut line = StdVec::new();
        let mut buf = [0u8; MAX_FRAME];
        line.extend_from_slice(encode(1, &biggest_setup(), &mut buf).unwrap());
        line.push(0); // a flush between frames is skipped
        line.extend_from_slice(encode(2, &Request::Ask, &mut buf).unwrap());
        let got = frames::<Request>(&line);
        assert_eq!(got.len(), 2);
        assert_eq!(got[0].as_ref().unwrap().body, biggest_setup());
        assert_eq!(got[1].as_ref().unwrap().seq, 2);
    }

    #[test]
    fn every_single_byte_corruption_is_rejected() {
        let mut buf = [0u8; MAX_FRAME];
        let frame = encode(9, &biggest_setup(), &mut buf).unwrap().to_vec();
        for i in 0..frame.len() {
            for flip in [0x01u8, 0x80, 0xFF] {
                let mut bad = frame.clone();
                bad[i] ^= flip;
                // Whatever the cut, nothing but the original is accepted.
                for f in frames::<Request>(&bad) {
                    assert!(f.is_err(), "byte {i} ^ {flip:#x} accepted");
                }
            }
        }
    }

    #[test]
    fn a_dropped_byte_is_rejected_and_the_next_frame_survives() {
        let mut buf = [0u8; MAX_FRAME];
        let a = encode(1, &Request::Status, &mut buf).unwrap().to_vec();
        let b = encode(2, &Request::Ask, &mut buf).unwrap().to_vec();
        for i in 0..a.len() - 1 {
            let mut line = a.clone();
            line.remove(i);
            line.extend_from_slice(&b);
            let got = frames::<Request>(&line);
            assert!(got[..got.len() - 1].iter().all(|f| f.is_err()));
            assert_eq!(got.last().unwrap().as_ref().unwrap().body, Request::Ask);
        }
    }

    #[test]
    fn oversized_frames_are_dropped_whole_and_the_stream_resyncs() {
        let mut line = std::vec![0x55u8; 3 * MAX_FRAME];
        line.push(0);
        let mut buf = [0u8; MAX_FRAME];
        line.extend_from_slice(encode(3, &Request::DmpNext, &mut buf).unwrap());
        let got = frames::<Request>(&line);
        assert_eq!(got[0], Err(FrameError::TooLong));
        assert_eq!(got[1].as_ref().unwrap().body, Request::DmpNext);
    }

    /// COBS-wraps `plain` (message and CRC) as a frame without delimiter.
    fn wrap(plain: &[u8]) -> StdVec<u8> {
        let mut enc = [0u8; 2 * MAX_FRAME];
        let n = cobs::encode(plain, &mut enc);
        enc[..n].to_vec()
    }

    #[test]
    fn trailing_bytes_and_wrong_types_are_rejected() {
        // A valid Status frame with a byte after the CRC.
        let mut plain = [0u8; 64];
        let frame = Frame {
            seq: 1,
            body: Request::Status,
        };
        let n = postcard::to_slice_crc32(&frame, &mut plain, CRC.digest())
            .unwrap()
            .len();
        assert!(decode::<Request>(&wrap(&plain[..n])).is_ok());
        assert_eq!(
            decode::<Request>(&wrap(&plain[..n + 1])),
            Err(FrameError::NonCanonical)
        );
        // A reply is not a request.
        let mut buf = [0u8; MAX_FRAME];
        let reply = encode(1, &Reply::Finished(SearchStatus::Converged), &mut buf).unwrap();
        assert!(decode::<Request>(&reply[..reply.len() - 1]).is_err());
    }

    #[test]
    fn over_long_varints_are_not_canonical() {
        let mut plain = [0u8; 64];
        let n = postcard::to_slice(
            &Frame {
                seq: 1u32,
                body: Request::Ask,
            },
            &mut plain,
        )
        .unwrap()
        .len();
        // seq 1 as the two-byte varint 0x81 0x00, with a correct CRC.
        let mut long = std::vec![0x81u8, 0x00];
        long.extend_from_slice(&plain[1..n]);
        long.extend_from_slice(&CRC.checksum(&long).to_le_bytes());
        assert_eq!(
            decode::<Request>(&wrap(&long)),
            Err(FrameError::NonCanonical)
        );
    }

    #[test]
    fn fault_details_are_cut_on_a_character_boundary() {
        let f = Fault::new(FaultKind::Invalid, "ü".repeat(DETAIL));
        assert_eq!(f.detail.len(), DETAIL);
        assert!(f.to_string().starts_with("invalid: ü"));
    }
}
