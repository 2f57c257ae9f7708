//! An experiment's output directory, claimed before its runs begin: held
//! by this process ([`crate::lock`]) and free of an earlier result, so a
//! long experiment is never lost to another one written over it.

use std::path::Path;

use crate::Error;
use crate::lock::{self, Held};
use crate::output::{check_dir, create_dir};

/// Checks, without creating anything, that an experiment writing `files`
/// may write into `dir`: a directory or none yet, held by no process, and
/// holding none of `files` unless `force` (then they are replaced).
pub fn check(dir: &Path, files: &[&str], force: bool) -> Result<(), Error> {
    check_dir(dir)?;
    lock::check_free(dir)?;
    check_result(dir, files, force)
}

/// [`check`], then creates `dir` and holds it until the value returned is
/// dropped.
pub fn claim(dir: &Path, files: &[&str], force: bool) -> Result<Held, Error> {
    check(dir, files, force)?;
    create_dir(dir)?;
    let held = lock::hold(dir)?;
    // Again, now that no other process can write a result here.
    check_result(dir, files, force).map(|()| held)
}

fn check_result(dir: &Path, files: &[&str], force: bool) -> Result<(), Error> {
    match files.iter().map(|f| dir.join(f)).find(|f| f.exists()) {
        Some(file) if !force => Err(Error::HoldsResult { file }),
        _ => Ok(()),
    }
}
