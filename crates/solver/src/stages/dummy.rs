//! Dummy-particle walls with the generalised wall boundary condition of Adami, Hu & Adams
//! 2012 (J. Comput. Phys. 231:7057, eqs. 22–23, 27): fixed wall particles (layers behind
//! each wall plane, [`dummy_layers`], and the particles of wall bodies of any shape) whose
//! velocity and pressure are extrapolated from the fluid every step.
//!
//! - velocity (no slip, eqs. 22–23): `u_w = 2 u_wall − ũ_w`, `ũ_w = Σ_f u_f W_wf / Σ_f W_wf`
//!   (walls at rest: `u_wall = 0`);
//! - pressure (eq. 27, wall at rest): `p_w = (Σ_f p_f W_wf + ρ g·Σ_f r_wf W_wf) / Σ_f W_wf`,
//!   `r_wf = r_w − r_f`.
//!
//! In the projection the pressure enters the PPE as known boundary values: it is
//! extrapolated from the previous step's fluid pressure before assembly (the rows of the
//! fluid near a wall move `c_aw p_w` to the right-hand side), and again from the new
//! pressure before the velocity correction. A wall particle with no fluid neighbour keeps
//! zero velocity and pressure (it is nobody's neighbour either).

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::neighbours::Domain;
use crate::scene::{Side, Wall};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// The lattice points behind the walls that lie within `depth` of the fluid region: the
/// fluid lattice (anchored at `anchor`, spacing `dx`) extended over the bounding box of
/// `fluid` grown by `depth` (over the whole period on periodic axes), keeping the points
/// behind at least one wall and at most `depth` behind every wall they are behind.
pub fn dummy_layers<const D: usize>(
    walls: &[Wall],
    domain: &Domain<D>,
    fluid: &[Vector<D>],
    dx: f64,
    depth: f64,
) -> Vec<Vector<D>> {
    let Some(anchor) = fluid.first().filter(|_| !walls.is_empty()) else { return Vec::new() };
    let mut lo = Vector::<D>::repeat(f64::INFINITY);
    let mut hi = Vector::<D>::repeat(f64::NEG_INFINITY);
    for x in fluid {
        lo = lo.inf(x);
        hi = hi.sup(x);
    }
    // Index ranges per axis, relative to the anchor.
    let mut range = [(0i64, 0i64); D];
    for k in 0..D {
        let (a, b) = match domain.periodic[k] {
            Some((pmin, pmax)) => (pmin, pmax - 1e-9 * dx),
            None => (lo[k] - depth, hi[k] + depth),
        };
        range[k] = (((a - anchor[k]) / dx).ceil() as i64, ((b - anchor[k]) / dx).floor() as i64);
    }
    let behind = |x: &Vector<D>, w: &Wall| {
        let side = if w.fluid_side == Side::Above { 1.0 } else { -1.0 };
        -side * (x[w.axis] - w.position)
    };
    let mut out = Vec::new();
    let mut idx: [i64; D] = std::array::from_fn(|k| range[k].0);
    loop {
        let x = Vector::<D>::from_fn(|k, _| anchor[k] + idx[k] as f64 * dx);
        let depths: Vec<f64> = walls.iter().map(|w| behind(&x, w)).collect();
        if depths.iter().any(|&d| d > 0.0) && depths.iter().all(|&d| d <= depth) {
            out.push(x);
        }
        let mut k = 0;
        loop {
            if k == D {
                return out;
            }
            idx[k] += 1;
            if idx[k] <= range[k].1 {
                break;
            }
            idx[k] = range[k].0;
            k += 1;
        }
    }
}

/// Which values a [`DummyWalls`] stage extrapolates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extrapolate {
    /// At the start of the step: `u_old`, `u` from `uⁿ` and `p` from the previous pressure.
    Start,
    /// After the predictor: `u` from `u*` (the PPE source reads it).
    Velocity,
    /// After the PPE solve: `p` from the new pressure (the correction reads it).
    Pressure,
}

/// Extrapolates the fluid's velocity and pressure onto the wall particles (Adami 2012).
#[derive(Debug)]
pub struct DummyWalls<K: Kernel, const D: usize> {
    kernel: Scaled<K, D>,
    g: Vector<D>,
    what: Extrapolate,
    scratch: Vec<(Vector<D>, f64)>,
}

impl<K: Kernel, const D: usize> DummyWalls<K, D> {
    /// A stage with the scene's `kernel` and body force `g` \[m/s²\].
    pub fn new(kernel: Scaled<K, D>, g: Vector<D>, what: Extrapolate) -> Self {
        Self { kernel, g, what, scratch: Vec::new() }
    }
}

impl<K: Kernel, const D: usize, O> Stage<D, O> for DummyWalls<K, D> {
    fn name(&self) -> &'static str {
        match self.what {
            Extrapolate::Start => "dummy_walls",
            Extrapolate::Velocity => "dummy_velocity",
            Extrapolate::Pressure => "dummy_pressure",
        }
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let (nf, total) = (s.particles.fluid, s.particles.total());
        let (list, pairs, k, g, rho) = (&s.neighbours, &s.pairs, self.kernel, self.g, s.density);
        let (u, p) = (&s.particles.u, &s.particles.p);
        let what = self.what;
        self.scratch.resize(total - nf, (Vector::zeros(), 0.0));
        self.scratch.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, out)| {
            let w = nf + i;
            let (lo, hi) = (list.offsets[w], list.offsets[w + 1]);
            let (mut sw, mut su, mut sp) = (0.0, Vector::<D>::zeros(), 0.0);
            for (pair, &f) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let f = f as usize;
                if f >= nf {
                    continue;
                }
                let wt = k.w(pair.r2().sqrt());
                sw += wt;
                su += u[f] * wt;
                // r_wf = r_w − r_f = r_ab of this row.
                sp += (p[f] + rho * g.dot(&pair.r_ab)) * wt;
            }
            *out = if sw > 0.0 { (-su / sw, sp / sw) } else { (Vector::zeros(), 0.0) };
        });
        for (i, &(uw, pw)) in self.scratch.iter().enumerate() {
            let w = nf + i;
            if what != Extrapolate::Pressure {
                s.particles.u[w] = uw;
            }
            if what == Extrapolate::Start {
                s.particles.u_old[w] = uw;
            }
            if what != Extrapolate::Velocity {
                s.particles.p[w] = pw;
            }
        }
        Ok(())
    }
}
