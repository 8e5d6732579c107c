//! The `young_laplace` probe (Zhou 2021 §3.4, OTM.md "Drop on a smooth plate"): the
//! pressure on a 2D drop's outline against the Young–Laplace pressure `γ κ` of a local
//! circle fit through five consecutive outline points.
//!
//! The outline is the scheme's own when it has one ([`State::outline`]: OTM's boundary
//! nodes, Zhou's five-node fit); otherwise it is traced from the particles: the fluid is
//! split into angular sectors about its centroid, about 2 Δx wide at the largest radius,
//! and each sector's farthest particle is an outline point (a star-shaped drop's surface
//! row; sectors without a particle are skipped). The pressure at an outline point is the
//! value there of the weighted least-squares plane `p ≈ p₀ + ∇p · (x − x_o)` through the
//! fluid's pressures within the kernel support of it (exact for a hydrostatic pressure, and
//! an extrapolation from inside where the outline is the scheme's boundary).
//!
//! [`State::outline`]: crate::state::State::outline

use crate::state::Vector;
use nalgebra::{Matrix3, Vector3};

/// The comparison at one instant \[Pa\]: over the outline points that are compared,
/// `rms` and `max` of `p − γ κ`, the mean Young–Laplace pressure `laplace` = mean `γ κ`
/// and the mean pressure `p`; `count` of them (NaN values and 0 when there are none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Comparison {
    pub rms: f64,
    pub max: f64,
    pub laplace: f64,
    pub p: f64,
    pub count: usize,
}

/// Fewest sectors: a drop resolved by fewer outline points has no local curvature.
const MIN_SECTORS: usize = 12;

/// The probe's scratch: each sector's farthest particle, the outline, the particles near it.
#[derive(Debug, Default)]
pub(super) struct Scratch {
    sectors: Vec<Option<(usize, f64)>>,
    outline: Vec<[f64; 2]>,
    band: Vec<usize>,
}

/// What the comparison reads: the fluid's positions `x` and pressures `p` \[m, Pa\], the
/// scheme's own `outline` (empty: traced), the spacing `dx` and kernel `support` \[m\],
/// the surface tension `gamma` \[N/m\], and `above`, the height on y below which outline
/// points shape the circle fits but are not compared (the contact with a plate).
pub(super) struct Input<'a, const D: usize> {
    pub x: &'a [Vector<D>],
    pub p: &'a [f64],
    pub outline: &'a [Vector<D>],
    pub dx: f64,
    pub support: f64,
    pub gamma: f64,
    pub above: Option<f64>,
}

/// The comparison of the module documentation.
pub(super) fn compare<const D: usize>(input: &Input<'_, D>, scratch: &mut Scratch) -> Comparison {
    let none = Comparison { rms: f64::NAN, max: f64::NAN, laplace: f64::NAN, p: f64::NAN, count: 0 };
    let Input { x, p, support, gamma, above, .. } = *input;
    if x.is_empty() {
        return none;
    }
    let c: Vector<D> = x.iter().sum::<Vector<D>>() / x.len() as f64;
    trace(input, c, scratch);
    let n = scratch.outline.len();
    if n < 5 {
        return none;
    }
    // The particles that can lie within the support of an outline point.
    let r_in = scratch.outline.iter().map(|o| (o[0] - c[0]).hypot(o[1] - c[1])).fold(f64::INFINITY, f64::min)
        - support;
    scratch.band.clear();
    scratch.band.extend((0..x.len()).filter(|&a| (x[a][0] - c[0]).hypot(x[a][1] - c[1]) >= r_in));
    let (mut sum2, mut max, mut laplace, mut pressure, mut count) = (0.0, 0.0f64, 0.0, 0.0, 0usize);
    let outline = &scratch.outline;
    for i in 0..n {
        let o = outline[i];
        if above.is_some_and(|y| o[1] < y) {
            continue;
        }
        let Some(p_o) = plane_fit(o, x, p, &scratch.band, support) else { continue };
        let five = [
            outline[(i + n - 2) % n],
            outline[(i + n - 1) % n],
            o,
            outline[(i + 1) % n],
            outline[(i + 2) % n],
        ];
        let e = p_o - gamma * curvature(&five);
        sum2 += e * e;
        max = max.max(e.abs());
        laplace += p_o - e;
        pressure += p_o;
        count += 1;
    }
    if count == 0 {
        return none;
    }
    let k = count as f64;
    Comparison { rms: (sum2 / k).sqrt(), max, laplace: laplace / k, p: pressure / k, count }
}

/// Fills `scratch.outline`: the scheme's own, or the farthest particle of each sector about
/// the centroid `c`.
fn trace<const D: usize>(input: &Input<'_, D>, c: Vector<D>, scratch: &mut Scratch) {
    scratch.outline.clear();
    if !input.outline.is_empty() {
        scratch.outline.extend(input.outline.iter().map(|o| [o[0], o[1]]));
        return;
    }
    let x = input.x;
    let r_max = x.iter().map(|q| (q - c).norm()).fold(0.0, f64::max);
    let m = ((std::f64::consts::PI * r_max / input.dx).floor() as usize).max(MIN_SECTORS);
    scratch.sectors.clear();
    scratch.sectors.resize(m, None);
    for (a, q) in x.iter().enumerate() {
        let (dx, dy) = (q[0] - c[0], q[1] - c[1]);
        let theta = dy.atan2(dx) + std::f64::consts::PI;
        let k = ((theta / std::f64::consts::TAU * m as f64) as usize).min(m - 1);
        let r2 = dx * dx + dy * dy;
        if scratch.sectors[k].is_none_or(|(_, best)| r2 > best) {
            scratch.sectors[k] = Some((a, r2));
        }
    }
    scratch.outline.extend(scratch.sectors.iter().flatten().map(|&(a, _)| [x[a][0], x[a][1]]));
}

/// The pressure at `o` of the least-squares plane through the pressures of the particles
/// `band` within `support` of it, weighted by `(1 − r/support)²`; `None` when they do not
/// span a plane.
fn plane_fit<const D: usize>(
    o: [f64; 2],
    x: &[Vector<D>],
    p: &[f64],
    band: &[usize],
    support: f64,
) -> Option<f64> {
    let mut m = Matrix3::<f64>::zeros();
    let mut rhs = Vector3::<f64>::zeros();
    for &a in band {
        let (dx, dy) = (x[a][0] - o[0], x[a][1] - o[1]);
        let r = dx.hypot(dy);
        if r >= support {
            continue;
        }
        let w = (1.0 - r / support).powi(2);
        let row = Vector3::new(1.0, dx / support, dy / support);
        m += row * row.transpose() * w;
        rhs += row * (w * p[a]);
    }
    // A plane needs three points off a line: the determinant against the system's scale.
    let lu = m.lu();
    let s = lu.solve(&rhs)?;
    (m.determinant().abs() > 1e-12 * m.norm().powi(3)).then_some(s[0])
}

/// Signed curvature \[1/m\] at the middle of five points in counter-clockwise order: the
/// algebraic least-squares circle (Kåsa 1976: `x² + y² + a x + b y + c = 0`) through them,
/// about the middle point; positive where the outline turns left (a convex drop), zero
/// for points on a line.
fn curvature(five: &[[f64; 2]; 5]) -> f64 {
    let o = five[2];
    let mut m = Matrix3::<f64>::zeros();
    let mut rhs = Vector3::<f64>::zeros();
    for q in five {
        let (x, y) = (q[0] - o[0], q[1] - o[1]);
        let row = Vector3::new(x, y, 1.0);
        m += row * row.transpose();
        rhs -= row * (x * x + y * y);
    }
    let Some(s) = m.lu().solve(&rhs) else { return 0.0 };
    let (cx, cy) = (-0.5 * s[0], -0.5 * s[1]);
    let r2 = cx * cx + cy * cy - s[2];
    if !(r2.is_finite() && r2 > 0.0) {
        return 0.0;
    }
    let (u, v) = ([o[0] - five[0][0], o[1] - five[0][1]], [five[4][0] - o[0], five[4][1] - o[1]]);
    let turn = u[0] * v[1] - u[1] * v[0];
    turn.signum() / r2.sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::state::Vector;

    /// Rings of points filling a disc of radius `r` about `c`, ring spacing `dx`.
    fn disc(c: [f64; 2], r: f64, dx: f64) -> Vec<Vector<2>> {
        let mut x = vec![Vector::<2>::new(c[0], c[1])];
        let rings = (r / dx).round() as usize;
        for k in 1..=rings {
            let rk = k as f64 * r / rings as f64;
            let m = (std::f64::consts::TAU * rk / dx).round() as usize;
            for j in 0..m {
                let t = std::f64::consts::TAU * (j as f64 + 0.5 * (k % 2) as f64) / m as f64;
                x.push(Vector::<2>::new(c[0] + rk * t.cos(), c[1] + rk * t.sin()));
            }
        }
        x
    }

    /// A disc at rest at its Laplace pressure matches; a linear pressure is read exactly at
    /// each outline point (its error is the linear part there); points below `above` are
    /// left out; a given outline is used as it is.
    #[test]
    fn a_disc_at_its_laplace_pressure_matches_and_a_linear_field_is_read_exactly() {
        let (c, r, dx, gamma) = ([0.3, -0.2], 0.7, 0.05, 3.0);
        let x = disc(c, r, dx);
        let mut scratch = Scratch::default();
        let uniform = vec![gamma / r; x.len()];
        let linear: Vec<f64> = x.iter().map(|q| gamma / r + 2.0 * (q[1] - c[1])).collect();
        let input = |p| Input { x: &x, p, outline: &[], dx, support: 3.0 * dx, gamma, above: None };
        let s = compare(&input(&uniform), &mut scratch);
        assert!(s.count > 30, "{s:?}");
        assert!((s.laplace - gamma / r).abs() < 1e-9 * gamma / r && s.rms < 1e-9, "{s:?}");
        let l = compare(&input(&linear), &mut scratch);
        let want = (scratch.outline.iter().map(|o| (2.0 * (o[1] - c[1])).powi(2)).sum::<f64>()
            / scratch.outline.len() as f64)
            .sqrt();
        assert!((l.rms - want).abs() < 1e-9, "{l:?} against {want}");
        let top = compare(&Input { above: Some(c[1]), ..input(&uniform) }, &mut scratch);
        assert!(top.count < s.count && top.count > s.count / 3, "{top:?} {s:?}");
        // An outline 0.1 dx outside the particles, the scheme's own: a circle of radius r + 0.1 dx.
        let own: Vec<Vector<2>> = (0..60)
            .map(|j| {
                let t = std::f64::consts::TAU * j as f64 / 60.0;
                Vector::<2>::new(c[0] + (r + 0.1 * dx) * t.cos(), c[1] + (r + 0.1 * dx) * t.sin())
            })
            .collect();
        let o = compare(&Input { outline: &own, ..input(&uniform) }, &mut scratch);
        assert_eq!(o.count, 60);
        assert!((o.laplace - gamma / (r + 0.1 * dx)).abs() < 1e-9, "{o:?}");
        let empty = Input { x: &[], p: &[], outline: &[], dx, support: 3.0 * dx, gamma, above: None };
        assert!(compare::<2>(&empty, &mut scratch).rms.is_nan());
    }

    /// Five points of an ellipse give its curvature to the fit's order; a line gives zero;
    /// a clockwise arc is negative.
    #[test]
    fn the_circle_fit_follows_an_ellipse_and_signs_its_turn() {
        let (a, b) = (1.0, 0.5);
        let at = |t: f64| [a * t.cos(), b * t.sin()];
        let dt = 0.02;
        let t0 = 0.7;
        let five = [at(t0 - 2.0 * dt), at(t0 - dt), at(t0), at(t0 + dt), at(t0 + 2.0 * dt)];
        let exact = a * b / (a * a * t0.sin().powi(2) + b * b * t0.cos().powi(2)).powf(1.5);
        assert!((curvature(&five) - exact).abs() < 1e-2 * exact, "{} {exact}", curvature(&five));
        let line = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [3.0, 3.0], [4.0, 4.0]];
        assert!(curvature(&line).abs() < 1e-9);
        let mut reversed = five;
        reversed.reverse();
        assert!((curvature(&reversed) + curvature(&five)).abs() < 1e-9);
    }
}
