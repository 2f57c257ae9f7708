//! The robot side's state from cycle to cycle: the arm's measured and
//! commanded joints, its servo, the measurement it reports and how it takes
//! a command.

use primo_fri::packet::{Command, Measurement, Quality, State, flags};
use primo_robot::{Arm, JOINTS, Pose};

use super::report::KrcReport;
use super::window::Window;
use crate::bottle::G;

/// Time constant of the joint position servo, s.
pub const SERVO_LAG: f64 = 0.005;

/// A pose as FRI's 3×4 row-major `[R | p]`.
fn pose_row_major(p: &Pose) -> [f32; 12] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 4, k % 4);
        let v = if j == 3 {
            p.position[i]
        } else {
            p.rotation[i][j]
        };
        v as f32
    })
}

/// The robot side's state from cycle to cycle.
#[derive(Debug)]
pub(super) struct Robot {
    arm: Arm,
    pub(super) cycle: f64,
    pub(super) state: State,
    /// Measured joint positions.
    pub(super) measured: [f64; JOINTS],
    /// Commanded joint positions.
    pub(super) target: [f64; JOINTS],
    /// The KRL program's part of the commanded position (`cmdJntPos`).
    krl: [f64; JOINTS],
    /// Consecutive on-time echoes in monitor mode.
    pub(super) echoes: usize,
    /// The cycle of the last on-time answer.
    pub(super) last_answer: u64,
    /// The last answer's `sendSeqCount`.
    refl: u16,
    /// Where the held load's weight acts, in the flange frame, m.
    lever: [f64; 3],
}

impl Robot {
    pub(super) fn new(start: [f64; JOINTS], cycle: f64, lever: [f64; 3]) -> Self {
        Robot {
            arm: Arm::new(primo_robot::Robot::lwr4()),
            cycle,
            state: State::Monitor,
            measured: start,
            target: start,
            krl: start,
            echoes: 0,
            last_answer: 0,
            refl: 0,
            lever,
        }
    }

    /// `friStart` / `friStop`: the KRL program's position becomes the
    /// commanded one, the remote's offset zero.
    pub(super) fn switch(&mut self, state: State) {
        self.state = state;
        self.krl = self.target;
    }

    pub(super) fn measurement(
        &self,
        seq: u16,
        t: f64,
        quality: Quality,
        window: &Window,
        missed: u64,
    ) -> Measurement {
        let mut m = Measurement::default();
        m.head.send_seq_count = seq;
        m.head.refl_seq_count = self.refl;
        let (latency, jitter) = window.latency();
        let rate = window.answer_rate();
        m.intf.timestamp = t as f32;
        m.intf.state = self.state;
        m.intf.quality = quality;
        m.intf.desired_msr_sample_time = self.cycle as f32;
        m.intf.desired_cmd_sample_time = self.cycle as f32;
        m.intf.stat.answer_rate = rate as f32;
        m.intf.stat.miss_rate = (1.0 - rate) as f32;
        m.intf.stat.latency = latency as f32;
        m.intf.stat.jitter = jitter as f32;
        m.intf.stat.miss_counter = missed as u32;
        m.robot.power = 0x7f;
        m.robot.control = 1;
        m.robot.temperature = [30.0; JOINTS];
        let d = &mut m.data;
        d.msr_jnt_pos = self.measured.map(|v| v as f32);
        d.msr_cart_pos = pose_row_major(&self.arm.forward(&self.measured));
        d.cmd_jnt_pos = self.krl.map(|v| v as f32);
        d.cmd_jnt_pos_fri_offset = std::array::from_fn(|j| (self.target[j] - self.krl[j]) as f32);
        d.cmd_cart_pos = pose_row_major(&self.arm.forward(&self.target));
        let jacobian = self.arm.jacobian(&self.measured);
        d.jacobian = std::array::from_fn(|k| jacobian[k / JOINTS][k % JOINTS] as f32);
        m
    }

    /// `estExtTcpFT` and `estExtJntTrq` with `mass` kg hanging at the
    /// lever: its weight and moment about the flange in the flange frame
    /// plus `noise` (force N, moment N·m), and `Jᵀ` times that wrench.
    pub(super) fn external_load(&self, mass: f64, noise: [f64; 6]) -> ([f32; 6], [f32; JOINTS]) {
        let pose = self.arm.forward(&self.measured);
        let r = pose.rotation;
        // The weight (0, 0, −mg) in the base frame, seen from the flange.
        let force: [f64; 3] = std::array::from_fn(|i| -mass * G * r[2][i]);
        let l = self.lever;
        let moment = [
            l[1] * force[2] - l[2] * force[1],
            l[2] * force[0] - l[0] * force[2],
            l[0] * force[1] - l[1] * force[0],
        ];
        let tcp: [f64; 6] =
            std::array::from_fn(|i| noise[i] + if i < 3 { force[i] } else { moment[i - 3] });
        // Back to the base frame, where the Jacobian is.
        let base: [f64; 6] = std::array::from_fn(|k| {
            let (v, i) = (&tcp[3 * (k / 3)..], k % 3);
            (0..3).map(|c| r[i][c] * v[c]).sum()
        });
        let jacobian = self.arm.jacobian(&self.measured);
        let torques =
            std::array::from_fn(|j| (0..6).map(|k| jacobian[k][j] * base[k]).sum::<f64>() as f32);
        (tcp.map(|v| v as f32), torques)
    }

    /// An on-time answer in cycle `k`: in command mode its `jntPos` is the
    /// new commanded position (clamped to the position limits; too fast or
    /// too far counted); in monitor mode it counts towards the handshake if
    /// it echoes the commanded position.
    pub(super) fn take(&mut self, c: &Command, k: u64, report: &mut KrcReport) {
        self.last_answer = k;
        self.refl = c.head.send_seq_count;
        let wanted = c.cmd.jnt_pos.map(f64::from);
        let moves = c.cmd.cmd_flags & flags::JNTPOS != 0;
        let limits = self.arm.robot();
        let velocity = limits.velocity_limits_deg.map(f64::to_radians);
        let position = limits.position_limits_deg.map(f64::to_radians);
        match self.state {
            State::Command if moves => {
                let step = |j: usize| (wanted[j] - self.target[j]).abs();
                if (0..JOINTS).any(|j| step(j) > velocity[j] * self.cycle * 1.001) {
                    report.too_fast += 1;
                }
                if (0..JOINTS).any(|j| wanted[j].abs() > position[j]) {
                    report.beyond_limits += 1;
                }
                self.target = std::array::from_fn(|j| wanted[j].clamp(-position[j], position[j]));
            }
            State::Monitor => {
                let echo = moves && (0..JOINTS).all(|j| (wanted[j] - self.target[j]).abs() < 1e-4);
                self.echoes = if echo { self.echoes + 1 } else { 0 };
            }
            _ => {}
        }
    }

    /// One cycle of the joint servo: a first-order lag of [`SERVO_LAG`]
    /// toward the commanded position, no faster than the velocity limits.
    pub(super) fn servo(&mut self) {
        let follow = 1.0 - (-self.cycle / SERVO_LAG).exp();
        for (j, limit) in self.arm.robot().velocity_limits_deg.iter().enumerate() {
            let max = limit.to_radians() * self.cycle;
            self.measured[j] += ((self.target[j] - self.measured[j]) * follow).clamp(-max, max);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_servo_lags_and_respects_the_velocity_limits() {
        let mut robot = Robot::new([0.0; JOINTS], 0.002, [0.0; 3]);
        robot.target = [1.0, 1e-3, 0.0, 0.0, 0.0, 0.0, 0.0];
        robot.servo();
        // Joint 1 at its 110 °/s limit; joint 2 a third of the way (lag).
        assert!((robot.measured[0] - 110f64.to_radians() * 0.002).abs() < 1e-12);
        let follow = 1.0 - (-0.002f64 / SERVO_LAG).exp();
        assert!((robot.measured[1] - 1e-3 * follow).abs() < 1e-15);
        for _ in 0..1000 {
            robot.servo();
        }
        assert!((0..JOINTS).all(|j| (robot.measured[j] - robot.target[j]).abs() < 1e-12));
    }

    #[test]
    fn the_external_load_is_the_weight_at_the_lever() {
        let q = crate::expert::rest_configuration(0.3);
        let lever = [0.01, -0.02, 0.16];
        let mut robot = Robot::new(q, 0.002, lever);
        robot.measured = q;
        let mass = 0.4;
        let (ft, torques) = robot.external_load(mass, [0.0; 6]);
        // The force: mg straight down, in the flange frame.
        let down = robot.arm.forward(&q).rotation[2];
        for i in 0..3 {
            assert!(
                (f64::from(ft[i]) + mass * G * down[i]).abs() < 1e-5,
                "{ft:?}"
            );
        }
        // The joint torques are the weight's virtual work: τ_j = −mg ∂z/∂q_j
        // of the point where it acts.
        let height = |q: &[f64; JOINTS]| {
            let at = robot
                .arm
                .forward(q)
                .then(&Pose::translation(lever[0], lever[1], lever[2]));
            at.position[2]
        };
        let h = 1e-6;
        for j in 0..JOINTS {
            let (mut plus, mut minus) = (q, q);
            plus[j] += h;
            minus[j] -= h;
            let expected = -mass * G * (height(&plus) - height(&minus)) / (2.0 * h);
            assert!(
                (f64::from(torques[j]) - expected).abs() < 1e-4,
                "joint {}: {} vs {expected}",
                j + 1,
                torques[j]
            );
        }
        // Noise adds in the flange frame.
        let (noisy, _) = robot.external_load(mass, [0.1, 0.0, 0.0, 0.0, 0.0, -0.2]);
        assert!((noisy[0] - ft[0] - 0.1).abs() < 1e-6 && (noisy[5] - ft[5] + 0.2).abs() < 1e-6);
    }
}
