//! An output directory is held by one process at a time: a learning run
//! (new or resumed) or an experiment takes `DIR/primo.lock` before it
//! writes anything there and keeps it until it ends.
//!
//! The lock is the operating system's (`flock`), on an open file: the
//! kernel releases it on any exit, SIGKILL included, so the file left
//! behind blocks nobody; only a live holder does. The holder writes its
//! pid and command line into the file, for the message of whoever it
//! refuses. The file stays: removing it would let a second process lock a
//! new file while a third still holds the old one.
//!
//! ```
//! use primo_learn::lock::{check_free, hold};
//! let dir = std::env::temp_dir().join(format!("primo-lock-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let held = hold(&dir).unwrap();
//! assert!(check_free(&dir).unwrap_err().to_string().contains("is in use by primo pid"));
//! drop(held);
//! check_free(&dir).unwrap();
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Write};
use std::path::Path;

use crate::Error;

/// The lock's file name in the directory it holds.
pub const FILE: &str = "primo.lock";

/// A held directory: held while this lives (and its process).
#[derive(Debug)]
pub struct Held {
    _file: File,
}

/// Takes `dir` (which exists) for this process, or refuses if another
/// holds it ([`Error::InUse`]).
pub fn hold(dir: &Path) -> Result<Held, Error> {
    let path = dir.join(FILE);
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(Error::io(&path))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(TryLockError::WouldBlock) => return Err(in_use(dir, &path)),
        Err(TryLockError::Error(e)) => return Err(Error::io(&path)(e)),
    }
    // Only the holder writes here, so a reader sees this or (briefly) an
    // empty file.
    file.set_len(0)
        .and_then(|()| file.write_all(holder().as_bytes()))
        .map_err(Error::io(&path))?;
    Ok(Held { _file: file })
}

/// Checks, without taking it, that no process holds `dir` (a directory
/// not made yet is free).
pub fn check_free(dir: &Path) -> Result<(), Error> {
    let path = dir.join(FILE);
    let file = match File::open(&path) {
        Ok(file) => file,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(Error::io(&path)(e)),
    };
    // A shared lock conflicts only with a holder's exclusive one; it goes
    // with `file`.
    match file.try_lock_shared() {
        Ok(()) => Ok(()),
        Err(TryLockError::WouldBlock) => Err(in_use(dir, &path)),
        Err(TryLockError::Error(e)) => Err(Error::io(&path)(e)),
    }
}

/// This process, as the lock file names it: its pid, a line, its command.
fn holder() -> String {
    let mut args = std::env::args();
    let program = args
        .next()
        .map(|a| {
            Path::new(&a)
                .file_name()
                .map_or(a.clone(), |n| n.to_string_lossy().into_owned())
        })
        .unwrap_or_default();
    let command: Vec<String> = std::iter::once(program).chain(args).collect();
    format!("{}\n{}\n", std::process::id(), command.join(" "))
}

/// The refusal of `dir`, naming its holder as its lock file at `path` does.
fn in_use(dir: &Path, path: &Path) -> Error {
    let mut text = String::new();
    let _ = File::open(path).and_then(|mut f| f.read_to_string(&mut text));
    let mut lines = text.lines();
    let pid = lines.next().and_then(|p| p.trim().parse().ok());
    let command = lines.next().map(str::to_string).filter(|c| !c.is_empty());
    Error::InUse {
        dir: dir.to_path_buf(),
        pid,
        command,
    }
}

/// Who holds a directory, as [`Error::InUse`] says it.
pub(crate) fn describe(dir: &Path, pid: &Option<u32>, command: &Option<String>) -> String {
    let by = match (pid, command) {
        (Some(pid), Some(command)) => format!("primo pid {pid} (`{command}`)"),
        (Some(pid), None) => format!("primo pid {pid}"),
        _ => "another process".into(),
    };
    format!(
        "{} is in use by {by}: wait for it or stop it",
        dir.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("primo-lock-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_held_directory_is_refused_naming_its_holder_and_free_once_dropped() {
        let d = dir("held");
        let held = hold(&d).unwrap();
        for refused in [hold(&d).unwrap_err(), check_free(&d).unwrap_err()] {
            let e = refused.to_string();
            assert!(
                e.contains(&format!("is in use by primo pid {} (`", std::process::id())),
                "{e}"
            );
            assert!(refused.is_input(), "{e}");
        }
        drop(held);
        check_free(&d).unwrap();
        let again = hold(&d).unwrap();
        drop(again);
    }

    #[test]
    fn a_lock_file_left_behind_blocks_nobody() {
        let d = dir("left");
        std::fs::write(d.join(FILE), "999999\nprimo pour --out gone\n").unwrap();
        check_free(&d).unwrap();
        let _held = hold(&d).unwrap();
        let text = std::fs::read_to_string(d.join(FILE)).unwrap();
        assert!(
            text.starts_with(&format!("{}\n", std::process::id())),
            "{text}"
        );
    }

    #[test]
    fn a_directory_not_made_yet_is_free() {
        check_free(&dir("none").join("not-yet")).unwrap();
    }
}
