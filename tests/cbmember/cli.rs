//! `faint reproduce cbmember --quick` runs end to end and writes its outputs; bad
//! arguments are one-line errors naming the argument; `--quick` never overrides a value
//! given on the command line.

use crate::common::{assert_one_line_error, faint, s, temp};

#[test]
fn reproduce_cbmember_quick_writes_tables_and_plots() {
    let dir = temp("cbmember", "quick");
    let args = [
        "--quiet",
        "reproduce",
        "cbmember",
        "--quick",
        "--runs",
        "1",
        "--out",
    ];
    let (code, stderr) = faint(&[&args[..], &[s(&dir)]].concat());
    assert_eq!(code, 0, "{stderr}");
    let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    for needle in [
        "joint 1500",
        "Doppler-only 1500",
        "Table 3",
        "False alarms",
        "Physical",
    ] {
        assert!(md.contains(needle), "{needle}: {md}");
    }
    for f in [
        "curves.csv",
        "table3.csv",
        "fig7_pd.svg",
        "fig8_ospa.svg",
        "fig9_blades.svg",
        "fig10_omega.svg",
        "fig11_particles.svg",
        "ablation_pd.svg",
        "physical_pd.svg",
        "false_alarms.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    // --runs 1 was kept under --quick (whose default is 2).
    let csv = std::fs::read_to_string(dir.join("curves.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let runs = header.iter().position(|h| *h == "runs").unwrap();
    assert!(lines.all(|l| l.split(',').nth(runs) == Some("1")), "{csv}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reproduce_cbmember_rejects_bad_arguments_before_any_run() {
    for (args, needle) in [
        (vec!["--runs", "0"], "--runs"),
        (vec!["--snr-db", "nan"], "--snr-db"),
        (vec!["--snr-db", "5:1:1"], "--snr-db"),
        (vec!["--physical-snr-db", "0:10:0"], "--physical-snr-db"),
        (vec!["--particles", "0"], "--particles"),
        (vec!["--particles", "2000"], "--particles"),
        (vec!["--timing-frames", "0"], "--timing-frames"),
        (vec!["--sets", "fig12"], "--sets"),
        (vec!["--quick", "--runs", "0"], "--runs"),
    ] {
        let mut all = vec!["--quiet", "reproduce", "cbmember"];
        all.extend_from_slice(&args);
        let (code, err) = faint(&all);
        assert_one_line_error(code, &err, needle, &args);
    }
}

#[test]
fn reproduce_cbmember_names_the_bad_value_and_path() {
    for (args, needle) in [
        (
            vec!["--snr-db", "0:1:inf"],
            "--snr-db: 'inf' is not a finite number",
        ),
        (
            vec!["--snr-db", "0:1:1:1"],
            "--snr-db: '0:1:1:1' is not a grid a:b:step",
        ),
        (
            vec!["--snr-db", "0:1e9:1"],
            "has 1000000001 points, at most 1000",
        ),
        (
            vec!["--snr-db", "-90:-80:5"],
            "--snr-db must lie in [-60, 60] dB, got -90",
        ),
        (
            vec!["--physical-snr-db", "0:100:50"],
            "--physical-snr-db must lie in [-60, 60] dB",
        ),
        (
            vec!["--quick", "--particles", "0"],
            "--particles must lie in 1..=1500, got 0",
        ),
        (
            vec!["--quick", "--timing-frames", "0"],
            "--timing-frames must lie in 1..=100",
        ),
        (
            vec!["--quick", "--runs", "2000000"],
            "--runs must lie in 1..=1000000",
        ),
        (
            vec!["--quick", "--out", "/proc/faint-no-such-dir"],
            "--out /proc/faint-no-such-dir",
        ),
    ] {
        let mut all = vec!["--quiet", "reproduce", "cbmember"];
        all.extend_from_slice(&args);
        let (code, err) = faint(&all);
        assert_one_line_error(code, &err, needle, &args);
    }
}
