//! [`Package`]: an output folder built in memory and written all or nothing.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::error::{Error, Result};
use crate::output_folder::{self, Kind, Marker, Replace, MARKER, OLD_PREFIX};

/// The package's file list with each file's SHA-256 (with the marker, what makes a folder a
/// gyrofx output that may be replaced: [`output_folder::check`]).
pub const MANIFEST: &str = "manifest.json";

/// Files of an output folder, by relative path.
#[derive(Clone, Debug)]
pub struct Package {
    kind: Kind,
    files: Vec<(PathBuf, Vec<u8>)>,
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

/// SHA-256 of `data` as lowercase hex.
pub fn sha256_hex(data: &[u8]) -> String {
    Sha256::digest(data)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

impl Package {
    /// A package of `kind` holding only its marker, which lists `build_outputs`: the paths
    /// the package's own Makefile writes (see [`Marker`]).
    pub fn new(kind: Kind, build_outputs: Vec<String>) -> Self {
        Package {
            kind,
            files: vec![(
                PathBuf::from(MARKER),
                Marker::new(kind, build_outputs).text().into_bytes(),
            )],
        }
    }

    /// Adds a file at the relative `path`.
    pub fn add(&mut self, path: impl Into<PathBuf>, content: impl Into<Vec<u8>>) {
        self.files.push((path.into(), content.into()));
    }

    /// Relative paths of every file so far, `/`-separated, in the order added.
    pub fn paths(&self) -> Vec<String> {
        self.files
            .iter()
            .map(|(path, _)| path.to_string_lossy().replace('\\', "/"))
            .collect()
    }

    /// Entries of every file so far, in the order added (hashed on parallel threads).
    pub fn entries(&self) -> Vec<FileEntry> {
        std::thread::scope(|scope| {
            let hashes: Vec<_> = self
                .files
                .iter()
                .map(|(_, data)| scope.spawn(move || sha256_hex(data)))
                .collect();
            self.paths()
                .into_iter()
                .zip(hashes)
                .zip(&self.files)
                .map(|((path, hash), (_, data))| FileEntry {
                    path,
                    sha256: hash.join().expect("hashing does not panic"),
                    bytes: data.len(),
                })
                .collect()
        })
    }

    /// Writes the package to `out`, all or nothing: into a staging folder beside `out`, then
    /// renamed into place. An existing `out` is replaced only as [`output_folder::check`]
    /// allows; anything else is refused untouched. The staging folder is removed on an error
    /// and, through [`output_folder::remove_registered`], on a signal; ones a killed run left
    /// in the same parent folder are removed first ([`output_folder::clean_stale`]).
    ///
    /// # Errors
    /// [`Error::Output`] when `out` cannot be used, [`Error::Io`] when writing fails (the
    /// staging folder is removed).
    pub fn write_atomically(&self, out: &Path, replace: Replace) -> Result<()> {
        let refuse = |message: String| Error::Output {
            path: out.to_path_buf(),
            message,
        };
        output_folder::check(out, self.kind, replace)?;
        let parent = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .map_err(|e| refuse(format!("cannot create its parent folder: {e}")))?;
        output_folder::clean_stale(&parent);
        let staged = output_folder::create_staging(&parent).map_err(|e| {
            refuse(format!(
                "cannot create a temporary folder in {}: {e}",
                parent.display()
            ))
        })?;
        let written = self.write_files(&staged);
        if let Some(hold) = std::env::var("GYROFX_TEST_HOLD_STAGING_MS")
            .ok()
            .and_then(|ms| ms.parse::<u64>().ok())
        {
            // Test hook: lets a test signal the process while the staging folder exists.
            std::thread::sleep(std::time::Duration::from_millis(hold));
        }
        let result = written.and_then(|()| self.move_into_place(&staged, out, &parent));
        if result.is_err() {
            let _ = std::fs::remove_dir_all(&staged);
        }
        output_folder::unregister(&staged);
        result
    }

    /// Writes every file under `root`, one thread per file: the large vector files are
    /// written side by side.
    fn write_files(&self, root: &Path) -> Result<()> {
        for (path, _) in &self.files {
            if let Some(folder) = root.join(path).parent() {
                std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
            }
        }
        std::thread::scope(|scope| {
            let writers: Vec<_> = self
                .files
                .iter()
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

    /// Renames `staged` to `out`, moving a previous `out` aside first and removing it after.
    fn move_into_place(&self, staged: &Path, out: &Path, parent: &Path) -> Result<()> {
        let refuse = |message: String| Error::Output {
            path: out.to_path_buf(),
            message,
        };
        let replaced = if out.exists() {
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
