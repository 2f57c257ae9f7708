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
    Realtime {
        fifo: schedule(),
        locked,
    }
}

/// Asks for `SCHED_FIFO` at [`PRIORITY`] for the calling thread: the
/// priority, or why not.
#[cfg(target_os = "linux")]
pub fn schedule() -> Result<i32, String> {
    let param = libc::sched_param {
        sched_priority: PRIORITY,
    };
    // SAFETY: the calling thread's own handle and a valid parameter.
    match unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) } {
        0 => Ok(PRIORITY),
        errno => Err(std::io::Error::from_raw_os_error(errno).to_string()),
    }
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

/// The first `n` CPUs the process may run on (fewer if it may use fewer;
/// none if that cannot be known).
#[cfg(target_os = "linux")]
pub fn cpus(n: usize) -> Vec<usize> {
    // SAFETY: an all-zero cpu_set_t is an empty set.
    let mut set: libc::cpu_set_t = unsafe { std::mem::zeroed() };
    // SAFETY: the calling process, a set of the size given.
    if unsafe { libc::sched_getaffinity(0, std::mem::size_of_val(&set), &mut set) } != 0 {
        return Vec::new();
    }
    (0..libc::CPU_SETSIZE as usize)
        // SAFETY: a valid set and an index within its size.
        .filter(|&cpu| unsafe { libc::CPU_ISSET(cpu, &set) })
        .take(n)
        .collect()
}

/// Pins the calling thread to `cpu`.
#[cfg(target_os = "linux")]
pub fn pin(cpu: usize) -> Result<(), String> {
    // SAFETY: an all-zero cpu_set_t is an empty set.
    let mut set: libc::cpu_set_t = unsafe { std::mem::zeroed() };
    // SAFETY: CPU_SET checks the index against the set's size.
    unsafe { libc::CPU_SET(cpu, &mut set) };
    // SAFETY: the calling thread's own handle and a set of the size given.
    match unsafe {
        libc::pthread_setaffinity_np(libc::pthread_self(), std::mem::size_of_val(&set), &set)
    } {
        0 => Ok(()),
        errno => Err(std::io::Error::from_raw_os_error(errno).to_string()),
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

/// Not implemented off Linux: says so.
#[cfg(not(target_os = "linux"))]
pub fn schedule() -> Result<i32, String> {
    Err("implemented on Linux only".to_string())
}

/// Not known off Linux: none.
#[cfg(not(target_os = "linux"))]
pub fn cpus(_: usize) -> Vec<usize> {
    Vec::new()
}

/// Not implemented off Linux.
#[cfg(not(target_os = "linux"))]
pub fn pin(_: usize) -> Result<(), String> {
    Err("implemented on Linux only".to_string())
}

/// Nothing to undo off Linux.
#[cfg(not(target_os = "linux"))]
pub fn leave(_: &Realtime) {}
