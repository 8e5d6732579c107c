//! Particle generation: bodies filled on the cell-centred lattice (DESIGN.md "Meaning").
//!
//! Along each axis the lattice is `x = c + (i + ½) Δx` about the shape's centre `c`, so it
//! is symmetric about the centre; a disc keeps the points with `|x − c| ≤ R`
//! (R = 1, Δx = 0.04 gives the 1976 particles of Qiu 2013 §3.1).

use super::schema::{Body, InitialPressure, InitialVelocity, Jitter, Packing, Shape};
use nalgebra::{SMatrix, SVector};
use rand::{Rng, SeedableRng};

/// Relative tolerance on shape membership, so lattice points exactly on the boundary count.
const EDGE_TOL: f64 = 1e-9;

/// Initial state of one particle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Seed<const D: usize> {
    /// Position \[m\].
    pub x: SVector<f64, D>,
    /// Velocity \[m/s\].
    pub u: SVector<f64, D>,
    /// Pressure \[Pa\].
    pub p: f64,
}

/// Lattice points of `shape` at spacing `dx` (shape assumed validated for dimension `D`).
pub fn lattice_points<const D: usize>(shape: &Shape, dx: f64) -> Vec<SVector<f64, D>> {
    match shape {
        Shape::Circle { center, radius } | Shape::Sphere { center, radius } => {
            let c = SVector::<f64, D>::from_iterator(center.iter().copied());
            let n = (radius / dx).ceil() as i64 + 1;
            let r2 = radius * radius * (1.0 + EDGE_TOL);
            let mut out = Vec::new();
            for_each_index::<D>([-n - 1; D], [n; D], |idx| {
                let x = c + SVector::<f64, D>::from_fn(|k, _| (idx[k] as f64 + 0.5) * dx);
                if (x - c).norm_squared() <= r2 {
                    out.push(x);
                }
            });
            out
        }
        Shape::Rectangle { min, max } | Shape::Box { min, max } => {
            let lo = SVector::<f64, D>::from_iterator(min.iter().copied());
            let hi = SVector::<f64, D>::from_iterator(max.iter().copied());
            let c = (lo + hi) * 0.5;
            let counts: [i64; D] = std::array::from_fn(|k| ((hi[k] - lo[k]) / dx + EDGE_TOL).floor() as i64);
            let mut out = Vec::new();
            // Each axis over its own count: a long thin rectangle costs its particle count,
            // not the cube of its longest side.
            for_each_index::<D>([0; D], counts.map(|n| n - 1), |idx| {
                out.push(SVector::<f64, D>::from_fn(|k, _| {
                    c[k] + (idx[k] as f64 - 0.5 * (counts[k] - 1) as f64) * dx
                }));
            });
            out
        }
        Shape::Cylinder { center, axis, radius, length, inner_radius } => {
            cylinder_points::<D>(center, *axis, (*inner_radius, *radius, *length), dx, false)
        }
    }
}

/// Concentric rings filling the disc of `radius` about `center` (`Packing::Rings`): ring
/// `k = 1..n`, `n = max(1, round(R/Δx))`, at `r_k = (k − ½) R/n` holds
/// `m_k = round(2π (k − ½))` particles at the angles `2π (j + ½)/m_k`. The annulus of ring
/// `k` has the area `2π r_k R/n`, so every particle stands for `(R/n)² (2π(k − ½)/m_k)`,
/// within 5 % of `(R/n)²` for `k ≥ 2` (the inner ring's 3 particles cover `π (R/n)²`).
fn ring_points<const D: usize>(center: &[f64], radius: f64, dx: f64) -> Vec<SVector<f64, D>> {
    let c = SVector::<f64, D>::from_iterator(center.iter().copied());
    rings(0.0, radius, dx).map(|(r, theta)| c + ring_offset::<D>(r, theta, 0, 1)).collect()
}

/// Concentric spherical shells filling the ball of `radius` about `center`
/// (`Packing::Shells`): shell `k = 1..n`, `n = max(1, round(R/Δx))`, at `r_k = (k − ½) s`,
/// `s = R/n`, holds `m_k = round(4π (k − ½)²)` points on the golden-angle spiral
/// `z_j = 1 − (2j + 1)/m_k`, `φ_j = (j + k) π (3 − √5)` (González 2010, Math. Geosci.
/// 42:49; the `+ k` turns each shell against the one inside it). The shell of radius `r_k`
/// and thickness `s` has the volume `4π r_k² s`, so every point stands for about `s³`.
fn shell_points<const D: usize>(center: &[f64], radius: f64, dx: f64) -> Vec<SVector<f64, D>> {
    let c = SVector::<f64, D>::from_iterator(center.iter().copied());
    let n = ((radius / dx).round() as usize).max(1);
    let spacing = radius / n as f64;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut out = Vec::new();
    for k in 1..=n {
        let shell = k as f64 - 0.5;
        let m = (4.0 * std::f64::consts::PI * shell * shell).round() as usize;
        for j in 0..m {
            let z = 1.0 - (2 * j + 1) as f64 / m as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let (s, co) = ((j + k) as f64 * golden).sin_cos();
            let dir = [rho * co, rho * s, z];
            out.push(c + SVector::<f64, D>::from_fn(|i, _| shell * spacing * dir[i]));
        }
    }
    out
}

/// The rings of the annulus `inner < ρ <= outer` as `(radius, angle)` pairs: with
/// `inner = 0` those of [`ring_points`] (spacing `s = R/round(R/Δx)`); with `inner > 0` the
/// rings of a disc of radius `inner` continued outward (`s = inner/round(inner/Δx)`, rings
/// `k > inner/s` while `(k − ½) s <= outer`), so a shell meets the disc it surrounds.
fn rings(inner: f64, outer: f64, dx: f64) -> impl Iterator<Item = (f64, f64)> {
    let base = if inner > 0.0 { inner } else { outer };
    let n = ((base / dx).round() as usize).max(1);
    let spacing = base / n as f64;
    let first = if inner > 0.0 { n + 1 } else { 1 };
    let last = if inner > 0.0 { (outer * (1.0 + EDGE_TOL) / spacing + 0.5).floor() as usize } else { n };
    (first..=last).flat_map(move |k| {
        let ring = k as f64 - 0.5;
        let m = (2.0 * std::f64::consts::PI * ring).round() as usize;
        (0..m).map(move |j| (ring * spacing, 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / m as f64))
    })
}

/// The offset `r (cos θ e_a + sin θ e_b)` in the plane of axes `a` and `b`.
fn ring_offset<const D: usize>(r: f64, theta: f64, a: usize, b: usize) -> SVector<f64, D> {
    let (s, c) = theta.sin_cos();
    SVector::<f64, D>::from_fn(|i, _| {
        if i == a {
            r * c
        } else if i == b {
            r * s
        } else {
            0.0
        }
    })
}

/// The two axes across a cylinder along `axis`, in increasing order.
fn cross_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

/// The points of a cylinder (or shell) along `axis`: `count = floor(length/Δx)` layers at
/// `c + (i − (count − 1)/2) Δx` along the axis (cell-centred and symmetric, as a box), each
/// layer the cross-section's rings (`rings` true) or its lattice points `(i + ½) Δx` about the
/// centre with `inner < ρ <= radius`.
fn cylinder_points<const D: usize>(
    center: &[f64],
    axis: usize,
    (inner, radius, length): (f64, f64, f64),
    dx: f64,
    rings_packing: bool,
) -> Vec<SVector<f64, D>> {
    let c = SVector::<f64, D>::from_iterator(center.iter().copied());
    let (a, b) = cross_axes(axis);
    let section: Vec<SVector<f64, D>> = if rings_packing {
        rings(inner, radius, dx).map(|(r, theta)| ring_offset::<D>(r, theta, a, b)).collect()
    } else {
        let n = (radius / dx).ceil() as i64 + 1;
        let (lo2, hi2) = (inner * inner * (1.0 + EDGE_TOL), radius * radius * (1.0 + EDGE_TOL));
        let mut out = Vec::new();
        for i in -n - 1..=n {
            for j in -n - 1..=n {
                let (p, q) = ((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx);
                let rho2 = p * p + q * q;
                if rho2 <= hi2 && (inner == 0.0 || rho2 > lo2) {
                    let mut x = SVector::<f64, D>::zeros();
                    (x[a], x[b]) = (p, q);
                    out.push(x);
                }
            }
        }
        out
    };
    let count = ((length / dx + EDGE_TOL).floor() as i64).max(1);
    let mut out = Vec::with_capacity(section.len() * count as usize);
    for i in 0..count {
        let mut along = SVector::<f64, D>::zeros();
        along[axis] = (i as f64 - 0.5 * (count - 1) as f64) * dx;
        out.extend(section.iter().map(|s| c + along + s));
    }
    out
}

/// The initial velocity of `body` at `x` \[m/s\].
pub fn initial_velocity<const D: usize>(body: &Body, x: &SVector<f64, D>) -> SVector<f64, D> {
    match &body.velocity {
        InitialVelocity::Zero => SVector::<f64, D>::zeros(),
        InitialVelocity::Affine { gradient, offset } => {
            let m = SMatrix::<f64, D, D>::from_fn(|i, j| gradient[i][j]);
            m * x + SVector::<f64, D>::from_iterator(offset.iter().copied())
        }
    }
}

/// The initial pressure of `body` at `x` \[Pa\] (`density` \[kg/m³\] and the body force `g`
/// \[m/s²\] for a hydrostatic field).
pub fn initial_pressure<const D: usize>(
    body: &Body,
    x: &SVector<f64, D>,
    density: f64,
    g: &SVector<f64, D>,
) -> f64 {
    match &body.pressure {
        InitialPressure::Zero => 0.0,
        InitialPressure::Quadratic { center, value, hessian } => {
            let c = SVector::<f64, D>::from_iterator(center.iter().copied());
            let h = SMatrix::<f64, D, D>::from_fn(|i, j| hessian[i][j]);
            let r = x - c;
            value + 0.5 * r.dot(&(h * r))
        }
        InitialPressure::Hydrostatic { surface_point } => {
            let s = SVector::<f64, D>::from_iterator(surface_point.iter().copied());
            density * g.dot(&(x - s))
        }
    }
}

/// Seeds (position, velocity, pressure) of one body; `g` is the body force for hydrostatic
/// pressure, `density` the fluid density \[kg/m³\].
pub fn seed_body<const D: usize>(body: &Body, dx: f64, density: f64, g: &SVector<f64, D>) -> Vec<Seed<D>> {
    let velocity = |x: &SVector<f64, D>| initial_velocity(body, x);
    let pressure = |x: &SVector<f64, D>| initial_pressure(body, x, density, g);
    seed_points::<D>(body, dx).into_iter().map(|x| Seed { x, u: velocity(&x), p: pressure(&x) }).collect()
}

/// The points of a body at spacing `dx`: its packing (rings) or the lattice.
pub fn seed_points<const D: usize>(body: &Body, dx: f64) -> Vec<SVector<f64, D>> {
    match (body.packing, &body.shape) {
        (Packing::Rings, Shape::Circle { center, radius }) => ring_points::<D>(center, *radius, dx),
        (Packing::Shells, Shape::Sphere { center, radius }) => shell_points::<D>(center, *radius, dx),
        (Packing::Rings, Shape::Cylinder { center, axis, radius, length, inner_radius }) => {
            cylinder_points::<D>(center, *axis, (*inner_radius, *radius, *length), dx, true)
        }
        _ => lattice_points::<D>(&body.shape, dx),
    }
}

/// Displaces every point by a vector uniform in the ball of radius `jitter.fraction · dx`
/// (rejection sampling in the cube), drawn in order from ChaCha8 seeded with `jitter.seed`:
/// deterministic for a seed, independent of threads and platform.
pub fn apply_jitter<const D: usize>(points: &mut [SVector<f64, D>], dx: f64, jitter: &Jitter) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(jitter.seed);
    let radius = jitter.fraction * dx;
    for x in points {
        let v = loop {
            let v = SVector::<f64, D>::from_fn(|_, _| rng.random_range(-1.0..=1.0));
            if v.norm_squared() <= 1.0 {
                break v;
            }
        };
        *x += radius * v;
    }
}

/// Calls `f` for every integer index `i` with `lo[k] <= i[k] <= hi[k]`, last axis fastest.
fn for_each_index<const D: usize>(lo: [i64; D], hi: [i64; D], mut f: impl FnMut(&[i64; D])) {
    if (0..D).any(|k| hi[k] < lo[k]) {
        return;
    }
    let mut idx = lo;
    loop {
        f(&idx);
        let mut k = D;
        loop {
            if k == 0 {
                return;
            }
            k -= 1;
            if idx[k] < hi[k] {
                idx[k] += 1;
                break;
            }
            idx[k] = lo[k];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn disc(r: f64) -> Shape {
        Shape::Circle { center: vec![0.0, 0.0], radius: r }
    }

    #[test]
    fn qiu_particle_counts() {
        // CASES.md: 1976, 7860, 31428, 125676 particles.
        for (dx, n) in [(0.04, 1976), (0.02, 7860), (0.01, 31428), (0.005, 125676)] {
            assert_eq!(lattice_points::<2>(&disc(1.0), dx).len(), n, "dx = {dx}");
        }
    }

    #[test]
    fn rings_fill_the_disc_with_one_spacing_per_particle() {
        let (r, dx) = (0.2, 0.01);
        let pts = ring_points::<2>(&[0.1, -0.3], r, dx);
        // Σ_k round(2π (k − ½)) for k = 1..20, against π R²/Δx² = 1256.6.
        assert_eq!(pts.len(), 1257);
        let c = SVector::<f64, 2>::new(0.1, -0.3);
        let radii: Vec<f64> = pts.iter().map(|x| (x - c).norm()).collect();
        let outer = radii.iter().cloned().fold(0.0, f64::max);
        assert!((outer - (r - 0.5 * dx)).abs() < 1e-12, "outer ring half a spacing inside R");
        let centroid: SVector<f64, 2> = pts.iter().sum::<SVector<f64, 2>>() / pts.len() as f64;
        assert!((centroid - c).norm() < 1e-12);
        // No two particles closer than 0.8 Δx (the ring spacing is Δx along and across).
        for (i, a) in pts.iter().enumerate() {
            for b in &pts[i + 1..] {
                assert!((a - b).norm() > 0.8 * dx, "{a} and {b}");
            }
        }
    }

    #[test]
    fn rectangle_is_cell_centred_and_symmetric() {
        let s = Shape::Rectangle { min: vec![-0.5, -0.5], max: vec![0.5, 0.5] };
        let pts = lattice_points::<2>(&s, 0.02);
        assert_eq!(pts.len(), 2500);
        let c: SVector<f64, 2> = pts.iter().sum::<SVector<f64, 2>>() / pts.len() as f64;
        assert!(c.norm() < 1e-12);
        let xmin = pts.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
        assert!((xmin + 0.49).abs() < 1e-12);
    }

    #[test]
    fn long_thin_rectangle_costs_its_particle_count() {
        // 1e6 × 1 lattice points: iterating the square of the long side would take hours.
        let s = Shape::Rectangle { min: vec![0.0, 0.0], max: vec![1e4, 0.01] };
        assert_eq!(lattice_points::<2>(&s, 0.01).len(), 1_000_000);
    }

    #[test]
    fn jitter_is_seeded_bounded_and_disorders() {
        let s = Shape::Rectangle { min: vec![0.0, 0.0], max: vec![1.0, 1.0] };
        let dx = 0.05;
        let lattice = lattice_points::<2>(&s, dx);
        let jittered = |fraction: f64, seed: u64| {
            let mut pts = lattice.clone();
            apply_jitter(&mut pts, dx, &Jitter { fraction, seed });
            pts
        };
        let a = jittered(0.3, 7);
        assert_eq!(a, jittered(0.3, 7), "same seed, same particles");
        assert_ne!(a, jittered(0.3, 8), "another seed, other particles");
        let moved: Vec<f64> = a.iter().zip(&lattice).map(|(p, q)| (p - q).norm() / dx).collect();
        let max = moved.iter().copied().fold(0.0, f64::max);
        let mean = moved.iter().sum::<f64>() / moved.len() as f64;
        assert!(max <= 0.3 + 1e-12, "bounded by 0.3 dx: {max}");
        // Uniform in the disc: the mean distance is 2/3 of the radius.
        assert!((mean - 0.2).abs() < 0.02, "mean displacement {mean} dx");
        assert!(max > 0.29, "the whole disc is sampled: {max}");
        assert_eq!(jittered(0.0, 7), lattice, "fraction 0 leaves the lattice");
        let mut b = lattice_points::<3>(&Shape::Sphere { center: vec![0.0; 3], radius: 0.2 }, dx);
        let before = b.clone();
        apply_jitter(&mut b, dx, &Jitter { fraction: 0.1, seed: 1 });
        assert!(b.iter().zip(&before).all(|(p, q)| (p - q).norm() <= 0.1 * dx + 1e-15));
    }

    fn cylinder(radius: f64, inner_radius: f64, packing: Packing) -> Body {
        let shape =
            Shape::Cylinder { center: vec![0.5, 0.0, 0.0], axis: 0, radius, length: 0.1, inner_radius };
        Body {
            role: super::super::schema::Role::Fluid,
            shape,
            velocity: InitialVelocity::Zero,
            pressure: InitialPressure::Zero,
            jitter: None,
            packing,
        }
    }

    #[test]
    fn a_ringed_pipe_wall_continues_its_fluid_rings() {
        let (r, dx) = (0.08, 0.01);
        let fluid = seed_points::<3>(&cylinder(r, 0.0, Packing::Rings), dx);
        let wall = seed_points::<3>(&cylinder(r + 0.025, r, Packing::Rings), dx);
        // 10 layers along x at 0.455 … 0.545; Σ_k round(2π (k − ½)) over k = 1..8 = 201 per
        // layer; the shell's rings k = 9, 10, 11 at 8.5, 9.5, 10.5 dx (≤ 10.5 dx): 53 + 60 + 66.
        assert_eq!(fluid.len(), 201 * 10);
        assert_eq!(wall.len(), (53 + 60 + 66) * 10);
        let rho = |x: &SVector<f64, 3>| x.y.hypot(x.z);
        let outer = fluid.iter().map(rho).fold(0.0, f64::max);
        let inner = wall.iter().map(rho).fold(f64::INFINITY, f64::min);
        assert!((outer - 7.5 * dx).abs() < 1e-12 && (inner - 8.5 * dx).abs() < 1e-12, "{outer} {inner}");
        let xs: Vec<f64> = fluid.iter().map(|x| x.x).collect();
        assert!((xs.iter().cloned().fold(f64::INFINITY, f64::min) - 0.455).abs() < 1e-12);
        // No wall particle closer than 0.8 dx to a fluid particle.
        for w in &wall {
            assert!(fluid.iter().all(|f| (w - f).norm() > 0.8 * dx), "{w}");
        }
    }

    #[test]
    fn a_lattice_shell_and_its_cylinder_share_no_point() {
        let dx = 0.01;
        let fluid = seed_points::<3>(&cylinder(0.05, 0.0, Packing::Lattice), dx);
        let wall = seed_points::<3>(&cylinder(0.08, 0.05, Packing::Lattice), dx);
        let solid = seed_points::<3>(&cylinder(0.08, 0.0, Packing::Lattice), dx);
        assert_eq!(fluid.len() + wall.len(), solid.len(), "the shell is the solid cylinder minus the fluid");
        for w in &wall {
            assert!(fluid.iter().all(|f| (w - f).norm() > 0.99 * dx));
        }
    }

    #[test]
    fn shells_fill_the_ball_with_one_spacing_per_particle() {
        let (r, dx) = (0.2, 0.02);
        let pts = shell_points::<3>(&[0.1, 0.0, -0.3], r, dx);
        // Σ_k round(4π (k − ½)²) for k = 1..10, against 4π R³/(3 Δx³) = 4188.8.
        let want: usize =
            (1..=10).map(|k| (4.0 * std::f64::consts::PI * (k as f64 - 0.5).powi(2)).round() as usize).sum();
        assert_eq!(pts.len(), want);
        assert!((want as f64 / 4188.8 - 1.0).abs() < 0.01, "{want}");
        let c = SVector::<f64, 3>::new(0.1, 0.0, -0.3);
        let outer = pts.iter().map(|x| (x - c).norm()).fold(0.0, f64::max);
        assert!((outer - (r - 0.5 * dx)).abs() < 1e-12, "outer shell half a spacing inside R");
        let centroid: SVector<f64, 3> = pts.iter().sum::<SVector<f64, 3>>() / pts.len() as f64;
        assert!((centroid - c).norm() < 0.01 * dx, "{centroid}");
        // No two particles closer than 0.8 Δx (the closest pair, 0.835 Δx, is in the
        // innermost shell: three points at Δx/2).
        let min = pts
            .iter()
            .enumerate()
            .flat_map(|(i, a)| pts[i + 1..].iter().map(move |b| (a - b).norm()))
            .fold(f64::INFINITY, f64::min);
        assert!(min > 0.8 * dx, "closest pair {} dx", min / dx);
    }

    #[test]
    fn sphere_in_3d() {
        let s = Shape::Sphere { center: vec![0.0; 3], radius: 0.2 };
        let pts = lattice_points::<3>(&s, 0.05);
        assert!(pts.iter().all(|p| p.norm() <= 0.2 + 1e-12));
        assert!(!pts.is_empty());
    }
}
