//! [`Package`]: an output folder built in memory and written all or nothing.

use std::path::{Path, PathBuf};

use crate::output_folder::{self, Kind, Marker, Replace, MANIFEST, MARKER, OLD_PREFIX};
use gyrofx_job::error::{Error, Result};
use gyrofx_job::hash::sha256_hex;

/// Files of an output folder, by relative path: built in memory, or already written into the
/// staging folder (streamed vector files) with their entries.
#[derive(Clone, Debug)]
pub struct Package {
    kind: Kind,
    files: Vec<(PathBuf, Content)>,
}

/// A file of a [`Package`].
#[derive(Clone, Debug)]
enum Content {
    /// To be written.
    Data(Vec<u8>),
    /// Written already, into the staging folder the package goes to.
    Written(FileEntry),
}

/// A file's entry in the manifest.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FileEntry {
    /// Relative path, `/`-separated.
    pub path: String,
    /// SHA-256 of the content, hex.
    pub sha256: String,
    /// Size in bytes.
    pub bytes: usize,
}

impl Package {
    /// A package of `kind` holding only its marker, which lists `build_outputs`: the paths
    /// the package's own Makefile writes (see [`Marker`]). Adding the manifest records its
    /// SHA-256 in the marker.
    pub fn new(kind: Kind, build_outputs: Vec<String>) -> Self {
        Package {
            kind,
            files: vec![(
                PathBuf::from(MARKER),
                Content::Data(Marker::new(kind, build_outputs).text().into_bytes()),
            )],
        }
    }

    /// Adds a file at the relative `path`. The manifest ([`MANIFEST`]) also goes into the
    /// marker, as its SHA-256: then an edit to the manifest is a changed file too.
    pub fn add(&mut self, path: impl Into<PathBuf>, content: impl Into<Vec<u8>>) {
        let (path, content) = (path.into(), content.into());
        if path == Path::new(MANIFEST) {
            self.record_manifest(&content);
        }
        self.files.push((path, Content::Data(content)));
    }

    /// Rewrites the marker with the manifest's SHA-256.
    fn record_manifest(&mut self, manifest: &[u8]) {
        for (path, content) in &mut self.files {
            if path == Path::new(MARKER) {
                if let Content::Data(data) = content {
                    if let Ok(mut marker) = serde_json::from_slice::<Marker>(data) {
                        marker.manifest_sha256 = Some(sha256_hex(manifest));
                        *data = marker.text().into_bytes();
                    }
                }
            }
        }
    }

    /// Lists a file already written into the staging folder the package will be written to
    /// ([`Package::write_staged`]).
    pub fn add_written(&mut self, entry: FileEntry) {
        self.files
            .push((PathBuf::from(entry.path.clone()), Content::Written(entry)));
    }

    /// Relative paths of every file so far, `/`-separated, in the order added.
    pub fn paths(&self) -> Vec<String> {
        self.files
            .iter()
            .map(|(path, _)| path.to_string_lossy().replace('\\', "/"))
            .collect()
    }

    /// Entries of every file so far but the marker, in the order added (hashed on parallel
    /// threads): the manifest lists these, and the marker, written after it, records the
    /// manifest's SHA-256 instead.
    pub fn entries(&self) -> Vec<FileEntry> {
        std::thread::scope(|scope| {
            let hashes: Vec<_> = self
                .files
                .iter()
                .map(|(_, content)| {
                    scope.spawn(move || match content {
                        Content::Data(data) => (sha256_hex(data), data.len()),
                        Content::Written(entry) => (entry.sha256.clone(), entry.bytes),
                    })
                })
                .collect();
            self.paths()
                .into_iter()
                .zip(hashes)
                .filter(|(path, _)| path != MARKER)
                .map(|(path, hash)| {
                    let (sha256, bytes) = hash.join().expect("hashing does not panic");
                    FileEntry {
                        path,
                        sha256,
                        bytes,
                    }
                })
                .collect()
        })
    }

    /// Writes the package to `out`, all or nothing: into a staging folder beside `out`
    /// ([`Staging`]), then renamed into place. An existing `out` is replaced only as
    /// [`output_folder::check`] allows; anything else is refused untouched.
    ///
    /// # Errors
    /// [`Error::Output`] when `out` cannot be used, [`Error::Io`] when writing fails (the
    /// staging folder is removed).
    pub fn write_atomically(&self, out: &Path, replace: Replace) -> Result<()> {
        let staging = Staging::create(out, self.kind, replace)?;
        self.write_staged(staging)
    }

    /// Writes the files not written yet into `staging` and moves it into place.
    ///
    /// # Errors
    /// As [`Package::write_atomically`].
    pub fn write_staged(&self, staging: Staging) -> Result<()> {
        self.write_files(&staging.path)?;
        staging.commit()
    }

    /// Writes every file under `root`, one thread per file: the large vector files are
    /// written side by side.
    fn write_files(&self, root: &Path) -> Result<()> {
        let pending = self
            .files
            .iter()
            .filter_map(|(path, content)| match content {
                Content::Data(data) => Some((path, data)),
                Content::Written(_) => None,
            });
        for (path, _) in pending.clone() {
            if let Some(folder) = root.join(path).parent() {
                output_folder::create_below(root, folder).map_err(|e| Error::io(folder, e))?;
            }
        }
        std::thread::scope(|scope| {
            let writers: Vec<_> = pending
                .map(|(path, data)| {
                    let target = root.join(path);
                    scope.spawn(move || {
                        if output_folder::interrupted() {
                            return Err(Error::io(
                                &target,
                                std::io::Error::from(std::io::ErrorKind::Interrupted),
                            ));
                        }
                        std::fs::write(&target, data).map_err(|e| Error::io(&target, e))
                    })
                })
                .collect();
            writers
                .into_iter()
                .try_for_each(|w| w.join().expect("writing does not panic"))
        })
    }
}

/// A staging folder beside an output folder: where a package is written before it is renamed
/// into place. Creating it checks the output folder ([`output_folder::check`]) and removes
/// staging folders a killed run left there ([`output_folder::clean_stale`]); it is registered
/// for removal on a signal ([`output_folder::remove_registered`]) and removed when dropped
/// without [`Staging::commit`] (any error on the way).
#[derive(Debug)]
pub struct Staging {
    path: PathBuf,
    out: PathBuf,
    parent: PathBuf,
    kind: Kind,
    replace: Replace,
    committed: bool,
    /// The output folder's lock, held until the staging folder is committed or removed.
    lock: Option<output_folder::Lock>,
    /// The outermost parent folder this staging created (removed again, if empty, when the
    /// package is not committed).
    created_parent: Option<PathBuf>,
}

impl Staging {
    /// A staging folder for `out`, a package of `kind`.
    ///
    /// # Errors
    /// [`Error::Output`] when `out` may not be replaced or the folder cannot be created.
    pub fn create(out: &Path, kind: Kind, replace: Replace) -> Result<Self> {
        let refuse = |message: String| Error::Output {
            path: out.to_path_buf(),
            message,
        };
        output_folder::check(out, kind, replace)?;
        let parent = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let created_parent = parent
            .ancestors()
            .take_while(|a| !a.as_os_str().is_empty() && !a.exists())
            .last()
            .map(Path::to_path_buf);
        std::fs::create_dir_all(&parent)
            .map_err(|e| refuse(format!("cannot create its parent folder: {e}")))?;
        let lock = match output_folder::lock(out) {
            Ok(lock) => lock,
            Err(e) => {
                remove_created(&parent, created_parent.as_deref());
                return Err(e);
            }
        };
        output_folder::clean_stale(&parent);
        let path = match output_folder::create_staging(&parent) {
            Ok(path) => path,
            Err(e) => {
                drop(lock);
                remove_created(&parent, created_parent.as_deref());
                return Err(refuse(format!(
                    "cannot create a temporary folder in {}: {e}",
                    parent.display()
                )));
            }
        };
        Ok(Staging {
            path,
            out: out.to_path_buf(),
            parent,
            kind,
            replace,
            committed: false,
            lock: Some(lock),
            created_parent,
        })
    }

    /// The staging folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Renames the staging folder to the output folder (a previous one moved aside first and
    /// removed after), once the output folder has been checked again.
    ///
    /// # Errors
    /// [`Error::Output`] when the output folder may no longer be replaced or the rename fails
    /// (the staging folder is removed).
    pub fn commit(mut self) -> Result<()> {
        if let Some(hold) = std::env::var("GYROFX_TEST_HOLD_STAGING_MS")
            .ok()
            .and_then(|ms| ms.parse::<u64>().ok())
        {
            // Test hook: lets a test signal the process while the staging folder exists.
            std::thread::sleep(std::time::Duration::from_millis(hold));
        }
        if output_folder::interrupted() {
            return Err(Error::io(
                &self.path,
                std::io::Error::from(std::io::ErrorKind::Interrupted),
            ));
        }
        // Checked again: the output folder may have changed during a long run.
        output_folder::check(&self.out, self.kind, self.replace)?;
        let result = Self::move_into_place(&self.path, &self.out, &self.parent);
        self.committed = result.is_ok();
        result
    }

    /// Renames `staged` to `out`, moving a previous `out` aside first and removing it after.
    fn move_into_place(staged: &Path, out: &Path, parent: &Path) -> Result<()> {
        let refuse = |message: String| Error::Output {
            path: out.to_path_buf(),
            message,
        };
        let replaced = if out.exists() {
            keep_mode_and_owner(out, staged);
            let old = parent.join(format!(
                "{OLD_PREFIX}{}-{}",
                std::process::id(),
                out.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default()
            ));
            if let Err(e) = std::fs::rename(out, &old) {
                return Err(refuse(format!(
                    "cannot move the previous output aside: {e}"
                )));
            }
            Some(old)
        } else {
            None
        };
        if let Err(e) = std::fs::rename(staged, out) {
            if let Some(old) = &replaced {
                let _ = std::fs::rename(old, out);
            }
            return Err(refuse(format!(
                "cannot move the new output into place: {e}"
            )));
        }
        if let Some(old) = replaced {
            let _ = std::fs::remove_dir_all(&old);
        }
        Ok(())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.path);
        }
        output_folder::unregister(&self.path);
        // The lock file is in the parent: gone before the parent may be removed.
        drop(self.lock.take());
        if !self.committed {
            remove_created(&self.parent, self.created_parent.as_deref());
        }
    }
}

/// Removes `parent` and its ancestors up to `created` (the outermost folder a staging created
/// for it), those that are empty: a refused package leaves no folders behind.
fn remove_created(parent: &Path, created: Option<&Path>) {
    let Some(created) = created else {
        return;
    };
    for folder in parent.ancestors() {
        if !folder.starts_with(created) || std::fs::remove_dir(folder).is_err() {
            break;
        }
    }
}

/// Gives the staged folder the permissions (and, where this process may, the owner and group)
/// of the folder it replaces: an existing `--out` (a private 0700 folder) keeps them.
fn keep_mode_and_owner(out: &Path, staged: &Path) {
    let Ok(meta) = std::fs::metadata(out) else {
        return;
    };
    let _ = std::fs::set_permissions(staged, meta.permissions());
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        let _ = std::os::unix::fs::chown(staged, Some(meta.uid()), Some(meta.gid()));
    }
}
