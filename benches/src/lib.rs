//! Shared fixtures for the criterion benches: the scenes benched, and a prepared state on
//! which one stage can be re-run with representative work.
//!
//! Scenes: [`scenes`] lists every benched scene: the DESIGN.md elliptical drop at
//! Δx = 0.04, 0.02, 0.01 ([`elliptical_drop`]) and the periodic Poiseuille channel at D/36
//! ([`periodic_channel`]: mirror walls, one periodic axis, so its steps include the
//! `walls` and `mirror_velocity` stages and the minimum-image displacements).
//!
//! Stage benches ([`StageBench`]): the scene is stepped [`WARM_STEPS`] whole steps (so the
//! PPE warm start, shifting and the particle order are those of a running simulation), the
//! next step's stages are run up to the benched one, and the per-particle arrays are
//! saved. Each timed iteration first restores them (untimed), then runs the stage alone
//! (timed), on a worker thread of the rayon pool as the run driver does. The PPE solve
//! therefore always starts from the pressure at the start of the step (not from its own
//! previous solution), `correction` and `shifting` always apply the same update, and the
//! stages that overwrite their outputs (`free_surface`, `viscosity`, `ppe_assemble`,
//! `neighbours`) do exactly one step's work per iteration. The neighbour stage is not
//! restored (it rebuilds the lists from unchanged positions); it reorders the particles by
//! cell every 25th call, so its mean includes that amortised cost, as in a run.

use meniscus::Scene;
use meniscus::profile::{Snapshot, Stepper, on_worker};
use meniscus::scene::{PpeSolver, Preconditioner, Scheme, Shifting};
use meniscus::stage::StepContext;
use std::time::{Duration, Instant};

/// Whole steps taken before a stage is benched.
pub const WARM_STEPS: usize = 5;

/// Spacings of the drop benches \[m\].
pub const DROP_SPACINGS: [f64; 3] = [0.04, 0.02, 0.01];

/// A scene to bench and its label.
#[derive(Debug, Clone)]
pub struct BenchScene {
    /// Label used in benchmark ids, e.g. `drop_dx0.02`.
    pub label: String,
    /// The scene.
    pub scene: Scene,
}

/// The DESIGN.md elliptical-drop scene at spacing `dx`, ending after `steps` steps of its
/// fixed Δt.
pub fn drop_scene(dx: f64, steps: usize) -> Scene {
    let text = include_str!("../../validation/scenes/elliptical_drop.json");
    let mut scene = Scene::from_json(text).expect("the committed scene is valid");
    scene.dx = dx;
    if let meniscus::scene::TimeStep::Fixed(dt) = scene.time.step {
        scene.time.end = dt * steps as f64;
    }
    scene
}

/// The elliptical drop (paper preset: BiCGSTAB 1e-3, eq. 10 divergence, Xu shifting) at
/// every spacing of [`DROP_SPACINGS`].
pub fn elliptical_drop() -> Vec<BenchScene> {
    DROP_SPACINGS
        .iter()
        .map(|&dx| BenchScene { label: format!("drop_dx{dx}"), scene: drop_scene(dx, 400) })
        .collect()
}

/// The periodic Poiseuille channel of `validation/poiseuille_periodic.json` as its
/// template stands (Re = U D/ν = 40, D = 0.2 m, Δx = D/36: 648 fluid particles, mirror
/// walls at y = 0 and D, periodic in x over D/2, Xu shifting, BiCGSTAB 1e-3, adaptive Δt).
pub fn periodic_channel() -> Vec<BenchScene> {
    let case: serde_json::Value =
        serde_json::from_str(include_str!("../../validation/poiseuille_periodic.json"))
            .expect("the committed case file is JSON");
    let scene = Scene::from_json(&case["scene"].to_string()).expect("the committed channel scene is valid");
    vec![BenchScene { label: "channel_d36".into(), scene }]
}

/// The 3D pipe of `validation/hagen_poiseuille.json` (ISPH, its template's options) at
/// R/Δx = 24: 65 160 fluid particles in rings and 50 688 dummy wall particles in the shell,
/// 115 848 in all (issue #36: a 3D step at about 100 k particles).
pub fn pipe_3d() -> BenchScene {
    let case: serde_json::Value =
        serde_json::from_str(include_str!("../../validation/hagen_poiseuille.json"))
            .expect("the committed case file is JSON");
    let mut scene = Scene::from_json(&case["scene"].to_string()).expect("the committed pipe scene is valid");
    scene.dx = 0.01 / 24.0;
    BenchScene { label: "pipe3d_r24".into(), scene }
}

/// Every benched scene: the drops, then the channel.
pub fn scenes() -> Vec<BenchScene> {
    let mut s = elliptical_drop();
    s.extend(periodic_channel());
    s
}

/// `scene` with the backward-Euler viscous predictor (`viscosity: implicit`).
pub fn with_implicit_viscosity(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    let Scheme::Isph(opts) = &mut s.scheme else { return s };
    opts.viscosity = meniscus::scene::ViscousIntegration::Implicit;
    s
}

/// `scene` with its PPE solved by `solver` with `preconditioner` (Krylov tolerance 1e-3,
/// the paper's).
pub fn with_ppe_solver(scene: &Scene, solver: PpeSolver, preconditioner: Preconditioner) -> Scene {
    let mut s = scene.clone();
    let Scheme::Isph(opts) = &mut s.scheme else { return s };
    opts.ppe.solver = solver;
    opts.ppe.tolerance = 1e-3;
    opts.ppe.preconditioner = preconditioner;
    s
}

/// `scene` with the given shifting law.
pub fn with_shifting(scene: &Scene, shifting: Shifting) -> Scene {
    let mut s = scene.clone();
    let Scheme::Isph(opts) = &mut s.scheme else { return s };
    opts.shifting = shifting;
    s
}

/// `scene` with the kernel-corrected velocity divergence on the PPE source.
pub fn with_corrected_divergence(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    let Scheme::Isph(opts) = &mut s.scheme else { return s };
    opts.divergence = meniscus::scene::Divergence::Corrected;
    s
}

/// Particle and pair counts of a scene's state after [`WARM_STEPS`] steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Size {
    /// Particles.
    pub particles: usize,
    /// Neighbour pairs (both orders, self included).
    pub pairs: usize,
}

/// One stage of a 2D scene, ready to be re-run with the work of a real step (see the
/// crate documentation).
#[derive(Debug)]
pub struct StageBench {
    stepper: Stepper<2>,
    ctx: StepContext,
    stage: usize,
    snapshot: Option<Snapshot<2>>,
}

impl StageBench {
    /// Prepares stage `name` of `scene`; `None` when the scene does not build that stage.
    /// With `restore = false` the stage is re-run without restoring the particle arrays
    /// (for the neighbour stage, which must not be restored across its reordering).
    pub fn new(scene: &Scene, name: &str, restore: bool) -> Option<Self> {
        let mut stepper = Stepper::<2>::new(scene).expect("bench scenes are valid");
        let stage = stepper.stage_index(name)?;
        on_worker(|| -> Option<Self> {
            for _ in 0..WARM_STEPS {
                stepper.step_once().expect("the warm-up steps are stable");
            }
            let ctx = stepper.begin_step().expect("a time step");
            stepper.run_stages_before(stage, &ctx).expect("the stages before the benched one run");
            let snapshot = restore.then(|| stepper.snapshot());
            Some(Self { stepper, ctx, stage, snapshot })
        })
    }

    /// Particle and pair counts of the prepared state.
    pub fn size(&self) -> Size {
        let st = self.stepper.state();
        Size { particles: st.particles.len(), pairs: st.neighbours.pairs() }
    }

    /// PPE iterations of the last run of the stage (meaningful for `ppe_solve`).
    pub fn ppe_iterations(&self) -> usize {
        self.stepper.state().solve.iterations
    }

    /// Runs the stage `iters` times and returns the time spent in the stage alone (the
    /// restores between runs are not timed). For criterion's `iter_custom`.
    pub fn time(&mut self, iters: u64) -> Duration {
        on_worker(|| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                if let Some(snap) = &self.snapshot {
                    self.stepper.restore(snap);
                }
                let t0 = Instant::now();
                let r = self.stepper.run_stage(self.stage, &self.ctx);
                total += t0.elapsed();
                r.expect("the benched stage runs");
            }
            total
        })
    }
}

/// Whole steps of a scene of dimension `D` (2 by default), each from the same state
/// (restored untimed before each).
#[derive(Debug)]
pub struct StepBench<const D: usize = 2> {
    stepper: Stepper<D>,
    snapshot: Snapshot<D>,
}

impl<const D: usize> StepBench<D> {
    /// Steps `scene` [`WARM_STEPS`] times and saves the state.
    pub fn new(scene: &Scene) -> Self {
        let mut stepper = Stepper::<D>::new(scene).expect("bench scenes are valid");
        on_worker(|| {
            for _ in 0..WARM_STEPS {
                stepper.step_once().expect("the warm-up steps are stable");
            }
        });
        let snapshot = stepper.snapshot();
        Self { stepper, snapshot }
    }

    /// Particles of the scene.
    pub fn particles(&self) -> usize {
        self.stepper.state().particles.len()
    }

    /// Takes `iters` whole steps (time step, every stage, guard), each from the saved
    /// state, and returns the time spent stepping.
    pub fn time(&mut self, iters: u64) -> Duration {
        on_worker(|| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                self.stepper.restore(&self.snapshot);
                let t0 = Instant::now();
                let r = self.stepper.step_once();
                total += t0.elapsed();
                r.expect("the benched step is stable");
            }
            total
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stage_bench_repeats_the_same_solve() {
        let scene = drop_scene(0.05, 10);
        let mut b = StageBench::new(&scene, "ppe_solve", true).unwrap();
        b.time(1);
        let first = b.ppe_iterations();
        assert!(first > 0);
        b.time(3);
        assert_eq!(b.ppe_iterations(), first, "each solve starts from the start-of-step pressure");
        assert!(b.size().pairs > 10 * b.size().particles);
        assert!(StageBench::new(&with_shifting(&scene, Shifting::None), "shifting", true).is_none());
    }

    #[test]
    fn channel_stages_are_benched() {
        let ch = &periodic_channel()[0].scene;
        let mut walls = StageBench::new(ch, "walls", true).unwrap();
        assert!(walls.time(2) > Duration::ZERO);
        assert_eq!(walls.size().particles, 648);
        let st = walls.stepper.state();
        assert!(st.particles.total() > st.particles.len(), "mirror particles added");
        let mut implicit = StageBench::new(&with_implicit_viscosity(ch), "viscosity_implicit", true).unwrap();
        assert!(implicit.time(2) > Duration::ZERO);
        let mut step = StepBench::<2>::new(ch);
        assert!(step.time(1) > Duration::ZERO);
    }

    #[test]
    fn the_3d_pipe_bench_has_about_100k_particles() {
        let stepper = Stepper::<3>::new(&pipe_3d().scene).expect("valid");
        let p = &stepper.state().particles;
        assert_eq!((p.len(), p.total()), (65_160, 115_848));
    }

    #[test]
    fn step_bench_restarts_from_the_saved_state() {
        let mut b = StepBench::<2>::new(&drop_scene(0.05, 10));
        assert!(b.time(2) > Duration::ZERO);
        assert_eq!(b.stepper.steps(), WARM_STEPS + 1);
    }

    #[test]
    fn every_scene_is_labelled_and_valid() {
        let s = scenes();
        assert_eq!(s.len(), 4);
        assert_eq!(s[1].label, "drop_dx0.02");
        assert_eq!(s[3].label, "channel_d36");
        for b in &s {
            meniscus::scene::validate(&b.scene).unwrap();
        }
        let direct = with_ppe_solver(&s[0].scene, PpeSolver::Direct, Preconditioner::Jacobi);
        let Scheme::Isph(o) = &direct.scheme else { panic!("an ISPH scene") };
        assert_eq!(o.ppe.solver, PpeSolver::Direct);
    }
}
