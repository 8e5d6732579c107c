//! Stage-level access to a simulation, for benchmarks and profiling.
//!
//! [`Stepper`] owns a [`Simulation`] and its clock and exposes what the run driver does in
//! one step as separate calls: pick the time step ([`Stepper::begin_step`]), run stage `i`
//! ([`Stepper::run_stage`]), run the end-of-step guard, or all of it at once
//! ([`Stepper::step_once`]). A [`Snapshot`] of the per-particle arrays and the clock lets
//! a caller put the state back before re-running a stage, so that repeated measurements
//! do the work of a real step:
//!
//! - the PPE solve warm-starts from the current pressure, so re-running it on its own
//!   output would converge in zero iterations; restoring the snapshot taken before the
//!   solve restores the pressure at the start of the step;
//! - `correction` and `shifting` update velocities (and positions) in place;
//! - a whole step moves the particles and advances the clock.
//!
//! The stages that only read the particles and overwrite derived arrays (`free_surface`,
//! `viscosity`, which recomputes u* from uⁿ, `ppe_assemble`, `position`, `neighbours`)
//! are idempotent on a restored state. The neighbour stage reorders the particles by cell
//! every 25th call, so a snapshot must be taken after the last neighbour call it is
//! restored across (restoring it after a reorder would mismatch the neighbour lists);
//! [`Stepper::restore`] is therefore meant for the stages after `neighbours`, or for a
//! whole step, which rebuilds the lists from the restored positions.

use crate::error::{SceneError, SolverError};
use crate::fields::Extent;
use crate::run::Simulation;
use crate::scene::Scene;
use crate::scheme::SavedState;
use crate::stage::StepContext;
use crate::state::State;

/// A simulation with its clock, steppable one stage at a time.
#[derive(Debug)]
pub struct Stepper<const D: usize> {
    sim: Simulation<D>,
    time: f64,
    step: usize,
    /// Stage and guard seconds of [`Stepper::step_once`] (not reported; the step function
    /// is the driver's, which times them).
    timings: Vec<f64>,
}

/// The declared per-particle fields (with the open-boundary bookkeeping) and the clock of
/// a [`Stepper`] at one instant.
#[derive(Debug, Clone, Default)]
pub struct Snapshot<const D: usize> {
    saved: SavedState<D>,
    time: f64,
    step: usize,
}

impl<const D: usize> Stepper<D> {
    /// Validates `scene` (its dimension must be D) and builds the simulation at t = 0.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        crate::scene::validate(scene)?;
        if scene.dimension != D {
            return Err(SceneError::new(
                "dimension",
                scene.dimension,
                format!("must be {D} for this stepper"),
            ));
        }
        Ok(Self::of(Simulation::new(scene)?))
    }

    /// A stepper of a built simulation at t = 0.
    pub fn of(sim: Simulation<D>) -> Self {
        let timings = vec![0.0; sim.method().stage_count() + 1];
        Self { sim, time: 0.0, step: 0, timings }
    }

    /// The current state.
    pub fn state(&self) -> &State<D> {
        self.sim.state()
    }

    /// The simulation.
    pub fn simulation(&self) -> &Simulation<D> {
        &self.sim
    }

    /// Time reached \[s\].
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.step
    }

    /// Number of stages of one step.
    pub fn stage_count(&self) -> usize {
        self.sim.method().stage_count()
    }

    /// Name of stage `i` (as in `summary.json`); panics if `i >= stage_count()`.
    pub fn stage_name(&self, i: usize) -> &'static str {
        self.sim.method().stage_name(i)
    }

    /// Index of the first stage called `name`, if the scene built one.
    pub fn stage_index(&self, name: &str) -> Option<usize> {
        (0..self.stage_count()).find(|&i| self.stage_name(i) == name)
    }

    /// The context of the next step: its number, the current time and Δt from the scene's
    /// rule (the end time is ignored: a stepper can run past it). Changes nothing.
    pub fn begin_step(&self) -> Result<StepContext, SolverError> {
        let dt = self.sim.time_step(f64::INFINITY).map_err(|cause| SolverError {
            stage: "time_step",
            step: self.step + 1,
            time: self.time,
            cause,
        })?;
        Ok(StepContext { step: self.step + 1, time: self.time, dt })
    }

    /// Runs stage `i` of the step described by `ctx`; panics if `i >= stage_count()`.
    pub fn run_stage(&mut self, i: usize, ctx: &StepContext) -> Result<(), SolverError> {
        let m = self.sim.method_mut();
        m.run_stage(i, ctx).map_err(|cause| SolverError {
            stage: m.stage_name(i),
            step: ctx.step,
            time: ctx.time,
            cause,
        })
    }

    /// Runs stages `0..end` of the step described by `ctx` (prepares the input of stage
    /// `end`).
    pub fn run_stages_before(&mut self, end: usize, ctx: &StepContext) -> Result<(), SolverError> {
        (0..end).try_for_each(|i| self.run_stage(i, ctx))
    }

    /// The driver's end-of-step guard (finite values, no escaped particle).
    pub fn guard(&self, ctx: &StepContext) -> Result<(), SolverError> {
        self.sim.guard(ctx.time + ctx.dt, ctx.dt).map_err(|cause| SolverError {
            stage: "guard",
            step: ctx.step,
            time: ctx.time,
            cause,
        })
    }

    /// One whole step as the driver takes it (its step function: every stage, then the
    /// guard) and advances the clock; returns Δt.
    pub fn step_once(&mut self) -> Result<f64, SolverError> {
        let ctx = self.begin_step()?;
        self.sim.advance(&ctx, &mut self.timings)?;
        self.step += 1;
        self.time += ctx.dt;
        Ok(ctx.dt)
    }

    /// Copies the declared per-particle fields and the clock.
    pub fn snapshot(&self) -> Snapshot<D> {
        let mut s = Snapshot::default();
        self.snapshot_into(&mut s);
        s
    }

    /// Copies the declared per-particle fields and the clock into `snap`, reusing its
    /// storage.
    pub fn snapshot_into(&self, snap: &mut Snapshot<D>) {
        self.sim.method().save(&mut snap.saved, Extent::All);
        snap.time = self.time;
        snap.step = self.step;
    }

    /// Puts back the declared per-particle fields and the clock of `snap` (taken from this
    /// stepper; see the module documentation for when that is consistent). The neighbour
    /// lists, the pair cache and the scheme's per-step data (the PPE system) are left as
    /// they are.
    pub fn restore(&mut self, snap: &Snapshot<D>) {
        self.sim.method_mut().restore(&snap.saved);
        self.time = snap.time;
        self.step = snap.step;
    }
}

/// Runs `f` on a worker thread of the current rayon pool (directly when already on one),
/// as the run driver does: parallel loops started from a worker need no hand-over from an
/// outside thread, so timings taken inside `f` match those of a run.
pub fn on_worker<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    if rayon::current_thread_index().is_some() { f() } else { rayon::scope(|_| f()) }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drop_scene(steps: usize) -> Scene {
        let text = include_str!("../../../validation/scenes/elliptical_drop.json");
        let mut scene = Scene::from_json(text).unwrap();
        scene.dx = 0.05;
        scene.time.end = 2e-5 * steps as f64;
        scene
    }

    #[test]
    fn stepping_matches_the_driver() {
        let scene = drop_scene(3);
        let report = crate::run(&scene, &mut crate::Quiet).unwrap();
        let mut st = Stepper::<2>::new(&scene).unwrap();
        for _ in 0..3 {
            st.step_once().unwrap();
        }
        assert_eq!(st.steps(), 3);
        assert!((st.time() - 6e-5).abs() < 1e-15);
        let f = &report.final_frame;
        let p = &st.state().particles;
        for a in 0..p.len() {
            let i = p.id[a] as usize;
            assert!((p.x[a][0] - f.x[i][0]).abs() < 1e-14 && (p.x[a][1] - f.x[i][1]).abs() < 1e-14);
            assert!((p.p[a] - f.p[i]).abs() <= 1e-9 * f.p[i].abs().max(1.0));
        }
    }

    #[test]
    fn restore_makes_a_stage_repeatable() {
        let mut st = Stepper::<2>::new(&drop_scene(10)).unwrap();
        st.step_once().unwrap();
        let ctx = st.begin_step().unwrap();
        let solve = st.stage_index("ppe_solve").unwrap();
        assert_eq!(st.stage_name(solve), "ppe_solve");
        assert!(st.stage_index("no_such_stage").is_none());
        st.run_stages_before(solve, &ctx).unwrap();
        let snap = st.snapshot();
        st.run_stage(solve, &ctx).unwrap();
        let first = st.state().solve;
        let p_first = st.state().particles.p.clone();
        assert!(first.iterations > 0);
        // Without a restore the warm start is the solution: no work left.
        st.run_stage(solve, &ctx).unwrap();
        assert!(st.state().solve.iterations < first.iterations);
        st.restore(&snap);
        st.run_stage(solve, &ctx).unwrap();
        assert_eq!(st.state().solve.iterations, first.iterations);
        assert_eq!(st.state().particles.p, p_first);
        // A whole step from a restored state is the same step again.
        st.restore(&snap);
        assert_eq!(st.steps(), 1);
    }

    #[test]
    fn wrong_dimension_is_rejected() {
        assert!(Stepper::<3>::new(&drop_scene(1)).is_err());
    }
}
