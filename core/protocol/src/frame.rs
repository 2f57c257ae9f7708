//! Frames: `COBS(postcard(Frame) ‖ CRC-32C little-endian) ‖ 0x00`, at
//! most [`MAX_FRAME`] bytes with the delimiter. Every [`Frame`] carries the
//! request's sequence number; the reply repeats it (a repeated one is a
//! retransmission: see [`crate::replay`]).
//!
//! **Decoding** ([`FrameReader`], [`decode`]) never panics and never
//! allocates. A frame that is too long, fails COBS, fails the CRC, does not
//! parse, has trailing bytes, or is not the canonical encoding of what it
//! parses to is rejected with a [`FrameError`], and the stream resynchronizes
//! at the next 0x00.
//!
//! ```
//! use primo_protocol::frame::{self, FrameReader, MAX_FRAME};
//! use primo_protocol::learner::Request;
//! let mut buf = [0u8; MAX_FRAME];
//! let bytes = frame::encode(7, &Request::Ask, &mut buf)?;
//! let mut reader = FrameReader::new();
//! let mut got = None;
//! for b in bytes {
//!     if let Some(raw) = reader.push(*b) {
//!         got = Some(frame::decode::<Request>(raw?)?);
//!     }
//! }
//! let frame = got.unwrap();
//! assert_eq!((frame.seq, frame.body), (7, Request::Ask));
//! # Ok::<(), frame::FrameError>(())
//! ```

use core::fmt;

use crc::{CRC_32_ISCSI, Crc};
use postcard::ser_flavors::{Cobs, Slice};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// Largest frame on the line, in bytes, the 0x00 delimiter included.
pub const MAX_FRAME: usize = 160;

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

// `TooLong`'s message names the value.
const _: () = assert!(MAX_FRAME == 160);

impl fmt::Display for FrameError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FrameError::TooLong => "frame longer than 160 bytes",
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
    use crate::VERSION;
    use crate::fault::{Fault, FaultKind};
    use crate::learner::{
        CHUNK, Capacities, DmpStart, LearnerSetup, MAX_DOF, MAX_QUERY, Outcome, Query, Reply,
        Request, Rollout, Setup, Status,
    };
    use crate::scale::{
        self, CalibrationPoint, Identity, Reading, ScaleReply, ScaleRequest, Unit, WeighMode,
    };
    use heapless::{String, Vec};
    use primo_core::dmp::Shape;
    use primo_core::generalize::Method as Regression;
    use primo_core::golden::Status as SearchStatus;
    use primo_core::power::{Block, MAX_BLOCKS, PowerConfig};
    use primo_core::secant::{Rule, SecantConfig};
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
        let mut config = PowerConfig::paper(&[block; MAX_BLOCKS]).unwrap();
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
    fn the_largest_messages_fit_a_frame() {
        let mut buf = [0u8; MAX_FRAME];
        let full = Vec::from_slice(&[f32::MAX; CHUNK]).unwrap();
        let messages: [scale::Request; 7] = [
            biggest_setup().into(),
            setup(LearnerSetup::Secant(SecantConfig {
                low: full_query(),
                high: full_query(),
                desired: full_query(),
                precision: f32::MAX,
                max_rollouts: u32::MAX,
                gain: f32::MAX,
                rule: Rule::Weighted,
            }))
            .into(),
            Request::Tell(Outcome {
                error: full_query(),
                reward: f32::MAX,
            })
            .into(),
            Request::Example {
                index: u8::MAX,
                query: full_query(),
                offset: u16::MAX,
                values: full.clone(),
            }
            .into(),
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
            })
            .into(),
            scale::Request::Scale(ScaleRequest::Calibrate(CalibrationPoint::High {
                grams: f32::MAX,
            })),
            scale::Request::Scale(ScaleRequest::Weigh {
                mode: WeighMode::Next { within: u16::MAX },
                unit: Unit::Kg,
            }),
        ];
        for m in &messages {
            encode(u32::MAX, m, &mut buf).unwrap();
        }
        let replies: [scale::Reply; 7] = [
            Reply::Rollout(Rollout {
                number: u32::MAX,
                query: full_query(),
                delta_len: u16::MAX,
                mean: true,
                update: u32::MAX,
            })
            .into(),
            Reply::Status(Status {
                rollouts: u32::MAX,
                updates: u32::MAX,
                search: SearchStatus::BracketCollapsed,
                best_query: Some(full_query()),
                best: Some(f32::MAX),
            })
            .into(),
            Reply::Chunk {
                offset: u16::MAX,
                values: full,
            }
            .into(),
            Reply::Error(Fault::new(FaultKind::Invalid, "é".repeat(100))).into(),
            Reply::Setpoint {
                time: 1.0,
                position: Vec::from_slice(&[1.0; MAX_DOF]).unwrap(),
                done: true,
            }
            .into(),
            scale::Reply::Scale(ScaleReply::Identity(Identity {
                model: String::try_from("é".repeat(8).as_str()).unwrap(),
                serial: u32::MAX,
                capacity: f32::MAX,
                decimals: u8::MAX,
                rate: u16::MAX,
                calibrated: true,
            })),
            scale::Reply::Scale(ScaleReply::Reading(Reading {
                digits: i32::MIN,
                exponent: i8::MIN,
                unit: Unit::Mg,
                stable: true,
                net: true,
                sample: u32::MAX,
            })),
        ];
        for m in &replies {
            encode(u32::MAX, m, &mut buf).unwrap();
        }
    }

    /// The bytes of one message without frame: what postcard writes.
    fn bytes<T: Serialize>(body: &T) -> StdVec<u8> {
        let mut plain = [0u8; 4 * MAX_FRAME];
        postcard::to_slice(body, &mut plain).unwrap().to_vec()
    }

    #[test]
    fn the_learner_messages_have_the_same_bytes_on_both_devices() {
        let requests = [
            Request::Hello { version: VERSION },
            biggest_setup(),
            Request::Ask,
            Request::Fetch { offset: 300 },
            Request::DmpNext,
            Request::Infeasible,
        ];
        for r in requests {
            let on_scale = scale::Request::Learner(r.clone());
            assert_eq!(bytes(&on_scale), bytes(&r), "{r:?}");
            let mut buf = [0u8; MAX_FRAME];
            let frame = encode(3, &r, &mut buf).unwrap();
            let back = decode::<scale::Request>(&frame[..frame.len() - 1]).unwrap();
            assert_eq!(back.body, on_scale);
        }
        let replies = [
            Reply::Ok,
            Reply::Finished(SearchStatus::Converged),
            Reply::Error(Fault::new(FaultKind::Version, "v")),
        ];
        for r in replies {
            let on_scale = scale::Reply::Learner(r.clone());
            assert_eq!(bytes(&on_scale), bytes(&r), "{r:?}");
            let mut buf = [0u8; MAX_FRAME];
            let frame = encode(3, &on_scale, &mut buf).unwrap();
            assert_eq!(decode::<Reply>(&frame[..frame.len() - 1]).unwrap().body, r);
        }
    }

    #[test]
    fn the_scale_messages_follow_the_learner_s_and_the_coprocessor_cannot_read_them() {
        // After the learner's last request (Infeasible) and reply (Error).
        let last_request = bytes(&Request::Infeasible)[0];
        let last_reply = bytes(&Reply::Error(Fault::new(FaultKind::Invalid, "")))[0];
        let identify = scale::Request::Scale(ScaleRequest::Identify);
        assert_eq!(bytes(&identify), [last_request + 1, 0]);
        let reading = scale::Reply::Scale(ScaleReply::Reading(Reading {
            digits: 1,
            exponent: -2,
            unit: Unit::G,
            stable: true,
            net: false,
            sample: 9,
        }));
        assert_eq!(bytes(&reading)[..2], [last_reply + 1, 1]);
        let mut buf = [0u8; MAX_FRAME];
        let frame = encode(4, &identify, &mut buf).unwrap().to_vec();
        let raw = &frame[..frame.len() - 1];
        assert_eq!(decode::<Request>(raw), Err(FrameError::Malformed));
        assert_eq!(decode::<scale::Request>(raw).unwrap().body, identify);
        let frame = encode(4, &reading, &mut buf).unwrap().to_vec();
        let raw = &frame[..frame.len() - 1];
        assert_eq!(decode::<Reply>(raw), Err(FrameError::Malformed));
        assert_eq!(decode::<scale::Reply>(raw).unwrap().body, reading);
        // One past the scale's is nobody's.
        let mut past = bytes(&identify);
        past[0] += 1;
        assert!(postcard::from_bytes::<scale::Request>(&past).is_err());
    }

    #[test]
    fn the_handshake_keeps_the_bytes_of_every_version() {
        // Hello: variant 0, then the version; answered by variant 0 with
        // the version first, or by the fault at variant 7.
        assert_eq!(bytes(&Request::Hello { version: 5 }), [0, 5]);
        let hello = Reply::Hello {
            version: 300,
            capacities: Capacities {
                theta: 1,
                examples: 2,
                dof: 3,
                kernels: 4,
                sampler: 5,
            },
        };
        assert_eq!(bytes(&hello)[..3], [0, 0xAC, 0x02]);
        let refused = Reply::Error(Fault::new(FaultKind::Version, "x"));
        assert_eq!(bytes(&refused), [7, 0, 1, b'x']);
    }
}
