//! The `umbra` binary: a thin shell over the umbra crates. Flags are parsed in [`args`],
//! checked into one configuration per command in [`config`], and each subcommand lives in its
//! own module, which receives only its configuration.

mod args;
mod backend;
mod bench;
mod config;
mod error;
mod export;
mod external_mask;
mod info;
mod methods;
mod render;
mod scenes;
mod session;
mod verify;
mod view;
mod wgpu_backend;

use clap::Parser;

use config::{BenchConfig, Checked, ExportConfig, InfoConfig, Listing, RenderConfig, VerifyConfig, WindowConfig};
use error::CliError;

/// Prints what a `--method help` or `--suite list` asked for.
fn list(l: Listing) {
    match l {
        Listing::Methods(backend) => methods::list_methods(backend),
        Listing::Suites => bench::list_suites(),
    }
}

/// Runs `run` on a checked configuration, or prints the list it asked for instead.
fn run_checked<T, R>(
    checked: Checked<T>,
    listed: R,
    run: impl FnOnce(&T) -> Result<R, CliError>,
) -> Result<R, CliError> {
    match checked {
        Checked::List(l) => {
            list(l);
            Ok(listed)
        }
        Checked::Run(c) => run(&c),
    }
}

fn main() {
    let cli = args::Cli::parse();
    let result = match &cli.command {
        args::Command::Info(a) => InfoConfig::from_args(a).and_then(|c| info::run(&c)),
        args::Command::Render(a) => RenderConfig::from_args(a).and_then(|c| run_checked(c, (), render::run)),
        args::Command::Bench(a) => BenchConfig::from_args(a).and_then(|c| run_checked(c, (), bench::run)),
        args::Command::View(a) => WindowConfig::from_args(a).and_then(|c| run_checked(c, (), view::run)),
        args::Command::Export(a) => ExportConfig::from_args(a).and_then(|c| export::run(&c)),
        args::Command::Verify(a) => match VerifyConfig::from_args(a).and_then(|c| run_checked(c, true, verify::run)) {
            // A method that must be exact was not: exit status 1 (errors are 2).
            Ok(false) => std::process::exit(1),
            Ok(true) => Ok(()),
            Err(e) => Err(e),
        },
    };
    if let Err(e) = result {
        eprintln!("umbra: error: {e}");
        std::process::exit(2);
    }
}
