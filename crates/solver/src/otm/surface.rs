//! Surface tension as a surface energy on the boundary nodes (Zhou et al. 2021 §2.3.2;
//! OTM.md "Surface tension as a surface energy"). The boundary nodes keep the connectivity
//! they had at set-up, so the surface cannot break up or coalesce.
//!
//! - 2D: a closed polyline, `E = γ Σ_edges |x_a − x_b|` \[J/m\]; the nodal force
//!   `f_a = −∂E/∂x_a = γ [(x_b − x_a)/r_ab + (x_c − x_a)/r_ac]`, two pulls of magnitude γ
//!   toward the neighbours (on a regular N-gon of radius R, `|f_a| = 2γ sin(π/N)`, so
//!   `Δp = γ/R`).
//! - Axisymmetric, in the (r, z) half-plane: an open polyline from the axis to the axis,
//!   `E = γ π Σ_segments (r_a + r_b) |x_a − x_b|` \[J\] (frustum areas), so
//!   `f_a = γ π [(r_a + r_b)(x_b − x_a)/r_ab + (r_a + r_c)(x_c − x_a)/r_ac − (r_ab + r_ac) e_r]`,
//!   the last term Zhou's "attraction toward the axis".

use nalgebra::SVector;

/// A point of the plane (2D) or of the (r, z) half-plane (axisymmetric) \[m\].
pub type Point = SVector<f64, 2>;

/// The closed polyline's surface energy per unit depth \[J/m\] for surface tension `gamma`
/// \[N/m\]: `γ Σ |x_a − x_b|` over the edges `ring[i] – ring[i+1]` (and back to the start).
pub fn energy_2d(nodes: &[Point], ring: &[usize], gamma: f64) -> f64 {
    let n = ring.len();
    (0..n).map(|i| (nodes[ring[(i + 1) % n]] - nodes[ring[i]]).norm()).sum::<f64>() * gamma
}

/// Adds the closed polyline's surface-tension forces \[N/m\] to `forces` (indexed like
/// `nodes`): `f_a = γ [(x_b − x_a)/r_ab + (x_c − x_a)/r_ac]` with `b`, `c` the neighbours
/// of `a` along `ring`.
pub fn add_forces_2d(nodes: &[Point], ring: &[usize], gamma: f64, forces: &mut [Point]) {
    let n = ring.len();
    for i in 0..n {
        let (a, b) = (ring[i], ring[(i + 1) % n]);
        let pull = (nodes[b] - nodes[a]).normalize() * gamma;
        forces[a] += pull;
        forces[b] -= pull;
    }
}

/// The surface energy \[J\] of the surface of revolution traced by the open polyline
/// `chain` in the (r, z) half-plane (`x[0] = r`, `x[1] = z`): `γ π Σ (r_a + r_b) |x_a − x_b|`,
/// the frustum areas times `gamma` \[N/m\].
pub fn energy_axisymmetric(nodes: &[Point], chain: &[usize], gamma: f64) -> f64 {
    chain
        .windows(2)
        .map(|w| {
            let (a, b) = (nodes[w[0]], nodes[w[1]]);
            (a[0] + b[0]) * (b - a).norm()
        })
        .sum::<f64>()
        * gamma
        * std::f64::consts::PI
}

/// Adds the axisymmetric surface-tension forces \[N\] of the open polyline `chain` to
/// `forces`: per segment `a – b` of length `ℓ`, `γ π [(r_a + r_b)(x_b − x_a)/ℓ − ℓ e_r]` on
/// `a` and its mirror on `b` (`−∂E/∂x` of [`energy_axisymmetric`]).
pub fn add_forces_axisymmetric(nodes: &[Point], chain: &[usize], gamma: f64, forces: &mut [Point]) {
    let e_r = Point::new(1.0, 0.0);
    let c = gamma * std::f64::consts::PI;
    for w in chain.windows(2) {
        let (a, b) = (w[0], w[1]);
        let d = nodes[b] - nodes[a];
        let len = d.norm();
        let along = d / len * (nodes[a][0] + nodes[b][0]);
        forces[a] += (along - e_r * len) * c;
        forces[b] += (-along - e_r * len) * c;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn circle(n: usize, radius: f64, from: f64, to: f64, closed: bool) -> Vec<Point> {
        let steps = if closed { n } else { n - 1 };
        (0..n)
            .map(|i| {
                let t = from + (to - from) * i as f64 / steps as f64;
                Point::new(radius * t.cos(), radius * t.sin())
            })
            .collect()
    }

    /// A regular N-gon: every node pulled inward by 2γ sin(π/N), so Δp = γ/R.
    #[test]
    fn regular_polygon_force_is_two_gamma_sin_pi_over_n() {
        let (gamma, radius) = (1.0, 0.2);
        for n in [3, 8, 64] {
            let nodes = circle(n, radius, 0.0, 2.0 * PI, true);
            let ring: Vec<usize> = (0..n).collect();
            let mut f = vec![Point::zeros(); n];
            add_forces_2d(&nodes, &ring, gamma, &mut f);
            let expected = 2.0 * gamma * (PI / n as f64).sin();
            for (fa, xa) in f.iter().zip(&nodes) {
                assert!((fa.norm() - expected).abs() < 1e-12, "|f| = {} against {expected}", fa.norm());
                assert!((fa.normalize() + xa.normalize()).norm() < 1e-12, "inward");
            }
            // Over the edge length 2 R sin(π/N): Δp = γ / R.
            let dp = expected / (2.0 * radius * (PI / n as f64).sin());
            assert!((dp - gamma / radius).abs() < 1e-12);
        }
    }

    /// The forces are −∂E/∂x (central differences) in 2D and axisymmetric.
    #[test]
    fn forces_are_minus_the_energy_gradient() {
        let nodes2: Vec<Point> = [[0.0, 0.0], [1.0, 0.1], [1.2, 0.9], [0.3, 1.1], [-0.2, 0.5]]
            .iter()
            .map(|p| Point::from(*p))
            .collect();
        let ring = [0, 1, 2, 3, 4];
        let chain = [0, 1, 2, 3];
        let axi: Vec<Point> =
            [[0.0, -1.0], [0.7, -0.6], [0.9, 0.3], [0.0, 1.0]].iter().map(|p| Point::from(*p)).collect();
        let check = |nodes: &[Point], energy: &dyn Fn(&[Point]) -> f64, forces: &[Point]| {
            let e = 1e-6;
            for a in 0..nodes.len() {
                for k in 0..2 {
                    let mut plus = nodes.to_vec();
                    plus[a][k] += e;
                    let mut minus = nodes.to_vec();
                    minus[a][k] -= e;
                    let fd = -(energy(&plus) - energy(&minus)) / (2.0 * e);
                    assert!(
                        (fd - forces[a][k]).abs() < 1e-7,
                        "node {a}, axis {k}: {fd} against {}",
                        forces[a][k]
                    );
                }
            }
        };
        let mut f2 = vec![Point::zeros(); 5];
        add_forces_2d(&nodes2, &ring, 1.5, &mut f2);
        check(&nodes2, &|n| energy_2d(n, &ring, 1.5), &f2);
        let mut fa = vec![Point::zeros(); 4];
        add_forces_axisymmetric(&axi, &chain, 1.5, &mut fa);
        check(&axi, &|n| energy_axisymmetric(n, &chain, 1.5), &fa);
    }

    /// A sphere of radius R traced by a fine semicircle: the frustum energy is 4πR²γ, and a
    /// node's force is the Laplace jump 2γ/R over its band of the sphere, pointing inward.
    #[test]
    fn axisymmetric_sphere_carries_the_laplace_jump() {
        let (gamma, radius, n) = (1.0, 0.2, 401);
        let nodes = circle(n, radius, -PI / 2.0, PI / 2.0, false);
        let chain: Vec<usize> = (0..n).collect();
        let area = 4.0 * PI * radius * radius;
        assert!((energy_axisymmetric(&nodes, &chain, gamma) / (gamma * area) - 1.0).abs() < 1e-4);
        let mut f = vec![Point::zeros(); n];
        add_forces_axisymmetric(&nodes, &chain, gamma, &mut f);
        let arc = PI * radius / (n - 1) as f64;
        for a in (n / 4)..(3 * n / 4) {
            let band = 2.0 * PI * nodes[a][0] * arc;
            let expected = 2.0 * gamma / radius * band;
            assert!(
                (f[a].norm() / expected - 1.0).abs() < 1e-3,
                "node {a}: {} against {expected}",
                f[a].norm()
            );
            assert!((f[a].normalize() + nodes[a].normalize()).norm() < 1e-3, "inward");
        }
    }
}
