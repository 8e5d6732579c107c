//! Neighbour stage: cell-list search and the pair cache.

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::neighbours::CellSearch;
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
/// `free_surface` stage to threshold.
#[derive(Debug)]
pub struct Neighbours<K: Kernel, const D: usize> {
    search: CellSearch<D>,
    kernel: Scaled<K, D>,
    rows: Rows,
    div_r: bool,
}

impl<K: Kernel, const D: usize> Neighbours<K, D> {
    /// A stage for `kernel` in `domain`; search radius = kernel support.
    pub fn new(kernel: Scaled<K, D>, domain: crate::neighbours::Domain<D>, rows: Rows) -> Self {
        Self { search: CellSearch::new(kernel.support, domain), kernel, rows, div_r: false }
    }

    /// Also sums `div r_a = −Σ_b V_b r_ab · ∇_a W_ab` into `Particles::div_r` (one pass
    /// over the pairs fewer than a separate sum; docs/notes/performance.md).
    pub fn summing_div_r(mut self) -> Self {
        self.div_r = true;
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
        par_rows_mut(
            &list.offsets,
            &mut s.pairs,
            &mut s.particles.div_r,
            &|a, row: &mut [Pair<D>], d: &mut f64| {
                for (pair, &b) in row.iter_mut().zip(list.of(a)) {
                    let r_ab = dom.displacement(&x[a], &x[b as usize]);
                    let r2 = r_ab.norm_squared();
                    *pair = Pair { r_ab, f: k.grad_factor(r2.sqrt()) };
                }
                if div_r {
                    // r_ab · ∇_a W_ab = f r².
                    *d = -v * row.iter().map(|p| p.f * p.r2()).sum::<f64>();
                }
            },
        );
        Ok(())
    }
}
