//! The factors of the study, the two presets they vary around, and the pruned design of
//! each tier.
//!
//! The cross product (5 Krylov settings × 2 gradients × 2 divergences × 3 shifting laws ×
//! 2 time-step rules = 120 option sets) is run at the coarsest spacing only. At every
//! spacing the design is one factor at a time around the `paper` and `tuned` presets of
//! `validation/elliptical_drop.json`: each preset, and each preset with one factor changed
//! to each of its other levels. The sparse LU, which refactorises every step, is pruned
//! below Δx = 0.04 (see [`Design::for_tier`]). The two presets are also run with one
//! thread at every spacing of the thread study, for the speed-up.
//!
//! Beside the ISPH option sets, the case's presets of the other schemes
//! ([`SCHEME_PRESETS`]: `wcsph_tuned`, `mps`) run at every spacing of the tier, each scene
//! built as the validation sweep builds it ([`crate::sweep::spec`]).

use crate::case::Case;
use crate::error::{HarnessError, Result};
use crate::tier::Tier;
use meniscus::Scene;
use meniscus::scene::{Divergence, PpeSolver, Preconditioner, PressureGradient, Scheme, Shifting, TimeStep};
use serde::{Deserialize, Serialize};

/// PPE solver and tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Ppe {
    /// BiCGSTAB (Qiu's Krylov method) with the two-level preconditioner, relative tolerance
    /// 1e-3 (Qiu's): the paper preset's solver.
    #[serde(rename = "bicgstab_two_level_1e-3")]
    BicgstabTwoLevel3,
    /// BiCGSTAB (Jacobi), relative tolerance 1e-3 (the paper's).
    #[serde(rename = "bicgstab_1e-3")]
    Bicgstab3,
    /// BiCGSTAB (Jacobi), relative tolerance 1e-5.
    #[serde(rename = "bicgstab_1e-5")]
    Bicgstab5,
    /// Conjugate gradient (Jacobi), relative tolerance 1e-3.
    #[serde(rename = "cg_1e-3")]
    Cg3,
    /// Conjugate gradient with the two-level preconditioner (Jacobi plus a coarse space
    /// kept across steps), relative tolerance 1e-3: the tuned preset's solver.
    #[serde(rename = "cg_two_level_1e-3")]
    CgTwoLevel3,
    /// Sparse LU.
    #[serde(rename = "direct")]
    Direct,
}

/// Pressure-gradient form of the correction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Gradient {
    /// Qiu eq. 15, `(p_a + p_b)`.
    Symmetric,
    /// `(p_b − p_a)`.
    Difference,
}

/// Velocity divergence on the PPE source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Div {
    /// Qiu eq. 10.
    Standard,
    /// Kernel-gradient corrected.
    Corrected,
}

/// Particle shifting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shift {
    /// None.
    None,
    /// Xu, C = 0.02.
    Xu,
    /// Lind's Fickian, A = 2.
    Fickian,
}

/// Time-step rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Dt {
    /// The case's fixed Δt (2e-5 s, scaled with Δx below 0.02 m).
    Fixed,
    /// Qiu eqs. 17–19 with α = 0.2 (CFL and viscous), capped at [`ADAPTIVE_MAX_DT`].
    Adaptive,
}

/// Cap of the adaptive time step \[s\] (never active in the drop, whose speed is ~100 m/s).
pub const ADAPTIVE_MAX_DT: f64 = 1e-3;

/// One option set of the study.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct Variant {
    /// PPE solver and tolerance.
    pub ppe: Ppe,
    /// Pressure-gradient form.
    pub gradient: Gradient,
    /// Divergence form.
    pub divergence: Div,
    /// Shifting law.
    pub shifting: Shift,
    /// Time-step rule.
    pub dt: Dt,
}

/// Every level of every factor, in display order.
const PPES: [Ppe; 6] =
    [Ppe::BicgstabTwoLevel3, Ppe::CgTwoLevel3, Ppe::Bicgstab3, Ppe::Bicgstab5, Ppe::Cg3, Ppe::Direct];
const GRADIENTS: [Gradient; 2] = [Gradient::Symmetric, Gradient::Difference];
const DIVS: [Div; 2] = [Div::Standard, Div::Corrected];
const SHIFTS: [Shift; 3] = [Shift::None, Shift::Xu, Shift::Fickian];
const DTS: [Dt; 2] = [Dt::Fixed, Dt::Adaptive];

impl Variant {
    /// The `paper` preset: BiCGSTAB 1e-3 (two-level preconditioner), symmetric gradient,
    /// eq. 10 divergence, Xu shifting, fixed Δt.
    pub const PAPER: Variant = Variant {
        ppe: Ppe::BicgstabTwoLevel3,
        gradient: Gradient::Symmetric,
        divergence: Div::Standard,
        shifting: Shift::Xu,
        dt: Dt::Fixed,
    };

    /// The `tuned` preset: the paper's with the corrected divergence, Fickian shifting and
    /// the PPE (to the same 1e-3) by two-level CG.
    pub const TUNED: Variant = Variant {
        ppe: Ppe::CgTwoLevel3,
        divergence: Div::Corrected,
        shifting: Shift::Fickian,
        ..Variant::PAPER
    };

    /// The name of a preset variant (`paper`, `tuned`), if it is one.
    pub fn preset(&self) -> Option<&'static str> {
        if *self == Variant::PAPER {
            Some("paper")
        } else if *self == Variant::TUNED {
            Some("tuned")
        } else {
            None
        }
    }

    /// A short label, e.g. `bicgstab_1e-3 sym std xu fixed`.
    pub fn label(&self) -> String {
        let ppe = match self.ppe {
            Ppe::BicgstabTwoLevel3 => "bicgstab_two_level_1e-3",
            Ppe::Bicgstab3 => "bicgstab_1e-3",
            Ppe::Bicgstab5 => "bicgstab_1e-5",
            Ppe::Cg3 => "cg_1e-3",
            Ppe::CgTwoLevel3 => "cg_two_level_1e-3",
            Ppe::Direct => "direct",
        };
        let gradient = match self.gradient {
            Gradient::Symmetric => "sym",
            Gradient::Difference => "diff",
        };
        let divergence = match self.divergence {
            Div::Standard => "std",
            Div::Corrected => "corr",
        };
        let shifting = match self.shifting {
            Shift::None => "noshift",
            Shift::Xu => "xu",
            Shift::Fickian => "fickian",
        };
        let dt = match self.dt {
            Dt::Fixed => "fixed",
            Dt::Adaptive => "adaptive",
        };
        format!("{ppe} {gradient} {divergence} {shifting} {dt}")
    }

    /// The full cross product of the factors (144 variants).
    pub fn all() -> Vec<Variant> {
        let mut out = Vec::with_capacity(144);
        for ppe in PPES {
            for gradient in GRADIENTS {
                for divergence in DIVS {
                    for shifting in SHIFTS {
                        for dt in DTS {
                            out.push(Variant { ppe, gradient, divergence, shifting, dt });
                        }
                    }
                }
            }
        }
        out
    }

    /// This variant and every variant that differs from it in exactly one factor.
    pub fn one_factor_at_a_time(&self) -> Vec<Variant> {
        let mut out = vec![*self];
        out.extend(PPES.iter().filter(|&&v| v != self.ppe).map(|&ppe| Variant { ppe, ..*self }));
        out.extend(
            GRADIENTS.iter().filter(|&&v| v != self.gradient).map(|&gradient| Variant { gradient, ..*self }),
        );
        out.extend(
            DIVS.iter().filter(|&&v| v != self.divergence).map(|&divergence| Variant { divergence, ..*self }),
        );
        out.extend(
            SHIFTS.iter().filter(|&&v| v != self.shifting).map(|&shifting| Variant { shifting, ..*self }),
        );
        out.extend(DTS.iter().filter(|&&v| v != self.dt).map(|&dt| Variant { dt, ..*self }));
        out
    }

    /// Applies the variant to a drop scene whose fixed Δt is the case's.
    pub fn apply(&self, scene: &mut Scene) {
        let Scheme::Isph(o) = &mut scene.scheme else {
            return; // the variants are ISPH options
        };
        (o.ppe.solver, o.ppe.tolerance, o.ppe.preconditioner) = match self.ppe {
            Ppe::BicgstabTwoLevel3 => (PpeSolver::Bicgstab, 1e-3, Preconditioner::TwoLevel),
            Ppe::Bicgstab3 => (PpeSolver::Bicgstab, 1e-3, Preconditioner::Jacobi),
            Ppe::Bicgstab5 => (PpeSolver::Bicgstab, 1e-5, Preconditioner::Jacobi),
            Ppe::Cg3 => (PpeSolver::Cg, 1e-3, Preconditioner::Jacobi),
            Ppe::CgTwoLevel3 => (PpeSolver::Cg, 1e-3, Preconditioner::TwoLevel),
            Ppe::Direct => (PpeSolver::Direct, o.ppe.tolerance, o.ppe.preconditioner),
        };
        o.pressure_gradient = match self.gradient {
            Gradient::Symmetric => PressureGradient::Symmetric,
            Gradient::Difference => PressureGradient::Difference,
        };
        o.divergence = match self.divergence {
            Div::Standard => Divergence::Standard,
            Div::Corrected => Divergence::Corrected,
        };
        o.shifting = match self.shifting {
            Shift::None => Shifting::None,
            Shift::Xu => Shifting::Xu { coefficient: 0.02, smooth: false },
            Shift::Fickian => Shifting::Fickian { coefficient: 2.0 },
        };
        if self.dt == Dt::Adaptive {
            scene.time.step = TimeStep::Adaptive { cfl: 0.2, viscous: 0.2, max: ADAPTIVE_MAX_DT };
        }
    }
}

/// A named preset of a case file whose scheme is not ISPH, run as the case file gives it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SchemePreset {
    /// The scheme: the key of the preset scene's `scheme` object (`wcsph`, `mps`).
    pub scheme: &'static str,
    /// The preset's name in the case file.
    pub preset: &'static str,
}

/// The drop's presets of the other schemes, run at every spacing of each tier: the tuned
/// WCSPH and the stabilised MPS (whose `expected_divergence` in the case file names the
/// spacings where it diverges).
pub const SCHEME_PRESETS: [SchemePreset; 2] =
    [SchemePreset { scheme: "wcsph", preset: "wcsph_tuned" }, SchemePreset { scheme: "mps", preset: "mps" }];

/// What a planned drop run runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Setup {
    /// An ISPH option set on the case template.
    Isph(Variant),
    /// A case preset of another scheme, unchanged.
    Preset(SchemePreset),
}

impl Setup {
    /// The scheme of the run's scene (`isph`, `wcsph`, `mps`).
    pub fn scheme(&self) -> &'static str {
        match self {
            Setup::Isph(_) => "isph",
            Setup::Preset(p) => p.scheme,
        }
    }

    /// The case preset the run is, if any (`paper`, `tuned`, or another scheme's preset).
    pub fn preset(&self) -> Option<&'static str> {
        match self {
            Setup::Isph(v) => v.preset(),
            Setup::Preset(p) => Some(p.preset),
        }
    }

    /// The ISPH option set, if the run is one.
    pub fn variant(&self) -> Option<Variant> {
        match self {
            Setup::Isph(v) => Some(*v),
            Setup::Preset(_) => None,
        }
    }

    /// A short label: the variant's ([`Variant::label`]), or `<scheme> <preset>`.
    pub fn label(&self) -> String {
        match self {
            Setup::Isph(v) => v.label(),
            Setup::Preset(p) => format!("{} {}", p.scheme, p.preset),
        }
    }
}

/// One planned run: spacing, what it runs, thread count, and the parts of the design that
/// asked for it.
#[derive(Debug, Clone, PartialEq)]
pub struct Planned {
    /// Spacing \[m\].
    pub dx: f64,
    /// ISPH option set or another scheme's preset.
    pub setup: Setup,
    /// Rayon threads.
    pub threads: usize,
    /// Design parts: `product`, `ofat:paper`, `ofat:tuned`, `presets`, `threads`, `schemes`.
    pub groups: Vec<String>,
}

impl Planned {
    /// A stable id, e.g. `dx0.02_t2_bicgstab_1e-3-sym-std-xu-fixed` or `dx0.02_t2_mps-mps`.
    pub fn id(&self) -> String {
        format!("dx{}_t{}_{}", self.dx, self.threads, self.setup.label().replace(' ', "-"))
    }
}

/// The runs of a tier, deduplicated (a run asked for by several parts is run once).
#[derive(Debug, Clone, PartialEq)]
pub struct Design {
    /// Runs, coarse spacings first.
    pub runs: Vec<Planned>,
    /// One line per part of the design, for the report.
    pub description: Vec<String>,
    /// Spacings of the thread study \[m\].
    pub thread_dx: Vec<f64>,
    /// Thread counts compared (1 and the main count).
    pub thread_counts: Vec<usize>,
}

impl Design {
    fn add(&mut self, dx: f64, variant: Variant, threads: usize, group: &str) {
        self.add_setup(dx, Setup::Isph(variant), threads, group);
    }

    fn add_setup(&mut self, dx: f64, setup: Setup, threads: usize, group: &str) {
        let same = |p: &&mut Planned| p.setup == setup && p.threads == threads && (p.dx - dx).abs() < 1e-12;
        match self.runs.iter_mut().find(|p| same(p)) {
            Some(p) => {
                if !p.groups.iter().any(|g| g == group) {
                    p.groups.push(group.to_string());
                }
            }
            None => self.runs.push(Planned { dx, setup, threads, groups: vec![group.to_string()] }),
        }
    }

    /// The design of `tier` with `threads` threads for the main runs.
    ///
    /// - quick: Δx 0.04 and 0.02; one factor at a time around `tuned` (sparse LU at 0.04
    ///   only), plus `paper`; the two presets with one thread too (27 ISPH runs).
    /// - default: the Krylov cross product at Δx = 0.04; one factor at a time around both
    ///   presets at 0.04, 0.02 and 0.01 (sparse LU at 0.04, and for `paper` at 0.02); both
    ///   presets with one thread at 0.04, 0.02, 0.01 (169 ISPH runs).
    /// - full: the default design plus both presets at Δx = 0.005.
    ///
    /// Every tier adds the [`SCHEME_PRESETS`] at each of its [`spacings`], with `threads`
    /// threads (31, 175 and 179 runs in all).
    pub fn for_tier(tier: Tier, threads: usize) -> Design {
        let mut d = Design {
            runs: Vec::new(),
            description: Vec::new(),
            thread_dx: Vec::new(),
            thread_counts: if threads == 1 { vec![1] } else { vec![1, threads] },
        };
        let presets = [("paper", Variant::PAPER), ("tuned", Variant::TUNED)];
        let iterative = |v: &Variant| v.ppe != Ppe::Direct;
        match tier {
            Tier::Quick => {
                for dx in [0.04, 0.02] {
                    d.add(dx, Variant::PAPER, threads, "presets");
                    for v in Variant::TUNED.one_factor_at_a_time() {
                        if dx >= 0.04 || iterative(&v) {
                            d.add(dx, v, threads, "ofat:tuned");
                        }
                    }
                }
                d.description.push(
                    "Δx = 0.04, 0.02: the tuned preset and each of its one-factor changes (the sparse LU at 0.04 only), and the paper preset.".into(),
                );
                d.thread_dx = vec![0.04, 0.02];
            }
            Tier::Default | Tier::Full => {
                for v in Variant::all().into_iter().filter(iterative) {
                    d.add(0.04, v, threads, "product");
                }
                d.description.push(
                    "Δx = 0.04: the full cross product of the factors with the five Krylov settings (120 option sets).".into(),
                );
                for dx in [0.04, 0.02, 0.01] {
                    for (name, p) in presets {
                        for v in p.one_factor_at_a_time() {
                            if dx >= 0.04 || iterative(&v) {
                                d.add(dx, v, threads, &format!("ofat:{name}"));
                            }
                        }
                    }
                }
                d.add(0.02, Variant { ppe: Ppe::Direct, ..Variant::PAPER }, threads, "ofat:paper");
                d.description.push(
                    "Δx = 0.04, 0.02, 0.01: the paper and tuned presets and each of their one-factor changes. The sparse LU \
                     refactorises every step (measured: 16 s at 0.04 and 87 s at 0.02 on a loaded machine, about 8 times \
                     more per halving of Δx), so it runs at 0.04 for both presets, at 0.02 for the paper preset, and not at 0.01."
                        .into(),
                );
                d.thread_dx = vec![0.04, 0.02, 0.01];
                if tier == Tier::Full {
                    for (_, p) in presets {
                        d.add(0.005, p, threads, "presets");
                    }
                    d.description.push("Δx = 0.005: the paper and tuned presets.".into());
                }
            }
        }
        for &dx in spacings(tier) {
            for p in SCHEME_PRESETS {
                d.add_setup(dx, Setup::Preset(p), threads, "schemes");
            }
        }
        d.description.push(format!(
            "Other schemes at Δx = {}: the case presets {}, each scene as the validation sweep builds it \
             (a divergence the case file expects is marked on its row).",
            spacings(tier).iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", "),
            SCHEME_PRESETS.map(|p| format!("{} ({})", p.preset, p.scheme.to_uppercase())).join(" and "),
        ));
        if threads != 1 {
            for &dx in &d.thread_dx.clone() {
                for (_, p) in presets {
                    d.add(dx, p, threads, "threads");
                    d.add(dx, p, 1, "threads");
                }
            }
            d.description.push(format!(
                "Thread study: the two presets with 1 and {threads} threads at Δx = {}.",
                d.thread_dx.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(", ")
            ));
        }
        d.runs.sort_by(|a, b| b.dx.total_cmp(&a.dx));
        d
    }
}

/// The drop spacings of `tier` \[m\], coarse to fine (those of the work-precision study,
/// not the case file's sweep).
pub fn spacings(tier: Tier) -> &'static [f64] {
    match tier {
        Tier::Quick => &[0.04, 0.02],
        Tier::Default => &[0.04, 0.02, 0.01],
        Tier::Full => &[0.04, 0.02, 0.01, 0.005],
    }
}

/// The scene of `setup` at `dx`: an ISPH variant's (`variant_scene`), or the case preset's
/// as the validation sweep builds it ([`crate::sweep::spec`]).
pub fn scene(case: &Case, setup: &Setup, dx: f64) -> Result<Scene> {
    match setup {
        Setup::Isph(v) => variant_scene(case, v, dx),
        Setup::Preset(p) => Ok(crate::sweep::spec(case, p.preset, dx)?.scene),
    }
}

/// The scene of `variant` at `dx`: the case template with the `paper` preset (the
/// template itself) at `dx`, the fixed Δt scaled as the case does, then the variant's
/// options.
fn variant_scene(case: &Case, variant: &Variant, dx: f64) -> Result<Scene> {
    let value = crate::sweep::effective_scene(case, "paper", dx)?;
    let mut scene = Scene::from_json(&value.to_string()).map_err(|source| HarnessError::Scene {
        case: case.case.clone(),
        run: format!("work-precision dx{dx}"),
        source,
    })?;
    variant.apply(&mut scene);
    meniscus::scene::validate(&scene).map_err(|source| HarnessError::Scene {
        case: case.case.clone(),
        run: format!("work-precision dx{dx} {}", variant.label()),
        source,
    })?;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::testing::committed;
    use std::collections::HashSet;

    #[test]
    fn presets_match_the_case_file() {
        let c = committed("elliptical_drop");
        for (name, v) in [("paper", Variant::PAPER), ("tuned", Variant::TUNED)] {
            for dx in [0.04, 0.01] {
                let spec = crate::sweep::spec(&c, name, dx).unwrap();
                assert_eq!(scene(&c, &Setup::Isph(v), dx).unwrap(), spec.scene, "{name} at dx {dx}");
            }
            assert_eq!(v.preset(), Some(name));
        }
        assert!(Variant { dt: Dt::Adaptive, ..Variant::PAPER }.preset().is_none());
    }

    /// The other schemes' rows run the case file's presets unchanged, at every spacing the
    /// study reaches (the validation sweep itself stops the drop at 0.02 below the full tier).
    #[test]
    fn scheme_presets_match_the_case_file() {
        let c = committed("elliptical_drop");
        for p in SCHEME_PRESETS {
            let setup = Setup::Preset(p);
            assert_eq!((setup.scheme(), setup.preset(), setup.variant()), (p.scheme, Some(p.preset), None));
            for &dx in spacings(Tier::Full) {
                let s = scene(&c, &setup, dx).unwrap();
                assert_eq!(s, crate::sweep::spec(&c, p.preset, dx).unwrap().scene, "{} at dx {dx}", p.preset);
                assert_eq!(s.scheme.key(), p.scheme, "{}", p.preset);
            }
        }
        let planned =
            Planned { dx: 0.02, setup: Setup::Preset(SCHEME_PRESETS[1]), threads: 2, groups: vec![] };
        assert_eq!(planned.id(), "dx0.02_t2_mps-mps");
    }

    #[test]
    fn factors_reach_the_scene() {
        let c = committed("elliptical_drop");
        let v = Variant {
            ppe: Ppe::Cg3,
            gradient: Gradient::Difference,
            divergence: Div::Corrected,
            shifting: Shift::None,
            dt: Dt::Adaptive,
        };
        let s = scene(&c, &Setup::Isph(v), 0.02).unwrap();
        let Scheme::Isph(o) = &s.scheme else { panic!("an ISPH scene") };
        assert_eq!(o.ppe.solver, PpeSolver::Cg);
        assert_eq!(o.pressure_gradient, PressureGradient::Difference);
        assert_eq!(o.divergence, Divergence::Corrected);
        assert_eq!(o.shifting, Shifting::None);
        assert!(matches!(s.time.step, TimeStep::Adaptive { .. }));
        // The fixed step is scaled with dx below 0.02 as the case does.
        let fine = scene(&c, &Setup::Isph(Variant::PAPER), 0.01).unwrap();
        assert!(matches!(fine.time.step, TimeStep::Fixed(dt) if (dt - 1e-5).abs() < 1e-18));
    }

    #[test]
    fn design_sizes() {
        let all = Variant::all();
        assert_eq!(all.len(), 144);
        assert_eq!(all.iter().collect::<HashSet<_>>().len(), 144);
        let ofat = Variant::PAPER.one_factor_at_a_time();
        assert_eq!(ofat.len(), 1 + 5 + 1 + 1 + 2 + 1);
        assert!(ofat.iter().skip(1).all(|v| *v != Variant::PAPER));

        let d = Design::for_tier(Tier::Default, 2);
        let at =
            |dx: f64, t: usize| d.runs.iter().filter(|r| (r.dx - dx).abs() < 1e-12 && r.threads == t).count();
        // 120 Krylov option sets, the sparse LU with either preset, and the two other
        // schemes' presets.
        assert_eq!(at(0.04, 2), 124);
        // Paper and tuned differ in three factors (solver, divergence, shifting), so they
        // share no neighbour: 11 + 10 option sets, the paper's sparse LU among them.
        assert_eq!(at(0.02, 2), 23);
        assert_eq!(at(0.01, 2), 22);
        let direct = |r: &&Planned| r.setup.variant().is_some_and(|v| v.ppe == Ppe::Direct);
        assert!(d.runs.iter().filter(direct).all(|r| r.dx >= 0.02));
        assert_eq!(at(0.01, 1), 2);
        assert_eq!(at(0.005, 2), 0);
        assert_eq!(d.runs.len(), 175);
        let ids: HashSet<String> = d.runs.iter().map(Planned::id).collect();
        assert_eq!(ids.len(), d.runs.len(), "ids are unique");
        assert!(d.runs.windows(2).all(|w| w[0].dx >= w[1].dx), "coarse first");
        let paper02 =
            d.runs.iter().find(|r| r.id() == "dx0.02_t2_bicgstab_two_level_1e-3-sym-std-xu-fixed").unwrap();
        assert!(paper02.groups.contains(&"ofat:paper".to_string()));
        assert!(paper02.groups.contains(&"threads".to_string()));

        let full = Design::for_tier(Tier::Full, 2);
        assert_eq!(full.runs.len(), d.runs.len() + 4);
        let quick = Design::for_tier(Tier::Quick, 2);
        assert!(quick.runs.iter().all(|r| r.dx >= 0.02));
        assert_eq!(quick.runs.len(), 31);
        assert_eq!(Design::for_tier(Tier::Quick, 1).thread_counts, vec![1]);
    }

    /// Each tier runs the WCSPH and the MPS preset once at each of its spacings, with the
    /// main thread count, and nowhere else.
    #[test]
    fn every_tier_runs_the_other_schemes_at_each_spacing() {
        for tier in [Tier::Quick, Tier::Default, Tier::Full] {
            let d = Design::for_tier(tier, 2);
            for scheme in ["wcsph", "mps"] {
                let rows: Vec<&Planned> = d.runs.iter().filter(|r| r.setup.scheme() == scheme).collect();
                let dx: Vec<f64> = rows.iter().map(|r| r.dx).collect();
                assert_eq!(dx, spacings(tier), "{scheme} in {tier}");
                assert!(rows.iter().all(|r| r.threads == 2 && r.groups == ["schemes"]), "{scheme} in {tier}");
            }
            assert!(
                d.description.iter().any(|l| l.contains("wcsph_tuned (WCSPH) and mps (MPS)")),
                "{:?}",
                d.description
            );
        }
    }
}
