//! The run log: a learning run's header and every roll-out, appended and
//! synced to disk before the next roll-out begins, so a run that crashed or
//! was killed continues where it stopped (resumed, [`crate::run`]).
//!
//! `DIR/run.log` holds one record per line: the CRC-32C of the JSON as 8
//! hex digits, a space, the JSON. The first record is the run's header,
//! then one per roll-out, then an end record once the run is complete.
//!
//! A crash can only tear the last record (appends are synced one by one).
//! [`RunLog::open`] moves a damaged last record (torn, or failing its CRC)
//! to `run.log.damaged-<time>` beside the log, truncates the log after the
//! last whole record and says so in [`Opened::recovered`]. Damage before
//! the last record is corruption, not a crash: it is an error that names
//! the line, and the log is left untouched.
//!
//! ```
//! use primo_learn::runlog::RunLog;
//! let dir = std::env::temp_dir().join(format!("primo-runlog-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! # std::fs::remove_file(dir.join("run.log")).ok();
//! let mut log = RunLog::create(&dir, &serde_json::json!({"seed": 1})).unwrap();
//! log.append(&serde_json::json!({"rollout": 1})).unwrap();
//! drop(log);
//! let opened = RunLog::open::<serde_json::Value, serde_json::Value>(&dir).unwrap();
//! assert_eq!(opened.header["seed"], 1);
//! assert_eq!(opened.entries.len(), 1);
//! assert!(!opened.ended && opened.recovered.is_none());
//! ```

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use serde::de::{DeserializeOwned, IgnoredAny};
use serde::{Deserialize, Serialize};

use crate::Error;

/// The log's file name in the run's directory.
pub const FILE: &str = "run.log";

const CRC: crc::Crc<u32> = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI);

/// One line of the log.
#[derive(Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
enum Line<H, E> {
    Run(H),
    Rollout(E),
    End,
}

/// What every learning run (`primo pour`, `primo learn`) reports of its
/// learner and its log.
#[derive(Debug)]
pub enum RunEvent<'a> {
    /// The learner is connected: where.
    Learner(String),
    /// A damaged last record of the run log was set aside.
    Recovered(&'a str),
    /// A resumed run continues with a changed setting: which, and how.
    Changed(&'a str),
    /// A forced new run moved the run logged in its directory aside.
    SetAside {
        /// The run's directory.
        dir: &'a Path,
        /// Where the earlier run is now.
        to: &'a Path,
    },
    /// A logged run is taken up again (or, complete, reported again).
    Resuming {
        /// Its directory.
        dir: &'a Path,
        /// The logged run was complete.
        complete: bool,
        /// Roll-outs logged.
        logged: usize,
    },
}

/// An open run log, appending.
#[derive(Debug)]
pub struct RunLog {
    file: File,
    path: PathBuf,
}

/// A run log read back by [`RunLog::open`].
#[derive(Debug)]
pub struct Opened<H, E> {
    /// The log, ready to append after the last whole record.
    pub log: RunLog,
    /// The run's header.
    pub header: H,
    /// The roll-outs, in order.
    pub entries: Vec<E>,
    /// The run was complete.
    pub ended: bool,
    /// What a damaged tail held and where it was moved, if there was one.
    pub recovered: Option<String>,
}

/// Moves the directory `dir`, if a run is logged in it, aside to
/// `DIR.replaced-<unix time>` beside it, and returns where: a forced new
/// run deletes nothing of the one it replaces.
pub fn set_aside(dir: &Path) -> Result<Option<PathBuf>, Error> {
    if !dir.join(FILE).exists() {
        return Ok(None);
    }
    let stamp = stamp();
    let name = dir.file_name().map_or_else(
        || std::ffi::OsString::from("run"),
        std::ffi::OsStr::to_os_string,
    );
    let mut n = 0;
    let to = loop {
        let mut aside = name.clone();
        aside.push(match n {
            0 => format!(".replaced-{stamp}"),
            n => format!(".replaced-{stamp}-{n}"),
        });
        let to = dir.with_file_name(aside);
        if !to.exists() {
            break to;
        }
        n += 1;
    };
    std::fs::rename(dir, &to).map_err(|e| Error::Io {
        path: dir.to_path_buf(),
        source: std::io::Error::new(
            e.kind(),
            format!("cannot move it aside to {}: {e}", to.display()),
        ),
    })?;
    Ok(Some(to))
}

impl RunLog {
    /// Whether a new run may be logged in `dir`: yes if no run is logged
    /// there, or if one without roll-outs is (it made nothing); with
    /// `force` always, the earlier run to be moved aside ([`set_aside`]).
    /// Without, a finished or unfinished run (continued with `--resume`)
    /// is never replaced.
    pub fn check_free(dir: &Path, force: bool) -> Result<(), Error> {
        let path = dir.join(FILE);
        let Ok(bytes) = std::fs::read(&path) else {
            return Ok(());
        };
        if force {
            return Ok(());
        }
        match scan::<IgnoredAny, IgnoredAny>(&path, &bytes) {
            Ok(old) if old.entries.is_empty() => Ok(()),
            Ok(old) => Err(Error::Occupied {
                log: path,
                rollouts: old.entries.len(),
                finished: old.ended,
            }),
            Err(e) => Err(Error::Log(format!("{e}; not overwriting it"))),
        }
    }

    /// Starts the log of a new run in `dir` with its `header`, if no run
    /// with roll-outs is logged there ([`RunLog::check_free`]: a forced run
    /// sets the earlier one aside first).
    pub fn create<H: Serialize>(dir: &Path, header: &H) -> Result<RunLog, Error> {
        Self::check_free(dir, false)?;
        let bytes = record::<H, ()>(&Line::Run(header))?;
        Self::write_whole(dir.join(FILE), &bytes)
    }

    /// Writes the log at `path` whole (complete before it replaces what
    /// was there) and opens it to append.
    fn write_whole(path: PathBuf, bytes: &[u8]) -> Result<RunLog, Error> {
        crate::output::write_file(&path, bytes)?;
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            sync_dir(dir)?;
        }
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| io_error(&path, e))?;
        Ok(RunLog { file, path })
    }

    /// Replaces the log's header by `header` (a resumed run's changed
    /// settings), every roll-out after it kept, and drops the end record
    /// of a complete run (the changed settings continue it): the log as
    /// it was is kept beside it as `run.log.before-<time>`, and the new one
    /// replaces it whole.
    pub fn rewrite_header<H: Serialize>(self, header: &H) -> Result<RunLog, Error> {
        let path = self.path;
        drop(self.file);
        let old = std::fs::read(&path).map_err(|e| io_error(&path, e))?;
        let rest = old
            .iter()
            .position(|b| *b == b'\n')
            .and_then(|end| old.get(end + 1..))
            .ok_or_else(|| Error::Log(format!("{}: no header record", path.display())))?;
        let body = rest.strip_suffix(b"\n").unwrap_or(rest);
        let last = body.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
        let rest = match body.get(last..).map(parse::<IgnoredAny, IgnoredAny>) {
            Some(Ok(Line::End)) => rest.get(..last).unwrap_or(rest),
            _ => rest,
        };
        let before = path.with_file_name(format!("{FILE}.before-{}", stamp()));
        crate::output::write_file(&before, &old)?;
        let mut bytes = record::<H, ()>(&Line::Run(header))?;
        bytes.extend_from_slice(rest);
        Self::write_whole(path, &bytes)
    }

    /// Appends a roll-out and waits until it is on disk.
    pub fn append<E: Serialize>(&mut self, entry: &E) -> Result<(), Error> {
        self.write(&record::<(), E>(&Line::Rollout(entry))?)
    }

    /// Marks the run complete.
    pub fn end(&mut self) -> Result<(), Error> {
        self.write(&record::<(), ()>(&Line::End)?)
    }

    fn write(&mut self, bytes: &[u8]) -> Result<(), Error> {
        self.file
            .write_all(bytes)
            .and_then(|()| self.file.sync_data())
            .map_err(|e| io_error(&self.path, e))
    }

    /// Opens the log in `dir` to continue its run ([`RunLog::open`]),
    /// telling `event` of a recovered record and of the resumption; a
    /// header (`version` gives its format version) of another version than
    /// `expected` is refused.
    pub fn resume<H: DeserializeOwned, E: DeserializeOwned>(
        dir: &Path,
        version: impl Fn(&H) -> u32,
        expected: u32,
        mut event: impl FnMut(RunEvent) -> Result<(), Error>,
    ) -> Result<Opened<H, E>, Error> {
        let opened = RunLog::open::<H, E>(dir)?;
        if let Some(note) = &opened.recovered {
            event(RunEvent::Recovered(note))?;
        }
        let found = version(&opened.header);
        if found != expected {
            return Err(Error::Log(format!(
                "{}: run log version {found}, this primo reads version {expected}: the run \
                 cannot continue here; start a new one (the log and its reports stay as they are)",
                dir.join(FILE).display()
            )));
        }
        event(RunEvent::Resuming {
            dir,
            complete: opened.ended,
            logged: opened.entries.len(),
        })?;
        Ok(opened)
    }

    /// Reads the log in `dir`, recovering a damaged last record (see the
    /// module docs).
    pub fn open<H: DeserializeOwned, E: DeserializeOwned>(
        dir: &Path,
    ) -> Result<Opened<H, E>, Error> {
        let path = dir.join(FILE);
        let bytes = std::fs::read(&path).map_err(|e| io_error(&path, e))?;
        let scan = scan::<H, E>(&path, &bytes)?;
        let recovered = match scan.damaged {
            Some(what) => Some(move_tail(&path, &bytes, scan.whole, &what)?),
            None => None,
        };
        let file = OpenOptions::new()
            .append(true)
            .open(&path)
            .map_err(|e| io_error(&path, e))?;
        Ok(Opened {
            log: RunLog { file, path },
            header: scan.header,
            entries: scan.entries,
            ended: scan.ended,
            recovered,
        })
    }
}

/// What a log's bytes hold.
struct Scan<H, E> {
    header: H,
    entries: Vec<E>,
    ended: bool,
    /// Bytes of whole, valid records.
    whole: usize,
    /// What is wrong with the rest (the last record), if anything.
    damaged: Option<String>,
}

/// Reads the records of `bytes` (the log at `path`); damage before the last
/// record is an error.
fn scan<H: DeserializeOwned, E: DeserializeOwned>(
    path: &Path,
    bytes: &[u8],
) -> Result<Scan<H, E>, Error> {
    let name = path.display();
    // Whole records end in a newline; what follows the last is torn.
    let mut lines = Vec::new();
    let mut start = 0;
    while let Some(n) = bytes[start..].iter().position(|b| *b == b'\n') {
        lines.push(start..start + n);
        start += n + 1;
    }
    let torn = start < bytes.len();
    let mut header = None;
    let mut entries = Vec::new();
    let mut ended = false;
    let mut whole = 0;
    let mut damage = None;
    for (k, range) in lines.iter().enumerate() {
        let line = k + 1;
        let parsed = match parse::<H, E>(&bytes[range.clone()]) {
            Ok(parsed) => parsed,
            Err(why) => {
                damage = Some((line, why));
                break;
            }
        };
        let out_of_place = match parsed {
            Line::Run(h) if header.is_none() => {
                header = Some(h);
                None
            }
            _ if header.is_none() => Some("the first record must be the run's header"),
            _ if ended => Some("a record after the run's end"),
            Line::Run(_) => Some("a second header"),
            Line::Rollout(e) => {
                entries.push(e);
                None
            }
            Line::End => {
                ended = true;
                None
            }
        };
        if let Some(why) = out_of_place {
            return Err(Error::Log(format!("{name}:{line}: {why}")));
        }
        whole = range.end + 1;
    }
    let damaged = match damage {
        Some((line, why)) if line < lines.len() || torn => {
            return Err(Error::Log(format!(
                "{name}:{line}: {why}, and records follow it: the log is corrupt, not torn \
                 by a crash; it was left as it is"
            )));
        }
        Some((line, why)) => Some(format!("line {line} ({why})")),
        None if torn => Some(format!(
            "line {} (torn: {} bytes without a line end)",
            lines.len() + 1,
            bytes.len() - start
        )),
        None => None,
    };
    let Some(header) = header else {
        return Err(Error::Log(format!(
            "{name}: no whole header record: there is no run to resume"
        )));
    };
    Ok(Scan {
        header,
        entries,
        ended,
        whole,
        damaged,
    })
}

/// One line: CRC, space, JSON, newline.
fn record<H: Serialize, E: Serialize>(line: &Line<&H, &E>) -> Result<Vec<u8>, Error> {
    let json =
        serde_json::to_string(line).map_err(|e| Error::Log(format!("run log record: {e}")))?;
    Ok(format!("{:08x} {json}\n", CRC.checksum(json.as_bytes())).into_bytes())
}

fn parse<H: DeserializeOwned, E: DeserializeOwned>(bytes: &[u8]) -> Result<Line<H, E>, String> {
    let (crc, json) = bytes
        .split_at_checked(9)
        .filter(|(c, _)| c.last() == Some(&b' '))
        .ok_or("not `<crc> <json>`")?;
    let crc = std::str::from_utf8(&crc[..8])
        .ok()
        .and_then(|h| u32::from_str_radix(h, 16).ok())
        .ok_or("the CRC is not 8 hex digits")?;
    let actual = CRC.checksum(json);
    if actual != crc {
        return Err(format!("CRC {crc:08x} but the record's is {actual:08x}"));
    }
    serde_json::from_slice(json).map_err(|e| format!("the record does not parse: {e}"))
}

/// Moves `bytes[keep..]` to a file beside `path` and truncates `path` to
/// `keep` bytes; says what it did.
fn move_tail(path: &Path, bytes: &[u8], keep: usize, what: &str) -> Result<String, Error> {
    let aside = path.with_file_name(format!("{FILE}.damaged-{}", stamp()));
    crate::output::write_file(&aside, &bytes[keep..])?;
    OpenOptions::new()
        .write(true)
        .open(path)
        .and_then(|f| {
            f.set_len(keep as u64)?;
            f.sync_all()
        })
        .map_err(|e| io_error(path, e))?;
    Ok(format!(
        "{}: the last record, {what}, was damaged; its {} bytes were moved to {} and the log \
         continues after the last whole record",
        path.display(),
        bytes.len() - keep,
        aside.display()
    ))
}

/// Makes a new file's directory entry durable.
/// Now, in seconds since 1970: what names the files set aside.
fn stamp() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs())
}

fn sync_dir(dir: &Path) -> Result<(), Error> {
    File::open(dir)
        .and_then(|d| d.sync_all())
        .map_err(|e| io_error(dir, e))
}

fn io_error(path: &Path, e: std::io::Error) -> Error {
    Error::Io {
        path: path.to_path_buf(),
        source: e,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::{Value, json};

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("primo-runlog-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn three(name: &str) -> PathBuf {
        let d = dir(name);
        let mut log = RunLog::create(&d, &json!({"seed": 7})).unwrap();
        for i in 1..=3 {
            log.append(&json!({ "rollout": i })).unwrap();
        }
        d
    }

    fn open(d: &Path) -> Result<Opened<Value, Value>, Error> {
        RunLog::open(d)
    }

    #[test]
    fn appends_read_back_in_order_and_continue() {
        let d = three("order");
        let mut o = open(&d).unwrap();
        assert_eq!(
            o.entries,
            vec![
                json!({"rollout": 1}),
                json!({"rollout": 2}),
                json!({"rollout": 3})
            ]
        );
        o.log.append(&json!({"rollout": 4})).unwrap();
        o.log.end().unwrap();
        let o = open(&d).unwrap();
        assert_eq!((o.entries.len(), o.ended), (4, true));
    }

    #[test]
    fn a_torn_tail_is_moved_aside_and_the_log_continues() {
        let d = three("torn");
        let path = d.join(FILE);
        let whole = std::fs::read(&path).unwrap();
        let mut f = OpenOptions::new().append(true).open(&path).unwrap();
        f.write_all(b"1234abcd {\"kind\":\"rollout\",\"rol")
            .unwrap();
        let mut o = open(&d).unwrap();
        assert_eq!(o.entries.len(), 3);
        let note = o.recovered.clone().unwrap();
        assert!(note.contains("line 5 (torn: 31 bytes"), "{note}");
        assert_eq!(std::fs::read(&path).unwrap(), whole);
        let aside: Vec<_> = std::fs::read_dir(&d)
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| {
                e.file_name()
                    .to_string_lossy()
                    .starts_with("run.log.damaged-")
            })
            .collect();
        assert_eq!(aside.len(), 1);
        assert_eq!(
            std::fs::read(aside[0].path()).unwrap(),
            b"1234abcd {\"kind\":\"rollout\",\"rol"
        );
        o.log.append(&json!({"rollout": 4})).unwrap();
        assert_eq!(open(&d).unwrap().entries.len(), 4);
    }

    #[test]
    fn a_damaged_last_record_is_recovered_one_in_the_middle_is_an_error() {
        let d = three("flip");
        let path = d.join(FILE);
        let whole = std::fs::read(&path).unwrap();
        // A flipped digit in the last record: recovered.
        let mut bytes = whole.clone();
        let at = bytes.len() - 3;
        bytes[at] ^= 0x01;
        std::fs::write(&path, &bytes).unwrap();
        let o = open(&d).unwrap();
        assert_eq!(o.entries.len(), 2);
        assert!(o.recovered.unwrap().contains("line 4 (CRC"));
        // In the second record: an error, and the file is untouched.
        let mut bytes = whole.clone();
        let second = bytes.iter().position(|b| *b == b'\n').unwrap() + 20;
        bytes[second] ^= 0x01;
        std::fs::write(&path, &bytes).unwrap();
        let e = open(&d).unwrap_err().to_string();
        assert!(e.contains("run.log:2: CRC") && e.contains("corrupt"), "{e}");
        assert_eq!(std::fs::read(&path).unwrap(), bytes);
    }

    #[test]
    fn a_logged_run_is_never_overwritten_only_set_aside() {
        let d = three("keep");
        let e = RunLog::create(&d, &json!({"seed": 8}))
            .unwrap_err()
            .to_string();
        assert!(e.contains("an unfinished run (3 roll-outs)"), "{e}");
        open(&d).unwrap().log.end().unwrap();
        let e = RunLog::create(&d, &json!({"seed": 8}))
            .unwrap_err()
            .to_string();
        assert!(e.contains("a finished run (3 roll-outs)"), "{e}");
        assert!(RunLog::check_free(&d, true).is_ok());
        let to = set_aside(&d).unwrap().unwrap();
        assert_eq!(open(&to).unwrap().entries.len(), 3);
        assert!(!d.exists());
        std::fs::create_dir_all(&d).unwrap();
        RunLog::create(&d, &json!({"seed": 8})).unwrap();
        let o = open(&d).unwrap();
        assert_eq!((o.header, o.entries.len()), (json!({"seed": 8}), 0));
        assert!(set_aside(&to.join("nothing")).unwrap().is_none());
    }

    #[test]
    fn a_log_without_a_header_or_out_of_order_is_an_error() {
        let d = dir("headless");
        std::fs::write(d.join(FILE), b"").unwrap();
        assert!(
            open(&d)
                .unwrap_err()
                .to_string()
                .contains("no whole header")
        );
        let end = record::<(), ()>(&Line::End).unwrap();
        std::fs::write(d.join(FILE), &end).unwrap();
        assert!(
            open(&d)
                .unwrap_err()
                .to_string()
                .contains("must be the run's header")
        );
    }
}
