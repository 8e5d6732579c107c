//! MPS weight functions (Lan 2022 eq. 3; Koshizuka & Oka 1996) and the lattice constants
//! n0 and λ every operator is normalised by (MPS.md, "Operators").

use crate::fields::Vector;

/// A weight function `w(r)` of the MPS operators, zero at and beyond its radius `re`.
pub trait Weight: Copy + Send + Sync + std::fmt::Debug + 'static {
    /// `w(r)` for a radius `re` (both in the same unit).
    fn w(r: f64, re: f64) -> f64;
}

/// Lan 2022 eq. 3 (from Zhang's 2014 thesis): `w = re/(0.85 r + 0.15 re) − 1` for
/// `r < re`; finite at r = 0 (5.67).
#[derive(Debug, Clone, Copy)]
pub struct Lan;

impl Weight for Lan {
    #[inline(always)]
    fn w(r: f64, re: f64) -> f64 {
        if r < re { re / (0.85 * r + 0.15 * re) - 1.0 } else { 0.0 }
    }
}

/// Koshizuka & Oka 1996: `w = re/r − 1` for `r < re` (unbounded as r → 0: close pairs
/// repel through the number density).
#[derive(Debug, Clone, Copy)]
pub struct Classic;

impl Weight for Classic {
    #[inline(always)]
    fn w(r: f64, re: f64) -> f64 {
        if r < re { re / r - 1.0 } else { 0.0 }
    }
}

/// The constants of one operator radius, summed over the neighbours of an interior
/// particle of the initial square (cubic) lattice of spacing l0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatticeSums {
    /// n0 = Σ_j w(|r_ij|) (dimensionless).
    pub n0: f64,
    /// λ = Σ_j w |r_ij|² / Σ_j w \[m²\] (Lan eq. 8).
    pub lambda: f64,
    /// n/n0 of a particle on a flat free surface (the half lattice, the plane included).
    pub surface_ratio: f64,
    /// |F|0: the length of `F = (d/n0) Σ (r_i − r_j) w/|r_ij|` at a flat free surface \[m\]
    /// (the auxiliary free-surface criterion's reference).
    pub surface_f: f64,
}

impl LatticeSums {
    /// The sums for weight `W` and radius `re` \[m\] on the lattice of spacing `l0` \[m\]
    /// in `D` dimensions.
    pub fn of<W: Weight, const D: usize>(re: f64, l0: f64) -> Self {
        let (mut n0, mut r2w, mut half) = (0.0, 0.0, 0.0);
        let mut f = Vector::<D>::zeros();
        for_each_offset::<D>(re, l0, |r_ij| {
            let r = r_ij.norm();
            let w = W::w(r, re);
            n0 += w;
            r2w += w * r * r;
            if r_ij[D - 1] <= 0.0 {
                half += w;
                f -= r_ij * (w / r);
            }
        });
        LatticeSums { n0, lambda: r2w / n0, surface_ratio: half / n0, surface_f: f.norm() * D as f64 / n0 }
    }
}

/// Calls `f(r_ij)` for every point of the square (cubic) lattice of spacing `l0` within
/// `reach` \[m\] of the origin, the origin excluded.
pub fn for_each_offset<const D: usize>(reach: f64, l0: f64, mut f: impl FnMut(Vector<D>)) {
    let k = (reach / l0).ceil() as i64;
    let mut idx = [-k; D];
    loop {
        let r_ij = Vector::<D>::from_fn(|i, _| idx[i] as f64 * l0);
        let r = r_ij.norm();
        if r > 0.0 && r < reach {
            f(r_ij);
        }
        // Next offset (an odometer over [-k, k]^D).
        let Some(i) = idx.iter().position(|&v| v < k) else { return };
        idx[i] += 1;
        idx[..i].iter_mut().for_each(|v| *v = -k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// MPS.md's table of lattice constants, to 1e-4 (its values are rounded to 4 decimals;
    /// the flat-surface ratios to 3).
    #[test]
    fn lattice_constants_match_the_table() {
        let l0 = 1.0;
        let cases: [(&str, usize, f64, f64, f64, f64); 6] = [
            ("lan 2D", 2, 2.1, 4.9160, 1.4156, 0.672),
            ("lan 2D", 2, 4.1, 25.8852, 4.2265, 0.612),
            ("lan 3D", 3, 2.1, 11.0793, 1.7374, 0.722),
            ("lan 3D", 3, 4.1, 97.3470, 5.7781, 0.633),
            ("classic 2D", 2, 2.1, 6.5397, 1.3884, 0.676),
            ("classic 2D", 2, 3.1, 18.9764, 2.4485, 0.641),
        ];
        for (name, d, re, n0, lambda, ratio) in cases {
            let s = match (name.starts_with("lan"), d) {
                (true, 2) => LatticeSums::of::<Lan, 2>(re, l0),
                (true, _) => LatticeSums::of::<Lan, 3>(re, l0),
                (false, _) => LatticeSums::of::<Classic, 2>(re, l0),
            };
            assert!((s.n0 - n0).abs() <= 1e-4, "{name} re {re}: n0 {} against {n0}", s.n0);
            assert!((s.lambda - lambda).abs() <= 1e-4, "{name} re {re}: λ {} against {lambda}", s.lambda);
            assert!(
                (s.surface_ratio - ratio).abs() <= 1e-3,
                "{name} re {re}: {} against {ratio}",
                s.surface_ratio
            );
        }
    }

    /// n0 scales with nothing and λ with l0²: the sums on a lattice of spacing 0.004 m are
    /// those of the unit lattice, λ times l0².
    #[test]
    fn lattice_sums_scale_with_the_spacing() {
        let (a, b) = (LatticeSums::of::<Lan, 2>(4.1, 1.0), LatticeSums::of::<Lan, 2>(4.1 * 0.004, 0.004));
        assert!((a.n0 - b.n0).abs() < 1e-9 * a.n0);
        assert!((a.lambda * 0.004 * 0.004 - b.lambda).abs() < 1e-9 * b.lambda);
    }

    /// Lan's weight is finite at r = 0 (re/(0.15 re) − 1 = 5.67) and both vanish at re.
    #[test]
    fn weights_at_the_ends() {
        assert!((Lan::w(0.0, 2.1) - (1.0 / 0.15 - 1.0)).abs() < 1e-12);
        assert_eq!(Lan::w(2.1, 2.1).to_bits(), 0);
        assert_eq!(Classic::w(2.1, 2.1).to_bits(), 0);
        assert!((Classic::w(1.0, 2.1) - 1.1).abs() < 1e-12);
    }
}
