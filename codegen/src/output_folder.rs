//! Who owns an output folder: the marker gyrofx writes into each package, the check that runs
//! before a folder is replaced, and the clean-up of staging folders.
//!
//! gyrofx replaces an existing `--out` folder only when it is empty, or when it is a package of
//! the same kind that gyrofx wrote and that holds nothing else: its marker ([`MARKER`]) names
//! the kind and the build outputs the package's own Makefile may add, its `manifest.json` lists
//! every file with its SHA-256, and every file in the folder must be one of those (unchanged)
//! or a build output. Anything else (a user's file, an edited vector file, a package of another
//! kind) is refused with the offending paths named; [`Replace::Force`] overrides.
//!
//! A package is written into a staging folder beside `--out` (`.gyrofx-staging-<pid>-…`) and
//! renamed into place. The staging folders of this process are registered so that a signal
//! handler can remove them ([`remove_registered`]); the ones a killed run left behind (their
//! process is gone) are removed by the next run in the same parent folder ([`clean_stale`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::{Error, Result};
use crate::package::{sha256_hex, MANIFEST};

/// The marker file at the root of every package.
pub const MARKER: &str = ".gyrofx-package";

/// Prefix of the staging folders (followed by the process id and a random part).
pub const STAGING_PREFIX: &str = ".gyrofx-staging-";

/// Prefix of the folder a replaced package is moved to while the new one moves in.
pub const OLD_PREFIX: &str = ".gyrofx-old-";

/// What a package is; only a package of the same kind is replaced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// `gyrofx generate`: vectors, ROMs, RTL and testbenches.
    Generate,
    /// `gyrofx synth`: synthesis scripts and reports.
    Synth,
    /// `gyrofx reproduce --out`: a paper's reproduction.
    Reproduce,
    /// `gyrofx filter --vectors`: the KF's vectors of a filtered record.
    Filter,
    /// `gyrofx explore`: the candidates' CSV, the Pareto plots and the chosen config.
    Explore,
}

impl Kind {
    /// The command's name, as the marker records it.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Generate => "generate",
            Kind::Synth => "synth",
            Kind::Reproduce => "reproduce",
            Kind::Filter => "filter",
            Kind::Explore => "explore",
        }
    }

    fn from_name(name: &str) -> Option<Kind> {
        [
            Kind::Generate,
            Kind::Synth,
            Kind::Reproduce,
            Kind::Filter,
            Kind::Explore,
        ]
        .into_iter()
        .find(|k| k.name() == name)
    }
}

/// Whether an existing folder that gyrofx does not own may be replaced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Replace {
    /// Only an empty folder or a package of the same kind holding nothing else (the default).
    IfOwned,
    /// Any folder (`--force`).
    Force,
}

/// The marker's content: the package's kind and the paths its Makefile may create (`dir/` a
/// whole folder, `dir/*.ext` the files of one folder ending so, or an exact path).
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Marker {
    /// Always `gyrofx`.
    pub tool: String,
    /// [`Kind::name`].
    pub kind: String,
    /// Build outputs the package's own Makefile writes (simulator work folders, logs).
    pub build_outputs: Vec<String>,
}

impl Marker {
    /// The marker of a package of `kind` whose Makefile writes `build_outputs`.
    pub fn new(kind: Kind, build_outputs: Vec<String>) -> Self {
        Marker {
            tool: "gyrofx".into(),
            kind: kind.name().into(),
            build_outputs,
        }
    }

    /// The marker file's text (JSON).
    pub fn text(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("a marker serializes");
        text.push('\n');
        text
    }

    fn allows(&self, path: &str) -> bool {
        self.build_outputs.iter().any(|pattern| {
            if let Some(folder) = pattern.strip_suffix('/') {
                path.starts_with(&format!("{folder}/"))
            } else if let Some((folder, suffix)) = pattern.split_once("/*") {
                path.strip_prefix(&format!("{folder}/"))
                    .is_some_and(|name| !name.contains('/') && name.ends_with(suffix))
            } else {
                path == pattern
            }
        })
    }
}

/// Checks that `out` may receive a package of `kind`: it does not exist, is an empty folder,
/// or (unless `replace` is [`Replace::Force`]) a package of that kind holding only its own
/// files, unchanged, and its build outputs. Reads the folder, changes nothing.
///
/// # Errors
/// [`Error::Output`] naming what is in the way.
pub fn check(out: &Path, kind: Kind, replace: Replace) -> Result<()> {
    let refuse = |message: String| Error::Output {
        path: out.to_path_buf(),
        message,
    };
    let Ok(meta) = std::fs::symlink_metadata(out) else {
        return Ok(());
    };
    if !meta.is_dir() {
        return Err(refuse(
            "exists and is not a folder: gyrofx writes a folder there".into(),
        ));
    }
    let mut entries = std::fs::read_dir(out).map_err(|e| Error::io(out, e))?;
    if entries.next().is_none() || replace == Replace::Force {
        return Ok(());
    }
    let force = "move it away, choose another --out, or give --force to replace it anyway";
    let marker: Marker = match std::fs::read_to_string(out.join(MARKER))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok())
    {
        Some(marker) => marker,
        None => {
            return Err(refuse(format!(
                "is not empty and holds no gyrofx marker ({MARKER}): it is not a gyrofx output, \
                 so it is not replaced ({}); {force}",
                listing(&walk(out)?.into_keys().collect::<Vec<_>>())
            )))
        }
    };
    match Kind::from_name(&marker.kind) {
        Some(found) if found == kind => {}
        Some(found) => {
            return Err(refuse(format!(
                "holds a `gyrofx {}` package, which `gyrofx {}` does not replace; {force}",
                found.name(),
                kind.name()
            )))
        }
        None => {
            return Err(refuse(format!(
                "holds a marker of an unknown kind {:?}; {force}",
                marker.kind
            )))
        }
    }
    let listed: BTreeMap<String, (String, u64)> = std::fs::read_to_string(out.join(MANIFEST))
        .ok()
        .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
        .and_then(|manifest| {
            manifest["files"].as_array().map(|files| {
                files
                    .iter()
                    .filter_map(|f| {
                        Some((
                            f["path"].as_str()?.to_string(),
                            (f["sha256"].as_str()?.to_string(), f["bytes"].as_u64()?),
                        ))
                    })
                    .collect()
            })
        })
        .ok_or_else(|| {
            refuse(format!(
                "holds a gyrofx marker but no readable {MANIFEST} with its file list, so what \
                 it holds cannot be checked; {force}"
            ))
        })?;
    let mut foreign = Vec::new();
    let mut changed = Vec::new();
    for (path, size) in walk(out)? {
        if path == MANIFEST || marker.allows(&path) {
            continue;
        }
        match (listed.get(&path), size) {
            (Some((sha256, bytes)), Some(size)) if *bytes == size => {
                let data = std::fs::read(out.join(&path)).map_err(|e| Error::io(out, e))?;
                if sha256_hex(&data) != *sha256 {
                    changed.push(path);
                }
            }
            (Some(_), Some(_)) => changed.push(path),
            _ => foreign.push(path),
        }
    }
    if foreign.is_empty() && changed.is_empty() {
        return Ok(());
    }
    let mut what = Vec::new();
    if !foreign.is_empty() {
        what.push(format!("files gyrofx did not write: {}", listing(&foreign)));
    }
    if !changed.is_empty() {
        what.push(format!(
            "files changed since gyrofx wrote them: {}",
            listing(&changed)
        ));
    }
    Err(refuse(format!(
        "is a gyrofx {} package but also holds {}; it is not replaced: {force}",
        kind.name(),
        what.join("; and ")
    )))
}

/// Up to eight paths, then how many more.
fn listing(paths: &[String]) -> String {
    const SHOWN: usize = 8;
    let mut text = paths
        .iter()
        .take(SHOWN)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if paths.len() > SHOWN {
        text.push_str(&format!(" and {} more", paths.len() - SHOWN));
    }
    text
}

/// Every entry under `root` by `/`-separated relative path: files with their size, and
/// anything that is neither a file nor a folder (a link, a socket) with `None`. Empty folders
/// are listed with `None` too, so that they count as foreign. Links are not followed.
fn walk(root: &Path) -> Result<BTreeMap<String, Option<u64>>> {
    let mut out = BTreeMap::new();
    let mut pending = vec![PathBuf::new()];
    while let Some(relative) = pending.pop() {
        let folder = root.join(&relative);
        let mut empty = true;
        for entry in std::fs::read_dir(&folder).map_err(|e| Error::io(&folder, e))? {
            empty = false;
            let entry = entry.map_err(|e| Error::io(&folder, e))?;
            let path = relative.join(entry.file_name());
            let kind = entry.file_type().map_err(|e| Error::io(entry.path(), e))?;
            let name = path.to_string_lossy().replace('\\', "/");
            if kind.is_dir() {
                pending.push(path);
            } else if kind.is_file() {
                let size = entry
                    .metadata()
                    .map_err(|e| Error::io(entry.path(), e))?
                    .len();
                out.insert(name, Some(size));
            } else {
                out.insert(name, None);
            }
        }
        if empty && !relative.as_os_str().is_empty() {
            out.insert(
                format!("{}/", relative.to_string_lossy().replace('\\', "/")),
                None,
            );
        }
    }
    Ok(out)
}

/// Staging folders of this process that exist now.
static STAGING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Records a staging folder, removed by [`remove_registered`] if a signal ends the process.
pub fn register(path: &Path) {
    if let Ok(mut staging) = STAGING.lock() {
        staging.push(path.to_path_buf());
    }
}

/// Forgets a staging folder (it was renamed into place or removed).
pub fn unregister(path: &Path) {
    if let Ok(mut staging) = STAGING.lock() {
        staging.retain(|p| p != path);
    }
}

/// Set once a signal asked the process to end: writers stop creating files.
static INTERRUPTED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Whether [`remove_registered`] has run (a signal is ending the process).
pub fn interrupted() -> bool {
    INTERRUPTED.load(std::sync::atomic::Ordering::SeqCst)
}

/// Removes every registered staging folder: for a signal handler, just before the process
/// exits. Writer threads may still be creating a file when it starts, so a removal that finds
/// the folder refilled is retried (for up to 5 s) after they have seen [`interrupted`].
pub fn remove_registered() {
    INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst);
    if let Ok(mut staging) = STAGING.lock() {
        for path in staging.drain(..) {
            for _ in 0..500 {
                if std::fs::remove_dir_all(&path).is_ok() || !path.exists() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
        }
    }
}

/// Creates a new staging folder in `parent`, `.gyrofx-staging-<pid>-<n>`, registered before
/// it exists so that a signal cannot fall between its creation and its registration.
///
/// # Errors
/// The error of creating it.
pub fn create_staging(parent: &Path) -> std::io::Result<PathBuf> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    loop {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path = parent.join(format!(
            "{STAGING_PREFIX}{}-{nanos:08x}{n}",
            std::process::id()
        ));
        register(&path);
        match std::fs::create_dir(&path) {
            Ok(()) => return Ok(path),
            Err(e) => {
                unregister(&path);
                if e.kind() != std::io::ErrorKind::AlreadyExists {
                    return Err(e);
                }
            }
        }
    }
}

/// Removes the staging and set-aside folders in `parent` that a run killed before it could
/// clean up left behind: those whose process no longer runs (where the platform tells,
/// `/proc/<pid>`), else those older than a day. Errors are ignored: this is housekeeping.
pub fn clean_stale(parent: &Path) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let own = std::process::id();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(rest) = name
            .strip_prefix(STAGING_PREFIX)
            .or_else(|| name.strip_prefix(OLD_PREFIX))
        else {
            continue;
        };
        if !entry.file_type().is_ok_and(|t| t.is_dir()) {
            continue;
        }
        let pid = rest
            .split_once('-')
            .and_then(|(pid, _)| pid.parse::<u32>().ok());
        let proc_root = Path::new("/proc");
        let stale = match pid {
            Some(pid) if pid == own => false,
            Some(pid) if proc_root.join("self").exists() => {
                !proc_root.join(pid.to_string()).exists()
            }
            _ => entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 24 * 3600),
        };
        if stale {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// A private work folder (yosys's scratch files, ...) in the system's temporary folder,
/// registered so that a signal ending the process removes it ([`remove_registered`]), and
/// removed when dropped.
#[derive(Debug)]
pub struct WorkFolder(tempfile::TempDir);

impl WorkFolder {
    /// Creates one.
    ///
    /// # Errors
    /// The error of creating it.
    pub fn new() -> std::io::Result<WorkFolder> {
        let folder = tempfile::Builder::new().prefix("gyrofx-work-").tempdir()?;
        register(folder.path());
        Ok(WorkFolder(folder))
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        self.0.path()
    }
}

impl Drop for WorkFolder {
    fn drop(&mut self) {
        unregister(self.0.path());
    }
}

/// A temporary file in `folder` (`<prefix>…<suffix>`) for a single output file that is
/// renamed into place when complete. Created with mode 0666 less the umask, as any file a
/// program writes, not the 0600 of a private temporary file: the renamed output keeps it.
///
/// # Errors
/// The error of creating it.
pub fn staged_file(
    folder: &Path,
    prefix: &str,
    suffix: &str,
) -> std::io::Result<tempfile::NamedTempFile> {
    let mut builder = tempfile::Builder::new();
    builder.prefix(prefix).suffix(suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder.tempfile_in(folder)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn build_output_patterns_match_only_their_paths() {
        let marker = Marker::new(
            Kind::Generate,
            vec![
                "kf/obj_verilator/".into(),
                "kf/*.vvp".into(),
                "kf/build.log".into(),
            ],
        );
        for allowed in [
            "kf/obj_verilator/a.o",
            "kf/obj_verilator/x/y",
            "kf/tb.vvp",
            "kf/build.log",
        ] {
            assert!(marker.allows(allowed), "{allowed}");
        }
        for refused in [
            "kf/obj_verilator",
            "top/tb.vvp",
            "kf/sub/tb.vvp",
            "kf/tb.vvp.txt",
            "kf/build.log2",
            "kf_vectors.csv",
        ] {
            assert!(!marker.allows(refused), "{refused}");
        }
    }
}
