//! Particle snapshots of a run (`output.snapshot_times` of its scene): positions and
//! pressures at the requested times, cached with the run and written to
//! `reports/<case>/snapshots/<slug>.json` for the report's scatter plots
//! ([`crate::report::plots::snapshots`]).

use crate::error::Result;
use crate::io;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The particles of a 2D run at one time (in initial-id order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Time \[s\].
    pub time: f64,
    /// Steps taken.
    pub step: usize,
    /// x coordinates \[m\].
    pub x: Vec<f64>,
    /// y coordinates \[m\].
    pub y: Vec<f64>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
}

impl From<&meniscus::Frame> for Snapshot {
    fn from(f: &meniscus::Frame) -> Self {
        Snapshot {
            time: f.time,
            step: f.step,
            x: f.x.iter().map(|x| x[0]).collect(),
            y: f.x.iter().map(|x| x[1]).collect(),
            p: f.p.clone(),
        }
    }
}

/// `reports/<case>/snapshots/<slug>.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SnapshotFile {
    /// Run slug.
    pub slug: String,
    /// Preset.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// The run's status (`ok` or `diverged: …`).
    pub status: String,
    /// The snapshots, in time order.
    pub frames: Vec<Snapshot>,
}

/// Where the snapshots of run `slug` of a case live.
pub fn path(case_dir: &Path, slug: &str) -> PathBuf {
    case_dir.join("snapshots").join(format!("{slug}.json"))
}

/// Writes `file` atomically as compact JSON (thousands of numbers per frame).
pub fn store(case_dir: &Path, file: &SnapshotFile) -> Result<()> {
    let p = path(case_dir, &file.slug);
    let bytes = serde_json::to_vec(file)
        .map_err(|source| crate::error::HarnessError::Json { path: p.clone(), source })?;
    io::write_atomic(&p, &bytes)
}

/// The snapshots of run `slug`, when written.
pub fn load(case_dir: &Path, slug: &str) -> Option<SnapshotFile> {
    io::read_json(&path(case_dir, slug)).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    #[test]
    fn round_trip_through_the_case_directory() {
        let dir = Scratch::new("snapshots");
        let frame = meniscus::Frame {
            step: 3,
            time: 0.01,
            x: vec![[0.1, 0.2, 0.0], [0.3, -0.4, 0.0]],
            u: vec![[0.0; 3]; 2],
            p: vec![-5.0, 7.5],
            free_surface: vec![false, true],
            ..Default::default()
        };
        let file = SnapshotFile {
            slug: "isph-shifting_dx0.02".into(),
            preset: "shifting".into(),
            dx: 0.02,
            status: "ok".into(),
            frames: vec![Snapshot::from(&frame)],
        };
        store(dir.path(), &file).unwrap();
        assert_eq!(load(dir.path(), "isph-shifting_dx0.02"), Some(file.clone()));
        assert_eq!(file.frames[0].y, [0.2, -0.4]);
        assert!(load(dir.path(), "isph-other_dx0.02").is_none());
    }
}
