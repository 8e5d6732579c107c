//! Probes: time series of measured quantities (DESIGN.md "Run outputs", `probes.json`).
//!
//! Every probe kind writes one or more named quantities; the record is
//! `{ "t": [...], "<probe kind>": { "<quantity>": [...] } }`, arrays aligned with `t`.

use crate::neighbours::{CellSearch, Domain, NeighbourList};
use crate::scene::Probe;
use crate::state::{State, Vector};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

mod young_laplace;

/// Recorded probe series.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ProbeRecord {
    /// Sample times \[s\].
    pub t: Vec<f64>,
    /// Probe kind → quantity → values aligned with `t`.
    #[serde(flatten)]
    pub series: BTreeMap<String, BTreeMap<String, Vec<f64>>>,
}

impl ProbeRecord {
    /// The series `kind.quantity`, if recorded.
    pub fn get(&self, kind: &str, quantity: &str) -> Option<&[f64]> {
        self.series.get(kind)?.get(quantity).map(Vec::as_slice)
    }

    fn push(&mut self, kind: &str, quantity: &str, value: f64) {
        self.series.entry(kind.to_string()).or_default().entry(quantity.to_string()).or_default().push(value);
    }
}

/// How many copies around the axis stand for each ring of an axisymmetric body in the
/// probes ([`State::axis`]): eight, so that the moments up to the second (centroid,
/// ellipsoid axes, kinetic energy, momenta) are the rings' exactly (`Σ_k cos² θ_k = K/2`
/// for K ≥ 3 equally spaced angles).
pub const AZIMUTHS: usize = 8;

/// The rings of an axisymmetric body as [`AZIMUTHS`] copies each, at the angles
/// `θ_k = 2πk/K` about the axis: positions, velocities `(u_r cos θ, u_r sin θ, u_z)`,
/// pressures and volumes (the ring's over K).
#[derive(Debug, Default)]
struct Revolved<const D: usize> {
    x: Vec<Vector<D>>,
    u: Vec<Vector<D>>,
    p: Vec<f64>,
    volume: Vec<f64>,
}

impl<const D: usize> Revolved<D> {
    /// Fills the copies from the fluid particles of `s`, the axis through `axis` along z.
    fn revolve(&mut self, s: &State<D>, axis: [f64; 2]) {
        let n = s.particles.fluid;
        self.x.clear();
        self.u.clear();
        self.p.clear();
        self.volume.clear();
        for a in 0..n {
            let (x, u) = (&s.particles.x[a], &s.particles.u[a]);
            let r = x[0] - axis[0];
            for k in 0..AZIMUTHS {
                let (sin, cos) = (2.0 * std::f64::consts::PI * k as f64 / AZIMUTHS as f64).sin_cos();
                let mut xk = *x;
                let mut uk = *u;
                xk[0] = axis[0] + r * cos;
                xk[1] = axis[1] + r * sin;
                uk[0] = u[0] * cos;
                uk[1] = u[0] * sin;
                self.x.push(xk);
                self.u.push(uk);
                self.p.push(s.particles.p[a]);
                self.volume.push(s.volumes[a] / AZIMUTHS as f64);
            }
        }
    }
}

/// The centroid and the second central moments (per axis) of the points `x` \[m, m²\],
/// weighted by `weights` (equal weights when `None`).
fn moments<const D: usize>(x: &[Vector<D>], weights: Option<&[f64]>) -> (Vector<D>, Vector<D>) {
    match weights {
        None => {
            let n = x.len() as f64;
            let c: Vector<D> = x.iter().sum::<Vector<D>>() / n;
            let m2 = x.iter().map(|p| (p - c).component_mul(&(p - c))).sum::<Vector<D>>() / n;
            (c, m2)
        }
        Some(w) => {
            let total: f64 = w.iter().sum();
            let c: Vector<D> = x.iter().zip(w).map(|(p, w)| p * *w).sum::<Vector<D>>() / total;
            let m2 =
                x.iter().zip(w).map(|(p, w)| (p - c).component_mul(&(p - c)) * *w).sum::<Vector<D>>() / total;
            (c, m2)
        }
    }
}

/// Per-bin sums of a profile: Σ position, Σ velocity, count.
type Bins = (Vec<f64>, Vec<f64>, Vec<usize>);

/// Profile bins: the sums and the writing shared by the velocity profiles.
mod profile_bins {
    use super::{Bins, ProbeRecord};

    /// Fills the profile scratch with `bins` bins from `(bin, position, velocity)` samples
    /// (bins outside `0..bins` dropped): per bin Σ position, Σ velocity and the count.
    pub(super) fn fill(scratch: &mut Bins, bins: usize, samples: impl Iterator<Item = (f64, f64, f64)>) {
        let (sum_y, sum_u, count) = (&mut scratch.0, &mut scratch.1, &mut scratch.2);
        for v in [&mut *sum_y, &mut *sum_u] {
            v.clear();
            v.resize(bins, 0.0);
        }
        count.clear();
        count.resize(bins, 0);
        for (k, y, u) in samples {
            if k >= 0.0 && (k as usize) < bins {
                let k = k as usize;
                sum_y[k] += y;
                sum_u[k] += u;
                count[k] += 1;
            }
        }
    }

    /// Writes the binned profile as `{position}_###` (mean position) and `u_###` (mean
    /// velocity), NaN for an empty bin.
    pub(super) fn write(scratch: &Bins, out: &mut ProbeRecord, key: &str, position: &str) {
        let (sum_y, sum_u, count) = (&scratch.0, &scratch.1, &scratch.2);
        for k in 0..count.len() {
            let c = count[k] as f64;
            let (y, v) = if count[k] > 0 { (sum_y[k] / c, sum_u[k] / c) } else { (f64::NAN, f64::NAN) };
            out.push(key, &format!("{position}_{k:03}"), y);
            out.push(key, &format!("u_{k:03}"), v);
        }
    }
}

/// Kernel weight W(r) used by the Shepard average of `pressure_at`, with its support.
pub struct Weight {
    /// W(r) \[1/m^D\].
    pub w: Box<dyn Fn(f64) -> f64 + Send + Sync>,
    /// Support radius \[m\].
    pub support: f64,
}

impl std::fmt::Debug for Weight {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Weight {{ support: {} }}", self.support)
    }
}

/// The scene's probes with their output keys (`pressure_at`, `pressure_at_1`, ...).
#[derive(Debug)]
pub struct ProbeSet<const D: usize> {
    probes: Vec<(String, Probe)>,
    weight: Weight,
    /// Own neighbour search of the disorder probe (pairs closer than Δx).
    search: Option<(CellSearch<D>, NeighbourList)>,
    /// Scratch of the velocity profiles: per bin Σ position, Σ velocity, count.
    bins: Bins,
    /// Own neighbour search of the drop-shape probe (pairs closer than 2 Δx) and its
    /// union-find parents.
    clusters: Option<(CellSearch<D>, NeighbourList, Vec<u32>)>,
    /// Scratch: the rings of an axisymmetric body as copies around the axis.
    view: Revolved<D>,
    /// The fluid's surface tension γ \[N/m\] (the `young_laplace` probe's `γ κ`).
    surface_tension: f64,
    /// Scratch of the `young_laplace` probe.
    outline: young_laplace::Scratch,
}

impl<const D: usize> ProbeSet<D> {
    /// Probes of a scene; repeated kinds get `_1`, `_2`, ... suffixes. `surface_tension`
    /// \[N/m\] is the fluid's γ (the `young_laplace` probe's).
    pub fn new(probes: &[Probe], weight: Weight, dx: f64, domain: Domain<D>, surface_tension: f64) -> Self {
        let probes: Vec<(String, Probe)> =
            crate::scene::probe_keys(probes).into_iter().zip(probes.iter().cloned()).collect();
        let search = probes
            .iter()
            .any(|(_, p)| matches!(p, Probe::Disorder {}))
            .then(|| (CellSearch::new(dx, domain), NeighbourList::default()));
        let clusters = probes
            .iter()
            .any(|(_, p)| matches!(p, Probe::DropShape {}))
            .then(|| (CellSearch::new(2.0 * dx, domain), NeighbourList::default(), Vec::new()));
        Self {
            probes,
            weight,
            search,
            bins: Default::default(),
            clusters,
            view: Revolved::default(),
            surface_tension,
            outline: Default::default(),
        }
    }

    /// Appends one sample of every probe at time `t`.
    pub fn record(&mut self, s: &State<D>, t: f64, out: &mut ProbeRecord) {
        out.t.push(t);
        let nf = s.particles.fluid;
        let mut view = std::mem::take(&mut self.view);
        let (x, u, pressure, weights) = match s.axis {
            Some(axis) => {
                view.revolve(s, axis);
                (&view.x[..], &view.u[..], &view.p[..], Some(&view.volume[..]))
            }
            None => (
                &s.particles.x[..nf],
                &s.particles.u[..nf],
                &s.particles.p[..nf],
                (!s.volumes.is_empty()).then(|| &s.volumes[..nf]),
            ),
        };
        let mass = s.density * s.volume;
        // Σ over the particles of `f(a)` times the particle's mass \[kg × f\].
        let mass_sum = |f: &dyn Fn(usize) -> f64| -> f64 {
            match weights {
                None => (0..x.len()).map(|a| mass * f(a)).sum(),
                Some(w) => (0..x.len()).map(|a| s.density * w[a] * f(a)).sum(),
            }
        };
        for (key, probe) in &self.probes {
            match probe {
                Probe::EllipseAxes {} => {
                    let (c, m2) = moments(x, weights);
                    let mut lo = Vector::<D>::repeat(f64::INFINITY);
                    let mut hi = Vector::<D>::repeat(f64::NEG_INFINITY);
                    for p in x {
                        lo = lo.inf(p);
                        hi = hi.sup(p);
                    }
                    out.push(key, "a_moment", 2.0 * m2[0].sqrt());
                    out.push(key, "b_moment", 2.0 * m2[1].sqrt());
                    out.push(key, "a_extent", 0.5 * (hi[0] - lo[0]));
                    out.push(key, "b_extent", 0.5 * (hi[1] - lo[1]));
                    out.push(key, "x_centroid", c[0]);
                    out.push(key, "y_centroid", c[1]);
                }
                Probe::PressureAt { point } => {
                    let q = Vector::<D>::from_fn(|i, _| point[i]);
                    let (mut num, mut den) = (0.0, 0.0);
                    for (a, p) in x.iter().enumerate() {
                        let r = s.domain.displacement(p, &q).norm();
                        if r < self.weight.support {
                            let w = (self.weight.w)(r);
                            num += w * pressure[a];
                            den += w;
                        }
                    }
                    out.push(key, "p", if den > 0.0 { num / den } else { f64::NAN });
                }
                Probe::MeanPressure { center, radius } => {
                    let q = Vector::<D>::from_fn(|i, _| center[i]);
                    // Σ V p and Σ V over the particles within the radius (V = 1 when equal).
                    let (mut sum, mut volume, mut count) = (0.0, 0.0, 0usize);
                    for (a, p) in x.iter().enumerate() {
                        if s.domain.displacement(p, &q).norm() <= *radius {
                            let v = weights.map_or(1.0, |w| w[a]);
                            sum += v * pressure[a];
                            volume += v;
                            count += 1;
                        }
                    }
                    out.push(key, "p", if count > 0 { sum / volume } else { f64::NAN });
                    out.push(key, "count", count as f64);
                }
                Probe::PressureGradient { center, radius } => {
                    let q = Vector::<D>::from_fn(|i, _| center[i]);
                    let within = |a: &usize| s.domain.displacement(&x[*a], &q).norm() <= *radius;
                    let weight = |a: usize| weights.map_or(1.0, |w| w[a]);
                    let (mut sum_w, mut sum_x, mut sum_p, mut count) =
                        (0.0, Vector::<D>::zeros(), 0.0, 0usize);
                    for a in (0..x.len()).filter(within) {
                        sum_w += weight(a);
                        sum_x += x[a] * weight(a);
                        sum_p += pressure[a] * weight(a);
                        count += 1;
                    }
                    let (xm, pm) = (sum_x / sum_w, sum_p / sum_w);
                    let mut m = crate::fields::Matrix::<D>::zeros();
                    let mut b = Vector::<D>::zeros();
                    for a in (0..x.len()).filter(within) {
                        let d = x[a] - xm;
                        m += d * d.transpose() * weight(a);
                        b += d * ((pressure[a] - pm) * weight(a));
                    }
                    let g = m.try_inverse().map_or(Vector::<D>::repeat(f64::NAN), |mi| mi * b);
                    for (i, name) in ["dp_dx", "dp_dy", "dp_dz"].iter().enumerate().take(D) {
                        out.push(key, name, g[i]);
                    }
                    out.push(key, "count", count as f64);
                }
                Probe::EllipsoidAxes {} => {
                    let (c, m2) = moments(x, weights);
                    for (i, name) in ["a_moment", "b_moment", "c_moment"].iter().enumerate().take(D) {
                        out.push(key, name, (5.0 * m2[i]).sqrt());
                    }
                    for (i, name) in ["x_centroid", "y_centroid", "z_centroid"].iter().enumerate().take(D) {
                        out.push(key, name, c[i]);
                    }
                }
                Probe::KineticEnergy {} => {
                    let e = mass_sum(&|a| 0.5 * u[a].norm_squared());
                    out.push(key, "e", e);
                }
                Probe::Momentum {} => {
                    let p: Vector<D> = match weights {
                        None => u.iter().sum::<Vector<D>>() * mass,
                        Some(w) => u.iter().zip(w).map(|(v, w)| v * (s.density * w)).sum(),
                    };
                    for (i, name) in ["px", "py", "pz"].iter().enumerate().take(D) {
                        out.push(key, name, p[i]);
                    }
                    let l = |i: usize, j: usize| mass_sum(&|a| x[a][i] * u[a][j] - x[a][j] * u[a][i]);
                    out.push(key, "lz", l(0, 1));
                    if D == 3 {
                        out.push(key, "lx", l(1, 2));
                        out.push(key, "ly", l(2, 0));
                    }
                }
                Probe::Disorder {} => {
                    let (search, list) = self.search.as_mut().expect("built for a disorder probe");
                    search.build(x, list);
                    let (min_pair, close) = disorder(s, x, list);
                    out.push(key, "min_pair_over_dx", min_pair / s.dx);
                    out.push(key, "close_fraction", close);
                }
                Probe::VelocityProfile { axis, component, range, bins, slab } => {
                    let bins = bins.unwrap_or(((range[1] - range[0]) / s.dx).round() as usize);
                    let width = (range[1] - range[0]) / bins as f64;
                    let in_slab = |p: &Vector<D>| {
                        slab.is_none_or(|sl| sl.range[0] <= p[sl.axis] && p[sl.axis] <= sl.range[1])
                    };
                    profile_bins::fill(
                        &mut self.bins,
                        bins,
                        x.iter()
                            .zip(u)
                            .filter(|(p, _)| in_slab(p))
                            .map(|(p, v)| (((p[*axis] - range[0]) / width).floor(), p[*axis], v[*component])),
                    );
                    profile_bins::write(&self.bins, out, key, "y");
                }
                Probe::RadialProfile { axis, center, radius, component, bins } => {
                    let bins = bins.unwrap_or((radius / s.dx).round() as usize);
                    let c = Vector::<D>::from_iterator(center.iter().copied());
                    let width = radius / bins as f64;
                    profile_bins::fill(
                        &mut self.bins,
                        bins,
                        x.iter().zip(u).map(|(p, v)| {
                            let mut r = p - c;
                            r[*axis] = 0.0;
                            let rho = r.norm();
                            ((rho / width).floor(), rho, v[*component])
                        }),
                    );
                    profile_bins::write(&self.bins, out, key, "r");
                }
                Probe::MassBalance {} => {
                    let total = match weights {
                        None => mass * nf as f64,
                        Some(w) => s.density * w.iter().sum::<f64>(),
                    };
                    out.push(key, "mass", total);
                    out.push(key, "inflow", s.flux.inflow);
                    out.push(key, "outflow", s.flux.outflow);
                }
                Probe::MaxSpeed {} => {
                    let max2 = u.iter().map(|v| v.norm_squared()).fold(0.0f64, f64::max);
                    let rms2 = match weights {
                        None => u.iter().map(|v| v.norm_squared()).sum::<f64>() / u.len().max(1) as f64,
                        Some(w) => mass_sum(&|a| u[a].norm_squared()) / (s.density * w.iter().sum::<f64>()),
                    };
                    out.push(key, "u_max", max2.sqrt());
                    out.push(key, "u_rms", rms2.sqrt());
                }
                Probe::DropShape {} => {
                    let (search, list, parent) =
                        self.clusters.as_mut().expect("built for a drop-shape probe");
                    search.build(x, list);
                    out.push(key, "clusters", count_clusters(list, x.len(), parent) as f64);
                    let n = x.len().max(1) as f64;
                    let c: Vector<D> = x.iter().sum::<Vector<D>>() / n;
                    let r_max = x.iter().map(|p| (p - c).norm()).fold(0.0, f64::max);
                    out.push(key, "r_max", r_max);
                }
                Probe::Spread { axis, position, layer } => {
                    let (diameter, width, height) =
                        spread(x, *axis, *position, layer.unwrap_or(1.5 * s.dx), s.dx);
                    out.push(key, "diameter", diameter);
                    out.push(key, "width", width);
                    out.push(key, "height", height);
                }
                Probe::YoungLaplace { above } => {
                    let input = young_laplace::Input {
                        x,
                        p: pressure,
                        outline: &s.outline,
                        dx: s.dx,
                        support: self.weight.support,
                        gamma: self.surface_tension,
                        above: *above,
                    };
                    let c = young_laplace::compare(&input, &mut self.outline);
                    out.push(key, "error_rms", c.rms);
                    out.push(key, "error_max", c.max);
                    out.push(key, "laplace_mean", c.laplace);
                    out.push(key, "p_mean", c.p);
                    out.push(key, "count", c.count as f64);
                }
                Probe::Solver {} => {
                    out.push(
                        key,
                        "free_surface_count",
                        s.particles.free_surface.iter().filter(|&&f| f).count() as f64,
                    );
                    out.push(key, "iterations", s.solve.iterations as f64);
                    // Measured whenever the scene has this probe (the run driver asks for it).
                    out.push(key, "residual", s.solve.residual.unwrap_or(f64::NAN));
                    out.push(key, "p_max", largest_magnitude(&s.particles.p[..nf]));
                }
            }
        }
        self.view = view;
    }
}

/// Largest |v| over `values`, NaN if any is NaN (`f64::max` would skip it), 0 when empty.
fn largest_magnitude(values: &[f64]) -> f64 {
    values.iter().map(|v| v.abs()).fold(0.0, |m, v| if v > m || v.is_nan() { v } else { m })
}

/// The `spread` probe's (contact diameter, spread width, height) \[m\] of the particles
/// `x` above the plane `x[axis] = position` (see [`Probe::Spread`]); zeros when none is.
fn spread<const D: usize>(
    x: &[Vector<D>],
    axis: usize,
    position: f64,
    layer: f64,
    dx: f64,
) -> (f64, f64, f64) {
    let above = || x.iter().filter(|p| p[axis] > position);
    let n = above().count();
    if n == 0 {
        return (0.0, 0.0, 0.0);
    }
    let mut c: Vector<D> = above().sum::<Vector<D>>() / n as f64;
    c[axis] = 0.0;
    let (mut contact, mut all, mut top) = (f64::NEG_INFINITY, 0.0f64, 0.0f64);
    for p in above() {
        let mut r = p - c;
        r[axis] = 0.0;
        let (rho, s) = (r.norm(), p[axis] - position);
        all = all.max(rho);
        top = top.max(s);
        if s <= layer {
            contact = contact.max(rho);
        }
    }
    let diameter = if contact.is_finite() { 2.0 * (contact + 0.5 * dx) } else { 0.0 };
    (diameter, 2.0 * (all + 0.5 * dx), top + 0.5 * dx)
}

/// Smallest pair distance \[m\] (Δx when no pair is closer) and the fraction of particles
/// with a neighbour closer than 0.5 Δx; `list` holds the pairs closer than Δx.
fn disorder<const D: usize>(s: &State<D>, x: &[Vector<D>], list: &NeighbourList) -> (f64, f64) {
    let mut min = s.dx;
    let mut close = 0usize;
    for a in 0..x.len() {
        let mut m = s.dx;
        for &b in list.of(a) {
            m = m.min(s.domain.displacement(&x[a], &x[b as usize]).norm());
        }
        min = min.min(m);
        if m < 0.5 * s.dx {
            close += 1;
        }
    }
    (min, close as f64 / x.len().max(1) as f64)
}

/// Number of connected components of the graph of `n` particles with the edges of `list`
/// (union-find with path halving; `parent` is scratch).
fn count_clusters(list: &NeighbourList, n: usize, parent: &mut Vec<u32>) -> usize {
    fn root(parent: &mut [u32], mut a: usize) -> usize {
        while parent[a] as usize != a {
            parent[a] = parent[parent[a] as usize];
            a = parent[a] as usize;
        }
        a
    }
    parent.clear();
    parent.extend(0..n as u32);
    for a in 0..n {
        for &b in list.of(a) {
            let (ra, rb) = (root(parent, a), root(parent, b as usize));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb) as u32;
            }
        }
    }
    (0..n).filter(|&a| root(parent, a) == a).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A puddle on the plane z = 0: a one-row disc of particles at z = Δx/2 (lattice points
    /// within 5 Δx of the axis) under a column rising to z = 6.5 Δx, above a film row at
    /// z = −Δx/2 that the probe leaves out. The diameter and width add Δx/2 to the outermost
    /// centre, the height Δx/2 to the top one.
    #[test]
    fn spread_of_a_puddle_and_its_column() {
        let dx = 0.1;
        let mut x: Vec<Vector<3>> = Vec::new();
        for i in -8..=8 {
            for j in -8..=8 {
                let (px, py) = (i as f64 * dx, j as f64 * dx);
                if px.hypot(py) <= 5.0 * dx + 1e-12 {
                    x.push(Vector::<3>::new(px, py, 0.5 * dx));
                }
                x.push(Vector::<3>::new(px, py, -0.5 * dx));
            }
        }
        for k in 1..=6 {
            x.push(Vector::<3>::new(0.0, 0.0, (k as f64 + 0.5) * dx));
        }
        let (diameter, width, height) = spread(&x, 2, 0.0, 1.5 * dx, dx);
        assert!((diameter - 2.0 * 5.5 * dx).abs() < 1e-12, "{diameter}");
        assert!((width - diameter).abs() < 1e-12 && (height - 7.0 * dx).abs() < 1e-12, "{width} {height}");
        // A lamella lifted off the plane at the rim widens the width, not the diameter.
        x.push(Vector::<3>::new(7.0 * dx, 0.0, 2.5 * dx));
        x.push(Vector::<3>::new(-7.0 * dx, 0.0, 2.5 * dx));
        let (d2, w2, _) = spread(&x, 2, 0.0, 1.5 * dx, dx);
        assert!((d2 - diameter).abs() < 1e-12 && w2 > diameter + 2.0 * dx, "{d2} {w2}");
        // Nothing above the plane: zeros, not NaN.
        assert_eq!(spread(&x, 2, 10.0, dx, dx), (0.0, 0.0, 0.0));
    }
}
