//! Laminar entrance flow between parallel plates from a uniform inlet: the boundary-layer
//! (parabolised) equations of Bodoia & Osterle (1961, Appl. Sci. Res. A10:265) marched in `x`
//! (REFERENCES.md §3c, CASES.md `poiseuille_channel`).
//!
//! # Equations
//! With plate spacing `H`, mean (inlet) velocity `U`, kinematic viscosity `nu`, `Re = U H / nu`
//! and the dimensionless variables `X = x / (H Re)`, `Y = y / H`, `u' = u / U`,
//! `v' = v Re / U`, `P = p / (rho U^2)`:
//!
//! ```text
//! u' du'/dX + v' du'/dY = -dP/dX + d2u'/dY2,     du'/dX + dv'/dY = 0,
//! u'(0, Y) = 1,   u' = v' = 0 at Y = 0 and Y = 1,   int_0^1 u' dY = 1,
//! ```
//!
//! so a single dimensionless solution serves every `Re` (the boundary-layer model neglects
//! axial diffusion and is the large-`Re` limit; Durst et al. 2005 add an `O(1)` correction at
//! small `Re`, see [`crate::entrance_length`]). The fully developed limit is
//! `u = 6 U (y/H)(1 - y/H)`, `u_c = 1.5 U`, `dP/dX = -12`.
//!
//! # Scheme
//! Half channel `0 <= Y <= 1/2` (symmetry `du'/dY = v' = 0` on the centre line) on [`NY`]
//! intervals of a uniform grid in `eta`, mapped by `Y = (1 - tanh(BETA (1 - eta)) / tanh BETA) / 2`
//! (wall cells ~14 times smaller than a uniform grid's, for [`BETA`] = 2.5). In `X`, [`NXI`]
//! uniform steps in `xi = (X / X_MAX)^(1/POWER)`, `POWER = 4`, so the first steps are tiny
//! (`X_1 ~ 1.6e-14`) and the layer, of thickness `~ sqrt(X)`, is resolved by the wall cells
//! from a few steps on. Each station is implicit: `X` derivative by second-order backward
//! differentiation in `xi` (backward Euler for the first [`EULER_STEPS`] steps), central
//! differences in `eta`, and the convecting velocities `u*, v*` are iterated (Picard, starting
//! from the extrapolation of the two previous stations) until no `u'` changes by more than
//! 1e-11; the first step from the discontinuous inlet is a single linear solve with `u* = 1`,
//! `v* = 0`. For given `u*, v*` the system for `(u'_j, dP/dX)` is tridiagonal plus one column
//! and is solved by superposition of two tridiagonal solves so that the trapezoidal flux
//! `sum_j w_j u'_j = 1/2` (weights `w_j ~ Y'(eta_j) d eta`, normalised to be exact for a
//! constant) holds to rounding at every station, including the uniform inlet. `v'` is
//! continuity integrated from the wall with the same weights, so it vanishes on the centre
//! line.
//!
//! # Accuracy (checked by the tests of this module)
//! - Grid convergence: halving both the `eta` and the `xi` step changes `u_c` by at most
//!   1.1e-5 relative at `X = 0.001 ... 0.1` and `L_e(99 %)` by ~1e-4 relative (test
//!   `grid_convergence`); refining `xi` alone changes `u_c` by < 1e-7, so the error is that
//!   of the `Y` grid.
//! - Far downstream the discrete centre-line velocity is `1.5 U (1 + 1.4e-5)`; it changes by
//!   less than 1e-6 after `X = 0.2`. For `X >= X_MAX` the exact fully developed profile is
//!   returned.
//! - Interpolation is linear in `xi` between stations (tested < 1e-6 of `U` at the mid-points,
//!   except in the first interval `X < 1.6e-14`) and cubic Lagrange in `eta` across the
//!   channel (off-node values agree with the halved grid's nodes to < 6e-5 of `U` at
//!   `X = 1e-4`, < 2.1e-5 for `X >= 1e-3`).
//!
//! Result: `L_e / (H Re) = 0.04320` for `u_c = 0.99 * 1.5 U`, `u_c / U = 1.30988` at
//! `X = 0.01` and `1.49104` at `X = 0.05`.
//!
//! The solution is computed once per process (about 0.1 s in an optimised build) and shared
//! by every [`EntranceFlow`].

use crate::error::{non_negative, positive, within};
use crate::{ReferenceError, Result};
use std::sync::OnceLock;

/// Intervals of the `Y` grid on the half channel `0 <= Y <= 1/2`.
pub const NY: usize = 200;

/// Steps of the uniform `xi = (X / X_MAX)^(1/POWER)` grid from the inlet to [`X_MAX`].
pub const NXI: usize = 2000;

/// Wall clustering of the `Y` grid `Y = (1 - tanh(BETA (1 - eta)) / tanh BETA) / 2`: the wall
/// cell is `BETA / (tanh(BETA) cosh^2(BETA))` times the cell of a uniform grid (0.067).
pub const BETA: f64 = 2.5;

/// Exponent of the `X` grid map `X = X_MAX xi^POWER`, `xi` uniform.
pub const POWER: f64 = 4.0;

/// Steps with backward Euler before the second-order scheme takes over.
pub const EULER_STEPS: usize = 4;

/// End of the march, `X = x / (H Re)`; beyond it the flow is taken as fully developed (the
/// march's centre-line velocity changes by < 1e-6 after `X = 0.2` and is `1.5 U` to ~1.4e-5,
/// the `Y`-discretisation error of the parabola).
pub const X_MAX: f64 = 0.25;

/// Dimensionless march: centre-line velocity and half-channel profiles at every station.
#[derive(Debug, Clone)]
struct March {
    /// Number of `Y` intervals on the half channel.
    ny: usize,
    /// Number of `xi` steps.
    nxi: usize,
    /// Wall clustering parameter of the `Y` grid.
    beta: f64,
    /// Exponent of the `X` grid map `X = X_MAX xi^power`.
    power: f64,
    /// `u / U` at every station (`(nxi + 1) * (ny + 1)` values, station-major).
    u: Vec<f64>,
    /// `dP/dX` at every station (index 0 is unused and set to 0).
    dpdx: Vec<f64>,
    #[cfg_attr(not(test), allow(dead_code))]
    /// Trapezoidal flux on the half channel at every station (should be 1/2).
    flux: Vec<f64>,
    #[cfg_attr(not(test), allow(dead_code))]
    /// `v' = v Re / U` on the centre line at every station (should be 0).
    v_centre: Vec<f64>,
    #[cfg_attr(not(test), allow(dead_code))]
    /// Largest number of Picard iterations used at a station.
    picard_max: usize,
    #[cfg_attr(not(test), allow(dead_code))]
    /// Largest last Picard update at a station where the iteration hit [`MAX_PICARD`] (0 if
    /// it converged everywhere).
    worst_change: f64,
}

/// Largest `fraction` accepted by [`EntranceFlow::development_length`]: the discrete
/// centre-line velocity approaches `1.5 U` only to ~2e-5 relative, so levels closer to 1 than
/// ~1e-4 would measure the discretisation error, not the development.
pub const MAX_FRACTION: f64 = 0.9999;

/// Maximum Picard iterations per station.
const MAX_PICARD: usize = 100;

/// Picard iteration stops when no `u / U` changes by more than this.
const PICARD_TOL: f64 = 1e-11;

/// Solve the tridiagonal system `a_j x_{j-1} + b_j x_j + c_j x_{j+1} = d_j` (Thomas), in place
/// of `d`; `cp` is scratch. The matrices here are diagonally dominant, so no pivoting is needed.
fn thomas(a: &[f64], b: &[f64], c: &[f64], d: &mut [f64], cp: &mut [f64]) {
    let n = d.len();
    cp[0] = c[0] / b[0];
    d[0] /= b[0];
    for j in 1..n {
        let m = b[j] - a[j] * cp[j - 1];
        cp[j] = c[j] / m;
        d[j] = (d[j] - a[j] * d[j - 1]) / m;
    }
    for j in (0..n - 1).rev() {
        d[j] -= cp[j] * d[j + 1];
    }
}

/// Grid map `Y(eta) = (1 - tanh(beta (1 - eta)) / tanh(beta)) / 2` (wall at `eta = 0`, centre
/// line at `eta = 1`, continued antisymmetrically to the far wall at `eta = 2`): returns
/// `(dY/deta, d2Y/deta2)` at `eta`.
fn grid_metrics(eta: f64, beta: f64) -> (f64, f64) {
    let s = beta * (1.0 - eta);
    let sech2 = 1.0 / s.cosh().powi(2);
    (0.5 * beta * sech2 / beta.tanh(), beta * beta * sech2 * s.tanh() / beta.tanh())
}

/// Inverse of the grid map: `eta` in `[0, 2]` of `Y` in `[0, 1]`.
fn eta_of(y: f64, beta: f64) -> f64 {
    1.0 - ((1.0 - 2.0 * y) * beta.tanh()).atanh() / beta
}

impl March {
    /// March the dimensionless equations with `ny` intervals across the half channel and
    /// `nxi` steps in `xi` (see the module documentation).
    fn compute(ny: usize, nxi: usize, beta: f64, pw: f64) -> Self {
        let deta = 1.0 / ny as f64;
        let map: Vec<(f64, f64)> = (0..=ny).map(|j| grid_metrics(j as f64 * deta, beta)).collect();
        // Trapezoid weights of int_0^1 (.) Y'(eta) d eta.
        // Normalised to sum to 1/2 exactly (exact for constants; the uniform inlet then carries
        // exactly the flux of every later station).
        let mut wq: Vec<f64> = (0..=ny)
            .map(|j| if j == 0 || j == ny { 0.5 * deta * map[j].0 } else { deta * map[j].0 })
            .collect();
        let scale = 0.5 / wq.iter().sum::<f64>();
        for w in &mut wq {
            *w *= scale;
        }
        let dxi = 1.0 / nxi as f64;
        let x_of = |k: usize| X_MAX * (k as f64 * dxi).powf(pw);
        let nu = ny + 1;
        let mut u: Vec<f64> = vec![0.0; (nxi + 1) * nu];
        let mut dpdx = vec![0.0; nxi + 1];
        let mut flux = vec![0.0; nxi + 1];
        let mut v_centre = vec![0.0; nxi + 1];
        // Inlet: uniform, including the wall node (no slip acts for X > 0), so that the
        // discrete inlet flux is exactly 1/2 like at every later station.
        for val in &mut u[..nu] {
            *val = 1.0;
        }
        // Trapezoidal flux of a full half-channel profile w_0 ..= w_ny.
        let quad = |w: &[f64]| w.iter().zip(&wq).map(|(a, b)| a * b).sum::<f64>();
        flux[0] = quad(&u[..nu]);
        // Unknowns are u_1 .. u_ny (u_0 = 0 on the wall).
        let n = ny;
        let (mut a, mut b, mut c) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let (mut r, mut s, mut cp) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let mut v_prev = vec![0.0; nu];
        let mut v_prev2 = vec![0.0; nu];
        let (mut us, mut vs) = (vec![0.0; nu], vec![0.0; nu]);
        let mut worst_change = 0.0f64;
        let mut picard_max = 0usize;
        let mut v_new = vec![0.0; nu];
        let mut ux = vec![0.0; nu];
        for k in 1..=nxi {
            let euler = k <= EULER_STEPS;
            let (done, rest) = u.split_at_mut(k * nu);
            let cur = &mut rest[..nu];
            let prev = &done[(k - 1) * nu..k * nu];
            let prev2 = if k >= 2 { &done[(k - 2) * nu..(k - 1) * nu] } else { prev };
            // u_X ~ alpha u_new - hist.
            let (alpha, hist_coef_1, hist_coef_2) = if euler {
                let dx = x_of(k) - x_of(k - 1);
                (1.0 / dx, 1.0 / dx, 0.0)
            } else {
                let dxdxi = pw * X_MAX * (k as f64 * dxi).powf(pw - 1.0);
                let f = 1.0 / (2.0 * dxi * dxdxi);
                (3.0 * f, 4.0 * f, -f)
            };
            // Picard iteration on the convecting velocities, starting from the previous station.
            for j in 0..nu {
                if k > EULER_STEPS + 1 {
                    us[j] = (2.0 * prev[j] - prev2[j]).max(0.5 * prev[j]);
                    vs[j] = 2.0 * v_prev[j] - v_prev2[j];
                } else {
                    us[j] = prev[j];
                    vs[j] = v_prev[j];
                }
            }
            let mut converged = false;
            let mut last_change = 0.0;
            for it in 0..MAX_PICARD {
                for i in 0..n {
                    let j = i + 1;
                    let hist = hist_coef_1 * prev[j] + hist_coef_2 * prev2[j];
                    let (yp, ypp) = map[j];
                    let g = 1.0 / (deta * deta * yp * yp);
                    if j < ny {
                        let q = (vs[j] / yp + ypp / (yp * yp * yp)) / (2.0 * deta);
                        a[i] = if i == 0 { 0.0 } else { -q - g };
                        c[i] = q - g;
                    } else {
                        a[i] = -2.0 * g;
                        c[i] = 0.0;
                    }
                    b[i] = us[j] * alpha + 2.0 * g;
                    r[i] = us[j] * hist;
                    s[i] = 1.0;
                }
                // A u = r - P' 1  =>  u = A^-1 r - P' A^-1 1.
                thomas(&a, &b, &c, &mut r, &mut cp);
                thomas(&a, &b, &c, &mut s, &mut cp);
                // Flux of u_1 ..= u_ny with u_0 = 0.
                let qi = |w: &[f64]| w.iter().zip(&wq[1..]).map(|(a, b)| a * b).sum::<f64>();
                let p = (qi(&r) - 0.5) / qi(&s);
                cur[0] = 0.0;
                for i in 0..n {
                    cur[i + 1] = r[i] - p * s[i];
                }
                dpdx[k] = p;
                // Continuity: v_j = v_{j-1} - h/2 (u_X,j-1 + u_X,j), from the wall.
                for j in 0..nu {
                    ux[j] = alpha * cur[j] - (hist_coef_1 * prev[j] + hist_coef_2 * prev2[j]);
                }
                v_new[0] = 0.0;
                for j in 1..nu {
                    v_new[j] =
                        v_new[j - 1] - 0.5 * scale * deta * (ux[j - 1] * map[j - 1].0 + ux[j] * map[j].0);
                }
                let change = (0..nu).map(|j| (cur[j] - us[j]).abs()).fold(0.0, f64::max);
                last_change = change;
                us[..].copy_from_slice(cur);
                vs[..].copy_from_slice(&v_new);
                picard_max = picard_max.max(it + 1);
                // The first step, from the discontinuous inlet, is the classical single linear
                // solve with u* = 1, v* = 0 (the layer is far thinner than the wall cell there).
                if change <= PICARD_TOL || k == 1 {
                    converged = true;
                    break;
                }
            }
            if !converged {
                worst_change = worst_change.max(last_change);
            }
            flux[k] = quad(cur);
            v_centre[k] = v_new[ny];
            v_prev2.copy_from_slice(&v_prev);
            v_prev.copy_from_slice(&v_new);
        }
        Self { ny, nxi, beta, power: pw, u, dpdx, flux, v_centre, picard_max, worst_change }
    }

    /// Station index and linear weight of `xi = sqrt(X / X_MAX)` (`0 <= X <= X_MAX`).
    fn locate(&self, x: f64) -> (usize, f64) {
        let t = (x / X_MAX).powf(1.0 / self.power) * self.nxi as f64;
        let k = (t.floor() as usize).min(self.nxi - 1);
        (k, (t - k as f64).clamp(0.0, 1.0))
    }

    #[cfg_attr(not(test), allow(dead_code))]
    /// `Y = y / H` of grid node `j` (0 ..= 2 ny across the full channel).
    fn y_node(&self, j: usize) -> f64 {
        let eta = j as f64 / self.ny as f64;
        0.5 * (1.0 - (self.beta * (1.0 - eta)).tanh() / self.beta.tanh())
    }

    /// `u / U` at grid node `j` (0 ..= 2 ny across the full channel) of station `k`.
    fn node(&self, k: usize, j: usize) -> f64 {
        let jj = if j > self.ny { 2 * self.ny - j } else { j };
        self.u[k * (self.ny + 1) + jj]
    }

    /// `dP/dX` at `X` (`X_1 <= X <= X_MAX`, `X_1` the first station), linear in `xi`.
    fn pressure_gradient(&self, x: f64) -> f64 {
        let (k, w) = self.locate(x);
        let k = k.max(1);
        let w = if k == 1 && x < self.x_station(1) { 0.0 } else { w };
        (1.0 - w) * self.dpdx[k] + w * self.dpdx[(k + 1).min(self.nxi)]
    }

    /// `X` of station `k`.
    fn x_station(&self, k: usize) -> f64 {
        X_MAX * (k as f64 / self.nxi as f64).powf(self.power)
    }

    /// Centre-line `u_c / U` at `X` (`0 <= X <= X_MAX`), linear in `xi`.
    fn centreline(&self, x: f64) -> f64 {
        let (k, w) = self.locate(x);
        (1.0 - w) * self.node(k, self.ny) + w * self.node(k + 1, self.ny)
    }

    /// `u / U` at station `k` and `Y` in `[0, 1]`: cubic Lagrange on the 4 nearest nodes.
    fn at_station(&self, k: usize, y: f64) -> f64 {
        let n_full = 2 * self.ny;
        let t = eta_of(y, self.beta) * self.ny as f64;
        let i = (t.floor() as usize).min(n_full - 1);
        let start = i.saturating_sub(1).min(n_full - 3);
        let mut sum = 0.0;
        for m in 0..4 {
            let mut l = 1.0;
            for q in 0..4 {
                if q != m {
                    l *= (t - (start + q) as f64) / ((start + m) as f64 - (start + q) as f64);
                }
            }
            sum += l * self.node(k, start + m);
        }
        sum
    }

    /// `u / U` at `(X, Y)` (`0 <= X <= X_MAX`, `0 <= Y <= 1`).
    fn velocity(&self, x: f64, y: f64) -> f64 {
        let (k, w) = self.locate(x);
        (1.0 - w) * self.at_station(k, y) + w * self.at_station(k + 1, y)
    }

    /// First `X` where `u_c / U >= target` (linear in `xi` between stations), if reached.
    fn first_reaching(&self, target: f64) -> Option<f64> {
        let uc = |k: usize| self.node(k, self.ny);
        if uc(0) >= target {
            return Some(0.0);
        }
        (1..=self.nxi).find(|&k| uc(k) >= target).map(|k| {
            let (u0, u1) = (uc(k - 1), uc(k));
            let xi = ((k - 1) as f64 + (target - u0) / (u1 - u0)) / self.nxi as f64;
            X_MAX * xi.powf(self.power)
        })
    }
}

/// The default march, computed on first use and shared.
fn march() -> &'static March {
    static MARCH: OnceLock<March> = OnceLock::new();
    MARCH.get_or_init(|| March::compute(NY, NXI, BETA, POWER))
}

/// Developing laminar flow between parallel plates `y = 0` and `y = H` from a uniform inlet
/// velocity `U` at `x = 0` (boundary-layer model of Bodoia & Osterle 1961; see the module
/// documentation for the equations, the scheme and its accuracy).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EntranceFlow {
    width: f64,
    mean_velocity: f64,
    viscosity: f64,
}

impl EntranceFlow {
    /// Channel of plate spacing `width = H` (m), inlet (= mean) velocity `mean_velocity = U`
    /// (m/s) and kinematic viscosity `kinematic_viscosity = nu` (m^2/s), all finite and > 0.
    /// The dimensionless march (shared by every `Re`) is run on the first call in the process.
    pub fn new(width: f64, mean_velocity: f64, kinematic_viscosity: f64) -> Result<Self> {
        let flow = Self {
            width: positive("width", width)?,
            mean_velocity: positive("mean_velocity", mean_velocity)?,
            viscosity: positive("kinematic_viscosity", kinematic_viscosity)?,
        };
        march();
        Ok(flow)
    }

    /// Plate spacing `H` (m).
    pub fn width(&self) -> f64 {
        self.width
    }

    /// Mean velocity `U` (m/s).
    pub fn mean_velocity(&self) -> f64 {
        self.mean_velocity
    }

    /// Kinematic viscosity `nu` (m^2/s).
    pub fn kinematic_viscosity(&self) -> f64 {
        self.viscosity
    }

    /// Reynolds number `Re = U H / nu`.
    pub fn reynolds(&self) -> f64 {
        self.mean_velocity * self.width / self.viscosity
    }

    /// Length scale `H Re = U H^2 / nu` (m) of the dimensionless `X = x / (H Re)`.
    pub fn axial_scale(&self) -> f64 {
        self.width * self.reynolds()
    }

    /// Centre-line velocity `u_c(x)` (m/s) at `x >= 0` (m), from `U` at the inlet to `1.5 U`
    /// (exactly `1.5 U` for `x / (H Re) >= X_MAX`). Grid-converged to ~1e-5 relative.
    pub fn centreline_velocity(&self, x: f64) -> Result<f64> {
        let big_x = non_negative("x", x)? / self.axial_scale();
        if big_x >= X_MAX {
            return Ok(1.5 * self.mean_velocity);
        }
        Ok(self.mean_velocity * march().centreline(big_x))
    }

    /// Streamwise velocity `u(x, y)` (m/s) at `x >= 0` (m) for every `y` in `ys`, each in
    /// `[0, H]` (m); the fully developed `6 U (y/H)(1 - y/H)` for `x / (H Re) >= X_MAX`.
    /// At `x = 0` the uniform inlet `U` is returned (also at the walls; no slip acts for `x > 0`).
    pub fn profile(&self, x: f64, ys: &[f64]) -> Result<Vec<f64>> {
        let big_x = non_negative("x", x)? / self.axial_scale();
        ys.iter()
            .map(|&y| {
                let eta = within("y", y, 0.0, self.width, "must lie in [0, width]")? / self.width;
                let u = if big_x >= X_MAX { 6.0 * eta * (1.0 - eta) } else { march().velocity(big_x, eta) };
                Ok(self.mean_velocity * u)
            })
            .collect()
    }

    /// Kinematic pressure gradient `(1/rho) dp/dx` (m/s^2) at `x > 0` (m):
    /// `(nu U / H^2) dP/dX`, tending to the Poiseuille value `-12 nu U / H^2` downstream
    /// (returned exactly for `x / (H Re) >= X_MAX`). Near the inlet `dP/dX` is singular like
    /// `X^(-1/2)`; for `X` below the first station (`~1.6e-14`) the first station's value is
    /// returned. Grid-converged to ~1e-4 relative for `X >= 1e-4` (test `grid_convergence`).
    pub fn pressure_gradient(&self, x: f64) -> Result<f64> {
        let x = positive("x", x)?;
        let big_x = x / self.axial_scale();
        let scale = self.viscosity * self.mean_velocity / (self.width * self.width);
        if big_x >= X_MAX {
            return Ok(-12.0 * scale);
        }
        Ok(scale * march().pressure_gradient(big_x))
    }

    /// Development length (m): the first `x` where `u_c >= fraction * 1.5 U`, for `fraction`
    /// in `(0, 1)` (0 when `fraction <= 2/3`, since `u_c(0) = U`). For `fraction = 0.99` it is
    /// `0.04320 H Re` in this boundary-layer model; an error names `fraction` if the level is
    /// not reached by `x = X_MAX H Re` (only for `fraction` within ~1e-5 of 1).
    pub fn development_length(&self, fraction: f64) -> Result<f64> {
        if !(fraction.is_finite() && fraction > 0.0 && fraction <= MAX_FRACTION) {
            return Err(ReferenceError::InvalidParameter {
                name: "fraction",
                value: fraction,
                rule: "must lie in (0, 0.9999] (closer to 1 the discretisation error dominates)",
            });
        }
        march().first_reaching(1.5 * fraction).map(|x| x * self.axial_scale()).ok_or(
            ReferenceError::InvalidParameter {
                name: "fraction",
                value: fraction,
                rule: "is too close to 1: not reached within the computed range X <= X_MAX",
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entrance_length::channel_durst;

    fn flow(re: f64) -> EntranceFlow {
        // H = 0.2 m, nu = 1e-6 m^2/s (CASES.md poiseuille_channel).
        EntranceFlow::new(0.2, re * 1e-6 / 0.2, 1e-6).unwrap()
    }

    #[test]
    fn fully_developed_limit() {
        let m = march();
        let last = m.nxi;
        let uc = m.node(last, m.ny);
        assert!((uc - 1.5).abs() <= 1e-4, "u_c(X_MAX) / U = {uc}");
        for j in 0..=2 * m.ny {
            let eta = m.y_node(j);
            let exact = 6.0 * eta * (1.0 - eta);
            assert!((m.node(last, j) - exact).abs() <= 1e-4, "eta = {eta}: {}", m.node(last, j));
        }
        assert!((m.dpdx[last] + 12.0).abs() <= 1e-3, "dP/dX = {}", m.dpdx[last]);
        // Developed before X_MAX: u_c changes by < 1e-6 after X = 0.2.
        let (k, _) = m.locate(0.2);
        assert!((m.node(k, m.ny) - uc).abs() <= 1e-6, "{} vs {uc}", m.node(k, m.ny));
        // Public API, dimensional, before and beyond X_MAX.
        let f = flow(100.0);
        let u = f.mean_velocity();
        let x_far = 0.2 * f.axial_scale();
        assert!((f.centreline_velocity(x_far).unwrap() - 1.5 * u).abs() <= 1e-4 * u);
        assert!((f.centreline_velocity(10.0 * f.axial_scale()).unwrap() - 1.5 * u).abs() <= 1e-15);
        let g0 = -12.0 * 1e-6 * u / (0.2 * 0.2);
        assert!((f.pressure_gradient(x_far).unwrap() / g0 - 1.0).abs() <= 1e-4);
        assert!((f.pressure_gradient(10.0 * f.axial_scale()).unwrap() / g0 - 1.0).abs() <= 1e-15);
        // Favourable and steeper than Poiseuille in the entrance.
        assert!(f.pressure_gradient(1e-3 * f.axial_scale()).unwrap() < 2.0 * g0);
        let ys: Vec<f64> = (0..=20).map(|i| 0.2 * i as f64 / 20.0).collect();
        for xx in [x_far, 10.0 * f.axial_scale()] {
            for (y, v) in ys.iter().zip(f.profile(xx, &ys).unwrap()) {
                let exact = 6.0 * u * (y / 0.2) * (1.0 - y / 0.2);
                assert!((v - exact).abs() <= 1e-4 * u, "y = {y}: {v} vs {exact}");
            }
        }
    }

    #[test]
    fn mass_flux_conserved_at_every_station() {
        let m = march();
        for k in 1..=m.nxi {
            assert!((m.flux[k] - 0.5).abs() <= 1e-8 * 0.5, "station {k}: flux {}", m.flux[k]);
            // v' on the centre line is -(flux change) / dX: zero up to rounding / dX.
            let dx = X_MAX
                * ((k as f64 / m.nxi as f64).powf(m.power) - ((k - 1) as f64 / m.nxi as f64).powf(m.power));
            assert!(m.v_centre[k].abs() * dx <= 1e-14, "station {k}: v_c = {}", m.v_centre[k]);
        }
        // Through the public profile (cubic interpolation, Simpson's rule on the full width).
        let f = flow(400.0);
        let n = 400;
        let ys: Vec<f64> = (0..=n).map(|i| 0.2 * i as f64 / n as f64).collect();
        for big_x in [1e-4, 1e-3, 0.01, 0.05] {
            let p = f.profile(big_x * f.axial_scale(), &ys).unwrap();
            let simpson: f64 = (0..n / 2).map(|i| p[2 * i] + 4.0 * p[2 * i + 1] + p[2 * i + 2]).sum::<f64>()
                * (0.2 / n as f64)
                / 3.0;
            let q = simpson / (0.2 * f.mean_velocity());
            assert!((q - 1.0).abs() <= 2e-4, "X = {big_x}: flux / (U H) = {q}");
        }
    }

    #[test]
    fn centreline_grows_monotonically_from_inlet() {
        let m = march();
        assert!((m.node(0, m.ny) - 1.0).abs() <= 1e-15);
        for k in 1..=m.nxi {
            assert!(m.node(k, m.ny) >= m.node(k - 1, m.ny) - 1e-12, "station {k}");
        }
        let f = flow(40.0);
        assert!((f.centreline_velocity(0.0).unwrap() - f.mean_velocity()).abs() <= 1e-15);
    }

    #[test]
    fn grid_convergence() {
        let coarse = March::compute(NY, NXI, BETA, POWER);
        let fine = March::compute(2 * NY, 2 * NXI, BETA, POWER);
        for big_x in [1e-3, 0.005, 0.01, 0.02, 0.05, 0.1] {
            let (a, b) = (coarse.centreline(big_x), fine.centreline(big_x));
            eprintln!("X = {big_x}: u_c/U = {a:.7} (default), {b:.7} (halved), rel diff {:.2e}", (a - b) / b);
            assert!((a - b).abs() <= 1e-4 * b, "X = {big_x}: {a} vs {b}");
        }
        // The Picard iteration converged (to PICARD_TOL) at every station of both grids.
        for m in [&coarse, &fine] {
            assert!(
                m.worst_change <= 0.0 && m.picard_max < MAX_PICARD,
                "{} {}",
                m.worst_change,
                m.picard_max
            );
        }
        let (la, lb) = (coarse.first_reaching(1.5 * 0.99).unwrap(), fine.first_reaching(1.5 * 0.99).unwrap());
        eprintln!("L_e/(H Re) = {la:.6} (default), {lb:.6} (halved)");
        for big_x in [1e-4, 1e-3, 0.01, 0.05] {
            let (a, b) = (coarse.pressure_gradient(big_x), fine.pressure_gradient(big_x));
            eprintln!("X = {big_x}: dP/dX = {a:.6} (default), {b:.6} (halved)");
            assert!((a - b).abs() <= 1e-4 * b.abs(), "X = {big_x}: {a} vs {b}");
        }
        // Profiles away from the nodes: the coarse grid's cubic interpolation at the fine
        // grid's extra nodes (mid-points in eta) against the fine grid's values there.
        for big_x in [1e-4, 1e-3, 0.01, 0.05] {
            let (k, w) = fine.locate(big_x);
            let mut worst = 0.0f64;
            for j in (1..2 * fine.ny).step_by(2) {
                let uf = (1.0 - w) * fine.node(k, j) + w * fine.node(k + 1, j);
                worst = worst.max((coarse.velocity(big_x, fine.y_node(j)) - uf).abs());
            }
            eprintln!("X = {big_x}: profile max diff {worst:.2e} U");
            assert!(worst <= 1e-4, "X = {big_x}: {worst}");
        }
        assert!((la - lb).abs() <= 1e-3 * lb, "L_e/(H Re): {la} vs {lb}");
    }

    #[test]
    fn interpolation_between_stations() {
        // A march with the xi step halved has a station at every mid-point of the default one.
        let m = march();
        let fine = March::compute(NY, 2 * NXI, BETA, POWER);
        // (From the second interval on: the first, X < 1.6e-14, holds the inlet jump.)
        let mut worst = 0.0f64;
        for k in 1..NXI {
            let big_x = X_MAX * ((2 * k + 1) as f64 / (2 * NXI) as f64).powf(POWER);
            let d = (m.centreline(big_x) - fine.node(2 * k + 1, fine.ny)).abs();
            worst = worst.max(d);
        }
        eprintln!("centre-line interpolation: max diff {worst:.2e} U");
        assert!(worst <= 1e-6, "{worst}");
    }

    #[test]
    fn development_length_matches_durst_slope() {
        let m = march();
        let le = m.first_reaching(1.5 * 0.99).unwrap();
        eprintln!(
            "L_e / (H Re) at 99 % = {le:.5}; u_c/U at X = 0.01: {:.5}, 0.05: {:.5}",
            m.centreline(0.01),
            m.centreline(0.05)
        );
        // Durst et al. 2005 large-Re slope 0.0442 (REFERENCES.md §3c), within 10 %.
        assert!((le / 0.0442 - 1.0).abs() <= 0.10, "L_e / (H Re) = {le}");
        // The same through the dimensional API, and against the full Durst formula at Re = 1000.
        let f = flow(1000.0);
        let l = f.development_length(0.99).unwrap() / f.width();
        assert!((l - le * 1000.0).abs() <= 1e-9 * l);
        let durst = channel_durst(1000.0).unwrap();
        assert!((l / durst - 1.0).abs() <= 0.10, "L_e / H = {l} vs Durst {durst}");
        // u_c at the returned length is 0.99 * 1.5 U; and 0 for fractions <= 2/3.
        let uc = f.centreline_velocity(f.development_length(0.99).unwrap()).unwrap();
        assert!((uc / (1.5 * f.mean_velocity()) - 0.99).abs() <= 1e-6, "{uc}");
        assert!(f.development_length(0.5).unwrap().abs() <= 0.0);
        assert!(f.development_length(0.9).unwrap() < f.development_length(0.95).unwrap());
    }

    #[test]
    fn rejects_bad_parameters() {
        for (h, u, nu, name) in [
            (0.0, 1.0, 1.0, "width"),
            (-1.0, 1.0, 1.0, "width"),
            (f64::NAN, 1.0, 1.0, "width"),
            (1.0, 0.0, 1.0, "mean_velocity"),
            (1.0, -1.0, 1.0, "mean_velocity"),
            (1.0, 1.0, 0.0, "kinematic_viscosity"),
            (1.0, 1.0, f64::INFINITY, "kinematic_viscosity"),
        ] {
            let e = EntranceFlow::new(h, u, nu).unwrap_err();
            assert!(e.to_string().contains(name), "{e}");
        }
        let f = flow(100.0);
        assert!(f.centreline_velocity(-1e-9).unwrap_err().to_string().contains("x"));
        assert!(f.pressure_gradient(0.0).unwrap_err().to_string().contains("x = 0"));
        assert!(f.profile(-1.0, &[0.1]).unwrap_err().to_string().contains("x = -1"));
        assert!(f.profile(1.0, &[0.1, 0.3]).unwrap_err().to_string().contains("y = 0.3"));
        assert!(f.profile(1.0, &[]).unwrap().is_empty());
        for bad in [0.0, 1.0, -0.5, 1.5, f64::NAN] {
            assert!(f.development_length(bad).unwrap_err().to_string().contains("fraction"), "{bad}");
        }
        assert!(f.development_length(0.99991).unwrap_err().to_string().contains("fraction"));
        assert!(f.development_length(MAX_FRACTION).unwrap() > f.development_length(0.999).unwrap());
    }
}
