//! Surface tension of a single fluid with a free surface, for both schemes.
//!
//! Colour function: `c_a = Σ_b V_b W_ab` (1 in the bulk, falling towards the free surface),
//! its gradient `n_a = Σ_b V_b ∇_aW_ab` (pointing into the fluid, magnitude ≈ the surface
//! delta), valid where `|n_a| > ε` (below it `n_a` is set to zero); `ε = 0.01/h` by default
//! (Xu 2016 after Hu & Adams 2006), `fluid.surface_tension_threshold / h` in general. With
//! a single fluid `n_a` is not a difference, so in a disordered bulk it is O(disorder/h),
//! above 0.01/h: measured on the static drop (Δx = R/10, ν = 5e-3), CSF spurious speeds
//! reach 1–4 m/s with ε = 0.01/h and stay below 0.15 m/s with 0.1/h. Two forms
//! (`fluid.surface_tension_model`):
//!
//! - **Hu–Adams surface stress** (Hu & Adams 2006, J. Comput. Phys. 213:844, eqs. 14 and
//!   21): `Π_a = σ |n_a| (I/D − n̂_a ⊗ n̂_a)`, acceleration
//!   `a_a = (1/m_a) Σ_b (Π_a V_a² + Π_b V_b²)·∇_aW_ab` (momentum conserving; boundary
//!   particles carry no stress);
//! - **continuum surface force** (Brackbill, Kothe & Zemach 1992, J. Comput. Phys.
//!   100:335, eq. 14; Morris 2000 for the SPH curvature): `a_a = σ κ_a n_a / ρ_a`,
//!   `κ_a = −∇·n̂_a = D Σ'_b V_b (n̂_b − n̂_a)·∇_aW_ab / Σ'_b V_b r_ab·∇_aW_ab`, the sums
//!   `Σ'` over the neighbours with a valid normal (the division renormalises the truncated
//!   support at the surface; Morris 2000 eq. 32).
//!
//! With `fluid.surface_tension_normalise`, σ is divided by the one-sided surface-delta
//! integral of a flat lattice surface ([`flat_surface_delta`], ≈ 0.5).
//!
//! Volumes are `V_b = m/ρ_b` for the weakly compressible scheme and `Δx^D` for ISPH. The
//! acceleration is added to the WCSPH acceleration (its `Stage` in `wcsph`) or applied to
//! the ISPH predicted velocity as `u* += Δt a` (its `Stage` in `isph`).

use crate::kernel::{Kernel, Scaled};
use crate::scene::SurfaceTensionModel;

use crate::state::{State, Vector};
use nalgebra::SMatrix;
use rayon::prelude::*;

/// The discrete surface-delta integral `I = Σ_rows |n| Δx` across the flat free surface of
/// a half-space filled with the cell-centred lattice of spacing `dx` (`n = Σ_b V_b ∇W`).
/// A two-sided colour jump gives 1; with a single fluid the colour stops at the last row
/// (its kernel sum is about ½), so `I ≈ 0.5` for the cubic spline at h = 1.2–2 Δx. Dividing
/// σ by `I` (`fluid.surface_tension_normalise`) restores the force per unit area `σκ` of
/// the continuum surface force.
pub fn flat_surface_delta<K: Kernel, const D: usize>(kernel: &Scaled<K, D>, dx: f64) -> f64 {
    let reach = (kernel.support / dx).ceil() as i64 + 1;
    let v = dx.powi(D as i32);
    let mut total = 0.0;
    // Rows a at depth (j + ½) Δx below the surface; neighbours b at lateral offsets k Δx
    // (D − 1 axes) and depths (jb + ½) Δx.
    for j in 0..reach {
        let mut n = 0.0;
        for jb in 0..(j + reach + 1) {
            let dy = (jb - j) as f64 * dx;
            let mut idx = vec![-reach; D - 1];
            loop {
                let lateral2: f64 = idx.iter().map(|&k| (k as f64 * dx).powi(2)).sum();
                let r = (lateral2 + dy * dy).sqrt();
                if r > 0.0 && r < kernel.support {
                    // ∇_aW_ab along the outward normal: r_ab · e = dy (b deeper: dy > 0).
                    n += v * kernel.grad_factor(r) * dy;
                }
                let mut k = 0;
                while k < D - 1 {
                    idx[k] += 1;
                    if idx[k] <= reach {
                        break;
                    }
                    idx[k] = -reach;
                    k += 1;
                }
                if k == D - 1 {
                    break;
                }
            }
        }
        total += n.abs() * dx;
    }
    total
}

/// σ of the scene \[N/m\], divided by [`flat_surface_delta`] when the scene asks to
/// normalise.
pub fn effective_sigma<K: Kernel, const D: usize>(scene: &crate::scene::Scene, kernel: &Scaled<K, D>) -> f64 {
    let sigma = scene.fluid.surface_tension;
    if scene.fluid.surface_tension_normalise { sigma / flat_surface_delta(kernel, scene.dx) } else { sigma }
}

/// The force forms of this stage (`young_laplace` is a pressure condition instead:
/// [`crate::stages::young_laplace`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Force {
    /// Hu & Adams 2006 surface stress.
    HuAdams,
    /// Continuum surface force (Brackbill et al. 1992).
    Csf,
}

impl Force {
    /// The force form of a scene's model (None for `young_laplace`).
    pub fn of(model: SurfaceTensionModel) -> Option<Self> {
        match model {
            SurfaceTensionModel::HuAdams => Some(Self::HuAdams),
            SurfaceTensionModel::Csf => Some(Self::Csf),
            SurfaceTensionModel::YoungLaplace => None,
        }
    }
}

/// The surface-tension acceleration (see the module documentation): [`SurfaceTension::compute`]
/// fills it; each scheme's stage applies it (ISPH: `u += Δt a` in the predictor; WCSPH:
/// added to the acceleration before the second half kick).
#[derive(Debug)]
pub struct SurfaceTension<const D: usize> {
    /// σ \[N/m\].
    sigma: f64,
    model: Force,
    /// ε = 0.01/h \[1/m\].
    eps: f64,
    /// Colour gradient n of the fluid \[1/m\].
    n: Vec<Vector<D>>,
    /// Hu–Adams stress Π of the fluid \[N/m²·m = N/m\] (σ |n|).
    stress: Vec<SMatrix<f64, D, D>>,
    /// Surface-tension acceleration \[m/s²\].
    accel: Vec<Vector<D>>,
}

impl<const D: usize> SurfaceTension<D> {
    /// A stage with coefficient `sigma` \[N/m\] (already divided by the surface-delta
    /// integral when normalised, see [`flat_surface_delta`]), smoothing length `h` \[m\]
    /// and the normal threshold `ε = threshold / h`.
    pub fn new(sigma: f64, model: Force, threshold: f64, h: f64) -> Self {
        Self { sigma, model, eps: threshold / h, n: Vec::new(), stress: Vec::new(), accel: Vec::new() }
    }
}

impl<const D: usize> SurfaceTension<D> {
    /// The stage name of every scheme's surface-tension stage.
    pub const NAME: &'static str = "surface_tension";

    /// Computes the surface-tension acceleration of every fluid particle \[m/s²\] from the
    /// step's pairs; `rho`: the particle densities of a compressible scheme (all
    /// particles), volumes `m/ρ` then; otherwise V and ρ₀.
    pub fn compute(&mut self, s: &State<D>, rho: Option<&[f64]>) -> &[Vector<D>] {
        let (nf, total) = (s.particles.fluid, s.particles.total());
        let (list, pairs) = (&s.neighbours, &s.pairs);
        let mass = s.density * s.volume;
        let rho = rho.unwrap_or(&[]);
        let wc = rho.len() >= total;
        let v0 = s.volume;
        let vol = |b: usize| if wc { mass / rho[b] } else { v0 };
        let dens = |b: usize| if wc { rho[b] } else { s.density };
        let (eps, sigma) = (self.eps, self.sigma);
        self.n.resize(nf, Vector::zeros());
        self.accel.resize(nf, Vector::zeros());
        self.n.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, n)| {
            let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
            let mut sum = Vector::<D>::zeros();
            for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                sum += p.r_ab * (p.f * vol(b as usize));
            }
            *n = if sum.norm() > eps { sum } else { Vector::zeros() };
        });
        let n = &self.n;
        let unit = |b: usize| -> Option<Vector<D>> {
            let v = n.get(b)?;
            let l = v.norm();
            (l > 0.0).then(|| v / l)
        };
        match self.model {
            Force::HuAdams => {
                self.stress.resize(nf, SMatrix::zeros());
                self.stress.par_iter_mut().zip(n.par_iter()).with_min_len(512).for_each(|(st, n)| {
                    let l = n.norm();
                    *st = if l > 0.0 {
                        let u = n / l;
                        (SMatrix::<f64, D, D>::identity() / D as f64 - u * u.transpose()) * (sigma * l)
                    } else {
                        SMatrix::zeros()
                    };
                });
                let stress = &self.stress;
                self.accel.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, acc)| {
                    let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
                    let va = vol(a);
                    let sa = stress[a] * (va * va);
                    let mut sum = Vector::<D>::zeros();
                    for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                        let b = b as usize;
                        let mut t = sa;
                        if b < nf {
                            let vb = vol(b);
                            t += stress[b] * (vb * vb);
                        }
                        sum += t * (p.r_ab * p.f);
                    }
                    *acc = sum / (dens(a) * va);
                });
            }
            Force::Csf => {
                self.accel.par_iter_mut().enumerate().with_min_len(256).for_each(|(a, acc)| {
                    let Some(na) = unit(a) else {
                        *acc = Vector::zeros();
                        return;
                    };
                    let (lo, hi) = (list.offsets[a], list.offsets[a + 1]);
                    let (mut num, mut den) = (0.0, 0.0);
                    for (p, &b) in pairs[lo..hi].iter().zip(&list.indices[lo..hi]) {
                        let b = b as usize;
                        if b >= nf {
                            continue;
                        }
                        if let Some(nb) = unit(b) {
                            let vb = vol(b);
                            num += vb * p.f * (nb - na).dot(&p.r_ab);
                            den += vb * p.f * p.r2();
                        }
                    }
                    let kappa = if den < 0.0 { D as f64 * num / den } else { 0.0 };
                    *acc = n[a] * (sigma * kappa / dens(a));
                });
            }
        }
        &self.accel
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::CubicSpline;

    #[test]
    fn surface_delta_of_a_flat_lattice_is_about_one_half() {
        // A one-sided colour: the kernel sum falls from 1 to about ½ at the last row.
        for hdx in [1.2, 1.5, 2.0] {
            let i = flat_surface_delta(&Scaled::<CubicSpline, 2>::new(hdx * 0.01), 0.01);
            assert!((i - 0.5).abs() < 0.01, "h = {hdx} dx: {i}");
        }
        let i3 = flat_surface_delta(&Scaled::<CubicSpline, 3>::new(1.5), 1.0);
        assert!((i3 - 0.5).abs() < 0.02, "3D: {i3}");
    }
}
