//! A run's wall-clock time over its sessions. The run log keeps no time,
//! so that a resumed run's log is the uninterrupted run's bit for bit:
//! each session, as it ends, writes the run's time so far beside the log
//! (`time.json`), and the next one adds its own. A session killed outright
//! (SIGKILL, power lost) leaves no time: its part is not counted.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::output::write_json;

/// The file beside the run log.
pub const FILE: &str = "time.json";

/// A run's wall-clock time, s, as its summary gives it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Seconds {
    /// Over all its sessions that ended (not killed outright), and this
    /// one.
    #[serde(rename = "seconds")]
    pub total: f64,
    /// This session's alone (the whole run unless it was resumed).
    #[serde(rename = "session_seconds")]
    pub session: f64,
}

/// This session's clock; dropped as the session ends, it writes the run's
/// time so far.
#[derive(Debug)]
pub struct Clock {
    file: PathBuf,
    before: f64,
    started: Instant,
}

impl Clock {
    /// The clock of a session of the run in `dir` that began at
    /// `started`, after the earlier sessions' time written there (none:
    /// 0, as for a run logged before primo kept it).
    pub fn start(dir: &Path, started: Instant) -> Clock {
        let file = dir.join(FILE);
        let before = std::fs::read(&file)
            .ok()
            .and_then(|bytes| serde_json::from_slice::<Seconds>(&bytes).ok())
            .map_or(0.0, |s| s.total);
        Clock {
            file,
            before,
            started,
        }
    }

    /// The time now.
    pub fn now(&self) -> Seconds {
        let session = self.started.elapsed().as_secs_f64();
        Seconds {
            total: self.before + session,
            session,
        }
    }
}

impl Drop for Clock {
    fn drop(&mut self) {
        // The time is a report, not the run: a session whose directory can
        // no longer be written has failed already, and says so.
        let _ = write_json(&self.file, &self.now());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sessions_add_up() {
        let dir = std::env::temp_dir().join(format!("primo-clock-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let earlier = Instant::now() - std::time::Duration::from_secs(5);
        drop(Clock::start(&dir, earlier));
        let now = Clock::start(&dir, Instant::now()).now();
        assert!(now.total >= 5.0 && now.session < 1.0, "{now:?}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
