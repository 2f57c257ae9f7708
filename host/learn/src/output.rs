//! Writing results: an output file holds its old or its new content, never
//! a torn mix, and only regular files are replaced.
//!
//! A regular file (or a new one) is written through a temporary file in
//! the same directory and a rename; a file replaced keeps its mode, and
//! one this user may not write (as `open` for writing would refuse) is
//! refused, left as it is. A symbolic link is followed: its target
//! is written, the link stays. Anything else that exists (a device such as
//! `/dev/null` or `/dev/stdout`, a FIFO, a socket) is written in place,
//! since renaming over it would replace the node itself.
//!
//! ```
//! use primo_learn::output::write_file;
//! let dir = std::env::temp_dir().join(format!("primo-output-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! let file = dir.join("a.txt");
//! write_file(&file, b"one").unwrap();
//! write_file(&file, b"two").unwrap();
//! assert_eq!(std::fs::read(&file).unwrap(), b"two");
//! write_file(std::path::Path::new("/dev/null"), b"gone").unwrap();
//! assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_file() == false);
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::fs::Permissions;
use std::io::Write;
use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::{Path, PathBuf};

use crate::Error;

/// Writes `bytes` to `path` (see the module docs).
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    let target = resolve(path)?;
    match std::fs::metadata(&target) {
        Ok(meta) if !meta.is_file() => {
            if meta.is_dir() {
                return Err(Error::Invalid(format!(
                    "{}: is a directory, not a file",
                    path.display()
                )));
            }
            std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .and_then(|mut f| f.write_all(bytes))
                .map_err(Error::io(path))
        }
        Ok(meta) => {
            check_writable(path)?;
            replace(&target, bytes, Some(meta.permissions())).map_err(Error::io(path))
        }
        Err(_) => replace(&target, bytes, None).map_err(Error::io(path)),
    }
}

/// Checks, before any work, that this user may write `path` if it is an
/// existing regular file (links followed): as `open` for writing would,
/// without changing it.
pub fn check_writable(path: &Path) -> Result<(), Error> {
    let target = resolve(path)?;
    let Ok(meta) = std::fs::metadata(&target) else {
        return Ok(());
    };
    if !meta.is_file() {
        return Ok(());
    }
    // Opened without truncating: a probe of the permissions, nothing more.
    match std::fs::OpenOptions::new().write(true).open(&target) {
        Ok(_) => Ok(()),
        Err(e)
            if matches!(
                e.kind(),
                std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::ReadOnlyFilesystem
            ) =>
        {
            Err(Error::ReadOnly {
                path: path.to_path_buf(),
                mode: meta.permissions().mode() & 0o7777,
            })
        }
        Err(e) => Err(Error::io(path)(e)),
    }
}

/// Whether `a` and `b` name the same existing file (the same device and
/// inode, links followed): a hard link, a symbolic link or another
/// spelling of one path is the same file.
pub fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => (a.dev(), a.ino()) == (b.dev(), b.ino()),
        _ => false,
    }
}

/// `path` with every symbolic link of its last component followed (a
/// dangling link gives its target, to be created).
fn resolve(path: &Path) -> Result<PathBuf, Error> {
    let mut target = path.to_path_buf();
    // A chain of links, followed as the system does (at most 40).
    for _ in 0..40 {
        match std::fs::symlink_metadata(&target) {
            Ok(meta) if meta.file_type().is_symlink() => {
                let link = std::fs::read_link(&target).map_err(Error::io(path))?;
                target = match target.parent() {
                    Some(dir) => dir.join(link),
                    None => link,
                };
            }
            _ => return Ok(target),
        }
    }
    Err(Error::Invalid(format!(
        "{}: too many levels of symbolic links",
        path.display()
    )))
}

/// Writes a regular file through a temporary file and a rename; the new
/// file gets `mode` (the old one's), else the default for a new file.
fn replace(path: &Path, bytes: &[u8], mode: Option<Permissions>) -> std::io::Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"))?;
    let tmp = dir.join(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = (|| {
        let mut f = std::fs::File::create(&tmp)?;
        if let Some(mode) = mode {
            f.set_permissions(mode)?;
        }
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// Writes `value` as pretty JSON and a newline to `path`, atomically.
pub fn write_json(path: &Path, value: &impl serde::Serialize) -> Result<(), Error> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(|e| Error::Report(format!("{}: {e}", path.display())))?;
    text.push('\n');
    write_file(path, text.as_bytes())
}

/// Checks, before any work, that `out` is a directory or can be made one:
/// nothing that is not a directory in its way.
pub fn check_dir(out: &Path) -> Result<(), Error> {
    let mut at = Some(out);
    while let Some(p) = at {
        if let Ok(meta) = std::fs::metadata(p) {
            if meta.is_dir() {
                return Ok(());
            }
            return Err(Error::NotADirectory {
                out: out.to_path_buf(),
                blocking: p.to_path_buf(),
            });
        }
        at = p.parent().filter(|p| !p.as_os_str().is_empty());
    }
    Ok(())
}

/// Creates `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<(), Error> {
    std::fs::create_dir_all(dir).map_err(|e| Error::Io {
        path: dir.to_path_buf(),
        source: std::io::Error::new(e.kind(), format!("cannot create: {e}")),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::{FileTypeExt, symlink};

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("primo-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_symlink_is_followed_and_stays_a_link() {
        let d = dir("link");
        let target = d.join("target.csv");
        std::fs::write(&target, b"old").unwrap();
        let link = d.join("link.csv");
        symlink("target.csv", &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        // A dangling link: its target is created.
        let dangling = d.join("dangling.csv");
        symlink("made.csv", &dangling).unwrap();
        write_file(&dangling, b"made").unwrap();
        assert!(
            std::fs::symlink_metadata(&dangling)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read(d.join("made.csv")).unwrap(), b"made");
    }

    #[test]
    fn a_fifo_is_written_in_place() {
        let d = dir("fifo");
        let fifo = d.join("pipe");
        let status = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap();
        assert!(status.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        write_file(&fifo, b"through the pipe").unwrap();
        assert_eq!(reader.join().unwrap(), b"through the pipe");
        assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    }

    #[test]
    fn a_device_is_written_not_replaced() {
        write_file(Path::new("/dev/null"), b"nothing").unwrap();
        let meta = std::fs::metadata("/dev/null").unwrap();
        assert!(meta.file_type().is_char_device());
    }

    #[test]
    fn a_replaced_file_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let d = dir("mode");
        let f = d.join("private.json");
        std::fs::write(&f, b"old").unwrap();
        std::fs::set_permissions(&f, std::fs::Permissions::from_mode(0o600)).unwrap();
        write_file(&f, b"new").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"new");
        let mode = std::fs::metadata(&f).unwrap().permissions().mode() & 0o7777;
        assert_eq!(mode, 0o600);
    }

    #[test]
    fn the_same_file_is_known_by_its_inode_not_its_name() {
        let d = dir("same");
        let f = d.join("a.csv");
        std::fs::write(&f, b"a").unwrap();
        let hard = d.join("hard.csv");
        std::fs::hard_link(&f, &hard).unwrap();
        let soft = d.join("soft.csv");
        symlink("a.csv", &soft).unwrap();
        let other = d.join("b.csv");
        std::fs::write(&other, b"a").unwrap();
        for same in [&f, &hard, &soft, &d.join(".").join("a.csv")] {
            assert!(same_file(&f, same), "{}", same.display());
        }
        assert!(!same_file(&f, &other));
        assert!(!same_file(&f, &d.join("missing.csv")));
    }

    #[test]
    fn a_regular_file_is_replaced_and_a_directory_refused() {
        let d = dir("regular");
        let f = d.join("a.json");
        write_file(&f, b"1").unwrap();
        write_file(&f, b"2").unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"2");
        let leftovers = std::fs::read_dir(&d).unwrap().count();
        assert_eq!(leftovers, 1, "no temporary file is left behind");
        let e = write_file(&d, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
    }
}
