//! Mettler Toledo MT-SICS precision scales: the protocol, and a client for
//! a scale on a serial port. The simulated scale that speaks it lives with
//! the simulator (`primo-sim`).
//!
//! - [`parse_response`] turns any line into a typed [`Response`] or an
//!   error quoting it; [`Response`]'s `Display` writes the line back.
//! - [`Client`]: the client (`@`, `S`, `SI`, `Z`, `T`, `TAC`) on a serial
//!   port, with timeouts, re-sends, waiting for a stable reading, and
//!   skipping of line noise and power-on lines (feature `serial`, on by
//!   default).
//! - [`path`]: what is wrong with a port or file that would not open, one
//!   wording for every command (feature `serial`).
//!
#![deny(missing_docs)]

#[cfg(feature = "serial")]
mod client;
mod fixed;
#[cfg(feature = "serial")]
pub mod path;
mod protocol;

#[cfg(feature = "serial")]
pub use client::{ASK_AGAIN, Client, ClientConfig, ErrorKind, Noise, ScaleError};
pub use fixed::Fixed;
pub use protocol::{
    Lines, MAX_LINE, Reply, Response, ResponseError, Stability, Unit, Weight, parse_response,
    parse_tail, parse_value, quote,
};
