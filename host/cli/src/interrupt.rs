//! Ctrl-C during a learning run: the first asks the run to stop after the
//! roll-out in progress (a robot is not stopped mid-pour), the second
//! stops at once. Either way the run log holds every roll-out made.

use std::sync::atomic::{AtomicU32, Ordering};

static PRESSED: AtomicU32 = AtomicU32::new(0);

/// Installs the handler; `hint` is said at the second Ctrl-C before the
/// process exits (status 130).
pub fn install(hint: String) -> Result<(), crate::error::CliError> {
    ctrlc::set_handler(move || {
        if PRESSED.fetch_add(1, Ordering::SeqCst) == 0 {
            eprintln!("primo: stopping after the roll-out in progress (Ctrl-C again to stop now)");
        } else {
            // Exiting runs no destructors: the evaluators' groups are ended
            // here.
            primo_learn::task::evaluator::end_all();
            eprintln!("primo: interrupted; {hint}");
            std::process::exit(crate::error::INTERRUPTED);
        }
    })
    .map_err(|e| crate::error::CliError::other(format!("cannot catch Ctrl-C: {e}")))
}

/// Whether Ctrl-C was pressed.
pub fn pressed() -> bool {
    PRESSED.load(Ordering::SeqCst) > 0
}
