//! MPS walls (Lan 2022 §1.7; MPS.md "Walls"): fixed wall particles on the fluid's lattice
//! behind each wall plane, deep enough to cover the Laplacian radius. Type 1, within the
//! gradient radius of the first fluid layer, are unknowns of the PPE (their pressure
//! pushes the fluid off the wall through the gradient); type 2, the outer layers, only
//! complete the number density of their neighbours (they are not in the PPE, as the dummy
//! walls of Koshizuka's sample code), their pressure extrapolated after each solve
//! ([`WallPressure`]) for the gradient of a fluid particle that comes within reach. The
//! no-slip viscous term does not use them: it mirrors the fluid across the plane
//! ([`Mirror`], Lan Fig. 2).

use super::MpsData;
use super::operators::Operators;
use super::weight::Weight;
use crate::error::Cause;
use crate::scene::{Side, Wall};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};
use rayon::prelude::*;

/// The wall particles of `walls` for the fluid at `fluid` (lattice spacing `l0`):
/// positions, type 1 first, and the number of type-1 particles. `depth` \[m\] is the
/// Laplacian radius, `type1_depth` \[m\] the depth behind the plane within which a wall
/// particle is of type 1.
pub fn wall_particles<const D: usize>(
    walls: &[Wall],
    domain: &crate::neighbours::Domain<D>,
    fluid: &[Vector<D>],
    l0: f64,
    depth: f64,
    type1_depth: f64,
) -> (Vec<Vector<D>>, usize) {
    let layers = crate::stages::dummy::dummy_layers(walls, domain, fluid, l0, depth);
    let behind = |x: &Vector<D>| {
        walls.iter().map(|w| -Mirror::side(w) * (x[w.axis] - w.position)).fold(f64::NEG_INFINITY, f64::max)
    };
    let (mut type1, type2): (Vec<_>, Vec<_>) = layers.into_iter().partition(|x| behind(x) < type1_depth);
    let n1 = type1.len();
    type1.extend(type2);
    (type1, n1)
}

/// The no-slip images of the viscous term: a fluid particle `j` within the Laplacian
/// radius of particle `i`'s side of a wall has an image across the plane with velocity
/// `−u_j` (both components; Lan Fig. 2). An image is never nearer to `i` than `j` itself
/// (`(d_i + d_j)² ≥ (d_i − d_j)²` for particles on the fluid side), so `i`'s neighbour
/// list (and `i`) hold every `j` whose image counts. Corners (images across two walls) are
/// not built: the cases' walls are parallel. The wall particles themselves are laid once,
/// over the initial fluid's extent plus the Laplacian radius: a flow that spreads along a
/// wall beyond it (a dam break) would find no wall particles there.
#[derive(Debug, Clone)]
pub struct Mirror {
    walls: Vec<Wall>,
}

impl Mirror {
    /// The images of `walls`.
    pub fn new(walls: &[Wall]) -> Self {
        Self { walls: walls.to_vec() }
    }

    /// +1 when the fluid is above the plane, −1 below.
    fn side(w: &Wall) -> f64 {
        if w.fluid_side == Side::Above { 1.0 } else { -1.0 }
    }

    /// Calls `f(|r_ij'|²)` for the image `j'` of `j` across every wall near `i`, with
    /// `r_ij = r_j − r_i` (minimum image) and `reach` \[m\] the largest distance that counts.
    #[inline]
    pub fn images<const D: usize>(
        &self,
        x_i: &Vector<D>,
        x_j: &Vector<D>,
        r_ij: &Vector<D>,
        reach: f64,
        mut f: impl FnMut(f64),
    ) {
        for w in &self.walls {
            let s = Self::side(w);
            let (d_i, d_j) = (s * (x_i[w.axis] - w.position), s * (x_j[w.axis] - w.position));
            // Every image is at least d_i away.
            if d_i >= reach {
                continue;
            }
            // Tangential part kept, normal part d_i + d_j across the plane.
            let r2 = r_ij.norm_squared() - r_ij[w.axis] * r_ij[w.axis] + (d_i + d_j) * (d_i + d_j);
            if r2 < reach * reach {
                f(r2);
            }
        }
    }

    /// True when there is no wall.
    pub fn is_empty(&self) -> bool {
        self.walls.is_empty()
    }
}

/// Type-2 wall pressures after the solve (MPS.md "Walls"): the number-density-weighted
/// average over the fluid and type-1 neighbours of `P_j + ρ g·(r_k − r_j)` (the
/// hydrostatic difference to the wall particle); zero with no such neighbour.
#[derive(Debug)]
pub struct WallPressure<W: Weight, const D: usize> {
    /// The operators (the number-density radius weights the average).
    pub ops: Operators<W, D>,
    /// Body force per unit mass \[m/s²\].
    pub g: Vector<D>,
}

impl<W: Weight, const D: usize> Stage<D, MpsData<D>> for WallPressure<W, D> {
    fn name(&self) -> &'static str {
        "wall_pressure"
    }

    fn run(&mut self, s: &mut State<D>, own: &mut MpsData<D>, _ctx: &StepContext) -> Result<(), Cause> {
        let start = s.particles.fluid + own.type1;
        let (list, pairs, rho, g, ops) = (&s.neighbours, &s.pairs, s.density, self.g, &self.ops);
        let (p_all, type2) = s.particles.p.split_at_mut(start);
        let p_solved = &*p_all;
        type2.par_iter_mut().enumerate().with_min_len(256).for_each(|(k, pk)| {
            let a = start + k;
            let (mut sum, mut wsum) = (0.0, 0.0);
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            for (&b, pair) in list.indices[lo..hi].iter().zip(&pairs[lo..hi]) {
                let b = b as usize;
                if b >= start {
                    continue;
                }
                // r_k − r_j (the pair cache of this step's positions).
                let r_kj = pair.r_ab;
                let w = ops.density_weight(pair.f);
                sum += w * (p_solved[b] + rho * g.dot(&r_kj));
                wsum += w;
            }
            *pk = if wsum > 0.0 { sum / wsum } else { 0.0 };
        });
        Ok(())
    }
}
