//! The kernel-gradient correction of the step: `L_a = M_a⁻¹` of every fluid particle from
//! the step's pairs ([`crate::operators::moment`]), computed once for all the stages
//! that correct a gradient (the corrected PPE divergence, the corrected pressure gradient,
//! the shifting's Taylor correction of u).

use crate::error::Cause;
use crate::operators::moment;
use crate::stage::{Stage, StepContext};
use crate::state::State;
use rayon::prelude::*;

/// Fills `State::moments` (`None` where `M_a` is singular); built only when a stage of the
/// scheme reads it.
#[derive(Debug)]
pub struct Moments;

impl<const D: usize, O> Stage<D, O> for Moments {
    fn name(&self) -> &'static str {
        "moments"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let (list, pairs, v) = (&s.neighbours, &s.pairs, s.volume);
        s.moments.resize(s.particles.fluid, None);
        s.moments.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, m)| {
            *m = moment(&pairs[list.offsets[a]..list.offsets[a + 1]], v).try_inverse();
        });
        Ok(())
    }
}
