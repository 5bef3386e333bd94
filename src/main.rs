//! `faint`: the command-line program. Run `faint --help`.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
    /// Reproduce a paper's figures and tables (CSV, SVG plots, Markdown table).
    #[command(subcommand)]
    Reproduce(Reproduce),
}

#[derive(Subcommand, Debug)]
enum Reproduce {
    /// CRPF-TBD vs PF-TBD, JOTT, PF-LRT on the OTHR scenario (Lu et al. 2017).
    Crpf(faint::host::reproduce::crpf::Args),
    /// MHT-TBD (modified Hough transform) in dense sea clutter, with the classic Hough TBD.
    Mht(faint::host::reproduce::mht::Args),
    /// Pei et al. 2019: PSO-PHD-TBD versus PHD-TBD (Tables 2-4, Fig. 3-5).
    Psophd(faint::host::reproduce::psophd::Args),
    /// CBMeMBer TBD, joint Doppler / micro-Doppler vs Doppler-only (rotor-UAV paper, 2023).
    Cbmember(faint::host::reproduce::cbmember::Args),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    faint::host::montecarlo::set_quiet(cli.quiet);
    match cli.command {
        Command::Scenarios => {
            for (name, about) in faint::host::scenario::catalogue() {
                println!("{name:14} {about}");
            }
            Ok(())
        }
        Command::Scenario { name } => {
            let v = faint::host::scenario::describe(&name)?;
            println!("{}", serde_json::to_string_pretty(&v)?);
            Ok(())
        }
        Command::Reproduce(r) => match r {
            Reproduce::Crpf(a) => faint::host::reproduce::crpf::run(&a),
            Reproduce::Mht(a) => faint::host::reproduce::mht::run(&a),
            Reproduce::Psophd(a) => faint::host::reproduce::psophd::run(&a),
            Reproduce::Cbmember(a) => faint::host::reproduce::cbmember::run(&a),
        },
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
