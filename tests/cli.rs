//! Bad input at the host boundary: clear message, non-zero exit, no panic trace.

use std::process::Command;

fn faint(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(args)
        .output()
        .expect("run faint");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn unknown_scenario_is_a_clear_error() {
    let (code, _, err) = faint(&["scenario", "no-such-scene"]);
    assert_ne!(code, 0);
    assert!(err.contains("unknown scenario 'no-such-scene'"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn unknown_command_is_a_clear_error() {
    let (code, _, err) = faint(&["frobnicate"]);
    assert_ne!(code, 0);
    assert!(err.contains("frobnicate"), "{err}");
    assert!(!err.contains("panicked"));
}

#[test]
fn help_lists_commands() {
    let (code, out, _) = faint(&["--help"]);
    assert_eq!(code, 0);
    assert!(out.contains("scenarios"));
}
