//! The run driver: builds the simulation from a scene, steps it to the end time, guards
//! every step, records probes, and returns a report (DESIGN.md "Run outputs").

use crate::error::{Cause, SceneError, SolverError};
use crate::kernel::{CubicSpline, Kernel, Scaled, WendlandC2};
use crate::neighbours::Domain;
use crate::probes::{ProbeRecord, ProbeSet, Weight};
use crate::scene::{KernelKind, Role, Scene, Scheme, TimeStep, WallModel, lattice};
use crate::stage::{Stage, StepContext};
use crate::stages::dummy::dummy_layers;
use crate::stages::open_boundary::{OpenSetup, Openings};
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

/// A particle snapshot in initial-id order, for VTK frames, final-state metrics and the
/// snapshots of `output.snapshot_times`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
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

/// α_f of the weakly compressible scheme's force limit `Δt ≤ α_f √(h/|a|_max)` (Monaghan
/// 1992, Annu. Rev. Astron. Astrophys. 30:543, §10).
const WCSPH_FORCE_LIMIT: f64 = 0.25;

/// Coefficient of the capillary time-step limit `Δt ≤ 0.25 √(ρ h³/(2π σ))` (Brackbill,
/// Kothe & Zemach 1992 eq. 63; Morris 2000), applied to both schemes when σ > 0.
const CAPILLARY_LIMIT: f64 = 0.25;

/// A simulation of dimension D, built from a scene.
#[derive(Debug)]
pub struct Simulation<const D: usize> {
    scene: Scene,
    pub(crate) state: State<D>,
    pub(crate) stages: Vec<Box<dyn Stage<D>>>,
    probes: ProbeSet<D>,
    guard_box: GuardBox<D>,
    /// Kernel support radius \[m\]: no particle may move farther in one step.
    support: f64,
    neighbour_band: NeighbourBand,
    last_good: LastGood<D>,
}

/// The upper bound of the neighbour-count guard.
///
/// A particle of the initial lattice has `bulk` neighbours within the kernel support: the
/// lattice points `z Δx`, `z ∈ ℤ^D \ {0}`, with `|z| Δx` up to the support (the shell on the
/// support included, as rounding may put it inside): 28 for h = 1.5 Δx in 2D. In an
/// incompressible flow the particle number density stays near its initial value, so a
/// fluid particle with more than `4 × bulk` neighbours
/// means the local spacing has shrunk to half of Δx in 2D (0.63 Δx in 3D): particles are
/// clumping or penetrating each other, which precedes a blow-up (and makes the neighbour
/// lists grow without bound). Zero neighbours is allowed: an isolated splash particle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct NeighbourBand {
    bulk: usize,
    limit: usize,
}

impl NeighbourBand {
    /// The band for kernel `support` \[m\] on a lattice of spacing `dx` in D dimensions.
    fn new<const D: usize>(support: f64, dx: f64) -> Self {
        let r = support / dx;
        let n = r.ceil() as i64;
        let mut bulk = 0usize;
        let mut idx = [-n; D];
        'all: loop {
            let r2: i64 = idx.iter().map(|i| i * i).sum();
            if r2 > 0 && (r2 as f64).sqrt() <= r * (1.0 + 1e-9) {
                bulk += 1;
            }
            for i in idx.iter_mut() {
                if *i < n {
                    *i += 1;
                    continue 'all;
                }
                *i = -n;
            }
            break;
        }
        Self { bulk, limit: 4 * bulk.max(1) }
    }
}

/// The particles at the start of the current step, copied into reused buffers (no
/// allocation once warm): what [`RunReport::last_good`] shows when a step fails.
#[derive(Debug, Clone, Default)]
struct LastGood<const D: usize> {
    step: usize,
    time: f64,
    particles: Particles<D>,
    free_surface: Vec<bool>,
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
        let mut body_start = Vec::with_capacity(scene.bodies.len());
        for (i, body) in scene.bodies.iter().enumerate() {
            body_start.push(particles.x.len());
            if body.role == Role::Wall {
                return Err(SceneError::new(
                    format!("bodies[{i}].role"),
                    "wall",
                    "wall bodies are not supported yet by the ISPH runner",
                ));
            }
            for seed in lattice::seed_body::<D>(body, scene.dx, scene.fluid.density, &g) {
                particles.fluid += 1;
                particles.id.push(particles.x.len() as u32);
                particles.x.push(seed.x);
                particles.u.push(seed.u);
                particles.p.push(seed.p);
            }
        }
        if particles.is_empty() {
            return Err(SceneError::new("bodies", scene.bodies.len(), "hold no particle"));
        }
        for (i, wall) in scene.boundaries.walls.iter().enumerate() {
            let side = if wall.fluid_side == crate::scene::Side::Above { 1.0 } else { -1.0 };
            if let Some(x) = particles.x.iter().find(|x| side * (x[wall.axis] - wall.position) <= 0.0) {
                return Err(SceneError::new(
                    format!("boundaries.walls[{i}].position"),
                    wall.position,
                    format!("leaves fluid particles behind the wall (one at {:?})", x.as_slice()),
                ));
            }
        }
        let mut domain = Domain::<D>::default();
        for axis in &scene.boundaries.periodic {
            domain.periodic[axis.axis] = Some((axis.min, axis.max));
        }
        for x in &mut particles.x {
            domain.wrap(x);
        }
        check_seeds(&particles, &body_start, scene.dx, domain)?;
        for (i, body) in scene.bodies.iter().enumerate() {
            if let Some(jitter) = &body.jitter {
                let end = body_start.get(i + 1).copied().unwrap_or(particles.fluid);
                lattice::apply_jitter(&mut particles.x[body_start[i]..end], scene.dx, jitter);
            }
        }
        for x in &mut particles.x {
            domain.wrap(x);
        }
        let h = scene.h();
        let support = match scene.kernel.kind {
            KernelKind::CubicSpline => Scaled::<CubicSpline, D>::new(h).support,
            KernelKind::WendlandC2 => Scaled::<WendlandC2, D>::new(h).support,
        };
        let open = match (&scene.boundaries.inflow, &scene.boundaries.outflow) {
            (Some(i), Some(o)) => {
                let openings = Openings::new(i, o, scene.dx, support);
                let (inlet, link) = openings.seed(&mut particles)?;
                Some(OpenSetup { openings, inlet, next_id: particles.fluid as u32, link })
            }
            _ => None,
        };
        let buffer = particles.total() - particles.fluid;
        if scene.boundaries.wall_model == WallModel::Dummy && !scene.boundaries.walls.is_empty() {
            let depth = 2.0 * scene.h();
            for x in dummy_layers(&scene.boundaries.walls, &domain, &particles.x, scene.dx, depth) {
                particles.x.push(x);
                particles.u.push(Vector::zeros());
                particles.p.push(0.0);
            }
        }
        let mut lo = Vector::<D>::repeat(f64::INFINITY);
        let mut hi = Vector::<D>::repeat(f64::NEG_INFINITY);
        for x in &particles.x {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let guard_box = GuardBox::new(scene, &particles.u, lo, hi);
        let n = particles.len();
        let state = State {
            particles,
            x_old: Vec::with_capacity(n),
            u_old: Vec::with_capacity(n),
            neighbours: Default::default(),
            pairs: Vec::new(),
            div_r: vec![0.0; n],
            free_surface: vec![false; n],
            particle_density: Vec::new(),
            volume: scene.dx.powi(D as i32),
            density: scene.fluid.density,
            dx: scene.dx,
            h,
            domain,
            ppe: Default::default(),
            mirrors: Default::default(),
            buffer,
            flux: Default::default(),
            inlet: open.as_ref().map(|o| o.link.clone()).unwrap_or_default(),
            wc: Default::default(),
        };
        let (stages, weight) = match scene.kernel.kind {
            KernelKind::CubicSpline => build::<CubicSpline, D>(scene, h, domain, open.as_ref()),
            KernelKind::WendlandC2 => build::<WendlandC2, D>(scene, h, domain, open.as_ref()),
        };
        let neighbour_band = NeighbourBand::new::<D>(weight.support, scene.dx);
        Ok(Self {
            scene: scene.clone(),
            state,
            stages,
            probes: ProbeSet::new(&scene.probes, weight, scene.dx, domain),
            guard_box,
            support,
            neighbour_band,
            last_good: LastGood::default(),
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
    /// 12 % of a single-thread run went to futex waits before), and the pool's other
    /// threads are kept polling for work meanwhile ([`crate::warm_pool`]).
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
        while t < t_end * (1.0 - 1e-12) {
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
            let guard = self.guard(t + dt, dt);
            t_guard += s0.elapsed().as_secs_f64();
            if let Err(cause) = guard {
                error = Some(SolverError { stage: "guard", step: ctx.step, time: t, cause });
                break;
            }
            step += 1;
            let landed = (stop - (t + dt)).abs() <= 1e-12 * t_end;
            t = if landed { stop } else { t + dt };
            let last = t >= t_end * (1.0 - 1e-12);
            // A probe time is hit when the step landed on it (not on a snapshot time before it).
            let hit = landed && !last && probe_stop <= snap_stop;
            if hit {
                next += 1;
            }
            while due(next_snap, t) {
                snapshots.push(self.frame(step, t));
                next_snap += 1;
            }
            if step % every == 0 || last || hit {
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
            status: if error.is_some() { Status::Diverged } else { Status::Ok },
            error: error.as_ref().map(|e| e.to_string()),
            stages,
            threads,
            ppe_iterations_mean: ppe_iters as f64 / step.max(1) as f64,
        };
        let last_good = error.as_ref().map(|_| self.last_good_frame());
        RunReport { summary, probes: record, final_frame: self.frame(step, t), error, last_good, snapshots }
    }

    /// Δt of the next step, never past `remaining` (the time to the end or to the next
    /// requested probe time; Qiu eqs. 17–19 when adaptive).
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
                match &self.scene.scheme {
                    Scheme::Isph(opts) => {
                        if mu > 0.0 && opts.viscosity == crate::scene::ViscousIntegration::Explicit {
                            // The Monaghan–Cleary operator acts along r̂_ab with weight
                            // 2(D+2) against Shao–Lo's 2 on all components: its largest
                            // eigenvalue is (D+2)/D times larger, so its stable step smaller.
                            let stiffness = match opts.viscous_operator {
                                crate::scene::ViscousOperator::ShaoLo
                                | crate::scene::ViscousOperator::Consistent => 1.0,
                                crate::scene::ViscousOperator::MonaghanCleary => (D as f64 + 2.0) / D as f64,
                            };
                            dt = dt.min(viscous * self.state.density * h * h / (mu * stiffness));
                        }
                    }
                    Scheme::Wcsph(opts) => {
                        // Monaghan 1992 §10: the sound speed enters the CFL; force limit.
                        dt = dt.min(cfl * h / (opts.sound_speed + u));
                        if mu > 0.0 {
                            dt = dt.min(viscous * self.state.density * h * h / mu);
                        }
                        let a =
                            self.state.wc.accel.iter().map(|a| a.norm_squared()).fold(0.0, f64::max).sqrt();
                        if a > 0.0 {
                            dt = dt.min(WCSPH_FORCE_LIMIT * (h / a).sqrt());
                        }
                    }
                }
                let sigma = self.scene.fluid.surface_tension;
                if sigma > 0.0 {
                    // Capillary waves (Brackbill, Kothe & Zemach 1992 eq. 63; Morris 2000).
                    dt = dt.min(
                        CAPILLARY_LIMIT
                            * (self.state.density * h * h * h / (2.0 * std::f64::consts::PI * sigma)).sqrt(),
                    );
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

    /// End-of-step checks, in this order of precedence: every position, velocity and
    /// pressure is finite; no particle left the [`GuardBox`] at `time` \[s\]; no two fluid
    /// neighbours move farther than the kernel support relative to each other in a step of
    /// `dt` \[s\] (the neighbour lists could not follow them: a fixed step far beyond the
    /// CFL limit; Galilean invariant, so a fast but rigid motion passes); no fluid particle has more neighbours than the
    /// [`NeighbourBand`] allows. The cause names the lowest particle id that failed the
    /// most severe check and how many others failed it too.
    pub(crate) fn guard(&self, time: f64, dt: f64) -> Result<(), Cause> {
        use rayon::prelude::*;
        let p = &self.state.particles;
        let (lo, hi) = &self.guard_box.at(time);
        let list = &self.state.neighbours;
        // Rows 0..fluid are the fluid's (dummy walls add rows after them).
        let counted = list.len() >= p.len();
        let limit = self.neighbour_band.limit;
        let support = self.support;
        // Two fluid particles approach at most at twice the largest speed: when even that
        // cannot cover the support in one step (always at the start of an adaptive step,
        // cfl ≤ 1), the pair scan for an overstep is skipped.
        let scan_pairs = 2.0 * self.state.max_speed() * dt > support;
        // Severity of particle a's failure (0 = none), most severe first.
        let severity = |a: usize| -> u8 {
            if !p.x[a].iter().all(|v| v.is_finite()) {
                6
            } else if !p.u[a].iter().all(|v| v.is_finite()) {
                5
            } else if !p.p[a].is_finite() {
                4
            } else if (0..D).any(|k| p.x[a][k] < lo[k] || p.x[a][k] > hi[k]) {
                3
            } else if scan_pairs
                && a < list.len()
                && list.of(a).iter().any(|&b| {
                    (b as usize) < p.len()
                        && (p.u[a] - p.u[b as usize]).norm_squared() * dt * dt > support * support
                })
            {
                2
            } else if counted && list.of(a).len() > limit {
                1
            } else {
                0
            }
        };
        // (severity, id of the first particle, particles with that severity)
        let worst =
            (0..p.len()).into_par_iter().map(|a| (severity(a), p.id[a], 1usize)).filter(|w| w.0 > 0).reduce(
                || (0, u32::MAX, 0),
                |x, y| match x.0.cmp(&y.0) {
                    std::cmp::Ordering::Greater => x,
                    std::cmp::Ordering::Less => y,
                    std::cmp::Ordering::Equal => (x.0, x.1.min(y.1), x.2 + y.2),
                },
            );
        let (level, id, n) = worst;
        if level == 0 {
            return Ok(());
        }
        let a = (0..p.len()).find(|&a| p.id[a] == id).unwrap_or(0);
        let (particle, others) = (id as usize, n - 1);
        let vec = |v: &Vector<D>| v.iter().copied().collect::<Vec<f64>>();
        Err(match level {
            6 => Cause::NonFinite { quantity: "position", particle, others },
            5 => Cause::NonFinite { quantity: "velocity", particle, others },
            4 => Cause::NonFinite { quantity: "pressure", particle, others },
            3 => Cause::Escape { particle, position: vec(&p.x[a]), lo: vec(lo), hi: vec(hi), others },
            2 => {
                let speed = |b: &u32| (p.u[a] - p.u[*b as usize]).norm();
                let fluid = list.of(a).iter().copied().filter(|&b| (b as usize) < p.len());
                let b = fluid.max_by(|b, c| speed(b).total_cmp(&speed(c))).unwrap_or(0);
                Cause::Overstep {
                    particle,
                    position: vec(&p.x[a]),
                    neighbour: p.id[b as usize] as usize,
                    speed: speed(&b),
                    dt,
                    support,
                    others,
                }
            }
            _ => Cause::Clumping {
                particle,
                position: vec(&p.x[a]),
                count: list.of(a).len(),
                limit,
                bulk: self.neighbour_band.bulk,
                others,
            },
        })
    }

    /// Copies the particles into the last-good buffers (called before every step).
    fn keep_last_good(&mut self, step: usize, time: f64) {
        let (keep, p) = (&mut self.last_good, &self.state.particles);
        keep.step = step;
        keep.time = time;
        // The fluid only (boundary particles are rebuilt or extrapolated every step).
        let nf = p.fluid;
        keep.particles.fluid = nf;
        keep.particles.id.clone_from(&p.id);
        for (dst, src) in [(&mut keep.particles.x, &p.x), (&mut keep.particles.u, &p.u)] {
            dst.clear();
            dst.extend_from_slice(&src[..nf]);
        }
        keep.particles.p.clear();
        keep.particles.p.extend_from_slice(&p.p[..nf]);
        keep.free_surface.clone_from(&self.state.free_surface);
    }

    /// The particles at the start of the step being taken (the last state that passed
    /// every guard), in initial-id order.
    fn last_good_frame(&self) -> Frame {
        let k = &self.last_good;
        frame_of(&k.particles, &k.free_surface, k.step, k.time)
    }

    /// The particles in initial-id order.
    pub fn frame(&self, step: usize, time: f64) -> Frame {
        frame_of(&self.state.particles, &self.state.free_surface, step, time)
    }
}

/// The fluid of `particles` (with their free-surface flags) in id order (initial order;
/// particles that entered through an inlet follow in order of entry).
fn frame_of<const D: usize>(p: &Particles<D>, free_surface: &[bool], step: usize, time: f64) -> Frame {
    let n = p.len();
    let mut f = Frame {
        step,
        time,
        x: vec![[0.0; 3]; n],
        u: vec![[0.0; 3]; n],
        p: vec![0.0; n],
        free_surface: vec![false; n],
    };
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by_key(|&a| p.id[a]);
    for (i, &a) in order.iter().enumerate() {
        for k in 0..D.min(3) {
            f.x[i][k] = p.x[a][k];
            f.u[i][k] = p.u[a][k];
        }
        f.p[i] = p.p[a];
        f.free_surface[i] = free_surface.get(a).copied().unwrap_or(false);
    }
    f
}

/// Rejects initial particles that cannot be run: a non-finite initial velocity or pressure
/// (an affine or quadratic field overflowing), and particles closer than Δx/2 to each other
/// (overlapping bodies). `body_start[i]` is the index of body i's first particle.
fn check_seeds<const D: usize>(
    p: &Particles<D>,
    body_start: &[usize],
    dx: f64,
    domain: Domain<D>,
) -> Result<(), SceneError> {
    let body_of = |a: usize| body_start.partition_point(|&s| s <= a).saturating_sub(1);
    let show = |v: &Vector<D>| {
        let parts: Vec<String> = v.iter().map(|x| format!("{x:.4e}")).collect();
        format!("({})", parts.join(", "))
    };
    if let Some(a) = (0..p.len()).find(|&a| !p.u[a].iter().all(|v| v.is_finite())) {
        return Err(SceneError::new(
            format!("bodies[{}].velocity", body_of(a)),
            format!("u = {} at x = {}", show(&p.u[a]), show(&p.x[a])),
            "must give a finite initial velocity at every particle",
        ));
    }
    if let Some(a) = (0..p.len()).find(|&a| !p.p[a].is_finite()) {
        return Err(SceneError::new(
            format!("bodies[{}].pressure", body_of(a)),
            format!("p = {} at x = {}", p.p[a], show(&p.x[a])),
            "must give a finite initial pressure at every particle",
        ));
    }
    let mut list = crate::neighbours::NeighbourList::default();
    crate::neighbours::CellSearch::new(0.5 * dx, domain).build(&p.x, &mut list);
    let close = (0..p.len()).flat_map(|a| list.of(a).iter().map(move |&b| (a, b as usize)));
    // The pair whose later body comes first: that body is the one that overlaps.
    if let Some((a, b)) = close.min_by_key(|&(a, b)| (body_of(a.max(b)), a.max(b), a.min(b))) {
        let (i, j) = (body_of(a.max(b)), body_of(a.min(b)));
        let x = show(&p.x[a.max(b)]);
        return Err(if i == j {
            SceneError::new(
                format!("bodies[{i}].shape"),
                format!("particles at {x}"),
                "places particles closer than dx/2 to each other (the shape wraps onto itself \
                 across a periodic boundary)",
            )
        } else {
            SceneError::new(
                format!("bodies[{i}].shape"),
                format!("a particle at {x}"),
                format!("overlaps bodies[{j}] (particles closer than dx/2); bodies must not overlap"),
            )
        });
    }
    Ok(())
}

fn build<K: Kernel, const D: usize>(
    scene: &Scene,
    h: f64,
    domain: Domain<D>,
    open: Option<&OpenSetup>,
) -> (Vec<Box<dyn Stage<D>>>, Weight) {
    let kernel = Scaled::<K, D>::new(h);
    let stages = match &scene.scheme {
        Scheme::Isph(opts) => crate::isph::build_stages::<K, D>(scene, opts, kernel, domain, open),
        Scheme::Wcsph(opts) => crate::wcsph::build_stages::<K, D>(scene, opts, kernel, domain),
    };
    (stages, Weight { w: Box::new(move |r| kernel.w(r)), support: kernel.support })
}

/// The box a particle must stay in: the initial bounding box enlarged on every side by
/// four times its largest size (at least 10 Δx), or, if larger, by twice the distance a
/// particle could have coasted by time t, `2 (|u|_max,0 t + |g| t²/2)`. A free body spun
/// fast (`rotating_square`: 70 m/s at the corners) legitimately flings fluid far beyond
/// four times its size; leaving the box faster than that is a blow-up.
#[derive(Debug, Clone, Copy)]
struct GuardBox<const D: usize> {
    lo: Vector<D>,
    hi: Vector<D>,
    /// Fixed margin \[m\].
    margin: f64,
    /// Largest initial speed \[m/s\].
    speed: f64,
    /// |g| \[m/s²\].
    accel: f64,
}

impl<const D: usize> GuardBox<D> {
    fn new(scene: &Scene, u: &[Vector<D>], lo: Vector<D>, hi: Vector<D>) -> Self {
        let accel = scene.body_force.iter().map(|g| g * g).sum::<f64>().sqrt();
        let speed = u.iter().map(|u| u.norm()).fold(0.0, f64::max);
        Self { lo, hi, margin: 4.0 * (hi - lo).max().max(10.0 * scene.dx), speed, accel }
    }

    /// The box's corners at time `t` \[s\].
    fn at(&self, t: f64) -> (Vector<D>, Vector<D>) {
        let m = self.margin.max(2.0 * (self.speed * t + 0.5 * self.accel * t * t));
        (self.lo.add_scalar(-m), self.hi.add_scalar(m))
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

    #[test]
    fn bulk_neighbour_count_of_the_lattice() {
        // Lattice points within 3 Δx (cubic spline, h = 1.5 Δx): |z|² ∈ {1, 2, 4, 5, 8, 9}.
        assert_eq!(NeighbourBand::new::<2>(3.0, 1.0), NeighbourBand { bulk: 28, limit: 112 });
        assert_eq!(NeighbourBand::new::<2>(0.3, 0.1).bulk, 28);
        // h = Δx: |z|² ∈ {1, 2, 4} in 2D; in 3D |z|² ∈ {1, 2, 3, 4}: 6 + 12 + 8 + 6.
        assert_eq!(NeighbourBand::new::<2>(2.0, 1.0).bulk, 12);
        assert_eq!(NeighbourBand::new::<3>(2.0, 1.0).bulk, 32);
    }

    /// Runs the neighbour-search stage of a simulation.
    fn search_neighbours(sim: &mut Simulation<2>, ctx: &StepContext) -> Result<(), Cause> {
        let stage = sim.stages.iter_mut().find(|s| s.name() == "neighbours").expect("a neighbour stage");
        stage.run(&mut sim.state, ctx)
    }

    #[test]
    fn clumped_particles_trip_the_neighbour_guard() {
        let mut sim = small_drop();
        let ctx = StepContext { step: 1, time: 0.0, dt: 1e-5 };
        search_neighbours(&mut sim, &ctx).expect("neighbour search");
        assert_eq!(sim.guard(0.0, 0.0), Ok(()), "the initial lattice is within the band");
        // Squeeze the drop to a third of its size: every interior particle now has about
        // 9 × 28 neighbours.
        for x in &mut sim.state.particles.x {
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
        let n = sim.state.particles.len();
        let at = |sim: &Simulation<2>, id: u32| sim.state.particles.id.iter().position(|&i| i == id).unwrap();
        let (a, b, c) = (at(&sim, 7), at(&sim, 3), at(&sim, (n - 1) as u32));
        sim.state.particles.x[a][0] = 1e6;
        sim.state.particles.x[b][1] = -1e6;
        sim.state.particles.p[c] = f64::NAN;
        match sim.guard(0.0, 0.0) {
            Err(Cause::NonFinite { quantity: "pressure", particle, others: 0 }) => {
                assert_eq!(particle, n - 1)
            }
            other => panic!("{other:?}"),
        }
        sim.state.particles.p[c] = 0.0;
        let cause = sim.guard(0.0, 0.0).expect_err("escape");
        assert!(matches!(cause, Cause::Escape { particle: 3, others: 1, .. }), "{cause}");
        let msg = cause.to_string();
        assert!(
            msg.starts_with("particle 3 escaped to (") && msg.contains("(and 1 other particle)"),
            "{msg}"
        );
    }
}
