//! Bad files and arguments: one clear line naming the file, field or argument, exit
//! status 2, nothing written.

use super::{data, faint, s, temp};

/// Runs `faint detect` and checks the failure: status 2, one line on stderr containing
/// every needle, and `out` not created.
fn fails(args: &[&str], out: &std::path::Path, needles: &[&str]) {
    let mut all: Vec<&str> = args.to_vec();
    all.extend(["--out", s(out)]);
    let (code, stdout, err) = faint(&all);
    assert_eq!(code, 2, "{args:?}: {err}");
    assert!(stdout.is_empty(), "{args:?}: {stdout}");
    assert_eq!(
        err.trim_end().lines().count(),
        1,
        "{args:?}: not one line: {err}"
    );
    for n in needles {
        assert!(err.contains(n), "{args:?}: `{n}` not in: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{args:?}: wrote {}", out.display());
}

#[test]
fn bad_frames_files() {
    let dir = temp("bad-files");
    let out = dir.join("out");
    let cases: &[(&str, &str, &[&str])] = &[
        ("crpf", "int32.npy", &["int32.npy", "int32", "not accepted"]),
        ("crpf", "rank1.npy", &["rank1.npy", "shape (3,)"]),
        (
            "crpf",
            "complex_c.npy",
            &["complex_c.npy", "8 bins", "model.bins is 32"],
        ),
        ("crpf", "empty.npy", &["empty.npy", "empty"]),
        ("jott", "nan.npy", &["nan.npy", "frame 1, index 5", "NaN"]),
        (
            "crpf",
            "iq_inf.npy",
            &["iq_inf.npy", "frame 2, bin 3", "inf"],
        ),
        ("pf-tbd", "truncated.npy", &["truncated.npy", "truncated"]),
        ("crpf", "text.npy", &["text.npy", "not a NumPy"]),
        ("crpf", "ambiguous.npz", &["ambiguous.npz", "frames"]),
        ("phd-tbd", "cube_c.npy", &["cube_c.npy", "geometry"]),
        ("phd-tbd", "complex_c.npy", &["complex_c.npy"]),
        ("mht", "plots_nan.csv", &["plots_nan.csv", "NaN"]),
        ("mht", "plots_header.csv", &["plots_header.csv", "header"]),
        (
            "hough-classic",
            "plots_text.csv",
            &["plots_text.csv", "non-numeric"],
        ),
    ];
    for (det, file, needles) in cases {
        fails(&["detect", det, "--input", s(&data(file))], &out, needles);
    }
    fails(
        &["detect", "crpf", "--input", s(&dir.join("missing.npy"))],
        &out,
        &["missing.npy", "no such file"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_configs_and_arguments() {
    let dir = temp("bad-config");
    let out = dir.join("out");
    let frames = dir.join("othr.npy");
    assert_eq!(
        faint(&["simulate", "othr", "--out", s(&frames), "--frames", "4"]).0,
        0
    );
    let (_, default, _) = faint(&["detect", "crpf", "--print-config"]);
    let write = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    // A key that does not exist, at the top and inside the core config.
    let unknown = write("unknown.json", default.replacen('{', "{\"bogus\": 1,", 1));
    let inner = write("inner.json", default.replace("\"q\":", "\"qq\":"));
    // A value out of range: the core's own validation message.
    let p_bad = write("p.json", default.replace("\"p\": 8.0", "\"p\": -1.0"));
    let particles = write(
        "particles.json",
        default.replace("\"particles\": 1000", "\"particles\": 123"),
    );
    let syntax = write("syntax.json", "{ not json".into());
    let input = s(&frames);
    for (cfg, needles) in [
        (&unknown, &["unknown.json", "unknown field `bogus`"][..]),
        (&inner, &["inner.json", "unknown field `qq`"]),
        (&p_bad, &["p.json", "cost exponent p"]),
        (&particles, &["particles.json", "particles = 123"]),
        (&syntax, &["syntax.json"]),
    ] {
        fails(
            &["detect", "crpf", "--input", input, "--config", s(cfg)],
            &out,
            needles,
        );
    }
    fails(
        &[
            "detect",
            "crpf",
            "--input",
            input,
            "--config",
            s(&dir.join("none.json")),
        ],
        &out,
        &["--config", "none.json"],
    );
    fails(
        &["detect", "nosuch", "--input", input],
        &out,
        &["unknown detector 'nosuch'"],
    );
    fails(
        &["detect", "crpf", "--input", input, "--gospa-c", "0"],
        &out,
        &["--gospa-c"],
    );
    // A truth file that does not fit.
    let truth = write("truth.csv", "frame,x_m\n0,1.0\n".into());
    fails(
        &["detect", "crpf", "--input", input, "--truth", s(&truth)],
        &out,
        &["truth.csv", "header", "frame,fd_hz"],
    );
    let truth = write("late.csv", "frame,fd_hz\n9,1.0\n".into());
    fails(
        &["detect", "crpf", "--input", input, "--truth", s(&truth)],
        &out,
        &["late.csv", "frame 9"],
    );
    fails(
        &[
            "detect",
            "hough-classic",
            "--input",
            s(&super::data("plots.csv")),
            "--truth",
            s(&truth),
        ],
        &out,
        &["--truth", "no positions"],
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unwritable_out_is_named() {
    let dir = temp("bad-out");
    let frames = dir.join("othr.npy");
    assert_eq!(
        faint(&["simulate", "othr", "--out", s(&frames), "--frames", "2"]).0,
        0
    );
    // A folder under a regular file cannot be created, by root or anyone.
    let blocker = dir.join("file");
    std::fs::write(&blocker, b"x").unwrap();
    let out = blocker.join("sub");
    let (code, _, err) = faint(&["detect", "crpf", "--input", s(&frames), "--out", s(&out)]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("--out") && err.contains("file/sub"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_simulate_arguments() {
    let dir = temp("bad-sim");
    for (args, needle) in [
        (
            vec!["simulate", "othr", "--out", "x.csv"],
            "written as .npy",
        ),
        (
            vec!["simulate", "sea-clutter", "--out", "x.npy"],
            "written as .csv",
        ),
        (
            vec!["simulate", "sea-clutter", "--out", "x.csv", "--snr-db", "3"],
            "--snr-db",
        ),
        (
            vec!["simulate", "othr", "--out", "x.npy", "--frames", "0"],
            "--frames must lie in 1..=1000000, got 0",
        ),
        (
            vec![
                "simulate",
                "six-targets",
                "--out",
                "x.npy",
                "--frames",
                "41",
            ],
            "--frames 41",
        ),
        (
            vec!["simulate", "nosuch", "--out", "x.npy"],
            "unknown scenario 'nosuch'",
        ),
        (
            vec!["simulate", "othr", "--out", "x.npy", "--lambda", "3"],
            "--lambda",
        ),
    ] {
        let (code, _, err) = faint(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    assert!(!std::path::Path::new("x.npy").exists() && !std::path::Path::new("x.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn list_names_every_detector() {
    let (code, out, _) = faint(&["detect", "--list"]);
    assert_eq!(code, 0);
    for name in [
        "crpf",
        "pf-tbd",
        "jott",
        "pf-lrt",
        "mht",
        "hough-classic",
        "phd-tbd",
        "pso-phd-kmeans",
        "pso-phd-dbscan",
    ] {
        assert!(out.lines().any(|l| l.starts_with(name)), "{name}: {out}");
    }
}

#[test]
fn bad_numbers_name_the_argument_and_value() {
    let dir = temp("bad-numbers");
    let out = dir.join("out");
    let frames = dir.join("othr.npy");
    assert_eq!(
        faint(&["simulate", "othr", "--out", s(&frames), "--frames", "2"]).0,
        0
    );
    let input = s(&frames);
    for (args, needle) in [
        (
            vec!["--gospa-c", "inf"],
            "--gospa-c inf: must be finite and > 0",
        ),
        (
            vec!["--gospa-c", "nan"],
            "--gospa-c NaN: must be finite and > 0",
        ),
        (vec!["--min-score", "nan"], "--min-score: must be a number"),
        (
            vec!["--gospa-c", "-1"],
            "--gospa-c -1: must be finite and > 0",
        ),
    ] {
        let mut all = vec!["detect", "crpf", "--input", input];
        all.extend(args);
        fails(&all, &out, &[needle]);
    }
    let x = dir.join("x.npy");
    let xc = dir.join("x.csv");
    for (args, needle) in [
        (
            vec!["othr", "--out", s(&x), "--snr-db", "inf"],
            "--snr-db: 'inf' is not a finite number",
        ),
        (
            vec!["othr", "--out", s(&x), "--snr-db", "1e300"],
            "--snr-db must lie in [-60, 60] dB, got 1e300",
        ),
        (
            vec!["othr", "--out", s(&x), "--frames", "2000000"],
            "--frames must lie in 1..=1000000, got 2000000",
        ),
        (
            vec!["sea-clutter", "--out", s(&xc), "--lambda", "nan"],
            "--lambda: 'NaN' is not a finite number",
        ),
        (
            vec!["sea-clutter", "--out", s(&xc), "--lambda", "-1"],
            "--lambda must lie in [0, 10000] plots per scan, got -1",
        ),
        (
            vec!["dim-point", "--out", s(&x), "--snr", "inf"],
            "--snr: 'inf' is not a finite number",
        ),
        (
            vec!["dim-point", "--out", s(&x), "--snr", "200"],
            "--snr must lie in [0, 100] (a / sigma), got 200",
        ),
    ] {
        let mut all = vec!["simulate"];
        all.extend(args);
        let (code, _, err) = faint(&all);
        assert_eq!(code, 2, "{all:?}: {err}");
        assert!(err.contains(needle), "{all:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(!x.exists() && !xc.exists(), "{all:?} wrote a file");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn simulate_unwritable_out_is_named() {
    let (code, _, err) = faint(&[
        "simulate",
        "othr",
        "--out",
        "/proc/faint-no-such-dir/x.npy",
        "--frames",
        "2",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("/proc/faint-no-such-dir"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}
