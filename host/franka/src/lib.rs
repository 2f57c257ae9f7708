//! The Franka Control Interface (FCI) as libfranka 0.21 speaks it
//! (protocol version 10), primo's client side: a TCP command channel
//! (port [`DEFAULT_PORT`]) and a 1 kHz UDP stream, the robot's state out
//! and one joint-position command back each millisecond.
//!
//! - [`wire`]: the messages, byte for byte.
//! - [`plan`]: what is streamed, a checked [`primo_robot::JointPath`] as
//!   millisecond setpoints within the description's limits and the FCI's
//!   rate limits; the built-in FR3 description.
//! - [`retime`]: phase stopping, the plan played at a rate that waits
//!   for a robot lagging its command, every setpoint checked as it goes.
//! - [`session`]: the client, sans I/O: connect, model, motion, one
//!   command per state, finish; the robot's errors and reflexes as typed
//!   errors ([`FrankaError`]).
//! - [`net`]: the session on TCP and UDP, its loop on real-time threads.
//!
//! The simulated controller is the simulator's (`primo-sim`).
//!
//! ```
//! use primo_franka::parse_robot;
//! assert_eq!(parse_robot("franka:127.0.0.1")?.to_string(), "127.0.0.1:1337");
//! assert_eq!(parse_robot("franka:127.0.0.1:4000")?.to_string(), "127.0.0.1:4000");
//! assert!(parse_robot("fri:127.0.0.1").is_err());
//! # Ok::<(), primo_fri::AddressError>(())
//! ```

#![deny(missing_docs)]

mod error;
pub mod net;
pub mod plan;
pub mod retime;
pub mod session;
pub mod wire;

use std::net::{SocketAddr, ToSocketAddrs};

pub use error::{Exceeded, FrankaError, Quantity};
pub use primo_fri::AddressError;

/// The FCI's command port.
pub const DEFAULT_PORT: u16 = 1337;

/// Parses a robot address `franka:ADDR[:PORT]`: the robot's (its control
/// unit's) command channel, port [`DEFAULT_PORT`] unless given.
pub fn parse_robot(spec: &str) -> Result<SocketAddr, AddressError> {
    let bad = |why: String| AddressError {
        spec: spec.to_string(),
        why: format!(
            "{why}; expected franka:ADDR[:PORT], the robot's address (default port {DEFAULT_PORT})"
        ),
    };
    let Some(rest) = spec.strip_prefix("franka:") else {
        return Err(bad("unknown robot driver".into()));
    };
    let unbracketed = rest.trim_start_matches('[').trim_end_matches(']');
    if let Ok(ip) = unbracketed.parse::<std::net::IpAddr>() {
        return Ok(SocketAddr::new(ip, DEFAULT_PORT));
    }
    if let Ok(addr) = rest.parse::<SocketAddr>() {
        return Ok(addr);
    }
    let (host, port) = match rest.rsplit_once(':') {
        Some((host, port)) => (
            host,
            port.parse::<u16>()
                .map_err(|_| bad(format!("port `{port}` is not a number in 1..=65535")))?,
        ),
        None => (rest, DEFAULT_PORT),
    };
    if host.is_empty() {
        return Err(bad("no address".into()));
    }
    (host, port)
        .to_socket_addrs()
        .map_err(|e| bad(format!("cannot resolve `{host}`: {e}")))?
        .next()
        .ok_or_else(|| bad(format!("`{host}` resolves to no address")))
}
