//! The set-up triangulation of an OTM body (OTM.md "Two point sets"): nodes at the
//! triangles' vertices, one material point per triangle at its centroid; the connectivity
//! is used once, for the material points and the boundary polyline, then dropped.
//!
//! Only the bodies of Zhou's cases are needed (a disc, a rectangle, and the half-disc that
//! is a ball's (r, z) section), all with a structured triangulation, which a general
//! mesher would not improve on: a disc of concentric rings of 6k nodes (equal spacing
//! 2πR/(6K) on every ring, joined ring to ring by advancing along both in angle), a
//! half-disc of half-rings of 3k + 1 nodes joined the same way, a rectangle of a grid with
//! alternating diagonals.
//! Written here rather than taken from a Delaunay crate for that reason (the rings fix the
//! nodes, and their connection is the zipper below).

use nalgebra::SVector;
use std::f64::consts::PI;

/// A point of the plane \[m\].
pub type Point = SVector<f64, 2>;

/// A triangulated body.
#[derive(Debug, Clone, PartialEq)]
pub struct Mesh {
    /// Node positions \[m\].
    pub nodes: Vec<Point>,
    /// Triangles (node indices, counter-clockwise).
    pub triangles: Vec<[usize; 3]>,
    /// The boundary nodes as a closed polyline, counter-clockwise.
    pub boundary: Vec<usize>,
    /// The nodes on the symmetry axis x = centre of a [`half_disc`] (ascending), empty for
    /// plane bodies.
    pub axis: Vec<usize>,
}

/// A body the mesher cannot triangulate: names the field, the value and the rule.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("mesh field `{field}` = {value}: {rule}")]
pub struct MeshError {
    /// The offending field.
    pub field: &'static str,
    /// Its value.
    pub value: f64,
    /// The rule it breaks.
    pub rule: &'static str,
}

impl Mesh {
    /// Centroid \[m\] and area \[m²\] of each triangle: the material points' positions and
    /// initial volumes per unit depth.
    pub fn material_points(&self) -> Vec<(Point, f64)> {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.nodes[i]);
                ((a + b + c) / 3.0, signed_area(a, b, c))
            })
            .collect()
    }

    /// Three points per triangle at the barycentric points (2/3, 1/6, 1/6) of the
    /// degree-two rule (Strang & Fix), each with a third of the area \[m, m²\]: the
    /// material points of an axisymmetric body, whose integrands carry the factor r.
    pub fn material_points_degree_two(&self) -> Vec<(Point, f64)> {
        self.triangles
            .iter()
            .flat_map(|t| {
                let [a, b, c] = t.map(|i| self.nodes[i]);
                let third = signed_area(a, b, c) / 3.0;
                let at = |p: Point, q: Point, r: Point| (p * (2.0 / 3.0) + (q + r) / 6.0, third);
                [at(a, b, c), at(b, c, a), at(c, a, b)]
            })
            .collect()
    }
}

/// The signed area of triangle `a b c` (positive when counter-clockwise) \[m²\].
fn signed_area(a: Point, b: Point, c: Point) -> f64 {
    0.5 * ((b - a).x * (c - a).y - (b - a).y * (c - a).x)
}

fn positive(field: &'static str, value: f64) -> Result<(), MeshError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(MeshError { field, value, rule: "must be a positive finite length" })
    }
}

/// K = round(R/h), the rings of a disc or half-disc of `radius` at spacing `h` \[m\] (at
/// least one).
fn rings(radius: f64, h: f64) -> Result<usize, MeshError> {
    positive("radius", radius)?;
    positive("spacing", h)?;
    match (radius / h).round() as usize {
        0 => {
            Err(MeshError { field: "spacing", value: h, rule: "must be at most twice the radius (one ring)" })
        }
        k => Ok(k),
    }
}

/// A disc of `radius` about `centre` with node spacing about `h` \[m\]: K = round(R/h)
/// rings (at least one), ring k of radius kR/K with 6k nodes, the centre a node.
pub fn disc(centre: Point, radius: f64, h: f64) -> Result<Mesh, MeshError> {
    let rings = rings(radius, h)?;
    let mut nodes = vec![centre];
    // first[k]: index of ring k's first node (ring 0 is the centre).
    let mut first = vec![0];
    for k in 1..=rings {
        first.push(nodes.len());
        let r = radius * k as f64 / rings as f64;
        for i in 0..6 * k {
            let t = 2.0 * PI * i as f64 / (6 * k) as f64;
            nodes.push(centre + Point::new(r * t.cos(), r * t.sin()));
        }
    }
    let mut triangles = Vec::with_capacity(6 * rings * rings);
    // The centre's fan.
    for i in 0..6 {
        triangles.push([0, first[1] + i, first[1] + (i + 1) % 6]);
    }
    for k in 1..rings {
        zip(&mut triangles, (first[k], 6 * k), (first[k + 1], 6 * (k + 1)), true);
    }
    let boundary = (first[rings]..nodes.len()).collect();
    Ok(Mesh { nodes, triangles, boundary, axis: Vec::new() })
}

/// Joins two rings of a disc (or two arcs of a half-disc) by triangles: `inner` and
/// `outer` are (first node, number of segments); advancing along whichever ring's next
/// node comes first in angle. A closed ring's last segment returns to its first node; an
/// open arc has one node more than segments.
fn zip(triangles: &mut Vec<[usize; 3]>, inner: (usize, usize), outer: (usize, usize), closed: bool) {
    let ((f_in, n_in), (f_out, n_out)) = (inner, outer);
    let node = |first: usize, n: usize, i: usize| first + if closed { i % n } else { i };
    let (mut i, mut j) = (0, 0);
    while i < n_in || j < n_out {
        let next_in = (i + 1) as f64 / n_in as f64;
        let next_out = (j + 1) as f64 / n_out as f64;
        if j < n_out && (i == n_in || next_out <= next_in) {
            triangles.push([node(f_in, n_in, i), node(f_out, n_out, j), node(f_out, n_out, j + 1)]);
            j += 1;
        } else {
            triangles.push([node(f_in, n_in, i), node(f_out, n_out, j), node(f_in, n_in, i + 1)]);
            i += 1;
        }
    }
}

/// The right half (x ≥ `centre.x`) of a disc of `radius` with node spacing about `h` \[m\]:
/// the (r, z) section of a ball about the axis x = `centre.x` (axisymmetric bodies, Zhou
/// 2021 §2.3.3). K = round(R/h) half-rings, half-ring k of radius kR/K with 3k + 1 nodes
/// from the bottom pole to the top pole (the same spacing πR/(3K) as [`disc`]'s rings),
/// its end nodes exactly on the axis. The boundary polygon starts with the free arc, from
/// the bottom pole up to the top pole; the rest of it lies on the axis.
pub fn half_disc(centre: Point, radius: f64, h: f64) -> Result<Mesh, MeshError> {
    let rings = rings(radius, h)?;
    let mut nodes = vec![centre];
    let mut first = vec![0];
    for k in 1..=rings {
        first.push(nodes.len());
        let r = radius * k as f64 / rings as f64;
        for i in 0..=3 * k {
            let t = PI * (i as f64 / (3 * k) as f64 - 0.5);
            let x = if i == 0 || i == 3 * k { 0.0 } else { r * t.cos() };
            nodes.push(centre + Point::new(x, r * t.sin()));
        }
    }
    let mut triangles = Vec::with_capacity(3 * rings * rings);
    for i in 0..3 {
        triangles.push([0, first[1] + i, first[1] + i + 1]);
    }
    for k in 1..rings {
        zip(&mut triangles, (first[k], 3 * k), (first[k + 1], 3 * (k + 1)), false);
    }
    let top = |k: usize| first[k] + 3 * k;
    let mut boundary: Vec<usize> = (first[rings]..=top(rings)).collect();
    boundary.extend((1..rings).rev().map(top));
    boundary.push(0);
    boundary.extend((1..rings).map(|k| first[k]));
    let mut axis: Vec<usize> = (1..=rings).flat_map(|k| [first[k], top(k)]).collect();
    axis.push(0);
    axis.sort_unstable();
    Ok(Mesh { nodes, triangles, boundary, axis })
}

/// The rectangle `lo`–`hi` with node spacing about `h` \[m\] in each direction (at least
/// one cell per side), each cell cut by a diagonal that alternates from cell to cell.
pub fn rectangle(lo: Point, hi: Point, h: f64) -> Result<Mesh, MeshError> {
    positive("width", hi.x - lo.x)?;
    positive("height", hi.y - lo.y)?;
    positive("spacing", h)?;
    let nx = (((hi.x - lo.x) / h).round() as usize).max(1);
    let ny = (((hi.y - lo.y) / h).round() as usize).max(1);
    let id = |i: usize, j: usize| j * (nx + 1) + i;
    let mut nodes = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let s = Point::new(i as f64 / nx as f64, j as f64 / ny as f64);
            nodes.push(lo + (hi - lo).component_mul(&s));
        }
    }
    let mut triangles = Vec::with_capacity(2 * nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            let [a, b, c, d] = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if (i + j) % 2 == 0 {
                triangles.extend([[a, b, c], [a, c, d]]);
            } else {
                triangles.extend([[a, b, d], [b, c, d]]);
            }
        }
    }
    let mut boundary: Vec<usize> = (0..nx).map(|i| id(i, 0)).collect();
    boundary.extend((0..ny).map(|j| id(nx, j)));
    boundary.extend((1..=nx).rev().map(|i| id(i, ny)));
    boundary.extend((1..=ny).rev().map(|j| id(0, j)));
    Ok(Mesh { nodes, triangles, boundary, axis: Vec::new() })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    /// A valid triangulation of a disc-like region: counter-clockwise triangles covering
    /// the boundary polygon's area, V − E + F = 1, every boundary edge in one triangle and
    /// every inner edge in two.
    fn valid(m: &Mesh) {
        let points = m.material_points();
        assert!(points.iter().all(|(_, a)| *a > 0.0), "counter-clockwise");
        let polygon: f64 = (0..m.boundary.len())
            .map(|i| {
                let (a, b) = (m.nodes[m.boundary[i]], m.nodes[m.boundary[(i + 1) % m.boundary.len()]]);
                0.5 * (a.x * b.y - b.x * a.y)
            })
            .sum();
        let area: f64 = points.iter().map(|(_, a)| a).sum();
        assert!((area / polygon - 1.0).abs() < 1e-12, "{area} against {polygon}");
        let mut edges: BTreeMap<(usize, usize), usize> = BTreeMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        let euler = m.nodes.len() as i64 - edges.len() as i64 + m.triangles.len() as i64;
        assert_eq!(euler, 1);
        let n = m.boundary.len();
        for i in 0..n {
            let (a, b) = (m.boundary[i], m.boundary[(i + 1) % n]);
            assert_eq!(edges.remove(&(a.min(b), a.max(b))), Some(1), "boundary edge {a}–{b}");
        }
        assert!(edges.values().all(|&c| c == 2), "inner edges in two triangles");
    }

    #[test]
    fn discs_are_ringed_triangulations() {
        for (radius, h) in [(0.2, 0.02), (1.0, 0.3), (0.2, 0.39)] {
            let m = disc(Point::new(0.1, -0.3), radius, h).unwrap();
            let k = (radius / h).round() as usize;
            assert_eq!(m.triangles.len(), 6 * k * k);
            assert_eq!(m.nodes.len(), 1 + 3 * k * (k + 1));
            assert_eq!(m.boundary.len(), 6 * k);
            valid(&m);
            for &b in &m.boundary {
                assert!(((m.nodes[b] - Point::new(0.1, -0.3)).norm() - radius).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn half_discs_are_ringed_triangulations_with_their_poles_on_the_axis() {
        for (radius, h) in [(0.2, 0.02), (1.0, 0.3), (0.2, 0.39)] {
            let c = Point::new(0.0, 0.3);
            let m = half_disc(c, radius, h).unwrap();
            let k = (radius / h).round() as usize;
            assert_eq!(m.triangles.len(), 3 * k * k);
            assert_eq!(m.boundary.len(), 3 * k + 1 + 2 * k - 1);
            valid(&m);
            // The free arc: on the circle, from the bottom pole to the top pole.
            for &b in &m.boundary[..=3 * k] {
                assert!(((m.nodes[b] - c).norm() - radius).abs() < 1e-12);
            }
            assert_eq!(m.nodes[m.boundary[0]], c - Point::new(0.0, radius));
            assert_eq!(m.nodes[m.boundary[3 * k]], c + Point::new(0.0, radius));
            assert_eq!(m.axis.len(), 2 * k + 1);
            assert!(m.axis.iter().all(|&a| m.nodes[a].x == 0.0));
            assert!(m.boundary[3 * k..].iter().all(|b| m.axis.contains(b)));
        }
    }

    /// The degree-two rule: three points per triangle, inside it, a third of its area each,
    /// their mean its centroid (so the total area and the first moments are the centroid
    /// rule's).
    #[test]
    fn the_degree_two_points_split_each_triangle_in_three() {
        let m = disc(Point::new(0.1, -0.3), 0.2, 0.05).unwrap();
        let one = m.material_points();
        let three = m.material_points_degree_two();
        assert_eq!(three.len(), 3 * one.len());
        for (t, (c, area)) in one.iter().enumerate() {
            let part = &three[3 * t..3 * t + 3];
            let mean = part.iter().map(|(x, _)| x).sum::<Point>() / 3.0;
            assert!((mean - c).norm() < 1e-15);
            assert!(part.iter().all(|(_, a)| (a * 3.0 - area).abs() < 1e-15));
        }
    }

    #[test]
    fn rectangles_are_grids() {
        let m = rectangle(Point::new(0.0, 0.0), Point::new(1.0, 0.5), 0.1).unwrap();
        assert_eq!((m.nodes.len(), m.triangles.len(), m.boundary.len()), (66, 100, 30));
        valid(&m);
        let one = rectangle(Point::new(0.0, 0.0), Point::new(0.01, 0.01), 1.0).unwrap();
        assert_eq!(one.triangles.len(), 2);
        valid(&one);
    }

    #[test]
    fn bodies_it_cannot_triangulate_are_errors_naming_the_field() {
        let e = disc(Point::zeros(), 0.2, 0.5).unwrap_err();
        assert_eq!(e.to_string(), "mesh field `spacing` = 0.5: must be at most twice the radius (one ring)");
        assert_eq!(disc(Point::zeros(), -1.0, 0.1).unwrap_err().field, "radius");
        assert_eq!(disc(Point::zeros(), 1.0, f64::NAN).unwrap_err().field, "spacing");
        assert_eq!(rectangle(Point::zeros(), Point::new(-1.0, 1.0), 0.1).unwrap_err().field, "width");
        assert_eq!(rectangle(Point::zeros(), Point::new(1.0, 1.0), 0.0).unwrap_err().field, "spacing");
    }
}
