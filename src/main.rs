//! `faint`: the command-line program. Run `faint --help`.

use std::process::ExitCode;

use std::path::PathBuf;

use anyhow::Context;
use clap::{Parser, Subcommand};
use faint::detect::ScoreKind;
use faint::host::detect;

#[derive(Parser, Debug)]
#[command(
    name = "faint",
    version,
    about = "Track-before-detect for dim radar targets: simulate, detect, reproduce the papers"
)]
struct Cli {
    /// Hide progress bars.
    #[arg(long, global = true)]
    quiet: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// List the built-in scenario presets.
    Scenarios,
    /// Print one scenario preset (every value, including the documented choices) as JSON.
    Scenario {
        /// Preset name, as listed by `faint scenarios`.
        name: String,
    },
    /// Reproduce a paper's figures and tables (CSV, SVG charts, Markdown table).
    #[command(subcommand)]
    Reproduce(Reproduce),
    /// Run a detector on recorded frames (a .npy/.npz array or a CSV plot list).
    Detect(DetectArgs),
    /// Write a preset's frames in the format `faint detect` reads, with a truth file.
    Simulate(SimulateArgs),
    /// Thresholds at a false-alarm probability for a detector, from noise-only data or
    /// from a noise model estimated on a recording (for `faint detect --calibration`).
    Calibrate {
        #[command(flatten)]
        args: faint::host::calibrate::Args,
        #[command(flatten)]
        shard: faint::host::shard::ShardArg,
    },
    /// One detector on data from the physics simulator of its input kind: calibrated
    /// Pfa measured, Pd against SNR, the SNR at Pd 0.9 (one Markdown table row).
    Evaluate(faint::host::physics::evaluate::Args),
    /// Join the shard files of a `--shard I/N` run (folders or files) into the outputs of
    /// the unsharded run, after checking they are every shard of one run.
    Merge {
        /// Shard files, or folders whose *.faint-shard files are read.
        #[arg(required = true)]
        inputs: Vec<PathBuf>,
        /// Write the outputs here instead of the run's --out.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Drive detectors with mutated configurations and hostile frames; write the findings.
    Fuzz(faint::host::reliability::cli::FuzzArgs),
    /// Stream plausible frames through detectors without reset; report cost drift and memory.
    Soak(faint::host::reliability::cli::SoakArgs),
}

#[derive(clap::Args, Debug)]
struct DetectArgs {
    /// Detector, as listed by `faint detect --list`.
    #[arg(required_unless_present = "list")]
    detector: Option<String>,
    /// The frames: `.npy`/`.npz` (Doppler frames, power cubes) or `.csv` (plot lists).
    #[arg(long, required_unless_present_any = ["list", "print_config"])]
    input: Option<PathBuf>,
    /// JSON configuration (`--print-config` writes the defaults); unknown keys are errors.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Output folder [default: out/detect/<detector>].
    #[arg(long)]
    out: Option<PathBuf>,
    /// Seed of the detector's random stream.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Truth file (`frame,<position columns>`, as `faint simulate` writes) to score the
    /// detections against with GOSPA.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Number of the first frame in the truth file: 0 (as `faint simulate` writes) or 1
    /// (a file numbered from 1); the truth's frame `f` is the input's frame `f - N`.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=1))]
    truth_first_frame: u64,
    /// GOSPA cut-off `c` in the position's units, finite and > 0 [default: 2 Hz Doppler,
    /// 100 m x/y, 3 px for pixels].
    #[arg(long, allow_hyphen_values = true)]
    gospa_c: Option<f64>,
    /// Write (and score) only detections with at least this score [default: 0.5 for an
    /// existence probability, everything otherwise].
    #[arg(long, allow_hyphen_values = true, conflicts_with = "calibration")]
    min_score: Option<f32>,
    /// Write (and score) only detections above the per-frame thresholds of a calibration
    /// file (`faint calibrate`), made for this detector and configuration.
    #[arg(long)]
    calibration: Option<PathBuf>,
    /// Also write every frame's full report (`reports.json`).
    #[arg(long)]
    reports: bool,
    /// Skip the SVG charts (`--no-plots` is an alias).
    #[arg(long, alias = "no-plots")]
    no_charts: bool,
    /// List the detectors with their input kind.
    #[arg(long)]
    list: bool,
    /// Print the detector's default configuration as JSON and exit.
    #[arg(long)]
    print_config: bool,
}

#[derive(clap::Args, Debug)]
struct SimulateArgs {
    /// Scenario preset: othr, sea-clutter, six-targets, rotor-uav or dim-point.
    scenario: String,
    /// Frames file to write (.npy for othr, six-targets, rotor-uav and dim-point, .csv for
    /// sea-clutter); the truth goes beside it as <stem>.truth.csv.
    #[arg(long)]
    out: PathBuf,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// SNR in dB, in [-60, 60] (othr: eq. 18 of Lu et al. 2017, default 8; six-targets:
    /// default 9; rotor-uav: default 10).
    #[arg(long, allow_hyphen_values = true)]
    snr_db: Option<f64>,
    /// Frames to write, 1 to 1000000 (at most the preset's 40 for six-targets,
    /// rotor-uav and dim-point) [default: one run of the preset].
    #[arg(long)]
    frames: Option<usize>,
    /// Clutter plots per scan, in [0, 10000] (sea-clutter) [default: 80].
    #[arg(long, allow_hyphen_values = true)]
    lambda: Option<f32>,
    /// SNR `a / sigma`, linear, in [0, 100] (dim-point) [default: 2].
    #[arg(long, allow_hyphen_values = true)]
    snr: Option<f64>,
    /// Target speed in px/frame, 1 or 2 (dim-point) [default: 1].
    #[arg(long)]
    speed: Option<u8>,
    /// Background noise (othr).
    #[arg(long, value_enum, default_value = "gaussian")]
    noise: faint::host::simulate::crpf::Noise,
}

#[derive(Subcommand, Debug)]
enum Reproduce {
    /// CRPF-TBD vs PF-TBD, JOTT, PF-LRT on the OTHR scenario (Lu et al. 2017).
    Crpf(faint::host::reproduce::crpf::Args),
    /// MHT-TBD (modified Hough transform) in dense sea clutter, with the classic Hough TBD.
    Mht(faint::host::reproduce::mht::Args),
    /// Pei et al. 2019: PSO-PHD-TBD versus PHD-TBD (Tables 2-4, Fig. 3-5).
    #[command(alias = "psophd")]
    Phd(faint::host::reproduce::phd::Args),
    /// CBMeMBer TBD, joint Doppler / micro-Doppler vs Doppler-only (rotor-UAV paper, 2023).
    Cbmember(faint::host::reproduce::cbmember::Args),
    /// DP-TBD: second-order DP vs Arnold and Pulford first-order DP (Wang, Zhang 2016, Fig. 5-7).
    Dp(faint::host::reproduce::dp::Args),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    faint::host::montecarlo::set_quiet(cli.quiet);
    match cli.command {
        Command::Scenarios => {
            for (name, about) in faint::host::simulate::catalogue() {
                println!("{name:14} {about}");
            }
            Ok(())
        }
        Command::Scenario { name } => {
            let v = faint::host::simulate::describe(&name)?;
            println!("{}", serde_json::to_string_pretty(&v)?);
            Ok(())
        }
        Command::Detect(a) => run_detect(&a),
        Command::Simulate(a) => {
            let done = faint::host::simulate::simulate(&faint::host::simulate::Spec {
                scenario: a.scenario,
                out: a.out,
                seed: a.seed,
                snr_db: a.snr_db,
                frames: a.frames,
                lambda: a.lambda,
                snr: a.snr,
                speed: a.speed,
                noise: a.noise,
            })?;
            println!(
                "wrote {} frames to {} and the truth to {}",
                done.frames,
                done.frames_path.display(),
                done.truth_path.display()
            );
            Ok(())
        }
        Command::Calibrate { args: a, shard } => match shard.resolve()? {
            Some(s) => {
                let path = faint::host::calibrate::run_shard(&a, s)?;
                println!(
                    "{}: shard {s} written to {}; merge with `faint merge {}`",
                    a.detector,
                    path.display(),
                    faint::host::calibrate::shard_dir(&a.out).display()
                );
                Ok(())
            }
            None => {
                let cal = faint::host::calibrate::run(&a)?;
                print_calibration(&cal, &a.out);
                Ok(())
            }
        },
        Command::Merge { inputs, out } => {
            use faint::host::{calibrate, reproduce};
            let m = faint::host::shard::read(&inputs)?;
            match m.run.command.as_str() {
                c if reproduce::COMMANDS.contains(&c) => reproduce::merge(&m, out.as_deref())?,
                calibrate::COMMAND => {
                    let cal = calibrate::merge(&m, out.as_deref())?;
                    let args: calibrate::Args = m.run.args()?;
                    print_calibration(&cal, out.as_deref().unwrap_or(&args.out));
                }
                other => anyhow::bail!(
                    "{}: shards of `faint {other}`, which this faint cannot merge",
                    m.files[0].display()
                ),
            }
            println!("merged {} shards of `faint {}`", m.count, m.run.command);
            Ok(())
        }
        Command::Evaluate(a) => {
            let ev = faint::host::physics::evaluate::run(&a)?;
            println!("SNR: {}", ev.snr_definition);
            if let Some(g) = ev.gate {
                println!("gate: {g} {} ({})", ev.gate_unit, ev.input);
            }
            for c in &ev.curve {
                println!(
                    "  SNR {:6.2} dB: Pd {:.3} [{:.3}, {:.3}] (declared anywhere {:.3})",
                    c.snr_db, c.pd.p, c.pd.lo, c.pd.hi, c.declared.p
                );
            }
            println!("{}", faint::host::physics::evaluate::Evaluation::header());
            println!("{}", ev.row());
            if let Some(o) = &a.out {
                println!("curve written to {}", o.display());
            }
            Ok(())
        }
        Command::Fuzz(a) => faint::host::reliability::cli::fuzz_command(&a),
        Command::Soak(a) => faint::host::reliability::cli::soak_command(&a),
        Command::Reproduce(r) => match r {
            Reproduce::Crpf(a) => faint::host::reproduce::crpf::run(&a),
            Reproduce::Mht(a) => faint::host::reproduce::mht::run(&a),
            Reproduce::Phd(a) => faint::host::reproduce::phd::run(&a),
            Reproduce::Cbmember(a) => faint::host::reproduce::cbmember::run(&a),
            Reproduce::Dp(a) => faint::host::reproduce::dp::run(&a),
        },
    }
}

/// The summary lines of a calibration written to `out`.
fn print_calibration(cal: &faint::host::detect::calibration::Calibration, out: &std::path::Path) {
    let values: Vec<f32> = cal.thresholds.iter().filter_map(|t| t.value).collect();
    let lo = values.iter().copied().fold(f32::INFINITY, f32::min);
    let hi = values.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    println!(
        "{}: Pfa {} per frame from frame {} to {}: {} noise runs of {} frames; {} thresholds on the {} score{}; written to {}",
        cal.detector,
        cal.pfa,
        cal.burn_in,
        cal.run_frames - 1,
        cal.runs,
        cal.run_frames,
        cal.thresholds.len(),
        cal.score,
        if values.is_empty() {
            " (every one minus infinity: the noise reported nothing)".to_string()
        } else {
            format!(" in [{lo}, {hi}]")
        },
        out.display()
    );
    if let Some(got) = cal.achieved_pfa().filter(|&g| g < 0.5 * cal.pfa) {
        println!(
            "{}: note: the {} score is discrete and ties at the thresholds: they achieve Pfa {got:.4} on the noise runs (mean over frames), below the {} asked",
            cal.detector, cal.score, cal.pfa
        );
    }
}

fn run_detect(a: &DetectArgs) -> anyhow::Result<()> {
    if a.list {
        for e in detect::REGISTRY {
            println!("{:15} {:16} {}", e.name, format!("{:?}", e.input), e.about);
            println!("{:15} input: {}", "", e.input.describe());
        }
        return Ok(());
    }
    let name = a.detector.as_deref().unwrap_or_default();
    let entry = detect::find(name)?;
    if a.print_config {
        println!("{}", (entry.default_config)());
        return Ok(());
    }
    let input = a.input.as_deref().context("--input is required")?;
    detect::check_input(input)?;
    if let Some(c) = a.gospa_c {
        anyhow::ensure!(
            c.is_finite() && c > 0.0,
            "--gospa-c {c}: must be finite and > 0"
        );
    }
    if let Some(m) = a.min_score {
        anyhow::ensure!(!m.is_nan(), "--min-score: must be a number");
    }
    let text = match &a.config {
        Some(p) => Some(
            std::fs::read_to_string(p)
                .with_context(|| format!("--config {}: cannot read", p.display()))?,
        ),
        None => None,
    };
    let out_dir = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/detect").join(entry.name));
    let calibration = match &a.calibration {
        Some(p) => Some(detect::calibration::Calibration::load(p)?),
        None => None,
    };
    let req = detect::Request {
        input,
        config: a.config.as_deref().zip(text.as_deref()),
        seed: a.seed,
        reports: a.reports,
        restart_every: None,
        runs: None,
    };
    let outcome = (entry.run)(&req)?;
    if let Some(cal) = &calibration {
        let config: serde_json::Value = match &text {
            Some(t) => serde_json::from_str(t)?,
            None => serde_json::from_str(&(entry.default_config)())?,
        };
        cal.check(entry.name, &config, outcome.frames)?;
    }
    let truth = match &a.truth {
        Some(p) => {
            anyhow::ensure!(
                !outcome.position.is_empty(),
                "--truth: {} reports no positions to compare",
                entry.name
            );
            let names: Vec<&str> = outcome
                .position
                .iter()
                .map(|&i| outcome.state_names.get(i).copied().unwrap_or("?"))
                .collect();
            Some(detect::read_truth(
                p,
                &names,
                outcome.frames,
                a.truth_first_frame as usize,
            )?)
        }
        None => None,
    };
    let min_score = a.min_score.unwrap_or(match outcome.score {
        ScoreKind::Existence => 0.5,
        _ => f32::NEG_INFINITY,
    });
    let select = match &calibration {
        Some(c) => detect::Selection::Calibrated(c),
        None => detect::Selection::MinScore(min_score),
    };
    let pixels = outcome
        .position
        .first()
        .and_then(|&i| outcome.state_names.get(i))
        .is_some_and(|n| n.ends_with("_px"));
    let c = a.gospa_c.unwrap_or(if outcome.position.len() == 1 {
        2.0
    } else if pixels {
        3.0
    } else {
        100.0
    });
    let t = faint::host::timing::thread_cpu_seconds();
    let w = detect::write(&outcome, &out_dir, select, truth.as_deref(), c)?;
    let write_seconds = faint::host::timing::thread_cpu_seconds() - t;
    let t = faint::host::timing::thread_cpu_seconds();
    if !a.no_charts {
        detect::write_charts(&outcome, &out_dir, select)?;
    }
    let chart_seconds = faint::host::timing::thread_cpu_seconds() - t;
    let rule = match &calibration {
        Some(c) => format!(
            "above the thresholds at Pfa {} per frame from frame {}",
            c.pfa, c.burn_in
        ),
        None => format!("score >= {min_score}"),
    };
    println!(
        "{}: {} frames, {} detections ({rule}) written to {}",
        entry.name,
        outcome.frames,
        w.detections,
        w.dir.display()
    );
    for n in &outcome.notes {
        println!("{}: {n}", entry.name);
    }
    for w in &outcome.warnings {
        eprintln!("warning: {w}");
    }
    println!(
        "CPU time: read {:.4} s, detector {:.4} s, collecting {:.4} s, writing {:.4} s, charts {:.4} s",
        outcome.read_seconds,
        outcome.detector_seconds,
        outcome.collect_seconds,
        write_seconds,
        chart_seconds
    );
    if let Some(g) = w.mean_gospa {
        println!("mean GOSPA (c = {c}, p = 2, alpha = 2): {g:.4}");
    }
    Ok(())
}

/// A closed pipe (`faint detect --list | head`) ends the process quietly, as it does for
/// other Unix tools, instead of a panic in `println!`: the signal's default action is
/// restored (Rust ignores SIGPIPE at start-up).
#[cfg(unix)]
fn default_sigpipe() {
    // SAFETY: called first in `main`, before any thread starts; `signal` with `SIG_DFL`
    // has no other precondition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    #[cfg(unix)]
    default_sigpipe();
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
