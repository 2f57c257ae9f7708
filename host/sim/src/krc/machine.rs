//! The simulated KRC's FRI cycle, sans I/O: a [`Krc`] is told the time and
//! the datagrams that arrive, and hands out the measurements to send
//! ([`super::SimKrc`] is the UDP socket around it).
//!
//! One cycle `k` is due `k` cycles after the first (or after the clock
//! was restarted, see below):
//!
//! 1. [`Krc::poll_transmit`] opens it: the mode switches (`friStart`,
//!    `friStop`), the measurement, its noise and whether it is lost on
//!    purpose, and how late it goes out ([`KrcReport::late_sends`]);
//! 2. [`Krc::handle_datagram`] takes what arrives until the cycle's end,
//!    [`Krc::poll_timeout`]: the first command that reflects the
//!    measurement is the answer, any other is stale or malformed;
//! 3. [`Krc::handle_timeout`] closes it at its end: the answer is taken
//!    (or the cycle missed), the servo and the cell step, the report and
//!    the statistics are updated.
//!
//! A cycle opened more than a cycle after it was due (a loaded machine)
//! restarts the clock there: the KRC skips ahead rather than bursting.
//!
//! ```
//! use std::time::{Duration, Instant};
//! use primo_fri::packet::{Command, Measurement, State};
//! use primo_sim::krc::{HANDSHAKE, Krc, KrcConfig};
//! let mut krc = Krc::new(KrcConfig::new(([127, 0, 0, 1], 49938).into()))?;
//! let mut now = Instant::now();
//! // The remote echoes the commanded position on time: command mode.
//! for _ in 0..=HANDSHAKE {
//!     let m = Measurement::parse(&krc.poll_transmit(now).unwrap()).unwrap();
//!     let echo = Command::joint_position(0, &m, &m.commanded());
//!     krc.handle_datagram(now + Duration::from_micros(300), &echo.encode());
//!     now = krc.poll_timeout().unwrap();
//!     krc.handle_timeout(now);
//! }
//! assert_eq!(krc.state(), State::Command);
//! assert_eq!(krc.report().answered, HANDSHAKE as u64 + 1);
//! # Ok::<(), primo_sim::Error>(())
//! ```

use std::time::{Duration, Instant};

use primo_core::normal::StandardNormal;
use primo_core::rng::Xoshiro128PlusPlus;
use primo_fri::packet::{Command, Quality, State};
use primo_robot::{JOINTS, Pose};
use rand_core::{Rng, SeedableRng};

use super::config::{CellHandle, KrcConfig};
use super::report::{CycleRecord, KrcReport};
use super::robot::Robot;
use super::window::Window;
use crate::Error;
use crate::cell::{Cell, CellConfig};

/// Consecutive on-time echoes in monitor mode before command mode.
pub const HANDSHAKE: usize = 20;
/// Standard deviation of the noise on each force component of
/// `estExtTcpFT`, N: an LWR4's estimate from its joint torque sensors is
/// good to a few tenths of a newton at a standstill. Averaged over 0.3 s
/// of 2 ms cycles (150 samples) it is 0.025 N, the weight of 2.5 ml of
/// water.
pub const FORCE_NOISE: f64 = 0.3;
/// Standard deviation of the noise on each moment component of
/// `estExtTcpFT`, N·m (the force noise on a lever of about 16 cm).
pub const MOMENT_NOISE: f64 = 0.05;

/// The simulated KRC's state machine, sans I/O.
#[derive(Debug)]
pub struct Krc {
    cfg: KrcConfig,
    cell_cfg: CellConfig,
    cell: CellHandle,
    cell_steps: usize,
    rng: Xoshiro128PlusPlus,
    normal: StandardNormal,
    /// A measurement is lost when the draw is below this.
    drop_below: u32,
    /// Silent cycles in command mode before `friStop`.
    release: u64,
    report: KrcReport,
    window: Window,
    robot: Robot,
    /// The liquid in the bottle, kg, as of the last cycle.
    liquid: f64,
    /// The next cycle to open, or the open one.
    k: u64,
    /// The clock `(anchor, anchor_k)`: cycle `anchor_k` was due at `anchor`
    /// (the first cycle, or the one that restarted it).
    clock: Option<(Instant, u64)>,
    /// The cycle between its measurement and its end.
    open: Option<Open>,
    finished: bool,
}

/// A cycle whose measurement is out.
#[derive(Debug)]
struct Open {
    /// Time since power-on, s.
    t: f64,
    quality: Quality,
    /// The measurement was sent (not lost).
    sent: bool,
    sent_at: Instant,
    /// The cycle's end.
    deadline: Instant,
    /// The answer and its latency, s.
    answer: Option<(Command, f64)>,
}

impl Krc {
    /// Checks `cfg` and powers on: the arm at `cfg.start` in monitor
    /// mode, a fresh cell ([`KrcConfig::fresh_cell`]). Its clock starts
    /// with the first [`Krc::poll_transmit`].
    pub fn new(cfg: KrcConfig) -> Result<Krc, Error> {
        cfg.validate()?;
        let cell_cfg = cfg.cell_config();
        let cell_steps = (cfg.cycle.as_secs_f64() / cell_cfg.dt).round() as usize;
        let cell = CellHandle::new(cfg.fresh_cell()?);
        // The bottle's centre in the flange frame: where its weight acts.
        let half = Pose::translation(0.0, 0.0, 0.5 * cell_cfg.bottle.length);
        let lever = cell_cfg.grasp.then(&half).position;
        Ok(Krc {
            rng: Xoshiro128PlusPlus::seed_from_u64(cfg.seed),
            normal: StandardNormal::new(),
            drop_below: (cfg.drop * f64::from(u32::MAX)) as u32,
            release: (cfg.release_after.as_secs_f64() / cfg.cycle.as_secs_f64()).ceil() as u64,
            report: KrcReport::default(),
            window: Window::default(),
            robot: Robot::new(cfg.start, cfg.cycle.as_secs_f64(), lever),
            liquid: 0.0,
            k: 0,
            clock: None,
            open: None,
            finished: false,
            cfg,
            cell_cfg,
            cell,
            cell_steps,
        })
    }

    /// What it does.
    pub fn config(&self) -> &KrcConfig {
        &self.cfg
    }

    /// The cell it drives, shared.
    pub fn cell(&self) -> CellHandle {
        self.cell.clone()
    }

    /// The interface state (monitor or command mode).
    pub fn state(&self) -> State {
        self.robot.state
    }

    /// What has happened so far.
    pub fn report(&self) -> &KrcReport {
        &self.report
    }

    /// The report, with the measured joint position at the end.
    pub fn into_report(self) -> KrcReport {
        KrcReport {
            measured: self.robot.measured,
            ..self.report
        }
    }

    /// It has stopped by itself: `stop_after` passed, or (with `once`)
    /// the command session ended.
    pub fn is_finished(&self) -> bool {
        self.finished
    }

    /// The open cycle's measurement is out and not answered yet.
    pub fn awaiting_answer(&self) -> bool {
        self.open.as_ref().is_some_and(|o| o.answer.is_none())
    }

    /// When to call [`Krc::handle_timeout`] (the open cycle's end) or
    /// [`Krc::poll_transmit`] (when the next cycle is due); `None` before
    /// the first cycle and once finished.
    pub fn poll_timeout(&self) -> Option<Instant> {
        if self.finished {
            return None;
        }
        match &self.open {
            Some(open) => Some(open.deadline),
            None => self.due(),
        }
    }

    /// When the next cycle is due.
    fn due(&self) -> Option<Instant> {
        self.clock.map(|clock| self.start_of(self.k, clock))
    }

    /// When cycle `k` starts on the clock `(anchor, anchor_k)`: `anchor`
    /// plus `k − anchor_k` cycles.
    fn start_of(&self, k: u64, (anchor, anchor_k): (Instant, u64)) -> Instant {
        anchor + self.cfg.cycle.mul_f64((k - anchor_k) as f64)
    }

    /// Opens the next cycle if it is due by `now` (the first at once): its
    /// measurement, to be sent at `now` to the remote, unless it is lost on
    /// purpose. `None` too while a cycle is open, before the next is due,
    /// and when the KRC stops instead.
    pub fn poll_transmit(&mut self, now: Instant) -> Option<Vec<u8>> {
        if self.finished || self.open.is_some() {
            return None;
        }
        let due = match self.due() {
            Some(due) => due,
            None => {
                self.liquid = self.liquid(&self.cell.lock());
                now
            }
        };
        if now < due {
            return None;
        }
        // Fell behind (a loaded machine): skip ahead rather than burst.
        let clock = match self.clock {
            Some(clock) if now <= due + self.cfg.cycle => clock,
            _ => (now, self.k),
        };
        self.clock = Some(clock);
        let due = self.start_of(self.k, clock);
        let (cfg, k) = (self.cfg, self.k);
        let t = k as f64 * self.robot.cycle;
        let past = |d: Option<Duration>| d.is_some_and(|d| t >= d.as_secs_f64());
        if past(cfg.stop_after) {
            self.finished = true;
            return None;
        }
        let quality = if past(cfg.quality_drop_at) {
            Quality::Bad
        } else {
            self.window.quality(cfg.thresholds)
        };
        let robot = &mut self.robot;
        match robot.state {
            State::Command if k.saturating_sub(robot.last_answer) > self.release => {
                robot.switch(State::Monitor);
                self.report.left_command = Some(t);
                if cfg.once {
                    self.finished = true;
                    return None;
                }
            }
            State::Monitor
                if !cfg.monitor_only && quality >= Quality::Ok && robot.echoes >= HANDSHAKE =>
            {
                robot.switch(State::Command);
                self.report.entered_command.get_or_insert(t);
            }
            _ => {}
        }
        let seq = k as u16;
        let mut m = robot.measurement(seq, t, quality, &self.window, self.report.missed);
        let (normal, rng) = (&mut self.normal, &mut self.rng);
        let noise = std::array::from_fn(|i| {
            let sigma = if i < 3 { FORCE_NOISE } else { MOMENT_NOISE };
            sigma * f64::from(normal.sample(rng))
        });
        (m.data.est_ext_tcp_ft, m.data.est_ext_jnt_trq) = robot.external_load(self.liquid, noise);
        let sent = self.rng.next_u32() >= self.drop_below;
        self.report
            .sent_after(now.saturating_duration_since(due), cfg.cycle);
        if sent {
            self.report.sent += 1;
        } else {
            self.report.dropped += 1;
        }
        self.open = Some(Open {
            t,
            quality,
            sent,
            sent_at: now,
            deadline: self.start_of(k + 1, clock),
            answer: None,
        });
        sent.then(|| m.encode().to_vec())
    }

    /// A datagram from the remote, arrived at `now`: the open cycle's
    /// answer if it is the first command that reflects the measurement;
    /// otherwise counted as stale or malformed.
    pub fn handle_datagram(&mut self, now: Instant, datagram: &[u8]) {
        let report = &mut self.report;
        match Command::parse(datagram) {
            Ok(c) => match &mut self.open {
                Some(open)
                    if open.sent
                        && open.answer.is_none()
                        && c.head.refl_seq_count == self.k as u16 =>
                {
                    let latency = now.saturating_duration_since(open.sent_at);
                    open.answer = Some((c, latency.as_secs_f64()));
                }
                _ => report.stale += 1,
            },
            Err(e) => {
                report.malformed += 1;
                if report.rejections.len() < 10 {
                    report.rejections.push(e.to_string());
                }
            }
        }
    }

    /// Closes the open cycle once `now` is past its end: takes its answer
    /// or counts it missed, steps the servo and the cell, and records it.
    pub fn handle_timeout(&mut self, now: Instant) {
        let Some(open) = self.open.take_if(|o| now >= o.deadline) else {
            return;
        };
        let (k, robot, report) = (self.k, &mut self.robot, &mut self.report);
        self.window
            .push(open.answer.as_ref().map(|(_, latency)| *latency));
        match &open.answer {
            Some((c, _)) => {
                report.answered += 1;
                robot.take(c, k, report);
            }
            None => {
                report.missed += 1;
                robot.echoes = 0;
            }
        }
        let before = robot.measured;
        robot.servo();
        let to = robot.measured;
        self.liquid = self.step_cell(before, to);
        let (robot, report) = (&self.robot, &mut self.report);
        report.cycles += 1;
        report.command_cycles += u64::from(robot.state == State::Command);
        let excursion = (0..JOINTS)
            .map(|j| (robot.measured[j] - self.cfg.start[j]).abs())
            .fold(0.0, f64::max);
        report.max_excursion = report.max_excursion.max(excursion);
        if self.cfg.record {
            report.log.push(CycleRecord {
                t: open.t,
                state: robot.state,
                quality: open.quality,
                sent: open.sent,
                answered: open.answer.is_some(),
                target: robot.target,
                measured: robot.measured,
            });
        }
        self.k += 1;
    }

    /// Steps the cell through the cycle, the joints interpolated from
    /// `from` to `to`; the liquid left in the bottle, kg.
    fn step_cell(&self, from: [f64; JOINTS], to: [f64; JOINTS]) -> f64 {
        let mut cell = self.cell.lock();
        for i in 1..=self.cell_steps {
            let s = i as f64 / self.cell_steps as f64;
            cell.step_joints(&std::array::from_fn(|j| from[j] + (to[j] - from[j]) * s));
        }
        self.liquid(&cell)
    }

    /// The liquid in the cell's bottle, kg.
    fn liquid(&self, cell: &Cell) -> f64 {
        cell.totals().bottle * 1e-3 * self.cell_cfg.density
    }
}

#[cfg(test)]
mod tests {
    use super::super::report::LATE_SEND;
    use super::super::robot::SERVO_LAG;
    use super::super::window::RAMP;
    use super::*;
    use primo_fri::packet::Measurement;

    /// How long the remote takes to answer.
    const LATENCY: Duration = Duration::from_micros(300);

    fn config() -> KrcConfig {
        KrcConfig::new(([127, 0, 0, 1], 49938).into())
    }

    /// A remote that echoes the commanded position.
    fn echo(m: &Measurement) -> Option<Command> {
        Some(Command::joint_position(0, m, &m.commanded()))
    }

    fn silent(_: &Measurement) -> Option<Command> {
        None
    }

    /// A KRC driven in memory on a clock of its own, cycle by cycle.
    struct Bench {
        krc: Krc,
        now: Instant,
    }

    impl Bench {
        fn new(cfg: KrcConfig) -> Self {
            Bench {
                krc: Krc::new(cfg).unwrap(),
                now: Instant::now(),
            }
        }

        /// Opens the next cycle at `now`; its measurement, if sent.
        fn open(&mut self) -> Option<Measurement> {
            let datagram = self.krc.poll_transmit(self.now)?;
            Some(Measurement::parse(&datagram).unwrap())
        }

        /// Hands `c` over `after` the measurement went out.
        fn answer_after(&mut self, after: Duration, c: &Command) {
            self.krc.handle_datagram(self.now + after, &c.encode());
        }

        /// Closes the open cycle at its end (nothing once finished).
        fn close(&mut self) {
            if let Some(end) = self.krc.poll_timeout() {
                self.now = end;
                self.krc.handle_timeout(end);
            }
        }

        /// One cycle on time, answered by `remote` after [`LATENCY`] (if the
        /// measurement was sent and it answers); the measurement.
        fn cycle(
            &mut self,
            remote: impl FnOnce(&Measurement) -> Option<Command>,
        ) -> Option<Measurement> {
            let m = self.open();
            if let Some(c) = m.as_ref().and_then(remote) {
                self.answer_after(LATENCY, &c);
            }
            self.close();
            m
        }

        /// Echoes until command mode; the cycles it took.
        fn handshake(&mut self) -> u64 {
            while self.cycle(echo).unwrap().intf.state == State::Monitor {}
            self.krc.report().cycles
        }
    }

    #[test]
    fn opens_in_monitor_mode_and_commands_after_the_handshake() {
        let mut bench = Bench::new(config());
        let start = bench.now;
        let mut seen = Vec::new();
        for k in 0..=HANDSHAKE as u16 {
            let m = bench.cycle(echo).unwrap();
            assert_eq!(m.head.send_seq_count, k);
            // The last answer's sendSeqCount (the echo's is 0).
            assert_eq!(m.head.refl_seq_count, 0);
            assert_eq!(m.intf.timestamp, (f64::from(k) * 0.002) as f32);
            seen.push((m.intf.state, m.intf.quality));
        }
        // Quality ramps with the answers; command mode once it is OK and
        // the remote echoed for HANDSHAKE cycles.
        let (ramp, handshake) = (RAMP as usize, HANDSHAKE);
        assert_eq!(seen[0], (State::Monitor, Quality::Unacceptable));
        assert_eq!(seen[1], (State::Monitor, Quality::Bad));
        assert_eq!(seen[ramp], (State::Monitor, Quality::Ok));
        assert_eq!(seen[handshake - 1].0, State::Monitor);
        assert_eq!(seen[handshake], (State::Command, Quality::Perfect));
        let report = bench.krc.report();
        assert_eq!(report.entered_command, Some(HANDSHAKE as f64 * 0.002));
        assert_eq!((report.cycles, report.sent, report.answered), (21, 21, 21));
        assert_eq!((report.missed, report.stale, report.malformed), (0, 0, 0));
        assert_eq!(report.command_cycles, 1);
        // Every cycle on the clock: the next is due 21 cycles after the first.
        assert_eq!(bench.now, start + Duration::from_millis(42));
        assert_eq!(bench.krc.poll_timeout(), Some(bench.now));
    }

    #[test]
    fn monitor_only_never_commands_and_echoes_that_miss_start_over() {
        let mut cfg = config();
        cfg.monitor_only = true;
        let mut bench = Bench::new(cfg);
        for _ in 0..3 * HANDSHAKE {
            assert_eq!(bench.cycle(echo).unwrap().intf.state, State::Monitor);
        }
        assert_eq!(bench.krc.report().entered_command, None);
        // A wrong echo, or none, breaks the handshake.
        let mut bench = Bench::new(config());
        for k in 0..2 * HANDSHAKE {
            let m = bench.cycle(|m| match k % (HANDSHAKE - 1) {
                0 => Some(Command::joint_position(
                    0,
                    m,
                    &m.commanded().map(|q| q + 0.01),
                )),
                1 => None,
                _ => echo(m),
            });
            assert_eq!(m.unwrap().intf.state, State::Monitor, "cycle {k}");
        }
    }

    #[test]
    fn follows_the_commands_within_the_limits() {
        let mut bench = Bench::new(config());
        bench.handshake();
        let m = bench.open().unwrap();
        let start = m.commanded();
        // Joint 1 by 1 mrad: followed through the servo's lag.
        let mut q = start;
        q[0] += 1e-3;
        bench.answer_after(LATENCY, &Command::joint_position(1, &m, &q));
        bench.close();
        let m = bench.cycle(silent).unwrap();
        assert!((m.commanded()[0] - q[0]).abs() < 1e-6);
        let follow = 1.0 - (-0.002f64 / SERVO_LAG).exp();
        let moved = m.measured()[0] - start[0];
        assert!((moved - 1e-3 * follow).abs() < 1e-6, "{moved}");
        assert_eq!(bench.krc.report().too_fast, 0);
        // Too fast, and beyond the limits: counted, clamped to the limits.
        let m = bench.open().unwrap();
        let mut q = m.commanded();
        q[1] = 3.0;
        bench.answer_after(LATENCY, &Command::joint_position(2, &m, &q));
        bench.close();
        let m = bench.cycle(silent).unwrap();
        assert!((m.commanded()[1] - 120f64.to_radians()).abs() < 1e-6);
        let report = bench.krc.report();
        assert_eq!((report.too_fast, report.beyond_limits), (1, 1));
        assert!(report.max_excursion > 0.0);
    }

    #[test]
    fn silence_in_command_mode_releases_it_and_once_ends_the_run() {
        for once in [false, true] {
            let mut cfg = config();
            cfg.once = once;
            let mut bench = Bench::new(cfg);
            let entered = bench.handshake();
            // 0.5 s of silence at 2 ms: 250 cycles, then friStop.
            for _ in 0..250 {
                assert_eq!(bench.cycle(silent).unwrap().intf.state, State::Command);
            }
            let m = bench.open();
            let left = (entered + 250) as f64 * 0.002;
            assert_eq!(bench.krc.report().left_command, Some(left));
            assert_eq!(bench.krc.is_finished(), once);
            if once {
                assert!(m.is_none());
                assert_eq!(bench.krc.poll_timeout(), None);
                assert_eq!(bench.krc.poll_transmit(bench.now), None);
            } else {
                assert_eq!(m.unwrap().intf.state, State::Monitor);
            }
            let report = bench.krc.into_report();
            assert_eq!(report.missed, 250);
            assert_eq!(report.command_cycles, 251);
        }
    }

    #[test]
    fn stale_and_malformed_datagrams_are_counted() {
        let mut bench = Bench::new(config());
        let m = bench.open().unwrap();
        let answer = Command::joint_position(0, &m, &m.commanded());
        let mut wrong = answer;
        wrong.head.refl_seq_count = 7;
        bench.answer_after(LATENCY, &wrong);
        bench.answer_after(LATENCY, &answer);
        // A second answer in the same cycle is stale.
        bench.answer_after(2 * LATENCY, &answer);
        let now = bench.now;
        bench.krc.handle_datagram(now + LATENCY, b"not FRI");
        bench.krc.handle_datagram(now + LATENCY, &m.encode());
        bench.close();
        // An answer after its cycle is stale too.
        bench.open().unwrap();
        bench.answer_after(LATENCY, &answer);
        bench.close();
        let report = bench.krc.into_report();
        assert_eq!((report.answered, report.missed), (1, 1));
        assert_eq!((report.stale, report.malformed), (3, 2));
        assert_eq!(report.rejections.len(), 2);
    }

    #[test]
    fn the_answers_latency_is_in_the_next_measurement() {
        let mut bench = Bench::new(config());
        bench.cycle(echo);
        let m = bench.open().unwrap();
        assert!((m.intf.stat.latency - 3e-4).abs() < 1e-9);
        assert_eq!(
            (m.intf.stat.answer_rate, m.intf.stat.miss_counter),
            (1.0, 0)
        );
        // Before the cycle's end nothing closes.
        assert!(bench.krc.awaiting_answer());
        bench
            .krc
            .handle_timeout(bench.now + Duration::from_micros(1999));
        assert_eq!(bench.krc.report().cycles, 1);
        assert_eq!(bench.krc.poll_transmit(bench.now), None);
        bench.close();
        let m = bench.open().unwrap();
        assert_eq!(
            (m.intf.stat.answer_rate, m.intf.stat.miss_counter),
            (0.5, 1)
        );
    }

    #[test]
    fn lost_measurements_are_not_sent_and_go_unanswered() {
        let mut cfg = config();
        cfg.drop = 0.3;
        let mut bench = Bench::new(cfg);
        let mut lost = 0;
        for k in 0..1000u16 {
            let m = bench.open();
            lost += u64::from(m.is_none());
            // A remote that guesses the lost one's sequence is stale.
            let answer = match &m {
                Some(m) => echo(m).unwrap(),
                None => {
                    let mut guess =
                        Command::joint_position(0, &Measurement::default(), &[0.0; JOINTS]);
                    guess.head.refl_seq_count = k;
                    guess
                }
            };
            bench.answer_after(LATENCY, &answer);
            bench.close();
        }
        let report = bench.krc.into_report();
        assert_eq!(report.dropped, lost);
        assert_eq!(report.sent + report.dropped, 1000);
        assert_eq!((report.answered, report.missed), (report.sent, lost));
        assert_eq!(report.stale, lost);
        assert!((250..350).contains(&lost), "{lost}");
    }

    #[test]
    fn late_sends_are_counted_and_a_cycle_late_restarts_the_clock() {
        let mut bench = Bench::new(config());
        let start = bench.now;
        bench.cycle(echo);
        // A quarter cycle late and more: late.
        let late = Duration::from_micros(600);
        assert!(late.as_secs_f64() > 0.002 * LATE_SEND);
        bench.now += late;
        bench.open().unwrap();
        assert_eq!(
            bench.krc.poll_timeout(),
            Some(start + Duration::from_millis(4))
        );
        bench.close();
        let report = bench.krc.report();
        assert_eq!(report.late_sends, 1);
        assert!((report.max_send_delay - 6e-4).abs() < 1e-9);
        // More than a cycle late: the clock starts again there, no burst.
        bench.now += Duration::from_micros(2500);
        let opened = bench.now;
        bench.open().unwrap();
        assert_eq!(
            bench.krc.poll_timeout(),
            Some(opened + Duration::from_millis(2))
        );
        bench.close();
        assert_eq!(bench.krc.report().late_sends, 1);
        // Not yet due: nothing.
        assert_eq!(bench.krc.poll_transmit(bench.now - LATENCY), None);
    }

    #[test]
    fn stops_after_its_time_and_drops_the_quality_on_cue() {
        let mut cfg = config();
        cfg.stop_after = Some(Duration::from_millis(100));
        cfg.quality_drop_at = Some(Duration::from_millis(80));
        cfg.record = true;
        let mut bench = Bench::new(cfg);
        assert_eq!(bench.krc.poll_timeout(), None);
        let mut qualities = Vec::new();
        while let Some(m) = bench.cycle(echo) {
            qualities.push(m.intf.quality);
        }
        assert!(bench.krc.is_finished());
        assert_eq!(qualities.len(), 50);
        assert_eq!(qualities[39], Quality::Perfect);
        assert!(qualities[40..].iter().all(|q| *q == Quality::Bad));
        let report = bench.krc.into_report();
        assert_eq!(report.log.len(), 50);
        assert_eq!(report.log[40].quality, Quality::Bad);
        assert!(report.log.iter().all(|r| r.sent && r.answered));
        assert_eq!(report.measured, report.log[49].measured);
    }

    #[test]
    fn the_same_seed_and_the_same_answers_give_the_same_measurements() {
        let mut cfg = config();
        cfg.drop = 0.1;
        let (mut a, mut b) = (Bench::new(cfg), Bench::new(cfg));
        b.now = a.now + Duration::from_secs(3);
        for _ in 0..200 {
            let (ma, mb) = (a.cycle(echo), b.cycle(echo));
            assert_eq!(ma.map(|m| m.encode()), mb.map(|m| m.encode()));
        }
        cfg.seed = 2;
        let mut c = Bench::new(cfg);
        let noise = |m: Option<Measurement>| m.map(|m| m.data.est_ext_tcp_ft);
        assert_ne!(
            noise(Bench::new(config()).cycle(echo)),
            noise(c.cycle(echo))
        );
    }
}
