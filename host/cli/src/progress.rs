//! Progress on stderr: a bar redrawn in place when stderr is a terminal;
//! otherwise nothing for roll-outs (their lines are on stdout) and an
//! occasional line for experiments' runs.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Least time between two progress lines when stderr is not a terminal.
const EVERY: Duration = Duration::from_secs(60);

/// A progress bar on stderr.
pub struct Progress {
    /// Steps in all (roll-outs in the budget, runs of an experiment).
    pub total: u32,
    tty: bool,
    started: Instant,
    /// When the last line went to a non-terminal.
    said: Instant,
}

impl Progress {
    /// A bar started now, of one step until told the total.
    pub fn new() -> Self {
        let now = Instant::now();
        Progress {
            total: 1,
            tty: std::io::stderr().is_terminal(),
            started: now,
            said: now,
        }
    }

    /// Shows `done` of the total, with a note (on a terminal only).
    pub fn show(&self, done: u32, note: &str) {
        if !self.tty {
            return;
        }
        let width = 30;
        let filled = (done.min(self.total) * width / self.total.max(1)) as usize;
        eprint!(
            "\r[{}{}] {done}/{} {note}   ",
            "#".repeat(filled),
            ".".repeat(width as usize - filled),
            self.total
        );
    }

    /// Shows `done` runs of the total with the time spent and the time
    /// left at the pace so far: on a terminal in the bar, else as a line
    /// at most every minute (none for the last run: the results follow).
    pub fn runs(&mut self, command: &str, done: u32) {
        let spent = self.started.elapsed();
        let left =
            spent.mul_f64(f64::from(self.total.saturating_sub(done)) / f64::from(done.max(1)));
        let times = format!("{} elapsed, ETA {}", clock(spent), clock(left));
        if self.tty {
            self.show(done, &format!("runs, {times}"));
        } else if done < self.total && self.said.elapsed() >= EVERY {
            self.said = Instant::now();
            eprintln!("{command}: {done}/{} runs, {times}", self.total);
        }
    }

    /// Clears the bar.
    pub fn clear(&self) {
        if self.tty {
            eprint!("\r{}\r", " ".repeat(79));
        }
    }
}

/// `m:ss`, or `h:mm:ss` from an hour.
fn clock(d: Duration) -> String {
    let s = d.as_secs();
    let (h, m, s) = (s / 3600, s / 60 % 60, s % 60);
    if h > 0 {
        format!("{h}:{m:02}:{s:02}")
    } else {
        format!("{m}:{s:02}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clock_reads_as_minutes_or_hours() {
        assert_eq!(clock(Duration::from_secs(0)), "0:00");
        assert_eq!(clock(Duration::from_millis(65_900)), "1:05");
        assert_eq!(clock(Duration::from_secs(3600 + 62)), "1:01:02");
    }
}
