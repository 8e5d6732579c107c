//! The stability limits of the adaptive time step (Qiu 2013 eqs. 17–19; Monaghan 1992
//! §10), each scheme taking the smallest of those that bind it
//! ([`crate::scheme::Scheme::stable_step`]). Every limit is in seconds; a limit that does
//! not bind (no flow, no viscosity, no force) is `+∞`.

/// α_f of the force limit `Δt ≤ α_f √(h/|a|_max)` (Monaghan 1992, Annu. Rev. Astron.
/// Astrophys. 30:543, §10).
pub const FORCE_LIMIT: f64 = 0.25;

/// Coefficient of the capillary limit `Δt ≤ 0.25 √(ρ h³/(2π σ))` (Brackbill, Kothe &
/// Zemach 1992 eq. 63; Morris 2000).
pub const CAPILLARY_LIMIT: f64 = 0.25;

/// Advective (CFL) limit `cfl h / speed` (Qiu eq. 17; with the sound speed in `speed` for
/// a compressible scheme, Monaghan 1992 §10).
pub fn advective(cfl: f64, h: f64, speed: f64) -> f64 {
    if speed > 0.0 { cfl * h / speed } else { f64::INFINITY }
}

/// Viscous limit `α_d ρ h² / (μ s)` (Qiu eq. 18), `s` the operator's stiffness relative to
/// the Shao–Lo Laplacian's (1 for it).
pub fn viscous(coefficient: f64, density: f64, h: f64, mu: f64, stiffness: f64) -> f64 {
    if mu > 0.0 { coefficient * density * h * h / (mu * stiffness) } else { f64::INFINITY }
}

/// Force limit `α_f √(h/|a|_max)` ([`FORCE_LIMIT`]).
pub fn force(h: f64, accel: f64) -> f64 {
    if accel > 0.0 { FORCE_LIMIT * (h / accel).sqrt() } else { f64::INFINITY }
}

/// Capillary limit `0.25 √(ρ h³/(2π σ))` ([`CAPILLARY_LIMIT`]).
pub fn capillary(density: f64, h: f64, sigma: f64) -> f64 {
    if sigma > 0.0 {
        CAPILLARY_LIMIT * (density * h * h * h / (2.0 * std::f64::consts::PI * sigma)).sqrt()
    } else {
        f64::INFINITY
    }
}
