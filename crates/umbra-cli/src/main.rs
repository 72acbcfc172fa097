//! The `umbra` binary: a thin shell over the umbra crates. Flags are parsed in [`args`],
//! checked in [`config`], and each subcommand lives in its own module.

mod args;
mod config;
mod info;
mod render;
mod session;

use clap::Parser;

fn main() {
    let cli = args::Cli::parse();
    let result = match &cli.command {
        args::Command::Info(a) => info::run(a),
        args::Command::Render(a) => render::run(a),
        args::Command::Verify(_) => Err(config::CliError::Other("not yet wired".into())),
    };
    if let Err(e) = result {
        eprintln!("umbra: error: {e}");
        std::process::exit(2);
    }
}
