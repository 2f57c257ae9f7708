//! Whether this process may read its terminal.

use std::io::IsTerminal;

/// Whether stdin is a terminal this process is in the background of (a
/// shell's `&`): reading it would stop the process (SIGTTIN). From
/// `/proc/self/stat` (process group and the terminal's foreground group);
/// without it, assume the foreground.
pub fn in_background() -> bool {
    if !std::io::stdin().is_terminal() {
        return false;
    }
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return false;
    };
    // After `pid (comm)`: state, ppid, pgrp, session, tty_nr, tpgid.
    let fields: Vec<&str> = stat
        .rsplit_once(')')
        .map(|(_, rest)| rest.split_whitespace().collect())
        .unwrap_or_default();
    matches!((fields.get(2), fields.get(5)), (Some(pgrp), Some(tpgid)) if pgrp != tpgid)
}
