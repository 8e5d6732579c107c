//! The run cache: every finished run is stored at `reports/<case>/runs/<slug>.json`
//! (atomically, with `"completed": true` and the SHA-256 of its effective scene and of the
//! solver build), and reused by the next invocation unless `--force`, the scene changed or
//! the solver was rebuilt from changed code. Metrics are
//! recomputed from the cached probes each time, so changing a metric never needs a rerun.

use crate::error::Result;
use crate::io;
use serde::{Deserialize, Deserializer, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A finished run as cached on disk (the raw solver output, before metrics).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    /// Always `true` in a written record (an absent or false flag means "rerun").
    pub completed: bool,
    /// Run slug (`isph-paper_dx0.02`).
    pub slug: String,
    /// Scheme.
    pub scheme: String,
    /// Preset.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// SHA-256 (hex) of the solver build fingerprint and the effective scene JSON.
    pub scene_hash: String,
    /// The effective scene.
    pub scene: serde_json::Value,
    /// The solver's `summary.json`.
    pub summary: meniscus::Summary,
    /// The solver's `probes.json` content (non-finite samples written as `null`).
    pub probes: CachedProbes,
    /// The particles at the scene's `output.snapshot_times` (absent when none).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub snapshots: Vec<crate::snapshots::Snapshot>,
    /// CPU time of the threads that ran the run (user + system) \[s\]; absent off Linux.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cpu_s: Option<f64>,
    /// Threads the run had (its rayon pool); absent in records written before it was kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
}

impl RunRecord {
    /// The run's status as DESIGN.md writes it: `ok`, or `diverged: <cause at step/time>`.
    pub fn status(&self) -> String {
        if self.summary.status == meniscus::Status::Ok && self.summary.error.is_none() {
            "ok".to_string()
        } else {
            format!("diverged: {}", self.summary.error.as_deref().unwrap_or("unknown cause"))
        }
    }
}

/// `probes.json` content that survives NaN samples (written as `null`, read back as NaN).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CachedProbes {
    /// Sample times \[s\].
    #[serde(deserialize_with = "nan_vec")]
    pub t: Vec<f64>,
    /// Kind → quantity → values.
    #[serde(flatten, deserialize_with = "nan_nested")]
    pub series: BTreeMap<String, BTreeMap<String, Vec<f64>>>,
}

impl From<meniscus::ProbeRecord> for CachedProbes {
    fn from(p: meniscus::ProbeRecord) -> Self {
        CachedProbes { t: p.t, series: p.series }
    }
}

impl From<CachedProbes> for meniscus::ProbeRecord {
    fn from(p: CachedProbes) -> Self {
        meniscus::ProbeRecord { t: p.t, series: p.series }
    }
}

fn nan_vec<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Vec<f64>, D::Error> {
    let v: Vec<Option<f64>> = Deserialize::deserialize(d)?;
    Ok(v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect())
}

type Nested = BTreeMap<String, BTreeMap<String, Vec<f64>>>;

fn nan_nested<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<Nested, D::Error> {
    let m: BTreeMap<String, BTreeMap<String, Vec<Option<f64>>>> = Deserialize::deserialize(d)?;
    Ok(m.into_iter()
        .map(|(k, q)| {
            (
                k,
                q.into_iter()
                    .map(|(n, v)| (n, v.into_iter().map(|x| x.unwrap_or(f64::NAN)).collect()))
                    .collect(),
            )
        })
        .collect())
}

/// SHA-256 (lower-case hex) of `text`.
pub fn sha256_hex(text: &str) -> String {
    use sha2::{Digest, Sha256};
    Sha256::digest(text.as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
}

/// Where the record of run `slug` of a case lives.
pub fn record_path(case_dir: &Path, slug: &str) -> PathBuf {
    case_dir.join("runs").join(format!("{slug}.json"))
}

/// The cached record at `path` if it is complete and was produced from a scene with hash
/// `scene_hash`; `None` otherwise (missing, unreadable, interrupted or stale).
pub fn load(path: &Path, scene_hash: &str) -> Option<RunRecord> {
    let record: RunRecord = io::read_json(path).ok()?;
    (record.completed && record.scene_hash == scene_hash).then_some(record)
}

/// Whether [`load`] would reuse the record at `path`: it reads the file but keeps only the
/// two fields checked (the runner asks this of every job before it runs any).
pub fn is_cached(path: &Path, scene_hash: &str) -> bool {
    #[derive(Deserialize)]
    struct Head {
        completed: bool,
        scene_hash: String,
    }
    io::read_json::<Head>(path).is_ok_and(|h| h.completed && h.scene_hash == scene_hash)
}

/// Stores a record atomically.
pub fn store(path: &Path, record: &RunRecord) -> Result<()> {
    io::write_json(path, record)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    pub(crate) fn record(hash: &str) -> RunRecord {
        RunRecord {
            completed: true,
            slug: "isph-paper_dx0.04".into(),
            scheme: "isph".into(),
            preset: "paper".into(),
            dx: 0.04,
            scene_hash: hash.into(),
            scene: serde_json::json!({"dx": 0.04}),
            summary: meniscus::Summary {
                scene: "s".into(),
                particles: 4,
                steps: 2,
                t_end: 1.0,
                wall_s: 0.5,
                status: meniscus::Status::Ok,
                error: None,
                stages: BTreeMap::new(),
                threads: 1,
                ppe_iterations_mean: 3.0,
                steady_at: None,
            },
            probes: CachedProbes {
                t: vec![0.0, 1.0],
                series: [("kinetic_energy".to_string(), [("e".to_string(), vec![1.0, f64::NAN])].into())]
                    .into(),
            },
            snapshots: Vec::new(),
            cpu_s: None,
            threads: None,
        }
    }

    #[test]
    fn hash_is_sha256() {
        assert_eq!(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    }

    #[test]
    fn reuses_only_complete_records_with_the_same_hash() {
        let dir = Scratch::new("cache");
        let path = record_path(dir.path(), "isph-paper_dx0.04");
        assert!(load(&path, "h1").is_none(), "nothing cached yet");
        store(&path, &record("h1")).unwrap();
        let back = load(&path, "h1").expect("same hash: reused");
        assert!(back.probes.series["kinetic_energy"]["e"][1].is_nan(), "NaN survives as null");
        assert!(load(&path, "h2").is_none(), "scene changed: rerun");
        let mut incomplete = record("h1");
        incomplete.completed = false;
        store(&path, &incomplete).unwrap();
        assert!(load(&path, "h1").is_none(), "interrupted: rerun");
        std::fs::write(&path, "{\"completed\": tr").unwrap();
        assert!(load(&path, "h1").is_none(), "truncated: rerun");
    }
}
