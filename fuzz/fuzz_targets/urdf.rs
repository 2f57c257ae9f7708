//! Arbitrary URDF files: the reader gives a model or an error placed in
//! the file, never a panic; a chain taken from what it reads (default base
//! and tip) has 1 to MAX_JOINTS joints with sensible limits, and its
//! forward kinematics and Jacobian at zero agree and never panic (their
//! values may overflow: a URDF's numbers are only checked finite).
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
    let zeros = vec![0.0; chain.dof()];
    let (tool, jacobian) = chain.forward_and_jacobian(&zeros);
    assert_eq!(chain.forward(&zeros), tool);
    assert_eq!(jacobian, chain.jacobian(&zeros));
    assert_eq!(jacobian.ncols(), chain.dof());
});
