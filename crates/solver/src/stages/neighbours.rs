//! Neighbour stage: cell-list search and the pair cache.

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::neighbours::CellSearch;
use crate::stage::{Stage, StepContext, par_rows_mut};
use crate::state::{Pair, State};

/// Rebuilds the neighbour lists of the fluid particles at the current positions (their
/// neighbours include boundary particles; dummy wall particles get rows too) and fills the pair cache (`r_ab`, `r²`,
/// `W'(r)/r`).
#[derive(Debug)]
pub struct Neighbours<K: Kernel, const D: usize> {
    search: CellSearch<D>,
    kernel: Scaled<K, D>,
    boundary_rows: bool,
}

impl<K: Kernel, const D: usize> Neighbours<K, D> {
    /// A stage for `kernel` in `domain`; search radius = kernel support. With
    /// `boundary_rows` the boundary particles get neighbour rows too (dummy walls
    /// extrapolate from their fluid neighbours).
    pub fn new(kernel: Scaled<K, D>, domain: crate::neighbours::Domain<D>, boundary_rows: bool) -> Self {
        Self { search: CellSearch::new(kernel.support, domain), kernel, boundary_rows }
    }
}

impl<K: Kernel, const D: usize> Stage<D> for Neighbours<K, D> {
    fn name(&self) -> &'static str {
        "neighbours"
    }

    fn run(&mut self, s: &mut State<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let rows = if self.boundary_rows { s.particles.total() } else { s.particles.fluid };
        self.search.build_rows(&s.particles.x, rows, &mut s.neighbours);
        let n_pairs = s.neighbours.pairs();
        s.pairs.resize(n_pairs, Pair::default());
        let (x, list, dom, k) = (&s.particles.x, &s.neighbours, s.domain, self.kernel);
        par_rows_mut(&list.offsets, &mut s.pairs, &|a, row: &mut [Pair<D>]| {
            for (pair, &b) in row.iter_mut().zip(list.of(a)) {
                let r_ab = dom.displacement(&x[a], &x[b as usize]);
                let r2 = r_ab.norm_squared();
                *pair = Pair { r_ab, r2, f: k.grad_factor(r2.sqrt()) };
            }
        });
        Ok(())
    }
}
