//! Out-of-memory tests in a child process: an `#[ignore]`d test of the same binary runs in a
//! child (so a limit or a crash never reaches the test runner), and limits its own address
//! space (`setrlimit RLIMIT_AS`) around the allocation it wants refused. Mesa allocates buffer
//! and texture storage with `malloc`/`mmap` in the calling process, so the driver's allocation
//! fails and GL reports GL_OUT_OF_MEMORY (tests/gl_failures.rs, module doc).

/// Set in the child process: the name of the child test to run.
pub const CHILD_ENV: &str = "UMBRA_GL_TEST_CHILD";
/// Printed by a child test when all its assertions passed.
pub const CHILD_DONE: &str = "child test: all checks passed";

/// Runs the ignored test `name` in a child process of this test binary and fails with its
/// output unless it passed (exit 0 and [`CHILD_DONE`] printed).
pub fn run_in_child(name: &str) {
    let out = std::process::Command::new(std::env::current_exe().expect("test binary path"))
        .args(["--exact", name, "--ignored", "--test-threads=1", "--nocapture"])
        .env(CHILD_ENV, name)
        .output()
        .expect("run the child test process");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("--- child {name} ---\n{stdout}{stderr}");
    assert!(
        out.status.success() && stdout.contains(CHILD_DONE),
        "child {name} failed ({}):\n{stdout}{stderr}",
        out.status
    );
}

/// Whether this process is the child for `name` (else the ignored test does nothing).
pub fn is_child(name: &str) -> bool {
    std::env::var(CHILD_ENV).is_ok_and(|v| v == name)
}

/// One value of /proc/self/status in KiB (VmRSS, VmSize, ...).
pub fn status_kib(key: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").expect("read /proc/self/status");
    status
        .lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(':'))
        .and_then(|v| v.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("{key} missing from /proc/self/status"))
}

/// `struct rlimit` of Linux (two `rlim_t` = u64).
#[repr(C)]
struct RLimit {
    cur: u64,
    max: u64,
}

extern "C" {
    fn getrlimit(resource: i32, rlim: *mut RLimit) -> i32;
    fn setrlimit(resource: i32, rlim: *const RLimit) -> i32;
}

/// `RLIMIT_AS` on Linux (x86-64 and aarch64 alike).
const RLIMIT_AS: i32 = 9;

/// Runs `f` with the process's address space limited to its current size + `headroom` bytes,
/// then restores the previous limit. Only ever called in a child process ([`run_in_child`]).
pub fn with_address_space_headroom<T>(headroom: u64, f: impl FnOnce() -> T) -> T {
    let mut old = RLimit { cur: 0, max: 0 };
    // SAFETY: getrlimit/setrlimit of libc (linked by std) with a valid struct rlimit.
    assert_eq!(unsafe { getrlimit(RLIMIT_AS, &mut old) }, 0, "getrlimit");
    let limited = RLimit { cur: (status_kib("VmSize") * 1024 + headroom).min(old.max), max: old.max };
    // SAFETY: as above; lowering the soft limit is always allowed.
    assert_eq!(unsafe { setrlimit(RLIMIT_AS, &limited) }, 0, "setrlimit");
    let out = f();
    // SAFETY: as above; raising the soft limit back up to the unchanged hard limit is allowed.
    assert_eq!(unsafe { setrlimit(RLIMIT_AS, &old) }, 0, "restore the address-space limit");
    out
}
