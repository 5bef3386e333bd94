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
