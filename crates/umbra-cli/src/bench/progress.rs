//! A progress bar on stderr while a measurement runs.

use std::io::{IsTerminal, Write};

/// Progress on stderr when it is a terminal.
pub struct Progress {
    on: bool,
    total: usize,
    label: String,
}

impl Progress {
    pub fn new(total: usize, label: &str) -> Self {
        Self { on: std::io::stderr().is_terminal(), total, label: label.to_string() }
    }
    pub fn show(&self, done: usize, what: &str) {
        if !self.on {
            return;
        }
        let width = 30;
        let filled = (done * width).checked_div(self.total).unwrap_or(width).min(width);
        let bar: String = "#".repeat(filled) + &" ".repeat(width - filled);
        eprint!("\r{} [{bar}] {done}/{} {what:<28}", self.label, self.total);
        let _ = std::io::stderr().flush();
    }
    pub fn done(&self) {
        if self.on {
            eprint!("\r{}\r", " ".repeat(self.label.len() + 80));
            let _ = std::io::stderr().flush();
        }
    }
}
