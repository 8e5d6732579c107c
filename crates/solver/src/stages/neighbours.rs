//! Neighbour stage: cell-list search, reordering by cell, and the pair cache.

use crate::error::Cause;
use crate::kernel::{Kernel, Scaled};
use crate::neighbours::CellSearch;
use crate::stage::{Stage, StepContext, par_rows_mut};
use crate::state::{Pair, State};

/// Rebuilds the neighbour lists at the current positions and fills the pair cache
/// (`r_ab`, `r²`, `W'(r)/r`). Every `reorder_every` calls the particles are first
/// reordered by cell for memory locality.
#[derive(Debug)]
pub struct Neighbours<K: Kernel, const D: usize> {
    search: CellSearch<D>,
    kernel: Scaled<K, D>,
    reorder_every: usize,
    calls: usize,
}

impl<K: Kernel, const D: usize> Neighbours<K, D> {
    /// A stage for `kernel` in `domain`; search radius = kernel support.
    pub fn new(kernel: Scaled<K, D>, domain: crate::neighbours::Domain<D>, reorder_every: usize) -> Self {
        Self { search: CellSearch::new(kernel.support, domain), kernel, reorder_every, calls: 0 }
    }
}

impl<K: Kernel, const D: usize> Stage<D> for Neighbours<K, D> {
    fn name(&self) -> &'static str {
        "neighbours"
    }

    fn run(&mut self, s: &mut State<D>, _ctx: &StepContext) -> Result<(), Cause> {
        if self.reorder_every > 0 && self.calls.is_multiple_of(self.reorder_every) {
            let perm = self.search.cell_order(&s.particles.x);
            s.permute(&perm);
        }
        self.calls += 1;
        self.search.build(&s.particles.x, &mut s.neighbours);
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
