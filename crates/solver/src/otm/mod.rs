//! The optimal-transportation meshfree method (OTM; Li, Habbal & Ortiz 2010; Zhou et al.
//! 2021, seed 003; OTM.md): nodes carrying position and velocity, material points carrying
//! mass, volume and stress, coupled by local max-entropy shape functions ([`lme`]); the
//! bodies triangulated once at set-up ([`mesh`]); surface tension as the energy of the
//! boundary nodes' polyline ([`surface`]); the step of a plane or axisymmetric body, with
//! no-slip nodes and a periodic axis ([`step`]), its nodal forces optionally integrated
//! consistently ([`integration`]).
//!
//! As a scheme of the scene file ([`scheme`]): one body, a circle or a rectangle in 2D, a
//! sphere solved axisymmetric in 3D; walls and a periodic axis on a rectangle's edges
//! (issue #38 in progress; docs/notes/otm.md).

pub mod integration;
pub mod lme;
pub mod mesh;
pub mod scheme;
pub mod step;
pub mod surface;

#[cfg(test)]
mod tests {
    use super::lme::{LmeParams, shape_functions};
    use super::mesh::{Point, disc};

    /// Every material point of a disc, the boundary triangles' included, has shape
    /// functions over the nodes within the support (tol 1e-6), reproducing its position,
    /// in a few Newton steps from λ = 0.
    #[test]
    fn every_material_point_of_a_disc_has_shape_functions() {
        let h = 0.02;
        let mesh = disc(Point::zeros(), 0.2, h).unwrap();
        for gamma in [0.8, 1.5, 4.0] {
            let params = LmeParams { gamma, ..LmeParams::default() };
            let support = params.cutoff(h, 1e-6);
            let mut worst = 0;
            for (x, _) in mesh.material_points() {
                let near: Vec<Point> =
                    mesh.nodes.iter().copied().filter(|n| (n - x).norm() < support).collect();
                let (mut p, mut g, mut l) =
                    (vec![0.0; near.len()], vec![Point::zeros(); near.len()], Point::zeros());
                let info = shape_functions(&x, &near, h, &params, &mut l, &mut p, &mut g).unwrap();
                let reproduced: Point = p.iter().zip(&near).map(|(pa, xa)| xa * *pa).sum();
                assert!((reproduced - x).norm() < 1e-12);
                worst = worst.max(info.iterations);
            }
            assert!(worst <= 8, "γ = {gamma}: {worst} Newton iterations");
        }
    }
}
