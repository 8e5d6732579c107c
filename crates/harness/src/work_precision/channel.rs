//! The second study of `cargo xtask bench`: the periodic Poiseuille channel
//! (`validation/poiseuille_periodic.json`, preset `re4`: Re = U D/ν = 4, mirror walls, one
//! periodic axis) from rest to τ = ν t/D² = 1, wall time against the steady profile error
//! `u_profile_l2_rel_steady` = `sqrt(Σ (u − u_ref)² / Σ u_ref²)` over the bins at τ = 1
//! against the start-up series of Morris, Fox & Zhu 1997 (`metrics::poiseuille`).
//!
//! Factors, one at a time around each viscous integration (explicit, Qiu eq. 13, bound by
//! the viscous limit Δt ≤ α_d ρ h²/μ; implicit backward Euler, bound by the CFL limit and
//! the case's 100 s cap): Xu shifting coefficient (C = 0.02, the case's, or 0.01) and PPE
//! solver (BiCGSTAB 1e-3 with the two-level preconditioner, the case's, whose coarse null
//! space is grounded: the periodic mirror channel has no Dirichlet row; BiCGSTAB or CG 1e-3
//! with Jacobi; CG 1e-3 with the two-level preconditioner).
//!
//! Beside them, at every spacing, an MPS point on the same flow and metric: the `re4` scene
//! with its `scheme` replaced by the `scheme` of the case's `mps` preset ([`MPS`]). That
//! preset is at Re = 40; only its scheme options are taken (not its step, whose viscous
//! factor was measured at Re = 40), so the point is at Re = 4 like the others.

use super::design::SchemePreset;
use super::record::{Cost, isph};
use crate::case::Case;
use crate::error::{HarnessError, Result};
use crate::runner::Ran;
use crate::tier::Tier;
use meniscus::Scene;
use meniscus::scene::schema::{PpeSolver, Preconditioner, Scheme, Shifting, ViscousIntegration};
use serde::{Deserialize, Serialize};

/// The case file of the study (`validation/<CASE>.json`).
pub const CASE: &str = "poiseuille_periodic";

/// The case preset the variants start from.
pub const PRESET: &str = "re4";

/// The error metric of the study.
pub const METRIC: &str = "u_profile_l2_rel_steady";

/// The channel spacings \[m\]: D/36 (the paper's 0.0055), 0.004, 0.0025.
pub const D36: f64 = 0.2 / 36.0;

/// Viscous integration of the predictor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Viscosity {
    /// Forward Euler (Qiu 2013 eq. 13), with the viscous time-step limit.
    Explicit,
    /// Backward Euler (`scheme.isph.viscosity: implicit`), no viscous limit.
    Implicit,
}

/// Xu shifting coefficient C (Qiu 2013 eqs. 20–21).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelShift {
    /// C = 0.02 (the case's).
    Xu002,
    /// C = 0.01.
    Xu001,
}

/// PPE solver and preconditioner at tolerance 1e-3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChannelPpe {
    /// BiCGSTAB with the two-level preconditioner (the case's).
    BicgstabTwoLevel,
    /// BiCGSTAB with Jacobi.
    Bicgstab,
    /// Conjugate gradient.
    Cg,
    /// Conjugate gradient with the two-level preconditioner.
    CgTwoLevel,
}

/// Every PPE level, in display order.
const CHANNEL_PPES: [ChannelPpe; 4] =
    [ChannelPpe::BicgstabTwoLevel, ChannelPpe::Bicgstab, ChannelPpe::Cg, ChannelPpe::CgTwoLevel];

/// One option set of the channel study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ChannelVariant {
    /// Viscous integration.
    pub viscosity: Viscosity,
    /// Shifting coefficient.
    pub shifting: ChannelShift,
    /// PPE solver.
    pub ppe: ChannelPpe,
}

impl ChannelVariant {
    /// The case's `re4` preset: explicit viscosity, Xu C = 0.02, BiCGSTAB 1e-3 with the
    /// two-level preconditioner.
    pub const EXPLICIT: ChannelVariant = ChannelVariant {
        viscosity: Viscosity::Explicit,
        shifting: ChannelShift::Xu002,
        ppe: ChannelPpe::BicgstabTwoLevel,
    };

    /// The case's `re4_implicit` preset: `re4` with the backward-Euler predictor.
    pub const IMPLICIT: ChannelVariant =
        ChannelVariant { viscosity: Viscosity::Implicit, ..ChannelVariant::EXPLICIT };

    /// The case preset this option set is, if any (`re4`, `re4_implicit`).
    pub fn preset(&self) -> Option<&'static str> {
        match *self {
            ChannelVariant::EXPLICIT => Some("re4"),
            ChannelVariant::IMPLICIT => Some("re4_implicit"),
            _ => None,
        }
    }

    /// A short label, e.g. `explicit xu0.02 bicgstab_two_level_1e-3`.
    pub fn label(&self) -> String {
        let v = match self.viscosity {
            Viscosity::Explicit => "explicit",
            Viscosity::Implicit => "implicit",
        };
        let s = match self.shifting {
            ChannelShift::Xu002 => "xu0.02",
            ChannelShift::Xu001 => "xu0.01",
        };
        let p = match self.ppe {
            ChannelPpe::BicgstabTwoLevel => "bicgstab_two_level_1e-3",
            ChannelPpe::Bicgstab => "bicgstab_1e-3",
            ChannelPpe::Cg => "cg_1e-3",
            ChannelPpe::CgTwoLevel => "cg_two_level_1e-3",
        };
        format!("{v} {s} {p}")
    }

    /// This variant and its one-factor changes (shifting, then each other PPE solver).
    pub fn one_factor_at_a_time(&self) -> Vec<ChannelVariant> {
        let shifting = match self.shifting {
            ChannelShift::Xu002 => ChannelShift::Xu001,
            ChannelShift::Xu001 => ChannelShift::Xu002,
        };
        let mut out = vec![*self, ChannelVariant { shifting, ..*self }];
        out.extend(
            CHANNEL_PPES.iter().filter(|&&p| p != self.ppe).map(|&ppe| ChannelVariant { ppe, ..*self }),
        );
        out
    }

    /// Applies the variant to a channel scene (an ISPH scene; others are left alone).
    pub fn apply(&self, scene: &mut Scene) {
        let Scheme::Isph(o) = &mut scene.scheme else {
            return;
        };
        o.viscosity = match self.viscosity {
            Viscosity::Explicit => ViscousIntegration::Explicit,
            Viscosity::Implicit => ViscousIntegration::Implicit,
        };
        o.shifting = Shifting::Xu {
            coefficient: match self.shifting {
                ChannelShift::Xu002 => 0.02,
                ChannelShift::Xu001 => 0.01,
            },
            smooth: false,
        };
        (o.ppe.solver, o.ppe.preconditioner) = match self.ppe {
            ChannelPpe::BicgstabTwoLevel => (PpeSolver::Bicgstab, Preconditioner::TwoLevel),
            ChannelPpe::Bicgstab => (PpeSolver::Bicgstab, Preconditioner::Jacobi),
            ChannelPpe::Cg => (PpeSolver::Cg, Preconditioner::Jacobi),
            ChannelPpe::CgTwoLevel => (PpeSolver::Cg, Preconditioner::TwoLevel),
        };
        o.ppe.tolerance = 1e-3;
    }
}

/// The case preset whose `scheme` the channel's MPS point runs on the `re4` scene.
pub const MPS: SchemePreset = SchemePreset { scheme: "mps", preset: "mps" };

/// What a planned channel run runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ChannelSetup {
    /// An ISPH option set on the `re4` scene.
    Isph(ChannelVariant),
    /// The `re4` scene with the `scheme` of another scheme's case preset (the preset's other
    /// changes, such as its body force, left out).
    SchemeOf(SchemePreset),
}

impl ChannelSetup {
    /// The scheme of the run's scene.
    pub fn scheme(&self) -> &'static str {
        match self {
            ChannelSetup::Isph(_) => "isph",
            ChannelSetup::SchemeOf(p) => p.scheme,
        }
    }

    /// The case preset the run is (`re4`, `re4_implicit`), or whose scheme options it
    /// takes (`mps`).
    pub fn preset(&self) -> Option<&'static str> {
        match self {
            ChannelSetup::Isph(v) => v.preset(),
            ChannelSetup::SchemeOf(p) => Some(p.preset),
        }
    }

    /// The ISPH option set, if the run is one.
    pub fn variant(&self) -> Option<ChannelVariant> {
        match self {
            ChannelSetup::Isph(v) => Some(*v),
            ChannelSetup::SchemeOf(_) => None,
        }
    }

    /// A short label: the variant's ([`ChannelVariant::label`]), or
    /// `mps options-of-mps` for another scheme's point.
    pub fn label(&self) -> String {
        match self {
            ChannelSetup::Isph(v) => v.label(),
            ChannelSetup::SchemeOf(p) => format!("{} options-of-{}", p.scheme, p.preset),
        }
    }
}

/// The name of another scheme's channel point for tables and legends:
/// `mps (options of the mps preset) · re4`.
pub fn scheme_of_label(scheme: &str, preset: &str) -> String {
    format!("{scheme} (options of the {preset} preset) · {PRESET}")
}

/// One planned channel run.
#[derive(Debug, Clone, PartialEq)]
pub struct ChannelPlanned {
    /// Spacing \[m\].
    pub dx: f64,
    /// ISPH option set or another scheme's options.
    pub setup: ChannelSetup,
    /// Rayon threads.
    pub threads: usize,
}

impl ChannelPlanned {
    /// A stable id, e.g. `channel_dx0.00400_t2_explicit-xu0.02-bicgstab_1e-3` or
    /// `channel_dx0.00400_t2_mps-options-of-mps`.
    pub fn id(&self) -> String {
        format!("channel_dx{:.5}_t{}_{}", self.dx, self.threads, self.setup.label().replace(' ', "-"))
    }
}

/// The channel runs of a tier, coarse spacings first, each spacing's ISPH runs then its
/// MPS point ([`MPS`]):
/// - quick: D/36, both viscous integrations with the case's other options (3 runs);
/// - default: D/36 and 0.004, each viscous integration and its one-factor changes
///   (22 runs);
/// - full: the default design at D/36, 0.004 and 0.0025 (33 runs).
pub fn design(tier: Tier, threads: usize) -> (Vec<ChannelPlanned>, String) {
    let (spacings, variants): (&[f64], Vec<ChannelVariant>) = match tier {
        Tier::Quick => (&[D36], vec![ChannelVariant::EXPLICIT, ChannelVariant::IMPLICIT]),
        Tier::Default | Tier::Full => {
            let mut v = ChannelVariant::EXPLICIT.one_factor_at_a_time();
            v.extend(ChannelVariant::IMPLICIT.one_factor_at_a_time());
            (if tier == Tier::Full { &[D36, 0.004, 0.0025] } else { &[D36, 0.004] }, v)
        }
    };
    let setups: Vec<ChannelSetup> =
        variants.into_iter().map(ChannelSetup::Isph).chain([ChannelSetup::SchemeOf(MPS)]).collect();
    let runs = spacings
        .iter()
        .flat_map(|&dx| setups.iter().map(move |&setup| ChannelPlanned { dx, setup, threads }))
        .collect();
    let dx = spacings.iter().map(|d| format!("{d:.5}")).collect::<Vec<_>>().join(", ");
    let which = if tier == Tier::Quick {
        "explicit and implicit viscosity with the case's options"
    } else {
        "explicit and implicit viscosity, each with Xu C = 0.01 instead of 0.02, and with BiCGSTAB (Jacobi), CG (Jacobi) and two-level CG instead of two-level BiCGSTAB"
    };
    (
        runs,
        format!(
            "Periodic channel (Re = 4, to τ = 1), Δx = {dx}: {which}; and at each spacing {}: the re4 scene with the \
             scheme options of the case's {} preset (a Re = 40 preset: only its scheme is taken).",
            scheme_of_label(MPS.scheme, MPS.preset),
            MPS.preset
        ),
    )
}

/// The scene of `setup` at `dx`: the case's `re4` preset at `dx`, then the ISPH variant,
/// or with the `scheme` of the other scheme's preset (at `dx`) in place of its own.
pub fn scene(case: &Case, setup: &ChannelSetup, dx: f64) -> Result<Scene> {
    let mut value = crate::sweep::effective_scene(case, PRESET, dx)?;
    if let ChannelSetup::SchemeOf(p) = setup {
        value["scheme"] = crate::sweep::effective_scene(case, p.preset, dx)?["scheme"].take();
    }
    let run = format!("work-precision dx{dx} {}", setup.label());
    let mut scene = Scene::from_json(&value.to_string()).map_err(|source| HarnessError::Scene {
        case: case.case.clone(),
        run: run.clone(),
        source,
    })?;
    if let ChannelSetup::Isph(variant) = setup {
        variant.apply(&mut scene);
    }
    meniscus::scene::validate(&scene).map_err(|source| HarnessError::Scene {
        case: case.case.clone(),
        run,
        source,
    })?;
    Ok(scene)
}

/// One channel run. A diverged run is a row with its status and no error value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelRow {
    /// Stable id ([`ChannelPlanned::id`]).
    pub id: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// The scheme of the run's scene: `isph` or `mps` (`isph` in files written before the
    /// MPS point existed).
    #[serde(default = "isph")]
    pub scheme: String,
    /// The ISPH option set; absent for another scheme's point.
    #[serde(flatten)]
    pub variant: Option<ChannelVariant>,
    /// `re4` or `re4_implicit` when the ISPH option set is one of the case's presets; for
    /// another scheme's point, the preset whose scheme options it runs on the `re4` scene
    /// (`mps`; see [`ChannelRow::series`]).
    pub preset: Option<String>,
    /// Rayon threads.
    pub threads: usize,
    /// Size and cost of the run.
    #[serde(flatten)]
    pub cost: Cost,
    /// Steady profile error at τ = 1 (`u_profile_l2_rel_steady`); `None` when diverged.
    pub error: Option<f64>,
    /// Largest start-up profile error, τ < 1 (`u_profile_l2_rel_startup_max`).
    pub error_startup_max: Option<f64>,
    /// `ok` or `diverged: <cause>`.
    pub status: String,
    /// Taken from the run cache of an earlier invocation (see `RunRow::reused`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub reused: bool,
}

impl ChannelRow {
    /// Whether the run reached its end time.
    pub fn ok(&self) -> bool {
        self.status == "ok"
    }

    /// What the row is, if a named series: its ISPH preset (`re4`, `re4_implicit`), or
    /// another scheme's point ([`scheme_of_label`]).
    pub fn series(&self) -> Option<String> {
        let preset = self.preset.as_deref()?;
        Some(if self.scheme == "isph" { preset.to_string() } else { scheme_of_label(&self.scheme, preset) })
    }
}

/// The channel study in `results.json` (its `channel` field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelStudy {
    /// `poiseuille_periodic`.
    pub case: String,
    /// The error measure.
    pub error_metric: String,
    /// The parts of the design.
    pub design: Vec<String>,
    /// Every run, in the order run.
    pub runs: Vec<ChannelRow>,
    /// Ids of the runs on the Pareto front of (error, wall time) of each scheme
    /// ([`super::pareto::fronts_by_scheme`]), each scheme's cheapest first.
    pub pareto: Vec<String>,
}

impl ChannelStudy {
    /// An empty study of `design`.
    pub fn new(design: String) -> ChannelStudy {
        ChannelStudy {
            case: CASE.into(),
            error_metric: format!(
                "{METRIC}: sqrt(Σ (u − u_ref)² / Σ u_ref²) over the velocity bins at τ = νt/D² = 1 (Re = 4), \
                 against the Morris, Fox & Zhu 1997 start-up series"
            ),
            design: vec![design],
            runs: Vec::new(),
            pareto: Vec::new(),
        }
    }

    /// Fills the Pareto front of each scheme from its finished runs.
    pub fn derive(&mut self) {
        let pts: Vec<(&ChannelRow, (f64, f64))> = self
            .runs
            .iter()
            .filter(|r| r.ok())
            .filter_map(|r| r.error.filter(|e| e.is_finite()).map(|e| (r, (e, r.cost.wall_s))))
            .collect();
        let schemes: Vec<&str> = pts.iter().map(|p| p.0.scheme.as_str()).collect();
        let xy: Vec<(f64, f64)> = pts.iter().map(|p| p.1).collect();
        self.pareto =
            super::pareto::fronts_by_scheme(&schemes, &xy).into_iter().map(|i| pts[i].0.id.clone()).collect();
    }
}

/// The row of a planned run from how it ran.
pub fn row(case: &Case, planned: &ChannelPlanned, ran: &Ran) -> Result<ChannelRow> {
    let m = super::measure(case, ran)?;
    let get = |k: &str| m.metrics.get(k).copied();
    Ok(ChannelRow {
        id: planned.id(),
        dx: planned.dx,
        scheme: planned.setup.scheme().to_string(),
        variant: planned.setup.variant(),
        preset: planned.setup.preset().map(str::to_string),
        threads: planned.threads,
        error: get(METRIC),
        error_startup_max: get("u_profile_l2_rel_startup_max"),
        cost: m.cost,
        status: m.status,
        reused: ran.reused(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::testing::committed;
    use std::collections::HashSet;

    #[test]
    fn presets_match_the_case_file() {
        let c = committed("poiseuille_periodic");
        for v in [ChannelVariant::EXPLICIT, ChannelVariant::IMPLICIT] {
            let name = v.preset().unwrap();
            for dx in [D36, 0.0025] {
                assert_eq!(
                    scene(&c, &ChannelSetup::Isph(v), dx).unwrap(),
                    crate::sweep::spec(&c, name, dx).unwrap().scene,
                    "{name} {dx}"
                );
            }
        }
        let s = scene(
            &c,
            &ChannelSetup::Isph(ChannelVariant {
                shifting: ChannelShift::Xu001,
                ppe: ChannelPpe::Cg,
                ..ChannelVariant::IMPLICIT
            }),
            0.004,
        )
        .unwrap();
        let Scheme::Isph(o) = &s.scheme else { panic!("an ISPH scene") };
        assert_eq!(o.shifting, Shifting::Xu { coefficient: 0.01, smooth: false });
        assert_eq!(o.ppe.solver, PpeSolver::Cg);
        assert_eq!(o.ppe.preconditioner, Preconditioner::Jacobi);
        assert_eq!(o.viscosity, ViscousIntegration::Implicit);
        let s = scene(
            &c,
            &ChannelSetup::Isph(ChannelVariant { ppe: ChannelPpe::CgTwoLevel, ..ChannelVariant::EXPLICIT }),
            D36,
        )
        .unwrap();
        let Scheme::Isph(o) = &s.scheme else { panic!("an ISPH scene") };
        assert_eq!((o.ppe.solver, o.ppe.preconditioner), (PpeSolver::Cg, Preconditioner::TwoLevel));
    }

    /// The MPS point is the case's `mps` preset with `re4`'s body force and time step: the
    /// `re4` flow (Re = 4) run with the `mps` preset's scheme options, nothing else of that
    /// preset.
    #[test]
    fn the_mps_point_is_re4_with_the_scheme_of_the_mps_preset() {
        let c = committed("poiseuille_periodic");
        for dx in [D36, 0.004, 0.0025] {
            let s = scene(&c, &ChannelSetup::SchemeOf(MPS), dx).unwrap();
            let re4 = crate::sweep::spec(&c, PRESET, dx).unwrap().scene;
            let mut want = crate::sweep::spec(&c, MPS.preset, dx).unwrap().scene;
            assert_ne!(want.body_force, re4.body_force, "the mps preset is not at Re = 4");
            want.body_force = re4.body_force.clone();
            // The preset's step (its viscous factor, measured at Re = 40) is not taken either.
            assert_ne!(want.time, re4.time, "the mps preset has its own step");
            want.time = re4.time.clone();
            assert_eq!(s, want, "dx {dx}");
            assert_eq!(s.scheme.key(), MPS.scheme);
        }
        let planned = ChannelPlanned { dx: 0.004, setup: ChannelSetup::SchemeOf(MPS), threads: 2 };
        assert_eq!(planned.id(), "channel_dx0.00400_t2_mps-options-of-mps");
        assert_eq!(scheme_of_label("mps", "mps"), "mps (options of the mps preset) · re4");
    }

    #[test]
    fn design_sizes() {
        let (quick, _) = design(Tier::Quick, 2);
        assert_eq!(quick.len(), 3);
        let (default, text) = design(Tier::Default, 2);
        assert_eq!(default.len(), 22);
        assert!(text.contains("0.00400") && text.contains("mps (options of the mps preset) · re4"), "{text}");
        let (full, _) = design(Tier::Full, 2);
        assert_eq!(full.len(), 33);
        let ids: HashSet<String> = full.iter().map(ChannelPlanned::id).collect();
        assert_eq!(ids.len(), 33, "ids are unique");
        assert!(full.iter().any(|r| r.setup.variant().is_some_and(|v| v.ppe == ChannelPpe::CgTwoLevel)));
        assert!(full.windows(2).all(|w| w[0].dx >= w[1].dx), "coarse first");
        // The MPS point at each spacing of each tier, once.
        for (tier, spacings) in [
            (Tier::Quick, vec![D36]),
            (Tier::Default, vec![D36, 0.004]),
            (Tier::Full, vec![D36, 0.004, 0.0025]),
        ] {
            let (runs, _) = design(tier, 2);
            let mps: Vec<f64> = runs.iter().filter(|r| r.setup.scheme() == "mps").map(|r| r.dx).collect();
            assert_eq!(mps, spacings, "{tier}");
        }
    }
}
