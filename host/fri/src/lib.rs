//! The KUKA Fast Research Interface (FRI) of the LWR4 on a KRC2lr: the robot controller (KRC) sends a measurement packet
//! over UDP every cycle (1–10 ms) and the remote side, primo, answers each
//! with exactly one command packet within the cycle.
//!
//! - [`packet`]: the measurement and command datagrams, byte for byte.
//! - [`path`]: what FRI streams, a checked joint trajectory
//!   ([`primo_robot::JointPath`]) of seven joints.
//! - [`session`]: primo's side, sans I/O: a session that streams it with
//!   the tracking error.
//! - [`udp`]: the UDP loop around a session, on a thread of its own.
//! - [`realtime`]: real-time scheduling and locked memory for that thread.
//!
//! The simulated KRC is the simulator's (`primo-sim`).
//!
//! Addressing is as on a real cell: in `fri:ADDR:PORT`, `ADDR:PORT` is the
//! local UDP address primo binds (default port [`DEFAULT_PORT`]); the KRC
//! is configured to send its packets there, and primo answers each one to
//! the address it came from.
//!
//! ```
//! use primo_fri::parse_robot;
//! assert_eq!(parse_robot("fri:127.0.0.1")?.to_string(), "127.0.0.1:49938");
//! assert_eq!(parse_robot("fri:[::1]:50000")?.to_string(), "[::1]:50000");
//! assert!(parse_robot("127.0.0.1:49938").unwrap_err().to_string().contains("expected fri:ADDR"));
//! # Ok::<(), primo_fri::AddressError>(())
//! ```

#![deny(missing_docs)]

pub mod packet;
pub mod path;
pub mod realtime;
pub mod session;
pub mod udp;

use std::net::{IpAddr, SocketAddr, ToSocketAddrs};

/// A robot address that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("robot address `{spec}`: {}", self.explained())]
pub struct AddressError {
    /// What was given.
    pub spec: String,
    /// What is wrong with it.
    pub why: String,
}

impl AddressError {
    /// What is wrong, and what an address is.
    pub fn explained(&self) -> String {
        format!(
            "{}; expected fri:ADDR[:PORT], the local UDP address primo binds for the KRC's \
             packets (default port {DEFAULT_PORT})",
            self.why
        )
    }
}

/// The UDP port a KRC sends its FRI packets to unless configured otherwise.
pub const DEFAULT_PORT: u16 = 49938;

/// Parses a robot address `fri:ADDR[:PORT]` into the local address to bind. `ADDR`
/// is an IP address (IPv6 in brackets when a port follows) or a host name.
pub fn parse_robot(spec: &str) -> Result<SocketAddr, AddressError> {
    let bad = |why: String| AddressError {
        spec: spec.to_string(),
        why,
    };
    let Some(rest) = spec.strip_prefix("fri:") else {
        return Err(bad("unknown robot driver".into()));
    };
    let unbracketed = rest.trim_start_matches('[').trim_end_matches(']');
    if let Ok(ip) = unbracketed.parse::<IpAddr>() {
        return Ok(SocketAddr::new(ip, DEFAULT_PORT));
    }
    if let Ok(addr) = rest.parse::<SocketAddr>() {
        return check_port(addr).map_err(bad);
    }
    let (host, port) = match rest.rsplit_once(':') {
        Some((host, port)) if !host.contains(':') || host.starts_with('[') => {
            let port = port
                .parse::<u16>()
                .map_err(|_| bad(format!("port `{port}` is not a number in 1..=65535")))?;
            (host, port)
        }
        _ => (rest, DEFAULT_PORT),
    };
    if host.is_empty() {
        return Err(bad("no address".into()));
    }
    let mut addrs = (host, port)
        .to_socket_addrs()
        .map_err(|e| bad(format!("cannot resolve `{host}`: {e}")))?;
    let addr = addrs
        .next()
        .ok_or_else(|| bad(format!("`{host}` resolves to no address")))?;
    check_port(addr).map_err(bad)
}

fn check_port(addr: SocketAddr) -> Result<SocketAddr, String> {
    if addr.port() == 0 {
        return Err("port 0: the KRC needs a fixed port to send to".into());
    }
    Ok(addr)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn robot_addresses() {
        let ok = |s: &str| parse_robot(s).unwrap().to_string();
        assert_eq!(ok("fri:0.0.0.0:30200"), "0.0.0.0:30200");
        assert_eq!(ok("fri:192.168.0.2"), "192.168.0.2:49938");
        assert_eq!(ok("fri:::1"), "[::1]:49938");
        assert_eq!(ok("fri:[::1]"), "[::1]:49938");
        assert_eq!(ok("fri:localhost:40000").rsplit(':').next(), Some("40000"));
        let err = |s: &str| parse_robot(s).unwrap_err().to_string();
        assert!(
            err("udp:1.2.3.4").starts_with("robot address `udp:1.2.3.4`: unknown robot driver;")
        );
        assert!(
            err("fri:127.0.0.1:http").starts_with(
                "robot address `fri:127.0.0.1:http`: port `http` is not a number in 1..=65535"
            ),
            "{}",
            err("fri:127.0.0.1:http")
        );
        assert!(err("fri:127.0.0.1:70000").contains("port `70000` is not a number"));
        assert!(err("fri:127.0.0.1:0").contains("port 0: the KRC needs a fixed port"));
        assert!(err("fri:").contains("no address"));
        assert!(err("fri::5").contains("no address"));
    }
}
