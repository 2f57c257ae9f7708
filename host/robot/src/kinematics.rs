//! The built-in 7-joint arm described by a [`Robot`] (standard DH, all θ
//! offsets 0), holding a tool, on its [`Chain`]: forward kinematics, the
//! geometric Jacobian, and inverse kinematics ([`crate::ik`]) whose
//! null-space pull toward a rest configuration picks the elbow of this
//! redundant arm, in the fixed-size terms of the pour's code.
//!
//! ```
//! use primo_robot::{Arm, JOINTS, Robot};
//! let arm = Arm::new(Robot::lwr4());
//! // Stretched out: the flange is straight above the base.
//! let pose = arm.forward(&[0.0; JOINTS]);
//! assert!((pose.position[2] - 1.178).abs() < 1e-12);
//! // Back from the pose to joint angles, elbow pulled toward `rest`.
//! let q = [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5];
//! let rest = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
//! let solution = arm.inverse(&arm.forward(&q), &q, &rest).unwrap();
//! let reached = arm.forward(&solution).position;
//! assert!((0..3).all(|i| (reached[i] - arm.forward(&q).position[i]).abs() < 1e-9));
//! ```

use crate::chain::Chain;
use crate::ik::{IkError, IkOptions};
use crate::pose::Pose;
use crate::{JOINTS, Robot};

/// A robot with a tool transform from its last joint frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Arm {
    robot: Robot,
    tool: Pose,
    /// The robot's chain, ending at the tool.
    chain: Chain,
}

impl Arm {
    /// The bare arm, tool frame at the flange.
    pub fn new(robot: Robot) -> Self {
        Arm::holding(robot, Pose::translation(0.0, 0.0, robot.flange))
    }

    /// The arm holding a tool: `grasp` is flange → tool frame.
    pub fn with_tool(robot: Robot, grasp: &Pose) -> Self {
        Arm::holding(robot, Pose::translation(0.0, 0.0, robot.flange).then(grasp))
    }

    /// `robot` with `tool` as its last joint frame → tool frame.
    fn holding(robot: Robot, tool: Pose) -> Self {
        Arm {
            robot,
            tool,
            chain: robot.chain_to(&tool.isometry()),
        }
    }

    /// The robot's description.
    pub fn robot(&self) -> &Robot {
        &self.robot
    }

    /// Last joint frame → tool frame (flange, hand, bottle, …).
    pub fn tool(&self) -> &Pose {
        &self.tool
    }

    /// The arm as a chain ending at the tool.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// Base → tool frame for joint angles `q` (radians).
    pub fn forward(&self, q: &[f64; JOINTS]) -> Pose {
        Pose::from_matrix(&self.chain.forward_matrix(q))
    }

    /// The geometric Jacobian of the tool frame in the base frame at `q`:
    /// rows vx, vy, vz, ωx, ωy, ωz; column i is joint i's axis `z` crossed
    /// with the lever to the tool, then `z` itself.
    pub fn jacobian(&self, q: &[f64; JOINTS]) -> [[f64; JOINTS]; 6] {
        let j = self.chain.jacobian(q);
        std::array::from_fn(|r| std::array::from_fn(|c| j[(r, c)]))
    }

    /// Joint angles that put the tool at `target`, by damped least squares
    /// from `seed`, plus a null-space pull toward `rest` ([`crate::ik`]):
    /// the arm is redundant, and `rest` chooses among the tool-preserving
    /// motions (mainly the elbow swing about the shoulder–wrist line).
    /// Joints stay within the robot's position limits; the tool pose has
    /// priority over the pull, which only moves joints where the limits
    /// leave room. Within 1e-9 m and rad.
    pub fn inverse(
        &self,
        target: &Pose,
        seed: &[f64; JOINTS],
        rest: &[f64; JOINTS],
    ) -> Result<[f64; JOINTS], IkError> {
        let q = crate::ik::inverse(
            &self.chain,
            &target.isometry(),
            seed,
            rest,
            &IkOptions::default(),
        )?;
        Ok(std::array::from_fn(|j| q.get(j).copied().unwrap_or(0.0)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::tests::{close, distance};
    use std::f64::consts::FRAC_PI_2;

    #[test]
    fn known_configurations() {
        let arm = Arm::new(Robot::lwr4());
        assert!(close(arm.forward(&[0.0; 7]).position, [0.0, 0.0, 1.178]));
        // Joint 2 at +90°: the arm lies along the base x axis (or −x: the DH
        // z axes fix the sign), at shoulder height.
        let p = arm
            .forward(&[0.0, FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0])
            .position;
        assert!(
            (p[0].abs() - 0.868).abs() < 1e-9 && p[1].abs() < 1e-9 && (p[2] - 0.31).abs() < 1e-9,
            "{p:?}"
        );
        // Elbow (joint 4) at +90°: forearm horizontal at elbow height.
        let p = arm
            .forward(&[0.0, 0.0, 0.0, FRAC_PI_2, 0.0, 0.0, 0.0])
            .position;
        assert!(
            (p[0].abs() - 0.468).abs() < 1e-9 && (p[2] - 0.71).abs() < 1e-9,
            "{p:?}"
        );
        // Joint 1 rotates everything about the base z axis.
        let q = [0.7, 0.5, -0.3, 1.1, 0.4, -0.6, 0.2];
        let mut turned = q;
        turned[0] += 0.5;
        let (a, b) = (arm.forward(&q).position, arm.forward(&turned).position);
        let (r_a, r_b) = (a[0].hypot(a[1]), b[0].hypot(b[1]));
        assert!((r_a - r_b).abs() < 1e-12 && (a[2] - b[2]).abs() < 1e-12);
        let angle = b[1].atan2(b[0]) - a[1].atan2(a[0]);
        assert!((angle.rem_euclid(std::f64::consts::TAU) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn rotation_stays_orthonormal() {
        let r = Arm::new(Robot::lwr4())
            .forward(&[0.3, -1.0, 2.0, 1.5, -2.5, 0.9, 3.0])
            .rotation;
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| r[i][k] * r[j][k]).sum();
                assert!((dot - if i == j { 1.0 } else { 0.0 }).abs() < 1e-12);
            }
        }
    }

    /// Configurations well inside the limits and away from the shoulder
    /// (q2 = 0), elbow (q4 = 0) and wrist (q6 = 0) singularities.
    const CONFIGURATIONS: [[f64; JOINTS]; 5] = [
        [0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5],
        [-1.1, -0.8, 0.9, 1.4, -1.3, -0.6, 2.0],
        [2.2, 1.0, -1.5, -0.7, 2.1, 1.2, -2.4],
        [0.0, -0.5, 0.4, -1.8, 0.2, 0.9, 0.0],
        [-2.5, 1.3, 2.0, 0.9, -0.6, -1.5, 1.1],
    ];

    #[test]
    fn inverse_pose_composes_to_identity() {
        let pose = Arm::new(Robot::lwr4()).forward(&CONFIGURATIONS[1]);
        for product in [pose.then(&pose.inverse()), pose.inverse().then(&pose)] {
            let (dp, dr) = distance(&product, &Pose::IDENTITY);
            assert!(dp < 1e-15 && dr < 1e-15, "{product:?}");
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let arm = Arm::holding(
            Robot::lwr4(),
            Pose::from_rotation_vector([0.02, -0.01, 0.2], [0.3, 0.0, -0.2]),
        );
        let h = 1e-6;
        for q in CONFIGURATIONS {
            let jacobian = arm.jacobian(&q);
            let pose = arm.forward(&q);
            for j in 0..JOINTS {
                let (mut plus, mut minus) = (q, q);
                plus[j] += h;
                minus[j] -= h;
                let (plus, minus) = (arm.forward(&plus), arm.forward(&minus));
                // Angular velocity in the base frame: log(R(q ± h) R(q)ᵀ).
                let turn = |p: &Pose| p.then(&pose.inverse()).rotation_vector();
                let (w_plus, w_minus) = (turn(&plus), turn(&minus));
                for k in 0..3 {
                    let v = (plus.position[k] - minus.position[k]) / (2.0 * h);
                    let w = (w_plus[k] - w_minus[k]) / (2.0 * h);
                    assert!((jacobian[k][j] - v).abs() < 1e-8, "v{k} joint {j}: {q:?}");
                    assert!(
                        (jacobian[k + 3][j] - w).abs() < 1e-8,
                        "w{k} joint {j}: {q:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn inverse_kinematics_round_trips() {
        let arm = Arm::new(Robot::lwr4());
        for (n, q) in CONFIGURATIONS.into_iter().enumerate() {
            let target = arm.forward(&q);
            // ±0.2 rad on every joint, a different sign pattern each time.
            let seed: [f64; JOINTS] =
                std::array::from_fn(|j| q[j] + if (j + n) % 3 == 0 { -0.2 } else { 0.2 });
            let solution = arm.inverse(&target, &seed, &q).unwrap();
            let (dp, dr) = distance(&arm.forward(&solution), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "{q:?}: {dp:e} m, {dr:e} rad");
            // Resting at q itself, the pull brings the elbow back there too.
            assert!(solution.iter().zip(q).all(|(a, b)| (a - b).abs() < 1e-6));
            assert_eq!(
                Robot::lwr4().chain().check_samples([(0.0, &solution[..])]),
                Ok(())
            );
        }
    }

    #[test]
    fn rest_configuration_chooses_the_elbow() {
        let arm = Arm::new(Robot::lwr4());
        let q = CONFIGURATIONS[0];
        let target = arm.forward(&q);
        let (mut up, mut down) = (q, q);
        up[2] = 0.6;
        down[2] = -0.6;
        let up = arm.inverse(&target, &q, &up).unwrap();
        let down = arm.inverse(&target, &q, &down).unwrap();
        for solution in [up, down] {
            let (dp, dr) = distance(&arm.forward(&solution), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "{solution:?}: {dp:e} m, {dr:e} rad");
        }
        assert!(up[2] - down[2] > 0.3, "{up:?} vs {down:?}");
    }

    #[test]
    fn pull_toward_rest_respects_the_limits() {
        let arm = Arm::new(Robot::lwr4());
        let mut q = CONFIGURATIONS[0];
        q[0] = 2.9;
        let target = arm.forward(&q);
        // Rest beyond joint 1's limit: the pull takes it to the limit and no
        // further.
        let mut rest = q;
        rest[0] = 3.5;
        let solution = arm.inverse(&target, &q, &rest).unwrap();
        let (dp, dr) = distance(&arm.forward(&solution), &target);
        assert!(dp < 1e-9 && dr < 1e-9, "{solution:?}: {dp:e} m, {dr:e} rad");
        assert!(
            (solution[0] - 170f64.to_radians()).abs() < 1e-9,
            "{solution:?}"
        );
        assert_eq!(
            Robot::lwr4().chain().check_samples([(0.0, &solution[..])]),
            Ok(())
        );
    }

    #[test]
    fn tracks_a_path_sample_by_sample() {
        let arm = Arm::new(Robot::lwr4());
        let rest = CONFIGURATIONS[0];
        let start = arm.forward(&rest);
        let mut q = rest;
        // 10 cm in 1 mm steps, turning 0.2 rad on the way.
        for k in 1..=100 {
            let s = k as f64 / 100.0;
            let mut target = start.then(&Pose::from_rotation_vector([0.0; 3], [0.0, 0.2 * s, 0.0]));
            target.position[0] += 0.06 * s;
            target.position[2] -= 0.08 * s;
            let next = arm.inverse(&target, &q, &rest).unwrap();
            let (dp, dr) = distance(&arm.forward(&next), &target);
            assert!(dp < 1e-9 && dr < 1e-9, "sample {k}: {dp:e} m, {dr:e} rad");
            // Smooth: small target steps, small joint steps.
            assert!(
                next.iter().zip(q).all(|(a, b)| (a - b).abs() < 0.01),
                "sample {k}"
            );
            q = next;
        }
    }

    #[test]
    fn unreachable_target_is_an_error() {
        let arm = Arm::new(Robot::lwr4());
        let q = CONFIGURATIONS[0];
        let err = arm
            .inverse(&Pose::translation(3.0, 0.0, 0.0), &q, &q)
            .unwrap_err();
        assert!(err.position_error > 1.5, "{err:?}");
        assert!(
            err.to_string()
                .starts_with("inverse kinematics did not converge")
        );
    }
}
