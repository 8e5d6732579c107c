//! Case files `validation/<case>.json`: everything about a validation case is data.
//!
//! ```json
//! { "case": "elliptical_drop", "title": "...", "description": "...", "scheme": "isph",
//!   "scene": { ...a full scene, DESIGN.md "Scene files"... },
//!   "sweep": { "dx": { "quick": [0.04, 0.02], "default": [0.04, 0.02], "full": [0.04, 0.02, 0.01, 0.005] },
//!              "presets": [ { "name": "paper", "patch": {} },
//!                           { "name": "tuned", "patch": { "scheme": { "isph": { "pressure_gradient": "difference" } } } } ] },
//!   "reference": { "elliptical_drop": { "radius": 1.0, "a0": 100.0, "density": 1000.0 } },
//!   "metrics": ["b_rel_err_max", ...], "key_metrics": ["b_rel_err_max"], "convergence": ["b_rel_err_max"],
//!   "checks": [ { "name": "...", "metric": "b_rel_err_max", "select": { "dx": 0.02, "preset": "paper" }, "max": 0.01 } ],
//!   "figures": [ { "history": { "file": "history_b", "series": ["b_moment"], "reference": "b_ref" } } ],
//!   "errata": ["CASES.md erratum 1 ..."],
//!   "published": [ { "source": "Lan et al. 2022, MPS", "metric": "u_max_station", "preset": "mps_re400",
//!                    "values": [[0.0025, 0.002822]], "note": "..." } ] }
//! ```
//! A preset is a JSON merge patch (RFC 7396, [`crate::patch`]) applied to the template;
//! the first preset is the case's primary one (its orders go into `convergence`).

use crate::checks::{CheckKind, CheckSpec, same_spacing};
use crate::error::{HarnessError, Result};
use crate::io;
use crate::provenance::Provenance;
use crate::tier::Tier;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A validation case, as read from `validation/<case>.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Case name (the file stem, the report directory).
    pub case: String,
    /// One-line title for the report.
    #[serde(default)]
    pub title: String,
    /// What the case tests.
    #[serde(default)]
    pub description: String,
    /// Default scheme of the case (results.json top-level `scheme`).
    pub scheme: String,
    /// The scene template: a complete scene (its `dx` is replaced per run).
    pub scene: serde_json::Value,
    /// Which runs make up the sweep.
    pub sweep: Sweep,
    /// The analytical reference the metrics compare against.
    pub reference: ReferenceSpec,
    /// Metrics shown in the error table, in order (computed per reference kind).
    #[serde(default)]
    pub metrics: Vec<String>,
    /// The few metrics shown on the index page.
    #[serde(default)]
    pub key_metrics: Vec<String>,
    /// Metrics whose observed order in dx is fitted (least squares in log-log).
    #[serde(default)]
    pub convergence: Vec<String>,
    /// Acceptance checks.
    #[serde(default)]
    pub checks: Vec<CheckSpec>,
    /// Figures of the case page.
    #[serde(default)]
    pub figures: Vec<Figure>,
    /// Errata of the source papers applied in this case (shown in the report).
    #[serde(default)]
    pub errata: Vec<String>,
    /// Values the source papers publish for the case's metrics, shown on the case page
    /// beside the measured ones.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub published: Vec<Published>,
}

/// A source paper's published values of one metric, one per spacing, compared on the case
/// page with the runs of one preset (`published[]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Published {
    /// Where the values come from (paper, table or figure, method).
    pub source: String,
    /// The run metric they are values of.
    pub metric: String,
    /// The preset whose runs they are compared with.
    pub preset: String,
    /// `[dx, value]` pairs, dx \[m\] as the preset runs it (the paper's own spacing goes in
    /// `note` when it differs).
    pub values: Vec<[f64; 2]>,
    /// How the paper's quantity relates to the metric.
    #[serde(default)]
    pub note: String,
}

/// Spacings per tier and the presets run at each spacing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Sweep {
    /// Particle spacings per tier \[m\].
    pub dx: BTreeMap<Tier, Vec<f64>>,
    /// Option sets; every preset runs at every spacing of the tier (unless it names tiers).
    pub presets: Vec<Preset>,
    /// For spacings finer than the template's, scale a fixed Δt by `dx / dx_template`, so the
    /// CFL number `u_max Δt / h` never exceeds the template's (coarser spacings keep the
    /// template's Δt).
    #[serde(default)]
    pub scale_dt_with_dx: bool,
}

/// A named option set: a JSON merge patch on the scene template.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Preset {
    /// Preset name (`paper`, `tuned`, ...): part of the run slug.
    pub name: String,
    /// What the preset changes and why.
    #[serde(default)]
    pub description: String,
    /// RFC 7396 merge patch applied to the template.
    #[serde(default = "empty_object")]
    pub patch: serde_json::Value,
    /// Tiers in which this preset runs (all when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tiers: Option<Vec<Tier>>,
    /// This preset's spacings per tier \[m\], in place of `sweep.dx` for the tiers it
    /// lists (a preset that converges where the others diverge runs finer).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dx: Option<BTreeMap<Tier, Vec<f64>>>,
    /// Spacings at which this preset is known to diverge, with the measured reason: such a
    /// run's divergence is an expected failure, its completion an unexpected pass. Any
    /// other run must reach its end time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected_divergence: Option<ExpectedDivergence>,
    /// Extra runs of the preset from perturbed starts, at some spacings: a quantity that a
    /// bit-level change of the trajectory redraws is judged over them (worst member for a
    /// bound, member mean for a convergence fit; [`crate::checks`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub perturbed_starts: Option<PerturbedStarts>,
}

/// The perturbed starts of a preset (`sweep.presets[].perturbed_starts`): at each spacing
/// of `dx`, one more run per seed with every fluid body's lattice jittered by
/// `fraction · dx` (`bodies[].jitter`, uniform in the ball, ChaCha8 from the seed). The
/// unperturbed run is the ensemble's first member.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PerturbedStarts {
    /// Spacings \[m\] (of `sweep.dx`).
    pub dx: Vec<f64>,
    /// Jitter seeds, one run each (distinct).
    pub seeds: Vec<u64>,
    /// Jitter radius over Δx: small enough not to change the discretisation (default
    /// 1e-12, at most 1e-6).
    #[serde(default = "default_start_fraction")]
    pub fraction: f64,
    /// Why the quantity needs an ensemble (what a bit-level change redraws, measured).
    pub reason: String,
}

fn default_start_fraction() -> f64 {
    1e-12
}

/// Whether `dx` is one of `spacings` ([`same_spacing`]).
fn listed(spacings: &[f64], dx: f64) -> bool {
    spacings.iter().any(|&d| same_spacing(d, dx))
}

/// Where and why a preset diverges (`sweep.presets[].expected_divergence`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ExpectedDivergence {
    /// Spacings \[m\] (of `sweep.dx`).
    pub dx: Vec<f64>,
    /// The measured cause (where it diverges, why, and where it is documented).
    pub reason: String,
}

impl Preset {
    /// The reason the preset is expected to diverge at `dx`, if it is.
    pub fn expected_divergence_at(&self, dx: f64) -> Option<&str> {
        self.expected_divergence.as_ref().filter(|e| listed(&e.dx, dx)).map(|e| e.reason.as_str())
    }

    /// The seeds of the perturbed starts run at `dx` (empty when none are).
    pub fn starts_at(&self, dx: f64) -> &[u64] {
        self.perturbed_starts.as_ref().filter(|s| listed(&s.dx, dx)).map_or(&[], |s| s.seeds.as_slice())
    }
}

fn empty_object() -> serde_json::Value {
    serde_json::Value::Object(serde_json::Map::new())
}

/// The analytical reference of a case; metric computation is per kind ([`crate::metrics`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ReferenceSpec {
    /// The inviscid elliptical drop ODE (`meniscus_reference::elliptical_drop`).
    EllipticalDrop {
        /// Initial radius R \[m\].
        radius: f64,
        /// Initial strain rate A0 \[1/s\].
        a0: f64,
        /// Density \[kg/m^3\].
        density: f64,
    },
    /// The rotating square patch (`meniscus_reference::rotating_square`): the initial
    /// pressure of the inviscid patch, against which the first PPE solve is compared.
    RotatingSquare {
        /// Side L \[m\].
        side: f64,
        /// Angular velocity ω \[1/s\] (`u = ω y, v = −ω x`).
        omega: f64,
        /// Density \[kg/m^3\].
        density: f64,
    },
    /// Laminar entrance flow from a uniform inlet (`meniscus_reference::entrance_flow`);
    /// inflow speed, inlet position, viscosity and the station (the slab of the cross
    /// profile probe) come from each run's scene.
    EntranceFlow {
        /// Channel width D \[m\].
        width: f64,
        /// Position of the lower wall \[m\].
        wall: f64,
    },
    /// A drop at rest, a circle (2D) or a sphere (3D) after the scene's `dimension`: Laplace
    /// pressure `σ/R` (2D) or `2σ/R` (3D) and spurious currents
    /// (`meniscus_reference::capillarity`).
    StaticDrop {
        /// Radius R \[m\].
        radius: f64,
        /// Surface tension σ \[N/m\].
        sigma: f64,
    },
    /// Mode-2 oscillation of a drop, 2D or 3D after the scene's `dimension`: period
    /// `2π √(ρR³/(6σ))` and damping `4ν/R²` in 2D, `2π √(ρR³/(8σ))` and `5ν/R²` in 3D (ν
    /// from each run's scene).
    OscillatingDrop {
        /// Radius R \[m\].
        radius: f64,
        /// Surface tension σ \[N/m\].
        sigma: f64,
        /// Density \[kg/m^3\].
        density: f64,
    },
    /// A drop of diameter D hitting a plane at speed V at t = 0
    /// (`meniscus_reference::impact`): the `spread` probe's wetted diameter against `√(6T)`
    /// early and the published `β_max` correlations; the liquid's ρ, μ, σ come from each
    /// run's scene.
    DropletImpact {
        /// Drop diameter D \[m\].
        diameter: f64,
        /// Impact speed V \[m/s\].
        speed: f64,
    },
    /// A drop at rest on a plate under gravity (Zhou 2021 §3.4): the pressure gradient of
    /// its interior (the `pressure_gradient` probe) against the hydrostatic `ρ g`, ρ and g
    /// (`body_force`) from each run's scene.
    Hydrostatic {},
    /// A 2D square of side L relaxing to a circle of radius `L/√π`: Laplace pressure,
    /// connectivity, circularity and the mode-4 period.
    SquareDrop {
        /// Side L \[m\].
        side: f64,
        /// Surface tension σ \[N/m\].
        sigma: f64,
        /// Density \[kg/m^3\].
        density: f64,
    },
    /// Plane Poiseuille start-up from rest (`meniscus_reference::poiseuille`); viscosity and
    /// body force come from each run's scene.
    PoiseuilleStartup {
        /// Channel width D \[m\].
        width: f64,
        /// Position of the lower wall \[m\].
        wall: f64,
    },
    /// Hagen–Poiseuille start-up from rest (`meniscus_reference::pipe`) in a pipe of radius R
    /// along `axis`, driven by the body force component along `axis`; viscosity and that
    /// component come from each run's scene, the profile from its `radial_profile` probe.
    HagenPoiseuille {
        /// Pipe radius R \[m\].
        radius: f64,
        /// Index of the pipe's axis (0 = x, 1 = y, 2 = z; less than the scene's dimension).
        axis: usize,
    },
}

/// A figure of the case page (drawn from results.json only).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Figure {
    /// Time histories (or profiles, with `x`) of run series against a reference series: one
    /// figure per preset, one colour per resolution, one dash style per series.
    History {
        /// File stem (`<file>_<preset>.svg`).
        file: String,
        /// Title.
        #[serde(default)]
        title: String,
        /// y-axis label.
        #[serde(default)]
        y_label: String,
        /// Run series to draw (names in `runs[].series`).
        series: Vec<String>,
        /// Reference series (drawn once, from the finest run, in black).
        #[serde(default)]
        reference: Option<String>,
        /// Abscissa: a run series (e.g. `x_over_d` for a profile along a channel); absent:
        /// time `t`.
        #[serde(default)]
        x: Option<String>,
        /// x-axis label (absent: `t [s]`, or the abscissa series' name).
        #[serde(default)]
        x_label: Option<String>,
    },
    /// Error against dx in log-log, one line per metric and preset, with the fitted order
    /// and a reference slope.
    Convergence {
        /// File stem.
        file: String,
        /// Title.
        #[serde(default)]
        title: String,
        /// Metrics to draw.
        metrics: Vec<String>,
        /// Slope of the reference line (e.g. 2 for second order).
        #[serde(default)]
        slope: Option<f64>,
    },
    /// Run time against a metric, one point per run.
    Cost {
        /// File stem.
        file: String,
        /// Title.
        #[serde(default)]
        title: String,
        /// The error metric on the x axis.
        metric: String,
    },
    /// Relative error against time, `|series / reference − 1|` on a log axis: one figure
    /// per preset, one colour per resolution, one dash style per pair.
    ErrorHistory {
        /// File stem (`<file>_<preset>.svg`).
        file: String,
        /// Title.
        #[serde(default)]
        title: String,
        /// (run series, reference series) pairs, e.g. `["b_moment", "b_ref"]`.
        pairs: Vec<[String; 2]>,
    },
    /// Particle positions coloured by pressure at each snapshot time of the runs
    /// (`output.snapshot_times`), one panel per preset side by side with a shared colour
    /// bar: `<file>_<i>.svg` for the i-th time. Drawn from `snapshots/<slug>.json`; a preset
    /// without snapshots (not run in this tier) is left out. A 3D run is drawn as a cut:
    /// the particles within Δx/2 (the run's spacing) of the plane normal to `cut_axis`
    /// through the fluid's centroid, seen in that plane
    /// ([`crate::snapshots::Snapshot::view`]).
    Snapshots {
        /// File stem.
        file: String,
        /// Title.
        #[serde(default)]
        title: String,
        /// Presets side by side.
        presets: Vec<String>,
        /// Spacing of the runs shown (the finest with snapshots when absent).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        dx: Option<f64>,
        /// 3D runs: the axis normal to the cut plane, 0 (x), 1 (y) or 2 (z); absent: 1, the
        /// x–z plane (a drop falling or oscillating along z). The panels show the plane's
        /// two other axes in increasing order. Only for a case with 3D runs.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        cut_axis: Option<usize>,
    },
}

impl Figure {
    /// The cut axis of a snapshot figure when absent (y: the x–z plane).
    pub const DEFAULT_CUT_AXIS: usize = 1;

    /// Rules beyond the schema that need nothing but the figure; the message begins with
    /// the field.
    pub fn check(&self) -> std::result::Result<(), String> {
        match self {
            Figure::Snapshots { cut_axis: Some(a), .. } if *a > 2 => Err(format!(
                "`snapshots.cut_axis` = {a}: must be 0, 1 or 2 (the axis normal to the cut plane: x, y or z)"
            )),
            _ => Ok(()),
        }
    }

    /// The file stem.
    pub fn file(&self) -> &str {
        match self {
            Figure::History { file, .. }
            | Figure::Convergence { file, .. }
            | Figure::Cost { file, .. }
            | Figure::ErrorHistory { file, .. }
            | Figure::Snapshots { file, .. } => file,
        }
    }
}

impl Case {
    /// Parses a case from JSON text and checks its consistency; `origin` names the source
    /// in errors.
    pub fn from_json(text: &str, origin: &Path) -> Result<Case> {
        let case: Case = serde_json::from_str(text)
            .map_err(|source| HarnessError::Json { path: origin.to_path_buf(), source })?;
        case.check()?;
        Ok(case)
    }

    /// Reads `path`.
    pub fn load(path: &Path) -> Result<Case> {
        Case::from_json(&io::read_text(path)?, path)
    }

    /// Spacings of `tier` (empty when the case has none for it).
    pub fn spacings(&self, tier: Tier) -> &[f64] {
        self.sweep.dx.get(&tier).map(Vec::as_slice).unwrap_or(&[])
    }

    /// Spacings of `preset` in `tier`: its own `dx` for the tier, else the sweep's.
    pub fn preset_spacings<'a>(&'a self, preset: &'a Preset, tier: Tier) -> &'a [f64] {
        match preset.dx.as_ref().and_then(|d| d.get(&tier)) {
            Some(dx) => dx,
            None => self.spacings(tier),
        }
    }

    /// Every spacing of any tier, of the sweep and of the presets' own lists.
    fn all_spacings(&self) -> impl Iterator<Item = f64> + '_ {
        let own = self.sweep.presets.iter().filter_map(|p| p.dx.as_ref());
        self.sweep.dx.values().chain(own.flat_map(|d| d.values())).flatten().copied()
    }

    /// Spacings run in `tier` by the preset `preset` (by any preset when `None`), coarse to
    /// fine, each once.
    pub fn selected_spacings(&self, preset: Option<&str>, tier: Tier) -> Vec<f64> {
        let mut dx: Vec<f64> = self
            .presets(tier)
            .filter(|p| preset.is_none_or(|n| n == p.name))
            .flat_map(|p| self.preset_spacings(p, tier).iter().copied())
            .collect();
        dx.sort_by(|a, b| b.total_cmp(a));
        dx.dedup_by(|a, b| same_spacing(*a, *b));
        dx
    }

    /// Presets that run in `tier`.
    pub fn presets(&self, tier: Tier) -> impl Iterator<Item = &Preset> {
        self.sweep.presets.iter().filter(move |p| p.tiers.as_ref().is_none_or(|t| t.contains(&tier)))
    }

    /// The primary preset (the first).
    pub fn primary_preset(&self) -> &str {
        self.sweep.presets.first().map(|p| p.name.as_str()).unwrap_or("")
    }

    /// Consistency checks beyond the schema.
    fn check(&self) -> Result<()> {
        let err = |m: String| HarnessError::case(&self.case, m);
        if !self.scene.is_object() {
            return Err(err("`scene` must be a JSON object (a full scene)".into()));
        }
        if self.sweep.presets.is_empty() {
            return Err(err(
                "`sweep.presets` is empty: give at least one (e.g. {\"name\": \"paper\", \"patch\": {}})"
                    .into(),
            ));
        }
        let mut names = std::collections::BTreeSet::new();
        for p in &self.sweep.presets {
            if p.name.is_empty() || !p.name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            {
                return Err(err(format!("preset name `{}` must be non-empty [A-Za-z0-9_-]", p.name)));
            }
            if !names.insert(&p.name) {
                return Err(err(format!("preset `{}` is defined twice", p.name)));
            }
        }
        for p in &self.sweep.presets {
            if let Some(e) = &p.expected_divergence {
                if e.reason.trim().is_empty() {
                    return Err(err(format!(
                        "preset `{}`: `expected_divergence.reason` is empty: give the measured cause",
                        p.name
                    )));
                }
                if let Some(d) = e.dx.iter().find(|&&d| !self.all_spacings().any(|s| same_spacing(s, d))) {
                    return Err(err(format!(
                        "preset `{}`: `expected_divergence.dx` has {d}, not a spacing of `sweep.dx`",
                        p.name
                    )));
                }
            }
        }
        for p in &self.sweep.presets {
            if let Some(s) = &p.perturbed_starts {
                self.check_starts(p, s)
                    .map_err(|m| err(format!("preset `{}`: `perturbed_starts.{m}", p.name)))?;
            }
        }
        for (tier, dx) in &self.sweep.dx {
            if let Some(bad) = dx.iter().find(|d| !(d.is_finite() && **d > 0.0)) {
                return Err(err(format!("sweep.dx.{tier} has {bad}: spacings must be positive")));
            }
        }
        for p in &self.sweep.presets {
            for (tier, dx) in p.dx.iter().flatten() {
                if let Some(bad) = dx.iter().find(|d| !(d.is_finite() && **d > 0.0)) {
                    return Err(err(format!(
                        "preset `{}`: `dx.{tier}` has {bad}: spacings must be positive",
                        p.name
                    )));
                }
                if dx.is_empty() {
                    return Err(err(format!(
                        "preset `{}`: `dx.{tier}` is empty: give its spacings or leave the tier out",
                        p.name
                    )));
                }
            }
        }
        for (i, p) in self.published.iter().enumerate() {
            let field = format!("published[{i}]");
            if !names.contains(&p.preset) {
                return Err(err(format!("`{field}.preset` = {:?} is not a preset of the case", p.preset)));
            }
            if !self.metrics.contains(&p.metric) {
                return Err(err(format!(
                    "`{field}.metric` = {:?} is not one of the case's `metrics`",
                    p.metric
                )));
            }
            if let Some([d, _]) =
                p.values.iter().find(|[d, _]| !self.all_spacings().any(|s| same_spacing(s, *d)))
            {
                return Err(err(format!("`{field}.values` has dx = {d}, not a spacing of `sweep.dx`")));
            }
        }
        for f in &self.figures {
            let named = |m: String| err(format!("figure `{}`: {m}", f.file()));
            f.check().map_err(named)?;
            if let Figure::Snapshots { cut_axis: Some(a), .. } = f
                && !self.has_3d_runs()
            {
                return Err(named(format!(
                    "`snapshots.cut_axis` = {a}: only for 3D runs, and every preset's scene is 2D \
                     (drawn whole in the x–y plane)"
                )));
            }
        }
        for c in &self.checks {
            c.validate().map_err(|m| err(format!("check `{}`: {m}", c.display_name())))?;
            self.check_selector(c).map_err(|m| err(format!("check `{}`: {m}", c.display_name())))?;
            for (field, v) in [("study", &c.select.study), ("case", &c.select.case)] {
                if let Some(v) = v {
                    return Err(err(format!(
                        "check `{}`: `select.{field}` = {v:?}: selects a study's rows; a case's runs have no {field}",
                        c.display_name()
                    )));
                }
            }
        }
        Ok(())
    }
}

impl Case {
    /// A preset's perturbed starts are well formed and run somewhere; the message begins
    /// with the field.
    fn check_starts(&self, p: &Preset, s: &PerturbedStarts) -> std::result::Result<(), String> {
        // The spacings of the tiers the preset runs in.
        let all: Vec<f64> = Tier::ALL
            .into_iter()
            .filter(|tier| p.tiers.as_ref().is_none_or(|t| t.contains(tier)))
            .flat_map(|tier| self.preset_spacings(p, tier).iter().copied())
            .collect();
        if s.reason.trim().is_empty() {
            return Err("reason` is empty: say what a bit-level change of the start redraws".into());
        }
        if s.dx.is_empty() {
            return Err("dx` is empty: give the spacings of the ensemble".into());
        }
        if let Some(d) = s.dx.iter().find(|&&d| !listed(&all, d)) {
            return Err(format!("dx` has {d}, not a spacing of a tier the preset runs in (`sweep.dx`)"));
        }
        let mut seeds = s.seeds.clone();
        seeds.sort_unstable();
        seeds.dedup();
        if s.seeds.is_empty() || seeds.len() != s.seeds.len() {
            return Err(format!("seeds` = {:?}: give one or more distinct seeds", s.seeds));
        }
        if !(s.fraction > 0.0 && s.fraction <= 1e-6) {
            return Err(format!(
                "fraction` = {}: must be in (0, 1e-6] (a perturbation, not a disordered lattice)",
                s.fraction
            ));
        }
        Ok(())
    }

    /// A check's selector names what the sweep runs: a preset of the case, one of its
    /// spacings, a scheme of its presets; and each tier the check lists runs what it
    /// selects. (A misspelt selector would match nothing and the check would vanish.)
    fn check_selector(&self, c: &CheckSpec) -> std::result::Result<(), String> {
        let sel = &c.select;
        let names: Vec<&str> = self.sweep.presets.iter().map(|p| p.name.as_str()).collect();
        if let Some(p) = &sel.preset
            && !names.contains(&p.as_str())
        {
            return Err(format!(
                "`select.preset` = {p:?} is not a preset of the case ({})",
                names.join(", ")
            ));
        }
        if let Some(d) = sel.dx
            && !self.all_spacings().any(|s| same_spacing(s, d))
        {
            return Err(format!("`select.dx` = {d} is not a spacing of `sweep.dx`"));
        }
        let schemes: Vec<String> = self.sweep.presets.iter().map(|p| self.preset_scheme(p)).collect();
        if let Some(s) = &sel.scheme
            && !schemes.contains(s)
        {
            return Err(format!(
                "`select.scheme` = {s:?} is not a scheme of the presets ({})",
                schemes.join(", ")
            ));
        }
        // A check across spacings never applies to one spacing: a `select.dx`, or a listed
        // tier with a single spacing, would silently keep it from judging anything.
        let across =
            matches!(c.kind(), Some(CheckKind::Decreasing | CheckKind::Order | CheckKind::FinestChange));
        if across && let Some(d) = sel.dx {
            return Err(format!(
                "`select.dx` = {d} on a check across spacings, which one spacing cannot judge"
            ));
        }
        for &tier in c.tiers.iter().flatten() {
            let spacings = self.selected_spacings(sel.preset.as_deref(), tier);
            if across && spacings.len() < 2 {
                return Err(format!(
                    "lists tier `{tier}`, which has one spacing: a check across spacings never applies there"
                ));
            }
            if let Some(p) = &sel.preset
                && !self.presets(tier).any(|q| q.name == *p)
            {
                return Err(format!("lists tier `{tier}`, in which preset {p:?} does not run"));
            }
            if let Some(d) = sel.dx
                && !spacings.iter().any(|&s| same_spacing(s, d))
            {
                return Err(format!("lists tier `{tier}`, whose spacings do not include {d}"));
            }
        }
        Ok(())
    }

    /// Whether a preset runs a 3D scene (`dimension` of the template or its patch).
    fn has_3d_runs(&self) -> bool {
        self.sweep.presets.iter().any(|p| {
            p.patch.get("dimension").or_else(|| self.scene.get("dimension")).and_then(|d| d.as_u64())
                == Some(3)
        })
    }

    /// The scheme a preset runs: the key of the scene's `scheme` once the preset's patch
    /// is merged (as `sweep::spec` names it), else the case's.
    fn preset_scheme(&self, p: &Preset) -> String {
        let mut scheme = self.scene.get("scheme").cloned().unwrap_or_default();
        if let Some(patch) = p.patch.get("scheme") {
            crate::patch::merge_patch(&mut scheme, patch);
        }
        scheme.as_object().and_then(|m| m.keys().next().cloned()).unwrap_or_else(|| self.scheme.clone())
    }
}

/// Side file `reports/<case>/provenance.json`: the case file as run and where/when/what
/// produced the results (kept out of results.json to keep that contract exact).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CaseRecord {
    /// The case file as it was when the results were produced.
    pub case: Case,
    /// Machine, commit, date.
    pub provenance: Provenance,
    /// SHA-256 of each run's effective scene, by slug.
    pub scene_hashes: BTreeMap<String, String>,
}

/// Finds case files: `validation/*.json` (sorted by name), or only the `names` given.
pub fn discover(validation_dir: &Path, names: &[String]) -> Result<Vec<PathBuf>> {
    if !names.is_empty() {
        return names
            .iter()
            .map(|n| {
                let p = validation_dir.join(format!("{n}.json"));
                if p.is_file() { Ok(p) } else { Err(HarnessError::UnknownCase(n.clone())) }
            })
            .collect();
    }
    let rd = std::fs::read_dir(validation_dir)
        .map_err(|source| HarnessError::Io { path: validation_dir.to_path_buf(), source })?;
    let mut paths: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "json"))
        .collect();
    paths.sort();
    Ok(paths)
}

/// The names of the case files in `validation_dir` (their file stems), sorted.
pub fn known_cases(validation_dir: &Path) -> Result<Vec<String>> {
    Ok(discover(validation_dir, &[])?
        .iter()
        .filter_map(|p| p.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .collect())
}

#[cfg(test)]
pub(crate) mod testing {
    //! The committed case files, for tests.

    use super::Case;
    use std::path::Path;

    /// `validation/<name>.json` of this repository.
    pub(crate) fn committed(name: &str) -> Case {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../../validation/{name}.json"));
        Case::load(&path).expect("the committed case file parses")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn repo_case() -> Case {
        testing::committed("elliptical_drop")
    }

    #[test]
    fn committed_elliptical_drop_case_is_consistent() {
        let case = repo_case();
        assert_eq!(case.case, "elliptical_drop");
        assert_eq!(case.spacings(Tier::Quick), [0.04, 0.02]);
        assert_eq!(case.spacings(Tier::Full).len(), 4);
        assert_eq!(case.primary_preset(), "paper");
        assert_eq!(case.presets(Tier::Quick).count(), 7);
        assert!(case.checks.len() >= 8);
        assert!(!case.errata.is_empty());
    }

    #[test]
    fn rejects_duplicate_presets_and_unknown_fields() {
        let mut v = serde_json::to_value(repo_case()).unwrap();
        v["sweep"]["presets"][1]["name"] = "paper".into();
        let e = Case::from_json(&v.to_string(), Path::new("x.json")).unwrap_err();
        assert!(e.to_string().contains("twice"), "{e}");
        let mut v = serde_json::to_value(repo_case()).unwrap();
        v["bogus"] = 1.into();
        assert!(Case::from_json(&v.to_string(), Path::new("x.json")).is_err());
        let mut v = serde_json::to_value(repo_case()).unwrap();
        v["checks"][0]["select"]["study"] = "dt_max".into();
        let e = Case::from_json(&v.to_string(), Path::new("x.json")).unwrap_err();
        assert!(e.to_string().contains("`select.study` = \"dt_max\""), "{e}");
    }

    /// A selector that could match nothing is rejected when the case loads, naming the
    /// check: a misspelt preset, a spacing or scheme the sweep does not have, a tier in
    /// which the selected preset or spacing does not run.
    #[test]
    fn selectors_name_what_the_sweep_runs() {
        let error = |edit: &dyn Fn(&mut serde_json::Value)| {
            let mut v = serde_json::to_value(repo_case()).unwrap();
            v["checks"][0] = serde_json::json!({"name": "the check", "metric": "b_rel_err_max", "max": 0.01});
            edit(&mut v["checks"][0]);
            Case::from_json(&v.to_string(), Path::new("x.json")).err().map(|e| e.to_string())
        };
        assert_eq!(error(&|_| {}), None);
        assert_eq!(error(&|c| c["select"] = serde_json::json!({"preset": "tuned", "dx": 0.02})), None);
        for (edit, says) in [
            (serde_json::json!({"select": {"preset": "paperr"}}), "`select.preset` = \"paperr\""),
            (serde_json::json!({"select": {"dx": 0.03}}), "`select.dx` = 0.03"),
            (serde_json::json!({"select": {"scheme": "otm"}}), "`select.scheme` = \"otm\""),
            (serde_json::json!({"select": {"dx": 0.005}, "tiers": ["quick"]}), "tier `quick`"),
            (
                serde_json::json!({"kind": "decreasing", "max": null, "select": {"dx": 0.02}}),
                "check across spacings",
            ),
        ] {
            let e = error(&|c| crate::patch::merge_patch(c, &edit)).unwrap_or_default();
            assert!(e.contains("the check") && e.contains(says), "{edit}: {e}");
        }
        // A tier with one spacing cannot judge a check across spacings (for the selected
        // preset: tuned_h18 has spacings of its own).
        let mut v = serde_json::to_value(repo_case()).unwrap();
        v["sweep"]["dx"]["quick"] = serde_json::json!([0.04]);
        v["checks"][0] = serde_json::json!({"name": "the check", "kind": "finest_change", "metric": "b_rel_err_max",
                                            "select": {"preset": "paper"}, "max": 0.05, "tiers": ["quick", "full"]});
        let e = Case::from_json(&v.to_string(), Path::new("x.json"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default();
        assert!(e.contains("tier `quick`") && e.contains("one spacing"), "{e}");
    }

    /// Published values name a preset, a metric and spacings of the case: the channel's
    /// (Lan's u_max) load, and each wrong field is named when the case loads.
    #[test]
    fn published_values_name_what_the_case_has() {
        let channel = testing::committed("poiseuille_channel");
        assert_eq!(channel.published.len(), 1);
        assert_eq!(channel.published[0].values.len(), 3);
        let error = |edit: serde_json::Value| {
            let mut v = serde_json::to_value(&channel).unwrap();
            crate::patch::merge_patch(&mut v["published"][0], &edit);
            Case::from_json(&v.to_string(), Path::new("x.json"))
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        for (edit, says) in [
            (serde_json::json!({"preset": "mps_re500"}), "`published[0].preset` = \"mps_re500\""),
            (serde_json::json!({"metric": "u_peak"}), "`published[0].metric` = \"u_peak\""),
            (serde_json::json!({"values": [[0.003, 0.0029]]}), "dx = 0.003"),
        ] {
            let e = error(edit.clone());
            assert!(e.contains(says), "{edit}: {e}");
        }
    }

    /// `snapshots.cut_axis` is 0, 1 or 2, in a case with 3D runs; absent, it is not
    /// written back.
    #[test]
    fn snapshot_cut_axis_is_an_axis_of_a_3d_case() {
        let error = |case: &Case, figure: serde_json::Value| {
            let mut v = serde_json::to_value(case).unwrap();
            v["figures"] = serde_json::json!([{ "snapshots": figure }]);
            Case::from_json(&v.to_string(), Path::new("x.json")).err().map(|e| e.to_string())
        };
        let pipe = testing::committed("hagen_poiseuille");
        let preset = pipe.primary_preset().to_string();
        for a in 0..3 {
            assert_eq!(
                error(&pipe, serde_json::json!({"file": "s", "presets": [preset], "cut_axis": a})),
                None
            );
        }
        let e = error(&pipe, serde_json::json!({"file": "s", "presets": [preset], "cut_axis": 3})).unwrap();
        assert!(e.contains("figure `s`: `snapshots.cut_axis` = 3: must be 0, 1 or 2"), "{e}");
        let drop = repo_case();
        assert_eq!(error(&drop, serde_json::json!({"file": "s", "presets": ["paper"]})), None);
        let e = error(&drop, serde_json::json!({"file": "s", "presets": ["paper"], "cut_axis": 1})).unwrap();
        assert!(e.contains("`snapshots.cut_axis` = 1: only for 3D runs"), "{e}");
        let fig: Figure =
            serde_json::from_value(serde_json::json!({"snapshots": {"file": "s", "presets": []}})).unwrap();
        assert!(matches!(fig, Figure::Snapshots { cut_axis: None, .. }));
        assert!(!serde_json::to_string(&fig).unwrap().contains("cut_axis"));
    }
}
