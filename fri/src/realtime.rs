//! Real-time scheduling for the FRI loop's thread: `SCHED_FIFO` and locked
//! memory where the OS allows them, and why not where it does not. A
//! busy machine otherwise preempts the loop for milliseconds, and a 2 ms
//! cycle answered late is a cycle lost.

use std::fmt;

/// The `SCHED_FIFO` priority of the FRI loop: above every normal process
/// and the threaded interrupt handlers of a PREEMPT_RT kernel (50), below
/// the kernel's own watchdog and migration threads (99); cyclictest's
/// usual choice.
pub const PRIORITY: i32 = 80;

/// What the OS granted the FRI loop's thread.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Realtime {
    /// `SCHED_FIFO` at this priority, or why not.
    pub fifo: Result<i32, String>,
    /// The process's memory locked (no page faults), or why not.
    pub locked: Result<(), String>,
}

impl Realtime {
    /// Both granted.
    pub fn is_full(&self) -> bool {
        self.fifo.is_ok() && self.locked.is_ok()
    }
}

impl fmt::Display for Realtime {
    /// One line: what was granted, what was not and how to allow it.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.fifo {
            Ok(p) => write!(f, "real-time scheduling (SCHED_FIFO {p})")?,
            Err(why) => write!(
                f,
                "no real-time scheduling ({why}; allow it: root, CAP_SYS_NICE, or `ulimit -r {PRIORITY}`)"
            )?,
        }
        match &self.locked {
            Ok(()) => f.write_str(", memory locked"),
            Err(why) => write!(
                f,
                ", memory not locked ({why}; allow it: root, CAP_IPC_LOCK, or `ulimit -l unlimited`)"
            ),
        }
    }
}

/// Asks for `SCHED_FIFO` at [`PRIORITY`] for the calling thread and locks
/// the process's memory, present and future (undone by [`leave`]).
#[cfg(target_os = "linux")]
pub fn enter() -> Realtime {
    let os_error = || std::io::Error::last_os_error().to_string();
    // SAFETY: mlockall takes flags only and touches no Rust memory.
    let locked = match unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } {
        0 => Ok(()),
        _ => Err(os_error()),
    };
    let param = libc::sched_param {
        sched_priority: PRIORITY,
    };
    // SAFETY: the calling thread's own handle and a valid parameter.
    let fifo = match unsafe {
        libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param)
    } {
        0 => Ok(PRIORITY),
        errno => Err(std::io::Error::from_raw_os_error(errno).to_string()),
    };
    Realtime { fifo, locked }
}

/// Unlocks the memory [`enter`] locked (the thread's scheduling ends with
/// the thread).
#[cfg(target_os = "linux")]
pub fn leave(realtime: &Realtime) {
    if realtime.locked.is_ok() {
        // SAFETY: no arguments; it cannot fail in a way that matters here.
        unsafe { libc::munlockall() };
    }
}

/// Not implemented off Linux: says so.
#[cfg(not(target_os = "linux"))]
pub fn enter() -> Realtime {
    let why = || "implemented on Linux only".to_string();
    Realtime {
        fifo: Err(why()),
        locked: Err(why()),
    }
}

/// Nothing to undo off Linux.
#[cfg(not(target_os = "linux"))]
pub fn leave(_: &Realtime) {}
