//! The FRI datagrams of the LWR4 on a KRC2lr: little-endian,
//! IEEE f32, 4-byte aligned; field names follow KUKA's (`msrJntPos` is
//! [`RobotData::msr_jnt_pos`]). The robot sends a [`Measurement`] every
//! cycle, the remote side answers with a [`Command`].
//!
//! Parsing checks the length, the datagram id, the header's packet size
//! and the values the remote acts on (state, quality, finite joint and
//! Cartesian positions and sample times) and never panics: any bytes give
//! a value or a [`PacketError`] naming the field, its offset and the bytes.
//!
//! ```
//! use primo_fri::packet::{Measurement, State, Quality};
//! let mut m = Measurement::default();
//! m.intf.state = State::Command;
//! m.intf.quality = Quality::Perfect;
//! m.data.msr_jnt_pos[1] = 0.5;
//! let bytes = m.encode();
//! assert_eq!(bytes.len(), 916);
//! assert_eq!(Measurement::parse(&bytes), Ok(m));
//! let err = Measurement::parse(&bytes[..100]).unwrap_err();
//! assert!(err.to_string().starts_with("measurement packet of 100 bytes, expected 916"));
//! ```

use std::fmt;

use primo_robot::JOINTS;

/// Size of a measurement packet, bytes.
pub const MEASUREMENT_SIZE: usize = 916;
/// Size of a command packet, bytes.
pub const COMMAND_SIZE: usize = 376;
/// Datagram id of a measurement packet (robot → remote).
pub const MEASUREMENT_ID: u16 = 0x2006;
/// Datagram id of a command packet (remote → robot).
pub const COMMAND_ID: u16 = 0x1005;

/// `cmdFlags` bits: which parts of a command the robot uses.
pub mod flags {
    /// `jntPos`: joint position setpoint.
    pub const JNTPOS: u32 = 0x0001;
    /// `addJntTrq`: additional joint torques.
    pub const JNTTRQ: u32 = 0x0004;
    /// `jntStiffness`.
    pub const JNTSTIFF: u32 = 0x0010;
    /// `jntDamping`.
    pub const JNTDAMP: u32 = 0x0020;
    /// `cartPos`: Cartesian pose setpoint.
    pub const CARTPOS: u32 = 0x0100;
    /// `addTcpFT`: additional TCP force/torque.
    pub const TCPFT: u32 = 0x0400;
    /// `cartStiffness`.
    pub const CARTSTIFF: u32 = 0x1000;
    /// `cartDamping`.
    pub const CARTDAMP: u32 = 0x2000;
}

/// The FRI interface state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum State {
    /// FRI closed.
    #[default]
    Off = 0,
    /// Monitor mode: the robot reports, commands are not executed.
    Monitor = 1,
    /// Command mode: the robot follows the remote's commands.
    Command = 2,
}

/// The communication quality the robot measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Quality {
    /// Too poor for anything.
    #[default]
    Unacceptable = 0,
    /// Too poor to command motion.
    Bad = 1,
    /// Good enough to command motion.
    Ok = 2,
    /// Every answer on time.
    Perfect = 3,
}

impl State {
    fn from_wire(v: u16) -> Option<Self> {
        [State::Off, State::Monitor, State::Command]
            .into_iter()
            .find(|s| *s as u16 == v)
    }
}

impl Quality {
    fn from_wire(v: u16) -> Option<Self> {
        [
            Quality::Unacceptable,
            Quality::Bad,
            Quality::Ok,
            Quality::Perfect,
        ]
        .into_iter()
        .find(|q| *q as u16 == v)
    }
}

/// The 8-byte header of every FRI datagram.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Header {
    /// `sendSeqCount`: the sender's packet counter.
    pub send_seq_count: u16,
    /// `reflSeqCount`: the `sendSeqCount` of the packet answered.
    pub refl_seq_count: u16,
    /// `packetSize`: the datagram's length, bytes.
    pub packet_size: u16,
    /// `datagramId`: [`MEASUREMENT_ID`] or [`COMMAND_ID`].
    pub datagram_id: u16,
}

/// Data exchanged with the KRL program (offset 8, both directions).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct KrlData {
    /// `realData`: `$FRI_TO_REA` / `$FRI_FRM_REA`.
    pub real_data: [f32; 16],
    /// `intData`: `$FRI_TO_INT` / `$FRI_FRM_INT`.
    pub int_data: [i32; 16],
    /// `boolData`: `$FRI_TO_BOOL` / `$FRI_FRM_BOOL`, one bit each.
    pub bool_data: u16,
    /// `fill`: padding.
    pub fill: u16,
}

/// Communication statistics (offset 160).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Statistics {
    /// `answerRate`: fraction of packets answered in time.
    pub answer_rate: f32,
    /// `latency`: mean answer latency, s.
    pub latency: f32,
    /// `jitter`: variation of the latency, s.
    pub jitter: f32,
    /// `missRate`: fraction of packets not answered in time.
    pub miss_rate: f32,
    /// `missCounter`: packets not answered in time since FRI opened.
    pub miss_counter: u32,
}

/// The interface state (offset 140).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct InterfaceState {
    /// `timestamp`: the robot's clock, s.
    pub timestamp: f32,
    /// `state`.
    pub state: State,
    /// `quality`.
    pub quality: Quality,
    /// `desiredMsrSampleTime`: measurement period, s.
    pub desired_msr_sample_time: f32,
    /// `desiredCmdSampleTime`: command period, s (the FRI cycle).
    pub desired_cmd_sample_time: f32,
    /// `safetyLimits`.
    pub safety_limits: f32,
    /// `stat`.
    pub stat: Statistics,
}

/// The robot's state (offset 180).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RobotState {
    /// `power`: one bit per powered drive.
    pub power: u16,
    /// `control`: the control strategy (1 joint position, 2 Cartesian
    /// impedance, 3 joint impedance).
    pub control: u16,
    /// `error`: one bit per drive in error.
    pub error: u16,
    /// `warning`: one bit per drive with a warning.
    pub warning: u16,
    /// `temperature`: drive temperatures, °C.
    pub temperature: [f32; JOINTS],
}

impl RobotState {
    /// All seven drives are powered.
    pub fn powered(&self) -> bool {
        self.power & 0x7f == 0x7f
    }
}

/// The robot's measured and commanded data (offset 216). Poses are 3×4
/// row-major `[R | p]`, metres; joint values radians and N·m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RobotData {
    /// `msrJntPos`: measured joint positions.
    pub msr_jnt_pos: [f32; JOINTS],
    /// `msrCartPos`: measured TCP pose.
    pub msr_cart_pos: [f32; 12],
    /// `cmdJntPos`: commanded joint positions (the KRL program's part).
    pub cmd_jnt_pos: [f32; JOINTS],
    /// `cmdJntPosFriOffset`: the remote's offset on `cmdJntPos`.
    pub cmd_jnt_pos_fri_offset: [f32; JOINTS],
    /// `cmdCartPos`: commanded TCP pose.
    pub cmd_cart_pos: [f32; 12],
    /// `cmdCartPosFriOffset`: the remote's offset on `cmdCartPos`.
    pub cmd_cart_pos_fri_offset: [f32; 12],
    /// `msrJntTrq`: measured joint torques.
    pub msr_jnt_trq: [f32; JOINTS],
    /// `estExtJntTrq`: estimated external joint torques.
    pub est_ext_jnt_trq: [f32; JOINTS],
    /// `estExtTcpFT`: estimated external TCP force and torque.
    pub est_ext_tcp_ft: [f32; 6],
    /// `jacobian`: 6×7 row-major.
    pub jacobian: [f32; 42],
    /// `massMatrix`: 7×7 row-major.
    pub mass_matrix: [f32; 49],
    /// `gravity`: gravity torques.
    pub gravity: [f32; JOINTS],
}

impl Default for RobotData {
    fn default() -> Self {
        RobotData {
            msr_jnt_pos: [0.0; JOINTS],
            msr_cart_pos: [0.0; 12],
            cmd_jnt_pos: [0.0; JOINTS],
            cmd_jnt_pos_fri_offset: [0.0; JOINTS],
            cmd_cart_pos: [0.0; 12],
            cmd_cart_pos_fri_offset: [0.0; 12],
            msr_jnt_trq: [0.0; JOINTS],
            est_ext_jnt_trq: [0.0; JOINTS],
            est_ext_tcp_ft: [0.0; 6],
            jacobian: [0.0; 42],
            mass_matrix: [0.0; 49],
            gravity: [0.0; JOINTS],
        }
    }
}

/// A measurement packet, robot → remote, [`MEASUREMENT_SIZE`] bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measurement {
    /// Header (offset 0).
    pub head: Header,
    /// KRL data (offset 8).
    pub krl: KrlData,
    /// Interface state (offset 140).
    pub intf: InterfaceState,
    /// Robot state (offset 180).
    pub robot: RobotState,
    /// Robot data (offset 216).
    pub data: RobotData,
}

impl Default for Measurement {
    /// All zero but the header's size and id.
    fn default() -> Self {
        Measurement {
            head: Header {
                packet_size: MEASUREMENT_SIZE as u16,
                datagram_id: MEASUREMENT_ID,
                ..Header::default()
            },
            krl: KrlData::default(),
            intf: InterfaceState::default(),
            robot: RobotState::default(),
            data: RobotData::default(),
        }
    }
}

/// The command part of a command packet (offset 140).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CommandData {
    /// `cmdFlags`: [`flags`] of the fields to use.
    pub cmd_flags: u32,
    /// `jntPos`: joint position setpoint, rad.
    pub jnt_pos: [f32; JOINTS],
    /// `cartPos`: TCP pose setpoint, 3×4 row-major.
    pub cart_pos: [f32; 12],
    /// `addJntTrq`: additional joint torques, N·m.
    pub add_jnt_trq: [f32; JOINTS],
    /// `addTcpFT`: additional TCP force and torque.
    pub add_tcp_ft: [f32; 6],
    /// `jntStiffness`.
    pub jnt_stiffness: [f32; JOINTS],
    /// `jntDamping`.
    pub jnt_damping: [f32; JOINTS],
    /// `cartStiffness`.
    pub cart_stiffness: [f32; 6],
    /// `cartDamping`.
    pub cart_damping: [f32; 6],
}

/// A command packet, remote → robot, [`COMMAND_SIZE`] bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Command {
    /// Header (offset 0).
    pub head: Header,
    /// KRL data (offset 8).
    pub krl: KrlData,
    /// The command (offset 140).
    pub cmd: CommandData,
}

impl Default for Command {
    /// All zero but the header's size and id.
    fn default() -> Self {
        Command {
            head: Header {
                packet_size: COMMAND_SIZE as u16,
                datagram_id: COMMAND_ID,
                ..Header::default()
            },
            krl: KrlData::default(),
            cmd: CommandData::default(),
        }
    }
}

/// Why bytes are not a valid FRI packet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PacketError {
    /// The datagram's length is not the packet's.
    Size {
        /// "measurement" or "command".
        packet: &'static str,
        /// The packet's size.
        expected: usize,
        /// The datagram's length.
        found: usize,
        /// Its first bytes, hex.
        start: String,
    },
    /// `datagramId` (offset 6) is not the packet's.
    DatagramId {
        /// "measurement" or "command".
        packet: &'static str,
        /// The packet's id.
        expected: u16,
        /// The id found.
        found: u16,
    },
    /// `packetSize` (offset 4) disagrees with the datagram's length.
    PacketSize {
        /// "measurement" or "command".
        packet: &'static str,
        /// The header's value.
        header: u16,
        /// The datagram's length.
        length: usize,
    },
    /// A field's value is invalid.
    Field {
        /// "measurement" or "command".
        packet: &'static str,
        /// KUKA's field name, with the index for arrays.
        field: String,
        /// Byte offset.
        offset: usize,
        /// The field's bytes, hex.
        bytes: String,
        /// What is wrong.
        why: String,
    },
}

impl fmt::Display for PacketError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            PacketError::Size {
                packet,
                expected,
                found,
                start,
            } => write!(
                f,
                "{packet} packet of {found} bytes, expected {expected} (starts {start})"
            ),
            PacketError::DatagramId {
                packet,
                expected,
                found,
            } => write!(
                f,
                "{packet} packet: datagramId at offset 6 is {found:#06x}, expected {expected:#06x}"
            ),
            PacketError::PacketSize {
                packet,
                header,
                length,
            } => write!(
                f,
                "{packet} packet: packetSize at offset 4 says {header} bytes, the datagram has {length}"
            ),
            PacketError::Field {
                packet,
                field,
                offset,
                bytes,
                why,
            } => write!(
                f,
                "{packet} packet: {field} at offset {offset} (bytes {bytes}) {why}"
            ),
        }
    }
}

impl std::error::Error for PacketError {}

/// Bytes as space-separated hex.
fn hex(bytes: &[u8]) -> String {
    bytes
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Reads little-endian fields in order, checking what the remote acts on.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
    packet: &'static str,
}

impl<'a> Reader<'a> {
    fn error(&self, field: String, offset: usize, len: usize, why: String) -> PacketError {
        let bytes = self.bytes.get(offset..offset + len).unwrap_or_default();
        PacketError::Field {
            packet: self.packet,
            field,
            offset,
            bytes: hex(bytes),
            why,
        }
    }

    fn take<const N: usize>(&mut self, field: &str) -> Result<[u8; N], PacketError> {
        let at = self.at;
        let bytes = self
            .bytes
            .get(at..at + N)
            .and_then(|b| <[u8; N]>::try_from(b).ok())
            .ok_or_else(|| self.error(field.into(), at, N, "is past the end".into()))?;
        self.at += N;
        Ok(bytes)
    }

    fn u16(&mut self, field: &str) -> Result<u16, PacketError> {
        self.take(field).map(u16::from_le_bytes)
    }

    fn u32(&mut self, field: &str) -> Result<u32, PacketError> {
        self.take(field).map(u32::from_le_bytes)
    }

    fn f32(&mut self, field: &str) -> Result<f32, PacketError> {
        self.take(field).map(f32::from_le_bytes)
    }

    fn finite(&mut self, field: &str) -> Result<f32, PacketError> {
        let at = self.at;
        let v = self.f32(field)?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.error(field.into(), at, 4, format!("is {v}, not a finite number")))
        }
    }

    fn f32s<const N: usize>(&mut self, field: &str) -> Result<[f32; N], PacketError> {
        let mut out = [0.0; N];
        for (i, v) in out.iter_mut().enumerate() {
            *v = self.f32(&format!("{field}[{i}]"))?;
        }
        Ok(out)
    }

    fn finites<const N: usize>(&mut self, field: &str) -> Result<[f32; N], PacketError> {
        let mut out = [0.0; N];
        for (i, v) in out.iter_mut().enumerate() {
            *v = self.finite(&format!("{field}[{i}]"))?;
        }
        Ok(out)
    }

    fn i32s<const N: usize>(&mut self, field: &str) -> Result<[i32; N], PacketError> {
        let mut out = [0; N];
        for v in &mut out {
            *v = i32::from_le_bytes(self.take(field)?);
        }
        Ok(out)
    }

    /// Length, header and KRL data, shared by both packets.
    fn start(
        bytes: &'a [u8],
        packet: &'static str,
        size: usize,
        id: u16,
    ) -> Result<(Self, Header, KrlData), PacketError> {
        if bytes.len() != size {
            let shown = bytes.get(..16).unwrap_or(bytes);
            let more = if bytes.len() > shown.len() {
                " ..."
            } else {
                ""
            };
            return Err(PacketError::Size {
                packet,
                expected: size,
                found: bytes.len(),
                start: format!("{}{more}", hex(shown)),
            });
        }
        let mut r = Reader {
            bytes,
            at: 0,
            packet,
        };
        let head = Header {
            send_seq_count: r.u16("sendSeqCount")?,
            refl_seq_count: r.u16("reflSeqCount")?,
            packet_size: r.u16("packetSize")?,
            datagram_id: r.u16("datagramId")?,
        };
        if head.datagram_id != id {
            return Err(PacketError::DatagramId {
                packet,
                expected: id,
                found: head.datagram_id,
            });
        }
        if usize::from(head.packet_size) != size {
            return Err(PacketError::PacketSize {
                packet,
                header: head.packet_size,
                length: size,
            });
        }
        let krl = KrlData {
            real_data: r.f32s("realData")?,
            int_data: r.i32s("intData")?,
            bool_data: r.u16("boolData")?,
            fill: r.u16("fill")?,
        };
        Ok((r, head, krl))
    }
}

/// Writes a datagram's fields, little-endian, into `N` bytes on the stack
/// (no allocation: the FRI loop encodes one every cycle).
struct Writer<const N: usize> {
    bytes: [u8; N],
    at: usize,
}

impl<const N: usize> Writer<N> {
    fn put(&mut self, field: &[u8]) {
        // A datagram's fields fill exactly its N bytes.
        if let Some(to) = self.bytes.get_mut(self.at..self.at + field.len()) {
            to.copy_from_slice(field);
        }
        self.at += field.len();
    }

    fn u16(&mut self, v: u16) {
        self.put(&v.to_le_bytes());
    }

    fn u32(&mut self, v: u32) {
        self.put(&v.to_le_bytes());
    }

    fn f32s(&mut self, v: &[f32]) {
        for x in v {
            self.put(&x.to_le_bytes());
        }
    }

    fn start(head: &Header, krl: &KrlData) -> Self {
        let mut w = Writer {
            bytes: [0; N],
            at: 0,
        };
        for v in [
            head.send_seq_count,
            head.refl_seq_count,
            head.packet_size,
            head.datagram_id,
        ] {
            w.u16(v);
        }
        w.f32s(&krl.real_data);
        for v in krl.int_data {
            w.put(&v.to_le_bytes());
        }
        w.u16(krl.bool_data);
        w.u16(krl.fill);
        w
    }
}

impl Measurement {
    /// Parses a measurement datagram.
    pub fn parse(bytes: &[u8]) -> Result<Self, PacketError> {
        let (mut r, head, krl) =
            Reader::start(bytes, "measurement", MEASUREMENT_SIZE, MEASUREMENT_ID)?;
        let timestamp = r.f32("timestamp")?;
        let at = r.at;
        let state = r.u16("state")?;
        let state = State::from_wire(state).ok_or_else(|| {
            r.error(
                "state".into(),
                at,
                2,
                format!("is {state}, expected 0 (OFF), 1 (MON) or 2 (CMD)"),
            )
        })?;
        let at = r.at;
        let quality = r.u16("quality")?;
        let quality = Quality::from_wire(quality).ok_or_else(|| {
            r.error(
                "quality".into(),
                at,
                2,
                format!("is {quality}, expected 0 (UNACCEPTABLE), 1 (BAD), 2 (OK) or 3 (PERFECT)"),
            )
        })?;
        let intf = InterfaceState {
            timestamp,
            state,
            quality,
            desired_msr_sample_time: r.finite("desiredMsrSampleTime")?,
            desired_cmd_sample_time: r.finite("desiredCmdSampleTime")?,
            safety_limits: r.f32("safetyLimits")?,
            stat: Statistics {
                answer_rate: r.f32("answerRate")?,
                latency: r.f32("latency")?,
                jitter: r.f32("jitter")?,
                miss_rate: r.f32("missRate")?,
                miss_counter: r.u32("missCounter")?,
            },
        };
        let robot = RobotState {
            power: r.u16("power")?,
            control: r.u16("control")?,
            error: r.u16("error")?,
            warning: r.u16("warning")?,
            temperature: r.f32s("temperature")?,
        };
        let data = RobotData {
            msr_jnt_pos: r.finites("msrJntPos")?,
            msr_cart_pos: r.finites("msrCartPos")?,
            cmd_jnt_pos: r.finites("cmdJntPos")?,
            cmd_jnt_pos_fri_offset: r.finites("cmdJntPosFriOffset")?,
            cmd_cart_pos: r.finites("cmdCartPos")?,
            cmd_cart_pos_fri_offset: r.finites("cmdCartPosFriOffset")?,
            msr_jnt_trq: r.f32s("msrJntTrq")?,
            est_ext_jnt_trq: r.f32s("estExtJntTrq")?,
            est_ext_tcp_ft: r.f32s("estExtTcpFT")?,
            jacobian: r.f32s("jacobian")?,
            mass_matrix: r.f32s("massMatrix")?,
            gravity: r.f32s("gravity")?,
        };
        Ok(Measurement {
            head,
            krl,
            intf,
            robot,
            data,
        })
    }

    /// The datagram (the header as it is: [`Measurement::default`] has
    /// the right size and id).
    pub fn encode(&self) -> [u8; MEASUREMENT_SIZE] {
        let mut w = Writer::start(&self.head, &self.krl);
        let i = &self.intf;
        w.f32s(&[i.timestamp]);
        w.u16(i.state as u16);
        w.u16(i.quality as u16);
        w.f32s(&[
            i.desired_msr_sample_time,
            i.desired_cmd_sample_time,
            i.safety_limits,
            i.stat.answer_rate,
            i.stat.latency,
            i.stat.jitter,
            i.stat.miss_rate,
        ]);
        w.u32(i.stat.miss_counter);
        let r = &self.robot;
        for v in [r.power, r.control, r.error, r.warning] {
            w.u16(v);
        }
        w.f32s(&r.temperature);
        let d = &self.data;
        for part in [
            &d.msr_jnt_pos[..],
            &d.msr_cart_pos,
            &d.cmd_jnt_pos,
            &d.cmd_jnt_pos_fri_offset,
            &d.cmd_cart_pos,
            &d.cmd_cart_pos_fri_offset,
            &d.msr_jnt_trq,
            &d.est_ext_jnt_trq,
            &d.est_ext_tcp_ft,
            &d.jacobian,
            &d.mass_matrix,
            &d.gravity,
        ] {
            w.f32s(part);
        }
        w.bytes
    }

    /// The position the robot is commanded to now: `cmdJntPos +
    /// cmdJntPosFriOffset`, what a remote echoes in monitor mode.
    pub fn commanded(&self) -> [f64; JOINTS] {
        let d = &self.data;
        std::array::from_fn(|j| {
            f64::from(d.cmd_jnt_pos[j]) + f64::from(d.cmd_jnt_pos_fri_offset[j])
        })
    }

    /// The measured joint positions, rad.
    pub fn measured(&self) -> [f64; JOINTS] {
        self.data.msr_jnt_pos.map(f64::from)
    }
}

impl Command {
    /// Parses a command datagram.
    pub fn parse(bytes: &[u8]) -> Result<Self, PacketError> {
        let (mut r, head, krl) = Reader::start(bytes, "command", COMMAND_SIZE, COMMAND_ID)?;
        let cmd = CommandData {
            cmd_flags: r.u32("cmdFlags")?,
            jnt_pos: r.finites("jntPos")?,
            cart_pos: r.finites("cartPos")?,
            add_jnt_trq: r.f32s("addJntTrq")?,
            add_tcp_ft: r.f32s("addTcpFT")?,
            jnt_stiffness: r.f32s("jntStiffness")?,
            jnt_damping: r.f32s("jntDamping")?,
            cart_stiffness: r.f32s("cartStiffness")?,
            cart_damping: r.f32s("cartDamping")?,
        };
        Ok(Command { head, krl, cmd })
    }

    /// The datagram (the header as it is: [`Command::default`] has the
    /// right size and id).
    pub fn encode(&self) -> [u8; COMMAND_SIZE] {
        let mut w = Writer::start(&self.head, &self.krl);
        let c = &self.cmd;
        w.u32(c.cmd_flags);
        for part in [
            &c.jnt_pos[..],
            &c.cart_pos,
            &c.add_jnt_trq,
            &c.add_tcp_ft,
            &c.jnt_stiffness,
            &c.jnt_damping,
            &c.cart_stiffness,
            &c.cart_damping,
        ] {
            w.f32s(part);
        }
        w.bytes
    }

    /// A joint position command answering `to`: `reflSeqCount` is its
    /// `sendSeqCount`.
    pub fn joint_position(send_seq_count: u16, to: &Measurement, q: &[f64; JOINTS]) -> Self {
        Command {
            head: Header {
                send_seq_count,
                refl_seq_count: to.head.send_seq_count,
                packet_size: COMMAND_SIZE as u16,
                datagram_id: COMMAND_ID,
            },
            krl: KrlData::default(),
            cmd: CommandData {
                cmd_flags: flags::JNTPOS,
                jnt_pos: q.map(|v| v as f32),
                ..CommandData::default()
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample_measurement() -> Measurement {
        let mut m = Measurement::default();
        m.head.send_seq_count = 0x1234;
        m.head.refl_seq_count = 0x0102;
        m.krl.real_data[0] = std::f32::consts::PI;
        m.krl.int_data[15] = -2;
        m.krl.bool_data = 0x8001;
        m.intf.timestamp = 12.5;
        m.intf.state = State::Command;
        m.intf.quality = Quality::Ok;
        m.intf.desired_msr_sample_time = 0.002;
        m.intf.desired_cmd_sample_time = 0.004;
        m.intf.stat.miss_counter = 7;
        m.robot.power = 0x7f;
        m.robot.warning = 3;
        m.robot.temperature[6] = 31.5;
        m.data.msr_jnt_pos = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7];
        m.data.msr_cart_pos[11] = 1.178;
        m.data.cmd_jnt_pos[0] = -1.0;
        m.data.cmd_jnt_pos_fri_offset[6] = 0.25;
        m.data.jacobian[41] = 9.0;
        m.data.mass_matrix[0] = 2.0;
        m.data.gravity[6] = -0.5;
        m
    }

    fn f32_at(bytes: &[u8], at: usize) -> f32 {
        f32::from_le_bytes(bytes[at..at + 4].try_into().unwrap())
    }

    fn u16_at(bytes: &[u8], at: usize) -> u16 {
        u16::from_le_bytes(bytes[at..at + 2].try_into().unwrap())
    }

    #[test]
    fn byte_order_check_reads_pi() {
        assert_eq!(
            f32::from_le_bytes([0xdb, 0x0f, 0x49, 0x40]),
            std::f32::consts::PI
        );
        // The same four bytes in realData[0] of a datagram parse as π.
        let mut bytes = Measurement::default().encode();
        bytes[8..12].copy_from_slice(&[0xdb, 0x0f, 0x49, 0x40]);
        let m = Measurement::parse(&bytes).unwrap();
        assert_eq!(m.krl.real_data[0], std::f32::consts::PI);
        let bytes = sample_measurement().encode();
        assert_eq!(&bytes[8..12], &[0xdb, 0x0f, 0x49, 0x40]);
    }

    #[test]
    fn fields_sit_at_their_offsets() {
        let bytes = sample_measurement().encode();
        assert_eq!(bytes.len(), MEASUREMENT_SIZE);
        assert_eq!(u16_at(&bytes, 0), 0x1234);
        assert_eq!(u16_at(&bytes, 2), 0x0102);
        assert_eq!(u16_at(&bytes, 4), 916);
        assert_eq!(&bytes[6..8], &[0x06, 0x20]);
        assert_eq!(i32::from_le_bytes(bytes[132..136].try_into().unwrap()), -2);
        assert_eq!(u16_at(&bytes, 136), 0x8001);
        assert_eq!(f32_at(&bytes, 140), 12.5);
        assert_eq!(u16_at(&bytes, 144), 2);
        assert_eq!(u16_at(&bytes, 146), 2);
        assert_eq!(f32_at(&bytes, 148), 0.002);
        assert_eq!(f32_at(&bytes, 152), 0.004);
        assert_eq!(u32::from_le_bytes(bytes[176..180].try_into().unwrap()), 7);
        assert_eq!(u16_at(&bytes, 180), 0x7f);
        assert_eq!(u16_at(&bytes, 186), 3);
        assert_eq!(f32_at(&bytes, 212), 31.5);
        assert_eq!(f32_at(&bytes, 216), 0.1);
        assert_eq!(f32_at(&bytes, 240), 0.7);
        assert_eq!(f32_at(&bytes, 288), 1.178);
        assert_eq!(f32_at(&bytes, 292), -1.0);
        assert_eq!(f32_at(&bytes, 344), 0.25);
        assert_eq!(f32_at(&bytes, 688), 9.0);
        assert_eq!(f32_at(&bytes, 692), 2.0);
        assert_eq!(f32_at(&bytes, 912), -0.5);

        let mut c = Command::joint_position(5, &sample_measurement(), &[0.5; JOINTS]);
        c.cmd.cart_pos[0] = 1.0;
        c.cmd.add_jnt_trq[0] = 2.0;
        c.cmd.add_tcp_ft[0] = 3.0;
        c.cmd.jnt_stiffness[0] = 4.0;
        c.cmd.jnt_damping[0] = 5.0;
        c.cmd.cart_stiffness[0] = 6.0;
        c.cmd.cart_damping[5] = 7.0;
        let bytes = c.encode();
        assert_eq!(bytes.len(), COMMAND_SIZE);
        assert_eq!(u16_at(&bytes, 0), 5);
        assert_eq!(u16_at(&bytes, 2), 0x1234);
        assert_eq!(u16_at(&bytes, 4), 376);
        assert_eq!(&bytes[6..8], &[0x05, 0x10]);
        assert_eq!(u32::from_le_bytes(bytes[140..144].try_into().unwrap()), 1);
        assert_eq!(f32_at(&bytes, 144), 0.5);
        assert_eq!(f32_at(&bytes, 168), 0.5);
        for (at, v) in [
            (172, 1.0),
            (220, 2.0),
            (248, 3.0),
            (272, 4.0),
            (300, 5.0),
            (328, 6.0),
            (372, 7.0),
        ] {
            assert_eq!(f32_at(&bytes, at), v, "offset {at}");
        }
    }

    #[test]
    fn round_trips() {
        let m = sample_measurement();
        assert_eq!(Measurement::parse(&m.encode()), Ok(m));
        let c = Command::joint_position(9, &m, &[0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7]);
        assert_eq!(Command::parse(&c.encode()), Ok(c));
        assert_eq!(c.head.refl_seq_count, m.head.send_seq_count);
        assert_eq!(m.commanded()[0], -1.0);
        assert_eq!(m.commanded()[6], 0.25);
    }

    #[test]
    fn bad_datagrams_are_clear_errors() {
        let good = sample_measurement().encode();
        let err = |bytes: &[u8]| Measurement::parse(bytes).unwrap_err().to_string();
        assert_eq!(
            err(&good[..10]),
            "measurement packet of 10 bytes, expected 916 (starts 34 12 02 01 94 03 06 20 db 0f)"
        );
        assert_eq!(
            Command::parse(&good).unwrap_err().to_string(),
            "command packet of 916 bytes, expected 376 \
             (starts 34 12 02 01 94 03 06 20 db 0f 49 40 00 00 00 00 ...)"
        );
        let mut bad = good;
        bad[6] = 0x05;
        bad[7] = 0x10;
        assert_eq!(
            err(&bad),
            "measurement packet: datagramId at offset 6 is 0x1005, expected 0x2006"
        );
        let mut bad = good;
        bad[4..6].copy_from_slice(&376u16.to_le_bytes());
        assert_eq!(
            err(&bad),
            "measurement packet: packetSize at offset 4 says 376 bytes, the datagram has 916"
        );
        let mut bad = good;
        bad[228..232].copy_from_slice(&f32::NAN.to_le_bytes());
        assert_eq!(
            err(&bad),
            "measurement packet: msrJntPos[3] at offset 228 (bytes 00 00 c0 7f) is NaN, not a finite number"
        );
        let mut bad = good;
        bad[144] = 7;
        assert_eq!(
            err(&bad),
            "measurement packet: state at offset 144 (bytes 07 00) is 7, expected 0 (OFF), 1 (MON) or 2 (CMD)"
        );
        let mut bad = good;
        bad[152..156].copy_from_slice(&f32::INFINITY.to_le_bytes());
        assert!(err(&bad).contains("desiredCmdSampleTime at offset 152"));
        let mut c = Command::default().encode();
        c[144..148].copy_from_slice(&f32::NEG_INFINITY.to_le_bytes());
        assert_eq!(
            Command::parse(&c).unwrap_err().to_string(),
            "command packet: jntPos[0] at offset 144 (bytes 00 00 80 ff) is -inf, not a finite number"
        );
    }

    proptest::proptest! {
        #[test]
        fn any_bytes_parse_or_fail_cleanly(bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..1000)) {
            let _ = Measurement::parse(&bytes);
            let _ = Command::parse(&bytes);
        }

        #[test]
        fn any_valid_length_and_header_parses_or_fails_cleanly(
            body in proptest::collection::vec(proptest::num::u8::ANY, MEASUREMENT_SIZE..=MEASUREMENT_SIZE)
        ) {
            let mut bytes = body;
            bytes[4..6].copy_from_slice(&(MEASUREMENT_SIZE as u16).to_le_bytes());
            bytes[6..8].copy_from_slice(&MEASUREMENT_ID.to_le_bytes());
            bytes[144] %= 3;
            bytes[145] = 0;
            bytes[146] %= 4;
            bytes[147] = 0;
            if let Ok(m) = Measurement::parse(&bytes) {
                // What parses encodes back to the same bytes.
                proptest::prop_assert_eq!(m.encode().to_vec(), bytes);
            }
        }
    }
}
