//! Shared helpers of the CLI's integration tests: run the `umbra` binary as a user would and
//! read what it printed; scratch files under Cargo's per-target temporary directory.

#![allow(dead_code)] // each test binary compiles in what it needs

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs `umbra` with `args` and waits for it.
pub fn umbra(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_umbra")).args(args).output().expect("run umbra")
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Standard output parsed as JSON; panics with both outputs when it is not.
pub fn json(o: &Output) -> serde_json::Value {
    serde_json::from_str(&stdout(o)).unwrap_or_else(|e| panic!("not JSON ({e}): {}\nstderr: {}", stdout(o), stderr(o)))
}

/// The test binary's scratch directory `dir` under `CARGO_TARGET_TMPDIR`, created.
pub fn tmp_dir(dir: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(dir);
    std::fs::create_dir_all(&dir).expect("tmp dir");
    dir
}
