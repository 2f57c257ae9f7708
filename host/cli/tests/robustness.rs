//! `primo` under generated abuse: valid command lines with one thing
//! corrupted (a flag dropped, duplicated or replaced, a value replaced, an
//! input file mutated) and random flag lists. Whatever it is given, primo
//! must not panic or abort, must end within a bound, must say why on
//! stderr when it exits non-zero, must refuse a setting before the learner
//! does, and must touch no file but its named output. Seeded: every run
//! tries the same cases.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::hash::{Hash, Hasher};
use std::io::{Read, Write};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, OnceLock};
use std::time::{Duration, Instant, SystemTime};

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestRng, TestRunner};

use common::{primo, tmp};

/// Longest a case may run: the slowest valid line takes about a second.
const LIMIT: Duration = Duration::from_secs(20);

/// Valid command lines, each quick in a debug build, run in a scratch copy
/// of [`inputs`]. A token marked `!` bounds the run's size (a roll-out
/// budget, a timeout): it and its flag are never corrupted, so that a case
/// can only be slow by a defect. (`scale serve` and `sim-krc` serve until
/// killed, by design: their own tests stop them.)
const VALID: &[&str] = &[
    "dmp fit --demo reach.csv --kernels 10 --out o.json",
    "dmp fit --demo reach.csv --margin 0.5 --out o.json",
    "dmp fit --demo reach.csv --rhythmic --period 0.5 --kernels 8 --out o.json",
    "dmp run reach.json --dt 0.01 --out o.csv",
    "dmp run reach.json --dt 0.01 --tau 0.5 --goal 0.8,0.1 --start 0,0.1 --out o.csv",
    "dmp run wave.json --dt 0.01 --duration 1 --frequency 2 --amplitude 1,1 --out o.csv",
    "dmp run wave.json --dt 0.01 --change 0.2_frequency=3_anchor=0,0.1 --out o.csv",
    "demo synth --bottle 0.5 --pour 0.2 --seed 3 --out o.csv",
    "demo synth --space joint --elbow -0.2 --out o.csv",
    "rollout --print-start",
    "rollout --params params.json --series o.csv",
    "rollout --params params.json --kernels 10 --glass normal --target 0.15",
    "rollout --serve",
    "learn --task task.toml --out o --max-rollouts !2",
    "learn --task task.toml --out o --max-rollouts !2 --seed 5 --force",
    "learn --task operator.toml --out o --max-rollouts !2",
    "learn --resume run",
    "learn --resume run --task task.toml --max-rollouts !3",
    "learn --resume pour-run",
    "pour --max-rollouts !2 --out o",
    "pour --max-rollouts !2 --method power --kernels 5 --out o --seed 2",
    "pour --max-rollouts !2 --demo low.csv=0.3 --demo high.csv=1.0 --out o",
    "pour --resume pour-run",
    "experiment golden --volumes !0.5 --precision 0.01 --out o",
    "experiment power --runs !1 --updates !1 --kernels !5 --out o",
    "robot play joints.csv --robot fri:127.0.0.1:49938 --start-timeout !0.3",
    "robot check joints.csv",
    "robot check joints.csv --model arm.urdf --base base --tip l7 --max-acceleration 50",
    "scale read --port /dev/null --timeout !0.3 --retries !0",
    "scale zero --port missing-port",
    "dmp run --help",
    "learn --help",
];

/// Every flag any subcommand takes: what a replaced or inserted flag is.
const FLAGS: &[&str] = &[
    "--amplitude",
    "--anchor",
    "--approach-speed",
    "--base",
    "--baud",
    "--bottle",
    "--change",
    "--confirm",
    "--coprocessor",
    "--cycle-timeout",
    "--demo",
    "--density",
    "--dt",
    "--duration",
    "--elbow",
    "--firmware",
    "--force",
    "--frequency",
    "--gain",
    "--glass",
    "--glass-holds",
    "--goal",
    "--help",
    "--high",
    "--kernels",
    "--load",
    "--low",
    "--margin",
    "--max-acceleration",
    "--max-rollouts",
    "--method",
    "--model",
    "--no-realtime",
    "--out",
    "--params",
    "--period",
    "--port",
    "--pour",
    "--precision",
    "--print-start",
    "--resume",
    "--retries",
    "--rhythmic",
    "--robot",
    "--scale",
    "--search",
    "--seed",
    "--series",
    "--serve",
    "--settle",
    "--space",
    "--stable-timeout",
    "--start",
    "--start-timeout",
    "--stream",
    "--target",
    "--task",
    "--tau",
    "--timeout",
    "--tip",
    "--unit",
    "--version",
    "--volumes",
    "--weigh",
];

/// Flags that name what a command writes; their values are its outputs.
const OUTPUT_FLAGS: &[&str] = &["--out", "--series", "--resume"];

/// Where commands write when their --out is left out.
const DEFAULT_OUTPUTS: &[&str] = &[
    "learn-out",
    "pour-out",
    "experiment-golden",
    "experiment-power",
];

/// Values that stand in for a flag's: numbers at and past every edge,
/// text that is no number, paths that are no good input.
fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        3 => prop::sample::select(vec![
            "0", "-1", "-0", "1", "2", "0.5", "NaN", "nan", "inf", "-inf", "1e300", "-1e300",
            "1e-300", "1e39", "3.4e38", "4294967295", "4294967296", "18446744073709551615",
            "18446744073709551616", "-9223372036854775809", "999999999999999999999", "0x10",
            "1e", "", " ", ",", "1,2", "1,2,3", "0,0", "é", "日本語", "\u{feff}1", "--", "-",
            "=", "a=b", "auto", "none", "joint", "cartesian", "small", "golden", "power",
            "fri:", "fri:127.0.0.1:0", "fri:999.1.1.1", "postcard:", "qemu:missing",
            "missing.csv", "dir", "dir/", "dir/x.csv", "/dev/null", "o", "o.json", "o.csv",
            "reach.csv", "reach.json", "wave.json", "task.toml", "operator.toml", "params.json",
            "run",
            "pour-run", "run/run.log", "missing/x",
        ])
        .prop_map(String::from),
        1 => any::<f64>().prop_map(|x| x.to_string()),
        1 => any::<i64>().prop_map(|x| x.to_string()),
        // Values that pass a first look and reach the work.
        2 => (-3.0..3.0f64).prop_map(|x| format!("{x:.3}")),
        1 => (1e-9..1e-2f64).prop_map(|x| format!("{x:e}")),
        1 => (0..300u32).prop_map(|x| x.to_string()),
        1 => "[a-z0-9.,=:_ -]{0,12}",
    ]
}

/// A change to one input file.
#[derive(Debug, Clone)]
enum Mutation {
    Truncate(Index),
    Flip(Vec<(Index, u8)>),
    Bom,
    SwapLines(Index, Index),
    DeleteLine(Index),
    DuplicateLine(Index),
    DeleteColumn(Index),
    ReplaceNumber(Index, String),
    Empty,
    Directory,
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        1 => any::<Index>().prop_map(Mutation::Truncate),
        1 => prop::collection::vec((any::<Index>(), 1..=255u8), 1..4).prop_map(Mutation::Flip),
        1 => Just(Mutation::Bom),
        1 => (any::<Index>(), any::<Index>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
        1 => any::<Index>().prop_map(Mutation::DeleteLine),
        1 => any::<Index>().prop_map(Mutation::DuplicateLine),
        1 => any::<Index>().prop_map(Mutation::DeleteColumn),
        3 => (any::<Index>(), value()).prop_map(|(i, v)| Mutation::ReplaceNumber(i, v)),
        1 => Just(Mutation::Empty),
        1 => Just(Mutation::Directory),
    ]
}

impl Mutation {
    /// Applies the change to `path`.
    fn apply(&self, path: &Path) {
        let bytes = std::fs::read(path).unwrap();
        let text = String::from_utf8_lossy(&bytes).into_owned();
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        let changed: Vec<u8> = match self {
            Mutation::Truncate(at) => bytes[..at.index(bytes.len() + 1)].to_vec(),
            Mutation::Flip(flips) => {
                let mut b = bytes.clone();
                if !b.is_empty() {
                    for (at, mask) in flips {
                        let i = at.index(b.len());
                        b[i] ^= mask;
                    }
                }
                b
            }
            Mutation::Bom => [b"\xef\xbb\xbf".as_slice(), &bytes].concat(),
            Mutation::SwapLines(a, b) => {
                let mut l = lines.clone();
                if !l.is_empty() {
                    let (a, b) = (a.index(l.len()), b.index(l.len()));
                    l.swap(a, b);
                }
                l.concat().into_bytes()
            }
            Mutation::DeleteLine(at) => {
                let mut l = lines.clone();
                if !l.is_empty() {
                    l.remove(at.index(l.len()));
                }
                l.concat().into_bytes()
            }
            Mutation::DuplicateLine(at) => {
                let mut l = lines.clone();
                if !l.is_empty() {
                    let i = at.index(l.len());
                    l.insert(i, l[i]);
                }
                l.concat().into_bytes()
            }
            Mutation::DeleteColumn(at) => {
                let columns = lines.first().map_or(1, |l| l.split(',').count());
                let k = at.index(columns);
                lines
                    .iter()
                    .map(|line| {
                        let (body, end) = match line.strip_suffix('\n') {
                            Some(b) => (b, "\n"),
                            None => (*line, ""),
                        };
                        let mut fields: Vec<&str> = body.split(',').collect();
                        if k < fields.len() {
                            fields.remove(k);
                        }
                        format!("{}{end}", fields.join(","))
                    })
                    .collect::<String>()
                    .into_bytes()
            }
            Mutation::ReplaceNumber(at, garbage) => {
                let numbers = numbers(&text);
                match numbers.is_empty() {
                    true => bytes.clone(),
                    false => {
                        let (start, end) = numbers[at.index(numbers.len())];
                        format!("{}{garbage}{}", &text[..start], &text[end..]).into_bytes()
                    }
                }
            }
            Mutation::Empty => Vec::new(),
            Mutation::Directory => {
                std::fs::remove_file(path).unwrap();
                std::fs::create_dir(path).unwrap();
                return;
            }
        };
        std::fs::write(path, changed).unwrap();
    }
}

/// The byte ranges of the numbers in `text`.
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let mut found = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        let part = c.is_ascii_digit() || (start.is_some() && matches!(c, '.' | 'e' | '-'));
        match (part, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                found.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    found.extend(start.map(|s| (s, text.len())));
    found
}

/// CRC-32C, as the run log checks each record with.
fn crc32c(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for b in bytes {
        crc ^= u32::from(*b);
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0x82f6_3b78 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// `log` with every record's CRC made right again: a mutated record that
/// the log takes as whole, so that its content is what gets checked.
fn recrc(log: &Path) {
    let Ok(text) = std::fs::read_to_string(log) else {
        return;
    };
    let fixed: String = text
        .split_inclusive('\n')
        .map(|line| {
            let body = line.trim_end_matches('\n');
            match body.split_once(' ') {
                Some((crc, json)) if crc.len() == 8 => {
                    let end = &line[body.len()..];
                    format!("{:08x} {json}{end}", crc32c(json.as_bytes()))
                }
                _ => line.to_string(),
            }
        })
        .collect();
    std::fs::write(log, fixed).unwrap();
}

/// The inputs every case starts from, made once: demonstrations, DMPs, a
/// task file with its evaluator, parameters, and run directories to
/// resume. Paths in them are relative, or `@` for the case's directory.
fn inputs() -> &'static Path {
    static INPUTS: OnceLock<PathBuf> = OnceLock::new();
    INPUTS.get_or_init(|| {
        let dir = tmp("robustness-inputs");
        let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
        let throw = examples.join("throw");
        std::fs::create_dir_all(dir.join("dir")).unwrap();
        for (from, to) in [
            (examples.join("reach.csv"), "reach.csv"),
            (throw.join("demos/fast.csv"), "fast.csv"),
            (throw.join("demos/slow.csv"), "slow.csv"),
            (throw.join("throw.py"), "throw.py"),
        ] {
            std::fs::copy(from, dir.join(to)).unwrap();
        }
        let task = std::fs::read_to_string(throw.join("throw.toml"))
            .unwrap()
            .replace("demos/", "");
        let operator = task
            .replace("command = [\"python3\", \"throw.py\"]", "operator = true")
            .replace("timeout = 30", "");
        std::fs::write(dir.join("task.toml"), task).unwrap();
        std::fs::write(dir.join("operator.toml"), operator).unwrap();
        let at = |name: &str| dir.join(name).display().to_string();
        let made = |args: &[&str]| {
            let (code, _, err) = primo(args);
            assert_eq!(code, 0, "`primo {}`: {err}", args.join(" "));
        };
        made(&[
            "dmp",
            "fit",
            "--demo",
            &at("reach.csv"),
            "--kernels",
            "10",
            "--out",
            &at("reach.json"),
        ]);
        made(&[
            "dmp",
            "fit",
            "--demo",
            &at("reach.csv"),
            "--rhythmic",
            "--kernels",
            "10",
            "--out",
            &at("wave.json"),
        ]);
        for (bottle, name, space) in [
            ("0.3", "low.csv", "cartesian"),
            ("1.0", "high.csv", "cartesian"),
            ("0.5", "joints.csv", "joint"),
        ] {
            made(&[
                "demo",
                "synth",
                "--bottle",
                bottle,
                "--space",
                space,
                "--out",
                &at(name),
            ]);
        }
        // A seven-joint arm for `robot check --model`, its joints a1..a7.
        let mut arm = String::from("<robot name=\"arm\"><link name=\"base\"/>");
        for i in 1..=7 {
            let axis = if i % 2 == 1 { "0 0 1" } else { "0 1 0" };
            let parent = if i == 1 {
                "base".to_string()
            } else {
                format!("l{}", i - 1)
            };
            arm.push_str(&format!(
                "<link name=\"l{i}\"/><joint name=\"a{i}\" type=\"revolute\">\
                 <parent link=\"{parent}\"/><child link=\"l{i}\"/><origin xyz=\"0 0 0.2\"/>\
                 <axis xyz=\"{axis}\"/><limit lower=\"-3\" upper=\"3\" velocity=\"4\"/></joint>"
            ));
        }
        std::fs::write(dir.join("arm.urdf"), arm + "</robot>\n").unwrap();
        let (code, start, err) = primo(&["rollout", "--print-start"]);
        assert_eq!(code, 0, "{err}");
        std::fs::write(dir.join("params.json"), start).unwrap();
        // Unfinished runs: their last roll-out and the end record dropped.
        for (run, args) in [
            ("run", vec!["learn", "--task", "task.toml"]),
            (
                "pour-run",
                vec!["pour", "--method", "power", "--kernels", "5"],
            ),
        ] {
            let mut args = args.clone();
            let out = at(run);
            args.extend(["--max-rollouts", "2", "--out", &out]);
            let out = Command::new(env!("CARGO_BIN_EXE_primo"))
                .args(&args)
                .current_dir(&dir)
                .output()
                .unwrap();
            assert!(out.status.success(), "{args:?}: {out:?}");
            let log = dir.join(run).join("run.log");
            let text = std::fs::read_to_string(&log).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            let kept = lines[..lines.len() - 2].join("\n") + "\n";
            std::fs::write(&log, kept.replace(&dir.display().to_string(), "@")).unwrap();
        }
        dir
    })
}

/// One generated run: its arguments, an input file changed first (with
/// the run logs' CRCs then made right, or not), and the lines on its stdin
/// (`@params` is params.json's).
#[derive(Debug, Clone)]
struct Case {
    args: Vec<String>,
    mutation: Option<(String, Mutation, bool)>,
    stdin: Vec<String>,
}

/// Lines for an operator's answers or `rollout --serve`'s requests.
fn stdin() -> impl Strategy<Value = Vec<String>> {
    let line = prop_oneof![
        3 => value(),
        2 => Just("@params".to_string()),
        1 => (0.5..2.5f64).prop_map(|x| format!("{x:.3}")),
        1 => prop::sample::select(vec!["failed it fell", "reward 0.5", "1 reward 2", "1e300"])
            .prop_map(String::from),
    ];
    prop::collection::vec(line, 0..4)
}

/// A line's tokens, and which of them bound its size (marked `!`, with
/// their flags). `_` in a token is a space.
fn tokens(line: &str) -> (Vec<String>, BTreeSet<usize>) {
    let mut pinned = BTreeSet::new();
    let args = line
        .split(' ')
        .enumerate()
        .map(|(i, t)| match t.strip_prefix('!') {
            Some(t) => {
                pinned.extend([i - 1, i]);
                t.replace('_', " ")
            }
            None => t.replace('_', " "),
        })
        .collect();
    (args, pinned)
}

/// How many leading tokens name the subcommand.
fn depth(args: &[String]) -> usize {
    match args.first().map(String::as_str) {
        Some("dmp" | "demo" | "experiment" | "scale" | "robot") => 2,
        _ => 1,
    }
}

/// The input files `args` name (a run directory's: its log; a task's: its
/// demonstrations and evaluator too).
fn inputs_of(args: &[String]) -> Vec<String> {
    let mut files = Vec::new();
    for arg in args {
        let name = arg.split('=').next().unwrap_or(arg);
        let path = inputs().join(name);
        if path.join("run.log").is_file() {
            files.push(format!("{name}/run.log"));
        } else if path.is_file() {
            files.push(name.to_string());
        }
        if name == "task.toml" || name == "operator.toml" {
            files.extend(["fast.csv", "slow.csv"].map(String::from));
        }
        if name == "task.toml" {
            files.push("throw.py".into());
        }
    }
    files
}

/// A valid line with one thing corrupted: a token dropped, a flag and its
/// value dropped or given twice, a value or a flag replaced, a flag
/// inserted, or (`files`) one of its input files mutated.
fn corrupted(files: bool) -> impl Strategy<Value = Case> {
    let lines = VALID.iter().copied();
    let lines = lines.filter(|l| !files || !inputs_of(&tokens(l).0).is_empty());
    let line = prop::sample::select(lines.collect::<Vec<_>>());
    let corruption = (
        0..7u8,
        any::<Index>(),
        any::<Index>(),
        value(),
        mutation(),
        any::<bool>(),
    );
    (line, corruption, stdin()).prop_map(move |(line, corruption, stdin)| {
        let (how, at, flag, value, mutation, recrc) = corruption;
        let (mut args, pinned) = tokens(line);
        let free: Vec<usize> = (0..args.len()).filter(|i| !pinned.contains(i)).collect();
        let flag = FLAGS[flag.index(FLAGS.len())].to_string();
        let is_flag = |a: &String| a.starts_with("--");
        let values: Vec<usize> = free
            .iter()
            .copied()
            .filter(|&i| i >= depth(&args) && !is_flag(&args[i]))
            .collect();
        let flags: Vec<usize> = free
            .iter()
            .copied()
            .filter(|&i| is_flag(&args[i]))
            .collect();
        if files {
            let inputs = inputs_of(&args);
            let file = inputs[at.index(inputs.len())].clone();
            return Case {
                args,
                mutation: Some((file, mutation, recrc)),
                stdin,
            };
        }
        let pick = |from: &[usize]| (!from.is_empty()).then(|| from[at.index(from.len())]);
        // The value a flag at `i` takes, if it takes one.
        let pair = |args: &[String], i: usize| match args.get(i + 1) {
            Some(v) if !is_flag(v) && !pinned.contains(&(i + 1)) => i..i + 2,
            _ => i..i + 1,
        };
        match (how, pick(&free), pick(&values), pick(&flags)) {
            (0, Some(i), _, _) => {
                args.remove(i);
            }
            (1, _, _, Some(i)) => {
                args.drain(pair(&args, i));
            }
            (2, _, _, Some(i)) => {
                let twice: Vec<String> = args[pair(&args, i)].to_vec();
                args.extend(twice);
            }
            (3 | 4, _, Some(i), _) => args[i] = value,
            (5, _, _, Some(i)) => args[i] = flag,
            _ => {
                let i = depth(&args) + at.index(args.len() + 1 - depth(&args));
                args.insert(i, flag);
                if how % 2 == 0 {
                    args.insert(i + 1, value);
                }
            }
        }
        Case {
            args,
            mutation: None,
            stdin,
        }
    })
}

/// Subcommands with what bounds their runs' size, given random flags.
const RANDOM: &[(&str, &str)] = &[
    ("dmp fit", ""),
    ("dmp run reach.json", ""),
    ("dmp run wave.json", ""),
    ("demo synth", ""),
    ("rollout", ""),
    ("learn", "--max-rollouts 2"),
    ("pour", "--max-rollouts 2"),
    ("experiment golden", "--volumes 0.5"),
    ("experiment power", "--runs 1 --updates 1 --kernels 5"),
    ("robot play joints.csv", "--start-timeout 0.3"),
    ("robot check joints.csv", ""),
    ("scale read", "--timeout 0.3 --retries 0"),
    ("scale calibrate", "--timeout 0.3 --retries 0"),
];

/// A subcommand with random flags, each with a random value or none.
fn random_flags() -> impl Strategy<Value = Case> {
    let flags = prop::collection::vec(
        (
            prop::sample::select(FLAGS.to_vec()),
            prop::option::weighted(0.8, value()),
        ),
        0..6,
    );
    let command = prop::sample::select(RANDOM.to_vec());
    (command, flags, stdin()).prop_map(|((command, bound), flags, stdin)| {
        let mut args: Vec<String> = command.split(' ').map(String::from).collect();
        args.extend(bound.split(' ').filter(|t| !t.is_empty()).map(String::from));
        for (flag, value) in flags {
            args.push(flag.to_string());
            args.extend(value);
        }
        Case {
            args,
            mutation: None,
            stdin,
        }
    })
}

/// A file's kind, size, modification time and content.
type Seen = (bool, u64, Option<SystemTime>, u64);

/// Every file and directory under `dir` (by relative path) but `outputs`
/// and what lies under them or beside them as their moved-aside runs.
fn snapshot(dir: &Path, outputs: &[PathBuf]) -> BTreeMap<PathBuf, Seen> {
    let mut seen = BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for entry in std::fs::read_dir(&d).unwrap() {
            let path = entry.unwrap().path();
            let rel = path.strip_prefix(dir).unwrap().to_path_buf();
            let output = outputs.iter().any(|o| {
                let aside = format!("{}.replaced-", o.display());
                rel.starts_with(o) || rel.to_string_lossy().starts_with(&aside)
            });
            if output {
                continue;
            }
            let meta = std::fs::symlink_metadata(&path).unwrap();
            if meta.is_dir() {
                todo.push(path);
                // A directory's time changes with what is written in it.
                seen.insert(rel, (true, 0, None, 0));
            } else {
                let mut hash = std::hash::DefaultHasher::new();
                std::fs::read(&path).unwrap_or_default().hash(&mut hash);
                seen.insert(
                    rel,
                    (false, meta.len(), meta.modified().ok(), hash.finish()),
                );
            }
        }
    }
    seen
}

/// What `args` may write, relative to the case's directory: the values of
/// the output flags (or the default output directories without --out)
/// that no other argument names as an input.
fn outputs(args: &[String]) -> Vec<PathBuf> {
    let mut named = Vec::new();
    let mut read = BTreeSet::new();
    let mut i = 0;
    while i < args.len() {
        match args.get(i + 1) {
            Some(v) if OUTPUT_FLAGS.contains(&args[i].as_str()) => {
                named.push(v.clone());
                i += 2;
            }
            _ => {
                read.insert(args[i].split('=').next().unwrap_or(&args[i]).to_string());
                i += 1;
            }
        }
    }
    if !args.iter().any(|a| a == "--out") {
        named.extend(DEFAULT_OUTPUTS.iter().map(|d| d.to_string()));
    }
    named
        .iter()
        .filter(|o| !read.contains(*o))
        .map(|o| Path::new(o).components().collect())
        .collect()
}

/// Cases run, by the test and exit status.
static STATUSES: Mutex<BTreeMap<(&str, i32), usize>> = Mutex::new(BTreeMap::new());

/// Runs `primo args` in `dir` with `input` on its stdin, within [`LIMIT`]:
/// exit status (128 + the signal if one ended it), stdout, stderr.
fn run(dir: &Path, args: &[String], input: Vec<u8>) -> Result<(i32, String, String), String> {
    use std::os::unix::process::ExitStatusExt;
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(args)
        .current_dir(dir)
        .env_remove("RUST_BACKTRACE")
        .env_remove("PRIMO_FIRMWARE")
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        // Its own group, so that a timeout ends an evaluator it started too.
        .process_group(0)
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    // Written aside: primo may read none of it, or exit before.
    std::thread::spawn(move || stdin.write_all(&input));
    let (tx, rx) = std::sync::mpsc::channel();
    for (k, mut pipe) in [
        Box::new(child.stdout.take().unwrap()) as Box<dyn Read + Send>,
        Box::new(child.stderr.take().unwrap()),
    ]
    .into_iter()
    .enumerate()
    {
        let tx = tx.clone();
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            let _ = tx.send((k, String::from_utf8_lossy(&bytes).into_owned()));
        });
    }
    let deadline = Instant::now() + LIMIT;
    let kill = |child: &mut std::process::Child| {
        let group = format!("-{}", child.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = child.wait();
    };
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if Instant::now() > deadline {
            kill(&mut child);
            return Err(format!("still ran after {LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let mut texts = [String::new(), String::new()];
    for _ in 0..2 {
        let left = deadline.saturating_duration_since(Instant::now()) + Duration::from_secs(1);
        match rx.recv_timeout(left) {
            Ok((k, text)) => texts[k] = text,
            Err(_) => {
                kill(&mut child);
                return Err("exited, but left a process holding its stdout or stderr".into());
            }
        }
    }
    let code = status
        .code()
        .unwrap_or_else(|| 128 + status.signal().unwrap_or(0));
    let [stdout, stderr] = texts;
    Ok((code, stdout, stderr))
}

/// Copies the inputs to `to`, the run logs' `@` made `to`.
fn copy_inputs(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_inputs(&path, &target);
        } else if path.file_name().is_some_and(|n| n == "run.log") {
            let text = std::fs::read_to_string(&path).unwrap();
            std::fs::write(&target, text.replace('@', &to.display().to_string())).unwrap();
            recrc(&target);
        } else {
            std::fs::copy(&path, &target).unwrap();
        }
    }
}

/// Runs one case in a directory of its own and checks what it did.
fn check(test: &'static str, case: &Case) -> Result<(), TestCaseError> {
    static CASES: AtomicUsize = AtomicUsize::new(0);
    let n = CASES.fetch_add(1, Ordering::Relaxed);
    let dir = tmp(&format!("robustness-{n}"));
    copy_inputs(inputs(), &dir);
    if let Some((file, mutation, fix)) = &case.mutation {
        let path = dir.join(file);
        mutation.apply(&path);
        if *fix && file.ends_with("run.log") {
            recrc(&path);
        }
    }
    let outputs = outputs(&case.args);
    let before = snapshot(&dir, &outputs);
    let shown = format!("`primo {}` in {}", case.args.join(" "), dir.display());
    let params = std::fs::read_to_string(dir.join("params.json")).unwrap_or_default();
    let input: String = case
        .stdin
        .iter()
        .map(|l| l.replace("@params", params.trim()) + "\n")
        .collect();
    let (code, _, stderr) =
        run(&dir, &case.args, input.into_bytes()).map_err(|e| fail(&shown, &e))?;
    *STATUSES.lock().unwrap().entry((test, code)).or_default() += 1;
    if matches!(code, 101 | 134) || code > 128 && code != 130 && code != 141 {
        return Err(fail(&shown, &format!("exit status {code}: {stderr}")));
    }
    if stderr.contains("panicked at") || stderr.contains("RUST_BACKTRACE") {
        return Err(fail(&shown, &format!("panicked: {stderr}")));
    }
    if code != 0 && stderr.trim().is_empty() {
        return Err(fail(
            &shown,
            &format!("exit status {code} and nothing on stderr"),
        ));
    }
    // What the learner refuses, the checks before any work must have.
    if stderr.contains("learner: invalid") {
        return Err(fail(
            &shown,
            &format!("refused only by the learner: {stderr}"),
        ));
    }
    let after = snapshot(&dir, &outputs);
    let touched: Vec<&PathBuf> = before
        .keys()
        .chain(after.keys())
        .filter(|p| before.get(*p) != after.get(*p))
        .collect();
    if !touched.is_empty() {
        return Err(fail(
            &shown,
            &format!("touched {touched:?} (outputs {outputs:?})"),
        ));
    }
    std::fs::remove_dir_all(&dir).unwrap();
    Ok(())
}

fn fail(case: &str, what: &str) -> TestCaseError {
    TestCaseError::fail(format!("{case}: {what}"))
}

/// Runs `cases` cases of `strategy`, from a fixed seed, and says what
/// their exit statuses were.
fn robust(test: &'static str, seed: u8, cases: u32, strategy: impl Strategy<Value = Case>) {
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters: 64,
        ..Config::default()
    };
    let rng = TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]);
    let started = Instant::now();
    let result = TestRunner::new_with_rng(config, rng).run(&strategy, |case| check(test, &case));
    let statuses: BTreeMap<i32, usize> = STATUSES
        .lock()
        .unwrap()
        .iter()
        .filter(|((t, _), _)| *t == test)
        .map(|((_, code), n)| (*code, *n))
        .collect();
    // Past the harness's capture: the counts are the test's report.
    let _ = writeln!(
        std::io::stderr(),
        "{test}: {} cases in {:.0?}, by exit status: {statuses:?}",
        statuses.values().sum::<usize>(),
        started.elapsed()
    );
    if let Err(e) = result {
        panic!("{e}");
    }
}

#[test]
fn corrupted_command_lines_are_refused_or_run_cleanly() {
    robust("corrupted command lines", 1, 1000, corrupted(false));
}

#[test]
fn mutated_input_files_are_refused_or_run_cleanly() {
    robust("mutated input files", 2, 600, corrupted(true));
}

#[test]
fn random_flag_lists_are_refused_or_run_cleanly() {
    robust("random flag lists", 3, 400, random_flags());
}
