//! The free-surface pressure condition placed at the surface instead of on the particles
//! (`scheme.isph.free_surface_pressure: extrapolated`, ISPH only).
//!
//! Qiu 2013 (eq. 16) sets `p = 0` on the free-surface particles, which sit about Δx/2
//! inside the surface of the volume they represent: the pressure field is then that of a
//! body Δx/2 smaller, an O(Δx) error wherever the pressure has a normal gradient at the
//! surface (the elliptical drop: `|∇p| ≈ ρ A0² R` there). This stage puts the zero at
//! the surface: with `n̂_a` the unit colour-gradient normal into the fluid
//! (`Σ_b V_b ∇_aW_ab`, as in `stages::young_laplace`) and `∇p_a` the previous step's
//! pressure gradient (the kernel-corrected difference form `L_a Σ_b V_b (p_b − p_a)
//! ∇_aW_ab`, with the step's correction `L_a` of `stages::neighbours`, which the scene
//! rules make sure is inverted), each free-surface particle carries the linear
//! extrapolation `p_a = (Δx/2) n̂_a·∇p_a` \[Pa\] as its Dirichlet value. It runs before the
//! Young–Laplace stage, which then adds `σ κ` (the pressure at the surface).
//! The value is lagged by one step (it reads `pⁿ`), so the PPE keeps its symmetric matrix.
//!
//! Where there is nothing to extrapolate along — a colour gradient below
//! [`MIN_COLOUR`]` / h` (a gap between particle lines, not a surface) or a correction that
//! is singular or larger than [`MAX_CORRECTION`] (a splash of a few particles) — the particle
//! keeps Qiu's `p = 0`.

use crate::error::Cause;
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// Smallest `|Σ_b V_b ∇_aW_ab| h` along which a surface particle's pressure is
/// extrapolated: 0.62 on a flat lattice surface row (cubic spline, h = 1.5–2 Δx), 0.14–0.30
/// on the row beneath it, 0 between symmetric particle lines.
pub const MIN_COLOUR: f64 = 0.1;

/// Largest Frobenius norm of the kernel-gradient correction `L_a` trusted for the
/// gradient (about 2.2 on a flat surface row; the shifting's Taylor correction uses the
/// same bound).
pub const MAX_CORRECTION: f64 = 10.0;

/// The extrapolated free-surface pressure stage (see the module documentation).
#[derive(Debug, Default)]
pub struct SurfaceExtrapolation {
    /// The new free-surface values \[Pa\], written to `p` after they are all computed from
    /// the previous pressure.
    value: Vec<f64>,
}

impl<const D: usize, O> Stage<D, O> for SurfaceExtrapolation {
    fn name(&self) -> &'static str {
        "surface_extrapolation"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let nf = s.particles.fluid;
        let (list, pairs, moments) = (&s.neighbours, &s.pairs, &s.moments);
        let (p, fs, v, half, h) = (&s.particles.p, &s.particles.free_surface, s.volume, 0.5 * s.dx, s.h);
        self.value.resize(nf, 0.0);
        self.value.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, out)| {
            *out = 0.0;
            if !fs[a] {
                return;
            }
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let (mut colour, mut grad) = (Vector::<D>::zeros(), Vector::<D>::zeros());
            for (pr, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                let dw = pr.r_ab * (pr.f * v);
                colour += dw;
                grad += dw * (p[b as usize] - p[a]);
            }
            let norm = colour.norm();
            match moments.get(a) {
                Some(Some(l)) if l.norm() <= MAX_CORRECTION && norm * h >= MIN_COLOUR => {
                    let dpdn = (l * grad).dot(&colour) / norm;
                    if dpdn.is_finite() {
                        *out = half * dpdn;
                    }
                }
                _ => {}
            }
        });
        for (a, value) in self.value.iter().enumerate() {
            if fs[a] {
                s.particles.p[a] = *value;
            }
        }
        Ok(())
    }
}
