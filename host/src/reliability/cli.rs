//! `faint fuzz` and `faint soak`.

use std::path::PathBuf;

use anyhow::{bail, Result};
use rayon::prelude::*;

use super::soak::{Shape, Soak};
use super::targets::{run, Job, Outcome};
use super::{overflow_checks_on, Options, Tally};
use crate::montecarlo::progress_bar;

/// Cases per parallel work item (each item builds its own pair of detectors).
const CHUNK: u64 = 32;

/// Arguments of `faint fuzz`.
#[derive(clap::Args, Debug, Clone)]
pub struct FuzzArgs {
    /// Detectors (names of `faint detect --list`), or `all`.
    #[arg(default_value = "all")]
    pub detectors: Vec<String>,
    /// Cases per detector (a case: one configuration and its frames).
    #[arg(long, default_value_t = 256)]
    pub cases: u64,
    /// Frames per case.
    #[arg(long, default_value_t = 16)]
    pub frames_per_case: usize,
    /// Master seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// First case index (to continue a campaign).
    #[arg(long, default_value_t = 0)]
    pub first: u64,
    /// Output folder: `tally.json`, `tally.md` and one JSON file per finding.
    #[arg(long, default_value = "out/fuzz")]
    pub out: PathBuf,
    /// Instead of a campaign, replay one coverage-guided input (a file of the `fuzz/`
    /// targets, e.g. a crash) on the one detector named; a finding is written to `--out`
    /// in the corpus format.
    #[arg(long)]
    pub input: Option<PathBuf>,
}

/// Arguments of `faint soak`.
#[derive(clap::Args, Debug, Clone)]
pub struct SoakArgs {
    /// Detectors (names of `faint detect --list`), or `all`.
    #[arg(default_value = "all")]
    pub detectors: Vec<String>,
    /// Frames streamed through each detector without a reset.
    #[arg(long, default_value_t = 100_000)]
    pub frames: u64,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Configuration size: `preset`, or `reduced` (smaller cubes, maps, images and
    /// particle counts for PHD-TBD, PSO-PHD-TBD, CBMeMBer and DP-TBD, see
    /// `reliability::soak::Shape`; the other detectors unchanged).
    #[arg(long, value_enum, default_value_t = Shape::Preset)]
    pub shape: Shape,
    /// Output folder: `soak.json` and `soak.md`.
    #[arg(long, default_value = "out/soak")]
    pub out: PathBuf,
}

fn names(list: &[String]) -> Result<Vec<&'static str>> {
    if list.iter().any(|d| d == "all") {
        return Ok(super::targets::names().collect());
    }
    list.iter()
        .map(|d| Ok(crate::detect::find(d)?.name))
        .collect()
}

/// Adds `b` into `a`.
pub fn merge(a: &mut Tally, b: Tally) {
    a.cases += b.cases;
    a.rejected_parse += b.rejected_parse;
    a.rejected_config += b.rejected_config;
    a.frames += b.frames;
    a.rejected_frames += b.rejected_frames;
    a.lockstep_frames += b.lockstep_frames;
    a.panics += b.panics;
    a.non_finite += b.non_finite;
    a.existence += b.existence;
    a.changed_on_error += b.changed_on_error;
    a.slow += b.slow;
    a.slowest_step_s = a.slowest_step_s.max(b.slowest_step_s);
    a.seconds += b.seconds;
    a.findings.extend(b.findings);
}

/// Runs the campaign of `args` on each detector (cases split across threads in chunks;
/// each chunk is sequential, so the result does not depend on the thread count).
pub fn fuzz_all(args: &FuzzArgs) -> Result<Vec<Tally>> {
    crate::cli::count("--cases", args.cases as usize, 1..=1 << 40)?;
    crate::cli::count("--frames-per-case", args.frames_per_case, 1..=1_000_000)?;
    let dets = names(&args.detectors)?;
    let mut items = Vec::new();
    for (d, name) in dets.iter().enumerate() {
        let mut first = args.first;
        let end = args.first.saturating_add(args.cases);
        while first < end {
            let n = CHUNK.min(end - first);
            items.push((d, *name, first, n));
            first += n;
        }
    }
    let pb = progress_bar("fuzz", items.len());
    let parts: Vec<Result<(usize, Tally)>> = crate::montecarlo::pool().install(|| {
        items
            .par_iter()
            .map(|&(d, name, first, cases)| {
                let opts = Options {
                    seed: args.seed,
                    first,
                    cases,
                    frames_per_case: args.frames_per_case,
                };
                let r = match run(name, Job::Fuzz(opts))? {
                    Outcome::Fuzz(t) => (d, t),
                    Outcome::Soak(_) => bail!("internal: a soak outcome from a fuzz job"),
                };
                pb.inc(1);
                Ok(r)
            })
            .collect()
    });
    pb.finish_and_clear();
    let mut out: Vec<Tally> = dets
        .iter()
        .map(|n| Tally {
            detector: n.to_string(),
            ..Tally::default()
        })
        .collect();
    for p in parts {
        let (d, t) = p?;
        merge(&mut out[d], t);
    }
    Ok(out)
}

/// Markdown table of campaign tallies.
pub fn fuzz_table(t: &[Tally]) -> String {
    let mut s = String::from(
        "| detector | cases | configs rejected (parse / core) | frames | frames rejected | lockstep frames | panics | NaN/inf | existence | changed on error | slow | slowest step (ms) |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for x in t {
        s.push_str(&format!(
            "| {} | {} | {} / {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1} |\n",
            x.detector,
            x.cases,
            x.rejected_parse,
            x.rejected_config,
            x.frames,
            x.rejected_frames,
            x.lockstep_frames,
            x.panics,
            x.non_finite,
            x.existence,
            x.changed_on_error,
            x.slow,
            1e3 * x.slowest_step_s
        ));
    }
    s
}

/// `faint fuzz`.
pub fn fuzz_command(args: &FuzzArgs) -> Result<()> {
    if !overflow_checks_on() {
        eprintln!(
            "note: overflow checks are off in this build; run with `--profile checked` to \
             catch overflow panics"
        );
    }
    crate::cli::out_dir(&args.out)?;
    if let Some(input) = &args.input {
        let [name] = names(&args.detectors)?[..] else {
            bail!("--input replays on one detector: name exactly one");
        };
        let data = std::fs::read(input)
            .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", input.display()))?;
        let Some(f) = super::guided::finding(name, &data)? else {
            println!("{name}: no finding");
            return Ok(());
        };
        let kind = serde_json::to_value(f.kind)?;
        let path = args.out.join(format!(
            "{name}-{}-guided.json",
            kind.as_str().unwrap_or("finding")
        ));
        crate::io::write_text(&path, &serde_json::to_string_pretty(&f)?)?;
        bail!(
            "{name}: {:?}: {} (written to {})",
            f.kind,
            f.message,
            path.display()
        );
    }
    let tallies = fuzz_all(args)?;
    for t in &tallies {
        for (i, f) in t.findings.iter().enumerate() {
            let path = args.out.join(format!(
                "{}-{}-{}-{i}.json",
                t.detector,
                serde_json::to_value(f.kind)?.as_str().unwrap_or("finding"),
                f.case
            ));
            crate::io::write_text(&path, &serde_json::to_string_pretty(f)?)?;
        }
    }
    crate::io::write_text(
        args.out.join("tally.json"),
        &serde_json::to_string_pretty(&tallies)?,
    )?;
    let table = fuzz_table(&tallies);
    crate::io::write_text(args.out.join("tally.md"), &table)?;
    print!("{table}");
    let failures: u64 = tallies.iter().map(Tally::failures).sum();
    if failures > 0 {
        bail!(
            "{failures} finding(s); each is a JSON file in {}",
            args.out.display()
        );
    }
    Ok(())
}

/// Markdown table of soak runs.
pub fn soak_table(s: &[Soak]) -> String {
    let mut t = String::from(
        "| detector | shape | frames | errors | NaN/inf outputs | us/frame first block | last block | worst block | RSS before (KiB) | after | max | work counters, first -> last block |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n",
    );
    for x in s {
        t.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {} | {} | {} | {} |\n",
            x.detector,
            x.shape.name(),
            x.frames,
            x.errors,
            x.bad_outputs,
            x.first_us,
            x.last_us,
            x.worst_us,
            x.rss_before_kib,
            x.rss_after_kib,
            x.rss_max_kib,
            work_text(x)
        ));
    }
    t
}

/// `name: first -> last` for each work counter of a soak run.
fn work_text(x: &Soak) -> String {
    let (Some(a), Some(b)) = (x.blocks_work.first(), x.blocks_work.last()) else {
        return String::new();
    };
    x.work_names
        .iter()
        .enumerate()
        .map(|(i, n)| format!("{n}: {:.3} -> {:.3}", a[i], b[i]))
        .collect::<Vec<_>>()
        .join("; ")
}

/// `faint soak` (one detector at a time, so that the memory readings are its own). The
/// results so far are written after each detector.
pub fn soak_command(args: &SoakArgs) -> Result<()> {
    crate::cli::count("--frames", args.frames as usize, 1..=1 << 40)?;
    crate::cli::out_dir(&args.out)?;
    let mut all = Vec::new();
    for name in names(&args.detectors)? {
        match run(name, Job::Soak(args.frames, args.seed, args.shape))? {
            Outcome::Soak(s) => {
                eprintln!(
                    "{name}: {} frames, {:.1} -> {:.1} us/frame",
                    s.frames, s.first_us, s.last_us
                );
                all.push(s);
            }
            Outcome::Fuzz(_) => bail!("internal: a fuzz outcome from a soak job"),
        }
        crate::io::write_text(
            args.out.join("soak.json"),
            &serde_json::to_string_pretty(&all)?,
        )?;
        crate::io::write_text(args.out.join("soak.md"), &soak_table(&all))?;
    }
    print!("{}", soak_table(&all));
    Ok(())
}
