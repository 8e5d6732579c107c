//! The study's data, `validation/studies/stability.json` (outside the case files, so case
//! discovery never sees it): the budget ([`Settings`]), the case and preset each base scene
//! starts from, the option sets ([`OptionSet`]) and the checks ([`Check`]). The bisections
//! and the error measures stay code (the runs depend on each other).
//!
//! Unknown fields are rejected; an error names the field (its path in the file), the value
//! and the rule it breaks.

use crate::checks::CheckSpec;
use crate::error::{HarnessError, Result};
use crate::io;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Display;
use std::path::Path;

/// Where the study's file lives, relative to `validation/`.
pub const FILE: &str = "studies/stability.json";

/// `validation/studies/stability.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// What the study is (for readers of the file).
    #[serde(default)]
    pub description: String,
    /// The budget (written to `results.json` as it is).
    pub settings: Settings,
    /// The elliptical drop's case file and the preset its scenes start from.
    pub drop: BaseCase,
    /// The periodic channel's case file and preset.
    pub channel: BaseCase,
    /// Every option set the budget may name, in display order.
    pub option_sets: Vec<OptionSet>,
    /// The checks of the envelope, in order.
    pub checks: Vec<Check>,
}

/// Spacings, ranges and bounds of a stability run (the budget).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Spacing of the drop \[m\].
    pub drop_dx: f64,
    /// End time of the drop's time-step and jitter runs \[s\] (the case's 0.008 s).
    pub drop_end: f64,
    /// End time of the drop's long run \[s\].
    pub long_end: f64,
    /// Spacing of the channel \[m\].
    pub channel_dx: f64,
    /// End time of the channel runs in viscous times D²/ν.
    pub channel_tau: f64,
    /// Search range of the time-step multiple k (the scene rule cfl ≤ 1 caps k at 5).
    pub dt_range: [f64; 2],
    /// Bisection steps of k.
    pub dt_iterations: usize,
    /// Search range of the Reynolds number.
    pub re_range: [f64; 2],
    /// Bisection steps of Re.
    pub re_iterations: usize,
    /// Jitter fractions of Δx.
    pub jitter: Vec<f64>,
    /// Seed of the jitter.
    pub seed: u64,
    /// Stability bound on the drop's error (largest of a and b over the history).
    pub drop_bound: f64,
    /// Stability bound on the channel's profile L2 error at the end time.
    pub channel_bound: f64,
    /// Option sets run (names in [`Config::option_sets`]).
    pub option_sets: Vec<String>,
}

/// A case the study's scenes start from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseCase {
    /// The case file `validation/<case>.json`.
    pub case: String,
    /// Its preset whose scene is the template.
    pub preset: String,
}

/// An option set: merge patches on the base scenes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OptionSet {
    /// Name (a row's `preset`, part of the slugs).
    pub name: String,
    /// The scheme its scenes run (`isph`, `wcsph` or `mps`; a row's `scheme`).
    pub scheme: String,
    /// What it is, for the page.
    pub description: String,
    /// RFC 7396 merge patch on every base scene.
    #[serde(default = "empty_object")]
    pub patch: Value,
    /// What it does per case (by case name), after `patch`.
    #[serde(default)]
    pub cases: BTreeMap<String, CaseOptions>,
}

/// What an option set does to one case's scenes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaseOptions {
    /// A preset of the case whose patch is applied next (the drop's `wcsph_tuned`).
    #[serde(default)]
    pub preset: Option<String>,
    /// A merge patch applied after that.
    #[serde(default = "empty_object")]
    pub patch: Value,
    /// Sets `scheme.wcsph.sound_speed` to this multiple of the Poiseuille centre-line speed
    /// `F D²/(8ν)` of the run's body force, after the study's own edits (a Reynolds-number
    /// or time-step edit keeps the Mach number); a channel case only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sound_speed_over_u_max: Option<f64>,
}

/// A check of the envelope, stated before the numbers were known (issue #6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Check {
    /// Every run ends at its end time or with the solver's typed error: the value counts
    /// the panics and the other statuses, and must be 0.
    Explained {
        /// Check name.
        name: String,
    },
    /// A case's check ([`CheckSpec`]) on the rows its `select` picks (by `study`, `case`,
    /// `preset`); a row's status does not fail it (a bisection row names the unstable run
    /// that decided it), and no row picked fails it with the spec's `missing` as note.
    Bound(Box<CheckSpec>),
    /// The jitter rows of option set `preset` at `fraction`: the value counts those with an
    /// unstable run, and must be 0; fewer or more than `rows` rows fail with `missing`.
    Jittered {
        /// Check name.
        name: String,
        /// Option set.
        preset: String,
        /// Jitter fraction of Δx.
        fraction: f64,
        /// Rows expected (one per case).
        rows: usize,
        /// The note when the rows are not all there.
        missing: String,
    },
}

fn empty_object() -> Value {
    Value::Object(serde_json::Map::new())
}

/// An error naming the field, the value and the rule.
fn bad(field: &str, value: impl Display, rule: &str) -> HarnessError {
    HarnessError::case(super::NAME, format!("`{field}` = {value}: {rule}"))
}

impl Config {
    /// Parses the study's file from JSON text and checks it; `origin` names the source.
    pub fn from_json(text: &str, origin: &Path) -> Result<Config> {
        let de = &mut serde_json::Deserializer::from_str(text);
        let config: Config = serde_path_to_error::deserialize(de).map_err(|e| {
            let path = e.path().to_string();
            HarnessError::case(super::NAME, format!("{}: `{path}`: {}", origin.display(), e.into_inner()))
        })?;
        config.check()?;
        Ok(config)
    }

    /// Reads `<validation_dir>/studies/stability.json`.
    pub fn load(validation_dir: &Path) -> Result<Config> {
        let path = validation_dir.join(FILE);
        Config::from_json(&io::read_text(&path)?, &path)
    }

    /// The option set named `name`.
    pub fn option_set(&self, name: &str) -> Result<&OptionSet> {
        self.option_sets.iter().find(|o| o.name == name).ok_or_else(|| {
            bad("settings.option_sets", format!("{name:?}"), "names no option set of the file")
        })
    }

    /// The rules beyond the schema.
    fn check(&self) -> Result<()> {
        let s = &self.settings;
        for (field, v) in [
            ("drop_dx", s.drop_dx),
            ("drop_end", s.drop_end),
            ("long_end", s.long_end),
            ("channel_dx", s.channel_dx),
            ("channel_tau", s.channel_tau),
            ("drop_bound", s.drop_bound),
            ("channel_bound", s.channel_bound),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(&format!("settings.{field}"), v, "must be positive"));
            }
        }
        for (field, [lo, hi]) in [("dt_range", s.dt_range), ("re_range", s.re_range)] {
            if !(lo.is_finite() && hi.is_finite() && 0.0 < lo && lo < hi) {
                return Err(bad(
                    &format!("settings.{field}"),
                    format!("[{lo}, {hi}]"),
                    "must be [lo, hi] with 0 < lo < hi",
                ));
            }
        }
        if let Some(f) = s.jitter.iter().find(|f| !(**f > 0.0 && **f < 1.0)) {
            return Err(bad("settings.jitter", f, "fractions of dx must be in (0, 1)"));
        }
        if s.option_sets.is_empty() {
            return Err(bad("settings.option_sets", "[]", "name at least one option set"));
        }
        let mut names = BTreeSet::new();
        for (i, o) in self.option_sets.iter().enumerate() {
            let field = |f: &str| format!("option_sets[{i}].{f}");
            if o.name.is_empty() || !o.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                return Err(bad(&field("name"), format!("{:?}", o.name), "must be non-empty [A-Za-z0-9_]"));
            }
            if !names.insert(o.name.as_str()) {
                return Err(bad(&field("name"), format!("{:?}", o.name), "is defined twice"));
            }
            if !["isph", "wcsph", "mps"].contains(&o.scheme.as_str()) {
                return Err(bad(
                    &field("scheme"),
                    format!("{:?}", o.scheme),
                    "must be \"isph\", \"wcsph\" or \"mps\"",
                ));
            }
            for (case, c) in &o.cases {
                if *case != self.drop.case && *case != self.channel.case {
                    return Err(bad(
                        &field("cases"),
                        format!("{case:?}"),
                        "is neither the drop's case nor the channel's",
                    ));
                }
                if let Some(m) = c.sound_speed_over_u_max.filter(|m| !(m.is_finite() && *m > 0.0)) {
                    return Err(bad(
                        &field(&format!("cases.{case}.sound_speed_over_u_max")),
                        m,
                        "must be positive",
                    ));
                }
            }
        }
        let mut run = BTreeSet::new();
        for name in &s.option_sets {
            self.option_set(name)?;
            if !run.insert(name) {
                return Err(bad("settings.option_sets", format!("{name:?}"), "is named twice"));
            }
        }
        for (i, c) in self.checks.iter().enumerate() {
            match c {
                Check::Bound(spec) => spec
                    .validate()
                    .map_err(|m| bad(&format!("checks[{i}].bound"), spec.display_name(), &m))?,
                Check::Explained { name } | Check::Jittered { name, .. } if name.is_empty() => {
                    return Err(bad(&format!("checks[{i}].name"), "\"\"", "must not be empty"));
                }
                _ => {}
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn committed() -> Value {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../validation");
        serde_json::from_str(&std::fs::read_to_string(dir.join(FILE)).unwrap()).unwrap()
    }

    fn error(v: &Value) -> String {
        Config::from_json(&v.to_string(), Path::new("s.json")).unwrap_err().to_string()
    }

    #[test]
    fn the_committed_file_is_the_published_budget() {
        let c = Config::from_json(&committed().to_string(), Path::new("s.json")).unwrap();
        assert_eq!(
            c.settings.option_sets,
            ["xu", "none", "xu_difference", "fickian", "wcsph", "wcsph_xu", "mps_paper", "mps"]
        );
        assert_eq!(c.settings.channel_dx.to_bits(), (0.2f64 / 18.0).to_bits(), "D/18 to the last bit");
        assert_eq!((c.settings.dt_range, c.settings.re_range), ([0.25, 5.0], [4.0, 4000.0]));
        assert_eq!(c.checks.len(), 15);
        assert!(
            matches!(c.checks[0], Check::Explained { .. }) && matches!(c.checks[14], Check::Jittered { .. })
        );
    }

    #[test]
    fn errors_name_the_field_the_value_and_the_rule() {
        let mut v = committed();
        v["settings"]["dt_range"] = serde_json::json!([5.0, 0.25]);
        let e = error(&v);
        assert!(
            e.contains("settings.dt_range") && e.contains("[5, 0.25]") && e.contains("0 < lo < hi"),
            "{e}"
        );
        let mut v = committed();
        v["settings"]["option_sets"][1] = "bogus".into();
        let e = error(&v);
        assert!(
            e.contains("settings.option_sets") && e.contains("bogus") && e.contains("names no option set"),
            "{e}"
        );
        let mut v = committed();
        v["option_sets"][4]["scheme"] = "otm".into();
        let e = error(&v);
        assert!(e.contains("option_sets[4].scheme") && e.contains("otm"), "{e}");
        let mut v = committed();
        v["checks"][1]["bound"]["min"] = Value::Null;
        let e = error(&v);
        assert!(e.contains("checks[1].bound") && e.contains("give `kind` or one of"), "{e}");
        // Schema errors name the path.
        let mut v = committed();
        v["settings"]["drop_dx"] = "0.04".into();
        let e = error(&v);
        assert!(e.contains("settings.drop_dx") && e.contains("invalid type"), "{e}");
        let mut v = committed();
        v["option_sets"][0]["shifting"] = 1.into();
        let e = error(&v);
        assert!(e.contains("option_sets[0]") && e.contains("unknown field `shifting`"), "{e}");
    }
}
