//! MT-SICS end to end: the client against `primo scale serve` (the real
//! binary) over a real pseudo-terminal, and `primo scale read`; and both
//! against a small balance emulator of the tests' own (noise, a balance
//! settling, silence).
use std::io::{BufRead, BufReader, Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use primo_mtsics::{Client, ClientConfig, ErrorKind, Stability, Unit};
use primo_sim::scale::ScaleModel;
use primo_sim::scale_device::{Control, Device, DeviceConfig, LoadHandle, PtyServer};
use serialport::{SerialPort, TTYPort};

mod common;
use common::primo;

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
    /// The server serves until it is killed.
    fn drop(&mut self) {
        drop(self.stdin.take());
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
fn noise_lines_are_skipped_and_an_answer_for_another_command_is_an_error() {
    let mut served = Served::start(&["--load", "20"]);
    let mut scale = served.client(15.0, 2);
    let noise = [
        r"garbage S S 12,5 g",
        r"garbage S S 1.00",
        r"garbage S S 1.00 lb",
        r"garbage \xff\xfeS",
        r"garbage HELLO",
        "garbage ",
    ];
    for (i, op) in noise.into_iter().enumerate() {
        served.op(op);
        // The noise line is waiting before the answer to `S`: skipped.
        assert!(near(scale.stable().unwrap().grams(), 20.0), "after {op}");
        assert_eq!(scale.noise_lines(), i as u32 + 1, "{op}");
    }
    served.op(&format!("garbage {}", "A".repeat(300)));
    assert!(near(scale.stable().unwrap().grams(), 20.0));
    assert_eq!(scale.noise_lines(), 7);

    // A valid line answering another command: refused, then resynced.
    served.op("garbage Z A");
    let e = scale.stable().unwrap_err();
    assert!(matches!(e.kind, ErrorKind::Unexpected(_)), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: sent `S`, received `Z A`: not an answer to `S`",
            served.path
        )
    );
    assert!(near(scale.stable().unwrap().grams(), 20.0));
    assert!(near(scale.immediate().unwrap().0.grams(), 20.0));
}

#[test]
fn silence_times_out_within_the_timeout_then_the_scale_is_back() {
    let mut served = Served::start(&["--load", "10"]);
    let mut scale = served.client(1.2, 2);
    served.op("silent 120");
    let started = Instant::now();
    let e = scale.stable().unwrap_err();
    let took = started.elapsed();
    assert!(matches!(e.kind, ErrorKind::Timeout { attempts: 3 }), "{e}");
    // Three sends spread over the timeout, not three timeouts.
    assert!(
        took >= Duration::from_millis(1200) && took < Duration::from_millis(2000),
        "{took:?}"
    );
    assert!(
        e.to_string().ends_with(
            "sent `S` 3 time(s), no answer within 1.2 s: is the scale on and connected, at the right baud rate?"
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
fn zero_names_the_zero_setting_range_and_tare_warns_it_will_not_last() {
    let served = Served::start(&["--load", "200"]);
    let port = served.path.as_str();
    let (code, _, err) = primo(&["scale", "zero", "--port", port]);
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("beyond the balance's zero-setting range"),
        "{err}"
    );
    assert!(!err.contains("beyond the scale's range"), "{err}");
    let (code, out, err) = primo(&["scale", "read", "--port", port]);
    assert_eq!((code, out.trim()), (0, "200.00 g"), "{err}");
    let (code, out, err) = primo(&["scale", "tare", "--port", port]);
    assert_eq!((code, out.trim()), (0, "tared 200.00 g"), "{err}");
    assert!(
        err.contains("warning") && err.contains("until primo next connects"),
        "{err}"
    );
}

#[test]
fn a_scale_that_cannot_settle_is_asked_again_until_the_settling_time_is_over() {
    let mut served = Served::start(&["--stable-timeout", "0.3"]);
    let config = ClientConfig {
        timeout: Duration::from_secs(15),
        settle: Duration::from_secs(2),
        ..ClientConfig::default()
    };
    let mut scale = Client::open(&served.path, config).unwrap();
    served.op("load 80");
    // Each `S` gives up after 0.3 s; the display needs seconds.
    let started = Instant::now();
    let e = scale.stable().unwrap_err();
    let took = started.elapsed();
    let ErrorKind::NotExecutable {
        attempts,
        line,
        waited,
    } = &e.kind
    else {
        panic!("{e}")
    };
    assert_eq!(line, "S I");
    assert!(*attempts >= 4, "{e}");
    assert!(
        *waited >= Duration::from_millis(1800) && took < Duration::from_secs(4),
        "{e}"
    );
    assert!(
        e.to_string().contains(&format!(
            "received `S I`: the scale did not settle (or stayed busy): asked {attempts} time(s) over"
        )),
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
fn primo_scale_zero_and_tare_set_the_balance() {
    let served = Served::start(&["--load", "12.5"]);
    let port = served.path.as_str();
    let (code, out, err) = primo(&["scale", "tare", "--port", port]);
    assert_eq!(code, 0, "{err}");
    // (Each command connects anew, and primo's `@` at connect cancels a
    // tare: tare and zero are for the run that follows on the same line.)
    assert!(out.starts_with("tared 12.5"), "{out}");
    let (code, out, err) = primo(&["scale", "zero", "--port", port]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out, "zeroed\n");
    // A balance calibrates itself: refused, naming why.
    let (code, _, err) = primo(&["scale", "calibrate", "--port", port, "--high", "100"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("an MT-SICS balance calibrates itself"),
        "{err}"
    );
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

    for (flag, value) in [
        ("--timeout", "-1"),
        ("--timeout", "0"),
        ("--settle", "90000"),
    ] {
        let (code, _, err) = read(&[&format!("{flag}={value}")]);
        assert_eq!(code, 2, "{err}");
        assert_eq!(
            err.trim_end(),
            format!("primo: {flag}: {value} s must be more than 0 s and at most a day (86400 s)")
        );
    }
    let (code, _, err) = primo(&["scale", "read", "--port", "/nonexistent/tty"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--port /nonexistent/tty: no such file or device"),
        "{err}"
    );

    let served = Served::start(&["--load", "5000"]);
    let (code, _, err) = primo(&["scale", "read", "--port", &served.path]);
    assert_eq!(code, 1);
    assert!(err.contains("received `S +`: overload"), "{err}");
}

#[test]
fn serve_answers_every_operator_line() {
    let mut served = Served::start(&[]);
    let stdin = served.stdin.as_mut().unwrap();
    stdin
        .write_all(b"load x\nsilent -1\njump\n\ngarbage \\q\npower-on\n")
        .unwrap();
    stdin.flush().unwrap();
    let lines: Vec<String> = (0..5)
        .map(|_| served.replies.recv_timeout(REPLY).unwrap())
        .collect();
    assert!(lines[0].starts_with("error: stdin line 1: load <grams>: `x` is not a number"));
    assert!(lines[1].starts_with("error: stdin line 2: silent <seconds>: -1 is not a duration"));
    assert!(lines[2].starts_with("error: stdin line 3: `jump`: expected"));
    assert!(lines[3].starts_with("error: stdin line 5: garbage: unknown escape"));
    assert_eq!(lines[4], "ok power-on");
}

#[test]
fn serve_serves_on_after_stdin_closes() {
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(["scale", "serve", "--load", "12.5"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut path = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut path)
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let running = child.try_wait().unwrap().is_none();
    let (code, out, err) = primo(&["scale", "read", "--port", path.trim()]);
    let _ = child.kill();
    let _ = child.wait();
    assert!(running, "`primo scale serve < /dev/null` ended at once");
    assert_eq!((code, out.trim()), (0, "12.50 g"), "{err}");
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

/// A balance emulator written for these tests, apart from primo's
/// simulated scale: on a pseudo-terminal pair, a thread answers each
/// command line with the raw byte chunks its script gives (written one by
/// one, so a partial line arrives on its own), until stopped.
struct Emulator {
    path: String,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<Vec<String>>>,
    /// Kept open: without it the pair closes when the client does.
    _slave: TTYPort,
}

type Script = Box<dyn FnMut(&str) -> Vec<Vec<u8>> + Send>;

impl Emulator {
    fn start(mut script: Script) -> Emulator {
        let (mut master, slave) = {
            let _one = PAIR.lock().unwrap();
            TTYPort::pair().unwrap()
        };
        master.set_timeout(Duration::from_millis(20)).unwrap();
        let path = slave.name().unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = stop.clone();
        let thread = std::thread::spawn(move || {
            let mut commands = Vec::new();
            let mut pending = Vec::new();
            let mut buf = [0u8; 256];
            while !stopped.load(Ordering::Relaxed) {
                let n = match master.read(&mut buf) {
                    Ok(n) => n,
                    // No data yet, or no client on the slave side.
                    Err(_) => {
                        std::thread::sleep(Duration::from_millis(5));
                        continue;
                    }
                };
                pending.extend_from_slice(&buf[..n]);
                while let Some(end) = pending.iter().position(|&b| b == b'\n') {
                    let line: Vec<u8> = pending.drain(..=end).collect();
                    let command = String::from_utf8_lossy(&line).trim_end().to_string();
                    for chunk in script(&command) {
                        master.write_all(&chunk).unwrap();
                        master.flush().unwrap();
                        std::thread::sleep(Duration::from_millis(20));
                    }
                    commands.push(command);
                }
            }
            commands
        });
        Emulator {
            path,
            stop,
            thread: Some(thread),
            _slave: slave,
        }
    }

    /// Stops the emulator: the commands it received.
    fn stop(mut self) -> Vec<String> {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.take().unwrap().join().unwrap()
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
    }
}

const SERIAL: &[u8] = b"I4 A \"EMU-42\"\r\n";

/// Line noise and a partial line before every answer.
fn noisy(command: &str) -> Vec<Vec<u8>> {
    let answer: &[u8] = match command {
        "@" | "I4" => SERIAL,
        "S" => b"S S     42.00 g\r\n",
        _ => b"ES\r\n",
    };
    vec![
        b"\xf0\x80\x00\xff\r\n".to_vec(),
        b"S S   1".to_vec(),
        b"\r\n".to_vec(),
        b"\xfe\x7f".to_vec(),
        answer.to_vec(),
    ]
}

fn emulator_config(timeout: f64, settle: f64) -> ClientConfig {
    ClientConfig {
        timeout: Duration::from_secs_f64(timeout),
        settle: Duration::from_secs_f64(settle),
        ..ClientConfig::default()
    }
}

#[test]
fn line_noise_and_partial_lines_before_the_answers_are_skipped() {
    let emulator = Emulator::start(Box::new(noisy));
    let mut scale = Client::open(&emulator.path, emulator_config(5.0, 5.0)).unwrap();
    assert_eq!(scale.serial(), "EMU-42");
    // Two noise lines, the answer taken from the end of a third.
    assert_eq!(scale.noise_lines(), 3);
    let w = scale.stable().unwrap();
    assert_eq!((w.value, w.unit, w.decimals), (42.0, Unit::G, 2));
    assert_eq!(scale.noise_lines(), 6);
    drop(scale);

    let (code, out, err) = primo(&["scale", "read", "--port", &emulator.path]);
    assert_eq!((code, out.as_str()), (0, "42.00 g\n"), "{err}");
    let commands = emulator.stop();
    assert_eq!(commands, ["@", "S", "@", "S"]);
}

#[test]
fn noise_and_no_answer_says_what_was_skipped() {
    // A wrong baud rate: every answer is garbled.
    let emulator = Emulator::start(Box::new(|_: &str| vec![b"\xe1\x9c S\xb3\r\n".to_vec()]));
    let started = Instant::now();
    let e = Client::open(&emulator.path, emulator_config(1.0, 5.0)).unwrap_err();
    assert!(started.elapsed() < Duration::from_millis(1500));
    assert!(matches!(e.kind, ErrorKind::Timeout { attempts: 3 }), "{e}");
    assert_eq!(e.noise.as_ref().map(|n| n.lines), Some(3), "{e}");
    assert_eq!(
        e.to_string(),
        format!(
            "{}: sent `@` 3 time(s), no MT-SICS answer within 1.0 s, only 3 line(s) of noise \
             (the last `\\xe1\\x9c S\\xb3`: byte 1 is not text (not UTF-8)): is the baud rate \
             right (8N1), and the cable?",
            emulator.path
        )
    );
}

/// `S I` for the first five `S`, each after 0.4 s (a balance waiting for
/// a stable reading), then the weight; `@` answered at once.
fn settling() -> Script {
    let mut asked = 0;
    Box::new(move |command: &str| match command {
        "@" | "I4" => vec![SERIAL.to_vec()],
        "S" => {
            asked += 1;
            std::thread::sleep(Duration::from_millis(400));
            if asked <= 5 {
                vec![b"S I\r\n".to_vec()]
            } else {
                vec![b"S S    100.01 g\r\n".to_vec()]
            }
        }
        _ => vec![b"ES\r\n".to_vec()],
    })
}

#[test]
fn a_settling_balance_is_asked_again_until_it_is_stable() {
    let emulator = Emulator::start(settling());
    let mut scale = Client::open(&emulator.path, ClientConfig::default()).unwrap();
    let started = Instant::now();
    let w = scale.stable().unwrap();
    assert_eq!(w.value, 100.01);
    assert!(started.elapsed() >= Duration::from_millis(2400));
    drop(scale);
    assert_eq!(emulator.stop().iter().filter(|c| *c == "S").count(), 6);

    let emulator = Emulator::start(settling());
    let (code, out, err) = primo(&["scale", "read", "--port", &emulator.path]);
    assert_eq!((code, out.as_str()), (0, "100.01 g\n"), "{err}");

    // Never stable: given up after --settle, saying what it saw.
    let emulator = Emulator::start(Box::new(|command: &str| match command {
        "@" => vec![SERIAL.to_vec()],
        _ => vec![b"S I\r\n".to_vec()],
    }));
    let started = Instant::now();
    let (code, _, err) = primo(&["scale", "read", "--port", &emulator.path, "--settle", "1.5"]);
    let took = started.elapsed();
    assert_eq!(code, 1, "{err}");
    assert!(
        took >= Duration::from_millis(1400) && took < Duration::from_secs(4),
        "{took:?}"
    );
    assert!(
        err.starts_with(&format!(
            "primo: {}: sent `S`, received `S I`: the scale did not settle (or stayed busy): asked ",
            emulator.path
        )),
        "{err}"
    );
}

#[test]
fn a_silent_port_is_reported_within_ten_seconds_by_default() {
    let emulator = Emulator::start(Box::new(|_: &str| Vec::new()));
    let started = Instant::now();
    let (code, _, err) = primo(&["scale", "read", "--port", &emulator.path]);
    let took = started.elapsed();
    assert_eq!(code, 1, "{err}");
    assert!(took < Duration::from_secs(11), "{took:?}");
    assert_eq!(
        err.trim_end(),
        format!(
            "primo: {}: sent `@` 3 time(s), no answer within 10.0 s: is the scale on and \
             connected, at the right baud rate?",
            emulator.path
        )
    );
    assert_eq!(emulator.stop(), ["@", "@", "@"]);
}

#[test]
fn a_path_that_is_no_serial_port_is_refused() {
    let file = common::tmp("not-a-port.txt");
    std::fs::write(&file, "S S 1.00 g\r\n").unwrap();
    let file = file.to_str().unwrap();
    for (port, what) in [
        ("/dev/null", "a device that is not a terminal"),
        (file, "a regular file"),
        ("/tmp", "a directory"),
    ] {
        let (code, out, err) = primo(&["scale", "read", "--port", port]);
        assert_eq!((code, out.as_str()), (2, ""), "{err}");
        assert_eq!(
            err.trim_end(),
            format!("primo: --port {port}: not a serial port: it is {what}")
        );
    }
}
