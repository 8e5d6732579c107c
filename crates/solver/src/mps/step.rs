//! The stages of the semi-implicit MPS step (MPS.md "Step"; Koshizuka & Oka 1996 with Lan
//! 2022's operators and PPE): neighbour lists, number density and free surface,
//! PPE assembly and solve, velocity and position correction (the predictor: [`super::viscosity`]).

use super::operators::Operators;
use super::weight::Weight;
use super::{Density, MpsData};
use crate::error::Cause;
use crate::fields::Matrix;
use crate::linalg::{LinearSolver, par_csr_rows_mut, stored};
use crate::neighbours::CellSearch;
use crate::scene::{MpsDivergence, MpsGradient};
use crate::stage::par_rows_mut;
use crate::stage::{Stage, StepContext};
use crate::state::{Pair, State, Vector};
use rayon::prelude::*;

/// The neighbour lists of every particle (fluid and wall) within the operators' largest
/// radius plus a skin, so that one list serves the whole step: built at rⁿ (where the
/// viscous term is evaluated), and at the provisional positions r* only if some particle
/// moved farther than half the skin since (then a pair could have come within reach
/// unseen). The operators compute each distance from the positions they read; a pair
/// beyond an operator's radius weighs zero.
#[derive(Debug)]
pub struct Lists<const D: usize> {
    search: CellSearch<D>,
    skin: f64,
    provisional: bool,
}

impl<const D: usize> Lists<D> {
    /// The lists at the start of the step (also saves rⁿ and uⁿ), of radius
    /// `reach + skin` \[m\].
    pub fn start(reach: f64, skin: f64, domain: crate::neighbours::Domain<D>) -> Self {
        Self { search: CellSearch::new(reach + skin, domain), skin, provisional: false }
    }

    /// The check (and, when needed, rebuild) at the provisional positions.
    pub fn provisional(reach: f64, skin: f64, domain: crate::neighbours::Domain<D>) -> Self {
        Self { provisional: true, ..Self::start(reach, skin, domain) }
    }
}

impl<const D: usize, O> Stage<D, O> for Lists<D> {
    fn name(&self) -> &'static str {
        if self.provisional { "neighbour_lists_provisional" } else { "neighbour_lists" }
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let p = &mut s.particles;
        if self.provisional {
            let (x, x_old, dom) = (&p.x, &p.x_old, s.domain);
            let moved = (0..p.fluid)
                .into_par_iter()
                .with_min_len(1024)
                .map(|a| dom.displacement(&x[a], &x_old[a]).norm_squared())
                .reduce(|| 0.0, f64::max);
            if moved.sqrt() <= 0.5 * self.skin {
                return Ok(());
            }
        } else {
            p.x_old.clone_from(&p.x);
            p.u_old.clone_from(&p.u);
        }
        self.search.build_rows(&p.x, p.total(), &mut s.neighbours);
        Ok(())
    }
}

/// MPS.md steps 2–3: the number density `n*` at r* (Lan eq. 9) of every particle and the
/// free-surface flags of the fluid: `n* < β n0`, or with the auxiliary criterion
/// `n* < 0.8 n0`, or `n* ≤ β n0` and `|F| > 0.9 |F|0`. Fills the pair cache at r* that the
/// PPE, the wall pressures and the correction read.
///
/// Boundary particles are never free surface (Koshizuka's code tests type-1 walls too, so
/// that a tank's walls above the water line hold P = 0; no case here has a wall meeting a
/// free surface): their deficit is the domain's edge, not air. Beside an inlet's plate the
/// type-1 walls border the void behind the plate; read as surface they pinned P = 0 two
/// spacings from the inlet corner, and the channel at Re 40 over 3 m diverged there at
/// every spacing (docs/notes/mps.md).
#[derive(Debug)]
pub struct NumberDensity<W: Weight, const D: usize> {
    /// The operators.
    pub ops: Operators<W, D>,
    /// β of the test.
    pub beta: f64,
    /// Use the auxiliary criterion.
    pub auxiliary: bool,
}

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for NumberDensity<W, D> {
    fn name(&self) -> &'static str {
        "number_density"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let (x, list, dom, ops) = (&s.particles.x, &s.neighbours, s.domain, &self.ops);
        let n0 = ops.number_density.n0;
        let (beta, auxiliary) = (self.beta, self.auxiliary);
        let nf = s.particles.fluid;
        let f0 = ops.number_density.surface_f;
        s.pairs.resize(list.pairs(), Pair::default());
        own.density.resize(s.particles.total(), Density::default());
        // The pair cache at r* (`r_ab = r_a − r_b`, `f = |r_ab|`) for every later stage of
        // the step, and each row's number density in the same pass.
        par_rows_mut(
            &list.offsets,
            &mut s.pairs,
            &mut own.density,
            &|i, row: &mut [Pair<D>], out: &mut Density| {
                let (mut sum, mut f) = (0.0, Vector::<D>::zeros());
                for (pair, &j) in row.iter_mut().zip(list.of(i)) {
                    let r_ab = dom.displacement(&x[i], &x[j as usize]);
                    let r = r_ab.norm();
                    *pair = Pair { r_ab, f: r };
                    let w = ops.density_weight(r);
                    sum += w;
                    if auxiliary && w > 0.0 {
                        f += r_ab * (w / r);
                    }
                }
                let surface = if auxiliary {
                    let f = f.norm() * D as f64 / n0;
                    sum < 0.8 * n0 || (sum <= beta * n0 && f > 0.9 * f0)
                } else {
                    sum < beta * n0
                };
                // Only fluid particles: a boundary particle's deficit is the domain's edge.
                *out = Density { n: sum, surface: surface && i < nf };
            },
        );
        s.particles.free_surface.resize(nf, false);
        s.particles.free_surface.iter_mut().zip(&own.density).for_each(|(f, d)| *f = d.surface);
        Ok(())
    }
}

/// MPS.md step 3, Lan eq. 4 with Lee et al.'s mixed source, as `A P = b` with `A` symmetric
/// positive definite: for every fluid and type-1 wall particle off the free surface,
/// `Σ_j a_ij (P_i − P_j) + (ρ α/Δt²) P_i = −(1 − γ)(ρ/Δt)⟨∇·u*⟩_i + γ (ρ/Δt²)(n*_i − n0)/n0`,
/// `a_ij = (2d/(λ n0)) w_ij`. Free-surface particles (P = 0) drop out. Type-2 wall
/// particles are not in the sum (zero flux to them), as Koshizuka's sample code leaves its
/// dummy walls out of the matrix: as known values at their extrapolated pressures they
/// would be Dirichlet conditions a step behind (docs/notes/mps.md, the channel at Re 4).
/// With no free surface the system is singular (grounded by the solver).
#[derive(Debug)]
pub struct PpeAssemble<W: Weight, const D: usize> {
    /// The operators.
    pub ops: Operators<W, D>,
    /// γ of the mixed source.
    pub gamma: f64,
    /// Quasi-compressibility α \[1/Pa\].
    pub compressibility: f64,
    /// Form of the velocity divergence of the source.
    pub divergence: MpsDivergence,
}

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for PpeAssemble<W, D> {
    fn name(&self) -> &'static str {
        "ppe_assemble"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let nf = s.particles.fluid;
        let solved = nf + own.type1;
        let total = s.particles.total();
        let sys = &mut own.ppe;
        sys.row_of.clear();
        sys.row_of.resize(total, u32::MAX);
        sys.particle_of.clear();
        for (i, d) in own.density[..solved].iter().enumerate() {
            if !d.surface {
                sys.row_of[i] = sys.particle_of.len() as u32;
                sys.particle_of.push(i as u32);
            }
        }
        let rows = sys.particle_of.len();
        // Known pressures: the free surface (zero); the quasi-compressibility's diagonal
        // makes the system regular too.
        sys.singular = rows == solved && self.compressibility == 0.0;
        let (u, list, pairs, ops) = (&s.particles.u, &s.neighbours, &s.pairs, &self.ops);
        let (row_of, particle_of, density) = (&sys.row_of, &sys.particle_of, &own.density);
        let m = &mut sys.matrix;
        m.row_ptr.resize(rows + 1, 0);
        m.row_ptr[0] = 0;
        m.row_ptr[1..].par_iter_mut().enumerate().with_min_len(256).for_each(|(k, len)| {
            let i = particle_of[k] as usize;
            let (lo, hi) = (list.offsets[i], list.offsets[i + 1]);
            *len = list.indices[lo..hi]
                .iter()
                .zip(&pairs[lo..hi])
                .filter(|&(&j, pair)| {
                    let rj = row_of[j as usize];
                    rj != u32::MAX && rj != k as u32 && pair.f < ops.re_l
                })
                .count();
        });
        for k in 0..rows {
            m.row_ptr[k + 1] += m.row_ptr[k];
        }
        m.resize_entries();
        let (rho, dt) = (s.density, ctx.dt);
        let (gamma, n0) = (self.gamma, ops.number_density.n0);
        let corrected = self.divergence == MpsDivergence::Corrected;
        let compress = rho * self.compressibility / (dt * dt);
        sys.row_out.resize(rows, [0.0; 2]);
        let row = |k: usize, cols: &mut [u32], vals: &mut [f32], out: &mut [f64; 2]| {
            let i = particle_of[k] as usize;
            let mut diag = compress;
            // Σ (u_j − u_i) ⊗ r_ij w/r² (its trace times d/n0 is Lan's divergence) and the moment.
            let (mut grad_u, mut moment) = (Matrix::<D>::zeros(), Matrix::<D>::zeros());
            let mut e = 0;
            let (lo, hi) = (list.offsets[i], list.offsets[i + 1]);
            for (&j, pair) in list.indices[lo..hi].iter().zip(&pairs[lo..hi]) {
                let (j, r_ij, r) = (j as usize, -pair.r_ab, pair.f);
                let wg = ops.gradient_weight(r);
                if wg > 0.0 {
                    grad_u += (u[j] - u[i]) * r_ij.transpose() * wg;
                    if corrected {
                        moment += r_ij * r_ij.transpose() * wg;
                    }
                }
                if r >= ops.re_l {
                    continue;
                }
                // Rounded as stored, here and in the diagonal (see `CsrMatrix`).
                let c = stored(ops.laplacian_weight(r));
                match row_of[j] {
                    // Free-surface particles hold P = 0.
                    u32::MAX if j < solved => diag += c,
                    // Type-2 walls are not in the Laplacian (zero flux).
                    u32::MAX => {}
                    rj => {
                        diag += c;
                        (cols[e], vals[e]) = (rj, -c as f32);
                        e += 1;
                    }
                }
            }
            let div = if corrected
                && let Some(chol) = moment.cholesky()
                && chol.determinant() > MOMENT_DET_MIN
            {
                (grad_u * chol.inverse()).trace()
            } else {
                grad_u.trace()
            };
            let source = (1.0 - gamma) * rho / dt * div - gamma * rho / (dt * dt) * (density[i].n - n0) / n0;
            *out = [diag, -source];
        };
        par_csr_rows_mut(&m.row_ptr, &mut m.cols, &mut m.vals, &mut sys.row_out, &row);
        sys.finish_rows();
        Ok(())
    }
}

/// Solves the assembled PPE, warm-started from the last pressures; writes P (zero on the
/// free surface), and clips negative pressures when asked (Koshizuka's sample code).
#[derive(Debug)]
pub struct PpeSolve {
    /// The configured solver.
    pub solver: LinearSolver,
    /// Set negative pressures to zero after the solve.
    pub clip_negative: bool,
}

impl<const D: usize> Stage<D, MpsData<D>> for PpeSolve {
    fn name(&self) -> &'static str {
        "ppe_solve"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let nf = s.particles.fluid;
        let sys = &mut own.ppe;
        // Fluid rows are keyed by particle id, wall rows after every fluid id.
        let (id, base) = (&s.particles.id, own.key_base);
        s.solve =
            sys.solve(
                &mut self.solver,
                &s.particles.p,
                |i| if i < nf { id[i] } else { base + (i - nf) as u32 },
            )?;
        let p = &mut s.particles.p;
        let solved = nf + own.type1;
        p[..solved].iter_mut().for_each(|v| *v = 0.0);
        for (v, &i) in sys.solution.iter().zip(&sys.particle_of) {
            p[i as usize] = if self.clip_negative { v.max(0.0) } else { *v };
        }
        Ok(())
    }
}

/// MPS.md step 4: `uⁿ⁺¹ = u* − (Δt/ρ)⟨∇P⟩` at r* over the fluid and wall particles, with
/// Lan's eq. 6, Koshizuka's minimum-pressure form or the corrective matrix; then
/// `rⁿ⁺¹ = r* + Δt (uⁿ⁺¹ − u*)`.
#[derive(Debug)]
pub struct Correction<W: Weight, const D: usize> {
    /// The operators.
    pub ops: Operators<W, D>,
    /// Form of the gradient.
    pub form: MpsGradient,
}

/// Below this determinant of the moment `(d/n0) Σ w r⊗r/|r|²` (1 on the full lattice, about
/// 0.3 at a flat surface in 2D) the corrected gradient falls back to the plain one.
const MOMENT_DET_MIN: f64 = 1e-2;

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for Correction<W, D> {
    fn name(&self) -> &'static str {
        "correction"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, ctx: &StepContext) -> Result<(), Cause> {
        let (dt, nf, dom) = (ctx.dt, s.particles.fluid, s.domain);
        let periodic = dom.is_periodic();
        let (list, pairs, p, ops, form) = (&s.neighbours, &s.pairs, &s.particles.p, &self.ops, self.form);
        let c = dt / s.density;
        // The velocity change of each particle first (the positions are read as neighbours).
        own.du.resize(nf, Vector::zeros());
        own.du.par_iter_mut().enumerate().with_min_len(256).for_each(|(i, du)| {
            let (lo, hi) = (list.offsets[i], list.offsets[i + 1]);
            let row = || list.indices[lo..hi].iter().zip(&pairs[lo..hi]);
            let base = match form {
                MpsGradient::Minimum => {
                    row().fold(p[i], |m, (&j, pair)| if pair.f < ops.re_g { m.min(p[j as usize]) } else { m })
                }
                MpsGradient::Lan | MpsGradient::Corrected => p[i],
            };
            let corrected = form == MpsGradient::Corrected;
            let (mut g, mut m, mut count) = (Vector::<D>::zeros(), Matrix::<D>::zeros(), 0);
            for (&j, pair) in row() {
                let (j, r_ij) = (j as usize, -pair.r_ab);
                let wg = ops.gradient_weight(pair.f);
                if wg == 0.0 {
                    continue;
                }
                g += r_ij * ((p[j] - base) * wg);
                if corrected {
                    m += r_ij * r_ij.transpose() * wg;
                    count += 1;
                }
            }
            // The moment is symmetric: positive definite unless degenerate, its determinant
            // the square of the Cholesky factor's diagonal product.
            if corrected
                && count >= 4
                && let Some(chol) = m.cholesky()
                && chol.determinant() > MOMENT_DET_MIN
            {
                g = chol.solve(&g);
            }
            *du = -g * c;
        });
        // rⁿ⁺¹ = r* + Δt (uⁿ⁺¹ − u*).
        let parts = &mut s.particles;
        let du = &own.du;
        parts.u[..nf]
            .par_iter_mut()
            .zip(parts.x[..nf].par_iter_mut())
            .zip(du.par_iter())
            .with_min_len(512)
            .for_each(|((u, x), du)| {
                *u += du;
                *x += du * dt;
                if periodic {
                    dom.wrap(x);
                }
            });
        Ok(())
    }
}
