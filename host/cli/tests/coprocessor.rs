//! `primo pour --coprocessor` and `primo scale read`: the learner and the
//! scale on their firmware in QEMU (mps2-an386, a Cortex-M4F), reached
//! through a pseudo-terminal like a USB-serial adapter, and clear errors
//! when they cannot be reached.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

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
    assert_eq!(status, 2);
    assert!(
        stderr.contains("--coprocessor /dev/primo-no-such-port: no such file or device"),
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

/// `primo pour --coprocessor qemu --rollouts 1` run as `exe`, with
/// `CARGO_TARGET_DIR` set to `target` and nothing else pointing at the
/// firmware: exit status, stdout, stderr.
fn pour_with_target_dir(exe: &Path, target: &Path) -> (i32, String, String) {
    let out = Command::new(exe)
        .args(["pour", "--coprocessor", "qemu", "--out"])
        .arg(tmp(&format!(
            "copro-{}",
            target.display().to_string().len()
        )))
        .env("CARGO_TARGET_DIR", target)
        .env_remove("PRIMO_FIRMWARE")
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

/// The firmware this test run uses: where primo finds it (test.sh builds
/// it first, in firmware/target or under CARGO_TARGET_DIR).
fn built_firmware() -> PathBuf {
    primo_learn::coprocessor::Qemu::find(primo_learn::coprocessor::Image::Coprocessor).unwrap()
}

#[test]
fn the_firmware_is_found_at_run_time_or_the_build_command_is_named() {
    // Found under CARGO_TARGET_DIR, wherever that is.
    let target = tmp("copro-target");
    let release = target.join("thumbv7em-none-eabihf/release");
    std::fs::create_dir_all(&release).unwrap();
    let elf = release.join("primo-firmware");
    std::fs::copy(built_firmware(), &elf).unwrap();
    let (status, stdout, stderr) =
        pour_with_target_dir(Path::new(env!("CARGO_BIN_EXE_primo")), &target);
    assert_eq!(status, 0, "{stderr}");
    assert!(
        stdout.contains(&format!("learner: firmware {} on QEMU", elf.display())),
        "{stdout}"
    );

    // A primo away from any build, the target directory empty: either the
    // source tree's own build is found, or the message says where primo
    // looked and what to run.
    let alone = tmp("copro-alone");
    std::fs::create_dir_all(&alone).unwrap();
    let exe = alone.join("primo");
    std::fs::copy(env!("CARGO_BIN_EXE_primo"), &exe).unwrap();
    let empty = tmp("copro-empty");
    std::fs::create_dir_all(&empty).unwrap();
    let cli = Path::new(env!("CARGO_MANIFEST_DIR"));
    let firmware = cli.ancestors().nth(2).unwrap().join("firmware");
    let in_tree = firmware.join("target/thumbv7em-none-eabihf/release/primo-firmware");
    let (status, stdout, stderr) = pour_with_target_dir(&exe, &empty);
    if in_tree.is_file() {
        assert_eq!(status, 0, "{stderr}");
        assert!(stdout.contains("learner: firmware "), "{stdout}");
    } else {
        assert_eq!(status, 1, "{stdout}");
        let looked = [
            empty.join("thumbv7em-none-eabihf/release/primo-firmware"),
            in_tree,
            alone.join("primo-firmware"),
        ];
        for path in looked {
            assert!(stderr.contains(&path.display().to_string()), "{stderr}");
        }
        assert!(
            stderr.contains(&format!(
                "build it with `cd {} && cargo build --release`",
                firmware.display()
            )),
            "{stderr}"
        );
    }
}

#[test]
fn primo_scale_read_boots_the_scale_on_a_simulated_load_cell() {
    let (status, stdout, stderr) = primo(&["scale", "read", "--port", "qemu", "--load", "250"]);
    assert_eq!(status, 0, "{stderr}");
    let grams: f64 = stdout.trim().strip_suffix(" g").unwrap().parse().unwrap();
    assert!((grams - 250.0).abs() <= 0.011, "{stdout}");
    let (status, _, stderr) = primo(&["scale", "read", "--port", "qemu", "--load", "9000"]);
    assert_eq!(status, 1);
    assert!(stderr.contains(": weigh: overload"), "{stderr}");
}

#[test]
fn primo_scale_takes_zero_tare_and_calibration_points() {
    for (args, says) in [
        (&["tare", "--load", "50"][..], "tared\n"),
        (&["zero", "--load", "5"], "zeroed\n"),
        (
            &["calibrate", "--load", "0", "--low", "0"],
            "low calibration point 0 g taken; now --high\n",
        ),
    ] {
        let mut all = vec!["scale", args[0], "--port", "qemu"];
        all.extend_from_slice(&args[1..]);
        let (status, stdout, stderr) = primo(&all);
        assert_eq!(status, 0, "{args:?}: {stderr}");
        assert_eq!(stdout, says);
    }
    // The scale's own rule: the low point first.
    let (status, _, stderr) = primo(&[
        "scale",
        "calibrate",
        "--port",
        "qemu",
        "--load",
        "200",
        "--high",
        "200",
    ]);
    assert_eq!(status, 1);
    assert!(
        stderr.contains("calibrate: bad state: take the low point first"),
        "{stderr}"
    );
    let (status, _, stderr) = primo(&[
        "scale",
        "calibrate",
        "--port",
        "qemu",
        "--low",
        "0",
        "--high",
        "1",
    ]);
    assert_eq!(status, 2, "{stderr}");
}

#[test]
fn primo_scale_settings_are_checked_before_anything_starts() {
    let (status, _, stderr) = primo(&["scale", "read", "--port", "qemu:"]);
    assert_eq!(status, 2);
    assert!(
        stderr.contains("--port qemu:: name the load cell's port"),
        "{stderr}"
    );
    let (status, _, stderr) = primo(&[
        "pour",
        "--robot",
        "fri:127.0.0.1",
        "--scale",
        "qemu",
        "--glass-holds",
        "0.4",
    ]);
    assert_eq!(status, 2);
    assert!(
        stderr.contains("--scale qemu: name the load cell's port, qemu:PATH"),
        "{stderr}"
    );
    let out = tmp("on-scale-without-a-scale");
    let (status, _, stderr) = primo(&[
        "pour",
        "--coprocessor",
        "scale",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(status, 2);
    assert!(
        stderr.contains("--coprocessor scale: the learner runs on primo's scale"),
        "{stderr}"
    );
    assert!(!out.exists());
}
