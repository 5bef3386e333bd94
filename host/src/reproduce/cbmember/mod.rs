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
//! maps (sets "base" and "fa": joint at each `--particles` and at 1500, Doppler-only at
//! 1500). Run
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

use std::path::Path;

use anyhow::{Context, Result};
use faint_core::rng::derive_seed;

use crate::cli;
use crate::io;
use crate::shard::{self, Batch, Batches, Merged, Run, Shard};
use crate::simulate::cbmember::{MapKind, RotorUav};
use args::Effective;
use evaluation::{doppler, joint, matched, FilterSpec, Input, RunStats};

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

/// The command name in shard files.
pub const COMMAND: &str = "reproduce cbmember";

/// The filters of a set for its scene at one SNR.
type Filters = Box<dyn Fn(&RotorUav) -> Vec<FilterSpec>>;

/// One curve set of the run: its scene per SNR and its filters. Every set runs on the
/// streams of `seed` (SNR point `j`: `derive_seed(seed, j)`), so sets share their
/// random numbers.
struct SetSpec {
    name: String,
    snrs: Vec<f64>,
    seed: u64,
    make: Box<dyn Fn(f64) -> RotorUav>,
    filters: Filters,
}

impl SetSpec {
    fn new(
        name: &str,
        snrs: &[f64],
        seed: u64,
        make: impl Fn(f64) -> RotorUav + 'static,
        filters: impl Fn(&RotorUav) -> Vec<FilterSpec> + 'static,
    ) -> Self {
        Self {
            name: name.into(),
            snrs: snrs.to_vec(),
            seed,
            make: Box::new(make),
            filters: Box::new(filters),
        }
    }

    /// The batch key of SNR point `j`.
    fn key(&self, j: usize) -> String {
        format!("{} {j}", self.name)
    }
}

/// The Fig. 11 particle counts, sorted.
fn fig11(e: &Effective) -> Vec<usize> {
    let mut v = e.particles.clone();
    v.sort_unstable();
    v.dedup();
    v
}

/// The sets `--sets` selects, in the run's fixed order.
fn sets(e: &Effective, seed: u64) -> Vec<SetSpec> {
    let want = |s: &str| e.sets.iter().any(|x| x == s);
    let mut out = Vec::new();
    if want("base") {
        let parts = fig11(e);
        out.push(SetSpec::new(
            "base",
            &e.snrs,
            seed,
            RotorUav::new,
            move |sc| {
                let mut v = vec![joint(sc, 1500), doppler(sc, 1500)];
                v.extend(parts.iter().filter(|&&p| p != 1500).map(|&p| joint(sc, p)));
                v
            },
        ));
    }
    if want("blades") {
        for b in [3u32, 4] {
            out.push(SetSpec::new(
                &format!("blades {b}"),
                &e.snrs,
                seed,
                move |s| {
                    let mut sc = RotorUav::new(s);
                    sc.blades = b;
                    sc.filter.blades = b;
                    sc
                },
                |sc| vec![joint(sc, 1500)],
            ));
        }
    }
    if want("omega") {
        for w in [0.04, 0.08] {
            out.push(SetSpec::new(
                &format!("omega {w} pi"),
                &e.snrs,
                seed,
                move |s| {
                    let mut sc = RotorUav::new(s);
                    sc.omega = w * std::f64::consts::PI;
                    sc
                },
                |sc| vec![joint(sc, 1500)],
            ));
        }
    }
    if want("fa") {
        let parts = fig11(e);
        out.push(SetSpec::new(
            "target-free",
            &e.snrs,
            seed ^ 0xFA,
            |s| {
                let mut sc = RotorUav::new(s);
                sc.present = false;
                sc
            },
            move |sc| {
                let mut v = vec![joint(sc, 1500), doppler(sc, 1500)];
                v.extend(parts.iter().filter(|&&p| p != 1500).map(|&p| joint(sc, p)));
                v
            },
        ));
    }
    if want("ablation") {
        out.push(SetSpec::new(
            "ablation",
            &e.snrs,
            seed,
            RotorUav::new,
            |sc| {
                let mut est = joint(sc, 1500);
                est.cfg.estimate_blades = true;
                est.name = "joint 1500 B estimated".into();
                let mut q = joint(sc, 1500);
                q.input = Input::Quantised;
                q.name = "joint 1500 u8 map".into();
                vec![est, q]
            },
        ));
    }
    if want("merge") {
        // The narrower merge gate of the first runs, [2 m, 0.5 m/s]: a birth confirmed
        // in one frame 2-3 m behind the receding target is a second report.
        out.push(SetSpec::new("merge", &e.snrs, seed, RotorUav::new, |sc| {
            let narrow = |mut f: FilterSpec| {
                f.cfg.merge_gate = [2.0, 0.5];
                f.name = format!("{} merge gate 2 m 0.5 mps", f.name);
                f
            };
            vec![narrow(joint(sc, 1500)), narrow(doppler(sc, 1500))]
        }));
    }
    if want("known") {
        // The paper's comparison assumes the micro-Doppler parameters known: births with
        // the true V, omega and phase (referenced to frame 0), no V / omega noise.
        out.push(SetSpec::new("known", &e.snrs, seed, RotorUav::new, |sc| {
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
        }));
    }
    if want("physical") {
        out.push(SetSpec::new(
            "physical",
            &e.physical_snrs,
            seed,
            |s| {
                let mut sc = RotorUav::new(s);
                sc.map = MapKind::Physical;
                sc
            },
            |sc| {
                vec![
                    joint(sc, 1500),
                    doppler(sc, 1500),
                    matched(joint(sc, 1500)),
                    matched(doppler(sc, 1500)),
                ]
            },
        ));
    }
    out
}

/// Key of the Table 3 timing batch: one trial, so one shard (the last) measures it.
const TIMING: &str = "timing";

/// Every batch of the run, in order: each set's SNR points, then the timing.
fn keys(e: &Effective, seed: u64) -> Vec<String> {
    let mut k: Vec<String> = sets(e, seed)
        .iter()
        .flat_map(|s| (0..s.snrs.len()).map(|j| s.key(j)).collect::<Vec<_>>())
        .collect();
    if e.sets.iter().any(|x| x == "timing") {
        k.push(TIMING.into());
    }
    k
}

/// The runs of every batch that `shard` holds (all of them for `None`).
fn collect(
    args: &Args,
    e: &Effective,
    shard: Option<Shard>,
) -> Result<Vec<Batch<ciborium::Value>>> {
    let mut out = Vec::new();
    for set in sets(e, args.seed) {
        for (j, &snr) in set.snrs.iter().enumerate() {
            let sc = (set.make)(snr);
            let fs = (set.filters)(&sc);
            let label = format!("cbmember {} {snr} dB", set.name);
            let b = Batch::run(set.key(j), e.runs, shard, |range| {
                evaluation::run_point(&sc, &fs, range, derive_seed(set.seed, j as u64), &label)
            })?;
            out.push(b.into_values()?);
        }
    }
    if e.sets.iter().any(|x| x == "timing") {
        let b = Batch::run(TIMING, 1, shard, |range| -> Result<Vec<Vec<TimingRow>>> {
            range
                .map(|_| timing::timing(e.timing_frames, args.seed))
                .collect()
        })?;
        out.push(b.into_values()?);
    }
    Ok(out)
}

/// The outputs of the run from every batch and the `--previous` rows.
fn analyse(args: &Args, e: &Effective, batches: &Batches, previous: Vec<Row>) -> Result<()> {
    batches.expect(&keys(e, args.seed))?;
    let d = &args.out;
    cli::out_dir(d)?;
    let mut rows: Vec<Row> = Vec::new();
    for set in sets(e, args.seed) {
        for (j, &snr) in set.snrs.iter().enumerate() {
            let sc = (set.make)(snr);
            let fs = (set.filters)(&sc);
            let all: Vec<Vec<RunStats>> = batches.get(&set.key(j))?;
            rows.extend(evaluation::point_rows(&set.name, snr, &sc, &fs, &all));
        }
    }
    let timing_rows: Vec<TimingRow> = if e.sets.iter().any(|x| x == "timing") {
        let t: Vec<Vec<TimingRow>> = batches.get(TIMING)?;
        let t = t.into_iter().next().unwrap_or_default();
        io::write_csv(d.join("table3.csv"), &t)?;
        t
    } else {
        Vec::new()
    };
    // Earlier sets that this run did not redo.
    let ran: Vec<String> = rows.iter().map(|r| r.set.clone()).collect();
    rows.extend(previous.into_iter().filter(|r| !ran.contains(&r.set)));
    io::write_csv(d.join("curves.csv"), &rows)?;
    charts::charts(d, &rows, &fig11(e))?;
    let md = summary::summary(&rows, &timing_rows);
    io::write_text(d.join("summary.md"), &md)?;
    println!("{md}");
    Ok(())
}

/// The rows of `--previous`, read before any run (a shard file keeps them: the merge
/// does not read the file again).
fn previous(args: &Args) -> Result<Vec<Row>> {
    match &args.previous {
        Some(p) => {
            let mut r = csv::Reader::from_path(p)
                .with_context(|| format!("--previous: cannot read {}", p.display()))?;
            r.deserialize()
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("--previous: {} is not a curves.csv", p.display()))
        }
        None => Ok(Vec::new()),
    }
}

/// Runs the reproduction: the whole run, or with `--shard` (or a scheduler's array) one
/// shard's runs, written to `<out>/shards/` for `faint merge`. Table 3's timing runs in
/// one shard only (the last).
pub fn run(args: &Args) -> Result<()> {
    let e = args.effective()?;
    let shard = args.shard.resolve()?;
    cli::out_dir(&args.out)?;
    let previous = previous(args)?;
    let t0 = std::time::Instant::now();
    let batches = collect(args, &e, shard)?;
    match shard {
        None => analyse(args, &e, &Batches::whole(batches), previous),
        Some(s) => {
            let run = Run::new(COMMAND, args)?.with_meta(&previous)?;
            shard::finish(&args.out.join("shards"), &run, s, t0, &batches).map(|_| ())
        }
    }
}

/// `faint merge` of `reproduce cbmember` shards: the outputs of the unsharded run,
/// written where it writes them (under `out` if given, else the run's `--out`).
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<()> {
    let mut args: Args = m.run.args()?;
    if let Some(o) = out {
        args.out = o.to_path_buf();
    }
    let e = args.effective()?;
    let previous: Vec<Row> = m.run.meta()?;
    analyse(&args, &e, &m.batches(&keys(&e, args.seed))?, previous)
}
