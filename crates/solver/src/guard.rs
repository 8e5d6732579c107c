//! The end-of-step guard of the run driver: a run that goes unstable stops with a typed
//! cause ([`Cause`]) naming the particle, never a panic or NaN output passed off as a
//! result.

use crate::error::Cause;
use crate::scene::Scene;
use crate::state::{State, Vector};

/// The end-of-step checks of a run ([`Guard::check`]): finite values, the `GuardBox`, no
/// overstep beyond the kernel `support`, the `NeighbourBand`.
#[derive(Debug, Clone, Copy)]
pub struct Guard<const D: usize> {
    guard_box: GuardBox<D>,
    band: NeighbourBand,
    /// Kernel support radius \[m\]: no particle may move farther in one step.
    support: f64,
}

impl<const D: usize> Guard<D> {
    /// The guard of `scene`'s run from its initial `state` with kernel `support` \[m\].
    pub fn new(scene: &Scene, state: &State<D>, support: f64) -> Self {
        let x = &state.particles.x;
        let mut lo = Vector::<D>::repeat(f64::INFINITY);
        let mut hi = Vector::<D>::repeat(f64::NEG_INFINITY);
        for x in x {
            lo = lo.inf(x);
            hi = hi.sup(x);
        }
        let guard_box = GuardBox::new(&scene.body_force, scene.dx, &state.particles.u, lo, hi);
        Self { guard_box, band: NeighbourBand::new::<D>(support, scene.dx), support }
    }

    /// End-of-step checks, in this order of precedence: every position, velocity and
    /// pressure is finite; no particle left the `GuardBox` at `time` \[s\]; no two fluid
    /// neighbours move farther than the kernel support relative to each other in a step of
    /// `dt` \[s\] (the neighbour lists could not follow them: a fixed step far beyond the
    /// CFL limit; Galilean invariant, so a fast but rigid motion passes); no fluid particle has more neighbours than the
    /// `NeighbourBand` allows. The cause names the lowest particle id that failed the
    /// most severe check and how many others failed it too.
    pub fn check(&self, state: &State<D>, time: f64, dt: f64) -> Result<(), Cause> {
        use rayon::prelude::*;
        let p = &state.particles;
        let (lo, hi) = &self.guard_box.at(time);
        let list = &state.neighbours;
        // Rows 0..fluid are the fluid's (dummy walls add rows after them).
        let counted = list.len() >= p.len();
        let limit = self.band.limit;
        let support = self.support;
        // Two fluid particles approach at most at twice the largest speed: when even that
        // cannot cover the support in one step (always at the start of an adaptive step,
        // cfl ≤ 1), the pair scan for an overstep is skipped.
        let scan_pairs = 2.0 * state.max_speed() * dt > support;
        // Severity of particle a's failure (0 = none), most severe first.
        let severity = |a: usize| -> u8 {
            if !p.x[a].iter().all(|v| v.is_finite()) {
                6
            } else if !p.u[a].iter().all(|v| v.is_finite()) {
                5
            } else if !p.p[a].is_finite() {
                4
            } else if (0..D).any(|k| p.x[a][k] < lo[k] || p.x[a][k] > hi[k]) {
                3
            } else if scan_pairs
                && a < list.len()
                && list.of(a).iter().any(|&b| {
                    (b as usize) < p.len()
                        && (p.u[a] - p.u[b as usize]).norm_squared() * dt * dt > support * support
                })
            {
                2
            } else if counted && list.of(a).len() > limit {
                1
            } else {
                0
            }
        };
        // (severity, id of the first particle, particles with that severity)
        let worst =
            (0..p.len()).into_par_iter().map(|a| (severity(a), p.id[a], 1usize)).filter(|w| w.0 > 0).reduce(
                || (0, u32::MAX, 0),
                |x, y| match x.0.cmp(&y.0) {
                    std::cmp::Ordering::Greater => x,
                    std::cmp::Ordering::Less => y,
                    std::cmp::Ordering::Equal => (x.0, x.1.min(y.1), x.2 + y.2),
                },
            );
        let (level, id, n) = worst;
        if level == 0 {
            return Ok(());
        }
        let a = (0..p.len()).find(|&a| p.id[a] == id).unwrap_or(0);
        let (particle, others) = (id as usize, n - 1);
        let vec = |v: &Vector<D>| v.iter().copied().collect::<Vec<f64>>();
        Err(match level {
            6 => Cause::NonFinite { quantity: "position", particle, others },
            5 => Cause::NonFinite { quantity: "velocity", particle, others },
            4 => Cause::NonFinite { quantity: "pressure", particle, others },
            3 => Cause::Escape { particle, position: vec(&p.x[a]), lo: vec(lo), hi: vec(hi), others },
            2 => {
                let speed = |b: &u32| (p.u[a] - p.u[*b as usize]).norm();
                let fluid = list.of(a).iter().copied().filter(|&b| (b as usize) < p.len());
                let b = fluid.max_by(|b, c| speed(b).total_cmp(&speed(c))).unwrap_or(0);
                Cause::Overstep {
                    particle,
                    position: vec(&p.x[a]),
                    neighbour: p.id[b as usize] as usize,
                    speed: speed(&b),
                    dt,
                    support,
                    others,
                }
            }
            _ => Cause::Clumping {
                particle,
                position: vec(&p.x[a]),
                count: list.of(a).len(),
                limit,
                bulk: self.band.bulk,
                others,
            },
        })
    }
}

/// The upper bound of the neighbour-count guard.
///
/// A particle of the initial lattice has `bulk` neighbours within the kernel support: the
/// lattice points `z Δx`, `z ∈ ℤ^D \ {0}`, with `|z| Δx` up to the support (the shell on the
/// support included, as rounding may put it inside): 28 for h = 1.5 Δx in 2D. In an
/// incompressible flow the particle number density stays near its initial value, so a
/// fluid particle with more than `4 × bulk` neighbours
/// means the local spacing has shrunk to half of Δx in 2D (0.63 Δx in 3D): particles are
/// clumping or penetrating each other, which precedes a blow-up (and makes the neighbour
/// lists grow without bound). Zero neighbours is allowed: an isolated splash particle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct NeighbourBand {
    bulk: usize,
    limit: usize,
}

impl NeighbourBand {
    /// The band for kernel `support` \[m\] on a lattice of spacing `dx` in D dimensions.
    fn new<const D: usize>(support: f64, dx: f64) -> Self {
        let r = support / dx;
        let n = r.ceil() as i64;
        let mut bulk = 0usize;
        let mut idx = [-n; D];
        'all: loop {
            let r2: i64 = idx.iter().map(|i| i * i).sum();
            if r2 > 0 && (r2 as f64).sqrt() <= r * (1.0 + 1e-9) {
                bulk += 1;
            }
            for i in idx.iter_mut() {
                if *i < n {
                    *i += 1;
                    continue 'all;
                }
                *i = -n;
            }
            break;
        }
        Self { bulk, limit: 4 * bulk.max(1) }
    }
}

/// The box a particle must stay in: the initial bounding box enlarged on every side by
/// four times its largest size (at least 10 Δx), or, if larger, by twice the distance a
/// particle could have coasted by time t, `2 (|u|_max,0 t + |g| t²/2)`. A free body spun
/// fast (`rotating_square`: 70 m/s at the corners) legitimately flings fluid far beyond
/// four times its size; leaving the box faster than that is a blow-up.
#[derive(Debug, Clone, Copy)]
struct GuardBox<const D: usize> {
    lo: Vector<D>,
    hi: Vector<D>,
    /// Fixed margin \[m\].
    margin: f64,
    /// Largest initial speed \[m/s\].
    speed: f64,
    /// |g| \[m/s²\].
    accel: f64,
}

impl<const D: usize> GuardBox<D> {
    fn new(body_force: &[f64], dx: f64, u: &[Vector<D>], lo: Vector<D>, hi: Vector<D>) -> Self {
        let accel = body_force.iter().map(|g| g * g).sum::<f64>().sqrt();
        let speed = u.iter().map(|u| u.norm()).fold(0.0, f64::max);
        Self { lo, hi, margin: 4.0 * (hi - lo).max().max(10.0 * dx), speed, accel }
    }

    /// The box's corners at time `t` \[s\].
    fn at(&self, t: f64) -> (Vector<D>, Vector<D>) {
        let m = self.margin.max(2.0 * (self.speed * t + 0.5 * self.accel * t * t));
        (self.lo.add_scalar(-m), self.hi.add_scalar(m))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bulk_neighbour_count_of_the_lattice() {
        // Lattice points within 3 Δx (cubic spline, h = 1.5 Δx): |z|² ∈ {1, 2, 4, 5, 8, 9}.
        assert_eq!(NeighbourBand::new::<2>(3.0, 1.0), NeighbourBand { bulk: 28, limit: 112 });
        assert_eq!(NeighbourBand::new::<2>(0.3, 0.1).bulk, 28);
        // h = Δx: |z|² ∈ {1, 2, 4} in 2D; in 3D |z|² ∈ {1, 2, 3, 4}: 6 + 12 + 8 + 6.
        assert_eq!(NeighbourBand::new::<2>(2.0, 1.0).bulk, 12);
        assert_eq!(NeighbourBand::new::<3>(2.0, 1.0).bulk, 32);
    }
}
