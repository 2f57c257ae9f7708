//! What commands print, and where their files go.

use std::io::Write;
use std::path::Path;

use primo_learn::output::{check_writable, same_file};

use crate::error::CliError;

/// Prints `line` on stdout at once: another program may be waiting for it.
pub fn say(line: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")
        .and_then(|()| out.flush())
        .map_err(CliError::stdout)
}

/// Reads a file named on the command line: by `flag`, or by position.
pub fn read(flag: Option<&str>, path: &Path) -> Result<String, CliError> {
    primo_mtsics::path::read_text(path).map_err(|fault| {
        let named = match flag {
            Some(flag) => format!("{flag} {}", path.display()),
            None => path.display().to_string(),
        };
        CliError::opening(format!("{named}: {fault}"), &fault)
    })
}

/// Writes to `out` (safely: [`primo_learn::output`]), or to stdout.
pub fn emit(out: Option<&Path>, bytes: &[u8]) -> Result<(), CliError> {
    match out {
        Some(path) => Ok(primo_learn::output::write_file(path, bytes)?),
        None => {
            let mut stdout = std::io::stdout().lock();
            stdout
                .write_all(bytes)
                .and_then(|()| stdout.flush())
                .map_err(CliError::stdout)
        }
    }
}

/// Checks, before any work, that a file can be written at `out`: not a
/// directory, its directory exists, this user may write it if it exists,
/// and it is none of `inputs` (flag, file: the same file under any name).
pub fn check_out_file(flag: &str, out: &Path, inputs: &[(&str, &Path)]) -> Result<(), CliError> {
    if out.is_dir() {
        return Err(CliError::input(format!(
            "{flag} {}: is a directory, not a file",
            out.display()
        )));
    }
    let dir = out.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(d) = dir
        && !d.is_dir()
    {
        return Err(CliError::input(format!(
            "{flag} {}: no directory {}",
            out.display(),
            d.display()
        )));
    }
    if let Some((input, file)) = inputs.iter().find(|(_, file)| same_file(out, file)) {
        return Err(CliError::input(format!(
            "{flag} {}: is the same file as {input} {}: the output would destroy the input",
            out.display(),
            file.display()
        )));
    }
    check_writable(out).map_err(|e| CliError::input(format!("{flag} {e}")))
}
