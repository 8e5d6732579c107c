//! The run driver: builds the simulation from a scene (its scheme through
//! [`crate::registry`]), steps it to the end time, guards every step, records probes, and
//! returns a report (DESIGN.md "Run outputs"). It knows no scheme: it steps a
//! [`Method`].

use crate::error::{Cause, SceneError, SolverError};
use crate::fields::Extent;
use crate::frame::Frame;
use crate::guard::Guard;
use crate::probes::{ProbeRecord, ProbeSet};
use crate::registry::Built;
use crate::scene::{Scene, TimeStep};
use crate::scheme::{Adaptive, Method, SavedState, Scheme};
use crate::stage::StepContext;
use crate::state::State;
use crate::steady::is_steady;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Instant;

/// `summary.json` (DESIGN.md): counts, wall time, status and per-stage seconds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Number of particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Final time reached \[s\].
    pub t_end: f64,
    /// Wall time of the stepping loop \[s\].
    pub wall_s: f64,
    /// How the run ended (`"ok"` or `"diverged"` in the JSON).
    pub status: Status,
    /// The divergence message, when diverged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Seconds spent in each stage.
    pub stages: BTreeMap<String, f64>,
    /// Rayon threads used.
    pub threads: usize,
    /// Mean PPE iterations per step.
    pub ppe_iterations_mean: f64,
    /// When the steady-state stop (`time.steady`) ended the run: the time \[s\] (equal to
    /// `t_end`); absent when the run went to its end time or diverged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steady_at: Option<f64>,
}

/// How a run ended (`summary.json`'s `status`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// The run reached its end time.
    Ok,
    /// A stage or guard failed; [`Summary::error`] says where and why.
    Diverged,
}

/// Receives progress and frames while a run goes on (on a worker thread of the rayon pool).
pub trait Observer: Send {
    /// Called after every step.
    fn progress(&mut self, _step: usize, _time: f64, _t_end: f64) {}
    /// Called with a frame every `output.vtk_every` steps (and at step 0).
    fn frame(&mut self, _frame: &Frame) {}
}

/// An observer that ignores everything.
#[derive(Debug, Default)]
pub struct Quiet;

impl Observer for Quiet {}

/// What a run produced: its summary, the probes recorded (kept when it diverged), the
/// final (or last good) particle state, and the divergence if any.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// `summary.json` content.
    pub summary: Summary,
    /// `probes.json` content.
    pub probes: ProbeRecord,
    /// Final particle state.
    pub final_frame: Frame,
    /// The divergence, if the run did not reach its end time.
    pub error: Option<SolverError>,
    /// When the run diverged: the particles at the start of the failing step (the last
    /// state that passed every guard), for `frames/last_good.vtu`.
    pub last_good: Option<Frame>,
    /// The particles at each of `output.snapshot_times` reached (a diverged run has the
    /// ones before the divergence).
    pub snapshots: Vec<Frame>,
}

impl RunReport {
    /// The run's outcome as DESIGN.md's `Result<Summary, SolverError>`.
    pub fn result(&self) -> Result<&Summary, &SolverError> {
        match &self.error {
            None => Ok(&self.summary),
            Some(e) => Err(e),
        }
    }
}

/// A simulation of dimension D, built from a scene: its scheme (a [`Method`]), the probes,
/// the guard and the last good state.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    scene: Scene,
    method: Box<dyn Method<D>>,
    probes: ProbeSet<D>,
    guard: Guard<D>,
    last_good: LastGood<D>,
    /// Steps after which the run stops short of its end time ([`Simulation::stop_after`]).
    max_steps: usize,
}

/// The particles at the start of the current step (copied into reused buffers: no
/// allocation once warm): what [`RunReport::last_good`] shows when a step fails.
#[derive(Debug, Default)]
struct LastGood<const D: usize> {
    step: usize,
    time: f64,
    saved: SavedState<D>,
}

/// A simulation of either dimension.
#[derive(Debug)]
pub enum AnySimulation {
    /// 2D.
    Two(Box<Simulation<2>>),
    /// 3D.
    Three(Box<Simulation<3>>),
}

impl AnySimulation {
    /// Builds the particles and the stage list of a (validated) scene.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        crate::scene::validate(scene)?;
        Ok(match scene.dimension {
            2 => AnySimulation::Two(Box::new(Simulation::<2>::new(scene)?)),
            _ => AnySimulation::Three(Box::new(Simulation::<3>::new(scene)?)),
        })
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        match self {
            AnySimulation::Two(s) => s.state().particles.len(),
            AnySimulation::Three(s) => s.state().particles.len(),
        }
    }

    /// Names of the stages of one step, in order.
    pub fn stage_names(&self) -> Vec<&'static str> {
        match self {
            AnySimulation::Two(s) => s.stage_names(),
            AnySimulation::Three(s) => s.stage_names(),
        }
    }

    /// Δt of the first step \[s\]: the scene's fixed step, or the scheme's stable step of the
    /// initial state. With the particle count it estimates what a run costs (about
    /// `particles × end / Δt₀` particle-steps) before it runs.
    pub fn first_step(&self) -> Result<f64, Cause> {
        match self {
            AnySimulation::Two(s) => s.time_step(f64::INFINITY),
            AnySimulation::Three(s) => s.time_step(f64::INFINITY),
        }
    }

    /// Makes [`AnySimulation::run`] stop after `steps` steps if the end time is not reached
    /// before (a truncated run; its last step is recorded like the end).
    pub fn stop_after(&mut self, steps: usize) {
        match self {
            AnySimulation::Two(s) => s.stop_after(steps),
            AnySimulation::Three(s) => s.stop_after(steps),
        }
    }

    /// Runs to the scene's end time.
    pub fn run(&mut self, observer: &mut dyn Observer) -> RunReport {
        match self {
            AnySimulation::Two(s) => s.run(observer),
            AnySimulation::Three(s) => s.run(observer),
        }
    }
}

/// Builds and runs `scene` (see [`AnySimulation`]).
pub fn run(scene: &Scene, observer: &mut dyn Observer) -> Result<RunReport, SceneError> {
    Ok(AnySimulation::new(scene)?.run(observer))
}

impl<const D: usize> Simulation<D> {
    /// Builds the particles and stages of `scene` (dimension must equal D) with the scheme
    /// the scene names.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        Ok(Self::from_built(scene, crate::registry::compose::<D>(scene)?))
    }

    /// Builds `scene` with the scheme `S`, whatever scheme the scene names (for schemes
    /// that are not in the registry, such as a test's).
    pub fn with_scheme<S: Scheme<D>>(scene: &Scene) -> Result<Self, SceneError> {
        Ok(Self::from_built(scene, crate::registry::compose_with::<D, S>(scene)?))
    }

    fn from_built(scene: &Scene, built: Built<D>) -> Self {
        let Built { method, weight, support } = built;
        let state = method.state();
        Self {
            scene: scene.clone(),
            guard: Guard::new(scene, state, support),
            probes: ProbeSet::new(&scene.probes, weight, scene.dx, state.domain, scene.fluid.surface_tension),
            method,
            last_good: LastGood::default(),
            max_steps: usize::MAX,
        }
    }

    /// The current state.
    pub fn state(&self) -> &State<D> {
        self.method.state()
    }

    /// The scheme with its state.
    pub fn method(&self) -> &dyn Method<D> {
        &*self.method
    }

    /// The scheme with its state, writable (tests and tools that perturb a run).
    pub fn method_mut(&mut self) -> &mut dyn Method<D> {
        &mut *self.method
    }

    /// Makes [`Simulation::run`] stop after `steps` steps if the end time is not reached
    /// before (a truncated run; its last step is recorded like the end).
    pub fn stop_after(&mut self, steps: usize) {
        self.max_steps = steps;
    }

    /// Names of the stages of one step, in order.
    pub fn stage_names(&self) -> Vec<&'static str> {
        (0..self.method.stage_count()).map(|i| self.method.stage_name(i)).collect()
    }

    /// Runs to the end time.
    ///
    /// The step loop runs on a worker thread of the current rayon pool, so the parallel
    /// loops of the stages start without a hand-over from an outside thread, and the
    /// pool's other threads are kept polling for work meanwhile ([`crate::warm_pool`]).
    pub fn run(&mut self, observer: &mut dyn Observer) -> RunReport {
        if rayon::current_thread_index().is_some() {
            crate::warm_pool::with_warm_workers(|| self.run_on_worker(observer))
        } else {
            rayon::scope(|_| crate::warm_pool::with_warm_workers(|| self.run_on_worker(observer)))
        }
    }

    fn run_on_worker(&mut self, observer: &mut dyn Observer) -> RunReport {
        let threads = rayon::current_num_threads();
        let t_end = self.scene.time.end;
        // Seconds per stage, then the guard's.
        let mut timings = vec![0.0; self.method.stage_count() + 1];
        let mut t_probes = 0.0;
        let mut record = ProbeRecord::default();
        let (mut t, mut step, mut ppe_iters) = (0.0, 0usize, 0usize);
        let every = self.scene.output.probe_every.max(1);
        let vtk_every = self.scene.output.vtk_every;
        let start = Instant::now();
        self.probes.record(self.method.state(), t, &mut record);
        if vtk_every > 0 {
            observer.frame(&self.frame(0, 0.0));
        }
        let (mut error, mut steady_at) = (None, None);
        // Requested probe times: steps are shortened to land on them.
        let targets = self.scene.output.probe_times.clone();
        let mut next = targets.iter().take_while(|&&s| s <= 0.0).count();
        // Requested snapshot times: steps land on them too.
        let snaps = self.scene.output.snapshot_times.clone();
        let mut snapshots = Vec::new();
        let mut next_snap = 0;
        let due = |next_snap: usize, t: f64| snaps.get(next_snap).is_some_and(|&s| s <= t + 1e-12 * t_end);
        while due(next_snap, t) {
            snapshots.push(self.frame(step, t));
            next_snap += 1;
        }
        while t < t_end * (1.0 - 1e-12) && step < self.max_steps {
            self.keep_last_good(step, t);
            let probe_stop = targets.get(next).copied().filter(|&s| s < t_end).unwrap_or(t_end);
            let snap_stop = snaps.get(next_snap).copied().filter(|&s| s < t_end).unwrap_or(t_end);
            let stop = probe_stop.min(snap_stop);
            let dt = match self.time_step(stop - t) {
                Ok(dt) => dt,
                Err(cause) => {
                    error = Some(SolverError { stage: "time_step", step: step + 1, time: t, cause });
                    break;
                }
            };
            let ctx = StepContext { step: step + 1, time: t, dt };
            if let Err(e) = self.advance(&ctx, &mut timings) {
                error = Some(e);
                break;
            }
            ppe_iters += self.method.state().solve.iterations;
            step += 1;
            let landed = (stop - (t + dt)).abs() <= 1e-12 * t_end;
            t = if landed { stop } else { t + dt };
            let last = t >= t_end * (1.0 - 1e-12) || step >= self.max_steps;
            // A probe time is hit when the step landed on it (not on a snapshot time before it).
            let hit = landed && !last && probe_stop <= snap_stop;
            if hit {
                next += 1;
            }
            while due(next_snap, t) {
                snapshots.push(self.frame(step, t));
                next_snap += 1;
            }
            let mut steady = false;
            if step % every == 0 || last || hit {
                let s0 = Instant::now();
                self.probes.record(self.method.state(), t, &mut record);
                steady = !last && self.scene.time.steady.as_ref().is_some_and(|s| is_steady(s, &record));
                t_probes += s0.elapsed().as_secs_f64();
            }
            if vtk_every > 0 && (step % vtk_every == 0 || last) {
                observer.frame(&self.frame(step, t));
            }
            observer.progress(step, t, t_end);
            if steady {
                steady_at = Some(t);
                if vtk_every > 0 && step % vtk_every != 0 {
                    observer.frame(&self.frame(step, t));
                }
                break;
            }
        }
        let wall_s = start.elapsed().as_secs_f64();
        let mut stages = BTreeMap::new();
        for (i, time) in timings[..timings.len() - 1].iter().enumerate() {
            *stages.entry(self.method.stage_name(i).to_string()).or_insert(0.0) += time;
        }
        stages.insert("probes".into(), t_probes);
        stages.insert("guard".into(), timings[timings.len() - 1]);
        let summary = Summary {
            scene: self.scene.name.clone(),
            particles: self.method.state().particles.len(),
            steps: step,
            t_end: t,
            wall_s,
            status: if error.is_some() { Status::Diverged } else { Status::Ok },
            error: error.as_ref().map(|e| e.to_string()),
            stages,
            threads,
            ppe_iterations_mean: ppe_iters as f64 / step.max(1) as f64,
            steady_at,
        };
        let last_good = error.as_ref().map(|_| self.last_good_frame());
        RunReport { summary, probes: record, final_frame: self.frame(step, t), error, last_good, snapshots }
    }

    /// One step `ctx` as the driver and the profiler take it: every stage of the scheme,
    /// then the guard. `timings` (one entry per stage, then the guard's) accumulates the
    /// seconds each took.
    pub(crate) fn advance(&mut self, ctx: &StepContext, timings: &mut [f64]) -> Result<(), SolverError> {
        let n = self.method.stage_count();
        for (i, time) in timings[..n].iter_mut().enumerate() {
            let s0 = Instant::now();
            let r = self.method.run_stage(i, ctx);
            *time += s0.elapsed().as_secs_f64();
            if let Err(cause) = r {
                return Err(SolverError {
                    stage: self.method.stage_name(i),
                    step: ctx.step,
                    time: ctx.time,
                    cause,
                });
            }
        }
        let s0 = Instant::now();
        let guard = self.guard.check(self.method.state(), ctx.time + ctx.dt, ctx.dt);
        timings[n] += s0.elapsed().as_secs_f64();
        guard.map_err(|cause| SolverError { stage: "guard", step: ctx.step, time: ctx.time, cause })
    }

    /// Δt of the next step, never past `remaining` (the time to the end or to the next
    /// requested probe time): the fixed step, or the scheme's stable step (Qiu eqs.
    /// 17–19), which may not fall below 1e-9 of the end time. A remainder between one and
    /// two steps is split in halves, so that landing on a target never takes a step much
    /// shorter than the others: the density terms of the projection schemes' sources
    /// (ISPH's density relaxation, MPS's mixed source, both over Δt²) turn a sliver of a
    /// step into a pressure spike (docs/notes/mps.md, the channel at Re 4).
    pub(crate) fn time_step(&self, remaining: f64) -> Result<f64, Cause> {
        let dt = match self.scene.time.step {
            TimeStep::Fixed(dt) => dt,
            TimeStep::Adaptive { cfl, viscous, max } => {
                let dt = self.method.stable_step(Adaptive { cfl, viscous, max });
                let floor = 1e-9 * self.scene.time.end;
                if dt < floor {
                    return Err(Cause::DtFloor { dt, floor });
                }
                dt
            }
        };
        // Never more than Δt; a remainder within rounding of Δt is taken whole.
        Ok(if remaining <= dt * (1.0 + 1e-9) {
            remaining
        } else if remaining < 2.0 * dt {
            0.5 * remaining
        } else {
            dt
        })
    }

    /// The end-of-step guard at `time` after a step of `dt` \[s\] ([`Guard::check`]).
    pub(crate) fn guard(&self, time: f64, dt: f64) -> Result<(), Cause> {
        self.guard.check(self.method.state(), time, dt)
    }

    /// Copies the particles into the last-good buffers (called before every step).
    fn keep_last_good(&mut self, step: usize, time: f64) {
        let keep = &mut self.last_good;
        keep.step = step;
        keep.time = time;
        // The fluid only (boundary particles are rebuilt or extrapolated every step).
        self.method.save(&mut keep.saved, Extent::Output(self.method.state().particles.fluid));
    }

    /// The particles at the start of the step being taken (the last state that passed
    /// every guard), in initial-id order.
    fn last_good_frame(&self) -> Frame {
        let k = &self.last_good;
        Frame::of(k.step, k.time, k.saved.fluid(), |f| self.method.visit_fields(Some(&k.saved), f))
    }

    /// The particles in initial-id order.
    pub fn frame(&self, step: usize, time: f64) -> Frame {
        Frame::of(step, time, self.state().particles.fluid, |f| self.method.visit_fields(None, f))
    }
}

#[cfg(test)]
mod guard_tests {
    use super::*;

    fn small_drop() -> Simulation<2> {
        let text = include_str!("../../../validation/scenes/elliptical_drop.json");
        let mut scene = Scene::from_json(text).expect("DESIGN scene");
        scene.dx = 0.1;
        Simulation::<2>::new(&scene).expect("builds")
    }

    /// Runs the neighbour-search stage of a simulation.
    fn search_neighbours(sim: &mut Simulation<2>, ctx: &StepContext) -> Result<(), Cause> {
        let m = sim.method_mut();
        let i = (0..m.stage_count()).find(|&i| m.stage_name(i) == "neighbours").expect("a neighbour stage");
        m.run_stage(i, ctx)
    }

    #[test]
    fn clumped_particles_trip_the_neighbour_guard() {
        let mut sim = small_drop();
        let ctx = StepContext { step: 1, time: 0.0, dt: 1e-5 };
        search_neighbours(&mut sim, &ctx).expect("neighbour search");
        assert_eq!(sim.guard(0.0, 0.0), Ok(()), "the initial lattice is within the band");
        // Squeeze the drop to a third of its size: every interior particle now has about
        // 9 × 28 neighbours.
        for x in &mut sim.method_mut().state_mut().particles.x {
            *x /= 3.0;
        }
        search_neighbours(&mut sim, &ctx).expect("neighbour search");
        let cause = sim.guard(0.0, 0.0).expect_err("clumping must trip the guard");
        let Cause::Clumping { count, limit, bulk, others, .. } = &cause else { panic!("{cause}") };
        assert!(count > limit && *limit == 112 && *bulk == 28 && *others > 10, "{cause}");
        let msg = cause.to_string();
        assert!(msg.contains("neighbours") && msg.contains("clumping"), "{msg}");
    }

    #[test]
    fn guard_reports_the_most_severe_failure_with_the_lowest_id() {
        let mut sim = small_drop();
        let ctx = StepContext { step: 1, time: 0.0, dt: 1e-5 };
        search_neighbours(&mut sim, &ctx).expect("neighbour search");
        let n = sim.state().particles.len();
        let at =
            |sim: &Simulation<2>, id: u32| sim.state().particles.id.iter().position(|&i| i == id).unwrap();
        let (a, b, c) = (at(&sim, 7), at(&sim, 3), at(&sim, (n - 1) as u32));
        sim.method_mut().state_mut().particles.x[a][0] = 1e6;
        sim.method_mut().state_mut().particles.x[b][1] = -1e6;
        sim.method_mut().state_mut().particles.p[c] = f64::NAN;
        match sim.guard(0.0, 0.0) {
            Err(Cause::NonFinite { quantity: "pressure", particle, others: 0 }) => {
                assert_eq!(particle, n - 1)
            }
            other => panic!("{other:?}"),
        }
        sim.method_mut().state_mut().particles.p[c] = 0.0;
        let cause = sim.guard(0.0, 0.0).expect_err("escape");
        assert!(matches!(cause, Cause::Escape { particle: 3, others: 1, .. }), "{cause}");
        let msg = cause.to_string();
        assert!(
            msg.starts_with("particle 3 escaped to (") && msg.contains("(and 1 other particle)"),
            "{msg}"
        );
    }
}
