//! Progress on a terminal: a bar with percent and ETA (or a spinner where the total is
//! unknown; [`follow`] for a run that counts its own work) on stderr when stderr is a terminal and `--quiet` was not given; nothing otherwise,
//! so logs and pipes stay clean.

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressStyle};

/// A bar over `total` steps described by `what`, or a hidden one.
pub fn bar(total: u64, what: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(total);
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:30}] {percent:>3}% {pos}/{len} ETA {eta}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// A spinner with the elapsed time, or a hidden one.
pub fn spinner(what: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {msg} {elapsed}").expect("a valid template"),
    );
    bar.set_message(what.to_string());
    bar.enable_steady_tick(std::time::Duration::from_millis(200));
    bar
}

/// Runs `work` while a bar (on a terminal, unless `quiet`) shows `progress`: its phase, and
/// percent and ETA of the work units the run plans, refreshed five times a second.
pub fn follow<T>(
    what: &str,
    quiet: bool,
    progress: &gyrofx_codegen::progress::Progress,
    work: impl FnOnce() -> T,
) -> T {
    let bar = bar(1, what, quiet);
    if bar.is_hidden() {
        return work();
    }
    let finished = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        scope.spawn(|| {
            while !finished.load(std::sync::atomic::Ordering::Relaxed) {
                let (done, total) = progress.counts();
                bar.set_length(total.max(1));
                bar.set_position(done.min(total));
                bar.set_message(format!("{what}: {}", progress.phase()));
                std::thread::sleep(std::time::Duration::from_millis(200));
            }
        });
        let result = work();
        finished.store(true, std::sync::atomic::Ordering::Relaxed);
        bar.finish_and_clear();
        result
    })
}
