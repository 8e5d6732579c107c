//! Lan 2022's open channel (§1.7; MPS.md "Inflow and outflow"): a pushing plate at the
//! inlet and ghost particles recycled from the outlet, so that the number of particles
//! (fluid and ghosts) never changes.
//!
//! - **Plate**: wall particles on the fluid's lattice rows, `layers` columns deep (the
//!   Laplacian radius), the front column one spacing upstream of the fluid's first one. It
//!   moves at the inflow speed U (its particles carry `u = U e_axis` into the divergence
//!   and the viscous sum). After a stroke of one spacing (Lan does not state the stroke; one
//!   column, l0/U) it jumps back by l0, and the gap, where its front column was, is filled
//!   with a column of ghosts turned into fluid at `u = U`: the inflow is exactly ρ U per
//!   unit area on average. The columns within the gradient radius of the fluid's first
//!   column are type 1 (in the PPE), the others type 2 (extrapolated), as for the walls.
//! - **Outlet**: a fluid particle past the outlet plane becomes a ghost (zero mass, in no
//!   sum: it leaves the particle arrays, its id kept in [`MpsData::ghosts`]). The fluid next
//!   to the plane has no neighbours downstream, reads as free surface (n* < β n0) and holds
//!   P = 0: the outlet's pressure.
//!
//! The masses through both planes are counted in [`crate::state::Flux`] (the
//! `mass_balance` probe). A run starts with a reserve of `RESERVE_COLUMNS` columns of
//! ghosts; an inlet that finds the reserve empty (the outflow lagging the inflow by that
//! much: the fluid compressing) stops the run with [`Cause::GhostsExhausted`].

use super::MpsData;
use crate::error::Cause;
use crate::fields::retain;
use crate::scene::{Inflow, Outflow};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};

/// Ghost columns in reserve at the start.
pub const RESERVE_COLUMNS: usize = 8;

/// Where the plate's particles are: `type1` of them right after the fluid (the first
/// `rows` of which are its front column), `type2` right after the type-1 walls.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlateLayout {
    /// Lattice rows (particles per column).
    pub rows: usize,
    /// Type-1 plate particles (the leading type-1 boundary particles).
    pub type1: usize,
    /// Type-2 plate particles (the leading type-2 boundary particles).
    pub type2: usize,
}

impl PlateLayout {
    /// True when boundary particle `j` (an index ≥ `fluid`) belongs to the plate, with
    /// `walls_type1` type-1 boundary particles in all.
    #[inline]
    pub fn holds(&self, j: usize, fluid: usize, type1: usize) -> bool {
        let k = j - fluid;
        k < self.type1 || (k >= type1 && k < type1 + self.type2)
    }
}

/// The plate of a channel whose fluid is `fluid` (the lattice at spacing `l0`): its
/// particles by type (type 1, then type 2, column by column from the front) and layout.
/// `depth` \[m\] is the Laplacian radius, `gradient` \[m\] the gradient radius.
pub fn plate<const D: usize>(
    inflow: &Inflow,
    fluid: &[Vector<D>],
    l0: f64,
    depth: f64,
    gradient: f64,
) -> (Vec<Vector<D>>, Vec<Vector<D>>, PlateLayout) {
    let k = inflow.axis;
    let first = fluid.iter().map(|x| x[k]).fold(f64::INFINITY, f64::min);
    let rows: Vec<Vector<D>> = fluid.iter().filter(|x| x[k] < first + 0.5 * l0).copied().collect();
    let layers = (depth / l0 + 1e-9).floor().max(1.0) as usize;
    let (mut type1, mut type2) = (Vec::new(), Vec::new());
    for m in 0..layers {
        // Column m is (m + 1) l0 behind the fluid's first column.
        let behind = (m + 1) as f64 * l0;
        for r in &rows {
            let mut x = *r;
            x[k] -= behind;
            if behind < gradient { type1.push(x) } else { type2.push(x) }
        }
    }
    let layout = PlateLayout { rows: rows.len(), type1: type1.len(), type2: type2.len() };
    (type1, type2, layout)
}

/// Moves the plate at U with the provisional positions (after the predictor), so that the
/// number density, the PPE and the correction see it where it is at the end of the step.
#[derive(Debug)]
pub struct PlateMove {
    /// Flow axis.
    pub axis: usize,
    /// Inflow speed U \[m/s\].
    pub speed: f64,
}

impl<const D: usize> Stage<D, MpsData<D>> for PlateMove {
    fn name(&self) -> &'static str {
        "plate_move"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (nf, plate, type1) = (s.particles.fluid, own.plate, own.type1);
        let step = self.speed * ctx.dt;
        let x = &mut s.particles.x;
        for j in (nf..nf + plate.type1).chain(nf + type1..nf + type1 + plate.type2) {
            x[j][self.axis] += step;
        }
        Ok(())
    }
}

/// End of step: fluid past the outlet becomes ghosts; the plate jumps back after each
/// stroke and a column of ghosts enters as fluid where its front was. Serial, in index
/// order (deterministic); the boundary particles keep their order after the fluid.
#[derive(Debug)]
pub struct Recycle<const D: usize> {
    axis: usize,
    speed: f64,
    outlet: f64,
    l0: f64,
    /// Plate travel since its last jump \[m\].
    stroke: f64,
    /// The fluid's first column at the start (one row per entry).
    rows: Vec<Vector<D>>,
    /// Which fluid particles stay this step.
    keep: Vec<bool>,
    /// The boundary particles (x, u, p), set aside while the fluid changes.
    tail: Vec<(Vector<D>, Vector<D>, f64)>,
}

impl<const D: usize> Recycle<D> {
    /// The recycling of a channel from `inflow` to `outflow` whose fluid's first column is
    /// `rows` (lattice spacing `l0`).
    pub fn new(inflow: &Inflow, outflow: &Outflow, rows: Vec<Vector<D>>, l0: f64) -> Self {
        Self {
            axis: inflow.axis,
            speed: inflow.velocity,
            outlet: outflow.position,
            l0,
            stroke: 0.0,
            rows,
            keep: Vec::new(),
            tail: Vec::new(),
        }
    }
}

impl<const D: usize> Stage<D, MpsData<D>> for Recycle<D> {
    fn name(&self) -> &'static str {
        "recycle"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (k, nf, plate, type1) = (self.axis, s.particles.fluid, own.plate, own.type1);
        self.stroke += self.speed * ctx.dt;
        let jump = self.stroke >= self.l0;
        let p = &mut s.particles;
        let leaving = p.x[..nf].iter().any(|x| x[k] >= self.outlet);
        if !jump && !leaving {
            return Ok(());
        }
        if jump && own.ghosts.len() < plate.rows {
            return Err(Cause::GhostsExhausted {
                needed: plate.rows,
                ghosts: own.ghosts.len(),
                reserve: RESERVE_COLUMNS,
            });
        }
        let mass = s.density * s.volume;
        self.tail.clear();
        self.tail.extend((nf..p.total()).map(|j| (p.x[j], p.u[j], p.p[j])));
        if jump {
            self.stroke -= self.l0;
            for (j, t) in self.tail.iter_mut().enumerate() {
                if plate.holds(nf + j, nf, type1) {
                    t.0[k] -= self.l0;
                }
            }
        }
        p.x.truncate(nf);
        p.u.truncate(nf);
        p.p.truncate(nf);
        self.keep.clear();
        for a in 0..nf {
            let stays = p.x[a][k] < self.outlet;
            if !stays {
                own.ghosts.push(p.id[a]);
            }
            self.keep.push(stays);
        }
        let kept = retain(p, &self.keep);
        s.flux.outflow += mass * (nf - kept) as f64;
        if jump {
            // The gap one spacing ahead of the plate's front column (the first `rows` of the
            // tail), at the pressure of the plate particle behind it.
            for (r, row) in self.rows.iter().enumerate() {
                let (front, _, pressure) = self.tail[r];
                let mut x = *row;
                x[k] = front[k] + self.l0;
                let mut u = Vector::<D>::zeros();
                u[k] = self.speed;
                let id = own.ghosts.pop().expect("checked above: enough ghosts");
                p.x.push(x);
                p.u.push(u);
                p.p.push(pressure);
                p.id.push(id);
                p.free_surface.push(false);
            }
            s.flux.inflow += mass * self.rows.len() as f64;
        }
        p.fluid = p.x.len();
        p.div_r.resize(p.fluid, 0.0);
        for &(x, u, pr) in &self.tail {
            p.x.push(x);
            p.u.push(u);
            p.p.push(pr);
        }
        Ok(())
    }
}
