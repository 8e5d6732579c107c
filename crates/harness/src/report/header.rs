//! The header of the index and `summary.md`: what was run, when, from which commit, on
//! which machine, how long it took, against which baseline; read from the cases'
//! provenance records and results only.

use crate::case::CaseRecord;
use crate::results::{CaseResults, Totals};
use std::collections::BTreeSet;
use std::path::Path;

/// The facts of the header. A field that differs between the cases lists every value
/// (cases rendered from several invocations).
#[derive(Debug, Clone, PartialEq)]
pub struct Header {
    /// Tiers of the cases (`quick`).
    pub tiers: Vec<String>,
    /// Date of the latest case (UTC), when recorded.
    pub date_utc: Option<String>,
    /// Commits (short), with ` (dirty)` where the work tree had changes.
    pub commits: Vec<String>,
    /// Machines: host, CPU model and logical CPUs.
    pub machines: Vec<String>,
    /// Rayon threads of the harness.
    pub threads: Vec<usize>,
    /// Runs, with their summed wall and CPU seconds and particle-steps.
    pub totals: Totals,
    /// Wall time of the last invocation that ran runs \[s\].
    pub elapsed_s: Option<f64>,
    /// The baseline directory, when compared with one.
    pub baseline: Option<String>,
}

/// The distinct values in first-seen order.
fn distinct<T: Ord + Clone>(values: impl Iterator<Item = T>) -> Vec<T> {
    let mut seen = BTreeSet::new();
    values.filter(|v| seen.insert(v.clone())).collect()
}

impl Header {
    /// The header of `results` with their `records` (`records[i]` belongs to `results[i]`).
    pub fn of(
        results: &[CaseResults],
        records: &[Option<&CaseRecord>],
        elapsed_s: Option<f64>,
        baseline: Option<&Path>,
    ) -> Self {
        let provenance: Vec<_> = records.iter().flatten().map(|r| &r.provenance).collect();
        Header {
            tiers: distinct(results.iter().map(|r| r.tier.clone())),
            date_utc: provenance.iter().map(|p| p.date_utc.clone()).filter(|d| !d.is_empty()).max(),
            commits: distinct(provenance.iter().map(|p| {
                let short: String = p.git_commit.as_deref().unwrap_or("unknown").chars().take(10).collect();
                if p.git_dirty == Some(true) { format!("{short} (dirty)") } else { short }
            })),
            machines: distinct(provenance.iter().map(|p| {
                format!(
                    "{}: {}, {} logical CPUs",
                    p.hostname.as_deref().unwrap_or("unknown host"),
                    p.cpu.as_deref().unwrap_or("unknown CPU"),
                    p.cpus.map_or("?".to_string(), |n| n.to_string())
                )
            })),
            threads: distinct(provenance.iter().map(|p| p.threads)),
            totals: Totals::of(results.iter().flat_map(|r| &r.runs)),
            elapsed_s,
            baseline: baseline.map(|b| b.display().to_string()),
        }
    }

    /// `(label, value)` lines in display order.
    pub fn lines(&self) -> Vec<(&'static str, String)> {
        let join = |v: &[String]| if v.is_empty() { "unknown".to_string() } else { v.join("; ") };
        let t = &self.totals;
        let mut time = format!("{} runs, {:.0} s of run wall time", t.runs, t.wall_s);
        if let Some(cpu) = t.measured_cpu_s() {
            time.push_str(&format!(", {cpu:.0} s of CPU time"));
        }
        if let Some(e) = self.elapsed_s {
            time.push_str(&format!("; the last invocation that ran runs took {e:.0} s wall"));
        }
        vec![
            ("tier", join(&self.tiers)),
            ("date (UTC)", self.date_utc.clone().unwrap_or_else(|| "unknown".into())),
            ("commit", join(&self.commits)),
            ("machine", join(&self.machines)),
            ("threads", join(&self.threads.iter().map(|n| n.to_string()).collect::<Vec<_>>())),
            ("time", time),
            ("baseline", self.baseline.clone().unwrap_or_else(|| "none".into())),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::provenance::Provenance;

    #[test]
    fn lists_what_differs_between_cases() {
        let record = |commit: &str, date: &str, dirty| CaseRecord {
            case: crate::case::testing::committed("elliptical_drop"),
            provenance: Provenance {
                git_commit: Some(commit.into()),
                git_dirty: Some(dirty),
                hostname: Some("box".into()),
                cpu: Some("Xeon".into()),
                cpus: Some(2),
                threads: 2,
                date_utc: date.into(),
                harness_version: "0.1.0".into(),
            },
            scene_hashes: Default::default(),
        };
        let a = record("0123456789abcdef", "2026-12-07T10:00:00Z", false);
        let b = record("fedcba9876543210", "2026-12-07T11:00:00Z", true);
        let h = Header::of(&[], &[Some(&a), Some(&b), Some(&a)], Some(116.4), None);
        let lines: std::collections::BTreeMap<_, _> = h.lines().into_iter().collect();
        assert_eq!(lines["commit"], "0123456789; fedcba9876 (dirty)");
        assert_eq!(lines["date (UTC)"], "2026-12-07T11:00:00Z");
        assert_eq!(lines["machine"], "box: Xeon, 2 logical CPUs");
        assert_eq!(lines["threads"], "2");
        assert_eq!(
            lines["time"],
            "0 runs, 0 s of run wall time; the last invocation that ran runs took 116 s wall"
        );
        assert_eq!(lines["baseline"], "none");
    }
}
