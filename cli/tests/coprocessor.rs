//! `primo pour --coprocessor`: the learner on the firmware in QEMU
//! (mps2-an386, a Cortex-M4F), reached through a pseudo-terminal like a
//! USB-serial adapter, and clear errors when it cannot be reached.

mod common;

use common::{primo, tmp};

#[test]
fn pour_with_the_learner_on_the_emulated_mcu() {
    let out = tmp("copro-pour");
    let (status, stdout, stderr) = primo(&[
        "pour",
        "--coprocessor",
        "qemu",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(status, 0, "{stderr}");
    assert!(stdout.contains("learner: firmware"), "{stdout}");
    // The same run in-process: the same roll-outs, line for line.
    let host = tmp("copro-pour-host");
    let (status, local, stderr) = primo(&["pour", "--out", host.to_str().unwrap()]);
    assert_eq!(status, 0, "{stderr}");
    let rollouts = |s: &str| -> Vec<String> {
        s.lines()
            .filter(|l| l.starts_with("roll-out"))
            .map(String::from)
            .collect()
    };
    assert!(!rollouts(&local).is_empty(), "{local}");
    assert_eq!(rollouts(&stdout), rollouts(&local));
}

#[test]
fn an_unreachable_coprocessor_is_a_clear_error() {
    let (status, _, stderr) = primo(&["pour", "--coprocessor", "/dev/primo-no-such-port"]);
    assert_eq!(status, 1);
    assert!(
        stderr.contains("/dev/primo-no-such-port: cannot open"),
        "{stderr}"
    );
    let (status, _, stderr) = primo(&[
        "pour",
        "--coprocessor",
        "qemu",
        "--firmware",
        "/nonexistent/primo-firmware",
    ]);
    assert_eq!(status, 1);
    assert!(
        stderr.contains("/nonexistent/primo-firmware not found"),
        "{stderr}"
    );
}
