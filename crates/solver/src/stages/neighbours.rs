//! Neighbour stage: cell-list search and the pair cache.

use crate::error::Cause;
use crate::fields::Matrix;
use crate::kernel::{Kernel, Scaled};
use crate::neighbours::CellSearch;
use crate::operators::moment;
use crate::stage::{Stage, StepContext, par_rows_mut};
use crate::state::{Pair, State};

/// Which particles get a neighbour row (every particle is found as a neighbour).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rows {
    /// The fluid only.
    Fluid,
    /// Every particle (dummy walls extrapolate from their fluid neighbours).
    All,
}

/// Rebuilds the neighbour lists at the current positions (rows for the particles `rows`
/// selects; their neighbours include boundary particles) and fills the pair cache (`r_ab`
/// and `W'(r)/r`); with [`Neighbours::summing_div_r`], also `div r` (Qiu 2013 eq. 16 as
/// corrected by CASES.md erratum 3) while each row's pairs are in cache, for the
/// `free_surface` stage to threshold; with [`Neighbours::inverting_moments`], also the
/// kernel-gradient correction `L_a = M_a⁻¹` of every fluid particle.
#[derive(Debug)]
pub struct Neighbours<K: Kernel, const D: usize> {
    search: CellSearch<D>,
    kernel: Scaled<K, D>,
    rows: Rows,
    div_r: bool,
    moments: bool,
    /// Each row's `div r` and `L_a`, when the moments are asked for.
    sums: Vec<(f64, Option<Matrix<D>>)>,
}

impl<K: Kernel, const D: usize> Neighbours<K, D> {
    /// A stage for `kernel` in `domain`; search radius = kernel support.
    pub fn new(kernel: Scaled<K, D>, domain: crate::neighbours::Domain<D>, rows: Rows) -> Self {
        Self {
            search: CellSearch::new(kernel.support, domain),
            kernel,
            rows,
            div_r: false,
            moments: false,
            sums: Vec::new(),
        }
    }

    /// Also sums `div r_a = −Σ_b V_b r_ab · ∇_a W_ab` into `Particles::div_r` (one pass
    /// over the pairs fewer than a separate sum; docs/notes/performance.md).
    pub fn summing_div_r(mut self) -> Self {
        self.div_r = true;
        self
    }

    /// Also inverts the moment matrix of every fluid particle into `State::moments`
    /// ([`crate::operators::moment`], Bonet & Lok 1999 eq. 43): once per step, in the pass
    /// that makes the pairs, for every stage that corrects a gradient.
    pub fn inverting_moments(mut self) -> Self {
        self.moments = true;
        self
    }
}

impl<K: Kernel, const D: usize, O> Stage<D, O> for Neighbours<K, D> {
    fn name(&self) -> &'static str {
        "neighbours"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let rows = match self.rows {
            Rows::Fluid => s.particles.fluid,
            Rows::All => s.particles.total(),
        };
        self.search.build_rows(&s.particles.x, rows, &mut s.neighbours);
        let n_pairs = s.neighbours.pairs();
        s.pairs.resize(n_pairs, Pair::default());
        let (x, list, dom, k, v, div_r) =
            (&s.particles.x, &s.neighbours, s.domain, self.kernel, s.volume, self.div_r);
        s.particles.div_r.resize(rows, 0.0);
        let fill = |a: usize, row: &mut [Pair<D>]| {
            for (pair, &b) in row.iter_mut().zip(list.of(a)) {
                let r_ab = dom.displacement(&x[a], &x[b as usize]);
                let r2 = r_ab.norm_squared();
                *pair = Pair { r_ab, f: k.grad_factor(r2.sqrt()) };
            }
        };
        // r_ab · ∇_a W_ab = f r².
        let div_r_of = |row: &[Pair<D>]| -v * row.iter().map(|p| p.f * p.r2()).sum::<f64>();
        if !self.moments {
            par_rows_mut(
                &list.offsets,
                &mut s.pairs,
                &mut s.particles.div_r,
                &|a, row: &mut [Pair<D>], d: &mut f64| {
                    fill(a, row);
                    if div_r {
                        *d = div_r_of(row);
                    }
                },
            );
            return Ok(());
        }
        let fluid = s.particles.fluid;
        self.sums.resize(rows, (0.0, None));
        par_rows_mut(
            &list.offsets,
            &mut s.pairs,
            &mut self.sums,
            &|a, row: &mut [Pair<D>], out: &mut (f64, Option<Matrix<D>>)| {
                fill(a, row);
                if div_r {
                    out.0 = div_r_of(row);
                }
                out.1 = if a < fluid { moment(row, v).try_inverse() } else { None };
            },
        );
        if div_r {
            s.particles.div_r.iter_mut().zip(&self.sums).for_each(|(d, sum)| *d = sum.0);
        }
        s.moments.clear();
        s.moments.extend(self.sums[..fluid].iter().map(|sum| sum.1));
        Ok(())
    }
}
