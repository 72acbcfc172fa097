//! The `umbra` binary: a thin shell over the umbra crates. Flags are parsed in [`args`],
//! checked in [`config`], and each subcommand lives in its own module.

mod args;
mod bench;
mod config;
mod export;
mod external_mask;
mod info;
mod methods;
mod render;
mod session;
mod verify;
mod view;
mod wgpu_backend;

use clap::Parser;

fn main() {
    let cli = args::Cli::parse();
    let result = match &cli.command {
        args::Command::Info(a) => info::run(a),
        args::Command::Render(a) => render::run(a),
        args::Command::Bench(a) => bench::run(a),
        args::Command::View(a) => view::run(a),
        args::Command::Export(a) => export::run(a),
        args::Command::Verify(a) => match verify::run(a) {
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
