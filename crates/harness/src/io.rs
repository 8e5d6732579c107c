//! File helpers: atomic writes (temp file in the same directory + rename) and JSON I/O
//! with errors that name the file.

use crate::error::{HarnessError, Result};
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::Path;

/// Creates `dir` and its parents.
pub fn create_dir(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| HarnessError::Io { path: dir.to_path_buf(), source })
}

/// Writes `bytes` to `path` atomically: a reader sees the old file or the new one, never
/// a partial one (an interrupted sweep leaves no truncated JSON behind).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| HarnessError::Io { path: path.to_path_buf(), source };
    if let Some(dir) = path.parent() {
        create_dir(dir)?;
    }
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    std::fs::write(&tmp, bytes).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        io(e)
    })
}

/// Serialises `value` as pretty JSON (with a final newline) and writes it atomically.
pub fn write_json<T: Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)
        .map_err(|source| HarnessError::Json { path: path.to_path_buf(), source })?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// Reads a whole text file.
pub fn read_text(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).map_err(|source| HarnessError::Io { path: path.to_path_buf(), source })
}

/// Reads and parses a JSON file.
pub fn read_json<T: DeserializeOwned>(path: &Path) -> Result<T> {
    let text = read_text(path)?;
    serde_json::from_str(&text).map_err(|source| HarnessError::Json { path: path.to_path_buf(), source })
}

#[cfg(test)]
pub(crate) mod testing {
    //! A scratch directory for tests, removed on drop (no `tempfile` dependency needed).

    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// A fresh empty directory under the system temp dir.
    pub struct Scratch(PathBuf);

    impl Scratch {
        /// Creates `$TMPDIR/meniscus-harness-<pid>-<n>-<tag>`.
        pub fn new(tag: &str) -> Self {
            static N: AtomicUsize = AtomicUsize::new(0);
            let n = N.fetch_add(1, Ordering::Relaxed);
            let dir = std::env::temp_dir().join(format!("meniscus-harness-{}-{n}-{tag}", std::process::id()));
            let _ = std::fs::remove_dir_all(&dir);
            std::fs::create_dir_all(&dir).expect("scratch dir");
            Scratch(dir)
        }

        /// The directory.
        pub fn path(&self) -> &Path {
            &self.0
        }
    }

    impl Drop for Scratch {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::testing::Scratch;
    use super::*;

    #[test]
    fn atomic_json_round_trip_leaves_no_temp_file() {
        let dir = Scratch::new("io");
        let path = dir.path().join("a/b/x.json");
        write_json(&path, &serde_json::json!({"k": [1, 2]})).unwrap();
        write_json(&path, &serde_json::json!({"k": [3]})).unwrap();
        let v: serde_json::Value = read_json(&path).unwrap();
        assert_eq!(v["k"][0], 3);
        let names: Vec<_> =
            std::fs::read_dir(path.parent().unwrap()).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }
}
