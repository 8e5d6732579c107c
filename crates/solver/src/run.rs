//! The run driver: builds the simulation from a scene, steps it to the end time, guards
//! every step, records probes, and returns a report (DESIGN.md "Run outputs").

use crate::error::{Cause, SceneError, SolverError};
use crate::kernel::{CubicSpline, Kernel, Scaled, WendlandC2};
use crate::neighbours::Domain;
use crate::probes::{ProbeRecord, ProbeSet, Weight};
use crate::scene::{KernelKind, Role, Scene, Scheme, TimeStep, lattice};
use crate::stage::{Stage, StepContext};
use crate::state::{Particles, State, Vector};
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
    /// `ok` or `diverged`.
    pub status: String,
    /// The divergence message, when diverged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Seconds spent in each stage.
    pub stages: BTreeMap<String, f64>,
    /// Rayon threads used.
    pub threads: usize,
    /// Mean PPE iterations per step.
    pub ppe_iterations_mean: f64,
}

/// A particle snapshot in initial-id order, for VTK frames and final-state metrics.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Frame {
    /// Step number.
    pub step: usize,
    /// Time \[s\].
    pub time: f64,
    /// Positions \[m\] (3 components; z = 0 in 2D).
    pub x: Vec<[f64; 3]>,
    /// Velocities \[m/s\].
    pub u: Vec<[f64; 3]>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
    /// Free-surface flags.
    pub free_surface: Vec<bool>,
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

/// A simulation of dimension D, built from a scene.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    scene: Scene,
    pub(crate) state: State<D>,
    pub(crate) stages: Vec<Box<dyn Stage<D>>>,
    probes: ProbeSet<D>,
    bounds: (Vector<D>, Vector<D>),
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
            AnySimulation::Two(s) => s.state.particles.len(),
            AnySimulation::Three(s) => s.state.particles.len(),
        }
    }

    /// Names of the stages of one step, in order.
    pub fn stage_names(&self) -> Vec<&'static str> {
        match self {
            AnySimulation::Two(s) => s.stages.iter().map(|st| st.name()).collect(),
            AnySimulation::Three(s) => s.stages.iter().map(|st| st.name()).collect(),
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
    /// Builds the particles and stages of `scene` (dimension must equal D).
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        let g = Vector::<D>::from_fn(|i, _| scene.body_force.get(i).copied().unwrap_or(0.0));
        let mut particles = Particles::<D>::default();
        for (i, body) in scene.bodies.iter().enumerate() {
            if body.role == Role::Wall {
                return Err(SceneError::new(
                    format!("bodies[{i}].role"),
                    "wall",
                    "wall bodies are not supported yet by the ISPH runner",
                ));
            }
            for seed in lattice::seed_body::<D>(body, scene.dx, scene.fluid.density, &g) {
                particles.id.push(particles.x.len() as u32);
                particles.x.push(seed.x);
                particles.u.push(seed.u);
                particles.p.push(seed.p);
            }
        }
        if particles.is_empty() {
            return Err(SceneError::new("bodies", scene.bodies.len(), "hold no particle"));
        }
        let mut domain = Domain::<D>::default();
        for axis in &scene.boundaries.periodic {
            domain.periodic[axis.axis] = Some((axis.min, axis.max));
        }
        for x in &mut particles.x {
            domain.wrap(x);
        }
        let mut lo = Vector::<D>::repeat(f64::INFINITY);
        let mut hi = Vector::<D>::repeat(f64::NEG_INFINITY);
        for x in &particles.x {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let margin = 4.0 * (hi - lo).max().max(10.0 * scene.dx);
        let bounds = (lo.add_scalar(-margin), hi.add_scalar(margin));
        let h = scene.h();
        let n = particles.len();
        let state = State {
            particles,
            x_old: Vec::with_capacity(n),
            u_old: Vec::with_capacity(n),
            neighbours: Default::default(),
            pairs: Vec::new(),
            div_r: vec![0.0; n],
            free_surface: vec![false; n],
            volume: scene.dx.powi(D as i32),
            density: scene.fluid.density,
            dx: scene.dx,
            h,
            domain,
            ppe: Default::default(),
        };
        let (stages, weight) = match scene.kernel.kind {
            KernelKind::CubicSpline => build::<CubicSpline, D>(scene, h, domain),
            KernelKind::WendlandC2 => build::<WendlandC2, D>(scene, h, domain),
        };
        Ok(Self {
            scene: scene.clone(),
            state,
            stages,
            probes: ProbeSet::new(&scene.probes, weight, scene.dx, domain),
            bounds,
        })
    }

    /// The current state.
    pub fn state(&self) -> &State<D> {
        &self.state
    }

    /// Runs to the end time.
    ///
    /// The step loop runs on a worker thread of the current rayon pool, so the parallel
    /// loops of the stages start without a hand-over from an outside thread (measured:
    /// 12 % of a single-thread run went to futex waits before).
    pub fn run(&mut self, observer: &mut dyn Observer) -> RunReport {
        if rayon::current_thread_index().is_some() {
            self.run_on_worker(observer)
        } else {
            rayon::scope(|_| self.run_on_worker(observer))
        }
    }

    fn run_on_worker(&mut self, observer: &mut dyn Observer) -> RunReport {
        let threads = rayon::current_num_threads();
        let t_end = self.scene.time.end;
        let mut timings = vec![0.0; self.stages.len()];
        let (mut t_probes, mut t_guard) = (0.0, 0.0);
        let mut record = ProbeRecord::default();
        let (mut t, mut step, mut ppe_iters) = (0.0, 0usize, 0usize);
        let every = self.scene.output.probe_every.max(1);
        let vtk_every = self.scene.output.vtk_every;
        let start = Instant::now();
        self.probes.record(&self.state, t, &mut record);
        if vtk_every > 0 {
            observer.frame(&self.frame(0, 0.0));
        }
        let mut error = None;
        while t < t_end * (1.0 - 1e-12) {
            let dt = match self.time_step(t_end - t) {
                Ok(dt) => dt,
                Err(cause) => {
                    error = Some(SolverError { stage: "time_step", step: step + 1, time: t, cause });
                    break;
                }
            };
            let ctx = StepContext { step: step + 1, time: t, dt };
            for (stage, time) in self.stages.iter_mut().zip(timings.iter_mut()) {
                let s0 = Instant::now();
                let r = stage.run(&mut self.state, &ctx);
                *time += s0.elapsed().as_secs_f64();
                if let Err(cause) = r {
                    error = Some(SolverError { stage: stage.name(), step: ctx.step, time: t, cause });
                    break;
                }
            }
            if error.is_some() {
                break;
            }
            ppe_iters += self.state.ppe.info.iterations;
            let s0 = Instant::now();
            let guard = self.guard();
            t_guard += s0.elapsed().as_secs_f64();
            if let Err(cause) = guard {
                error = Some(SolverError { stage: "guard", step: ctx.step, time: t, cause });
                break;
            }
            step += 1;
            t = if (t_end - (t + dt)).abs() <= 1e-12 * t_end { t_end } else { t + dt };
            let last = t >= t_end * (1.0 - 1e-12);
            if step % every == 0 || last {
                let s0 = Instant::now();
                self.probes.record(&self.state, t, &mut record);
                t_probes += s0.elapsed().as_secs_f64();
            }
            if vtk_every > 0 && (step % vtk_every == 0 || last) {
                observer.frame(&self.frame(step, t));
            }
            observer.progress(step, t, t_end);
        }
        let wall_s = start.elapsed().as_secs_f64();
        let mut stages = BTreeMap::new();
        for (stage, time) in self.stages.iter().zip(&timings) {
            *stages.entry(stage.name().to_string()).or_insert(0.0) += time;
        }
        stages.insert("probes".into(), t_probes);
        stages.insert("guard".into(), t_guard);
        let summary = Summary {
            scene: self.scene.name.clone(),
            particles: self.state.particles.len(),
            steps: step,
            t_end: t,
            wall_s,
            status: if error.is_some() { "diverged".into() } else { "ok".into() },
            error: error.as_ref().map(|e| e.to_string()),
            stages,
            threads,
            ppe_iterations_mean: ppe_iters as f64 / step.max(1) as f64,
        };
        RunReport { summary, probes: record, final_frame: self.frame(step, t), error }
    }

    /// Δt of the next step, never past `remaining` (Qiu eqs. 17–19 when adaptive).
    pub(crate) fn time_step(&self, remaining: f64) -> Result<f64, Cause> {
        let dt = match self.scene.time.step {
            TimeStep::Fixed(dt) => dt,
            TimeStep::Adaptive { cfl, viscous, max } => {
                let h = self.state.h;
                let u = self.state.max_speed();
                let mut dt = max;
                if u > 0.0 {
                    dt = dt.min(cfl * h / u);
                }
                let mu = self.scene.fluid.viscosity;
                if mu > 0.0 {
                    dt = dt.min(viscous * self.state.density * h * h / mu);
                }
                let floor = 1e-9 * self.scene.time.end;
                if dt < floor {
                    return Err(Cause::DtFloor { dt, floor });
                }
                dt
            }
        };
        // Never more than Δt; a remainder within rounding of Δt is taken whole.
        Ok(if remaining <= dt * (1.0 + 1e-9) { remaining } else { dt })
    }

    /// End-of-step checks: finite values, no particle escaped.
    pub(crate) fn guard(&self) -> Result<(), Cause> {
        let p = &self.state.particles;
        let (lo, hi) = &self.bounds;
        let bad = |a: usize| -> Option<Cause> {
            if !p.x[a].iter().all(|v| v.is_finite()) {
                return Some(Cause::NonFinite { quantity: "position", particle: p.id[a] as usize });
            }
            if !p.u[a].iter().all(|v| v.is_finite()) {
                return Some(Cause::NonFinite { quantity: "velocity", particle: p.id[a] as usize });
            }
            if !p.p[a].is_finite() {
                return Some(Cause::NonFinite { quantity: "pressure", particle: p.id[a] as usize });
            }
            if (0..D).any(|k| p.x[a][k] < lo[k] || p.x[a][k] > hi[k]) {
                return Some(Cause::Escape {
                    particle: p.id[a] as usize,
                    position: p.x[a].iter().copied().collect(),
                });
            }
            None
        };
        use rayon::prelude::*;
        let first = (0..p.len()).into_par_iter().filter(|&a| bad(a).is_some()).min_by_key(|&a| p.id[a]);
        match first.and_then(bad) {
            Some(c) => Err(c),
            None => Ok(()),
        }
    }

    /// The particles in initial-id order.
    pub fn frame(&self, step: usize, time: f64) -> Frame {
        let p = &self.state.particles;
        let n = p.len();
        let mut f = Frame {
            step,
            time,
            x: vec![[0.0; 3]; n],
            u: vec![[0.0; 3]; n],
            p: vec![0.0; n],
            free_surface: vec![false; n],
        };
        for a in 0..n {
            let i = p.id[a] as usize;
            for k in 0..D.min(3) {
                f.x[i][k] = p.x[a][k];
                f.u[i][k] = p.u[a][k];
            }
            f.p[i] = p.p[a];
            f.free_surface[i] = self.state.free_surface.get(a).copied().unwrap_or(false);
        }
        f
    }
}

fn build<K: Kernel, const D: usize>(
    scene: &Scene,
    h: f64,
    domain: Domain<D>,
) -> (Vec<Box<dyn Stage<D>>>, Weight) {
    let kernel = Scaled::<K, D>::new(h);
    let stages = match &scene.scheme {
        Scheme::Isph(opts) => crate::isph::build_stages::<K, D>(scene, opts, kernel, domain),
    };
    (stages, Weight { w: Box::new(move |r| kernel.w(r)), support: kernel.support })
}
