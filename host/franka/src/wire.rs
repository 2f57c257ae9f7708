//! The FCI's messages, protocol version 10, byte for byte: little-endian,
//! packed, encoded and decoded field by field at fixed offsets.
//!
//! - The TCP command channel (port [`crate::DEFAULT_PORT`]): a
//!   [`Header`] (`command`, `command_id`, `size` of the whole message)
//!   then the command's payload; each response echoes its request's
//!   command and id, and a `Move` is answered twice (motion started,
//!   then how it ended).
//! - The UDP stream: a [`RobotState`] of [`STATE_SIZE`] bytes from the
//!   robot every millisecond, a [`RobotCommand`] of [`COMMAND_SIZE`]
//!   bytes back, carrying the `message_id` of the state it answers.
//!
//! The layouts are libfranka-common's (`service_types.h`, `rbk_types.h`)
//! with the deltas of version 10: `GetRobotModel` is command 11, `Move`
//! carries an asynchronous-motion flag and seven maximum velocities, and
//! the state's arrays are `f32` with two accelerometer arrays added.
//! [`RobotState`] holds the fields primo reads and the simulated
//! controller writes; the others encode as zeros and are skipped when
//! decoding.
//!
//! ```
//! use primo_franka::wire::{RobotState, STATE_SIZE};
//! let state = RobotState { message_id: 7, q: [0.5; 7], ..RobotState::default() };
//! let bytes = state.encode();
//! assert_eq!(bytes.len(), STATE_SIZE);
//! assert_eq!(RobotState::decode(&bytes).unwrap(), state);
//! ```

use std::fmt;

/// The protocol version primo speaks (libfranka 0.21's).
pub const VERSION: u16 = 10;
/// A TCP message's header: command, command id, size.
pub const HEADER_SIZE: usize = 12;
/// A robot state datagram.
pub const STATE_SIZE: usize = 1377;
/// A command datagram.
pub const COMMAND_SIZE: usize = 371;
/// A `Move` request's payload.
pub const MOVE_PAYLOAD: usize = 113;
/// Error and reflex flags in a state.
pub const FLAGS: usize = 41;
/// The arm's joints.
pub const JOINTS: usize = 7;
/// The largest TCP message accepted (a robot model's URDF is tens of kB).
pub const MAX_MESSAGE: usize = 4 << 20;

/// A message that cannot be what it claims to be.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum WireError {
    /// A datagram or payload of the wrong length.
    #[error("{what} of {got} bytes, expected {expected}")]
    Size {
        /// What it was meant to be.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length of that message.
        expected: usize,
    },
    /// A TCP header whose size is below the header's or absurdly large.
    #[error("a command message claiming {0} bytes")]
    BadLength(u32),
    /// A command number the protocol does not have.
    #[error("unknown command {0}")]
    UnknownCommand(u32),
    /// A robot model that is no UTF-8 text.
    #[error("the robot model is not UTF-8 text")]
    ModelNotText,
    /// A state whose joint positions or velocities are not numbers.
    #[error("a robot state with joint values that are not numbers (NaN or infinite)")]
    NotFinite,
}

/// The commands of the TCP channel (version 10 numbering).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Command {
    /// Open the session: protocol version and the client's UDP port.
    Connect,
    /// Start a motion.
    Move,
    /// Stop the motion.
    StopMove,
    /// Collision thresholds.
    SetCollisionBehavior,
    /// Joint impedance gains.
    SetJointImpedance,
    /// Cartesian impedance gains.
    SetCartesianImpedance,
    /// Guiding mode.
    SetGuidingMode,
    /// Stiffness frame.
    SetEeToK,
    /// End effector frame.
    SetNeToEe,
    /// Payload.
    SetLoad,
    /// Clear the robot's errors.
    AutomaticErrorRecovery,
    /// The robot's URDF.
    GetRobotModel,
}

impl Command {
    const ALL: [Command; 12] = [
        Command::Connect,
        Command::Move,
        Command::StopMove,
        Command::SetCollisionBehavior,
        Command::SetJointImpedance,
        Command::SetCartesianImpedance,
        Command::SetGuidingMode,
        Command::SetEeToK,
        Command::SetNeToEe,
        Command::SetLoad,
        Command::AutomaticErrorRecovery,
        Command::GetRobotModel,
    ];

    /// Its number on the wire.
    pub fn code(self) -> u32 {
        Command::ALL.iter().position(|&c| c == self).unwrap_or(0) as u32
    }

    /// The command of a number.
    pub fn from_code(code: u32) -> Result<Command, WireError> {
        Command::ALL
            .get(code as usize)
            .copied()
            .ok_or(WireError::UnknownCommand(code))
    }
}

/// A TCP message's header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Header {
    /// The command.
    pub command: Command,
    /// The request's number, echoed by its responses.
    pub id: u32,
    /// The whole message's length, header included.
    pub size: u32,
}

/// One framed TCP message: its header and payload.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    /// The header.
    pub header: Header,
    /// What follows it.
    pub payload: Vec<u8>,
}

impl Message {
    /// A message of `command` numbered `id` carrying `payload`.
    pub fn new(command: Command, id: u32, payload: Vec<u8>) -> Message {
        let size = (HEADER_SIZE + payload.len()) as u32;
        Message {
            header: Header { command, id, size },
            payload,
        }
    }

    /// Its bytes.
    pub fn encode(&self) -> Vec<u8> {
        let mut out = Vec::with_capacity(HEADER_SIZE + self.payload.len());
        out.extend_from_slice(&self.header.command.code().to_le_bytes());
        out.extend_from_slice(&self.header.id.to_le_bytes());
        out.extend_from_slice(&self.header.size.to_le_bytes());
        out.extend_from_slice(&self.payload);
        out
    }

    /// Takes the first whole message off the front of `buf`: `None` until
    /// one has arrived.
    pub fn take(buf: &mut Vec<u8>) -> Result<Option<Message>, WireError> {
        let Some(head) = buf.get(..HEADER_SIZE) else {
            return Ok(None);
        };
        let size = u32_at(head, 8);
        if (size as usize) < HEADER_SIZE || size as usize > MAX_MESSAGE {
            return Err(WireError::BadLength(size));
        }
        let command = Command::from_code(u32_at(head, 0))?;
        let id = u32_at(head, 4);
        if buf.len() < size as usize {
            return Ok(None);
        }
        let payload = buf[HEADER_SIZE..size as usize].to_vec();
        buf.drain(..size as usize);
        Ok(Some(Message {
            header: Header { command, id, size },
            payload,
        }))
    }

    /// The status byte every response starts with.
    pub fn status(&self) -> Result<u8, WireError> {
        self.payload.first().copied().ok_or(WireError::Size {
            what: "a response",
            got: 0,
            expected: 1,
        })
    }
}

/// A `Connect` request's payload: the protocol version and the UDP port
/// the client receives states on.
pub fn connect_request(udp_port: u16) -> Vec<u8> {
    let mut p = VERSION.to_le_bytes().to_vec();
    p.extend_from_slice(&udp_port.to_le_bytes());
    p
}

/// The version and UDP port of a `Connect` request's payload.
pub fn parse_connect_request(payload: &[u8]) -> Result<(u16, u16), WireError> {
    match payload {
        [v0, v1, p0, p1, ..] => Ok((
            u16::from_le_bytes([*v0, *v1]),
            u16::from_le_bytes([*p0, *p1]),
        )),
        _ => Err(WireError::Size {
            what: "a Connect request",
            got: payload.len(),
            expected: 4,
        }),
    }
}

/// A `Connect` response's payload: status, then the robot's version.
pub fn connect_response(status: ConnectStatus, version: u16) -> Vec<u8> {
    let mut p = vec![status as u8];
    p.extend_from_slice(&version.to_le_bytes());
    p
}

/// The status and version of a `Connect` response's payload.
pub fn parse_connect_response(payload: &[u8]) -> Result<(u8, u16), WireError> {
    match payload {
        [s, v0, v1, ..] => Ok((*s, u16::from_le_bytes([*v0, *v1]))),
        _ => Err(WireError::Size {
            what: "a Connect response",
            got: payload.len(),
            expected: 3,
        }),
    }
}

/// A `Move` request: joint impedance control of a joint-position motion
/// generator, the way primo moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveRequest {
    /// 0 joint impedance, 1 Cartesian impedance, 2 external controller.
    pub controller_mode: u32,
    /// 0 joint position, 1 joint velocity, 2 Cartesian position, 3
    /// Cartesian velocity, 4 none.
    pub motion_generator_mode: u32,
    /// Largest path deviation: translation m, rotation rad, elbow rad.
    pub path_deviation: [f64; 3],
    /// Largest goal pose deviation, likewise.
    pub goal_deviation: [f64; 3],
    /// libfranka's asynchronous position control.
    pub use_async_motion_generator: bool,
    /// Its joint velocity limits, rad/s (zero otherwise).
    pub maximum_velocities: [f64; JOINTS],
}

impl Default for MoveRequest {
    /// Joint impedance, joint positions, libfranka's default deviations.
    fn default() -> Self {
        let deviation = [10.0, 3.12, 2.0 * std::f64::consts::PI];
        MoveRequest {
            controller_mode: 0,
            motion_generator_mode: 0,
            path_deviation: deviation,
            goal_deviation: deviation,
            use_async_motion_generator: false,
            maximum_velocities: [0.0; JOINTS],
        }
    }
}

impl MoveRequest {
    /// Its payload.
    pub fn encode(&self) -> Vec<u8> {
        let mut p = Vec::with_capacity(MOVE_PAYLOAD);
        p.extend_from_slice(&self.controller_mode.to_le_bytes());
        p.extend_from_slice(&self.motion_generator_mode.to_le_bytes());
        for v in self.path_deviation.iter().chain(&self.goal_deviation) {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p.push(u8::from(self.use_async_motion_generator));
        for v in &self.maximum_velocities {
            p.extend_from_slice(&v.to_le_bytes());
        }
        p
    }

    /// A payload's request.
    pub fn decode(p: &[u8]) -> Result<MoveRequest, WireError> {
        if p.len() != MOVE_PAYLOAD {
            return Err(WireError::Size {
                what: "a Move request",
                got: p.len(),
                expected: MOVE_PAYLOAD,
            });
        }
        Ok(MoveRequest {
            controller_mode: u32_at(p, 0),
            motion_generator_mode: u32_at(p, 4),
            path_deviation: std::array::from_fn(|i| f64_at(p, 8 + 8 * i)),
            goal_deviation: std::array::from_fn(|i| f64_at(p, 32 + 8 * i)),
            use_async_motion_generator: p[56] != 0,
            maximum_velocities: std::array::from_fn(|i| f64_at(p, 57 + 8 * i)),
        })
    }
}

macro_rules! status_enum {
    ($(#[$doc:meta])* $name:ident { $($(#[$vdoc:meta])* $variant:ident = $code:literal => $text:literal,)* }) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        #[repr(u8)]
        pub enum $name {
            $($(#[$vdoc])* $variant = $code,)*
        }

        impl $name {
            /// The status of a byte, if the protocol has it.
            pub fn from_code(code: u8) -> Option<$name> {
                match code {
                    $($code => Some($name::$variant),)*
                    _ => None,
                }
            }
        }

        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(match self { $($name::$variant => $text,)* })
            }
        }
    };
}

status_enum!(
    /// How the robot answers `Connect`.
    ConnectStatus {
        /// Connected.
        Success = 0 => "connected",
        /// The client's protocol version is not the robot's.
        IncompatibleLibraryVersion = 1 => "incompatible protocol version",
    }
);

status_enum!(
    /// How the robot answers `Move`: first [`MoveStatus::MotionStarted`],
    /// then how the motion ended.
    MoveStatus {
        /// The motion finished.
        Success = 0 => "finished",
        /// The motion started.
        MotionStarted = 1 => "started",
        /// Another motion took its place.
        Preempted = 2 => "preempted by another motion",
        /// A safety function preempted it.
        PreemptedDueToActivatedSafetyFunctions = 3 => "preempted by a safety function",
        /// Refused: a safety function is active.
        CommandRejectedDueToActivatedSafetyFunctions = 4 => "refused: a safety function is active",
        /// Refused in the robot's present mode.
        CommandNotPossibleRejected = 5 => "refused in the robot's present mode",
        /// Refused: the start pose is singular.
        StartAtSingularPoseRejected = 6 => "refused: the start pose is singular",
        /// Refused: an argument is invalid.
        InvalidArgumentRejected = 7 => "refused: invalid argument",
        /// Aborted by a reflex.
        ReflexAborted = 8 => "aborted by a reflex",
        /// Aborted by the emergency stop.
        EmergencyAborted = 9 => "aborted by the emergency stop",
        /// Aborted for an invalid input.
        InputErrorAborted = 10 => "aborted for invalid commands",
        /// Aborted.
        Aborted = 11 => "aborted",
    }
);

status_enum!(
    /// How the robot answers `StopMove`.
    StopMoveStatus {
        /// Stopped.
        Success = 0 => "stopped",
        /// Refused in the robot's present mode.
        CommandNotPossibleRejected = 1 => "refused in the robot's present mode",
        /// Refused: a safety function is active.
        CommandRejectedDueToActivatedSafetyFunctions = 2 => "refused: a safety function is active",
        /// The emergency stop ended it.
        EmergencyAborted = 3 => "aborted by the emergency stop",
        /// A reflex ended it.
        ReflexAborted = 4 => "aborted by a reflex",
        /// Aborted.
        Aborted = 5 => "aborted",
    }
);

status_enum!(
    /// How the robot answers `AutomaticErrorRecovery`.
    RecoveryStatus {
        /// The errors are cleared.
        Success = 0 => "recovered",
        /// Refused in the robot's present mode.
        CommandNotPossibleRejected = 1 => "refused in the robot's present mode",
        /// Refused: a safety function is active.
        CommandRejectedDueToActivatedSafetyFunctions = 2 => "refused: a safety function is active",
        /// Only the operator can recover it.
        ManualErrorRecoveryRequiredRejected = 3 => "refused: needs manual error recovery",
        /// A reflex ended it.
        ReflexAborted = 4 => "aborted by a reflex",
        /// The emergency stop ended it.
        EmergencyAborted = 5 => "aborted by the emergency stop",
        /// Aborted.
        Aborted = 6 => "aborted",
    }
);

/// The names of the 41 error and reflex flags, by index (libfranka's).
pub const FLAG_NAMES: [&str; FLAGS] = [
    "joint_position_limits_violation",
    "cartesian_position_limits_violation",
    "self_collision_avoidance_violation",
    "joint_velocity_violation",
    "cartesian_velocity_violation",
    "force_control_safety_violation",
    "joint_reflex",
    "cartesian_reflex",
    "max_goal_pose_deviation_violation",
    "max_path_pose_deviation_violation",
    "cartesian_velocity_profile_safety_violation",
    "joint_position_motion_generator_start_pose_invalid",
    "joint_motion_generator_position_limits_violation",
    "joint_motion_generator_velocity_limits_violation",
    "joint_motion_generator_velocity_discontinuity",
    "joint_motion_generator_acceleration_discontinuity",
    "cartesian_position_motion_generator_start_pose_invalid",
    "cartesian_motion_generator_elbow_limit_violation",
    "cartesian_motion_generator_velocity_limits_violation",
    "cartesian_motion_generator_velocity_discontinuity",
    "cartesian_motion_generator_acceleration_discontinuity",
    "cartesian_motion_generator_elbow_sign_inconsistent",
    "cartesian_motion_generator_start_elbow_invalid",
    "force_controller_desired_force_tolerance_violation",
    "start_elbow_sign_inconsistent",
    "communication_constraints_violation",
    "power_limit_violation",
    "cartesian_motion_generator_joint_position_limits_violation",
    "cartesian_motion_generator_joint_velocity_limits_violation",
    "cartesian_motion_generator_joint_velocity_discontinuity",
    "cartesian_motion_generator_joint_acceleration_discontinuity",
    "cartesian_position_motion_generator_invalid_frame",
    "controller_torque_discontinuity",
    "joint_p2p_insufficient_torque_for_planning",
    "tau_J_range_violation",
    "instability_detected",
    "joint_move_in_wrong_direction",
    "cartesian_spline_violation",
    "joint_via_plan_limit_violation",
    "base_acceleration_initialization_timeout",
    "base_acceleration_invalid_reading",
];

/// A set of the 41 error or reflex flags, bit `i` for flag `i`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct Flags(pub u64);

impl Flags {
    /// No flag set.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// The flag of this index set.
    pub fn with(self, index: usize) -> Flags {
        if index < FLAGS {
            Flags(self.0 | 1 << index)
        } else {
            self
        }
    }

    /// The index of a flag's name.
    pub fn index(name: &str) -> Option<usize> {
        FLAG_NAMES.iter().position(|n| *n == name)
    }

    /// The names of the flags set.
    pub fn names(self) -> impl Iterator<Item = &'static str> {
        FLAG_NAMES
            .iter()
            .enumerate()
            .filter(move |(i, _)| self.0 >> i & 1 == 1)
            .map(|(_, n)| *n)
    }
}

impl fmt::Display for Flags {
    /// The names, comma-separated, or `none`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.is_empty() {
            return f.write_str("none");
        }
        for (i, name) in self.names().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(name)?;
        }
        Ok(())
    }
}

/// The robot's modes in a state.
pub mod robot_mode {
    /// Other.
    pub const OTHER: u8 = 0;
    /// Idle: ready for a motion.
    pub const IDLE: u8 = 1;
    /// Moving.
    pub const MOVE: u8 = 2;
    /// Guided by hand.
    pub const GUIDING: u8 = 3;
    /// A reflex stopped it.
    pub const REFLEX: u8 = 4;
    /// The user stop is pressed.
    pub const USER_STOPPED: u8 = 5;
    /// Recovering from errors.
    pub const AUTOMATIC_ERROR_RECOVERY: u8 = 6;
}

/// The motion generator running in a state (one above `Move`'s numbers).
pub mod motion_generator_mode {
    /// None running.
    pub const IDLE: u8 = 0;
    /// Joint positions.
    pub const JOINT_POSITION: u8 = 1;
}

const AT_Q: usize = 596;
const AT_TAU_J: usize = 512;
const AT_Q_D: usize = 624;
const AT_DQ: usize = 652;
const AT_DQ_D: usize = 680;
const AT_MOTION_MODE: usize = 1288;
const AT_CONTROLLER_MODE: usize = 1289;
const AT_ERRORS: usize = 1290;
const AT_REFLEX: usize = 1331;
const AT_ROBOT_MODE: usize = 1372;
const AT_SUCCESS_RATE: usize = 1373;
/// The six 4×4 frames at the start of a state (O_T_EE, O_T_EE_d, F_T_EE,
/// EE_T_K, F_T_NE, NE_T_EE) and O_T_EE_c, encoded as identities.
const FRAMES: [usize; 7] = [8, 72, 136, 200, 264, 328, 976];

/// The robot's state, the fields primo uses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RobotState {
    /// Counts up by one a millisecond.
    pub message_id: u64,
    /// Measured joint torques, N·m.
    pub tau_j: [f32; JOINTS],
    /// Measured joint positions, rad.
    pub q: [f32; JOINTS],
    /// Desired joint positions (the last command taken), rad.
    pub q_d: [f32; JOINTS],
    /// Measured joint velocities, rad/s.
    pub dq: [f32; JOINTS],
    /// Desired joint velocities, rad/s.
    pub dq_d: [f32; JOINTS],
    /// See [`motion_generator_mode`].
    pub motion_generator_mode: u8,
    /// 0 joint impedance, 1 Cartesian impedance, 2 external, 3 other.
    pub controller_mode: u8,
    /// The errors present.
    pub errors: Flags,
    /// What stopped the last motion.
    pub reflex_reason: Flags,
    /// See [`robot_mode`].
    pub robot_mode: u8,
    /// Share of the last cycles answered in time, 0 to 1.
    pub control_command_success_rate: f32,
}

impl RobotState {
    /// Its datagram.
    pub fn encode(&self) -> [u8; STATE_SIZE] {
        let mut b = [0u8; STATE_SIZE];
        b[..8].copy_from_slice(&self.message_id.to_le_bytes());
        for at in FRAMES {
            for i in [0, 5, 10, 15] {
                put_f32(&mut b, at + 4 * i, 1.0);
            }
        }
        for (at, v) in [
            (AT_TAU_J, &self.tau_j),
            (AT_Q, &self.q),
            (AT_Q_D, &self.q_d),
            (AT_DQ, &self.dq),
            (AT_DQ_D, &self.dq_d),
        ] {
            for (i, x) in v.iter().enumerate() {
                put_f32(&mut b, at + 4 * i, *x);
            }
        }
        b[AT_MOTION_MODE] = self.motion_generator_mode;
        b[AT_CONTROLLER_MODE] = self.controller_mode;
        for i in 0..FLAGS {
            b[AT_ERRORS + i] = (self.errors.0 >> i & 1) as u8;
            b[AT_REFLEX + i] = (self.reflex_reason.0 >> i & 1) as u8;
        }
        b[AT_ROBOT_MODE] = self.robot_mode;
        put_f32(&mut b, AT_SUCCESS_RATE, self.control_command_success_rate);
        b
    }

    /// A datagram's state.
    pub fn decode(b: &[u8]) -> Result<RobotState, WireError> {
        if b.len() != STATE_SIZE {
            return Err(WireError::Size {
                what: "a robot state",
                got: b.len(),
                expected: STATE_SIZE,
            });
        }
        let f7 = |at: usize| std::array::from_fn(|i| f32_at(b, at + 4 * i));
        let joints: [[f32; JOINTS]; 4] = [f7(AT_Q), f7(AT_Q_D), f7(AT_DQ), f7(AT_DQ_D)];
        // The joints are what a command answers: a garbled one must stop
        // the motion, not be planned from.
        if !joints.iter().flatten().all(|v| v.is_finite()) {
            return Err(WireError::NotFinite);
        }
        let flags = |at: usize| {
            Flags(
                (0..FLAGS)
                    .filter(|i| b[at + i] != 0)
                    .fold(0, |acc, i| acc | 1 << i),
            )
        };
        Ok(RobotState {
            message_id: u64_at(b, 0),
            tau_j: f7(AT_TAU_J),
            q: f7(AT_Q),
            q_d: f7(AT_Q_D),
            dq: f7(AT_DQ),
            dq_d: f7(AT_DQ_D),
            motion_generator_mode: b[AT_MOTION_MODE],
            controller_mode: b[AT_CONTROLLER_MODE],
            errors: flags(AT_ERRORS),
            reflex_reason: flags(AT_REFLEX),
            robot_mode: b[AT_ROBOT_MODE],
            control_command_success_rate: f32_at(b, AT_SUCCESS_RATE),
        })
    }

    /// The measured joint positions, rad.
    pub fn joints(&self) -> [f64; JOINTS] {
        self.q.map(f64::from)
    }
}

const AT_Q_C: usize = 8;
const AT_DQ_C: usize = 64;
const AT_FINISHED: usize = 313;
const AT_TAU_J_D: usize = 314;
const AT_TORQUE_FINISHED: usize = 370;

/// A command datagram, the fields of a joint-position motion.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RobotCommand {
    /// The `message_id` of the state it answers.
    pub message_id: u64,
    /// Commanded joint positions, rad.
    pub q_c: [f64; JOINTS],
    /// Commanded joint velocities, rad/s.
    pub dq_c: [f64; JOINTS],
    /// The motion's last command.
    pub motion_generation_finished: bool,
    /// Desired joint torques of an external controller, N·m.
    pub tau_j_d: [f64; JOINTS],
    /// The external controller's last command.
    pub torque_command_finished: bool,
}

impl RobotCommand {
    /// Its datagram.
    pub fn encode(&self) -> [u8; COMMAND_SIZE] {
        let mut b = [0u8; COMMAND_SIZE];
        b[..8].copy_from_slice(&self.message_id.to_le_bytes());
        for (at, v) in [
            (AT_Q_C, &self.q_c),
            (AT_DQ_C, &self.dq_c),
            (AT_TAU_J_D, &self.tau_j_d),
        ] {
            for (i, x) in v.iter().enumerate() {
                b[at + 8 * i..at + 8 * i + 8].copy_from_slice(&x.to_le_bytes());
            }
        }
        b[AT_FINISHED] = u8::from(self.motion_generation_finished);
        b[AT_TORQUE_FINISHED] = u8::from(self.torque_command_finished);
        b
    }

    /// A datagram's command.
    pub fn decode(b: &[u8]) -> Result<RobotCommand, WireError> {
        if b.len() != COMMAND_SIZE {
            return Err(WireError::Size {
                what: "a robot command",
                got: b.len(),
                expected: COMMAND_SIZE,
            });
        }
        let f7 = |at: usize| std::array::from_fn(|i| f64_at(b, at + 8 * i));
        Ok(RobotCommand {
            message_id: u64_at(b, 0),
            q_c: f7(AT_Q_C),
            dq_c: f7(AT_DQ_C),
            motion_generation_finished: b[AT_FINISHED] != 0,
            tau_j_d: f7(AT_TAU_J_D),
            torque_command_finished: b[AT_TORQUE_FINISHED] != 0,
        })
    }
}

fn bytes<const N: usize>(b: &[u8], at: usize) -> [u8; N] {
    std::array::from_fn(|i| b.get(at + i).copied().unwrap_or(0))
}

fn u32_at(b: &[u8], at: usize) -> u32 {
    u32::from_le_bytes(bytes(b, at))
}

fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(bytes(b, at))
}

fn f32_at(b: &[u8], at: usize) -> f32 {
    f32::from_le_bytes(bytes(b, at))
}

fn f64_at(b: &[u8], at: usize) -> f64 {
    f64::from_le_bytes(bytes(b, at))
}

fn put_f32(b: &mut [u8], at: usize, v: f32) {
    b[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn f32s() -> impl Strategy<Value = [f32; JOINTS]> {
        proptest::array::uniform7(-10.0f32..10.0)
    }

    fn f64s() -> impl Strategy<Value = [f64; JOINTS]> {
        proptest::array::uniform7(-10.0f64..10.0)
    }

    proptest! {
        #[test]
        fn states_round_trip(
            message_id: u64, tau_j in f32s(), q in f32s(), q_d in f32s(), dq in f32s(),
            dq_d in f32s(), motion_generator_mode: u8, controller_mode: u8,
            errors in 0u64..1 << FLAGS, reflex in 0u64..1 << FLAGS, robot_mode: u8,
            rate in 0.0f32..1.0,
        ) {
            let s = RobotState {
                message_id, tau_j, q, q_d, dq, dq_d, motion_generator_mode, controller_mode,
                errors: Flags(errors), reflex_reason: Flags(reflex), robot_mode,
                control_command_success_rate: rate,
            };
            prop_assert_eq!(RobotState::decode(&s.encode()).unwrap(), s);
        }

        #[test]
        fn commands_round_trip(
            message_id: u64, q_c in f64s(), dq_c in f64s(), tau in f64s(), fin: bool, tfin: bool,
        ) {
            let c = RobotCommand {
                message_id, q_c, dq_c, motion_generation_finished: fin, tau_j_d: tau,
                torque_command_finished: tfin,
            };
            prop_assert_eq!(RobotCommand::decode(&c.encode()).unwrap(), c);
        }

        #[test]
        fn moves_round_trip(
            cm in 0u32..3, mg in 0u32..5, dev in proptest::array::uniform6(0.0f64..10.0),
            asynchronous: bool, max in f64s(),
        ) {
            let m = MoveRequest {
                controller_mode: cm, motion_generator_mode: mg,
                path_deviation: [dev[0], dev[1], dev[2]], goal_deviation: [dev[3], dev[4], dev[5]],
                use_async_motion_generator: asynchronous, maximum_velocities: max,
            };
            let p = m.encode();
            prop_assert_eq!(p.len(), MOVE_PAYLOAD);
            prop_assert_eq!(MoveRequest::decode(&p).unwrap(), m);
        }

        #[test]
        fn messages_frame_in_any_split(
            payloads in proptest::collection::vec(proptest::collection::vec(any::<u8>(), 0..40), 1..5),
            split in 0usize..200,
        ) {
            let sent: Vec<Message> = payloads.into_iter().enumerate()
                .map(|(i, p)| Message::new(Command::from_code(i as u32 % 12).unwrap(), i as u32, p))
                .collect();
            let bytes: Vec<u8> = sent.iter().flat_map(Message::encode).collect();
            let split = split.min(bytes.len());
            let mut buf = bytes[..split].to_vec();
            let mut got = Vec::new();
            while let Some(m) = Message::take(&mut buf).unwrap() { got.push(m); }
            buf.extend_from_slice(&bytes[split..]);
            while let Some(m) = Message::take(&mut buf).unwrap() { got.push(m); }
            prop_assert_eq!(got, sent);
            prop_assert!(buf.is_empty());
        }
    }

    #[test]
    fn layouts_have_libfrankas_sizes_and_offsets() {
        let connect = Message::new(Command::Connect, 0, connect_request(40000)).encode();
        assert_eq!(connect.len(), 16);
        assert_eq!(&connect[12..], &[10, 0, 0x40, 0x9c]);
        let response = Message::new(
            Command::Connect,
            0,
            connect_response(ConnectStatus::Success, VERSION),
        );
        assert_eq!(response.encode().len(), 15);
        let mv = Message::new(Command::Move, 1, MoveRequest::default().encode()).encode();
        assert_eq!(mv.len(), 125);
        assert_eq!(Command::GetRobotModel.code(), 11);
        let s = RobotState {
            q: [1.0; JOINTS],
            robot_mode: robot_mode::REFLEX,
            errors: Flags::default().with(14),
            ..RobotState::default()
        }
        .encode();
        assert_eq!(f32::from_le_bytes(s[596..600].try_into().unwrap()), 1.0);
        assert_eq!((s[1290 + 14], s[1372]), (1, 4));
        let c = RobotCommand {
            motion_generation_finished: true,
            ..RobotCommand::default()
        }
        .encode();
        assert_eq!(c[313], 1);
    }

    #[test]
    fn bad_messages_are_errors() {
        let mut huge = Message::new(Command::Move, 0, vec![]).encode();
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert_eq!(
            Message::take(&mut huge),
            Err(WireError::BadLength(u32::MAX))
        );
        let mut unknown = Message::new(Command::Move, 0, vec![]).encode();
        unknown[0] = 12;
        assert_eq!(
            Message::take(&mut unknown),
            Err(WireError::UnknownCommand(12))
        );
        assert_eq!(
            RobotState::decode(&[0; 10]).unwrap_err().to_string(),
            "a robot state of 10 bytes, expected 1377"
        );
        assert_eq!(
            Flags::default().with(6).with(25).to_string(),
            "joint_reflex, communication_constraints_violation"
        );
        assert_eq!(Flags::index("tau_J_range_violation"), Some(34));
    }
}
