//! The per-step boundary map: for every particle, whether its pressure and its velocity are
//! unknowns of an implicit system (the fluid's), copies of another particle's (a wall
//! mirror shares its source's, an inlet buffer particle the pressure of the fluid particle
//! that entered last through its row) or known values (dummy wall particles, the outlet
//! buffer, an inlet row with no source yet). The PPE assembly and solve, the implicit
//! viscous solve and the mirror walls read it instead of deciding each for itself.

/// How a particle's value enters the fluid's implicit systems.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Link {
    /// A fluid particle: its value is an unknown (for the PPE, unless it is on the free
    /// surface).
    Unknown,
    /// The value is `sign` times particle `source`'s (whose own link says what that is:
    /// the source of a mirror may be a buffer particle).
    Shares {
        /// The particle whose value it takes.
        source: u32,
        /// Velocity factor (−1 after one no-slip reflection; 1 for pressures).
        sign: f64,
    },
    /// A known value: a right-hand-side term of the systems.
    Known,
}

/// The links of the boundary particles (those after the fluid) for the pressure and the
/// velocity, rebuilt every step ([`BoundaryMap::rebuild`]). Until it is first rebuilt (a
/// scene with no boundary particles never does) every particle is [`Link::Unknown`].
#[derive(Debug, Clone, PartialEq)]
pub struct BoundaryMap {
    /// Index of the first boundary particle (the fluid count).
    start: usize,
    /// Pressure link of each boundary particle.
    pressure: Vec<Link>,
    /// Velocity link of each boundary particle.
    velocity: Vec<Link>,
}

impl Default for BoundaryMap {
    fn default() -> Self {
        Self { start: usize::MAX, pressure: Vec::new(), velocity: Vec::new() }
    }
}

impl BoundaryMap {
    /// Rebuilds the links of the `total − fluid` boundary particles: the inlet buffer first
    /// (`inlet_sources`: each one's pressure source, `u32::MAX` for none; velocities known),
    /// then the rest of the open-boundary buffers (known) up to `walls_start`, then the
    /// wall particles: the mirrors (pressure and velocity of particle `mirror_source[k]`,
    /// the velocity times `mirror_sign[k]`) followed by dummy wall particles (known).
    pub fn rebuild(
        &mut self,
        (fluid, total, walls_start): (usize, usize, usize),
        inlet_sources: &[u32],
        mirror_source: &[u32],
        mirror_sign: &[f64],
    ) {
        self.start = fluid;
        self.pressure.clear();
        self.velocity.clear();
        for b in fluid..total {
            let (p, u) = if b < walls_start {
                match inlet_sources.get(b - fluid) {
                    Some(&src) if src != u32::MAX => (Link::Shares { source: src, sign: 1.0 }, Link::Known),
                    _ => (Link::Known, Link::Known),
                }
            } else {
                match (mirror_source.get(b - walls_start), mirror_sign.get(b - walls_start)) {
                    (Some(&source), Some(&sign)) => {
                        (Link::Shares { source, sign: 1.0 }, Link::Shares { source, sign })
                    }
                    _ => (Link::Known, Link::Known),
                }
            };
            self.pressure.push(p);
            self.velocity.push(u);
        }
    }

    /// The pressure link of particle `b`.
    #[inline]
    pub fn pressure(&self, b: usize) -> Link {
        if b < self.start { Link::Unknown } else { self.pressure[b - self.start] }
    }

    /// The velocity link of particle `b`.
    #[inline]
    pub fn velocity(&self, b: usize) -> Link {
        if b < self.start { Link::Unknown } else { self.velocity[b - self.start] }
    }

    /// Whether some boundary particle's pressure is a known value (then the PPE has
    /// right-hand-side terms from it, and a Dirichlet-like anchor).
    pub fn has_known_pressure(&self) -> bool {
        self.pressure.contains(&Link::Known)
    }

    /// The particle that holds particle `b`'s pressure: `b` itself unless its pressure is
    /// a copy, else the end of the chain of copies (a mirror's source may be a buffer
    /// particle sharing a fluid particle's).
    pub fn pressure_holder(&self, b: usize) -> usize {
        let mut b = b;
        while let Link::Shares { source, .. } = self.pressure(b) {
            b = source as usize;
        }
        b
    }

    /// The boundary particles (index, link) whose pressure is a copy.
    pub fn pressure_copies(&self) -> impl Iterator<Item = (usize, u32)> + '_ {
        self.pressure.iter().enumerate().filter_map(move |(k, l)| match *l {
            Link::Shares { source, .. } => Some((self.start + k, source)),
            _ => None,
        })
    }

    /// The boundary particles (index, source, sign) whose velocity is a signed copy.
    pub fn velocity_copies(&self) -> impl Iterator<Item = (usize, u32, f64)> + '_ {
        self.velocity.iter().enumerate().filter_map(move |(k, l)| match *l {
            Link::Shares { source, sign } => Some((self.start + k, source, sign)),
            _ => None,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two fluid particles, a linked and an unlinked inlet buffer particle, an outlet
    /// buffer particle, three mirrors (of a fluid particle, of the linked buffer and of the
    /// outlet buffer) and a dummy particle.
    #[test]
    fn links_of_every_kind_of_boundary_particle() {
        let mut map = BoundaryMap::default();
        map.rebuild((2, 9, 5), &[1, u32::MAX], &[0, 2, 4], &[-1.0, -1.0, 1.0]);
        let shares = |source, sign| Link::Shares { source, sign };
        let p: Vec<Link> = (0..9).map(|b| map.pressure(b)).collect();
        let u: Vec<Link> = (0..9).map(|b| map.velocity(b)).collect();
        use Link::{Known, Unknown};
        assert_eq!(
            p,
            [
                Unknown,
                Unknown,
                shares(1, 1.0),
                Known,
                Known,
                shares(0, 1.0),
                shares(2, 1.0),
                shares(4, 1.0),
                Known
            ]
        );
        assert_eq!(
            u,
            [Unknown, Unknown, Known, Known, Known, shares(0, -1.0), shares(2, -1.0), shares(4, 1.0), Known]
        );
        assert!(map.has_known_pressure());
        assert_eq!(map.pressure_copies().collect::<Vec<_>>(), [(2, 1), (5, 0), (6, 2), (7, 4)]);
    }
}
