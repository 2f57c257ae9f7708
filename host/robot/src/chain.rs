//! A serial chain of joints from a base link to a tip: any arm, taken from
//! its URDF ([`Chain::from_urdf`]) or from a standard DH table
//! ([`Chain::from_dh`]), with its joints' limits, and its forward
//! kinematics and geometric Jacobian on nalgebra. The inverse kinematics
//! is [`crate::ik`].
//!
//! Joint `i` moves its frame `Tᵢ = Tᵢ₋₁ · originᵢ · motionᵢ(qᵢ)` (a
//! rotation about, or a translation along, its axis in its own frame);
//! fixed joints fold into the next origin, and the tip (the tip link, then
//! a tool offset) into [`Chain::tip_offset`].
//!
//! ```
//! use primo_robot::chain::{Chain, Tip};
//! use primo_robot::urdf::Urdf;
//! let text = r#"<robot name="two">
//!   <link name="base"/> <link name="upper"/> <link name="hand"/>
//!   <joint name="shoulder" type="revolute">
//!     <parent link="base"/> <child link="upper"/> <axis xyz="0 0 1"/>
//!     <limit lower="-2" upper="2" velocity="1"/>
//!   </joint>
//!   <joint name="elbow" type="revolute">
//!     <parent link="upper"/> <child link="hand"/>
//!     <origin xyz="0.5 0 0"/> <axis xyz="0 0 1"/>
//!     <limit lower="-2" upper="2" velocity="1"/>
//!   </joint>
//! </robot>"#;
//! let urdf = Urdf::parse("two.urdf", text).unwrap();
//! let chain = Chain::from_urdf(&urdf, &Tip::default()).unwrap();
//! assert_eq!(chain.names(), ["shoulder", "elbow"]);
//! let tip = chain.forward(&[std::f64::consts::FRAC_PI_2, 0.0]);
//! assert!((tip.translation.vector.y - 0.5).abs() < 1e-12);
//! ```

use nalgebra::{
    Isometry3, IsometryMatrix3, Matrix3, Matrix6xX, Rotation3, SMatrix, Translation3, Unit,
    UnitQuaternion, Vector3,
};

use crate::urdf::{JointKind, MAX_DISTANCE, Urdf, UrdfError, UrdfJoint};

/// Most joints in a chain: more than any serial arm has (7 for the
/// redundant ones, 8–9 on a linear axis), few enough that a chain's
/// Jacobian stays small.
pub const MAX_JOINTS: usize = 16;

/// How a joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// About its axis, rad.
    Revolute,
    /// Along its axis, m.
    Prismatic,
}

/// A joint's limits, in its units (rad or m, per second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// Lowest position (−∞ for a continuous joint).
    pub lower: f64,
    /// Highest position (+∞ for a continuous joint).
    pub upper: f64,
    /// Fastest speed, > 0.
    pub velocity: f64,
}

/// One moving joint of a chain.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Its name (the URDF's, or `a1`… for a DH table).
    pub name: String,
    /// How it moves.
    pub motion: Motion,
    /// Its frame in the previous joint's moved frame (the base's, for the
    /// first), fixed joints between them folded in.
    pub origin: Isometry3<f64>,
    /// Its axis, in its own frame.
    pub axis: Unit<Vector3<f64>>,
    /// Its limits.
    pub limits: JointLimits,
}

/// Where a chain ends, and limits a URDF lacks.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Tip {
    /// The base link (default: the URDF's root, the link no joint moves).
    pub base: Option<String>,
    /// The tip link (default: the one leaf below the base, if only one).
    pub tip: Option<String>,
    /// A tool frame in the tip link's (default: the tip link's own).
    pub tool: Option<Isometry3<f64>>,
    /// Limits by joint name, for joints whose URDF has none, or a lab's
    /// own within the URDF's (wider ones are refused); each must name a
    /// joint of the chain.
    pub limits: Vec<(String, JointLimits)>,
}

/// A serial chain: its joints, base to tip.
#[derive(Debug, Clone, PartialEq)]
pub struct Chain {
    /// The robot's name.
    pub robot: String,
    /// The base link.
    pub base: String,
    /// The tip link.
    pub tip: String,
    joints: Vec<Joint>,
    /// The tool frame in the last joint's moved frame.
    tip_offset: Isometry3<f64>,
    /// The joints' origins and the tip offset as rotation matrices:
    /// composing matrices is cheaper than quaternions in the loops below.
    origins: Vec<IsometryMatrix3<f64>>,
    tip_matrix: IsometryMatrix3<f64>,
    /// Joints named by number (a DH table's): also found as `A1`, `j1`,
    /// `joint_1`.
    numbered: bool,
}

/// One link's standard DH parameters, `Rz(θ) · Tz(d) · Tx(a) · Rx(α)`
/// (`θ` is the joint angle, offset 0).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Link {
    /// Offset along the previous z, m.
    pub d: f64,
    /// Length along the new x, m.
    pub a: f64,
    /// Twist about the new x, rad.
    pub alpha: f64,
}

impl Chain {
    /// The chain of a standard DH table (all θ offsets 0) ending at
    /// `tool` in the last DH frame, with `limits` per joint; joints named
    /// `a1`, `a2`, … (and found by [`Chain::index`] as robot users write
    /// them: `A1`, `j1`, `joint_1`).
    pub fn from_dh(
        robot: &str,
        links: &[Link],
        tool: &Isometry3<f64>,
        limits: &[JointLimits],
    ) -> Chain {
        let twist = |l: &Link| {
            Isometry3::from_parts(
                Translation3::new(l.a, 0.0, l.d),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), l.alpha),
            )
        };
        let mut origin = Isometry3::identity();
        let mut joints = Vec::with_capacity(links.len());
        for (i, (link, limits)) in links.iter().zip(limits).enumerate() {
            joints.push(Joint {
                name: format!("a{}", i + 1),
                motion: Motion::Revolute,
                origin,
                axis: Vector3::z_axis(),
                limits: *limits,
            });
            origin = twist(link);
        }
        Chain {
            numbered: true,
            ..Chain::new(
                robot.to_string(),
                "base".into(),
                "flange".into(),
                joints,
                origin * tool,
            )
        }
    }

    /// The serial chain of `urdf` that `tip` names (see [`Tip`]); refused,
    /// naming the joint or link, if it is no serial chain primo can move
    /// safely: no moving joint, more than [`MAX_JOINTS`], a mimic,
    /// floating or planar joint on it, a link moved by two joints (a
    /// closed loop), a tip not below the base, a joint without position
    /// or velocity limits (give them in `tip.limits`), or limits that make
    /// no sense.
    pub fn from_urdf(urdf: &Urdf, tip: &Tip) -> Result<Chain, UrdfError> {
        let at_file = |what: String| urdf.error(1, 1, what);
        let link = |name: &str| urdf.links.iter().find(|l| l.name == name);
        // Each link is moved by one joint at most.
        let mut moving: Vec<(&str, &UrdfJoint)> = Vec::new();
        for joint in &urdf.joints {
            if let Some((_, first)) = moving.iter().find(|(child, _)| *child == joint.child) {
                return Err(urdf.error(
                    joint.line,
                    joint.column,
                    format!(
                        "link `{}` is the child of joints `{}` and `{}`: a closed loop, which a \
                         serial chain cannot have",
                        joint.child, first.name, joint.name
                    ),
                ));
            }
            moving.push((&joint.child, joint));
        }
        let parent_of = |name: &str| moving.iter().find(|(c, _)| *c == name).map(|(_, j)| *j);
        let base = match &tip.base {
            Some(b) => {
                link(b).ok_or_else(|| at_file(format!("base link `{b}`: no such <link>")))?;
                b.clone()
            }
            None => {
                let roots: Vec<&str> = urdf
                    .links
                    .iter()
                    .map(|l| l.name.as_str())
                    .filter(|l| parent_of(l).is_none())
                    .collect();
                match roots[..] {
                    [root] => root.to_string(),
                    [] => {
                        return Err(at_file(
                            "no root link: every link is moved by a joint".into(),
                        ));
                    }
                    _ => {
                        return Err(at_file(format!(
                            "the links form several trees (roots {}): name the base link",
                            roots.join(", ")
                        )));
                    }
                }
            }
        };
        let below = |from: &str| -> bool {
            let mut at = from;
            for _ in 0..=urdf.joints.len() {
                if at == base {
                    return true;
                }
                match parent_of(at) {
                    Some(j) => at = &j.parent,
                    None => return false,
                }
            }
            false
        };
        let tip_link = match &tip.tip {
            Some(t) => {
                link(t).ok_or_else(|| at_file(format!("tip link `{t}`: no such <link>")))?;
                if !below(t) {
                    return Err(at_file(format!(
                        "tip link `{t}` is not below the base link `{base}`"
                    )));
                }
                t.clone()
            }
            None => {
                let leaves: Vec<&str> = urdf
                    .links
                    .iter()
                    .map(|l| l.name.as_str())
                    .filter(|l| *l != base && below(l))
                    .filter(|l| !urdf.joints.iter().any(|j| j.parent == *l))
                    .collect();
                match leaves[..] {
                    [leaf] => leaf.to_string(),
                    [] => return Err(at_file(format!("no link below the base link `{base}`"))),
                    _ => {
                        return Err(at_file(format!(
                            "the chain branches below `{base}`: name the tip link, one of {}",
                            leaves.join(", ")
                        )));
                    }
                }
            }
        };
        // The joints from the tip up to the base, then in order.
        let mut path = Vec::new();
        let mut at = tip_link.as_str();
        while at != base {
            let Some(j) = parent_of(at) else {
                return Err(at_file(format!(
                    "tip link `{tip_link}` is not below the base link `{base}`"
                )));
            };
            path.push(j);
            at = &j.parent;
        }
        path.reverse();
        let mut joints = Vec::new();
        let mut origin = Isometry3::identity();
        for j in path {
            let place =
                |what: String| urdf.error(j.line, j.column, format!("joint `{}`: {what}", j.name));
            if let Some(followed) = &j.mimic {
                return Err(place(format!(
                    "it mimics `{followed}`: a mimic joint in the chain is not supported (end \
                     the chain before it)"
                )));
            }
            let motion = match j.kind {
                JointKind::Fixed => {
                    origin *= j.origin;
                    continue;
                }
                JointKind::Revolute | JointKind::Continuous => Motion::Revolute,
                JointKind::Prismatic => Motion::Prismatic,
                kind @ (JointKind::Floating | JointKind::Planar) => {
                    return Err(place(format!(
                        "a {} joint is no joint of a serial arm",
                        kind.name()
                    )));
                }
            };
            let supplied = tip
                .limits
                .iter()
                .find(|(n, _)| *n == j.name)
                .map(|(_, l)| *l);
            // The URDF's own: a continuous joint has no position limits.
            let own = j.limit.map(|l| match j.kind {
                JointKind::Continuous => (f64::NEG_INFINITY, f64::INFINITY, l.velocity),
                _ => (l.lower, l.upper, l.velocity),
            });
            let limits = match (supplied, own) {
                (Some(given), Some((lower, upper, velocity))) => {
                    let wider = given.lower < lower
                        || given.upper > upper
                        || velocity.is_some_and(|v| given.velocity > v);
                    if wider {
                        return Err(place(format!(
                            "the limits given for it, [{}, {}] at {} per s, are wider than its \
                             URDF's, [{lower}, {upper}] at {} per s: given limits may narrow \
                             a URDF's, never widen them",
                            given.lower,
                            given.upper,
                            given.velocity,
                            velocity.map_or("any".into(), |v| v.to_string())
                        )));
                    }
                    given
                }
                (Some(given), None) => given,
                (None, Some((lower, upper, Some(velocity)))) => JointLimits {
                    lower,
                    upper,
                    velocity,
                },
                (None, Some((_, _, None))) => return Err(place(no_limits("a velocity"))),
                (None, None) => return Err(place(no_limits("a <limit>"))),
            };
            check_limits(&limits, motion).map_err(place)?;
            joints.push(Joint {
                name: j.name.clone(),
                motion,
                origin: origin * j.origin,
                axis: Unit::new_normalize(j.axis),
                limits,
            });
            origin = Isometry3::identity();
        }
        if joints.is_empty() {
            return Err(at_file(format!(
                "no moving joint from `{base}` to `{tip_link}`: nothing to move"
            )));
        }
        if joints.len() > MAX_JOINTS {
            return Err(at_file(format!(
                "{} moving joints from `{base}` to `{tip_link}`: a chain has at most {MAX_JOINTS}",
                joints.len()
            )));
        }
        for (name, _) in &tip.limits {
            if !joints.iter().any(|j| &j.name == name) {
                return Err(at_file(format!(
                    "limits given for `{name}`, which is no moving joint of the chain from \
                     `{base}` to `{tip_link}`"
                )));
            }
        }
        let tool = tip.tool.unwrap_or_else(Isometry3::identity);
        if let Some(far) =
            (tool.translation.vector.iter()).find(|v| v.is_nan() || v.abs() > MAX_DISTANCE)
        {
            return Err(at_file(format!(
                "the tool frame is {far:.3e} m from the tip link `{tip_link}`: farther than \
                 {MAX_DISTANCE} m"
            )));
        }
        Ok(Chain::new(
            urdf.name.clone(),
            base,
            tip_link,
            joints,
            origin * tool,
        ))
    }

    fn new(
        robot: String,
        base: String,
        tip: String,
        joints: Vec<Joint>,
        tip_offset: Isometry3<f64>,
    ) -> Chain {
        Chain {
            robot,
            base,
            tip,
            origins: joints.iter().map(|j| matrix(&j.origin)).collect(),
            tip_matrix: matrix(&tip_offset),
            numbered: false,
            joints,
            tip_offset,
        }
    }

    /// The moving joints, base to tip.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// The tool frame in the last joint's moved frame.
    pub fn tip_offset(&self) -> &Isometry3<f64> {
        &self.tip_offset
    }

    /// How many joints move.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The joints' names, base to tip.
    pub fn names(&self) -> Vec<&str> {
        self.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// The index of the joint named `name`; a DH table's joints (`a1`,
    /// `a2`, …) also by `A1`, `j1` or `joint_1`.
    pub fn index(&self, name: &str) -> Option<usize> {
        let numbered = || {
            let digits = ["joint_", "a", "A", "j"]
                .iter()
                .find_map(|p| name.strip_prefix(p))
                .filter(|d| d.bytes().all(|b| b.is_ascii_digit()))?;
            let n: usize = digits.parse().ok()?;
            (1..=self.dof()).contains(&n).then(|| n - 1)
        };
        self.joints
            .iter()
            .position(|j| j.name == name)
            .or_else(|| self.numbered.then(numbered).flatten())
    }

    /// The joint named `name`, as [`Chain::index`] finds it.
    pub fn joint(&self, name: &str) -> Option<&Joint> {
        self.joints.get(self.index(name)?)
    }

    /// The tool frame in the base's at joint positions `q` (one per joint;
    /// missing ones taken as 0, extra ones ignored).
    pub fn forward(&self, q: &[f64]) -> Isometry3<f64> {
        quaternion(&self.forward_matrix(q))
    }

    /// [`Chain::forward`] with the rotation as a matrix.
    pub fn forward_matrix(&self, q: &[f64]) -> IsometryMatrix3<f64> {
        let mut frame = IsometryMatrix3::identity();
        for ((joint, origin), q) in self.joints.iter().zip(&self.origins).zip(padded(q)) {
            frame = frame * origin * joint.moved(*q);
        }
        frame * self.tip_matrix
    }

    /// The tool frame and the geometric Jacobian at `q`: column `i` maps
    /// joint `i`'s speed to the tool's linear velocity (rows 0–2) and
    /// angular velocity (rows 3–5), both in the base frame.
    pub fn forward_and_jacobian(&self, q: &[f64]) -> (Isometry3<f64>, Matrix6xX<f64>) {
        let (tool, jacobian) = self.forward_and_jacobian_matrix(q);
        (quaternion(&tool), jacobian)
    }

    /// [`Chain::forward_and_jacobian`] with the rotation as a matrix.
    pub fn forward_and_jacobian_matrix(&self, q: &[f64]) -> (IsometryMatrix3<f64>, Matrix6xX<f64>) {
        let mut full = Jacobian::zeros();
        let tool = self.jacobian_into(q, &mut full);
        (tool, full.columns(0, self.dof()).into_owned())
    }

    /// The tool frame at `q`, its Jacobian written into the first
    /// [`Chain::dof`] columns of `jacobian` (the rest left as they are):
    /// the inverse kinematics' loop, without allocating.
    pub(crate) fn jacobian_into(&self, q: &[f64], jacobian: &mut Jacobian) -> IsometryMatrix3<f64> {
        let mut frame = IsometryMatrix3::identity();
        // Each joint's origin and axis in the base frame, then the levers
        // to the tool once it is known.
        let mut axes = [(Vector3::zeros(), Vector3::zeros()); MAX_JOINTS];
        for (((joint, origin), q), axis) in self
            .joints
            .iter()
            .zip(&self.origins)
            .zip(padded(q))
            .zip(axes.iter_mut())
        {
            let at = frame * origin;
            *axis = (at.translation.vector, at.rotation * joint.axis.into_inner());
            frame = at * joint.moved(*q);
        }
        let tool = frame * self.tip_matrix;
        for ((mut column, joint), (origin, axis)) in
            jacobian.column_iter_mut().zip(&self.joints).zip(axes)
        {
            let (linear, angular) = match joint.motion {
                Motion::Revolute => (axis.cross(&(tool.translation.vector - origin)), axis),
                Motion::Prismatic => (axis, Vector3::zeros()),
            };
            column.fixed_rows_mut::<3>(0).copy_from(&linear);
            column.fixed_rows_mut::<3>(3).copy_from(&angular);
        }
        tool
    }

    /// The geometric Jacobian at `q` ([`Chain::forward_and_jacobian`]).
    pub fn jacobian(&self, q: &[f64]) -> Matrix6xX<f64> {
        self.forward_and_jacobian_matrix(q).1
    }
}

/// A Jacobian of up to [`MAX_JOINTS`] columns, on the stack.
pub(crate) type Jacobian = SMatrix<f64, 6, MAX_JOINTS>;

/// `q`, then zeros.
fn padded(q: &[f64]) -> impl Iterator<Item = &f64> {
    q.iter().chain(std::iter::repeat(&0.0))
}

/// A transform with its rotation as a matrix.
pub fn matrix(iso: &Isometry3<f64>) -> IsometryMatrix3<f64> {
    IsometryMatrix3::from_parts(iso.translation, iso.rotation.to_rotation_matrix())
}

/// A transform with its rotation as a unit quaternion (Shepperd's closed
/// form: the matrix is orthonormal already).
pub fn quaternion(iso: &IsometryMatrix3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        iso.translation,
        UnitQuaternion::from_rotation_matrix(&iso.rotation),
    )
}

impl Joint {
    /// The joint's own motion at position `q`.
    fn moved(&self, q: f64) -> IsometryMatrix3<f64> {
        let a = self.axis.into_inner();
        match self.motion {
            // Rodrigues: R = c·I + s·[a]× + (1 − c)·a aᵀ, for the unit axis a.
            Motion::Revolute => {
                let (s, c) = q.sin_cos();
                let t = 1.0 - c;
                let m = Matrix3::new(
                    c + t * a.x * a.x,
                    t * a.x * a.y - s * a.z,
                    t * a.x * a.z + s * a.y,
                    t * a.x * a.y + s * a.z,
                    c + t * a.y * a.y,
                    t * a.y * a.z - s * a.x,
                    t * a.x * a.z - s * a.y,
                    t * a.y * a.z + s * a.x,
                    c + t * a.z * a.z,
                );
                IsometryMatrix3::from_parts(
                    Translation3::identity(),
                    Rotation3::from_matrix_unchecked(m),
                )
            }
            Motion::Prismatic => {
                IsometryMatrix3::from_parts(Translation3::from(a * q), Rotation3::identity())
            }
        }
    }
}

fn no_limits(what: &str) -> String {
    format!(
        "it has no {what} limit, and limits are what the safety gate checks: give them in the \
         URDF, or in the task file's [movement.limits] by joint name"
    )
}

/// Limits that make sense: lower ≤ upper, a positive finite velocity.
fn check_limits(l: &JointLimits, motion: Motion) -> Result<(), String> {
    let unit = match motion {
        Motion::Revolute => "rad",
        Motion::Prismatic => "m",
    };
    if l.lower.is_nan() || l.upper.is_nan() || l.lower > l.upper {
        return Err(format!(
            "its limits lower {} and upper {} {unit}: lower must not be above upper",
            l.lower, l.upper
        ));
    }
    if !(l.velocity.is_finite() && l.velocity > 0.0) {
        return Err(format!(
            "its velocity limit {} {unit}/s must be a positive number",
            l.velocity
        ));
    }
    if motion == Motion::Prismatic && (l.lower.abs() > MAX_DISTANCE || l.upper.abs() > MAX_DISTANCE)
    {
        return Err(format!(
            "its limits lower {} and upper {} m: a prismatic joint travels at most \
             {MAX_DISTANCE} m either way",
            l.lower, l.upper
        ));
    }
    Ok(())
}
