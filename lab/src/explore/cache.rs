//! The synthesis cost cache: one JSON file per [`synth::cache_key`] (the RTL, parameters, ROM
//! words and yosys version), so a design is synthesized once across runs, and once within a
//! run however many candidates share it.
//!
//! A file is written to a temporary name in the cache folder and renamed into place, so that
//! parallel candidates (or runs) never read half a file; a file that does not parse is a miss
//! and is rewritten.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, OnceLock};

use crate::synth::{self, Design, Resources};
use gyrofx_job::error::{Error, Result};
use gyrofx_job::job::Job;

/// The cache folder when `--cache` is not given: `$XDG_CACHE_HOME/gyrofx/synth`, else
/// `$HOME/.cache/gyrofx/synth`; `None` when neither variable is set.
pub fn default_folder() -> Option<PathBuf> {
    let nonempty = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    let base = nonempty("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .or_else(|| nonempty("HOME").map(|home| PathBuf::from(home).join(".cache")))?;
    Some(base.join("gyrofx").join("synth"))
}

/// How the costs of a run were found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CostCounts {
    /// Designs synthesized by yosys in this run.
    pub synthesized: u64,
    /// Designs read from the cache folder.
    pub cached: u64,
    /// Designs another candidate of this run had already asked for (same key).
    pub shared: u64,
}

/// Why a cost is missing.
#[derive(Clone, Debug)]
enum Failure {
    /// yosys failed on the design: the candidate's row says why.
    Synthesis(String),
    /// The cache file could not be written: the run stops.
    Cache(String),
}

/// One design's cost, found once by whichever candidate asks first.
type Slot = Arc<OnceLock<std::result::Result<Resources, Failure>>>;

/// The cache folder and the designs asked for in this run.
#[derive(Debug)]
pub struct Costs {
    folder: PathBuf,
    asked: Mutex<HashMap<String, Slot>>,
    synthesized: AtomicU64,
    cached: AtomicU64,
    shared: AtomicU64,
}

impl Costs {
    /// The cache in `folder`, created if missing.
    ///
    /// # Errors
    /// [`Error::Io`] when the folder cannot be created.
    pub fn open(folder: &Path) -> Result<Costs> {
        std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
        Ok(Costs {
            folder: folder.to_path_buf(),
            asked: Mutex::new(HashMap::new()),
            synthesized: AtomicU64::new(0),
            cached: AtomicU64::new(0),
            shared: AtomicU64::new(0),
        })
    }

    /// The folder.
    pub fn folder(&self) -> &Path {
        &self.folder
    }

    /// How the costs asked for so far were found.
    pub fn counts(&self) -> CostCounts {
        CostCounts {
            synthesized: self.synthesized.load(Ordering::Relaxed),
            cached: self.cached.load(Ordering::Relaxed),
            shared: self.shared.load(Ordering::Relaxed),
        }
    }

    /// The resources of `design` of `job`: from this run, the cache folder, or yosys (then
    /// stored). A second candidate asking for a key that is being synthesized waits for it.
    ///
    /// # Errors
    /// Outer: the cache file cannot be written ([`Error::Output`]). Inner: yosys failed on the
    /// design (its message).
    pub fn cost(
        &self,
        job: &Job,
        design: Design,
    ) -> Result<std::result::Result<Resources, String>> {
        let inputs = synth::design_inputs(job, design);
        let key = synth::cache_key(&inputs);
        let cell = {
            let mut asked = self.asked.lock().unwrap_or_else(|e| e.into_inner());
            match asked.get(&key) {
                Some(cell) => {
                    self.shared.fetch_add(1, Ordering::Relaxed);
                    cell.clone()
                }
                None => {
                    let cell = Arc::new(OnceLock::new());
                    asked.insert(key.clone(), cell.clone());
                    cell
                }
            }
        };
        let outcome = cell.get_or_init(|| {
            let path = self.folder.join(format!("{key}.json"));
            if let Some(resources) = read(&path) {
                self.cached.fetch_add(1, Ordering::Relaxed);
                return Ok(resources);
            }
            let resources = synth::cost(&inputs).map_err(|e| Failure::Synthesis(e.to_string()))?;
            self.synthesized.fetch_add(1, Ordering::Relaxed);
            write(&self.folder, &path, module(job, design), &resources).map_err(Failure::Cache)?;
            Ok(resources)
        });
        match outcome {
            Ok(resources) => Ok(Ok(resources.clone())),
            Err(Failure::Synthesis(message)) => Ok(Err(message.clone())),
            Err(Failure::Cache(message)) => Err(Error::Output {
                path: self.folder.clone(),
                message: message.clone(),
            }),
        }
    }
}

/// The module name of `design` of `job` (the chain's and the loop's follow its `architecture`).
fn module(job: &Job, design: Design) -> &'static str {
    match design {
        Design::Chain if job.serial.is_some() => "gyrofx_top_serial",
        Design::Chain => synth::TOP,
        Design::GyroLoop if job.loop_schedule.is_some() => {
            gyrofx_codegen::blocks::gyro_loop::SERIAL_MODULE
        }
        Design::GyroLoop => gyrofx_codegen::design::LOOP_TOP,
    }
}

/// A cache file's resources, or `None` when it is missing or does not parse.
fn read(path: &Path) -> Option<Resources> {
    let text = std::fs::read_to_string(path).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    serde_json::from_value(json.get("resources")?.clone()).ok()
}

/// Writes a cache file atomically: a temporary file in `folder`, renamed to `path`.
fn write(
    folder: &Path,
    path: &Path,
    module: &str,
    resources: &Resources,
) -> std::result::Result<(), String> {
    use std::io::Write as _;
    let json = serde_json::json!({
        "tool": "gyrofx",
        "version": env!("CARGO_PKG_VERSION"),
        "module": module,
        "resources": resources,
    });
    let fail =
        |e: &dyn std::fmt::Display| format!("cannot write the cache file {}: {e}", path.display());
    let mut staged = gyrofx_codegen::output_folder::staged_file(folder, ".gyrofx-synth-", ".tmp")
        .map_err(|e| fail(&e))?;
    staged
        .write_all(format!("{}\n", serde_json::to_string_pretty(&json).expect("JSON")).as_bytes())
        .map_err(|e| fail(&e))?;
    staged.persist(path).map_err(|e| fail(&e))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{Generic, Xilinx};

    #[test]
    fn a_written_file_reads_back_and_a_broken_one_is_a_miss() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("k.json");
        let resources = Resources {
            generic: Generic {
                cells: 1,
                flip_flops: 2,
                multipliers: 3,
            },
            xilinx: Xilinx {
                luts: 4,
                flip_flops: 5,
                dsp48: 6,
                block_rams: 7,
                carry4: 8,
            },
        };
        write(dir.path(), &path, synth::TOP, &resources).unwrap();
        assert_eq!(read(&path), Some(resources));
        std::fs::write(&path, "{\"resources\": {\"generic\": {}}}").unwrap();
        assert_eq!(read(&path), None);
        // Only the file itself is left: the temporary one was renamed.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
