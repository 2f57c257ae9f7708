//! What happened while the KRC ran: the counts of a [`KrcReport`] and,
//! when recording, a [`CycleRecord`] of every cycle.

use std::time::Duration;

use primo_fri::packet::{Quality, State};
use primo_robot::JOINTS;

/// The fraction of a cycle after which a send counts as late
/// ([`KrcReport::late_sends`]).
pub const LATE_SEND: f64 = 0.25;

/// One cycle as the KRC saw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleRecord {
    /// Time since power-on, s.
    pub t: f64,
    /// Interface state sent.
    pub state: State,
    /// Quality sent.
    pub quality: Quality,
    /// The measurement was sent (not lost).
    pub sent: bool,
    /// An answer came back on time.
    pub answered: bool,
    /// The commanded joint position after the cycle.
    pub target: [f64; JOINTS],
    /// The measured joint position after the cycle.
    pub measured: [f64; JOINTS],
}

/// What happened while the KRC ran.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct KrcReport {
    /// Cycles run.
    pub cycles: u64,
    /// Measurement packets sent.
    pub sent: u64,
    /// Measurement packets lost on purpose.
    pub dropped: u64,
    /// Cycles answered on time.
    pub answered: u64,
    /// Cycles not answered on time (`missCounter`).
    pub missed: u64,
    /// Answers with the wrong `reflSeqCount` or after their cycle.
    pub stale: u64,
    /// Datagrams that are not command packets.
    pub malformed: u64,
    /// Measurements sent more than [`LATE_SEND`] of a cycle after they
    /// were due: the simulator's own lateness (a real KRC sends on a
    /// real-time clock), which leaves the remote less time to answer.
    pub late_sends: u64,
    /// The latest send after it was due, s.
    pub max_send_delay: f64,
    /// Commands in command mode faster than the velocity limits.
    pub too_fast: u64,
    /// Commands in command mode beyond the position limits (clamped).
    pub beyond_limits: u64,
    /// Cycles in command mode.
    pub command_cycles: u64,
    /// When command mode was first entered, s.
    pub entered_command: Option<f64>,
    /// When it was last left, s.
    pub left_command: Option<f64>,
    /// Largest distance of the measured position from the start, rad.
    pub max_excursion: f64,
    /// The measured joint position at the end.
    pub measured: [f64; JOINTS],
    /// Why the first few malformed datagrams were rejected.
    pub rejections: Vec<String>,
    /// Every cycle, if recording.
    pub log: Vec<CycleRecord>,
}

impl KrcReport {
    /// Notes a measurement sent `delay` after it was due.
    pub(super) fn sent_after(&mut self, delay: Duration, cycle: Duration) {
        self.late_sends += u64::from(delay > cycle.mul_f64(LATE_SEND));
        self.max_send_delay = self.max_send_delay.max(delay.as_secs_f64());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sends_later_than_a_quarter_cycle_count_as_late() {
        let cycle = Duration::from_millis(2);
        let mut report = KrcReport::default();
        report.sent_after(Duration::from_micros(20), cycle);
        report.sent_after(Duration::from_micros(500), cycle);
        assert_eq!(report.late_sends, 0);
        report.sent_after(Duration::from_micros(1500), cycle);
        report.sent_after(Duration::from_micros(700), cycle);
        assert_eq!(report.late_sends, 2);
        assert!((report.max_send_delay - 1.5e-3).abs() < 1e-12);
    }
}
