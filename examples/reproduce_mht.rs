//! Stand-in for `faint reproduce mht` until the CLI subcommand is wired:
//! `cargo run --release --example reproduce_mht -- --quick`.
use clap::Parser;

#[derive(Parser, Debug)]
struct Cli {
    #[command(flatten)]
    args: faint_host::reproduce::mht::Args,
}

fn main() -> anyhow::Result<()> {
    let cli = Cli::parse();
    faint_host::reproduce::mht::run(&cli.args)
}
