//! Rigid transforms and rotations in 3-D: [`Pose`] (SE(3), a rotation
//! matrix and a translation), its composition and inverse, and the
//! rotation's other forms: the rotation vector (the exponential and log
//! maps) and the unit quaternion.
//!
//! ```
//! use primo_robot::Pose;
//! // A quarter turn about z, 1 m along x.
//! let pose = Pose::from_rotation_vector([1.0, 0.0, 0.0], [0.0, 0.0, 1.5707963267948966]);
//! let back = pose.then(&pose.inverse());
//! assert!((back.position[0]).abs() < 1e-15);
//! assert!((pose.rotation_vector()[2] - 1.5707963267948966).abs() < 1e-15);
//! ```

/// A rigid transform: rotation (row-major 3×3) and translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Rotation matrix, rows.
    pub rotation: [[f64; 3]; 3],
    /// Translation in metres.
    pub position: [f64; 3],
}

impl Pose {
    /// The identity transform.
    pub const IDENTITY: Pose = Pose {
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        position: [0.0; 3],
    };

    /// A pure translation.
    pub fn translation(x: f64, y: f64, z: f64) -> Pose {
        Pose {
            position: [x, y, z],
            ..Pose::IDENTITY
        }
    }

    /// `self · other`: `other` expressed in `self`'s parent frame.
    pub fn then(&self, other: &Pose) -> Pose {
        let mut out = Pose::IDENTITY;
        for (i, row) in self.rotation.iter().enumerate() {
            out.rotation[i] =
                std::array::from_fn(|j| (0..3).map(|k| row[k] * other.rotation[k][j]).sum());
            out.position[i] =
                self.position[i] + (0..3).map(|k| row[k] * other.position[k]).sum::<f64>();
        }
        out
    }

    /// The rotation `exp([r]×)` about axis `r / |r|` by angle `|r|` (Rodrigues),
    /// placed at `position`.
    pub fn from_rotation_vector(position: [f64; 3], r: [f64; 3]) -> Pose {
        let angle2 = dot(r, r);
        // R = I + a·[r]× + b·[r]×², with [r]×² = r rᵀ − |r|²·I. The series
        // keeps a = sin θ / θ and b = (1 − cos θ) / θ² exact as θ → 0.
        let (a, b) = if angle2 < 1e-8 {
            (
                1.0 - angle2 / 6.0 + angle2 * angle2 / 120.0,
                0.5 - angle2 / 24.0 + angle2 * angle2 / 720.0,
            )
        } else {
            let angle = angle2.sqrt();
            // (1 − cos θ) / θ² as ½·sinc²(θ/2): no cancellation.
            let sinc_half = (0.5 * angle).sin() / (0.5 * angle);
            (angle.sin() / angle, 0.5 * sinc_half * sinc_half)
        };
        let skew = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
        let rotation = std::array::from_fn(|i| {
            std::array::from_fn(|j| {
                let diagonal = if i == j { 1.0 - b * angle2 } else { 0.0 };
                diagonal + a * skew[i][j] + b * r[i] * r[j]
            })
        });
        Pose { rotation, position }
    }

    /// The rotation as a vector `θ·n` (the log map), θ in [0, π]: inverse of
    /// [`Pose::from_rotation_vector`]. At exactly π both `±π·n` are valid.
    pub fn rotation_vector(&self) -> [f64; 3] {
        let r = &self.rotation;
        // sin θ · n from the skew-symmetric part, cos θ from the trace.
        let v = [
            0.5 * (r[2][1] - r[1][2]),
            0.5 * (r[0][2] - r[2][0]),
            0.5 * (r[1][0] - r[0][1]),
        ];
        let sin = norm(v);
        let cos = 0.5 * (r[0][0] + r[1][1] + r[2][2] - 1.0);
        let angle = sin.atan2(cos);
        if cos > 0.0 {
            // θ / sin θ → 1 as θ → 0.
            let scale = if angle < 1e-4 {
                1.0 + angle * angle / 6.0
            } else {
                angle / sin
            };
            v.map(|x| x * scale)
        } else {
            // Near π the skew part vanishes and its direction is noise; the
            // symmetric part (R + Rᵀ)/2 − cos θ·I = (1 − cos θ)·n nᵀ is not:
            // take its largest column, signed to agree with sin θ · n.
            let i = (0..3).fold(0, |best, k| if r[k][k] > r[best][best] { k } else { best });
            let column: [f64; 3] =
                std::array::from_fn(|j| 0.5 * (r[j][i] + r[i][j]) - if i == j { cos } else { 0.0 });
            let sign = if dot(column, v) < 0.0 { -1.0 } else { 1.0 };
            let scale = sign * angle / norm(column);
            column.map(|x| x * scale)
        }
    }

    /// The rotation of the quaternion `q = [w, x, y, z]`, normalized first
    /// (it must not be zero; `q` and `−q` are the same rotation), placed at
    /// `position`.
    pub fn from_quaternion(position: [f64; 3], q: [f64; 4]) -> Pose {
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let [w, x, y, z] = q.map(|v| v / n);
        let rotation = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        Pose { rotation, position }
    }

    /// The rotation as a unit quaternion `[w, x, y, z]`, `w ≥ 0`: inverse
    /// of [`Pose::from_quaternion`] up to the sign.
    pub fn quaternion(&self) -> [f64; 4] {
        let r = &self.rotation;
        let trace = r[0][0] + r[1][1] + r[2][2];
        // Shepperd: divide by the largest of 4w², 4x², 4y², 4z², never by a
        // small one.
        let q = if trace > r[0][0].max(r[1][1]).max(r[2][2]) {
            let s = 2.0 * (1.0 + trace).sqrt();
            [
                0.25 * s,
                (r[2][1] - r[1][2]) / s,
                (r[0][2] - r[2][0]) / s,
                (r[1][0] - r[0][1]) / s,
            ]
        } else if r[0][0] >= r[1][1] && r[0][0] >= r[2][2] {
            let s = 2.0 * (1.0 + r[0][0] - r[1][1] - r[2][2]).sqrt();
            [
                (r[2][1] - r[1][2]) / s,
                0.25 * s,
                (r[0][1] + r[1][0]) / s,
                (r[0][2] + r[2][0]) / s,
            ]
        } else if r[1][1] >= r[2][2] {
            let s = 2.0 * (1.0 + r[1][1] - r[0][0] - r[2][2]).sqrt();
            [
                (r[0][2] - r[2][0]) / s,
                (r[0][1] + r[1][0]) / s,
                0.25 * s,
                (r[1][2] + r[2][1]) / s,
            ]
        } else {
            let s = 2.0 * (1.0 + r[2][2] - r[0][0] - r[1][1]).sqrt();
            [
                (r[1][0] - r[0][1]) / s,
                (r[0][2] + r[2][0]) / s,
                (r[1][2] + r[2][1]) / s,
                0.25 * s,
            ]
        };
        let n = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
        q.map(|v| sign * v / n)
    }

    /// The frame turned by the quaternion `q` whose z axis reaches `point`
    /// at `reach`: a tool whose controlled point (a bottle's mouth) lies
    /// `reach` along its z axis. Inverse of [`Pose::point_along_z`].
    pub fn tool_at(point: [f64; 3], q: [f64; 4], reach: f64) -> Pose {
        let mut pose = Pose::from_quaternion([0.0; 3], q);
        let axis = pose.z_axis();
        pose.position = std::array::from_fn(|i| point[i] - reach * axis[i]);
        pose
    }

    /// The point `reach` along the frame's z axis.
    pub fn point_along_z(&self, reach: f64) -> [f64; 3] {
        let axis = self.z_axis();
        std::array::from_fn(|i| self.position[i] + reach * axis[i])
    }

    /// The inverse transform: `self.then(&self.inverse())` is the identity.
    pub fn inverse(&self) -> Pose {
        let rotation: [[f64; 3]; 3] =
            std::array::from_fn(|i| std::array::from_fn(|j| self.rotation[j][i]));
        let position = rotation.map(|row| -dot(row, self.position));
        Pose { rotation, position }
    }

    /// The same transform as nalgebra's.
    pub fn isometry(&self) -> nalgebra::Isometry3<f64> {
        let r = &self.rotation;
        let matrix = nalgebra::Matrix3::from_row_slice(&[
            r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
        ]);
        // Closed form (Shepperd's): the rotation is orthonormal already.
        nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::new(self.position[0], self.position[1], self.position[2]),
            nalgebra::UnitQuaternion::from_rotation_matrix(
                &nalgebra::Rotation3::from_matrix_unchecked(matrix),
            ),
        )
    }

    /// nalgebra's transform, its rotation a matrix, as a pose.
    pub fn from_matrix(iso: &nalgebra::IsometryMatrix3<f64>) -> Pose {
        let m = iso.rotation.matrix();
        let t = iso.translation.vector;
        Pose {
            rotation: std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)])),
            position: [t.x, t.y, t.z],
        }
    }

    /// The frame's z axis in the parent frame (third column).
    pub fn z_axis(&self) -> [f64; 3] {
        [
            self.rotation[0][2],
            self.rotation[1][2],
            self.rotation[2][2],
        ]
    }
}

// Small vector helpers.

pub(crate) fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub(crate) fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub(crate) fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
    }

    /// How far apart two poses are: metres, radians.
    pub(crate) fn distance(a: &Pose, b: &Pose) -> (f64, f64) {
        (
            norm(std::array::from_fn(|i| a.position[i] - b.position[i])),
            norm(a.then(&b.inverse()).rotation_vector()),
        )
    }

    #[test]
    fn rotation_vector_round_trips() {
        use std::f64::consts::PI;
        let axes = [
            [1.0, 0.0, 0.0],
            [0.0, 0.0, -1.0],
            [0.6, -0.8, 0.0],
            [0.48, 0.6, -0.64],
        ];
        let angles = [
            0.0,
            1e-12,
            1e-8,
            1e-4,
            0.3,
            1.5,
            2.9,
            PI - 1e-4,
            PI - 1e-7,
            PI - 1e-9,
        ];
        for axis in axes {
            for angle in angles {
                let r = axis.map(|x| x * angle);
                let pose = Pose::from_rotation_vector([0.1, 0.2, 0.3], r);
                let back = pose.rotation_vector();
                assert!(
                    back.iter().zip(r).all(|(x, y)| (x - y).abs() < 1e-12),
                    "{r:?} came back as {back:?}"
                );
                assert_eq!(pose.position, [0.1, 0.2, 0.3]);
            }
            // At π, ±π·n are the same rotation: compare rotations.
            let pose = Pose::from_rotation_vector([0.0; 3], axis.map(|x| x * PI));
            let back = Pose::from_rotation_vector([0.0; 3], pose.rotation_vector());
            assert!((norm(pose.rotation_vector()) - PI).abs() < 1e-12);
            assert!(distance(&pose, &back).1 < 1e-12);
        }
        // A rotation vector beyond π comes back wrapped into [0, π].
        let back = Pose::from_rotation_vector([0.0; 3], [0.0, 0.0, 4.0]).rotation_vector();
        assert!(close(back, [0.0, 0.0, 4.0 - 2.0 * PI]), "{back:?}");
        // Tiny angles keep full relative precision.
        let back = Pose::from_rotation_vector([0.0; 3], [3e-10, -4e-10, 0.0]).rotation_vector();
        assert!((back[0] - 3e-10).abs() < 1e-24 && (back[1] + 4e-10).abs() < 1e-24);
    }

    #[test]
    fn quaternions_round_trip_on_every_branch() {
        use std::f64::consts::PI;
        // Angles near 0 and π about each axis and a skew one exercise all
        // four of Shepperd's branches.
        let axes = [
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.48, 0.6, -0.64],
        ];
        for axis in axes {
            for angle in [0.0, 1e-9, 0.3, 2.0, PI - 1e-6, PI] {
                let pose = Pose::from_rotation_vector([0.0; 3], axis.map(|x| x * angle));
                let q = pose.quaternion();
                let (half, s) = (0.5 * angle, (0.5 * angle).sin());
                let expect = [half.cos(), s * axis[0], s * axis[1], s * axis[2]];
                let sign = if q.iter().zip(expect).map(|(a, b)| a * b).sum::<f64>() < 0.0 {
                    -1.0
                } else {
                    1.0
                };
                assert!(q[0] >= 0.0, "{q:?}");
                for (a, b) in q.iter().zip(expect) {
                    assert!(
                        (sign * a - b).abs() < 1e-12,
                        "{angle} about {axis:?}: {q:?}"
                    );
                }
                // −q is the same rotation; the norm does not matter.
                let back = Pose::from_quaternion([0.1, 0.2, 0.3], q.map(|v| -2.0 * v));
                assert!(distance(&back, &pose).1 < 1e-12);
                assert_eq!(back.position, [0.1, 0.2, 0.3]);
            }
        }
        let tool = Pose::tool_at([0.5, -0.1, 0.3], [0.8, 0.1, -0.5, 0.3], 0.21);
        let point = tool.point_along_z(0.21);
        assert!(close(point, [0.5, -0.1, 0.3]), "{point:?}");
    }
}
