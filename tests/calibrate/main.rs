//! `faint calibrate` and `faint detect --calibration`: thresholds at a stated Pfa hold on
//! fresh noise, the data a Pfa needs is enforced, and a calibration is refused for
//! another detector, configuration or a longer input.

#[path = "../common/cli.rs"]
mod common;
#[path = "../common/shards.rs"]
mod shards;

use common::{assert_one_line_error, faint_quiet as faint, s, temp};
use faint::host::calibrate::{self, noise};
use faint::host::detect::calibration::{Calibration, NoiseModel};
use faint::host::detect::{self, Request};
use faint_core::model::doppler::Window;
use std::path::Path;

/// Noise-only Doppler frames of the OTHR preset's format (32 bins, Hamming, unit
/// time-sample variance: bin variance `sum w_n^2`).
fn doppler_noise(path: &Path, frames: usize, seed: u64) {
    let m = 32;
    let energy: f64 = (0..m)
        .map(|n| Window::Hamming.coefficient(n, m).powi(2))
        .sum();
    let model = NoiseModel::WindowedComplexGaussian {
        bin_variance: energy,
        window: Window::Hamming,
    };
    noise::simulate(&model, &[m], frames, seed, path, path).unwrap();
}

fn args(detector: &str, input: &Path, pfa: f64, run_frames: usize, out: &Path) -> calibrate::Args {
    calibrate::Args {
        detector: detector.into(),
        input: Some(input.to_path_buf()),
        from_input: None,
        config: None,
        pfa,
        run_frames: Some(run_frames),
        burn_in: 0,
        runs: None,
        seed: 3,
        out: out.to_path_buf(),
    }
}

/// Share of (run, frame) pairs of `runs` fresh noise runs of `l` frames in which the
/// calibrated detector declares a detection.
fn false_alarm_rate(cal: &Calibration, input: &Path, runs: usize, l: usize) -> f64 {
    let entry = detect::find(&cal.detector).unwrap();
    let out = (entry.run)(&Request {
        input,
        config: None,
        seed: 99,
        reports: false,
        restart_every: Some(l),
        runs: None,
    })
    .unwrap();
    let mut declared = vec![false; runs * l];
    for r in &out.rows {
        if r.frame < runs * l && cal.declares(r.frame % l, r.score) {
            declared[r.frame] = true;
        }
    }
    declared.iter().filter(|&&d| d).count() as f64 / (runs * l) as f64
}

/// Calibrated at Pfa 0.05 on 400 noise runs of 16 frames, each detector's false-alarm
/// rate on 400 fresh runs lies in [0.025, 0.08]. Why that wide: each t_k is an order
/// statistic of 400 values, whose realised Pfa has sd sqrt(0.05 0.95 / 400) = 0.011; the
/// 16 thresholds of a run are correlated, so their mean keeps most of it; the fresh
/// count (6400 frame-runs, 320 expected) adds sd ~0.003. Without thresholds the rate of
/// these detectors is 1 (they report every frame), with a wrong frame index it moves by
/// several times 0.011.
#[test]
fn thresholds_hold_their_pfa_on_fresh_noise() {
    let dir = temp("calibrate", "fresh");
    let (runs, l) = (400, 16);
    let a = dir.join("a.npy");
    let b = dir.join("b.npy");
    doppler_noise(&a, runs * l, 1);
    doppler_noise(&b, runs * l, 2);
    for det in ["crpf", "pf-lrt", "jott"] {
        let cal =
            calibrate::run(&args(det, &a, 0.05, l, &dir.join(format!("{det}.json")))).unwrap();
        assert_eq!(cal.runs, runs);
        assert_eq!(cal.thresholds.len(), l);
        let back = Calibration::load(&dir.join(format!("{det}.json"))).unwrap();
        assert_eq!(back, cal);
        // The order statistic of rank ceil(400 * 0.95) = 380: 20 runs above it, fewer
        // only where scores tie at it (continuous scores: never, bar -inf frames).
        for t in &cal.thresholds {
            let e = t.exceedances.expect("exceedances written");
            assert!(e <= 20, "{det} frame {}: {e} runs above", t.frame);
        }
        let got = cal.achieved_pfa().unwrap();
        assert!(got <= 0.05 && got > 0.0, "{det}: achieved {got}");
        let rate = false_alarm_rate(&cal, &b, runs, l);
        eprintln!(
            "{det}: false-alarm rate on fresh noise {rate:.4} (Pfa 0.05, 400 x 16 frame-runs)"
        );
        assert!(
            (0.025..=0.08).contains(&rate),
            "{det}: false-alarm rate {rate}"
        );
    }
}

#[test]
fn too_little_noise_is_refused_with_the_amount_needed() {
    let dir = temp("calibrate", "little");
    let a = dir.join("a.npy");
    doppler_noise(&a, 100, 1);
    let cal = dir.join("cal.json");
    let argv = [
        "calibrate",
        "crpf",
        "--input",
        s(&a),
        "--pfa",
        "0.01",
        "--run-frames",
        "10",
        "--out",
        s(&cal),
    ];
    let (code, _, err) = faint(&argv);
    // 0.01 needs 1000 runs of 10 frames: 10000 frames.
    assert_one_line_error(
        code,
        &err,
        "needs at least 1000 noise runs of 10 frames (10000 frames)",
        &argv,
    );
    assert!(!cal.exists());
    let argv = [
        "calibrate",
        "crpf",
        "--input",
        s(&a),
        "--pfa",
        "1.5",
        "--out",
        s(&cal),
    ];
    let (code, _, err) = faint(&argv);
    assert_one_line_error(code, &err, "--pfa", &argv);
}

#[test]
fn detect_uses_a_calibration_only_where_it_holds() {
    let dir = temp("calibrate", "detect");
    let (runs, l) = (200, 8);
    let a = dir.join("a.npy");
    doppler_noise(&a, runs * l, 5);
    let cal = dir.join("cal.json");
    let argv = [
        "calibrate",
        "pf-lrt",
        "--input",
        s(&a),
        "--pfa",
        "0.05",
        "--run-frames",
        "8",
        "--out",
        s(&cal),
    ];
    let (code, out, err) = faint(&argv);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("Pfa 0.05 per frame"), "{out}");
    // A file of 8 frames: summary.csv states the threshold and the Pfa of every frame.
    let short = dir.join("short.npy");
    doppler_noise(&short, 8, 6);
    let o = dir.join("out");
    let (code, out, err) = faint(&[
        "detect",
        "pf-lrt",
        "--input",
        s(&short),
        "--calibration",
        s(&cal),
        "--out",
        s(&o),
        "--no-charts",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("above the thresholds at Pfa 0.05"), "{out}");
    let summary = std::fs::read_to_string(o.join("summary.csv")).unwrap();
    let mut lines = summary.lines();
    assert_eq!(
        lines.next(),
        Some("frame,detections,best_score,declared,threshold,pfa")
    );
    assert_eq!(lines.clone().count(), 8);
    assert!(lines.all(|l| l.ends_with(",0.05")), "{summary}");
    // Refused: another detector, another configuration, a longer input.
    let (code, _, err) = faint(&[
        "detect",
        "jott",
        "--input",
        s(&short),
        "--calibration",
        s(&cal),
        "--out",
        s(&o),
    ]);
    assert_one_line_error(code, &err, "made for pf-lrt", &[]);
    let cfg = dir.join("cfg.json");
    let (_, text, _) = faint(&["detect", "pf-lrt", "--print-config"]);
    std::fs::write(
        &cfg,
        text.replace("\"particles\": 1000", "\"particles\": 2000"),
    )
    .unwrap();
    let (code, _, err) = faint(&[
        "detect",
        "pf-lrt",
        "--input",
        s(&short),
        "--config",
        s(&cfg),
        "--calibration",
        s(&cal),
        "--out",
        s(&o),
    ]);
    assert_one_line_error(code, &err, "another configuration", &[]);
    let long = dir.join("long.npy");
    doppler_noise(&long, 9, 7);
    let (code, _, err) = faint(&[
        "detect",
        "pf-lrt",
        "--input",
        s(&long),
        "--calibration",
        s(&cal),
        "--out",
        s(&o),
    ]);
    assert_one_line_error(code, &err, "--run-frames 9", &[]);
}

/// `--from-input` on a file with a strong target: the bin variance is estimated within
/// 8 % of the truth (the median of 32 x 40 exponential powers has sd about 4 % and the
/// target's few bins move it up by about 2 %), and the simulated runs calibrate.
#[test]
fn from_input_estimates_the_noise_under_a_target() {
    let dir = temp("calibrate", "from");
    let f = dir.join("othr.npy");
    let (code, _, err) = faint(&[
        "simulate",
        "othr",
        "--out",
        s(&f),
        "--snr-db",
        "15",
        "--seed",
        "4",
    ]);
    assert_eq!(code, 0, "{err}");
    let cal = dir.join("cal.json");
    let (code, _, err) = faint(&[
        "calibrate",
        "crpf",
        "--from-input",
        s(&f),
        "--pfa",
        "0.1",
        "--out",
        s(&cal),
    ]);
    assert_eq!(code, 0, "{err}");
    let c = Calibration::load(&cal).unwrap();
    let energy: f64 = (0..32)
        .map(|n| Window::Hamming.coefficient(n, 32).powi(2))
        .sum();
    match &c.source {
        faint::host::detect::calibration::Source::Model {
            model: NoiseModel::WindowedComplexGaussian { bin_variance, .. },
            frames,
            ..
        } => {
            eprintln!("estimated bin variance {bin_variance:.3}, true {energy:.3}");
            assert!(
                (bin_variance / energy - 1.0).abs() < 0.08,
                "{bin_variance} vs {energy}"
            );
            assert_eq!(c.run_frames, *frames);
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(c.runs, 100);
}

/// `faint calibrate` in three shards (noise runs 0..13, 13..26, 26..40 of a recording;
/// then of a noise model estimated with `--from-input`), merged by `faint merge`, writes
/// the unsharded run's calibration file byte for byte.
#[test]
fn three_shards_merge_into_the_unsharded_calibration() {
    let dir = temp("calibrate", "shards");
    let noise = dir.join("noise.npy");
    doppler_noise(&noise, 40 * 8, 5);
    for (i, source) in ["--input", "--from-input"].into_iter().enumerate() {
        let root = dir.join(format!("run{i}"));
        let mut args = vec!["calibrate", "crpf", source, s(&noise), "--pfa", "0.25"];
        if source == "--input" {
            args.extend(["--run-frames", "8"]);
        } else {
            args.extend(["--run-frames", "8", "--runs", "40"]);
        }
        let n = shards::assert_merged_equals_whole(&root, &args, 3, Some("cal.json"), |out| {
            calibrate::shard_dir(out)
        });
        assert_eq!(n, 1);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
