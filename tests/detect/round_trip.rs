//! `faint simulate` then `faint detect` gives, bit for bit, the detections of the
//! reproductions' own code path (the same scenario call, the same detector and seed).

use std::path::Path;

use faint::core::detect::bernoulli::BernoulliTbd;
use faint::core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::core::detect::mht::MhtConfig;
use faint::core::detect::pf_lrt::PfLrt;
use faint::core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::core::detect::{run, Detector};
use faint::core::model::doppler::{estimate_noise_variance, DopplerReport, ModelConfig};
use faint::core::rng::Rng;
use faint::host::detect::default_classic;
use faint::host::reproduce::crpf::run_detector;
use faint::host::reproduce::mht::{Classic, Mht};
use faint::host::scenario::crpf::{Noise, Othr};
use faint::host::scenario::mht::SeaClutter;
use faint::host::scenario::phd::Variant;
use faint::host::scenario::phd::{HostFilter, SixTargets};

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
    let (code, _, err) = faint(&[
        "detect",
        name,
        "--input",
        s(input),
        "--out",
        s(out),
        "--seed",
        &DET_SEED.to_string(),
        "--min-score",
        "-1e30",
        "--no-plots",
    ]);
    assert_eq!(code, 0, "{name}: {err}");
    read_rows(&out.join("detections.csv"))
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
    assert_eq!(detect("crpf", &file, &dir.join("crpf")), want_crpf);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(PfTbd::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        false,
    );
    assert_eq!(detect("pf-tbd", &file, &dir.join("pf")), want);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(BernoulliTbd::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        false,
    );
    assert_eq!(detect("jott", &file, &dir.join("jott")), want);
    let want = doppler_rows(
        &run_detector(
            &mut *Box::new(PfLrt::<1000>::new(g, DET_SEED).unwrap()),
            &run0,
        )
        .unwrap(),
        true,
    );
    assert_eq!(detect("pf-lrt", &file, &dir.join("lrt")), want);
    // The truth file beside it: the target's Doppler in frames 7..=26 (1-based).
    let truth = std::fs::read_to_string(dir.join("othr.truth.csv")).unwrap();
    assert_eq!(truth.lines().count(), 1 + 20);
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
    assert_eq!(detect("mht", &file, &dir.join("mht")), want);
    let mut classic = Box::new(Classic::new(default_classic()).unwrap());
    let want = rows_of(classic.as_mut(), scans.iter().map(|s| s.as_slice()));
    assert_eq!(detect("hough-classic", &file, &dir.join("classic")), want);
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
        faint::host::detect::normalise_frame(&mut c, &mut Vec::new()).unwrap();
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
            "--no-plots",
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

#[test]
fn cbmember_detectors_round_trip() {
    use faint::core::detect::cbmember::CbmemberConfig;
    use faint::core::model::range_doppler::PointModel;
    use faint::host::scenario::cbmember::{HostFilter as Cbm, MapSource, RotorUav};
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
        faint::host::detect::normalise_frame(&mut m, &mut Vec::new()).unwrap();
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
