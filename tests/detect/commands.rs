//! Bad input at the host boundary: clear message, non-zero exit, no panic trace.

use super::faint;

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

#[test]
fn out_of_range_arguments_are_clear_errors() {
    for (args, needle) in [
        (
            &["reproduce", "mht", "--quick", "--pfa", "3"][..],
            "--pfa must lie in (0, 1)",
        ),
        (
            &["reproduce", "mht", "--quick", "--lambda", "0"][..],
            "--lambda must lie in",
        ),
        (
            &["reproduce", "mht", "--trials", "x"][..],
            "invalid value 'x'",
        ),
    ] {
        let (code, _, err) = faint(args);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn known_scenarios_print_as_json() {
    let (code, out, _) = faint(&["scenarios"]);
    assert_eq!(code, 0);
    for name in out.lines().filter_map(|l| l.split_whitespace().next()) {
        let (c, json, err) = faint(&["scenario", name]);
        assert_eq!(c, 0, "{name}: {err}");
        assert!(json.trim_start().starts_with('{'), "{name}: {json}");
    }
}

/// Regression: `faint detect --list | head -1` panicked in `println!` ("failed printing to
/// stdout: Broken pipe", exit 101). The reader closes its end before the child writes, so
/// every write meets a closed pipe; the process must end quietly (by SIGPIPE, or 0).
#[test]
fn closed_stdout_ends_quietly() {
    use std::process::{Command, Stdio};
    for args in [
        &["detect", "--list"][..],
        &["detect", "crpf", "--print-config"][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_faint"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn faint");
        drop(child.stdout.take());
        let out = child.wait_with_output().expect("wait for faint");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_ne!(out.status.code(), Some(101), "{args:?}: {err}");
    }
}
