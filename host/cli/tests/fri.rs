//! FRI end to end on loopback UDP: primo's client against the simulated
//! KRC (in-process threads, and the real `primo robot` binaries), with the
//! faults a real cell has: lost packets, a quality drop, a robot that stays
//! in monitor mode, packets that stop, malformed datagrams, and
//! trajectories that would cross a joint limit. And the KRC as the whole
//! simulated cell: repeated roll-outs on one socket, the held load from the
//! force estimate, the cell's scale over MT-SICS on a real pseudo-terminal,
//! the operator's reset.
//!
//! The tests run one at a time (they are real-time loops on a machine that
//! may have two cores), with cycles of 4 ms, and of 2 ms (the default) for
//! the long pouring movement.
use std::io::{BufRead, BufReader, Write};
use std::net::{SocketAddr, UdpSocket};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, mpsc};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use primo_core::power::{Power, PowerConfig};
use primo_fri::packet::{Measurement, Quality, State};
use primo_fri::path::FriPath;
use primo_fri::session::{SessionConfig, Stop};
use primo_fri::udp::{Ended, Event, PlayConfig, PlayResult, play};
use primo_learn::learner::{MAX_EXTENDED, power_blocks};
use primo_learn::pour::rig::{Simulated, roll_out};
use primo_learn::pour::skill::Space;
use primo_learn::pour::skill::built_in_skill;
use primo_learn::pour::skill::gate;
use primo_learner::SAMPLER;
use primo_mtsics::{Client, ClientConfig};
use primo_robot::JOINTS;
use primo_robot::Robot;
use primo_robot::safety::check_joints;
use primo_sim::bottle::G;
use primo_sim::cell::{CellConfig, GlassKind};
use primo_sim::expert::{Style, rest_configuration, synthesize};
use primo_sim::krc::{CellHandle, FORCE_NOISE, KrcConfig, KrcReport, SimKrc};

mod common;
use common::{primo, tmp};

static SERIAL: Mutex<()> = Mutex::new(());

fn serial() -> MutexGuard<'static, ()> {
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// primo's side: a socket on a free loopback port.
fn client_socket() -> (UdpSocket, SocketAddr) {
    let socket = UdpSocket::bind("127.0.0.1:0").unwrap();
    let addr = socket.local_addr().unwrap();
    (socket, addr)
}

struct Krc {
    thread: JoinHandle<KrcReport>,
    stop: Arc<AtomicBool>,
    cell: CellHandle,
    addr: SocketAddr,
}

impl Krc {
    fn start(cfg: KrcConfig) -> Krc {
        Krc::run(SimKrc::new(cfg).unwrap())
    }

    fn run(krc: SimKrc) -> Krc {
        let (cell, addr) = (krc.cell(), krc.local_addr().unwrap());
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let thread = std::thread::spawn(move || krc.run(&flag).unwrap());
        Krc {
            thread,
            stop,
            cell,
            addr,
        }
    }

    fn finish(self) -> KrcReport {
        self.stop.store(true, Ordering::Relaxed);
        self.thread.join().unwrap()
    }
}

/// A recording KRC for a loaded machine: a 4 ms cycle (twice the
/// default's time for primo's answers), content with half of them on time,
/// and waiting out a 1 s stall before leaving command mode. The faults
/// under test are injected on top.
fn krc_config(remote: SocketAddr) -> KrcConfig {
    let mut cfg = KrcConfig::new(remote);
    cfg.cycle = Duration::from_millis(4);
    cfg.thresholds = [0.2, 0.5, 0.98];
    cfg.release_after = Duration::from_secs(1);
    cfg.record = true;
    cfg
}

/// A 2 s movement near the rest posture: joints 1, 4 and 7 swing by up to
/// 0.3 rad, starting 0.2 rad from where the KRC's arm stands.
fn swing() -> FriPath {
    let rest = rest_configuration(0.0);
    let n = 201;
    let times = (0..n).map(|i| i as f64 * 0.01).collect();
    let rows = (0..n)
        .map(|i| {
            let s = i as f64 / (n - 1) as f64;
            let wave = (std::f64::consts::PI * s).sin();
            let mut q = rest;
            q[0] += 0.2 + 0.3 * wave;
            q[3] -= 0.2 * wave;
            q[6] += 0.3 * s;
            q
        })
        .collect();
    FriPath::try_from(&check_joints(&Robot::lwr4(), times, rows).unwrap()).unwrap()
}

fn max_abs(a: &[f64; JOINTS], b: &[f64; JOINTS]) -> f64 {
    (0..JOINTS).map(|j| (a[j] - b[j]).abs()).fold(0.0, f64::max)
}

/// The KRC ran but never got an answer, and the arm never moved.
fn assert_nothing_sent(report: &KrcReport) {
    assert!(report.cycles > 0);
    assert_eq!((report.answered, report.stale), (0, 0));
    assert_eq!(report.max_excursion, 0.0);
}

/// primo waiting out a 1 s stall.
fn fast_config() -> PlayConfig {
    PlayConfig {
        start_timeout: Duration::from_secs(20),
        cycle_timeout: Duration::from_secs(1),
        ..PlayConfig::default()
    }
}

fn assert_tracked(result: &PlayResult, report: &KrcReport, path: &FriPath) {
    println!(
        "KRC: {} cycles, {} answered on time, {} missed, {} stale",
        report.cycles, report.answered, report.missed, report.stale
    );
    assert_eq!(result.ended, Ended::Completed, "{result:?}");
    assert_eq!(result.sent, result.planned);
    assert!(result.approach > 1, "approached the start first");
    // Tracking error of the 5 ms servo at these speeds: well under 1°.
    for j in 0..JOINTS {
        assert!(
            result.tracking.max[j] < 1f64.to_radians(),
            "joint {}: {:?}",
            j + 1,
            result.tracking
        );
        assert!(result.tracking.rms[j] <= result.tracking.max[j]);
    }
    // The KRC never saw a command faster than the limits or beyond them,
    // and its arm ended at the trajectory's end.
    assert_eq!((report.too_fast, report.beyond_limits), (0, 0));
    let end = *path.rows().last().unwrap();
    assert!(
        max_abs(&report.measured, &end) < 1e-3,
        "{:?}",
        report.measured
    );
}

/// The events of a completed run: the loop's scheduling, the KRC, then
/// weighing, approaching, streaming (progress rising, about once a
/// second) and settling, each once and in that order.
fn assert_events_follow_the_run(timed: &[(Instant, Event)], result: &PlayResult) {
    let events: Vec<Event> = timed.iter().map(|(_, e)| e.clone()).collect();
    println!("{events:?}");
    assert!(
        matches!(events.first(), Some(Event::Realtime(_))),
        "{events:?}"
    );
    assert_eq!(events.get(1), result.krc.map(Event::Krc).as_ref());
    assert_eq!(
        events.get(2),
        Some(&Event::Weighing {
            setpoints: result.weighing
        })
    );
    assert_eq!(
        events.get(3),
        Some(&Event::Approaching {
            setpoints: result.approach
        })
    );
    assert_eq!(events.last(), Some(&Event::Settling));
    let streaming: Vec<usize> = events[4..events.len() - 1]
        .iter()
        .map(|e| match e {
            Event::Streaming { sent, planned } if *planned == result.planned => *sent,
            other => panic!("{other:?} while streaming"),
        })
        .collect();
    assert_eq!(
        streaming.first(),
        Some(&(result.weighing + result.approach + 1))
    );
    assert!(streaming.windows(2).all(|w| w[0] < w[1]), "{streaming:?}");
    // One a second of the streaming's wall-clock time (longer than the
    // trajectory's when the machine is loaded and the KRC misses cycles),
    // give or take one.
    // (The first progress event comes a second into the streaming.)
    let seconds = match (timed.get(4), timed.last()) {
        (Some((first, _)), Some((settled, _))) => (*settled - *first).as_secs_f64() + 1.0,
        _ => 0.0,
    };
    assert!(
        (streaming.len() as f64 - seconds).abs() <= 1.5,
        "{} progress events over {seconds} s",
        streaming.len()
    );
}

#[test]
fn a_pouring_movement_is_streamed_tracked_and_pours() {
    let _serial = serial();
    // The joint-space skill's movement for a 0.5 l bottle, through the
    // same check as the simulated roll-outs.
    let cell_cfg = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell_cfg, Space::Joint, 30).unwrap();
    let plan = skill.plan(&[0.5], &[], cell_cfg.dt).unwrap();
    let gate = gate(&cell_cfg);
    let path = FriPath::try_from(&skill.check(&gate, &plan).unwrap()).unwrap();
    let mut rig = Simulated::new(cell_cfg, 0.5, 1).unwrap();
    let direct = roll_out(&mut rig, &skill, 0.2, 1, &[0.5], &[]).unwrap();

    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.cycle = Duration::from_millis(2);
    let krc = Krc::start(cfg);
    let mut events = Vec::new();
    let result = play(&socket, &path, &fast_config(), &mut |e| {
        events.push((Instant::now(), e))
    })
    .unwrap();
    let cell = krc.cell.clone();
    let report = krc.finish();
    println!("{result:?}");
    assert_tracked(&result, &report, &path);
    assert_eq!(result.gaps, 0);
    assert_events_follow_the_run(&events, &result);
    // The handshake: monitor mode, the quality ramping up, then command
    // mode; the first commanded position was where the arm stood.
    let first_cmd = report
        .log
        .iter()
        .position(|c| c.state == State::Command)
        .unwrap();
    let ramp: Vec<Quality> = report.log[..first_cmd].iter().map(|c| c.quality).collect();
    assert!(
        ramp.contains(&Quality::Bad) && ramp.contains(&Quality::Ok),
        "{ramp:?}"
    );
    assert!(
        report.log[..first_cmd]
            .iter()
            .all(|c| c.state == State::Monitor)
    );
    assert!(max_abs(&report.log[first_cmd].target, &rest_configuration(0.0)) < 1e-6);
    // The liquid really poured, about as much as the same movement on the
    // simulated cell directly (the servo lags by a few ms).
    let totals = cell.lock().totals();
    let out_of_bottle = totals.glass + totals.spilled + totals.in_flight;
    println!("over FRI {totals:?}; directly {direct:?}");
    assert!(out_of_bottle > 0.1, "{totals:?}");
    assert!(
        (totals.glass + totals.in_flight - direct.poured).abs() < 0.01,
        "{totals:?} vs {direct:?}"
    );
}

#[test]
fn lost_packets_delay_but_do_not_spoil_the_run() {
    let _serial = serial();
    let path = swing();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.drop = 0.05;
    cfg.seed = 7;
    let krc = Krc::start(cfg);
    let result = play(&socket, &path, &fast_config(), &mut |_| {}).unwrap();
    let report = krc.finish();
    println!(
        "{result:?}\nKRC dropped {} of {}",
        report.dropped, report.cycles
    );
    assert_tracked(&result, &report, &path);
    // About 5 % lost, and primo saw the gaps in the sequence.
    let lost = report.dropped as f64 / report.cycles as f64;
    assert!((0.02..0.1).contains(&lost), "{lost}");
    assert!(result.gaps > 0 && result.gaps <= report.dropped);
}

#[test]
fn a_quality_drop_mid_run_holds_the_position() {
    let _serial = serial();
    let path = swing();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    // The handshake takes ~0.1 s and the approach ~1 s, so the swing runs
    // from about 1.1 s to 3.1 s: drop during it.
    let drop_at = 2.5;
    cfg.quality_drop_at = Some(Duration::from_secs_f64(drop_at));
    let krc = Krc::start(cfg);
    let result = play(&socket, &path, &fast_config(), &mut |_| {}).unwrap();
    let report = krc.finish();
    assert_eq!(result.ended, Ended::Stopped(Stop::Quality(Quality::Bad)));
    assert!(
        result.sent > result.approach && result.sent < result.planned,
        "{result:?}"
    );
    assert_eq!(
        result.ended.to_string(),
        "stopped: the communication quality dropped to Bad; held position"
    );
    // It was moving when the quality dropped, and nothing moved after:
    // the commanded position is constant from the drop on, and the arm
    // settles onto it within a few servo time constants.
    let at = report.log.iter().position(|c| c.t >= drop_at).unwrap();
    let before = &report.log[at - 10];
    assert!(max_abs(&before.target, &report.log[at - 1].target) > 1e-3);
    let held = report.log[at].target;
    let after = &report.log[at..];
    assert!(
        after.iter().all(|c| c.target == held),
        "commanded position changed"
    );
    let settled = &after[25..];
    assert!(settled.iter().all(|c| max_abs(&c.measured, &held) < 1e-4));
    assert!(after.iter().any(|c| c.answered), "primo kept answering");
}

#[test]
fn a_robot_that_never_leaves_monitor_mode_is_never_moved() {
    let _serial = serial();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.monitor_only = true;
    let krc = Krc::start(cfg);
    let play_cfg = PlayConfig {
        start_timeout: Duration::from_secs(1),
        ..PlayConfig::default()
    };
    let result = play(&socket, &swing(), &play_cfg, &mut |_| {}).unwrap();
    let report = krc.finish();
    match &result.ended {
        Ended::NeverCommanded {
            last: Some((State::Monitor, Quality::Perfect)),
            ..
        } => {}
        e => panic!("{e:?}"),
    }
    assert!(
        result
            .ended
            .to_string()
            .starts_with("the robot did not become commandable within 1.0 s (last: state Monitor")
    );
    assert_eq!(result.sent, 0);
    // primo answered every packet with the echo; the arm never moved.
    assert!(report.answered > 100);
    assert_eq!(report.command_cycles, 0);
    assert_eq!(report.max_excursion, 0.0);
}

#[test]
fn packets_that_stop_stop_the_client_after_its_timeout() {
    let _serial = serial();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.stop_after = Some(Duration::from_millis(2500));
    let krc = Krc::start(cfg);
    let started = std::time::Instant::now();
    let result = play(&socket, &swing(), &fast_config(), &mut |_| {}).unwrap();
    let report = krc.finish();
    match result.ended {
        Ended::Silent { after } => assert!(after >= Duration::from_secs(1), "{after:?}"),
        e => panic!("{e:?}"),
    }
    assert!(result.sent > result.approach && result.sent < result.planned);
    assert!(started.elapsed() < Duration::from_secs(10));
    assert!(report.command_cycles > 0);
}

#[test]
fn malformed_datagrams_get_clear_errors_and_crash_nothing() {
    let _serial = serial();
    let (socket, addr) = client_socket();
    // Garbage to primo before the KRC starts: rejected, the run goes on.
    let stranger = UdpSocket::bind("127.0.0.1:0").unwrap();
    stranger.send_to(b"hello", addr).unwrap();
    let mut wrong_id = Measurement::default();
    wrong_id.head.datagram_id = 0x1005;
    stranger.send_to(&wrong_id.encode(), addr).unwrap();
    let krc = Krc::start(krc_config(addr));
    // Garbage to the KRC: counted, the run goes on.
    stranger.send_to(&[0u8; 376], krc.addr).unwrap();
    let result = play(&socket, &swing(), &fast_config(), &mut |_| {}).unwrap();
    let report = krc.finish();
    assert_eq!(result.ended, Ended::Completed);
    let from = stranger.local_addr().unwrap();
    assert_eq!(
        result.rejections[..2],
        [
            format!(
                "from {from}: measurement packet of 5 bytes, expected 916 (starts 68 65 6c 6c 6f)"
            ),
            format!(
                "from {from}: measurement packet: datagramId at offset 6 is 0x1005, expected 0x2006"
            ),
        ]
    );
    assert_eq!(report.malformed, 1);
    assert_eq!(
        report.rejections,
        ["command packet: datagramId at offset 6 is 0x0000, expected 0x1005"]
    );
}

/// A `t,a1..a7` CSV of `path`.
fn write_csv(name: &str, path: &FriPath) -> std::path::PathBuf {
    let mut text = String::from("t,a1,a2,a3,a4,a5,a6,a7\n");
    for (t, q) in path.path().times().iter().zip(path.rows()) {
        let row: Vec<String> = q.iter().map(|v| v.to_string()).collect();
        text.push_str(&format!("{t},{}\n", row.join(",")));
    }
    let file = tmp(name);
    std::fs::write(&file, text).unwrap();
    file
}

#[test]
fn a_trajectory_crossing_a_joint_limit_is_rejected_before_anything_is_sent() {
    let _serial = serial();
    let (socket, addr) = client_socket();
    // The port is primo's: free it for the binary; the KRC sends there.
    drop(socket);
    let krc = Krc::start(krc_config(addr));
    // Joint 2 rises at 1.5 rad/s (within its velocity limit) from -0.75
    // rad and crosses its 120° limit at sample 190 (2.1 rad).
    let mut text = String::from("t,a1,a2,a3,a4,a5,a6,a7\n");
    let rest = rest_configuration(0.0);
    for i in 0..201 {
        let mut q = rest;
        q[1] = -0.75 + 0.015 * i as f64;
        let row: Vec<String> = q.iter().map(|v| v.to_string()).collect();
        text.push_str(&format!("{},{}\n", i as f64 * 0.01, row.join(",")));
    }
    let file = tmp("beyond.csv");
    std::fs::write(&file, text).unwrap();
    let (code, out, err) = primo(&[
        "robot",
        "play",
        file.to_str().unwrap(),
        "--robot",
        &format!("fri:{addr}"),
    ]);
    // Give the KRC time to notice an answer, were there one.
    std::thread::sleep(Duration::from_millis(300));
    let report = krc.finish();
    assert_eq!(code, 2, "{out}{err}");
    assert!(out.is_empty(), "{out}");
    assert_eq!(
        err.trim_end(),
        format!(
            "primo: {}: trajectory rejected, nothing sent to the robot: \
             joint a2 at sample 190 (t = 1.900 s): 2.1000 rad (120.32 deg) beyond its upper \
             limit 2.0944 rad (120.00 deg)",
            file.display()
        )
    );
    assert_nothing_sent(&report);
}

#[test]
fn power_exploration_that_crosses_a_limit_never_reaches_the_robot() {
    let _serial = serial();
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, Space::Joint, 10).unwrap();
    // PoWER exploring Δθ with 100 times the paper's variance.
    let blocks = power_blocks(&skill, 0.2, 5.0, primo_learn::learner::QUERY_DECAY).unwrap();
    let mut start = vec![0.0f32; skill.param_len() + 1];
    start[0] = 0.5;
    let cfg = PowerConfig::paper(&blocks).unwrap();
    let mut power = Power::<MAX_EXTENDED, SAMPLER>::new(&start, cfg, 3).unwrap();
    let (socket, addr) = client_socket();
    let krc = Krc::start(krc_config(addr));
    let mut rejected = Vec::new();
    let mut rig = Simulated::new(cell, 0.5, 1).unwrap();
    for _ in 0..12 {
        let theta = power.ask().to_vec();
        let (query, delta) = (theta[0], &theta[1..]);
        let trial = roll_out(&mut rig, &skill, 0.2, 1, &[query], delta).unwrap();
        power.tell(trial.reward as f32).unwrap();
        let Some(why) = trial.rejected else {
            continue;
        };
        // The learner recorded a failed roll-out with reward 0, and the
        // check a roll-out on the robot passes first (the only way to a
        // JointPath, which is all `play` takes) says the same.
        assert_eq!(trial.reward, 0.0);
        let plan = skill.plan(&[query], delta, cell.dt).unwrap();
        let checked = skill.check(&gate(&cell), &plan).map_err(|e| e.to_string());
        assert_eq!(checked.map(|_| ()), Err(why.clone()));
        rejected.push(why);
    }
    std::thread::sleep(Duration::from_millis(200));
    let report = krc.finish();
    drop(socket);
    println!("{rejected:#?}");
    assert!(!rejected.is_empty(), "the exploration crossed no limit");
    assert!(
        rejected
            .iter()
            .any(|w| w.starts_with("joint ") && w.contains(" at sample ") && w.contains("limit"))
    );
    assert_nothing_sent(&report);
}

/// `primo robot play FILE --robot ROBOT EXTRA...`: status, stdout, stderr.
fn primo_play(file: &std::path::Path, robot: &str, extra: &[&str]) -> (i32, String, String) {
    let mut args = vec!["robot", "play", file.to_str().unwrap(), "--robot", robot];
    args.extend_from_slice(extra);
    primo(&args)
}

#[test]
fn the_binaries_play_against_sim_krc() {
    let _serial = serial();
    let (socket, addr) = client_socket();
    drop(socket);
    let file = write_csv("swing.csv", &swing());
    let krc = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args([
            "robot",
            "sim-krc",
            "--port",
            &addr.port().to_string(),
            "--cycle-ms",
            "4",
            "--once",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let (code, out, err) = primo_play(
        &file,
        &format!("fri:{addr}"),
        &["--start-timeout", "20", "--cycle-timeout", "1"],
    );
    let krc = krc.wait_with_output().unwrap();
    let krc_out = String::from_utf8_lossy(&krc.stdout);
    println!("{out}{err}\n{krc_out}");
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.lines().last().unwrap() == "primo robot play: completed",
        "{out}"
    );
    assert!(
        out.contains("joint  max error [deg]  rms error [deg]"),
        "{out}"
    );
    // What it was doing, in order, each once but the progress.
    let mut stages: Vec<&str> = out
        .lines()
        .filter_map(|l| l.strip_prefix("primo robot play: "))
        .skip(1)
        .map(|l| l.split([':', ' ']).next().unwrap())
        .filter(|word| *word != "FRI")
        .collect();
    stages.dedup();
    assert_eq!(
        stages,
        [
            "KRC",
            "commandable",
            "approaching",
            "streaming",
            "settling",
            "completed"
        ],
        "{out}"
    );
    // The loop's scheduling: said, or warned about.
    assert!(
        out.contains(
            "primo robot play: FRI loop: real-time scheduling (SCHED_FIFO 80), memory locked"
        ) || err.contains("primo robot play: warning: "),
        "{out}{err}"
    );
    let a1 = out
        .lines()
        .find(|l| l.trim_start().starts_with("a1 "))
        .unwrap();
    let max: f64 = a1.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(max > 0.0 && max < 1.0, "{a1}");
    // Standing still before and after, the arm holds 0.5 l of water
    // (4.9 N); the swing pours nothing.
    let held = out
        .lines()
        .find_map(|l| l.strip_prefix("held load (estExtTcpFT): "))
        .unwrap_or_else(|| panic!("{out}"));
    let newtons: Vec<f64> = held
        .split(" N ")
        .take(2)
        .map(|v| v.split_whitespace().last().unwrap().parse().unwrap())
        .collect();
    assert!(
        newtons
            .iter()
            .all(|n| (n - 0.5 * KG_PER_LITRE * G).abs() < 0.2),
        "{held}"
    );
    assert!(krc.status.success());
    assert!(
        krc_out.contains("commands too fast 0, beyond limits 0"),
        "{krc_out}"
    );
}

#[test]
fn joint_columns_are_taken_by_name_in_any_order_for_the_lwr_or_a_urdf() {
    let _serial = serial();
    let swing = std::fs::read_to_string(write_csv("named.csv", &swing())).unwrap();
    let body = swing.split_once('\n').unwrap().1;
    // Waiting for a KRC that never comes: the trajectory was taken.
    let taken = |file: &std::path::Path, model: &[&str], what: &str| {
        let (socket, addr) = client_socket();
        drop(socket);
        let mut extra = vec!["--start-timeout", "0.3"];
        extra.extend(model);
        let (code, out, err) = primo_play(file, &format!("fri:{addr}"), &extra);
        assert_eq!(code, 1, "{what}: {out}{err}");
        assert!(out.contains("passed the limit checks"), "{out}");
        assert!(err.contains("no FRI packet from a KRC within"), "{err}");
    };
    for names in [
        "A1,A2,A3,A4,A5,A6,A7",
        "j1,j2,j3,j4,j5,j6,j7",
        "joint_1,joint_2,joint_3,joint_4,joint_5,joint_6,joint_7",
        "a1,a2,a3,a4,a5,a7,a6",
    ] {
        let file = tmp(&format!("named-{names}.csv"));
        std::fs::write(&file, format!("t,{names}\n{body}")).unwrap();
        taken(&file, &[], names);
    }
    for (names, why) in [
        ("a1,a2,a3,a4,a5,a6,a8", "column 8 `a8` names no joint"),
        ("J1,J2,J3,J4,J5,J6,J7", "column 2 `J1` names no joint"),
        (
            "a1,a2,a3,a4,a5,a6,A1",
            "columns `a1` and `A1` both name joint a1",
        ),
    ] {
        let file = tmp("misnamed.csv");
        std::fs::write(&file, format!("t,{names}\n{body}")).unwrap();
        let (code, out, err) = primo_play(&file, "fri:127.0.0.1", &[]);
        assert_eq!((code, out.as_str()), (2, ""), "{names}: {err}");
        assert!(err.contains(&format!("misnamed.csv: {why}")), "{err}");
    }
    // A URDF's seven joints, by its names, within its limits.
    let urdf = tmp("seven.urdf");
    std::fs::write(&urdf, common::seven()).unwrap();
    let model = ["--model", urdf.to_str().unwrap()];
    let file = tmp("named-q.csv");
    std::fs::write(&file, format!("t,q7,q2,q3,q4,q5,q6,q1\n{body}")).unwrap();
    taken(&file, &model, "seven.urdf");
    // Its limits, not the LWR's: at 0.01 rad/s the swing is too fast.
    let slow = tmp("slow.urdf");
    std::fs::write(
        &slow,
        common::seven().replace("velocity=\"2\"", "velocity=\"0.01\""),
    )
    .unwrap();
    let (code, _, err) = primo_play(&file, "fri:127.0.0.1", &["--model", slow.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("trajectory rejected, nothing sent to the robot: joint q"),
        "{err}"
    );
    assert!(
        err.contains("beyond its velocity limit 0.0100 rad/s"),
        "{err}"
    );
    // FRI streams seven joints: the chain to l6 has six.
    let (code, _, err) = primo_play(
        &file,
        "fri:127.0.0.1",
        &["--model", urdf.to_str().unwrap(), "--tip", "l6"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("column 2 `q7` names no joint"), "{err}");
    let six = tmp("six.csv");
    let rows: String = body
        .lines()
        .map(|l| l.rsplit_once(',').unwrap().0.to_string() + "\n")
        .collect();
    std::fs::write(&six, format!("t,q1,q2,q3,q4,q5,q6\n{rows}")).unwrap();
    let (code, _, err) = primo_play(
        &six,
        "fri:127.0.0.1",
        &["--model", urdf.to_str().unwrap(), "--tip", "l6"],
    );
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(
            "FRI streams the seven joints of a KUKA LWR; the path is for seven, which has 6 joints"
        ),
        "{err}"
    );
}

#[test]
fn robot_commands_refuse_bad_input_with_one_line() {
    let xy = tmp("xy.csv");
    std::fs::write(&xy, "t,x,y\n0,1,2\n1,2,3\n2,3,4\n").unwrap();
    let xy = xy.to_str().unwrap();
    let swing = write_csv("ok.csv", &swing());
    let swing = swing.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["robot", "play", xy, "--robot", "fri:127.0.0.1"],
            "xy.csv: no column `z`: a tool trajectory has the columns t,x,y,z,qw,qx,qy,qz",
        ),
        (
            &["robot", "play", swing, "--robot", "udp:1.2.3.4"],
            "--robot `udp:1.2.3.4`: unknown robot driver; expected fri:ADDR[:PORT]",
        ),
        (
            &["robot", "play", swing, "--robot", "udp:1.2.3.4"],
            "; or franka:ADDR[:PORT], a Franka's controller, or ros2:/CONTROLLER, a ROS 2 joint \
             trajectory controller's name",
        ),
        (
            &["robot", "play", swing, "--robot", "ros2:arm_controller"],
            "--robot `ros2:arm_controller`: the controller's name must be absolute, /NAME; \
             expected ros2:/CONTROLLER",
        ),
        (
            &["robot", "play", swing, "--robot", "ros2:/arm-controller"],
            "`ros2:/arm-controller`: not a ROS 2 name",
        ),
        (
            &["robot", "play", swing, "--robot", "fri:127.0.0.1:99999"],
            "--robot `fri:127.0.0.1:99999`: port `99999` is not a number in 1..=65535",
        ),
        (
            &[
                "robot",
                "play",
                swing,
                "--robot",
                "fri:127.0.0.1",
                "--approach-speed",
                "2",
            ],
            "--approach-speed: 2 is outside [0.001, 1]",
        ),
        (
            &["robot", "sim-krc", "--cycle-ms", "20"],
            "FRI cycle 20 ms: must be 1 to 10 ms",
        ),
        (
            &["robot", "sim-krc", "--start", "1,2"],
            "--start: expected 7 values (one per DoF: a1,a2,a3,a4,a5,a6,a7), found 2",
        ),
    ];
    for (args, message) in cases {
        let (code, out, err) = primo(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{out}");
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(message), "{args:?}: {err}");
    }
}

/// A short pour (1 s, about 23 ml from 0.5 l): the expert's 50 ml
/// demonstration cut to its pouring part and played twice as fast. It
/// starts and ends within 0.07 rad of where it starts.
fn short_pour() -> FriPath {
    let cfg = CellConfig::standard(GlassKind::Normal);
    let style = Style {
        elbow: 0.0,
        seed: 1,
    };
    let demo = synthesize(&cfg, 0.5, 0.05, &style).unwrap();
    let keep = 240..440;
    let t0 = demo.t[keep.start];
    let times = demo.t[keep.clone()]
        .iter()
        .map(|t| (t - t0) / 2.0)
        .collect();
    FriPath::try_from(&check_joints(&Robot::lwr4(), times, demo.joints[keep].to_vec()).unwrap())
        .unwrap()
}

/// Water, kg per litre.
const KG_PER_LITRE: f64 = 0.998;

/// The held load is the weight of `litres` of water within 4 σ of the
/// mean of `samples` noisy measurements (and the f32 rounding).
fn weighs(newtons: f64, litres: f64, samples: usize) -> bool {
    let sigma = FORCE_NOISE / (samples as f64).sqrt();
    (newtons - litres * KG_PER_LITRE * G).abs() < 4.0 * sigma + 1e-5
}

/// Waits until nothing is in flight between the bottle and the glass.
fn landed(cell: &CellHandle) {
    let until = Instant::now() + Duration::from_secs(5);
    while cell.lock().totals().in_flight > 0.0 {
        assert!(Instant::now() < until, "the stream never landed");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn repeated_roll_outs_on_one_socket_each_complete_and_pour() {
    let _serial = serial();
    let path = short_pour();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.start = path.start();
    let krc = Krc::start(cfg);
    let cell = krc.cell.clone();
    let mut bottle = vec![cell.lock().totals().bottle];
    let mut loads = Vec::new();
    // The host waits for its scale between roll-outs: seconds in which
    // nobody answers the KRC, which falls back to monitor mode after 1 s.
    for pause in [0.0, 1.2, 1.8] {
        std::thread::sleep(Duration::from_secs_f64(pause));
        let started = Instant::now();
        let result = play(&socket, &path, &fast_config(), &mut |_| {}).unwrap();
        landed(&cell);
        let totals = cell.lock().totals();
        println!(
            "after {pause} s: {:?} in {:.2?}, {} stale datagrams discarded, load {:?}; {totals:?}",
            result.ended,
            started.elapsed(),
            result.stale,
            result.load
        );
        assert_eq!(result.ended, Ended::Completed, "{result:?}");
        assert_eq!(result.sent, result.planned);
        if pause > 0.0 {
            // As many as the socket's receive buffer holds.
            assert!(result.stale > 50, "{result:?}");
        }
        bottle.push(totals.bottle);
        loads.push((result.load.unwrap(), result.load_samples));
    }
    let report = krc.finish();
    // Each roll-out poured, and the KRC shook hands each time anew.
    for (k, w) in bottle.windows(2).enumerate() {
        assert!(w[0] - w[1] > 0.01, "roll-out {}: {bottle:?}", k + 1);
    }
    let mut modes: Vec<State> = report.log.iter().map(|c| c.state).collect();
    modes.dedup();
    assert_eq!(
        modes,
        [
            State::Monitor,
            State::Command,
            State::Monitor,
            State::Command,
            State::Monitor,
            State::Command
        ]
    );
    assert_eq!((report.too_fast, report.beyond_limits), (0, 0));
    // What the robot held, before and after each roll-out: the liquid in
    // the bottle.
    for (k, ([before, after], [n_before, n_after])) in loads.iter().enumerate() {
        assert!(
            weighs(*before, bottle[k], *n_before) && weighs(*after, bottle[k + 1], *n_after),
            "roll-out {}: {:?} vs {bottle:?}",
            k + 1,
            loads[k]
        );
    }
}

#[test]
fn the_served_scale_and_the_force_estimate_weigh_the_pour() {
    let _serial = serial();
    let path = short_pour();
    let (socket, addr) = client_socket();
    let mut cfg = krc_config(addr);
    cfg.cycle = Duration::from_millis(2);
    cfg.record = false;
    cfg.start = path.start();
    let krc = SimKrc::new(cfg).unwrap();
    let server = krc.serve_scale().unwrap();
    let krc = Krc::run(krc);
    let mut scale = Client::open(server.path(), ClientConfig::default()).unwrap();
    let empty = scale.stable().unwrap().grams();
    assert!(empty.abs() <= 0.01, "{empty} g");
    // A second's standstill before and after: 500 measurements each.
    let play_cfg = PlayConfig {
        session: SessionConfig {
            weigh: 1.0,
            settle: 1.0,
            ..SessionConfig::default()
        },
        ..fast_config()
    };
    let result = play(&socket, &path, &play_cfg, &mut |_| {}).unwrap();
    assert_eq!(result.ended, Ended::Completed, "{result:?}");
    let weighed = scale.stable().unwrap().grams();
    let (totals, on_pan) = {
        let cell = krc.cell.lock();
        (cell.totals(), cell.load_on_pan())
    };
    krc.finish();
    drop(scale);
    server.stop().unwrap();
    let [before, after] = result.load.unwrap();
    let [n_before, n_after] = result.load_samples;
    let drop = 0.5 - totals.bottle;
    println!(
        "held {before} N, {after} N; {totals:?}; the scale read {weighed} g, the pan carries {on_pan} g"
    );
    // The scale weighs the glass to its resolution.
    assert_eq!(totals.in_flight, 0.0);
    assert!(totals.glass > 0.015, "{totals:?}");
    assert!((on_pan - totals.glass * KG_PER_LITRE * 1e3).abs() < 1e-9);
    assert!(
        (weighed - on_pan).abs() <= 0.02,
        "{weighed} g vs {on_pan} g"
    );
    // The force estimate: the bottle's liquid before and after, and the
    // drop between, within the noise of the means.
    assert!(n_before >= 500 && n_after >= 500, "{n_before} {n_after}");
    assert!(weighs(before, 0.5, n_before), "{before} N");
    assert!(weighs(after, totals.bottle, n_after), "{after} N");
    let sigma = FORCE_NOISE * (1.0 / n_before as f64 + 1.0 / n_after as f64).sqrt();
    let lost = before - after;
    assert!(
        (lost - drop * KG_PER_LITRE * G).abs() < 4.0 * sigma,
        "{lost} N for {drop} l"
    );
}

/// A running `primo robot sim-krc --scale`, its stdout read line by line.
struct SimKrcProcess {
    child: std::process::Child,
    lines: mpsc::Receiver<String>,
}

impl SimKrcProcess {
    fn next_line(&self) -> String {
        self.lines
            .recv_timeout(Duration::from_secs(30))
            .expect("a line from sim-krc")
    }

    fn say(&mut self, line: &str) {
        let stdin = self.child.stdin.as_mut().unwrap();
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
    }
}

#[test]
fn sim_krc_serves_its_scale_and_an_operator_resets_the_cell() {
    let _serial = serial();
    let path = short_pour();
    let start: Vec<String> = path.start().iter().map(|v| v.to_string()).collect();
    let (socket, addr) = client_socket();
    let mut child = Command::new(env!("CARGO_BIN_EXE_primo"))
        .args(["robot", "sim-krc", "--scale", "--cycle-ms", "4"])
        .args(["--port", &addr.port().to_string()])
        .args(["--start", &start.join(","), "--bottle", "0.4"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let (send, lines) = mpsc::channel();
    std::thread::spawn(move || {
        for line in stdout.lines().map_while(Result::ok) {
            if send.send(line).is_err() {
                return;
            }
        }
    });
    let mut krc = SimKrcProcess { child, lines };
    let first = krc.next_line();
    let pty = first
        .strip_prefix("primo robot sim-krc: scale served on ")
        .unwrap_or_else(|| panic!("{first}"))
        .to_string();
    let mut scale = Client::open(&pty, ClientConfig::default()).unwrap();
    let play_cfg = fast_config();
    let poured = play(&socket, &path, &play_cfg, &mut |_| {}).unwrap();
    assert_eq!(poured.ended, Ended::Completed, "{poured:?}");
    let glass = scale.stable().unwrap().grams();
    assert!(glass > 5.0, "{glass} g");
    // A typo is refused; `reset` refills the bottle, empties the glass.
    krc.say("rest");
    krc.say("reset");
    let mut line = krc.next_line();
    while line.starts_with("primo robot sim-krc: FRI measurements") {
        line = krc.next_line();
    }
    assert_eq!(
        line,
        "primo robot sim-krc: cell reset: bottle 0.4 l, glass empty"
    );
    let empty = scale.stable().unwrap().grams();
    assert!(empty.abs() <= 0.01, "{empty} g");
    // The bottle holds 0.4 l again.
    let again = play(&socket, &path, &play_cfg, &mut |_| {}).unwrap();
    assert_eq!(again.ended, Ended::Completed, "{again:?}");
    let [refilled, _] = again.load.unwrap();
    assert!(weighs(refilled, 0.4, again.load_samples[0]), "{refilled} N");
    // End of stdin changes nothing: the KRC runs on until stopped.
    drop(krc.child.stdin.take());
    std::thread::sleep(Duration::from_millis(300));
    assert!(krc.child.try_wait().unwrap().is_none(), "sim-krc exited");
    krc.child.kill().unwrap();
    let out = krc.child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(
        err.lines().collect::<Vec<_>>(),
        ["primo robot sim-krc: stdin line 1: `rest`: unknown command; expected `reset`"],
        "{err}"
    );
}
