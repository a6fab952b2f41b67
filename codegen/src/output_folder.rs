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

use gyrofx_job::error::{Error, Result};
use gyrofx_job::hash::{file_sha256, sha256_hex};

/// The package's file list with each file's SHA-256 (with the marker, what makes a folder a
/// gyrofx output that may be replaced: [`check`]).
pub const MANIFEST: &str = "manifest.json";

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
    /// `gyrofx population`: the members' CSV, the summary and its plots.
    Population,
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
            Kind::Population => "population",
        }
    }

    fn from_name(name: &str) -> Option<Kind> {
        [
            Kind::Generate,
            Kind::Synth,
            Kind::Reproduce,
            Kind::Filter,
            Kind::Explore,
            Kind::Population,
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
    /// SHA-256 (hex) of the package's `manifest.json`: the marker is written after it, so that
    /// an edited manifest counts as a changed file too. Missing in the markers of gyrofx
    /// before 0.1 of issue 27 (those packages are not replaced without `--force`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub manifest_sha256: Option<String>,
}

impl Marker {
    /// The marker of a package of `kind` whose Makefile writes `build_outputs`.
    pub fn new(kind: Kind, build_outputs: Vec<String>) -> Self {
        Marker {
            tool: "gyrofx".into(),
            kind: kind.name().into(),
            build_outputs,
            manifest_sha256: None,
        }
    }

    /// The marker file's text (JSON).
    pub fn text(&self) -> String {
        let mut text = serde_json::to_string_pretty(self).expect("a marker serializes");
        text.push('\n');
        text
    }

    /// Whether `path` (relative, `/`-separated) is one of the build outputs.
    pub fn allows(&self, path: &str) -> bool {
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
    if let Some(reason) = unsafe_folder(out) {
        return Err(refuse(reason));
    }
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
    let listed = read_manifest(out)
        .as_ref()
        .and_then(listed_files)
        .ok_or_else(|| {
            refuse(format!(
                "holds a gyrofx marker but no readable {MANIFEST} with its file list, so what \
             it holds cannot be checked; {force}"
            ))
        })?;
    let Some(manifest_sha256) = &marker.manifest_sha256 else {
        return Err(refuse(format!(
            "holds a package of an older gyrofx whose marker does not record the SHA-256 of \
             its {MANIFEST}, so an edit to that file cannot be told apart; it is not replaced: \
             {force}"
        )));
    };
    let mut foreign = Vec::new();
    let mut changed = Vec::new();
    if file_sha256(&out.join(MANIFEST)).ok().as_ref() != Some(manifest_sha256) {
        changed.push(MANIFEST.to_string());
    }
    for (path, size) in walk(out)? {
        if path == MANIFEST || path == MARKER || marker.allows(&path) {
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

/// The package's `manifest.json`, parsed; `None` when it cannot be read or is not JSON.
fn read_manifest(out: &Path) -> Option<serde_json::Value> {
    let text = std::fs::read_to_string(out.join(MANIFEST)).ok()?;
    serde_json::from_str(&text).ok()
}

/// The files `manifest` lists: relative path to (SHA-256 hex, bytes); `None` when it lists
/// none.
fn listed_files(manifest: &serde_json::Value) -> Option<BTreeMap<String, (String, u64)>> {
    let files = manifest["files"].as_array()?;
    Some(
        files
            .iter()
            .filter_map(|f| {
                Some((
                    f["path"].as_str()?.to_string(),
                    (f["sha256"].as_str()?.to_string(), f["bytes"].as_u64()?),
                ))
            })
            .collect(),
    )
}

/// Why `out` may never be an output folder, whatever `--force` says: a filesystem root, the
/// home folder, or the current folder or one of its ancestors (replacing it would take the
/// folder gyrofx runs in, and walking it would cross into everything below). `None` when it
/// may be one.
pub fn unsafe_folder(out: &Path) -> Option<String> {
    let resolved = resolve(out);
    if resolved.parent().is_none() {
        return Some("is a filesystem root: gyrofx writes its output into a folder of its own there; choose a new folder such as ./out".into());
    }
    let home = std::env::var_os("HOME").map(|h| resolve(Path::new(&h)));
    if home.as_ref() == Some(&resolved) {
        return Some(
            "is the home folder: gyrofx replaces its output folder; choose a new folder in it"
                .into(),
        );
    }
    let current = std::env::current_dir().map(|c| resolve(&c));
    if current.is_ok_and(|c| c.starts_with(&resolved)) {
        return Some("is the current folder or one of its ancestors: gyrofx replaces its output folder, and cannot replace the folder it runs in; choose a new folder such as ./out".into());
    }
    None
}

/// `path` made absolute with links resolved as far as it exists (the rest appended), so that
/// two names of one file compare equal even before the file exists.
pub fn resolve(path: &Path) -> PathBuf {
    let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_path_buf());
    let mut existing = absolute.as_path();
    let mut rest = Vec::new();
    loop {
        if let Ok(mut real) = existing.canonicalize() {
            // The part that does not exist holds no links: its `..` go up by name.
            for name in rest.iter().rev() {
                if name == std::ffi::OsStr::new("..") {
                    real.pop();
                } else if name != std::ffi::OsStr::new(".") {
                    real.push(name);
                }
            }
            return real;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last.as_os_str().to_os_string());
                existing = parent;
            }
            // A root that cannot be resolved: compared as written.
            _ => return absolute,
        }
    }
}

/// Refuses an output that is, or as a folder would hold, one of the command's inputs: the
/// message names both flags. `output` and each input are (flag, path); inputs that do not
/// exist are skipped.
///
/// # Errors
/// The message (for a usage error).
pub fn refuse_overlap(
    output: (&str, &Path),
    inputs: &[(&str, &Path)],
) -> std::result::Result<(), String> {
    let (out_flag, out_path) = output;
    let target = resolve(out_path);
    for (flag, path) in inputs {
        let Ok(input) = path.canonicalize() else {
            continue;
        };
        if input == target {
            return Err(format!(
                "{out_flag} {} is the {flag} file: the output would replace it; choose another {out_flag}",
                out_path.display()
            ));
        }
        if input.starts_with(&target) {
            return Err(format!(
                "{out_flag} {} holds the {flag} file {}: writing the output there would replace it; choose another {out_flag}",
                out_path.display(),
                path.display()
            ));
        }
    }
    Ok(())
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
/// are listed with `None` too, so that they count as foreign. Links are not followed, nor is a
/// folder on another file system (a mount point is listed with `None`).
fn walk(root: &Path) -> Result<BTreeMap<String, Option<u64>>> {
    #[cfg(unix)]
    use std::os::unix::fs::MetadataExt;
    #[cfg(unix)]
    let device = std::fs::symlink_metadata(root)
        .map_err(|e| Error::io(root, e))?
        .dev();
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
            #[cfg(unix)]
            let other_device = kind.is_dir()
                && entry
                    .metadata()
                    .map_err(|e| Error::io(entry.path(), e))?
                    .dev()
                    != device;
            #[cfg(not(unix))]
            let other_device = false;
            if kind.is_dir() && !other_device {
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

/// Staging folders, temporary files and lock files of this process that exist now.
static STAGING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Records a staging folder or a temporary file, removed by [`remove_registered`] if a signal
/// ends the process. Returns false, registering nothing, once that removal has started: then
/// the caller must not create it (nothing would remove it).
pub fn register(path: &Path) -> bool {
    if let Ok(mut staging) = STAGING.lock() {
        if interrupted() {
            return false;
        }
        staging.push(path.to_path_buf());
    }
    true
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
            if std::fs::symlink_metadata(&path).is_ok_and(|m| !m.is_dir()) {
                let _ = std::fs::remove_file(&path);
                continue;
            }
            for _ in 0..500 {
                if std::fs::remove_dir_all(&path).is_ok() || !path.exists() {
                    break;
                }
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
        }
    }
}

/// Creates `folder` and the folders between it and `root`, but never `root` itself, which
/// must exist: a writer still running when a signal handler has removed the staging folder
/// `root` then fails instead of bringing it back (`create_dir_all` would recreate it after
/// the removal, and the process would end leaving it behind).
///
/// # Errors
/// `NotFound` when `root` or a folder below it is gone; `InvalidInput` when `folder` is not
/// inside `root`; any other error of creating a folder.
pub fn create_below(root: &Path, folder: &Path) -> std::io::Result<()> {
    let relative = folder.strip_prefix(root).map_err(|_| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{} is not inside {}", folder.display(), root.display()),
        )
    })?;
    let mut path = root.to_path_buf();
    for part in relative.components() {
        path.push(part);
        match std::fs::create_dir(&path) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && path.is_dir() => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

/// Creates a new staging folder in `parent`, `.gyrofx-staging-<pid>-<n>`, registered before
/// it exists so that a signal cannot fall between its creation and its registration.
///
/// # Errors
/// The error of creating it.
pub fn create_staging(parent: &Path) -> std::io::Result<PathBuf> {
    create_registered_folder(parent, STAGING_PREFIX)
}

/// Creates a new folder `<prefix><pid>-<n>` in `parent`, registered before it exists.
fn create_registered_folder(parent: &Path, prefix: &str) -> std::io::Result<PathBuf> {
    use std::sync::atomic::{AtomicU64, Ordering};
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    loop {
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let path = parent.join(format!("{prefix}{}-{nanos:08x}{n}", std::process::id()));
        if !register(&path) {
            return Err(std::io::Error::from(std::io::ErrorKind::Interrupted));
        }
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

/// Removes what runs killed before they could clean up left in `parent`: staging and
/// set-aside folders (`.gyrofx-staging-<pid>-…`, `.gyrofx-old-<pid>-…`) and staged files
/// (`.gyrofx-<what>-<pid>-…`, [`staged_file`]) whose process no longer runs (where the platform
/// tells, `/proc/<pid>`). A folder without /proc to ask is removed once older than a day; a
/// file only by its pid, so that no file gyrofx did not name is ever taken for one of its own.
/// Errors are ignored: this is housekeeping.
pub fn clean_stale(parent: &Path) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if kind.is_symlink() {
            continue;
        }
        let folder = [STAGING_PREFIX, OLD_PREFIX]
            .iter()
            .find_map(|prefix| name.strip_prefix(prefix));
        if let Some(tail) = folder {
            if kind.is_dir() && is_stale(&entry, tail, true) {
                let _ = std::fs::remove_dir_all(entry.path());
            }
            continue;
        }
        // A staged file: `.gyrofx-<what>-<pid>-…` (lock files are the locks' own business).
        let Some((what, tail)) = name
            .strip_prefix(".gyrofx-")
            .and_then(|rest| rest.split_once('-'))
        else {
            continue;
        };
        if what != "lock" && kind.is_file() && is_stale(&entry, tail, false) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether the entry named `…<pid>-<tail>` belongs to a process that ended. Without a pid in
/// the name, or without /proc to ask, only an `aged` entry older than a day is.
fn is_stale(entry: &std::fs::DirEntry, pid_and_rest: &str, aged: bool) -> bool {
    let pid = pid_and_rest
        .split_once('-')
        .and_then(|(pid, _)| pid.parse::<u32>().ok());
    match pid {
        Some(pid) if pid == std::process::id() => false,
        Some(pid) if proc_tells() => !process_runs(pid),
        _ => {
            aged && entry
                .metadata()
                .and_then(|m| m.modified())
                .ok()
                .and_then(|t| t.elapsed().ok())
                .is_some_and(|age| age.as_secs() > 24 * 3600)
        }
    }
}

/// Whether this platform tells which processes run (`/proc/self`).
fn proc_tells() -> bool {
    Path::new("/proc/self").exists()
}

/// Prefix of the work folders in the system's temporary folder (then the pid and a random
/// part).
pub const WORK_PREFIX: &str = "gyrofx-work-";

/// Removes the work folders in `temp` whose process no longer runs (a SIGKILLed `synth` or
/// `explore` cannot remove its own).
pub fn clean_stale_work(temp: &Path) {
    let Ok(entries) = std::fs::read_dir(temp) else {
        return;
    };
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(tail) = name.strip_prefix(WORK_PREFIX) else {
            continue;
        };
        // A folder of an older gyrofx without a pid in its name is left alone.
        let has_pid = tail
            .split_once('-')
            .is_some_and(|(pid, _)| pid.parse::<u32>().is_ok());
        if has_pid && entry.file_type().is_ok_and(|t| t.is_dir()) && is_stale(&entry, tail, false) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

/// A private work folder (yosys's scratch files, ...) in the system's temporary folder,
/// registered so that a signal ending the process removes it ([`remove_registered`]), and
/// removed when dropped.
#[derive(Debug)]
pub struct WorkFolder(PathBuf);

impl WorkFolder {
    /// Creates one.
    ///
    /// # Errors
    /// The error of creating it.
    pub fn new() -> std::io::Result<WorkFolder> {
        let temp = std::env::temp_dir();
        clean_stale_work(&temp);
        // Registered before it exists, as a staging folder: a signal cannot leave it behind.
        let folder = WorkFolder(create_registered_folder(&temp, WORK_PREFIX)?);
        // Private, as a temporary folder should be.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&folder.0, std::fs::Permissions::from_mode(0o700))?;
        }
        Ok(folder)
    }

    /// Its path.
    pub fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for WorkFolder {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
        unregister(&self.0);
    }
}

/// A temporary file in `folder` (`<prefix><pid>-…<suffix>`, `prefix` being `.gyrofx-<what>-`)
/// for a single output file that is renamed into place when complete, registered for removal
/// on a signal (once renamed, its temporary name no longer exists). Those a killed process left
/// in `folder` are removed first ([`clean_stale`]). Created with mode 0666 less the umask, as
/// any file a program writes, not the 0600 of a private temporary file: the renamed output
/// keeps it.
///
/// # Errors
/// The error of creating it.
pub fn staged_file(
    folder: &Path,
    prefix: &str,
    suffix: &str,
) -> std::io::Result<tempfile::NamedTempFile> {
    // What killed runs left here goes first: every staged file's folder is cleaned, not only
    // the folders of the commands that remember to.
    clean_stale(folder);
    let prefix = format!("{prefix}{}-", std::process::id());
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(suffix);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let file = builder.tempfile_in(folder)?;
    if !register(file.path()) {
        return Err(std::io::Error::from(std::io::ErrorKind::Interrupted));
    }
    Ok(file)
}

/// Prefix of the lock file beside an output folder (then the folder's name); it holds the pid
/// of the process writing the folder.
pub const LOCK_PREFIX: &str = ".gyrofx-lock-";

/// The exclusive right to write one output folder: a lock file beside it, removed when
/// dropped (or by [`remove_registered`] on a signal). A lock this process holds already is
/// not taken twice (the second is empty and removes nothing).
#[derive(Debug)]
pub struct Lock {
    path: Option<PathBuf>,
}

/// Takes the lock of the output folder `out`: creates `.gyrofx-lock-<name>` beside it with this
/// pid, or takes over one whose process no longer runs. Without a parent folder yet, nothing
/// else can be writing there: the lock is empty (the staging folder takes it when it creates
/// the parent).
///
/// # Errors
/// [`Error::Output`] when another process holds it: "another gyrofx (pid N) is writing DIR".
pub fn lock(out: &Path) -> Result<Lock> {
    let parent = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    if !parent.is_dir() {
        return Ok(Lock { path: None });
    }
    let name = out
        .file_name()
        .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
    let path = parent.join(format!("{LOCK_PREFIX}{name}"));
    let own = std::process::id();
    let holder = |path: &Path| {
        std::fs::read_to_string(path)
            .ok()
            .and_then(|t| t.trim().parse::<u32>().ok())
    };
    if holder(&path) == Some(own) {
        // Taken already by this process (the command, then its staging folder): that one
        // stays registered and removes it.
        return Ok(Lock { path: None });
    }
    // The pid is written to a file of its own first and linked into place: a lock file is
    // never seen empty.
    let draft = parent.join(format!("{LOCK_PREFIX}{name}.{own}"));
    let interrupted = || Error::io(out, std::io::Error::from(std::io::ErrorKind::Interrupted));
    if !register(&draft) {
        return Err(interrupted());
    }
    std::fs::write(&draft, own.to_string()).map_err(|e| Error::io(&draft, e))?;
    let taken = (|| {
        for _ in 0..3 {
            if !register(&path) {
                return Err(interrupted());
            }
            match std::fs::hard_link(&draft, &path) {
                Ok(()) => {
                    return Ok(Lock {
                        path: Some(path.clone()),
                    })
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
                Err(e) => {
                    unregister(&path);
                    return Err(Error::io(&path, e));
                }
            }
            unregister(&path);
            match holder(&path) {
                Some(pid) if pid == own => return Ok(Lock { path: None }),
                Some(pid) if process_runs(pid) => {
                    return Err(Error::Output {
                        path: out.to_path_buf(),
                        message: format!(
                            "another gyrofx (pid {pid}) is writing {}: wait for it to end, or choose another --out (its lock is {})",
                            out.display(),
                            path.display()
                        ),
                    })
                }
                // Its process is gone (or it is unreadable): a stale lock, taken over.
                _ => {
                    let _ = std::fs::remove_file(&path);
                }
            }
        }
        Err(Error::Output {
            path: out.to_path_buf(),
            message: format!("cannot take its lock {}", path.display()),
        })
    })();
    let _ = std::fs::remove_file(&draft);
    unregister(&draft);
    taken
}

/// Whether process `pid` runs (where the platform cannot tell: assumed so).
fn process_runs(pid: u32) -> bool {
    !proc_tells() || Path::new("/proc").join(pid.to_string()).exists()
}

impl Drop for Lock {
    fn drop(&mut self) {
        if let Some(path) = self.path.take() {
            let _ = std::fs::remove_file(&path);
            unregister(&path);
        }
    }
}

/// Checks a package against its `manifest.json` before it is simulated: the marker's record
/// of the manifest's SHA-256, every listed file present with its size and SHA-256, and each
/// block's testbench `VECTOR_COUNT` as the manifest gives it. Files the manifest does not
/// list (build outputs, waves) are not checked.
///
/// # Errors
/// [`Error::Simulation`] listing every difference.
pub fn verify_contents(out: &Path) -> Result<()> {
    let mut differences = Vec::new();
    let marker: Option<Marker> = std::fs::read_to_string(out.join(MARKER))
        .ok()
        .and_then(|text| serde_json::from_str(&text).ok());
    match marker.and_then(|m| m.manifest_sha256) {
        Some(recorded) => {
            if file_sha256(&out.join(MANIFEST)).ok() != Some(recorded) {
                differences.push(format!("{MANIFEST} changed since gyrofx wrote it"));
            }
        }
        None => differences.push(format!(
            "{MARKER} records no SHA-256 of {MANIFEST} (a package of an older gyrofx, or not one): regenerate it"
        )),
    }
    let Some(manifest) = read_manifest(out) else {
        return Err(Error::Simulation(format!(
            "{}: no readable {MANIFEST}, so what its testbenches check cannot be told; \
             regenerate the package (gyrofx generate)",
            out.display()
        )));
    };
    let listed = listed_files(&manifest).unwrap_or_default();
    if listed.is_empty() {
        differences.push(format!("{MANIFEST} lists no files"));
    }
    for (path, (sha256, bytes)) in &listed {
        if path == MARKER {
            continue;
        }
        let file = out.join(path);
        match std::fs::metadata(&file) {
            Err(_) => differences.push(format!("{path} is missing")),
            Ok(meta) if meta.len() != *bytes => differences.push(format!(
                "{path} has {} bytes, the manifest {bytes}",
                meta.len()
            )),
            Ok(_) => {
                if file_sha256(&file).ok().as_ref() != Some(sha256) {
                    differences.push(format!(
                        "{path} changed (its SHA-256 is not the manifest's)"
                    ));
                }
            }
        }
    }
    differences.extend(vector_count_differences(out, &manifest));
    if differences.is_empty() {
        return Ok(());
    }
    Err(Error::Simulation(format!(
        "{} does not match its {MANIFEST}, so its testbenches would not check what gyrofx generated: {}; regenerate the package (gyrofx generate) or restore its files",
        out.display(),
        differences.join("; ")
    )))
}

/// Each block whose `<block>/<block>_params.vh` `VECTOR_COUNT` differs from the manifest's
/// vector count (the testbench checks that many vectors and says `PASS n=<that many>`).
fn vector_count_differences(out: &Path, manifest: &serde_json::Value) -> Vec<String> {
    let mut differences = Vec::new();
    for (block, section) in manifest["blocks"].as_object().into_iter().flatten() {
        let Some(vectors) = section["vectors"].as_u64() else {
            continue;
        };
        let params = format!("{block}/{block}_params.vh");
        if let Ok(text) = std::fs::read_to_string(out.join(&params)) {
            let count = text
                .lines()
                .filter_map(|l| l.split_once("VECTOR_COUNT ="))
                .find_map(|(_, v)| v.trim().trim_end_matches(';').trim().parse::<u64>().ok());
            if count != Some(vectors) {
                differences.push(format!(
                    "{params}: VECTOR_COUNT {} but the manifest gives {vectors} vectors",
                    count.map_or("missing".into(), |c| c.to_string())
                ));
            }
        }
    }
    differences
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn create_below_makes_the_folders_under_root_but_never_root_again() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path().join("staging");
        std::fs::create_dir(&root).unwrap();
        create_below(&root, &root.join("kf/deeper")).unwrap();
        assert!(root.join("kf/deeper").is_dir());
        // Again: the folders exist, which is no error.
        create_below(&root, &root.join("kf/deeper")).unwrap();
        create_below(&root, &root).unwrap();
        // The staging folder removed (a signal handler): it is not brought back.
        std::fs::remove_dir_all(&root).unwrap();
        let error = create_below(&root, &root.join("kf")).unwrap_err();
        assert_eq!(error.kind(), std::io::ErrorKind::NotFound);
        assert!(!root.exists());
        let error = create_below(&root, dir.path()).unwrap_err();
        assert_eq!(error.kind(), std::io::ErrorKind::InvalidInput);
    }

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

    #[test]
    fn stale_work_folders_of_ended_processes_are_removed() {
        let temp = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let gone = child.id();
        child.wait().unwrap();
        let own = std::process::id();
        for name in [
            format!("{WORK_PREFIX}{gone}-abc"),
            format!("{WORK_PREFIX}{own}-abc"),
            format!("{WORK_PREFIX}xyz"),
        ] {
            std::fs::create_dir(temp.path().join(name)).unwrap();
        }
        clean_stale_work(temp.path());
        let mut left: Vec<String> = std::fs::read_dir(temp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        assert_eq!(
            left,
            [
                format!("{WORK_PREFIX}{own}-abc"),
                format!("{WORK_PREFIX}xyz")
            ]
        );
    }

    /// Staged files of ended processes go, whichever command staged them; a file gyrofx did
    /// not name (no pid where its own names have one) stays, however old.
    #[test]
    fn stale_staged_files_are_removed_and_nothing_else() {
        let folder = tempfile::tempdir().unwrap();
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let gone = child.id();
        child.wait().unwrap();
        let own = std::process::id();
        let week_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(7 * 86400);
        for name in [
            format!(".gyrofx-plot-{gone}-x1.png"),
            format!(".gyrofx-plot-{own}-x2.png"),
            ".gyrofx-my-notes.txt".to_string(),
            ".gyrofx-notes".to_string(),
            format!("{LOCK_PREFIX}out"),
        ] {
            let file = std::fs::File::create(folder.path().join(name)).unwrap();
            file.set_modified(week_ago).unwrap();
        }
        let staged = staged_file(folder.path(), ".gyrofx-formats-", ".toml").unwrap();
        let mut left: Vec<String> = std::fs::read_dir(folder.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        let staged_name = staged
            .path()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let mut want = vec![
            format!(".gyrofx-plot-{own}-x2.png"),
            ".gyrofx-my-notes.txt".to_string(),
            ".gyrofx-notes".to_string(),
            format!("{LOCK_PREFIX}out"),
            staged_name,
        ];
        want.sort();
        assert_eq!(left, want);
    }

    #[test]
    fn an_output_holding_an_input_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let config = dir.path().join("c.toml");
        std::fs::write(&config, "").unwrap();
        let inputs = [("--config", config.as_path())];
        let same = refuse_overlap(("--output", &config), &inputs).unwrap_err();
        assert!(same.contains("is the --config file"), "{same}");
        let holds = refuse_overlap(("--out", dir.path()), &inputs).unwrap_err();
        assert!(holds.contains("holds the --config file"), "{holds}");
        // Through a name that does not exist yet.
        let other = dir.path().join("new/../c.toml");
        assert!(refuse_overlap(("--out", &other), &inputs).is_err());
        assert!(refuse_overlap(("--out", &dir.path().join("out")), &inputs).is_ok());
    }
}
