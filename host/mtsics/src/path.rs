//! What is wrong with a path the user gave: one classification and one
//! wording for every serial port and input file primo opens (the scale's
//! and the coprocessor's ports, demonstrations, task and DMP files), so
//! that the same fault gets the same answer from every command.

use std::fmt;
use std::io;
use std::path::Path;

/// What a path was to be.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wanted {
    /// A serial port: a terminal device.
    Port,
    /// A file to read.
    File,
}

/// Why a path would not open as what it was wanted for.
#[derive(Debug)]
pub enum Fault {
    /// Nothing is there.
    Missing,
    /// This user may not open it.
    Denied(Wanted),
    /// Something else is there: what.
    Not(Wanted, &'static str),
    /// Opening or reading it failed otherwise: not the path's fault.
    Io(io::Error),
}

impl Fault {
    /// Why `path`, wanted as `wanted`, failed to open or read with `e`.
    pub fn of(path: &Path, wanted: Wanted, e: io::Error) -> Fault {
        match check(path, wanted) {
            Err(fault) => fault,
            Ok(()) => match e.kind() {
                io::ErrorKind::NotFound => Fault::Missing,
                io::ErrorKind::PermissionDenied => Fault::Denied(wanted),
                _ => Fault::Io(e),
            },
        }
    }

    /// Whether the user can fix it by naming another path (bad input, exit
    /// status 2 on the command line), not a failure while opening.
    pub fn is_input(&self) -> bool {
        !matches!(self, Fault::Io(_))
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Fault::Missing => f.write_str("no such file or device"),
            Fault::Denied(Wanted::File) => f.write_str("permission denied"),
            Fault::Denied(Wanted::Port) => f.write_str(
                "permission denied (a serial port usually needs its group, e.g. dialout)",
            ),
            Fault::Not(Wanted::Port, is) => write!(f, "not a serial port: it is {is}"),
            Fault::Not(Wanted::File, is) => write!(f, "not a file: it is {is}"),
            Fault::Io(e) => write!(f, "cannot open: {e}"),
        }
    }
}

/// Reads the text file at `path`, its faults classified.
pub fn read_text(path: &Path) -> Result<String, Fault> {
    check(path, Wanted::File)?;
    std::fs::read_to_string(path).map_err(|e| Fault::of(path, Wanted::File, e))
}

/// What is at `path`, if it cannot be a `wanted` (asked before opening a
/// file: a directory opens, and only fails to read).
pub fn check(path: &Path, wanted: Wanted) -> Result<(), Fault> {
    let kind = match std::fs::metadata(path) {
        Ok(meta) => meta.file_type(),
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Err(Fault::Missing),
        Err(e) if e.kind() == io::ErrorKind::PermissionDenied => {
            return Err(Fault::Denied(wanted));
        }
        // Not a fault of the path: opening it says more.
        Err(_) => return Ok(()),
    };
    match (kind.is_dir(), wanted) {
        (true, _) => Err(Fault::Not(wanted, "a directory")),
        // A file may be any readable thing: a pipe, /dev/stdin.
        (false, Wanted::File) => Ok(()),
        (false, Wanted::Port) => match not_a_port(path, kind) {
            Some(is) => Err(Fault::Not(wanted, is)),
            None => Ok(()),
        },
    }
}

/// What the non-directory at `path` is, if it is no terminal.
#[cfg(unix)]
fn not_a_port(path: &Path, kind: std::fs::FileType) -> Option<&'static str> {
    use std::io::IsTerminal;
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    if kind.is_char_device() {
        // Non-blocking: a terminal without carrier would block the open.
        let file = std::fs::OpenOptions::new()
            .read(true)
            .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
            .open(path)
            .ok()?;
        return (!file.is_terminal()).then_some("a device that is not a terminal");
    }
    Some(if kind.is_file() {
        "a regular file"
    } else if kind.is_fifo() {
        "a named pipe"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "not a character device"
    })
}

#[cfg(not(unix))]
fn not_a_port(_: &Path, _: std::fs::FileType) -> Option<&'static str> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fault(path: &str, wanted: Wanted) -> String {
        check(Path::new(path), wanted).unwrap_err().to_string()
    }

    #[test]
    fn one_wording_per_fault() {
        let dir = std::env::temp_dir();
        let dir = dir.to_str().unwrap();
        assert_eq!(fault(dir, Wanted::File), "not a file: it is a directory");
        assert_eq!(
            fault(dir, Wanted::Port),
            "not a serial port: it is a directory"
        );
        assert_eq!(
            fault("/dev/null", Wanted::Port),
            "not a serial port: it is a device that is not a terminal"
        );
        assert_eq!(
            fault("/no/such/tty", Wanted::Port),
            "no such file or device"
        );
        assert!(check(Path::new("/dev/null"), Wanted::File).is_ok());
        let io = Fault::of(Path::new("/dev/null"), Wanted::File, io::Error::other("x"));
        assert!(!io.is_input());
    }
}
