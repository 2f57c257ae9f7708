//! A URDF document read as it is written: its links and joints, each with
//! the line and column of its element, so that every refusal names where
//! the file is wrong. [`crate::chain::Chain::from_urdf`] takes the serial
//! chain out of it.
//!
//! The reader is a small one on `roxmltree` (a read-only XML tree that
//! keeps every node's position) rather than `urdf-rs`: primo needs only
//! the kinematic elements, wants each refusal placed at a line and column,
//! and must refuse what `urdf-rs` reads silently (a xacro file, a
//! mimic joint in the chain, a revolute joint without limits). Geometry,
//! inertia, transmissions and `<gazebo>` are not read.
//!
//! ```
//! use primo_robot::urdf::{JointKind, Urdf};
//! let text = r#"<robot name="one">
//!   <link name="base"/> <link name="arm"/>
//!   <joint name="j1" type="revolute">
//!     <parent link="base"/> <child link="arm"/>
//!     <origin xyz="0 0 0.3" rpy="0 0 0"/> <axis xyz="0 0 1"/>
//!     <limit lower="-1" upper="1" velocity="2" effort="10"/>
//!   </joint>
//! </robot>"#;
//! let urdf = Urdf::parse("one.urdf", text).unwrap();
//! assert_eq!(urdf.joints[0].kind, JointKind::Revolute);
//! assert_eq!(urdf.joints[0].line, 3);
//! let err = Urdf::parse("one.urdf", &text.replace("velocity=\"2\"", "velocity=\"fast\"")).unwrap_err();
//! assert_eq!(err.to_string(), "one.urdf:6:5: <limit> velocity `fast` is not a number");
//! ```

use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

/// Largest URDF file read, bytes: vendor descriptions are tens of kilobytes.
pub const MAX_BYTES: usize = 16 * 1024 * 1024;

/// A URDF's kinematic elements.
#[derive(Debug, Clone, PartialEq)]
pub struct Urdf {
    /// The file, as named in messages.
    pub file: String,
    /// `<robot name>`.
    pub name: String,
    /// Every `<link>`, in file order.
    pub links: Vec<UrdfLink>,
    /// Every `<joint>`, in file order.
    pub joints: Vec<UrdfJoint>,
}

/// A `<link>`.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfLink {
    /// Its name.
    pub name: String,
    /// Where its element starts (1-based).
    pub line: u32,
    /// Its column (1-based).
    pub column: u32,
}

/// A joint's `type`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// A hinge with position limits.
    Revolute,
    /// A hinge without position limits.
    Continuous,
    /// A slider with position limits.
    Prismatic,
    /// No motion.
    Fixed,
    /// Six degrees of freedom (not in a serial arm).
    Floating,
    /// Motion in a plane (not in a serial arm).
    Planar,
}

impl JointKind {
    /// As the URDF writes it.
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Revolute => "revolute",
            JointKind::Continuous => "continuous",
            JointKind::Prismatic => "prismatic",
            JointKind::Fixed => "fixed",
            JointKind::Floating => "floating",
            JointKind::Planar => "planar",
        }
    }
}

/// A `<limit>`, in the URDF's units (rad or m, per second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UrdfLimit {
    /// `lower` (URDF's default 0).
    pub lower: f64,
    /// `upper` (URDF's default 0).
    pub upper: f64,
    /// `velocity`, if given.
    pub velocity: Option<f64>,
}

/// A `<joint>`.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfJoint {
    /// Its name.
    pub name: String,
    /// Its type.
    pub kind: JointKind,
    /// `<parent link>`.
    pub parent: String,
    /// `<child link>`.
    pub child: String,
    /// `<origin>`: the child frame in the parent's, at zero motion.
    pub origin: Isometry3<f64>,
    /// `<axis xyz>` (URDF's default x), in the child frame.
    pub axis: Vector3<f64>,
    /// `<limit>`, if given.
    pub limit: Option<UrdfLimit>,
    /// `<mimic joint>`: the joint it follows, if any.
    pub mimic: Option<String>,
    /// Where its element starts (1-based).
    pub line: u32,
    /// Its column (1-based).
    pub column: u32,
}

/// A URDF that cannot be used: the file, the place, what is wrong.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {what}")]
pub struct UrdfError {
    /// The file.
    pub file: String,
    /// The line (1-based).
    pub line: u32,
    /// The column (1-based).
    pub column: u32,
    /// What is wrong, in the URDF's terms.
    pub what: String,
}

/// The xacro namespace: a xacro file is a URDF generator, not a URDF.
const XACRO: &str = "http://www.ros.org/wiki/xacro";

impl Urdf {
    /// Reads the URDF `text` (`file` names it in errors).
    pub fn parse(file: &str, text: &str) -> Result<Urdf, UrdfError> {
        let at = |line: u32, column: u32, what: String| UrdfError {
            file: file.to_string(),
            line,
            column,
            what,
        };
        if text.len() > MAX_BYTES {
            return Err(at(
                1,
                1,
                format!(
                    "{} bytes: a URDF is read up to {MAX_BYTES} bytes",
                    text.len()
                ),
            ));
        }
        let doc = roxmltree::Document::parse_with_options(
            text,
            roxmltree::ParsingOptions {
                allow_dtd: false,
                ..Default::default()
            },
        )
        .map_err(|e| {
            let pos = e.pos();
            at(pos.row, pos.col, format!("not well-formed XML: {e}"))
        })?;
        let reader = Reader { file, doc: &doc };
        let root = doc.root_element();
        if root.tag_name().name() != "robot" {
            return Err(reader.error(
                root,
                format!(
                    "the root element is <{}>, a URDF's is <robot>",
                    root.tag_name().name()
                ),
            ));
        }
        reader.refuse_xacro(root)?;
        let name = root.attribute("name").unwrap_or_default().to_string();
        let mut links = Vec::new();
        let mut joints = Vec::new();
        for node in root.children().filter(roxmltree::Node::is_element) {
            match node.tag_name().name() {
                "link" => {
                    let (line, column) = reader.place(node);
                    links.push(UrdfLink {
                        name: reader.required(node, "name")?.to_string(),
                        line,
                        column,
                    });
                }
                "joint" => joints.push(reader.joint(node)?),
                // Materials, transmissions, <gazebo>, ros2_control: not kinematics.
                _ => {}
            }
        }
        for (i, link) in links.iter().enumerate() {
            if links[..i].iter().any(|l| l.name == link.name) {
                return Err(at(
                    link.line,
                    link.column,
                    format!("a second <link> named `{}`", link.name),
                ));
            }
        }
        for (i, joint) in joints.iter().enumerate() {
            if joints[..i].iter().any(|j| j.name == joint.name) {
                return Err(at(
                    joint.line,
                    joint.column,
                    format!("a second <joint> named `{}`", joint.name),
                ));
            }
            for (role, link) in [("parent", &joint.parent), ("child", &joint.child)] {
                if !links.iter().any(|l| &l.name == link) {
                    return Err(at(
                        joint.line,
                        joint.column,
                        format!(
                            "joint `{}`: its {role} link `{link}` is no <link> of the file",
                            joint.name
                        ),
                    ));
                }
            }
        }
        Ok(Urdf {
            file: file.to_string(),
            name,
            links,
            joints,
        })
    }

    /// The error `what` at `line`:`column` of this file.
    pub fn error(&self, line: u32, column: u32, what: String) -> UrdfError {
        UrdfError {
            file: self.file.clone(),
            line,
            column,
            what,
        }
    }
}

struct Reader<'a, 'input> {
    file: &'a str,
    doc: &'a roxmltree::Document<'input>,
}

impl Reader<'_, '_> {
    fn place(&self, node: roxmltree::Node) -> (u32, u32) {
        let pos = self.doc.text_pos_at(node.range().start);
        (pos.row, pos.col)
    }

    fn error(&self, node: roxmltree::Node, what: String) -> UrdfError {
        let (line, column) = self.place(node);
        UrdfError {
            file: self.file.to_string(),
            line,
            column,
            what,
        }
    }

    /// A xacro file uses xacro elements or `${…}` expressions. The xacro
    /// namespace declared alone is no refusal: xacro's own output keeps
    /// the declaration on `<robot>` (the vendor URDFs generated by xacro,
    /// Franka's and Universal Robots' among them, have it).
    fn refuse_xacro(&self, root: roxmltree::Node) -> Result<(), UrdfError> {
        let macro_node = root.descendants().find(|n| {
            n.tag_name().namespace() == Some(XACRO)
                || n.attributes().any(|a| a.value().contains("${"))
        });
        match macro_node {
            None => Ok(()),
            Some(node) => Err(self.error(
                node,
                "this is a xacro file, not a URDF: expand it first, e.g. `xacro robot.urdf.xacro \
                 > robot.urdf` (ROS's xacro package; `pip install xacro` outside ROS)"
                    .into(),
            )),
        }
    }

    fn required<'n>(&self, node: roxmltree::Node<'n, '_>, key: &str) -> Result<&'n str, UrdfError> {
        node.attribute(key)
            .ok_or_else(|| self.error(node, format!("<{}> has no `{key}`", node.tag_name().name())))
    }

    /// The one child element `<tag>` of `node`, if any; a second is refused.
    fn child<'n, 'i>(
        &self,
        node: roxmltree::Node<'n, 'i>,
        tag: &str,
    ) -> Result<Option<roxmltree::Node<'n, 'i>>, UrdfError> {
        let mut found = node.children().filter(|n| n.has_tag_name(tag));
        let first = found.next();
        match found.next() {
            Some(second) => Err(self.error(
                second,
                format!("a second <{tag}> in <{}>", node.tag_name().name()),
            )),
            None => Ok(first),
        }
    }

    fn number(&self, node: roxmltree::Node, key: &str, text: &str) -> Result<f64, UrdfError> {
        let tag = node.tag_name().name();
        match text.trim().parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(v) => Err(self.error(node, format!("<{tag}> {key} {v} is not a finite number"))),
            Err(_) => Err(self.error(node, format!("<{tag}> {key} `{text}` is not a number"))),
        }
    }

    fn optional_number(&self, node: roxmltree::Node, key: &str) -> Result<Option<f64>, UrdfError> {
        node.attribute(key)
            .map(|text| self.number(node, key, text))
            .transpose()
    }

    /// Three numbers, as `xyz` and `rpy` are written; `default` if absent.
    fn triple(
        &self,
        node: roxmltree::Node,
        key: &str,
        default: [f64; 3],
    ) -> Result<Vector3<f64>, UrdfError> {
        let Some(text) = node.attribute(key) else {
            return Ok(Vector3::from(default));
        };
        let values = text
            .split_whitespace()
            .map(|v| self.number(node, key, v))
            .collect::<Result<Vec<f64>, _>>()?;
        match values[..] {
            [x, y, z] => Ok(Vector3::new(x, y, z)),
            _ => Err(self.error(
                node,
                format!(
                    "<{}> {key} `{text}`: expected three numbers",
                    node.tag_name().name()
                ),
            )),
        }
    }

    fn joint(&self, node: roxmltree::Node) -> Result<UrdfJoint, UrdfError> {
        let name = self.required(node, "name")?.to_string();
        let kind = match self.required(node, "type")? {
            "revolute" => JointKind::Revolute,
            "continuous" => JointKind::Continuous,
            "prismatic" => JointKind::Prismatic,
            "fixed" => JointKind::Fixed,
            "floating" => JointKind::Floating,
            "planar" => JointKind::Planar,
            other => {
                return Err(self.error(
                    node,
                    format!(
                        "joint `{name}`: type `{other}` is none of revolute, continuous, \
                         prismatic, fixed, floating, planar"
                    ),
                ));
            }
        };
        let link = |tag: &str| -> Result<String, UrdfError> {
            match self.child(node, tag)? {
                Some(n) => Ok(self.required(n, "link")?.to_string()),
                None => Err(self.error(node, format!("joint `{name}` has no <{tag}>"))),
            }
        };
        let (parent, child) = (link("parent")?, link("child")?);
        let origin = match self.child(node, "origin")? {
            Some(o) => {
                let xyz = self.triple(o, "xyz", [0.0; 3])?;
                if xyz.iter().any(|v| v.abs() > MAX_DISTANCE) {
                    let text = o.attribute("xyz").unwrap_or_default();
                    return Err(self.error(
                        o,
                        format!(
                            "joint `{name}`: <origin> xyz `{text}` is farther than \
                             {MAX_DISTANCE} m from its parent: no arm's link is (URDF lengths \
                             are in m)"
                        ),
                    ));
                }
                let rpy = self.triple(o, "rpy", [0.0; 3])?;
                origin(xyz.into(), rpy.into())
            }
            None => Isometry3::identity(),
        };
        let axis = match self.child(node, "axis")? {
            Some(a) => {
                let axis = self.triple(a, "xyz", [1.0, 0.0, 0.0])?;
                if !(1e-9..f64::INFINITY).contains(&axis.norm())
                    && matches!(
                        kind,
                        JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic
                    )
                {
                    return Err(self.error(
                        a,
                        format!("joint `{name}`: its axis has no length (or no finite one)"),
                    ));
                }
                axis
            }
            None => Vector3::x(),
        };
        let limit = match self.child(node, "limit")? {
            Some(l) => Some(UrdfLimit {
                lower: self.optional_number(l, "lower")?.unwrap_or(0.0),
                upper: self.optional_number(l, "upper")?.unwrap_or(0.0),
                velocity: self.optional_number(l, "velocity")?,
            }),
            None => None,
        };
        let mimic = match self.child(node, "mimic")? {
            Some(m) => Some(self.required(m, "joint")?.to_string()),
            None => None,
        };
        let (line, column) = self.place(node);
        Ok(UrdfJoint {
            name,
            kind,
            parent,
            child,
            origin,
            axis,
            limit,
            mimic,
            line,
            column,
        })
    }
}

/// The farthest, m, an `<origin>` or a tool frame may be from its parent
/// and a prismatic joint may travel: beyond any arm's link, near enough
/// that a chain's forward kinematics stays finite.
pub const MAX_DISTANCE: f64 = 1000.0;

/// The frame an `<origin xyz=".." rpy=".."/>` places: translated by `xyz`
/// (m), turned by roll, pitch and yaw about the fixed x, y and z axes (rad).
pub fn origin(xyz: [f64; 3], rpy: [f64; 3]) -> Isometry3<f64> {
    let [roll, pitch, yaw] = rpy;
    Isometry3::from_parts(
        Translation3::from(xyz),
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(text: &str) -> String {
        Urdf::parse("r.urdf", text).unwrap_err().to_string()
    }

    #[test]
    fn every_fault_is_placed_and_named() {
        assert!(refused("<robot><link name=\"a\"></robot>").starts_with("r.urdf:1:"));
        assert!(refused("<robo/>").contains("the root element is <robo>"));
        let xacro = "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\" name=\"r\">\n\
                     <xacro:property name=\"l\" value=\"1\"/></robot>";
        let e = refused(xacro);
        assert!(e.starts_with("r.urdf:2:1: this is a xacro file"), "{e}");
        assert!(e.contains("xacro robot.urdf.xacro > robot.urdf"), "{e}");
        // xacro's output keeps the declaration: an expanded file is read.
        let expanded = "<robot xmlns:xacro=\"http://www.ros.org/wiki/xacro\" name=\"r\">\n\
                        <link name=\"a\"/></robot>";
        assert_eq!(Urdf::parse("r.urdf", expanded).unwrap().links.len(), 1);
        let two = "<robot name=\"r\"><link name=\"a\"/>\n<link name=\"a\"/></robot>";
        assert_eq!(refused(two), "r.urdf:2:1: a second <link> named `a`");
        let dangling = "<robot name=\"r\"><link name=\"a\"/>\n<joint name=\"j\" type=\"fixed\">\
                        <parent link=\"a\"/><child link=\"b\"/></joint></robot>";
        assert_eq!(
            refused(dangling),
            "r.urdf:2:1: joint `j`: its child link `b` is no <link> of the file"
        );
        let kind = "<robot name=\"r\"><joint name=\"j\" type=\"hinge\"/></robot>";
        assert!(refused(kind).contains("type `hinge` is none of"));
        let rpy = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" \
                   type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/>\
                   <origin rpy=\"0 1\"/></joint></robot>";
        assert!(refused(rpy).contains("<origin> rpy `0 1`: expected three numbers"));
        let nan = rpy.replace("rpy=\"0 1\"", "xyz=\"0 NaN 1\"");
        assert!(refused(&nan).contains("<origin> xyz NaN is not a finite number"));
        // Far enough to overflow a chain's forward kinematics.
        let far = rpy.replace("rpy=\"0 1\"", "xyz=\"0 1e300 1\"");
        let e = refused(&far);
        assert!(
            e.contains("joint `j`: <origin> xyz `0 1e300 1` is farther than 1000 m"),
            "{e}"
        );
        let long = rpy
            .replace("<origin rpy=\"0 1\"/>", "<axis xyz=\"1e300 1e300 0\"/>")
            .replace("fixed", "continuous");
        let e = refused(&long);
        assert!(
            e.contains("its axis has no length (or no finite one)"),
            "{e}"
        );
    }

    #[test]
    fn an_origin_is_rpy_about_fixed_axes_then_xyz() {
        let text = "<robot name=\"r\"><link name=\"a\"/><link name=\"b\"/><joint name=\"j\" \
                    type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/>\
                    <origin xyz=\"1 2 3\" rpy=\"0 0 1.5707963267948966\"/>\
                    <limit lower=\"-1\" upper=\"1\" velocity=\"1\"/></joint></robot>";
        let urdf = Urdf::parse("r.urdf", text).unwrap();
        let j = &urdf.joints[0];
        let x = j.origin * nalgebra::Point3::new(1.0, 0.0, 0.0);
        assert!(
            (x - nalgebra::Point3::new(1.0, 3.0, 3.0)).norm() < 1e-12,
            "{x}"
        );
        assert_eq!(j.axis, Vector3::x());
        assert_eq!(j.limit.unwrap().velocity, Some(1.0));
    }
}
