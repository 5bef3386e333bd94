//! `faint reproduce cbmember`: the rotor-UAV paper (*Weak targets detection and
//! estimation based on joint use of Doppler and micro-Doppler*, Journal of Radars, 2023):
//! CBMeMBer TBD with the joint Doppler / micro-Doppler model against the Doppler-only
//! baseline on the `rotor-uav` preset. Fig. 7 (Pd vs SNR), Fig. 8 (mean OSPA vs SNR),
//! Fig. 9 (blade count 2 / 3 / 4), Fig. 10 (rotor rate), Fig. 11 (particle counts),
//! Table 3 (time per frame), false alarms per frame from target-free runs, and the
//! ablations: the physical map generator (eq. 11 + slow-time FFT; preset filter and one
//! with `zeta_v` matched to the physical peak width), `B` estimated, the quantised `u8` map.
//!
//! Per SNR point and run: one truth and 40 maps; every filter of a set runs on the same
//! maps (set "base": joint at each `--particles` and at 1500, Doppler-only at 1500). Run
//! `i` of SNR point `j` uses `Rng::from_stream(derive_seed(seed, j), i)` in every set
//! (common random numbers across sets), so results are identical for any thread count.
//! Scores (preset): after a 5-frame burn-in a frame is a detection when a reported
//! component (existence > 0.5) is within 3 range bins and 1 m/s of the truth; Pd is over
//! (run, frame) pairs with a Clopper-Pearson 95 % interval (the frames of one run are
//! correlated, so the interval is optimistic); OSPA over (range m, velocity m/s),
//! `c = 5`, `p = 2`, averaged over all 40 frames (as the paper) and after the burn-in.
//!
//! The code is split by role: [`Args`] and its checks in `args.rs`, the filters of a
//! set, one run and a set's runs in `evaluation.rs`, Table 3's timing in `timing.rs`,
//! the SVG charts in `charts.rs` and the Markdown summary in `summary.rs`; [`run`] runs
//! the sets and chains them.

mod args;
mod charts;
mod evaluation;
mod summary;
mod timing;

use anyhow::{Context, Result};

use crate::cli;
use crate::io;
use crate::simulate::cbmember::{MapKind, RotorUav};
use evaluation::{doppler, joint, matched, run_set, FilterSpec, Input};

pub use args::{Args, SETS};
pub use evaluation::Row;
pub use timing::TimingRow;

/// The paper's numbers.
pub mod paper {
    /// Table 3 (MATLAB R2022b, AMD R4750U): seconds per frame, `(algorithm, L_max, s)`.
    pub const TABLE3: [(&str, usize, f64); 4] = [
        ("Doppler-only", 1500, 0.068),
        ("joint", 700, 0.066),
        ("joint", 1000, 0.101),
        ("joint", 1500, 0.143),
    ];
    /// Sensitivity gain of joint over Doppler-only at Pd 0.9-0.92 (dB).
    pub const GAIN_DB: f64 = 2.0;
    /// Mean OSPA level reached from about 0.5 dB (Fig. 8; units not stated).
    pub const OSPA_SETTLED: f64 = 0.1;
}

/// Runs the reproduction.
pub fn run(args: &Args) -> Result<()> {
    let e = args.effective()?;
    let pool = crate::montecarlo::pool();
    let want = |s: &str| e.sets.iter().any(|x| x == s);
    let d = &args.out;
    cli::out_dir(d)?;
    let previous: Vec<Row> = match &args.previous {
        Some(p) => {
            let mut r = csv::Reader::from_path(p)
                .with_context(|| format!("--previous: cannot read {}", p.display()))?;
            r.deserialize()
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("--previous: {} is not a curves.csv", p.display()))?
        }
        None => Vec::new(),
    };
    let mut rows: Vec<Row> = Vec::new();
    let mut fig11: Vec<usize> = e.particles.clone();
    fig11.sort_unstable();
    fig11.dedup();
    let save = |rows: &[Row]| -> Result<()> { io::write_csv(d.join("curves.csv"), rows) };

    if want("base") {
        let parts = fig11.clone();
        rows.extend(run_set(
            "base",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut v = vec![joint(sc, 1500), doppler(sc, 1500)];
                v.extend(parts.iter().filter(|&&p| p != 1500).map(|&p| joint(sc, p)));
                v
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("blades") {
        for b in [3u32, 4] {
            rows.extend(run_set(
                &format!("blades {b}"),
                &e.snrs,
                e.runs,
                args.seed,
                &|s| {
                    let mut sc = RotorUav::new(s);
                    sc.blades = b;
                    sc.filter.blades = b;
                    sc
                },
                &|sc| vec![joint(sc, 1500)],
                pool,
            )?);
        }
        save(&rows)?;
    }
    if want("omega") {
        for w in [0.04, 0.08] {
            rows.extend(run_set(
                &format!("omega {w} pi"),
                &e.snrs,
                e.runs,
                args.seed,
                &|s| {
                    let mut sc = RotorUav::new(s);
                    sc.omega = w * std::f64::consts::PI;
                    sc
                },
                &|sc| vec![joint(sc, 1500)],
                pool,
            )?);
        }
        save(&rows)?;
    }
    if want("fa") {
        rows.extend(run_set(
            "target-free",
            &e.snrs,
            e.runs,
            args.seed ^ 0xFA,
            &|s| {
                let mut sc = RotorUav::new(s);
                sc.present = false;
                sc
            },
            &|sc| vec![joint(sc, 1500), doppler(sc, 1500)],
            pool,
        )?);
        save(&rows)?;
    }
    if want("ablation") {
        rows.extend(run_set(
            "ablation",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut est = joint(sc, 1500);
                est.cfg.estimate_blades = true;
                est.name = "joint 1500 B estimated".into();
                let mut q = joint(sc, 1500);
                q.input = Input::Quantised;
                q.name = "joint 1500 u8 map".into();
                vec![est, q]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("merge") {
        // The narrower merge gate of the first runs, [2 m, 0.5 m/s]: a birth confirmed
        // in one frame 2-3 m behind the receding target is a second report.
        rows.extend(run_set(
            "merge",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let narrow = |mut f: FilterSpec| {
                    f.cfg.merge_gate = [2.0, 0.5];
                    f.name = format!("{} merge gate 2 m 0.5 mps", f.name);
                    f
                };
                vec![narrow(joint(sc, 1500)), narrow(doppler(sc, 1500))]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("known") {
        // The paper's comparison assumes the micro-Doppler parameters known: births with
        // the true V, omega and phase (referenced to frame 0), no V / omega noise.
        rows.extend(run_set(
            "known",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut f = joint(sc, 1500);
                let b = &mut f.cfg.birth;
                b.blade_speed = [sc.blade_speed as f32; 2];
                b.omega = [sc.omega as f32; 2];
                b.theta = [sc.theta0 as f32; 2];
                b.phase_from_frame0 = true;
                f.cfg.process.blade_speed = 0.0;
                f.cfg.process.omega = 0.0;
                f.name = "joint 1500 micro-Doppler known".into();
                vec![f]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("physical") {
        rows.extend(run_set(
            "physical",
            &e.physical_snrs,
            e.runs,
            args.seed,
            &|s| {
                let mut sc = RotorUav::new(s);
                sc.map = MapKind::Physical;
                sc
            },
            &|sc| {
                vec![
                    joint(sc, 1500),
                    doppler(sc, 1500),
                    matched(joint(sc, 1500)),
                    matched(doppler(sc, 1500)),
                ]
            },
            pool,
        )?);
        save(&rows)?;
    }
    let timing_rows = if want("timing") {
        let t = timing::timing(e.timing_frames, args.seed)?;
        io::write_csv(d.join("table3.csv"), &t)?;
        t
    } else {
        Vec::new()
    };
    // Earlier sets that this run did not redo.
    let ran: Vec<String> = rows.iter().map(|r| r.set.clone()).collect();
    rows.extend(previous.into_iter().filter(|r| !ran.contains(&r.set)));
    save(&rows)?;
    charts::charts(d, &rows, &fig11)?;
    let md = summary::summary(&rows, &timing_rows);
    io::write_text(d.join("summary.md"), &md)?;
    println!("{md}");
    Ok(())
}
