//! MT-SICS end to end: the client against `primo scale serve` (the real
//! binary) over a real pseudo-terminal, and `primo scale read`.
use std::io::{BufRead, BufReader, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::{Mutex, mpsc};
use std::time::{Duration, Instant};

use primo_mtsics::{Client, ClientConfig, ErrorKind, Stability, Unit};
use primo_sim::scale::ScaleModel;
use primo_sim::scale_device::{Control, Device, DeviceConfig, LoadHandle, PtyServer};

mod common;
use common::{primo, primo_with_input};

/// A running `primo scale serve`, driven through its stdin.
struct Served {
    child: Child,
    stdin: Option<ChildStdin>,
    replies: mpsc::Receiver<String>,
    path: String,
}

/// Generous: the machine may be busy with other builds.
const REPLY: Duration = Duration::from_secs(30);

impl Served {
    fn start(args: &[&str]) -> Served {
        let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
            .args(["scale", "serve"])
            .args(args)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = BufReader::new(child.stdout.take().unwrap());
        let (send, replies) = mpsc::channel();
        std::thread::spawn(move || {
            for line in stdout.lines() {
                if send.send(line.unwrap()).is_err() {
                    return;
                }
            }
        });
        let path = replies.recv_timeout(REPLY).expect("the pty path");
        assert!(path.starts_with("/dev/"), "{path}");
        Served {
            stdin: child.stdin.take(),
            child,
            replies,
            path,
        }
    }

    /// One operator command; waits until the server has done it.
    fn op(&mut self, line: &str) {
        let stdin = self.stdin.as_mut().unwrap();
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
        let reply = self.replies.recv_timeout(REPLY).unwrap();
        assert!(reply.starts_with("ok "), "{line}: {reply}");
    }

    fn client(&self, timeout: f64, retries: u32) -> Client {
        let config = ClientConfig {
            timeout: Duration::from_secs_f64(timeout),
            retries,
            ..ClientConfig::default()
        };
        Client::open(&self.path, config).unwrap_or_else(|e| panic!("{e}"))
    }
}

impl Drop for Served {
    /// Closing stdin ends the server; kill it only if it does not end.
    fn drop(&mut self) {
        drop(self.stdin.take());
        let until = Instant::now() + Duration::from_secs(20);
        while Instant::now() < until {
            if let Ok(Some(status)) = self.child.try_wait() {
                assert!(status.success() || std::thread::panicking(), "{status}");
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn near(grams: f64, want: f64) -> bool {
    (grams - want).abs() <= 0.02
}

#[test]
fn stable_weight_matches_the_load_after_settling_and_immediate_is_dynamic_meanwhile() {
    let mut served = Served::start(&["--load", "123.45", "--seed", "4"]);
    let mut scale = served.client(15.0, 2);
    assert_eq!(scale.serial(), "0123456789");
    let w = scale.stable().unwrap();
    assert!(
        near(w.grams(), 123.45) && w.unit == Unit::G && w.decimals == 2,
        "{w}"
    );
    assert!((w.to(Unit::Kg).value - 0.12345).abs() < 3e-5);

    served.op("load 50");
    let (w, stability) = scale.immediate().unwrap();
    assert_eq!(
        stability,
        Stability::Dynamic,
        "{w} right after the load changed"
    );
    // `S` waits for the display to settle (about 5 s from the step).
    let w = scale.stable().unwrap();
    assert!(near(w.grams(), 50.0), "{w}");
    let (w, stability) = scale.immediate().unwrap();
    assert!(
        stability == Stability::Stable && near(w.grams(), 50.0),
        "{w}"
    );
}

#[test]
fn zero_and_tare() {
    let served = Served::start(&["--load", "60"]);
    let mut scale = served.client(15.0, 2);
    let tare = scale.tare().unwrap();
    assert!(near(tare.grams(), 60.0), "{tare}");
    assert!(near(scale.stable().unwrap().grams(), 0.0));
    scale.clear_tare().unwrap();
    assert!(near(scale.stable().unwrap().grams(), 60.0));
    scale.zero().unwrap();
    assert!(near(scale.stable().unwrap().grams(), 0.0));
}

#[test]
fn garbage_gives_an_error_quoting_the_line_and_the_next_command_recovers() {
    let mut served = Served::start(&["--load", "20"]);
    let mut scale = served.client(15.0, 2);
    let cases = [
        (
            r"garbage S S 12,5 g",
            "received `S S 12,5 g`: not an MT-SICS response: field 3 `12,5` is not a decimal number",
        ),
        (
            r"garbage S S 1.00",
            "received `S S 1.00`: not an MT-SICS response: `S S` needs a value and a unit, found 1 field(s) after it",
        ),
        (
            r"garbage S S 1.00 lb",
            "field 4 `lb` is not a unit this client knows (g, mg, kg)",
        ),
        (
            r"garbage \xff\xfeS",
            "received `\\xff\\xfeS`: not an MT-SICS response: byte 1 is not text (not UTF-8)",
        ),
        (
            r"garbage HELLO",
            "received `HELLO`: not an MT-SICS response: field 1 `HELLO` is not an MT-SICS response",
        ),
        (r"garbage Z A", "received `Z A`: not an answer to `S`"),
        (
            "garbage ",
            "received ``: not an MT-SICS response: empty line",
        ),
    ];
    for (op, message) in cases {
        served.op(op);
        let e = scale.stable().unwrap_err();
        let text = e.to_string();
        assert!(
            matches!(e.kind, ErrorKind::Malformed(_) | ErrorKind::Unexpected(_)),
            "{op}: {text}"
        );
        assert!(
            text.starts_with(&format!("{}: sent `S`, ", served.path)),
            "{text}"
        );
        assert!(text.contains(message), "{op}: {text}");
        // The answer to the failed `S` is still on its way: dropped.
        assert!(near(scale.stable().unwrap().grams(), 20.0), "after {op}");
        assert!(
            near(scale.immediate().unwrap().0.grams(), 20.0),
            "after {op}"
        );
    }
    // An over-long line is cut and quoted.
    served.op(&format!("garbage {}", "A".repeat(300)));
    let text = scale.stable().unwrap_err().to_string();
    assert!(
        text.contains("longer than any MT-SICS line (128)"),
        "{text}"
    );
    assert!(near(scale.stable().unwrap().grams(), 20.0));
}

#[test]
fn silence_times_out_after_the_retries_then_the_scale_is_back() {
    let mut served = Served::start(&["--load", "10"]);
    let mut scale = served.client(0.4, 2);
    served.op("silent 120");
    let started = Instant::now();
    let e = scale.stable().unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Timeout { attempts: 3 }), "{e}");
    assert!(started.elapsed() >= Duration::from_millis(1200));
    assert!(
        e.to_string().ends_with(
            "sent `S` 3 time(s), no answer within 0.4 s each: is the scale on and connected, at the right baud rate?"
        ),
        "{e}"
    );
    served.op("silent 0");
    assert!(near(scale.stable().unwrap().grams(), 10.0));
}

#[test]
fn overload_and_underload_are_typed_errors() {
    let served = Served::start(&["--load", "5000"]);
    let mut scale = served.client(15.0, 2);
    let e = scale.stable().unwrap_err();
    assert!(
        matches!(&e.kind, ErrorKind::Overload(line) if line == "S +"),
        "{e}"
    );
    assert!(
        e.to_string().contains("sent `S`, received `S +`: overload"),
        "{e}"
    );
    assert!(matches!(
        scale.immediate().unwrap_err().kind,
        ErrorKind::Overload(_)
    ));
    assert!(matches!(
        scale.tare().unwrap_err().kind,
        ErrorKind::Overload(_)
    ));

    let served = Served::start(&["--load", "-300"]);
    let mut scale = served.client(15.0, 2);
    let e = scale.stable().unwrap_err();
    assert!(
        matches!(&e.kind, ErrorKind::Underload(line) if line == "S -"),
        "{e}"
    );
    assert!(matches!(
        scale.zero().unwrap_err().kind,
        ErrorKind::Underload(_)
    ));
}

#[test]
fn a_scale_that_cannot_settle_is_retried_then_reported_busy() {
    let mut served = Served::start(&["--stable-timeout", "0.3"]);
    let mut scale = served.client(15.0, 2);
    served.op("load 80");
    // Each `S` gives up after 0.3 s; the display needs seconds.
    let e = scale.stable().unwrap_err();
    assert!(
        matches!(&e.kind, ErrorKind::NotExecutable { attempts: 3, line } if line == "S I"),
        "{e}"
    );
    assert!(
        e.to_string()
            .contains("received `S I`: the scale is busy or could not settle, 3 time(s)"),
        "{e}"
    );
}

#[test]
fn power_on_lines_are_skipped_at_connect_and_mid_exchange() {
    let mut served = Served::start(&["--load", "30"]);
    // The scale sent its power-on line when serving started; two more are
    // waiting when the client connects (flushed, or skipped if in flight).
    served.op("power-on");
    served.op("power-on");
    let mut scale = served.client(15.0, 2);
    assert!(near(scale.stable().unwrap().grams(), 30.0));
    let at_connect = scale.power_on_lines();
    assert!(at_connect <= 3);

    // Between two commands.
    served.op("power-on");
    assert!(near(scale.stable().unwrap().grams(), 30.0));
    assert_eq!(scale.power_on_lines(), at_connect + 1);

    // While `S` waits for the display to settle after a load change.
    served.op("load 45");
    let w = std::thread::scope(|s| {
        s.spawn(|| {
            std::thread::sleep(Duration::from_millis(500));
            served.op("power-on");
        });
        scale.stable()
    });
    assert!(near(w.unwrap().grams(), 45.0));
    assert_eq!(scale.power_on_lines(), at_connect + 2);
}

#[test]
fn primo_scale_read_prints_one_stable_weight() {
    let served = Served::start(&["--load", "77.7"]);
    let read = |extra: &[&str]| {
        let mut args = vec!["scale", "read", "--port", served.path.as_str()];
        args.extend_from_slice(extra);
        primo(&args)
    };
    let number = |out: &str, unit: &str| -> f64 {
        let text = out
            .strip_suffix(&format!(" {unit}\n"))
            .unwrap_or_else(|| panic!("{out:?}"));
        text.parse().unwrap()
    };
    let (code, out, err) = read(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(near(number(&out, "g"), 77.7), "{out}");
    let (code, out, err) = read(&["--unit", "kg", "--baud", "19200"]);
    assert_eq!(code, 0, "{err}");
    assert!((number(&out, "kg") - 0.0777).abs() <= 2e-5, "{out}");
    assert_eq!(
        out.trim_end().split(['.', ' ']).nth(1).map(str::len),
        Some(5),
        "{out}"
    );
    let (code, out, err) = read(&["--unit", "ml", "--density", "1.25"]);
    assert_eq!(code, 0, "{err}");
    assert!((number(&out, "ml") - 77.7 / 1.25).abs() <= 0.02, "{out}");

    let (code, _, err) = read(&["--timeout=-1"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--timeout"), "{err}");
    let (code, _, err) = primo(&["scale", "read", "--port", "/nonexistent/tty"]);
    assert_eq!(code, 1);
    assert!(err.contains("/nonexistent/tty: cannot open"), "{err}");

    let served = Served::start(&["--load", "5000"]);
    let (code, _, err) = primo(&["scale", "read", "--port", &served.path]);
    assert_eq!(code, 1);
    assert!(err.contains("received `S +`: overload"), "{err}");
}

#[test]
fn serve_answers_every_operator_line() {
    let (code, text, err) = primo_with_input(
        &["scale", "serve"],
        b"load x\nsilent -1\njump\n\ngarbage \\q\npower-on\n",
    );
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 6, "{text}");
    assert!(lines[1].starts_with("error: stdin line 1: load <grams>: `x` is not a number"));
    assert!(lines[2].starts_with("error: stdin line 2: silent <seconds>: -1 is not a duration"));
    assert!(lines[3].starts_with("error: stdin line 3: `jump`: expected"));
    assert!(lines[4].starts_with("error: stdin line 5: garbage: unknown escape"));
    assert_eq!(lines[5], "ok power-on");
}

/// `TTYPort::pair` is not thread-safe: in-process servers start one at a time.
static PAIR: Mutex<()> = Mutex::new(());

#[test]
fn in_process_server_follows_a_shared_load() {
    let model = ScaleModel::default();
    let load = LoadHandle::new(0.0);
    let device = Device::new(model, 9, load.clone(), DeviceConfig::for_model(&model)).unwrap();
    let server = {
        let _one = PAIR.lock().unwrap();
        PtyServer::start(device).unwrap()
    };
    let config = ClientConfig {
        timeout: Duration::from_secs(15),
        ..ClientConfig::default()
    };
    let mut scale = Client::open(server.path(), config).unwrap();
    assert!(near(scale.stable().unwrap().grams(), 0.0));
    let skipped = scale.power_on_lines();
    load.set(25.0);
    server.control(Control::PowerOn).unwrap();
    let w = scale.stable().unwrap();
    assert!(near(w.grams(), 25.0), "{w}");
    assert_eq!(scale.power_on_lines(), skipped + 1);
    drop(scale);
    server.stop().unwrap();
}
