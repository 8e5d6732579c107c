//! Projection stages (Qiu 2013 §2.2–2.3, eqs. 5–7, 10, 12, 15): PPE assembly and solve,
//! velocity correction, position update.

use super::IsphData;
use crate::boundary_map::Link;
use crate::error::Cause;
use crate::linalg::{LinearSolver, par_csr_rows_mut, stored};
use crate::operators::{ShaoLo, corrected_divergence, divergence};
use crate::scene::{Divergence, PressureGradient};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// Assembles `A p = b` (NUMERICS.md): `A = −L` with the Shao–Lo Laplacian (Qiu eq. 12,
/// constant ρ) `L(p)_a = Σ_b c_ab (p_b − p_a)`, `c_ab = −2 V_b (r_ab·∇_aW_ab) / (ρ (r² + η²))`,
/// η² = 0.01 h², over the non-free-surface particles (p = 0 on the free surface), and
/// `b = −div u* / Δt` with `div u*_a = Σ_b V_b (u*_b − u*_a)·∇_aW_ab` (Qiu eq. 10).
///
/// Density relaxation (`scheme.isph.density_relaxation` = α > 0): the source gets the
/// density-invariant term of Shao & Lo 2003 (eq. 18, `∇·(∇p/ρ) = (ρ₀ − ρ*)/(ρ₀ Δt²)`)
/// weighted by α, as in the stabilised ISPH of Asai, Aly, Sonoda & Sakai 2012 (J. Appl.
/// Math. 2012:139583): `b_a += α (ρ_a/ρ₀ − 1)/(Δt Δt_max)`, with ρ_a/ρ₀ the kernel sum of
/// the `particle_density` stage (`isph::particle_density`).
/// `Δt_max` is the largest step taken so far instead of a second `Δt`: the term corrects a
/// fraction ~α of the density error per typical step, and a short step (one landing on a
/// probe time) then corrects proportionally less. With `Δt²` a landing step 100 times
/// shorter kicked the velocity 100 times harder (measured: centre-line velocities of 14 U
/// in an open channel at the last sample).
#[derive(Debug, Default)]
pub struct PpeAssemble {
    /// Divergence operator of the source term.
    pub divergence: Divergence,
    /// α of the density relaxation, when on (it reads `State::particle_density`).
    pub relaxation: Option<f64>,
    /// Largest Δt so far \[s\] (density relaxation).
    pub dt_max: f64,
    /// The free-surface particles carry known, non-zero pressures (the extrapolated value
    /// of `stages::surface_extrapolation` and the Young–Laplace value σκ of
    /// `stages::young_laplace`), moved to the right-hand side like the known boundary
    /// pressures; otherwise they are 0 and drop out.
    pub surface_pressure: bool,
}

impl<const D: usize> Stage<D, IsphData> for PpeAssemble {
    fn name(&self) -> &'static str {
        "ppe_assemble"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut IsphData, ctx: &StepContext) -> Result<(), Cause> {
        let n = s.particles.len();
        let sys = &mut own.ppe;
        sys.row_of.resize(s.particles.total(), u32::MAX);
        sys.particle_of.clear();
        for a in 0..n {
            if s.particles.free_surface[a] {
                sys.row_of[a] = u32::MAX;
            } else {
                sys.row_of[a] = sys.particle_of.len() as u32;
                sys.particle_of.push(a as u32);
            }
        }
        // Boundary particles by the boundary map: a mirror shares its source's unknown, an
        // inlet buffer particle its row source's (zero normal gradient); dummy walls and the
        // outlet buffer carry known pressures (boundary particles come in index order, so a
        // mirror of a buffer particle finds the buffer's row set).
        for b in n..s.particles.total() {
            sys.row_of[b] = match s.links.pressure(b) {
                Link::Shares { source, .. } => sys.row_of[source as usize],
                Link::Unknown | Link::Known => u32::MAX,
            };
        }
        let rows = sys.particle_of.len();
        let known_boundary = s.links.has_known_pressure();
        sys.singular = rows == n && !known_boundary;
        let (list, row_of, particle_of) = (&s.neighbours, &sys.row_of, &sys.particle_of);
        // Row lengths: the interior neighbours (the diagonal is stored apart).
        let m = &mut sys.matrix;
        m.row_ptr.resize(rows + 1, 0);
        m.row_ptr[0] = 0;
        m.row_ptr[1..].par_iter_mut().enumerate().with_min_len(256).for_each(|(i, len)| {
            let a = particle_of[i] as usize;
            let own = i as u32;
            *len = list
                .of(a)
                .iter()
                .filter(|&&b| {
                    let rb = row_of[b as usize];
                    rb != u32::MAX && rb != own
                })
                .count();
        });
        for i in 0..rows {
            m.row_ptr[i + 1] += m.row_ptr[i];
        }
        m.resize_entries();
        let (v, rho, shao_lo) = (s.volume, s.density, ShaoLo::new(s.h));
        let (pairs, moments, links) = (&s.pairs, &s.moments, &s.links);
        let (u, inv_dt, corrected) = (&s.particles.u, 1.0 / ctx.dt, self.divergence == Divergence::Corrected);
        self.dt_max = self.dt_max.max(ctx.dt);
        let (p, density, relaxation, dt_max) =
            (&s.particles.p, &own.particle_density, self.relaxation, self.dt_max);
        let surface_pressure = self.surface_pressure;
        // One pass over each row's pairs: the matrix row, then (the pairs still in cache)
        // the right-hand side; `row_out` holds (A_ii, b_i) until the diagonal pass below.
        sys.row_out.resize(rows, [0.0; 2]);
        let row = |i, cols: &mut [u32], vals: &mut [f32], out: &mut [f64; 2]| {
            let a = particle_of[i] as usize;
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let mut diag = 0.0;
            let mut k = 0;
            for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let rb = row_of[b as usize];
                if rb == i as u32 {
                    // The particle's own mirror: c (p_a − p_a) = 0.
                    continue;
                }
                // Rounded as stored, here and in the diagonal (see `CsrMatrix`).
                let c = stored(shao_lo.coefficient(p, -2.0 * v, rho));
                diag += c;
                if rb != u32::MAX {
                    (cols[k], vals[k]) = (rb, -c as f32);
                    k += 1;
                }
            }
            let (row_pairs, nbrs) = (&pairs[lo..hi], &list.indices[lo..hi]);
            let div = if corrected {
                corrected_divergence(u, a, (row_pairs, nbrs), v, moments[a].as_ref())
            } else {
                divergence(u, a, row_pairs, nbrs, v)
            };
            // Known pressures move to the right-hand side: the boundary's (dummy walls, the
            // outlet buffer) and, with `surface_pressure`, the free surface's, also through a
            // boundary particle that shares a surface particle's value (a mirror or an inlet
            // buffer particle: its own p is still the previous step's copy).
            let mut known = 0.0;
            if known_boundary || surface_pressure {
                for (pr, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                    let b = b as usize;
                    if row_of[b] != u32::MAX {
                        continue;
                    }
                    let src = links.pressure_holder(b);
                    if (src < n && surface_pressure) || (src >= n && known_boundary) {
                        known += shao_lo.coefficient(pr, -2.0 * v, rho) * p[src];
                    }
                }
            }
            let relax = match relaxation {
                Some(alpha) => alpha * (density[a] - 1.0) * inv_dt / dt_max,
                None => 0.0,
            };
            *out = [diag, -div * inv_dt + known + relax];
        };
        par_csr_rows_mut(&m.row_ptr, &mut m.cols, &mut m.vals, &mut sys.row_out, &row);
        sys.finish_rows();
        Ok(())
    }
}

/// Solves the assembled PPE (Qiu eq. 5) with the scene's solver, warm-started from the
/// previous pressure; writes p (zero on the free surface, or the known
/// value there with `surface_pressure`).
#[derive(Debug)]
pub struct PpeSolveStage {
    /// The configured solver.
    pub solver: LinearSolver,
    /// Keep the free-surface pressures set before the solve (see
    /// [`PpeAssemble::surface_pressure`]).
    pub surface_pressure: bool,
}

impl<const D: usize> Stage<D, IsphData> for PpeSolveStage {
    fn name(&self) -> &'static str {
        "ppe_solve"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut IsphData, _ctx: &StepContext) -> Result<(), Cause> {
        let sys = &mut own.ppe;
        // The particle ids key the rows for a coarse space kept across steps.
        let id = &s.particles.id;
        s.solve = sys.solve(&mut self.solver, &s.particles.p, |a| id[a])?;
        let p = &mut s.particles.p;
        // Free-surface particles get p = 0 (or keep their known value); boundary
        // particles keep their known values.
        if !self.surface_pressure {
            p[..s.particles.fluid].iter_mut().for_each(|v| *v = 0.0);
        }
        for (x, &a) in sys.solution.iter().zip(&sys.particle_of) {
            p[a as usize] = *x;
        }
        // Boundary particles sharing an unknown take its value (in index order: a mirror of
        // an inlet buffer particle after the buffer particle).
        for (b, source) in s.links.pressure_copies() {
            p[b] = p[source as usize];
        }
        Ok(())
    }
}

/// Velocity correction (Qiu eq. 6): `u^{n+1} = u* − Δt (∇p/ρ)` with the symmetric gradient
/// of Qiu eq. 15, `Σ_b V_b (p_a + p_b) ∇_aW_ab / ρ`, the difference form
/// `Σ_b V_b (p_b − p_a) ∇_aW_ab / ρ`, or the difference form with the kernel-gradient
/// correction `L_a = (Σ_b V_b (r_b − r_a) ⊗ ∇_aW_ab)⁻¹` (Bonet & Lok 1999, eq. 43).
#[derive(Debug)]
pub struct Correction {
    /// Gradient form.
    pub form: PressureGradient,
}

impl<const D: usize, O> Stage<D, O> for Correction {
    fn name(&self) -> &'static str {
        "correction"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let (list, pairs, p, moments) = (&s.neighbours, &s.pairs, &s.particles.p, &s.moments);
        let (c, v) = (ctx.dt * s.volume / s.density, s.volume);
        let sign = match self.form {
            PressureGradient::Symmetric => 1.0,
            PressureGradient::Difference | PressureGradient::Corrected => -1.0,
        };
        let corrected = self.form == PressureGradient::Corrected;
        let dt_rho = ctx.dt / s.density;
        s.particles.u[..s.particles.fluid].par_iter_mut().enumerate().with_min_len(256).for_each(|(a, u)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let mut g = Vector::<D>::zeros();
            for (pr, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                g += pr.r_ab * (pr.f * (p[b as usize] + sign * p[a]));
            }
            if corrected {
                // ∇p_a = L_a (V g) with the step's correction L_a = M_a⁻¹ (symmetric).
                if let Some(l) = &moments[a] {
                    *u -= l * (g * v) * dt_rho;
                    return;
                }
            }
            *u -= g * c;
        });
        Ok(())
    }
}

/// Position update (Qiu eq. 7): `r^{n+1} = r^n + Δt (u^{n+1} + u^n) / 2`.
#[derive(Debug)]
pub struct Position;

impl<const D: usize, O> Stage<D, O> for Position {
    fn name(&self) -> &'static str {
        "position"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, ctx: &StepContext) -> Result<(), Cause> {
        let (dt, dom) = (ctx.dt, s.domain);
        let periodic = dom.is_periodic();
        let (x_old, u_old, u) = (&s.particles.x_old, &s.particles.u_old, &s.particles.u);
        s.particles.x[..s.particles.fluid].par_iter_mut().enumerate().with_min_len(512).for_each(|(a, x)| {
            *x = x_old[a] + (u[a] + u_old[a]) * (0.5 * dt);
            if periodic {
                dom.wrap(x);
            }
        });
        Ok(())
    }
}
