//! The boundary map of the step ([`crate::boundary_map`]), rebuilt once the wall mirrors
//! and the inlet's pressure sources of the step are known.

use crate::error::Cause;
use crate::stage::{Stage, StepContext};
use crate::state::State;

/// Rebuilds `State::links` from this step's mirrors (`walls`) and inlet sources
/// (`inlet_sources`); built for scenes with walls or open boundaries.
#[derive(Debug)]
pub struct BoundaryLinks;

impl<const D: usize, O> Stage<D, O> for BoundaryLinks {
    fn name(&self) -> &'static str {
        "boundary_links"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let layout = (s.particles.fluid, s.particles.total(), s.walls_start());
        s.links.rebuild(layout, &s.inlet.source, &s.mirrors.source, &s.mirrors.sign);
        Ok(())
    }
}
