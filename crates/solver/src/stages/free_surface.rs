//! Free-surface detection (Qiu 2013 eq. 16, corrected as CASES.md erratum 3):
//! `div r_a = −Σ_b V_b r_ab · ∇_a W_ab`, ≈ D in the bulk; free surface where it is below
//! the threshold (1.5 in 2D, Lee et al. 2008).

use crate::error::Cause;
use crate::stage::{Stage, StepContext};
use crate::state::State;
use rayon::prelude::*;

/// Sets the free-surface flags from `div r`, which the `neighbours` stage of this step summed
/// in its pair pass ([`crate::stages::neighbours::Neighbours::summing_div_r`]) while each
/// row's pairs were in cache.
#[derive(Debug)]
pub struct FreeSurface {
    /// Threshold on `div r`.
    pub threshold: f64,
}

impl<const D: usize, O> Stage<D, O> for FreeSurface {
    fn name(&self) -> &'static str {
        "free_surface"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let n = s.particles.len();
        s.particles.div_r.resize(n, 0.0);
        s.particles.free_surface.resize(n, false);
        let t = self.threshold;
        s.particles
            .free_surface
            .par_iter_mut()
            .zip(&s.particles.div_r)
            .with_min_len(1024)
            .for_each(|(fs, d)| *fs = *d < t);
        Ok(())
    }
}
