//! What a command's checked flags ask for: a run, or only a listing (`--method help`,
//! `--suite list`), which is answered before any other flag is read.

use crate::backend::Backend;

/// A command's flags, checked.
pub enum Checked<T> {
    /// Print a list and do nothing else.
    List(Listing),
    /// Run the command with this configuration.
    Run(T),
}

/// The lists a command can print instead of running.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Listing {
    /// `--method help` / `--methods help` (or `list`): the backend's methods, one per line.
    Methods(Backend),
    /// `bench --suite list`: the benchmark suites, one per line.
    Suites,
}
