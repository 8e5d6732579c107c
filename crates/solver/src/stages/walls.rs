//! Mirror-particle walls (Qiu 2013 §2.4.2): plane no-slip walls at rest represented by
//! the reflections of the fluid particles near them, rebuilt every step.
//!
//! Every fluid particle closer to a wall than the kernel support is reflected across it;
//! a particle near two walls of different axes (a corner) is also reflected across both,
//! as the paper describes. A mirror takes the pressure of its source (the wall is a
//! symmetry plane of p, so `∂p/∂n = 0`) and the velocity `−u` of its source for one
//! reflection (the odd extension that makes `u = 0` on the wall: no slip) or `+u` for two
//! (odd in both axes). The mirrors enter every neighbour sum of the fluid — viscous term,
//! free-surface detection, divergence, the PPE through their source's unknown, pressure
//! gradient and shifting — so the kernel support of a fluid particle near a wall is full.

use crate::error::Cause;
use crate::scene::{Side, Wall};
use crate::stage::{Stage, StepContext};
use crate::state::{State, Vector};

/// Rebuilds the mirror particles at the current (advected) positions; a fluid particle
/// found on the wrong side of a wall is first reflected back into the fluid with its
/// wall-normal velocity reversed (an elastic bounce).
#[derive(Debug)]
pub struct Walls {
    walls: Vec<(usize, f64, f64)>,
    support: f64,
}

impl Walls {
    /// Walls of the scene, mirrored within `support` \[m\] (the kernel support).
    pub fn new(walls: &[Wall], support: f64) -> Self {
        let walls = walls
            .iter()
            .map(|w| (w.axis, w.position, if w.fluid_side == Side::Above { 1.0 } else { -1.0 }))
            .collect();
        Self { walls, support }
    }
}

impl<const D: usize, O> Stage<D, O> for Walls {
    fn name(&self) -> &'static str {
        "walls"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        // Fluid and open-boundary buffers are mirrored (a buffer near a wall needs its
        // mirrors as much as the fluid does).
        let nf = s.walls_start();
        let p = &mut s.particles;
        p.x.truncate(nf);
        p.u.truncate(nf);
        p.p.truncate(nf);
        p.u_old.truncate(nf);
        s.mirrors.source.clear();
        s.mirrors.sign.clear();
        let mut near = [0usize; 3];
        for a in 0..nf {
            let mut k = 0;
            for (w, &(axis, pos, side)) in self.walls.iter().enumerate() {
                let mut d = side * (p.x[a][axis] - pos);
                if d < 0.0 {
                    p.x[a][axis] = 2.0 * pos - p.x[a][axis];
                    p.u[a][axis] = -p.u[a][axis];
                    d = -d;
                }
                if d < self.support && k < near.len() {
                    near[k] = w;
                    k += 1;
                }
            }
            // Every non-empty subset of the near walls with distinct axes.
            for mask in 1u32..(1 << k) {
                let mut x: Vector<D> = p.x[a];
                let mut used = [false; 3];
                let mut distinct = true;
                for (bit, &w) in near[..k].iter().enumerate() {
                    if mask & (1 << bit) != 0 {
                        let (axis, pos, _) = self.walls[w];
                        distinct &= !std::mem::replace(&mut used[axis.min(2)], true);
                        x[axis] = 2.0 * pos - x[axis];
                    }
                }
                if !distinct {
                    continue;
                }
                let sign = if mask.count_ones() % 2 == 1 { -1.0 } else { 1.0 };
                p.x.push(x);
                s.mirrors.source.push(a as u32);
                s.mirrors.sign.push(sign);
            }
        }
        for (&src, &sign) in s.mirrors.source.iter().zip(&s.mirrors.sign) {
            let src = src as usize;
            p.u.push(p.u[src] * sign);
            p.p.push(p.p[src]);
            p.u_old.push(p.u_old[src] * sign);
        }
        Ok(())
    }
}

/// Copies the predicted velocities u* of the fluid onto their mirrors (before the PPE,
/// whose source term reads them).
#[derive(Debug)]
pub struct MirrorVelocity;

impl<const D: usize, O> Stage<D, O> for MirrorVelocity {
    fn name(&self) -> &'static str {
        "mirror_velocity"
    }

    fn run(&mut self, s: &mut State<D>, _own: &mut O, _ctx: &StepContext) -> Result<(), Cause> {
        let u = &mut s.particles.u;
        for (b, source, sign) in s.links.velocity_copies() {
            u[b] = u[source as usize] * sign;
        }
        Ok(())
    }
}
