//! Arbitrary URDF files: the reader gives a model or an error placed in
//! the file, never a panic; a chain taken from what it reads (default base
//! and tip) has 1 to MAX_JOINTS joints with sensible limits, and its
//! forward kinematics and Jacobian agree and are finite at zero and at
//! the corners of the limits (origins and travel are bounded by
//! MAX_DISTANCE).
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_robot::chain::{Chain, MAX_JOINTS, Tip};
use primo_robot::urdf::Urdf;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let urdf = match Urdf::parse("robot.urdf", &text) {
        Ok(urdf) => urdf,
        Err(e) => {
            assert!(e.to_string().starts_with("robot.urdf:"), "{e}");
            assert!(e.line >= 1 && e.column >= 1, "{e}");
            return;
        }
    };
    let chain = match Chain::from_urdf(&urdf, &Tip::default()) {
        Ok(chain) => chain,
        Err(e) => {
            assert!(e.to_string().starts_with("robot.urdf:"), "{e}");
            return;
        }
    };
    assert!((1..=MAX_JOINTS).contains(&chain.dof()));
    for joint in chain.joints() {
        let l = joint.limits;
        assert!(l.lower <= l.upper && l.velocity.is_finite() && l.velocity > 0.0);
    }
    // A continuous joint's corners: a turn either way.
    let corner = |v: f64| v.clamp(-std::f64::consts::TAU, std::f64::consts::TAU);
    let postures = [
        vec![0.0; chain.dof()],
        chain
            .joints()
            .iter()
            .map(|j| corner(j.limits.lower))
            .collect(),
        chain
            .joints()
            .iter()
            .map(|j| corner(j.limits.upper))
            .collect(),
    ];
    for q in &postures {
        let (tool, jacobian) = chain.forward_and_jacobian(q);
        assert_eq!(chain.forward(q), tool);
        assert_eq!(jacobian, chain.jacobian(q));
        assert_eq!(jacobian.ncols(), chain.dof());
        let t = tool.translation.vector;
        let r = tool.rotation;
        assert!(t.iter().all(|v| v.is_finite()), "{q:?}: {t:?}");
        assert!((r.norm() - 1.0).abs() < 1e-6, "{q:?}: {r:?}");
        assert!(jacobian.iter().all(|v| v.is_finite()), "{q:?}");
    }
});
