//! `faint simulate` then `faint detect` gives, bit for bit, the detections of the
//! reproductions' own code path (the same scenario call, the same detector and seed).

use std::path::Path;

use faint::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::detect::jott::JottTbd;
use faint::detect::mht::MhtConfig;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::{run, Detector};
use faint::host::detect::default_classic;
use faint::host::instances::mht::{Classic, Mht};
use faint::host::instances::phd::HostFilter;
use faint::host::reproduce::crpf::run_detector;
use faint::host::simulate::crpf::{Noise, Othr};
use faint::host::simulate::mht::SeaClutter;
use faint::host::simulate::phd::SixTargets;
use faint::host::simulate::phd::Variant;
use faint::model::doppler::{estimate_noise_variance, DopplerReport, ModelConfig};
use faint::rng::Rng;

use super::{faint, s, temp};

const SIM_SEED: u64 = 11;
const DET_SEED: u64 = 5;

/// `(frame, score, state)` of every row of a `detections.csv`, the numbers as bits.
fn read_rows(path: &Path) -> Vec<(usize, u32, Vec<u32>)> {
    let mut r = csv::Reader::from_path(path).unwrap();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            let f = |i: usize| rec[i].parse::<f32>().unwrap().to_bits();
            (
                rec[0].parse().unwrap(),
                f(2),
                (5..rec.len()).map(f).collect(),
            )
        })
        .collect()
}

/// The same rows from a detector run in-process.
fn rows_of<D: Detector>(
    det: &mut D,
    frames: impl Iterator<Item = impl AsRef<D::Frame>>,
) -> Vec<(usize, u32, Vec<u32>)> {
    let frames: Vec<_> = frames.collect();
    let mut rows = Vec::new();
    run(det, frames.iter().map(|f| f.as_ref()), |k, det, _| {
        for d in det.detections() {
            rows.push((
                k,
                d.score.to_bits(),
                d.state().iter().map(|v| v.to_bits()).collect(),
            ));
        }
    })
    .unwrap();
    rows
}

/// Runs `faint detect <name>` on `input` with every detection written.
fn detect(name: &str, input: &Path, out: &Path) -> Vec<(usize, u32, Vec<u32>)> {
    detect_with(name, input, out, None)
}

/// [`detect`] with a configuration file.
fn detect_with(
    name: &str,
    input: &Path,
    out: &Path,
    config: Option<&Path>,
) -> Vec<(usize, u32, Vec<u32>)> {
    let seed = DET_SEED.to_string();
    let mut args = vec![
        "detect",
        name,
        "--input",
        s(input),
        "--out",
        s(out),
        "--seed",
        &seed,
        "--min-score",
        "-1e30",
        "--no-charts",
    ];
    if let Some(c) = config {
        args.extend(["--config", s(c)]);
    }
    let (code, _, err) = faint(&args);
    assert_eq!(code, 0, "{name}: {err}");
    read_rows(&out.join("detections.csv"))
}

/// A Doppler detector's configuration file in the input's own units (`"noise":
/// "as-is"`, the preset's prior box): the reproduction's settings.
fn as_is(dir: &Path, name: &str, config: serde_json::Value) -> std::path::PathBuf {
    let p = dir.join(format!("{name}-as-is.json"));
    let v = serde_json::json!({
        "particles": 1000,
        "noise": "as-is",
        "amplitude_snr_db": null,
        "births_over_band": false,
        "config": config,
    });
    std::fs::write(&p, v.to_string()).unwrap();
    p
}

fn doppler_rows(reports: &[DopplerReport], lrt: bool) -> Vec<(usize, u32, Vec<u32>)> {
    reports
        .iter()
        .enumerate()
        .filter_map(|(k, r)| {
            let x = r.estimate?;
            let score = if lrt { r.log_lr } else { r.existence };
            Some((k, score.to_bits(), x.iter().map(|v| v.to_bits()).collect()))
        })
        .collect()
}

#[test]
fn doppler_detectors_round_trip() {
    let dir = temp("rt-doppler");
    let file = dir.join("othr.npy");
    let (code, _, err) = faint(&[
        "simulate",
        "othr",
        "--out",
        s(&file),
        "--seed",
        "11",
        "--snr-db",
        "10",
    ]);
    assert_eq!(code, 0, "{err}");
    // The reproduction's code path: its scenario call, its noise estimate, run_detector.
    let run0 = Othr::default().simulate(
        Some(10.0),
        Noise::Gaussian,
        &mut Rng::from_stream(SIM_SEED, 0),
    );
    let var = estimate_noise_variance(run0.frames.iter().map(|f| f.as_slice()), 32).unwrap();
    let g = GaussConfig {
        model: ModelConfig::othr(),
        noise_var: var,
        birth: Default::default(),
        likelihood: Default::default(),
    };
    let want_crpf = doppler_rows(
        &run_detector(
            &mut *Box::new(CrpfTbd::<1000>::new(CrpfConfig::othr(), DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        false,
    );
    assert!(want_crpf.len() > 20, "an estimate in most frames");
    // The reproduction works in the preset's absolute units and estimates the Gaussian
    // comparators' variance as the mean bin power: the same settings as a file.
    let crpf_cfg = as_is(
        &dir,
        "crpf",
        serde_json::to_value(CrpfConfig::othr()).unwrap(),
    );
    let gauss_cfg = as_is(&dir, "gauss", serde_json::to_value(g).unwrap());
    let run = |name: &str, cfg: &Path| detect_with(name, &file, &dir.join(name), Some(cfg));
    assert_eq!(run("crpf", &crpf_cfg), want_crpf);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(PfTbd::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        false,
    );
    assert_eq!(run("pf-tbd", &gauss_cfg), want);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(JottTbd::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        false,
    );
    assert_eq!(run("jott", &gauss_cfg), want);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(PfLrt::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        true,
    );
    assert_eq!(run("pf-lrt", &gauss_cfg), want);
    // The truth file beside it: the target's Doppler in frames 7..=26 (1-based).
    let truth = std::fs::read_to_string(dir.join("othr.truth.csv")).unwrap();
    assert_eq!(truth.lines().count(), 1 + 20);
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Doppler detectors' defaults are scale-free: the frames are divided by their
/// estimated noise level. A power-of-two scale is exact in `f32` (and so are the median
/// and the square root of a power-of-four ratio), so the detections keep their bits;
/// before, the CRPF amplitude prior `[0.05, 1.5]` was absolute and frames x 10 were
/// never detected.
#[test]
fn doppler_detectors_are_scale_free() {
    use faint::host::io::input::read_complex_frames;
    use faint::host::io::output::write_complex_frames;
    let dir = temp("rt-scale");
    let file = dir.join("othr.npy");
    let (code, _, err) = faint(&[
        "simulate",
        "othr",
        "--out",
        s(&file),
        "--seed",
        "11",
        "--snr-db",
        "10",
    ]);
    assert_eq!(code, 0, "{err}");
    let f = read_complex_frames(&file).unwrap();
    let scaled = |k: f32, name: &str| {
        let frames: Vec<Vec<faint::Complex32>> = (0..f.frames())
            .map(|i| f.frame(i).iter().map(|z| z * k).collect())
            .collect();
        let p = dir.join(name);
        write_complex_frames(&p, &frames).unwrap();
        p
    };
    for name in ["crpf", "jott", "pf-lrt"] {
        let base = detect(name, &file, &dir.join(format!("{name}-1")));
        // The target (frames 7..=26, 1-based) is found: estimates in most frames.
        assert!(base.len() > 20, "{name}: {} rows", base.len());
        for (k, tag) in [(1024.0f32, "up"), (1.0 / 1024.0, "down")] {
            let p = scaled(k, &format!("{name}-{tag}.npy"));
            let rows = detect(name, &p, &dir.join(format!("{name}-{tag}")));
            assert_eq!(rows, base, "{name} x {k}");
        }
    }
    // x 10 and x 1e-3 are not exact in f32, and a particle filter's run diverges after
    // the first rounding: compare over 8 detector seeds. The target (0-based frames
    // 6..=25) counts as found when at least 3 of its frames have an existence above
    // 0.5. Unscaled, 8 of 8 seeds find it at 10 dB (6 to 12 frames); each scaled copy
    // must find it in at least 6 of 8, while the preset's absolute prior (as-is) finds
    // it in at most 1 of 8 at x 10 (it used to be never).
    let found = |input: &Path, cfg: Option<&Path>, seed: u64| -> bool {
        let out = dir.join(format!("seed-{seed}"));
        let seed = seed.to_string();
        let mut args = vec![
            "detect",
            "crpf",
            "--input",
            s(input),
            "--out",
            s(&out),
            "--seed",
            &seed,
            "--min-score",
            "0.5",
            "--no-charts",
        ];
        if let Some(c) = cfg {
            args.extend(["--config", s(c)]);
        }
        let (code, _, err) = faint(&args);
        assert_eq!(code, 0, "{err}");
        let rows = read_rows(&out.join("detections.csv"));
        rows.iter().filter(|r| (6..=25).contains(&r.0)).count() >= 3
    };
    let x10 = scaled(10.0, "x10.npy");
    let milli = scaled(1e-3, "milli.npy");
    let asis = as_is(
        &dir,
        "crpf",
        serde_json::to_value(CrpfConfig::othr()).unwrap(),
    );
    for (input, cfg, lo, hi) in [
        (&file, None, 8, 8),
        (&x10, None, 6, 8),
        (&milli, None, 6, 8),
        (&x10, Some(asis.as_path()), 0, 1),
    ] {
        let n = (1..=8).filter(|&seed| found(input, cfg, seed)).count();
        assert!(
            (lo..=hi).contains(&n),
            "{} {cfg:?}: found in {n} of 8 runs",
            input.display()
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn hough_detectors_round_trip() {
    let dir = temp("rt-hough");
    let file = dir.join("sea.csv");
    let (code, _, err) = faint(&[
        "simulate",
        "sea-clutter",
        "--out",
        s(&file),
        "--seed",
        "11",
        "--lambda",
        "80",
    ]);
    assert_eq!(code, 0, "{err}");
    let trial = SeaClutter::paper(80.0).generate(&mut Rng::from_stream(SIM_SEED, 0));
    let scans: Vec<Vec<_>> = trial.scans.iter().map(|s| s.plots.clone()).collect();
    let mut mht = Box::new(Mht::new(MhtConfig::sea_clutter()).unwrap());
    let want = rows_of(mht.as_mut(), scans.iter().map(|s| s.as_slice()));
    assert!(!want.is_empty(), "MHT-TBD confirms tracks at lambda 80");
    // The configuration's thresholds as they are (`gamma_grid_pfa: null`), as the
    // reproduction runs them.
    let fixed = |name: &str, config: serde_json::Value| {
        let p = dir.join(format!("{name}.json"));
        let v = serde_json::json!({ "gamma_grid_pfa": null, "config": config });
        std::fs::write(&p, v.to_string()).unwrap();
        p
    };
    let cfg = fixed(
        "mht",
        serde_json::to_value(MhtConfig::sea_clutter()).unwrap(),
    );
    assert_eq!(
        detect_with("mht", &file, &dir.join("mht"), Some(&cfg)),
        want
    );
    let mut classic = Box::new(Classic::new(default_classic()).unwrap());
    let want = rows_of(classic.as_mut(), scans.iter().map(|s| s.as_slice()));
    let cfg = fixed("classic", serde_json::to_value(default_classic()).unwrap());
    assert_eq!(
        detect_with("hough-classic", &file, &dir.join("classic"), Some(&cfg)),
        want
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn phd_detectors_round_trip() {
    let dir = temp("rt-phd");
    let file = dir.join("cubes.npy");
    let (code, _, err) = faint(&[
        "simulate",
        "six-targets",
        "--out",
        s(&file),
        "--seed",
        "11",
        "--frames",
        "7",
    ]);
    assert_eq!(code, 0, "{err}");
    // The reproduction's run 0: truth from fork(1), cubes from fork(2).
    let sc = SixTargets::new(9.0);
    let mut seed_rng = Rng::from_stream(SIM_SEED, 0);
    let truth = sc.truth(&mut seed_rng.fork(1));
    let mut cube_rng = seed_rng.fork(2);
    let mut cubes = Vec::new();
    for frame in truth.iter().take(7) {
        let mut c = Vec::new();
        sc.cube(frame, &mut cube_rng, &mut c);
        // `faint detect`'s default divides each cube by its noise power.
        faint::host::detect::normalise_frame(&mut c).unwrap();
        cubes.push(c);
    }
    for (name, v) in [
        ("phd-tbd", Variant::PhdTbd),
        ("pso-phd-kmeans", Variant::PsoKMeans),
        ("pso-phd-dbscan", Variant::PsoDbscan),
    ] {
        let cfg = faint::host::detect::default_phd_file(v)
            .effective()
            .unwrap();
        let cubes = cubes.clone();
        let want = faint::host::montecarlo::on_worker_stack(move || {
            let mut f = Box::new(HostFilter::new(cfg, DET_SEED).unwrap());
            rows_of(f.as_mut(), cubes.iter().map(|c| c.as_slice()))
        });
        assert!(
            !want.is_empty(),
            "{name}: the first target (frame 5) is estimated by frame 7"
        );
        assert_eq!(detect(name, &file, &dir.join(name)), want, "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn printed_config_is_the_default() {
    // `--print-config` fed back as `--config` gives the same detections as no config.
    let dir = temp("rt-config");
    let file = dir.join("othr.npy");
    assert_eq!(
        faint(&["simulate", "othr", "--out", s(&file), "--frames", "8"]).0,
        0
    );
    for name in ["crpf", "jott"] {
        let (code, cfg, _) = faint(&["detect", name, "--print-config"]);
        assert_eq!(code, 0);
        let p = dir.join(format!("{name}.json"));
        std::fs::write(&p, cfg).unwrap();
        let a = detect(name, &file, &dir.join("a"));
        let (code, _, err) = faint(&[
            "detect",
            name,
            "--input",
            s(&file),
            "--out",
            s(&dir.join("b")),
            "--config",
            s(&p),
            "--seed",
            &DET_SEED.to_string(),
            "--min-score",
            "-1e30",
            "--no-charts",
        ]);
        assert_eq!(code, 0, "{err}");
        assert_eq!(read_rows(&dir.join("b/detections.csv")), a, "{name}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn truth_gives_gospa_and_plots() {
    let dir = temp("rt-truth");
    let file = dir.join("othr.npy");
    assert_eq!(
        faint(&["simulate", "othr", "--out", s(&file), "--snr-db", "14"]).0,
        0
    );
    let out = dir.join("out");
    let (code, stdout, err) = faint(&[
        "detect",
        "crpf",
        "--input",
        s(&file),
        "--truth",
        s(&dir.join("othr.truth.csv")),
        "--out",
        s(&out),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("mean GOSPA"), "{stdout}");
    let g = std::fs::read_to_string(out.join("gospa.csv")).unwrap();
    assert_eq!(g.lines().count(), 1 + 32);
    assert!(g.starts_with("frame,truth,estimates,gospa,localisation,missed,false_targets"));
    for f in [
        "detections.csv",
        "detections.json",
        "summary.csv",
        "score.svg",
        "tracks.svg",
    ] {
        assert!(out.join(f).exists(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// A truth file numbered from 1 gives the same GOSPA with `--truth-first-frame 1`; read
/// as 0-based, its last frame is past the input and the error says how to read it.
#[test]
fn truth_numbered_from_one() {
    let dir = temp("rt-truth1");
    let file = dir.join("othr.npy");
    assert_eq!(faint(&["simulate", "othr", "--out", s(&file)]).0, 0);
    let truth0 = std::fs::read_to_string(dir.join("othr.truth.csv")).unwrap();
    // The preset's target lives to the last frame (0-based 31 of 32)? Shift every row.
    let mut lines = truth0.lines();
    let mut truth1 = format!("{}\n", lines.next().unwrap());
    for l in lines {
        let (f, rest) = l.split_once(',').unwrap();
        truth1.push_str(&format!("{},{rest}\n", f.parse::<usize>().unwrap() + 1));
    }
    let t1 = dir.join("one.csv");
    std::fs::write(&t1, &truth1).unwrap();
    let run = |truth: &Path, extra: &[&str], out: &str| {
        let mut args = vec![
            "detect",
            "crpf",
            "--input",
            s(&file),
            "--truth",
            s(truth),
            "--out",
        ];
        let o = dir.join(out);
        args.push(s(&o));
        args.push("--no-charts");
        args.extend_from_slice(extra);
        let (code, _, err) = faint(&args);
        (code, err, std::fs::read_to_string(o.join("gospa.csv")).ok())
    };
    let (code, err, g0) = run(&dir.join("othr.truth.csv"), &[], "a");
    assert_eq!(code, 0, "{err}");
    let (code, err, g1) = run(&t1, &["--truth-first-frame", "1"], "b");
    assert_eq!(code, 0, "{err}");
    assert_eq!(g0, g1);
    // The preset's target is present in frames 7..=26 (1-based): shifted by one more
    // frame than the file holds, a row lands at frame 32 of 32 only if the truth
    // reaches the last frame; shift the numbering by 6 to put one there.
    let mut late = format!("{}\n", truth0.lines().next().unwrap());
    for l in truth0.lines().skip(1) {
        let (f, rest) = l.split_once(',').unwrap();
        late.push_str(&format!("{},{rest}\n", f.parse::<usize>().unwrap() + 7));
    }
    let tl = dir.join("late.csv");
    std::fs::write(&tl, &late).unwrap();
    let (code, err, _) = run(&tl, &[], "c");
    assert_eq!(code, 2);
    assert!(err.contains("add --truth-first-frame 1"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let (code, err, _) = run(&t1, &["--truth-first-frame", "2"], "d");
    assert_eq!(code, 2, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn cbmember_detectors_round_trip() {
    use faint::detect::cbmember::CbmemberConfig;
    use faint::host::instances::cbmember::HostFilter as Cbm;
    use faint::host::simulate::cbmember::{MapSource, RotorUav};
    use faint::model::range_doppler::PointModel;
    let dir = temp("rt-cbm");
    let file = dir.join("maps.npy");
    let (code, _, err) = faint(&[
        "simulate",
        "rotor-uav",
        "--out",
        s(&file),
        "--seed",
        "11",
        "--frames",
        "6",
        "--snr-db",
        "12",
    ]);
    assert_eq!(code, 0, "{err}");
    // The reproduction's map stream of run 0.
    let sc = RotorUav::new(12.0);
    let mut map_rng = Rng::from_stream(SIM_SEED, 0).fork(1);
    let mut src = MapSource::new(&sc);
    let mut maps = Vec::new();
    for (k, t) in sc.truth().iter().take(6).enumerate() {
        let mut m = Vec::new();
        src.power(&sc, t, k, &mut map_rng, &mut m);
        // `faint detect`'s default divides each map by its noise power.
        faint::host::detect::normalise_frame(&mut m).unwrap();
        maps.push(m);
    }
    for (name, model) in [
        ("cbmember", PointModel::Joint),
        ("cbmember-doppler", PointModel::DopplerOnly),
    ] {
        let cfg: CbmemberConfig = faint::host::detect::default_cbmember_file(model)
            .effective()
            .unwrap();
        let maps = maps.clone();
        let want = faint::host::montecarlo::on_worker_stack(move || {
            let mut f = Box::new(Cbm::new(cfg, DET_SEED).unwrap());
            rows_of(f.as_mut(), maps.iter().map(|m| m.as_slice()))
        });
        assert_eq!(detect(name, &file, &dir.join(name)), want, "{name}");
    }
    let truth = std::fs::read_to_string(dir.join("maps.truth.csv")).unwrap();
    assert!(truth.starts_with("frame,range_m,velocity_m_per_s"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `faint detect`'s default Doppler configurations assume an unknown phase per frame;
/// a file without the `phase` key (written before the option existed) still loads, as
/// the zero phase it was run with, and so do the reproductions' presets.
#[test]
fn doppler_phase_defaults_and_files_without_the_key() {
    use faint::host::detect::{find, DopplerFile};
    use faint::model::doppler::Phase;
    assert_eq!(CrpfConfig::othr().model.phase, Phase::Zero);
    assert_eq!(GaussConfig::othr(1.0).model.phase, Phase::Zero);
    assert_eq!(Othr::default().model().phase, Phase::Zero);
    for name in ["crpf", "pf-tbd", "jott", "pf-lrt"] {
        let text = (find(name).unwrap().default_config)();
        let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["config"]["model"]["phase"], "unknown", "{name}");
        let model = v["config"]["model"].as_object_mut().unwrap();
        model.remove("phase");
        let old = v.to_string();
        let phase = if name == "crpf" {
            serde_json::from_str::<DopplerFile<CrpfConfig>>(&old)
                .unwrap()
                .config
                .model
                .phase
        } else {
            serde_json::from_str::<DopplerFile<GaussConfig>>(&old)
                .unwrap()
                .config
                .model
                .phase
        };
        assert_eq!(phase, Phase::Zero, "{name}");
    }
    let mut v = serde_json::to_value(CrpfConfig::othr()).unwrap();
    v["model"]["phase"] = "sideways".into();
    assert!(serde_json::from_value::<CrpfConfig>(v).is_err());
}
