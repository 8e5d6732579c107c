//! Free-surface detection (Qiu 2013 eq. 16, corrected as CASES.md erratum 3):
//! `div r_a = −Σ_b V_b r_ab · ∇_a W_ab`, ≈ D in the bulk; free surface where it is below
//! the threshold (1.5 in 2D, Lee et al. 2008).

use crate::error::Cause;
use crate::stage::{Stage, StepContext};
use crate::state::State;
use rayon::prelude::*;

/// Computes `div r` and the free-surface flags.
#[derive(Debug)]
pub struct FreeSurface {
    /// Threshold on `div r`.
    pub threshold: f64,
    /// `div r` was summed by the `neighbours` stage of this step
    /// ([`crate::stages::neighbours::Neighbours::summing_div_r`]): only the flags are set here.
    pub summed: bool,
}

impl<const D: usize> Stage<D> for FreeSurface {
    fn name(&self) -> &'static str {
        "free_surface"
    }

    fn run(&mut self, s: &mut State<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let n = s.particles.len();
        s.div_r.resize(n, 0.0);
        s.free_surface.resize(n, false);
        let (v, list, pairs, t) = (s.volume, &s.neighbours, &s.pairs, self.threshold);
        if self.summed {
            s.free_surface.par_iter_mut().zip(&s.div_r).with_min_len(1024).for_each(|(fs, d)| *fs = *d < t);
            return Ok(());
        }
        s.div_r.par_iter_mut().zip(s.free_surface.par_iter_mut()).enumerate().with_min_len(256).for_each(
            |(a, (d, fs))| {
                let row = &pairs[list.offsets[a]..list.offsets[a + 1]];
                // r_ab · ∇_a W_ab = f r².
                *d = -v * row.iter().map(|p| p.f * p.r2()).sum::<f64>();
                *fs = *d < t;
            },
        );
        Ok(())
    }
}
