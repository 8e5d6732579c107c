//! The OTM time step on a 2D body (OTM.md "Time step"; Li, Habbal & Ortiz 2010; Zhou et
//! al. 2021 §2.4), weakly compressible with Newtonian viscosity and surface tension:
//!
//! 1. the nodes within the LME support of each material point (a cell search);
//! 2. the shape functions `N_a(x_p)`, `∇N_a(x_p)` ([`super::lme`], warm-started from the
//!    point's last `λ`);
//! 3. lumped nodal masses `m_a = Σ_p m_p N_a(x_p)`;
//! 4. nodal forces `f_a = −Σ_p V_p σ_p ∇N_a(x_p) + Σ_p m_p g N_a(x_p) + f_a^γ`, with
//!    `σ_p = −p_p I + μ (∇v + ∇vᵀ)_p`, `∇v_p = Σ_a v_a ⊗ ∇N_a(x_p)` and the surface
//!    tension of the boundary polyline ([`super::surface`]);
//! 5. `v_a += Δt f_a / m_a`, `x_a += Δt v_a`;
//! 6. the points follow the nodal map, `x_p = Σ_a N_a(x_p) x_a`; the volume update
//!    `V_p ← det(ΔF_p) V_p` with `ΔF_p = Σ_a x_a ⊗ ∇N_a(x_p)` (new nodal positions, old
//!    shape functions); `ρ_p = m_p / V_p` and the equation of state `p = c₀² (ρ − ρ₀)`
//!    (OTM.md: Zhou's form is lost; this is the weakly compressible one it names).
//!
//! Lengths per unit depth: areas \[m²\], masses \[kg/m\], forces \[N/m\].

use super::lme::{LmeError, LmeParams, shape_functions};
use super::mesh::{Mesh, Point};
use crate::error::Cause;
use nalgebra::Matrix2;

/// Physical and numerical parameters of an OTM body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OtmParams {
    /// Reference density ρ₀ \[kg/m³\].
    pub density: f64,
    /// Sound speed c₀ of the equation of state \[m/s\].
    pub sound_speed: f64,
    /// Dynamic viscosity μ \[Pa s\].
    pub viscosity: f64,
    /// Surface tension γ \[N/m\] (0: none).
    pub surface_tension: f64,
    /// Body force per unit mass \[m/s²\].
    pub gravity: Point,
    /// The shape functions' parameters.
    pub lme: LmeParams,
    /// Weights below this are outside a point's support (OTM.md: 1e-6).
    pub support_tolerance: f64,
}

/// A 2D OTM body: nodes (positions, velocities; the boundary polyline) and material
/// points (positions, masses, volumes, pressures, the LME multipliers).
#[derive(Debug, Clone)]
pub struct Body {
    /// Parameters.
    pub params: OtmParams,
    /// Nodal spacing h \[m\] (the LME locality `β = γ / h²`).
    pub h: f64,
    /// Node positions \[m\].
    pub nodes: Vec<Point>,
    /// Node velocities \[m/s\].
    pub velocity: Vec<Point>,
    /// The boundary nodes, a closed counter-clockwise polyline.
    pub boundary: Vec<usize>,
    /// Material point positions \[m\].
    pub points: Vec<Point>,
    /// Material point masses \[kg/m\].
    pub mass: Vec<f64>,
    /// Material point volumes (areas) \[m²\].
    pub volume: Vec<f64>,
    /// Material point pressures \[Pa\].
    pub pressure: Vec<f64>,
    /// Each point's LME multiplier `λ*` \[1/m\] (the next solve's start).
    lambda: Vec<Point>,
    /// Point `p`'s nodes are `support[offsets[p]..offsets[p + 1]]`, with their shape
    /// function values and gradients alongside.
    offsets: Vec<usize>,
    support: Vec<usize>,
    n: Vec<f64>,
    grad_n: Vec<Point>,
    /// Scratch: nodal masses \[kg/m\] and forces \[N/m\].
    nodal_mass: Vec<f64>,
    force: Vec<Point>,
}

/// Why a step failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum OtmError {
    /// A material point has no shape functions (it left its nodes' hull).
    #[error("material point {point}: {source}")]
    Shape {
        /// The point's index.
        point: usize,
        /// The LME failure.
        source: LmeError,
    },
    /// A material point's volume stopped being positive (the map folded).
    #[error("material point {point}: volume {volume:e} m² after the update (det ΔF = {det:e})")]
    Inverted {
        /// The point's index.
        point: usize,
        /// Its new volume.
        volume: f64,
        /// det ΔF.
        det: f64,
    },
}

impl OtmError {
    /// The failing material point and what happened to it, for the solver's [`Cause::Otm`].
    pub fn cause(self) -> Cause {
        match self {
            OtmError::Shape { point, source } => Cause::Otm { point, reason: source.to_string() },
            OtmError::Inverted { point, volume, det } => Cause::Otm {
                point,
                reason: format!(
                    "volume {volume:e} m² after the update (det ΔF = {det:e}): the nodal map folded"
                ),
            },
        }
    }
}

impl Body {
    /// A body at rest from `mesh` with nodal spacing `h` \[m\]: one material point per
    /// triangle at its centroid, mass `ρ₀ × area`, pressure 0.
    pub fn new(mesh: &Mesh, h: f64, params: OtmParams) -> Self {
        let (points, volume): (Vec<Point>, Vec<f64>) = mesh.material_points().into_iter().unzip();
        let np = points.len();
        Body {
            params,
            h,
            nodes: mesh.nodes.clone(),
            velocity: vec![Point::zeros(); mesh.nodes.len()],
            boundary: mesh.boundary.clone(),
            mass: volume.iter().map(|v| v * params.density).collect(),
            volume,
            pressure: vec![0.0; np],
            points,
            lambda: vec![Point::zeros(); np],
            offsets: Vec::new(),
            support: Vec::new(),
            n: Vec::new(),
            grad_n: Vec::new(),
            nodal_mass: vec![0.0; mesh.nodes.len()],
            force: vec![Point::zeros(); mesh.nodes.len()],
        }
    }

    /// The material points' velocities \[m/s\]: `Σ_a N_a(x_p) v_a` with the shape functions
    /// of the last step (those that moved the points), the nodes' velocities now.
    pub fn point_velocities(&self) -> impl Iterator<Item = Point> + '_ {
        (0..self.points.len()).map(|p| {
            (self.offsets[p]..self.offsets[p + 1]).map(|k| self.velocity[self.support[k]] * self.n[k]).sum()
        })
    }

    /// The support radius \[m\] of the shape functions.
    fn radius(&self) -> f64 {
        self.params.lme.cutoff(self.h, self.params.support_tolerance)
    }

    /// Steps 1–2: each point's nodes within the support (a uniform cell grid of the
    /// support's size) and their shape functions.
    fn shape_functions(&mut self) -> Result<(), OtmError> {
        let r = self.radius();
        let lo = self.nodes.iter().fold(Point::repeat(f64::INFINITY), |m, x| m.inf(x));
        let cell_of = |x: &Point| (((x.x - lo.x) / r).floor() as i64, ((x.y - lo.y) / r).floor() as i64);
        let mut cells: std::collections::HashMap<(i64, i64), Vec<usize>> = std::collections::HashMap::new();
        for (a, x) in self.nodes.iter().enumerate() {
            cells.entry(cell_of(x)).or_default().push(a);
        }
        self.offsets.clear();
        self.support.clear();
        self.offsets.push(0);
        for x in &self.points {
            let (ci, cj) = cell_of(x);
            let start = self.support.len();
            for di in -1..=1 {
                for dj in -1..=1 {
                    if let Some(list) = cells.get(&(ci + di, cj + dj)) {
                        self.support.extend(list.iter().filter(|&&a| (self.nodes[a] - x).norm() < r));
                    }
                }
            }
            // A deterministic order, whatever the hash map's.
            self.support[start..].sort_unstable();
            self.offsets.push(self.support.len());
        }
        self.n.resize(self.support.len(), 0.0);
        self.grad_n.resize(self.support.len(), Point::zeros());
        let mut near: Vec<Point> = Vec::new();
        for p in 0..self.points.len() {
            let range = self.offsets[p]..self.offsets[p + 1];
            near.clear();
            near.extend(self.support[range.clone()].iter().map(|&a| self.nodes[a]));
            shape_functions(
                &self.points[p],
                &near,
                self.h,
                &self.params.lme,
                &mut self.lambda[p],
                &mut self.n[range.clone()],
                &mut self.grad_n[range],
            )
            .map_err(|source| OtmError::Shape { point: p, source })?;
        }
        Ok(())
    }

    /// The velocity gradient `∇v_p = Σ_a v_a ⊗ ∇N_a(x_p)` \[1/s\] of point `p`.
    fn velocity_gradient(&self, p: usize) -> Matrix2<f64> {
        let mut l = Matrix2::zeros();
        for k in self.offsets[p]..self.offsets[p + 1] {
            l += self.velocity[self.support[k]] * self.grad_n[k].transpose();
        }
        l
    }

    /// One step of `dt` \[s\] (steps 1–6 of the module documentation).
    pub fn step(&mut self, dt: f64) -> Result<(), OtmError> {
        self.shape_functions()?;
        let OtmParams { viscosity: mu, gravity: g, sound_speed: c0, density: rho0, .. } = self.params;
        self.nodal_mass.iter_mut().for_each(|m| *m = 0.0);
        self.force.iter_mut().for_each(|f| *f = Point::zeros());
        for p in 0..self.points.len() {
            let l = self.velocity_gradient(p);
            let sigma = Matrix2::identity() * -self.pressure[p] + (l + l.transpose()) * mu;
            for k in self.offsets[p]..self.offsets[p + 1] {
                let a = self.support[k];
                self.nodal_mass[a] += self.mass[p] * self.n[k];
                self.force[a] += -(sigma * self.grad_n[k]) * self.volume[p] + g * (self.mass[p] * self.n[k]);
            }
        }
        if self.params.surface_tension > 0.0 {
            super::surface::add_forces_2d(
                &self.nodes,
                &self.boundary,
                self.params.surface_tension,
                &mut self.force,
            );
        }
        // A node the points hardly weigh (far from every point) carries no mass: it stays
        // put rather than take a force over a round-off mass.
        let floor = 1e-12 * self.nodal_mass.iter().sum::<f64>() / self.nodal_mass.len() as f64;
        for a in 0..self.nodes.len() {
            if self.nodal_mass[a] > floor {
                self.velocity[a] += self.force[a] * (dt / self.nodal_mass[a]);
                self.nodes[a] += self.velocity[a] * dt;
            }
        }
        for p in 0..self.points.len() {
            let mut x = Point::zeros();
            let mut df = Matrix2::zeros();
            for k in self.offsets[p]..self.offsets[p + 1] {
                let xa = self.nodes[self.support[k]];
                x += xa * self.n[k];
                df += xa * self.grad_n[k].transpose();
            }
            let det = df.determinant();
            let volume = self.volume[p] * det;
            if volume.is_nan() || volume <= 0.0 {
                return Err(OtmError::Inverted { point: p, volume, det });
            }
            self.points[p] = x;
            self.volume[p] = volume;
            self.pressure[p] = c0 * c0 * (self.mass[p] / volume - rho0);
        }
        Ok(())
    }

    /// The largest stable step \[s\]: `cfl h / (c₀ + |v|_max)` and `viscous ρ₀ h² / μ`.
    pub fn stable_step(&self, cfl: f64, viscous: f64) -> f64 {
        let v = self.velocity.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let advective = cfl * self.h / (self.params.sound_speed + v);
        let diffusive = if self.params.viscosity > 0.0 {
            viscous * self.params.density * self.h * self.h / self.params.viscosity
        } else {
            f64::INFINITY
        };
        advective.min(diffusive)
    }

    /// The volume-weighted mean pressure of the material points \[Pa\].
    pub fn mean_pressure(&self) -> f64 {
        let v: f64 = self.volume.iter().sum();
        self.pressure.iter().zip(&self.volume).map(|(p, v)| p * v).sum::<f64>() / v
    }

    /// Total area of the material points \[m²\].
    pub fn area(&self) -> f64 {
        self.volume.iter().sum()
    }

    /// Kinetic energy of the nodes per unit depth \[J/m\] (lumped masses of the last step).
    pub fn kinetic_energy(&self) -> f64 {
        self.velocity.iter().zip(&self.nodal_mass).map(|(v, m)| 0.5 * m * v.norm_squared()).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::otm::mesh::disc;

    fn zhou_static(h: f64) -> Body {
        // Zhou 2021 §3.2's static drop: R = 0.2, ρ = 1, γ = 1, η = 0.5, c₀ = 50.
        let params = OtmParams {
            density: 1.0,
            sound_speed: 50.0,
            viscosity: 0.5,
            surface_tension: 1.0,
            gravity: Point::zeros(),
            lme: LmeParams::default(),
            support_tolerance: 1e-6,
        };
        Body::new(&disc(Point::zeros(), 0.2, h).unwrap(), h, params)
    }

    /// Without forces a body at rest stays at rest: no pressure, no motion, the volumes kept
    /// (to round-off: det ΔF = 1 ± 1e-14 per step).
    #[test]
    fn a_body_without_forces_stays_at_rest() {
        let mut b = zhou_static(0.04);
        b.params.surface_tension = 0.0;
        let area = b.area();
        for _ in 0..20 {
            b.step(1e-4).unwrap();
        }
        assert!(
            b.kinetic_energy() < 1e-18 && (b.area() / area - 1.0).abs() < 1e-11,
            "{} {}",
            b.kinetic_energy(),
            b.area() / area - 1.0
        );
        assert!(
            b.pressure.iter().all(|p| p.abs() < 1e-6),
            "{:?}",
            b.pressure.iter().fold(0.0f64, |m, p| m.max(p.abs()))
        );
    }

    /// Under gravity alone every node falls with v = g t (Σ N_a = 1: the lumped masses carry
    /// the whole weight), the points with it, the volumes kept; to the round-off pressures
    /// (about 1e-8 Pa) of the volume updates.
    #[test]
    fn a_body_falls_freely_under_gravity() {
        let mut b = zhou_static(0.04);
        b.params.surface_tension = 0.0;
        b.params.gravity = Point::new(0.5, -9.81);
        let start = b.points.clone();
        let (dt, steps) = (1e-4, 50);
        for _ in 0..steps {
            b.step(dt).unwrap();
        }
        let t = dt * steps as f64;
        for v in &b.velocity {
            assert!((v - b.params.gravity * t).norm() < 1e-8, "{}", (v - b.params.gravity * t).norm());
        }
        // Symplectic Euler: x = x0 + g dt² n(n+1)/2.
        let drop = b.params.gravity * (dt * dt * (steps * (steps + 1)) as f64 / 2.0);
        for (x, x0) in b.points.iter().zip(&start) {
            assert!((x - x0 - drop).norm() < 1e-10, "{}", (x - x0 - drop).norm());
        }
        assert!(b.pressure.iter().all(|p| p.abs() < 1e-6));
    }

    /// Zhou's static drop settles at the Laplace pressure γ/R = 5 Pa (Zhou: 5.004 Pa) to
    /// 1 % with R/h = 10.
    #[test]
    fn the_static_drop_settles_at_the_laplace_pressure() {
        let mut b = zhou_static(0.02);
        let mut t = 0.0;
        while t < 0.5 {
            let dt = b.stable_step(0.3, 0.125);
            b.step(dt).unwrap();
            t += dt;
        }
        let p = b.mean_pressure();
        assert!((p / 5.0 - 1.0).abs() < 0.01, "mean pressure {p} Pa");
        assert!(b.kinetic_energy() < 1e-8, "{}", b.kinetic_energy());
    }
}
