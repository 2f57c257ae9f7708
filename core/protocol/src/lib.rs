//! # primo-protocol
//!
//! The wire protocol of primo's devices, the learning coprocessor and the
//! load-cell scale, shared by the host and the firmware so the two ends
//! cannot drift apart: the interface control document (ICD) of the
//! devices, as a `no_std` crate of types and framing with no device logic.
//!
//! - [`frame`]: `COBS(postcard(Frame) ‖ CRC-32C) ‖ 0x00`, a sequence
//!   number in every frame; decoding never panics and never allocates.
//! - [`learner`]: the learner's messages (setup, examples, ask/tell, the
//!   streamed movement) and the version handshake.
//! - [`scale`]: the scale's messages (weighings, zero, tare, calibration,
//!   the stream of readings), and the scale device's request and reply
//!   types, the learner's messages besides the scale's.
//! - [`endpoint`]: each device's endpoint, what it accepts and answers.
//! - [`fault`]: how a request fails, on every device.
//! - [`replay`]: retransmissions, one piece for every device: a repeated
//!   sequence number gets the previous reply's bytes again and changes
//!   nothing.
//!
//! The host sends requests, the device answers each with exactly one
//! reply. A host greets a device with [`learner::Request::Hello`] and
//! refuses one that speaks another [`VERSION`].
//!
//! The learner's handler (the service the coprocessor runs) is the crate
//! `primo-learner`, the scale's the crate `primo-device`: the protocol is
//! what both ends agree on, and a host that only talks to a device needs
//! no more of it.
//!
//! ```
//! use primo_protocol::frame::{self, MAX_FRAME};
//! use primo_protocol::{learner, scale};
//! let mut buf = [0u8; MAX_FRAME];
//! // The learner's request has the same bytes on either device …
//! let ask = frame::encode(7, &learner::Request::Ask, &mut buf)?.to_vec();
//! let on_scale = frame::encode(7, &scale::Request::Learner(learner::Request::Ask), &mut buf)?;
//! assert_eq!(ask, on_scale);
//! // … and the scale's is one the coprocessor cannot read.
//! let weigh = scale::Request::Scale(scale::ScaleRequest::Identify);
//! let bytes = frame::encode(8, &weigh, &mut buf)?;
//! let raw = &bytes[..bytes.len() - 1];
//! assert!(frame::decode::<learner::Request>(raw).is_err());
//! assert_eq!(frame::decode::<scale::Request>(raw)?.body, weigh);
//! # Ok::<(), frame::FrameError>(())
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

#[cfg(test)]
extern crate std;

pub mod endpoint;
mod extend;
pub mod fault;
pub mod frame;
pub mod learner;
pub mod replay;
pub mod scale;

/// Protocol version; a device speaking another one refuses to work.
/// 3: the scale's messages; 4: the scale's weighing modes, among them the
/// next stable reading, answered when it is ready, and PoWER's
/// error-learned query (`PowerConfig::query_gain`); 5: the kernel margin
/// in a DMP's shape (`Shape::margin`); 6: each device its own messages:
/// the learning coprocessor no longer reads the scale's (every message
/// keeps its version-5 bytes); 7: an error learner is told of a roll-out
/// that could not be made (`Request::Infeasible`, the search's
/// `Infeasible` status); 8: error learning on the movement's goals
/// (`LearnerSetup::SecantGoals`).
pub const VERSION: u16 = 8;
