//! Reordering of the fluid particles by cell, for memory locality of the neighbour loops.

use crate::error::Cause;
use crate::fields::{Fields, PermuteScratch, permute};
use crate::neighbours::{CellSearch, Domain};
use crate::stage::{Stage, StepContext};
use crate::state::State;

/// Every `every` steps (from the first), permutes the fluid particles into cell order:
/// every declared per-particle field, the shared ones and the scheme's own
/// ([`crate::fields`]).
/// Boundary particles are rebuilt after it (the wall stage comes later in the step), so
/// their sources always index the current order.
#[derive(Debug)]
pub struct Reorder<const D: usize> {
    search: CellSearch<D>,
    every: usize,
    calls: usize,
    scratch: PermuteScratch<D>,
}

impl<const D: usize> Reorder<D> {
    /// Reorders every `every` steps on cells of size `cell` \[m\] (the kernel support).
    pub fn new(cell: f64, domain: Domain<D>, every: usize) -> Self {
        Self {
            search: CellSearch::new(cell, domain),
            every: every.max(1),
            calls: 0,
            scratch: PermuteScratch::default(),
        }
    }
}

impl<const D: usize, O: Fields<D>> Stage<D, O> for Reorder<D> {
    fn name(&self) -> &'static str {
        "reorder"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        if self.calls.is_multiple_of(self.every) {
            let perm = self.search.cell_order(&s.particles.x[..s.particles.fluid]);
            permute(&mut s.particles, perm, &mut self.scratch);
            permute(own, perm, &mut self.scratch);
        }
        self.calls += 1;
        Ok(())
    }
}
