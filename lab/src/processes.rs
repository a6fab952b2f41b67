//! The external programs gyrofx runs (make and the simulators, yosys, nextpnr), tracked so
//! that a signal ending gyrofx ends them too ([`end_all`]) instead of leaving them writing into
//! folders the signal handler removes.
//!
//! Each child starts in a process group of its own (its pid is the group's id): what it starts
//! in turn (make's iverilog and vvp, yosys's abc) is in that group, so one signal to the group
//! reaches them all. Their own group also keeps a terminal's Ctrl-C from reaching them before
//! gyrofx has decided what to do; [`end_all`] passes it on.

use std::process::{Child, Command};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The process groups of the running children. Held while spawning, so that [`end_all`] either
/// sees a new child or runs before it is started (and then no child starts).
static GROUPS: Mutex<Vec<u32>> = Mutex::new(Vec::new());

/// Set by [`end_all`]: no child starts after it.
static ENDING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether [`end_all`] has started: a child that failed was ended by the signal handler.
pub fn ending() -> bool {
    ENDING.load(std::sync::atomic::Ordering::SeqCst)
}

/// How long the children get between SIGTERM and SIGKILL.
const GRACE: Duration = Duration::from_millis(1000);

/// Starts `command` in a process group of its own and tracks it until [`forget`].
///
/// # Errors
/// The error of spawning it; [`std::io::ErrorKind::Interrupted`] once [`end_all`] has run.
pub fn spawn(command: &mut Command) -> std::io::Result<Child> {
    #[cfg(unix)]
    std::os::unix::process::CommandExt::process_group(command, 0);
    let mut groups = GROUPS.lock().unwrap_or_else(|e| e.into_inner());
    if ENDING.load(std::sync::atomic::Ordering::SeqCst) {
        return Err(std::io::Error::from(std::io::ErrorKind::Interrupted));
    }
    let child = command.spawn()?;
    groups.push(child.id());
    Ok(child)
}

/// Stops tracking `child` (it has been waited for).
pub fn forget(child: &Child) {
    let mut groups = GROUPS.lock().unwrap_or_else(|e| e.into_inner());
    groups.retain(|g| *g != child.id());
}

/// Ends `child`'s process group at once (SIGKILL): for a child past its time limit, which
/// gets no grace. It is still to be waited for and forgotten.
pub fn end_group(child: &Child) {
    #[cfg(unix)]
    // SAFETY: kill has no memory effects; a negative pid names a process group.
    unsafe {
        libc::kill(-(child.id() as libc::pid_t), libc::SIGKILL);
    }
    #[cfg(not(unix))]
    let _ = child;
}

/// Ends every tracked child's process group: SIGTERM, then SIGKILL to the groups that still
/// have members after [`GRACE`]. For the signal handler; no child starts afterwards.
pub fn end_all() {
    ENDING.store(true, std::sync::atomic::Ordering::SeqCst);
    let groups: Vec<u32> = GROUPS
        .lock()
        .map(|g| g.clone())
        .unwrap_or_else(|e| e.into_inner().clone());
    #[cfg(unix)]
    {
        let signal_group = |group: u32, signal: i32| {
            // SAFETY: kill has no memory effects; a negative pid names a process group.
            unsafe { libc::kill(-(group as libc::pid_t), signal) == 0 }
        };
        let mut running: Vec<u32> = groups
            .into_iter()
            .filter(|g| signal_group(*g, libc::SIGTERM))
            .collect();
        let start = Instant::now();
        while !running.is_empty() && start.elapsed() < GRACE {
            std::thread::sleep(Duration::from_millis(10));
            running.retain(|g| group_runs(*g));
        }
        for group in running {
            signal_group(group, libc::SIGKILL);
        }
    }
}

/// Whether a process group has a member that is not a zombie (a leader that ended but has not
/// been waited for yet still counts as a member for kill(2)).
#[cfg(unix)]
fn group_runs(group: u32) -> bool {
    let Ok(entries) = std::fs::read_dir("/proc") else {
        // SAFETY: signal 0 only checks that the group exists.
        return unsafe { libc::kill(-(group as libc::pid_t), 0) == 0 };
    };
    entries.flatten().any(|entry| {
        std::fs::read_to_string(entry.path().join("stat")).is_ok_and(|stat| {
            let fields: Vec<&str> = stat
                .rsplit_once(')')
                .map(|(_, rest)| rest.split_whitespace().take(3).collect())
                .unwrap_or_default();
            // state ppid pgrp
            fields.len() == 3 && fields[0] != "Z" && fields[2] == group.to_string()
        })
    })
}
