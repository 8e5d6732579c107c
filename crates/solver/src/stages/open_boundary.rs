//! Inflow and outflow through buffer layers (the usual particle-method treatment of open
//! boundaries, e.g. Lastiwka, Basa & Quinlan 2009; Lan et al. 2022 §1.3 use the same idea
//! with a "push plate" that refills the inlet with ghost particles).
//!
//! - **Inlet** (`boundaries.inflow`): a buffer of particles upstream of the inlet plane, the
//!   fluid's first lattice column repeated over `⌈support/Δx⌉` columns, moves at the inflow
//!   velocity `U e_axis`. A buffer particle that crosses the plane becomes a fluid particle
//!   (velocity `U`, a new id) and is replaced by one a buffer depth upstream, so the buffer
//!   stays a lattice and the inflow is exactly `ρ U` per unit area. Its pressure is that of
//!   the fluid next to the plane in its lattice row, shared in the PPE ([`InletSources`]):
//!   a zero normal gradient.
//! - **Outlet** (`boundaries.outflow`): a fluid particle that crosses the outlet plane joins
//!   the outlet buffer with its normal velocity (clamped at zero; transverse components
//!   dropped) and `p = 0`, the Dirichlet value of the outlet; buffer particles move at that
//!   frozen velocity and are removed one buffer depth past the plane. At the start the
//!   buffer is the fluid's last column repeated downstream.
//!
//! Buffers fill the kernel support of the fluid near both planes, so those particles are
//! neither free-surface particles nor short of neighbours. The masses that crossed are
//! counted in [`crate::state::Flux`] (the `mass_balance` probe).

use crate::error::Cause;
use crate::fields::{Fields, retain};
use crate::scene::{Inflow, Outflow};
use crate::stage::{Stage, StepContext};
use crate::state::{InletLink, Particles, State, Vector};

/// The open boundaries of a channel: the planes, the inflow speed and the buffer depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Openings {
    /// Flow axis.
    pub axis: usize,
    /// Inlet plane \[m\].
    pub inlet: f64,
    /// Outlet plane \[m\].
    pub outlet: f64,
    /// Inflow speed U \[m/s\].
    pub speed: f64,
    /// Lattice spacing Δx \[m\].
    pub dx: f64,
    /// Buffer columns, `⌈support/Δx⌉`.
    pub columns: usize,
}

impl Openings {
    /// The openings of a scene's `inflow`/`outflow` for kernel `support` \[m\].
    pub fn new(inflow: &Inflow, outflow: &Outflow, dx: f64, support: f64) -> Self {
        let columns = (support / dx - 1e-9).ceil().max(1.0) as usize;
        Self {
            axis: inflow.axis,
            inlet: inflow.position,
            outlet: outflow.position,
            speed: inflow.velocity,
            dx,
            columns,
        }
    }

    /// Buffer depth `columns · Δx` \[m\].
    pub fn depth(&self) -> f64 {
        self.columns as f64 * self.dx
    }

    /// Appends the initial buffers after the fluid of `p` (inlet buffer first) and returns
    /// the number of inlet buffer particles with their pressure link (each row's source is
    /// at first the fluid particle of the first column). The fluid spans the channel, with
    /// a lattice column within Δx of each plane (a scene rule, checked by the validation).
    pub fn seed<const D: usize>(&self, p: &mut Particles<D>) -> (usize, InletLink) {
        let (k, dx) = (self.axis, self.dx);
        let nf = p.fluid;
        let (lo, hi) = p.x[..nf]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x[k]), hi.max(x[k])));
        let mut inlet = 0;
        let mut link = InletLink { columns: self.columns, ..Default::default() };
        for a in 0..nf {
            if p.x[a][k] < lo + 0.5 * dx {
                link.row_id.push(p.id[a]);
                for m in 1..=self.columns {
                    let mut x = p.x[a];
                    x[k] -= m as f64 * dx;
                    let mut u = Vector::<D>::zeros();
                    u[k] = self.speed;
                    p.x.push(x);
                    p.u.push(u);
                    p.p.push(0.0);
                    inlet += 1;
                }
            }
        }
        for a in 0..nf {
            if p.x[a][k] > hi - 0.5 * dx {
                for m in 1..=self.columns {
                    let mut x = p.x[a];
                    x[k] += m as f64 * dx;
                    let mut u = Vector::<D>::zeros();
                    u[k] = p.u[a][k].max(0.0);
                    p.x.push(x);
                    p.u.push(u);
                    p.p.push(0.0);
                }
            }
        }
        link.source = vec![u32::MAX; inlet];
        (inlet, link)
    }
}

/// What the simulation needs of the open boundaries: the openings, the number of inlet
/// buffer particles, the first id free for new fluid particles and the initial pressure
/// link of the inlet.
#[derive(Debug, Clone, PartialEq)]
pub struct OpenSetup {
    /// The planes and buffers.
    pub openings: Openings,
    /// Inlet buffer particles (right after the fluid).
    pub inlet: usize,
    /// First id for fluid particles that enter.
    pub next_id: u32,
    /// Initial pressure link of the inlet buffer.
    pub link: InletLink,
}

/// End-of-step transfer through the open boundaries: moves the buffers, turns inlet
/// buffer particles that crossed the inlet into fluid, moves fluid that crossed the outlet
/// into the outlet buffer and drops outlet buffer particles a buffer depth downstream.
/// Serial (one pass over the particles, in index order: deterministic).
#[derive(Debug)]
pub struct OpenBoundaries<const D: usize> {
    open: Openings,
    inlet: usize,
    next_id: u32,
    /// Inlet buffer, then outlet buffer (x, u, p), rebuilt every step.
    scratch: Vec<(Vector<D>, Vector<D>, f64)>,
    /// Fluid particles entering this step (x, u, p, inlet row).
    entering: Vec<(Vector<D>, Vector<D>, f64, usize)>,
    /// Which fluid particles stay in the fluid this step.
    keep: Vec<bool>,
}

impl<const D: usize> OpenBoundaries<D> {
    /// The stage for the open boundaries of `setup`.
    pub fn new(setup: &OpenSetup) -> Self {
        let (open, inlet, next_id) = (setup.openings, setup.inlet, setup.next_id);
        Self { open, inlet, next_id, scratch: Vec::new(), entering: Vec::new(), keep: Vec::new() }
    }
}

impl<const D: usize, O: Fields<D>> Stage<D, O> for OpenBoundaries<D> {
    fn name(&self) -> &'static str {
        "open_boundaries"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let o = self.open;
        let (k, nf, nb) = (o.axis, s.particles.fluid, s.buffer);
        let mass = s.density * s.volume;
        let p = &mut s.particles;
        // Wall mirrors are rebuilt next step.
        p.x.truncate(nf + nb);
        p.u.truncate(nf + nb);
        p.p.truncate(nf + nb);
        self.scratch.clear();
        self.entering.clear();
        for i in nf..nf + nb {
            let x = p.x[i] + p.u[i] * ctx.dt;
            if i < nf + self.inlet {
                if x[k] >= o.inlet {
                    self.entering.push((x, p.u[i], p.p[i], (i - nf) / o.columns));
                    let mut back = x;
                    back[k] -= o.depth();
                    self.scratch.push((back, p.u[i], p.p[i]));
                } else {
                    self.scratch.push((x, p.u[i], p.p[i]));
                }
            } else if x[k] < o.outlet + o.depth() {
                self.scratch.push((x, p.u[i], 0.0));
            }
        }
        // Compact the fluid (every declared field): particles past the outlet join the
        // outlet buffer; a particle pushed upstream of the inlet plane is reflected back.
        self.keep.clear();
        let mut left = 0usize;
        for a in 0..nf {
            let x = &mut p.x[a];
            if x[k] < o.inlet {
                x[k] = 2.0 * o.inlet - x[k];
            }
            let leaves = x[k] >= o.outlet;
            if leaves {
                let mut u = Vector::<D>::zeros();
                u[k] = p.u[a][k].max(0.0);
                self.scratch.push((*x, u, 0.0));
                left += 1;
            }
            self.keep.push(!leaves);
        }
        retain(p, &self.keep);
        retain(own, &self.keep);
        for &(x, u, pr, row) in &self.entering {
            p.x.push(x);
            p.u.push(u);
            p.p.push(pr);
            p.id.push(self.next_id);
            s.inlet.row_id[row] = self.next_id;
            self.next_id += 1;
            p.free_surface.push(false);
            p.div_r.push(0.0);
        }
        p.fluid = p.x.len();
        for &(x, u, pr) in &self.scratch {
            p.x.push(x);
            p.u.push(u);
            p.p.push(pr);
        }
        s.buffer = self.scratch.len();
        s.flux.inflow += mass * self.entering.len() as f64;
        s.flux.outflow += mass * left as f64;
        Ok(())
    }
}

/// Finds, after the reorder, the current index of every inlet row's source (the fluid
/// particle that entered last through the row, [`InletLink`]); the PPE assembly and solve
/// then give each inlet buffer particle its row source's pressure. This is the inlet's
/// zero normal gradient, implicit in the PPE like the wall mirrors' (Qiu §2.4.2).
///
/// Measured alternatives (5 D channel at Re = 40, mass in the channel after 15 D/U):
/// the Shepard average of the fluid pressure around each buffer particle, as a known
/// value lagged by one solve, let the fluid near the inlet compress (+11 %: it takes the
/// pressure of the fluid ~1.5 Δx downstream, lower than at the plane where the entrance
/// flow's pressure falls steeply); a first-order least-squares extrapolation to the plane,
/// also lagged, diverged in the first steps; `p = 0` compressed by +12 % in 2 D/U.
#[derive(Debug)]
pub struct InletSources;

impl<const D: usize, O> Stage<D, O> for InletSources {
    fn name(&self) -> &'static str {
        "inlet_sources"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let link = &mut s.inlet;
        let rows = link.row_id.len();
        // (id, row) sorted by id, to look up every fluid particle's id once.
        let mut wanted: Vec<(u32, usize)> = link.row_id.iter().copied().zip(0..rows).collect();
        wanted.sort_unstable();
        let mut index = vec![u32::MAX; rows];
        for (a, id) in s.particles.id[..s.particles.fluid].iter().enumerate() {
            if let Ok(k) = wanted.binary_search_by_key(id, |w| w.0) {
                index[wanted[k].1] = a as u32;
            }
        }
        let columns = link.columns.max(1);
        for (i, src) in link.source.iter_mut().enumerate() {
            *src = index.get(i / columns).copied().unwrap_or(u32::MAX);
        }
        Ok(())
    }
}
