//! A simulated KRC: the robot side of FRI on UDP, driving the simulated
//! LWR4 and pouring cell, for tests and for trying primo without a robot.
//!
//! Every cycle (1–10 ms) it sends a measurement packet to the remote and
//! waits until the cycle's end for the answer; an answer with the wrong
//! `reflSeqCount` or after the cycle is stale and counts as a miss
//! (`answerRate`, `missRate`, `missCounter`, over the last
//! [`STAT_WINDOW`] cycles). As on a real KRC it opens in monitor mode; the
//! quality ramps BAD → OK → PERFECT as the remote answers (and falls with
//! the answer rate); once the quality is at least OK and the remote has
//! echoed the commanded position on time for [`HANDSHAKE`] cycles in a
//! row, it switches to command mode (`friStart`). In command mode the
//! commanded joint position is the remote's `jntPos`; if the remote falls
//! silent for `release_after` it falls back to monitor mode (`friStop`),
//! holding the last commanded position.
//!
//! The arm's measured position follows the commanded one through a
//! first-order lag of [`SERVO_LAG`] limited to the joint velocity limits;
//! commands beyond the position limits are clamped and counted, commands
//! faster than the velocity limits are counted. The pouring cell is
//! stepped with the measured joints (interpolated within the cycle at the
//! cell's ≤ 2 ms step), so the liquid pours; it is shared through a
//! [`CellHandle`] for other simulated instruments in the same process.
//!
//! It follows `jntPos` in command mode whatever the quality: checking the
//! quality is the remote's job, and the tests can see that it does it.
//!
//! The estimated external load (`estExtTcpFT`, and `estExtJntTrq`) is the
//! weight of the liquid still in the bottle: the tool's load data on a
//! real KRC cover the hand and the empty bottle, so what remains is the
//! liquid. The force (N) and its moment about the flange (N·m, the weight
//! taken at the bottle's centre: the liquid's centre of mass moving as it
//! tilts and empties is not modelled) are expressed in the flange frame,
//! the TCP of `msrCartPos`, as on a real LWR; each component carries
//! Gaussian noise ([`FORCE_NOISE`], [`MOMENT_NOISE`]) from the KRC's seed.
//! `estExtJntTrq` is `Jᵀ` times that noisy wrench. Inertial forces are not
//! modelled: the estimate is meant to be read while the arm stands still.
//!
//! [`Krc`] is that KRC as a state machine, sans I/O (time and datagrams
//! in, measurements out), tested in memory; [`SimKrc`] runs it on a UDP
//! socket and the wall clock. [`SimKrc::serve_scale`] serves the cell's
//! scale over MT-SICS, weighing what lands on the cell's pan;
//! [`SimKrc::serve_load_cell`] serves it as a bare load cell's raw counts,
//! for the scale firmware.

mod config;
mod machine;
mod report;
mod robot;
mod udp;
mod window;

pub use config::{CellHandle, KrcConfig};
pub use machine::{FORCE_NOISE, HANDSHAKE, Krc, MOMENT_NOISE};
pub use report::{CycleRecord, KrcReport, LATE_SEND};
pub use robot::SERVO_LAG;
pub use udp::SimKrc;
pub use window::{RAMP, STAT_WINDOW};
