use std::fmt;
use std::io::Write;
use std::path::Path;

/// A command's failure: a one-line message and the process exit status
/// (2 for bad input, 1 for everything else).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// The message, already naming file, line and column where known.
    pub message: String,
    /// Exit status.
    pub status: i32,
}

impl CliError {
    /// Bad input (a malformed file or argument): exit status 2.
    pub fn input(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 2,
        }
    }

    /// Anything else (I/O): exit status 1.
    pub fn other(message: impl Into<String>) -> Self {
        Self {
            message: message.into(),
            status: 1,
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// Writes `bytes` to `path` through a temporary file in the same directory
/// and a rename, so `path` holds either its old or its new content, never a
/// torn mix, even if the process dies half way.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<(), CliError> {
    let fail =
        |e: std::io::Error| CliError::other(format!("{}: cannot write: {e}", path.display()));
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| CliError::input(format!("{}: not a file name", path.display())))?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result.map_err(fail)
}
