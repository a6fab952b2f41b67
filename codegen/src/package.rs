//! [`Package`]: an output folder built in memory and written all or nothing.

use std::path::{Path, PathBuf};

use sha2::{Digest, Sha256};

use crate::error::{Error, Result};

/// The file that marks a folder as a gyrofx output (and so safe to replace).
pub const MANIFEST: &str = "manifest.json";

/// Files of an output folder, by relative path.
#[derive(Clone, Debug, Default)]
pub struct Package {
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
    /// An empty package.
    pub fn new() -> Self {
        Package::default()
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

    /// Writes the package to `out`, all or nothing: into a temporary folder beside `out`, then
    /// renamed into place. An existing `out` is replaced only when it is empty or a previous
    /// gyrofx output (it holds a `manifest.json`); anything else is refused untouched.
    ///
    /// # Errors
    /// [`Error::Output`] when `out` cannot be used, [`Error::Io`] when writing fails (the
    /// temporary folder is removed).
    pub fn write_atomically(&self, out: &Path) -> Result<()> {
        let refuse = |message: String| Error::Output {
            path: out.to_path_buf(),
            message,
        };
        if out.exists() {
            if !out.is_dir() {
                return Err(refuse("exists and is not a folder".into()));
            }
            let mut entries = std::fs::read_dir(out).map_err(|e| Error::io(out, e))?;
            let empty = entries.next().is_none();
            if !empty && !out.join(MANIFEST).is_file() {
                return Err(refuse(
                    "exists, is not empty and holds no manifest.json: not a gyrofx output, so it is not replaced".into(),
                ));
            }
        }
        let parent = match out.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        std::fs::create_dir_all(&parent)
            .map_err(|e| refuse(format!("cannot create its parent folder: {e}")))?;
        let staging = tempfile::Builder::new()
            .prefix(".gyrofx-staging-")
            .tempdir_in(&parent)
            .map_err(|e| {
                refuse(format!(
                    "cannot create a temporary folder in {}: {e}",
                    parent.display()
                ))
            })?;
        for (path, _) in &self.files {
            if let Some(folder) = staging.path().join(path).parent() {
                std::fs::create_dir_all(folder).map_err(|e| Error::io(folder, e))?;
            }
        }
        // One thread per file: the large vector files are written side by side.
        std::thread::scope(|scope| {
            let writers: Vec<_> = self
                .files
                .iter()
                .map(|(path, data)| {
                    let target = staging.path().join(path);
                    scope.spawn(move || {
                        std::fs::write(&target, data).map_err(|e| Error::io(&target, e))
                    })
                })
                .collect();
            writers
                .into_iter()
                .try_for_each(|w| w.join().expect("writing does not panic"))
        })?;
        let staged = staging.keep();
        let replaced = if out.exists() {
            let old = parent.join(format!(
                ".gyrofx-old-{}",
                out.file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default()
            ));
            let _ = std::fs::remove_dir_all(&old);
            if let Err(e) = std::fs::rename(out, &old) {
                let _ = std::fs::remove_dir_all(&staged);
                return Err(refuse(format!(
                    "cannot move the previous output aside: {e}"
                )));
            }
            Some(old)
        } else {
            None
        };
        if let Err(e) = std::fs::rename(&staged, out) {
            if let Some(old) = &replaced {
                let _ = std::fs::rename(old, out);
            }
            let _ = std::fs::remove_dir_all(&staged);
            return Err(refuse(format!(
                "cannot move the new output into place: {e}"
            )));
        }
        if let Some(old) = replaced {
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(())
    }
}
