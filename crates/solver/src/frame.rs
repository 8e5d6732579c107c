//! Particle frames: the fluid in initial-id order, for VTK output, the last good state of
//! a diverged run, final-state metrics and the snapshots of `output.snapshot_times`. A
//! frame shows every declared field with an output name ([`crate::fields`]): position,
//! velocity, pressure and free-surface flags in their own members, a scheme's others
//! (`div_r`, WCSPH's `density`, ...) in [`Frame::scalars`] and [`Frame::vectors`].

use crate::fields::{ColumnRef, Field};
use crate::state::Vector;
use serde::{Deserialize, Serialize};

/// A particle snapshot in initial-id order (particles that entered through an inlet follow
/// in order of entry).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Frame {
    /// Step number.
    pub step: usize,
    /// Time \[s\].
    pub time: f64,
    /// Positions \[m\] (3 components; z = 0 in 2D).
    pub x: Vec<[f64; 3]>,
    /// Velocities \[m/s\].
    pub u: Vec<[f64; 3]>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
    /// Free-surface flags.
    pub free_surface: Vec<bool>,
    /// Further declared scalar fields (flags as 0 / 1), by output name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scalars: Vec<(String, Vec<f64>)>,
    /// Further declared vector fields (3 components), by output name.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub vectors: Vec<(String, Vec<[f64; 3]>)>,
}

impl Frame {
    /// The frame of the `fluid` leading particles of the declared fields that `visit`
    /// calls its argument with (see [`crate::scheme::Method::visit_fields`]).
    pub fn of<const D: usize>(
        step: usize,
        time: f64,
        fluid: usize,
        visit: impl FnOnce(&mut dyn FnMut(Field<ColumnRef<'_, D>>)),
    ) -> Frame {
        let mut f = Frame { step, time, ..Frame::default() };
        let mut ids: Vec<u32> = Vec::new();
        let mut scalars: Vec<(&'static str, Vec<f64>)> = Vec::new();
        let mut vectors: Vec<(&'static str, Vec<[f64; 3]>)> = Vec::new();
        visit(&mut |field| {
            let lead = |len: usize| len.min(fluid);
            match (field.column, field.output) {
                (ColumnRef::Ids(v), _) if ids.is_empty() => ids = v[..lead(v.len())].to_vec(),
                (_, None) | (ColumnRef::Ids(_), _) => {}
                (ColumnRef::Vectors(v), Some(name)) => {
                    let v: Vec<[f64; 3]> = v[..lead(v.len())].iter().map(three).collect();
                    match name {
                        "position" => f.x = v,
                        "velocity" => f.u = v,
                        _ => vectors.push((name, v)),
                    }
                }
                (ColumnRef::Scalars(v), Some(name)) => {
                    let v = v[..lead(v.len())].to_vec();
                    match name {
                        "pressure" => f.p = v,
                        _ => scalars.push((name, v)),
                    }
                }
                (ColumnRef::Flags(v), Some(name)) => {
                    let v = &v[..lead(v.len())];
                    match name {
                        "free_surface" => f.free_surface = v.to_vec(),
                        _ => scalars.push((name, v.iter().map(|&b| f64::from(u8::from(b))).collect())),
                    }
                }
            }
        });
        // Initial-id order; a field shorter than the fluid reads as zero (false) past its end.
        let mut order: Vec<usize> = (0..fluid).collect();
        order.sort_unstable_by_key(|&a| ids.get(a).copied().unwrap_or(u32::MAX));
        fn arrange<T: Copy + Default>(v: &[T], order: &[usize]) -> Vec<T> {
            order.iter().map(|&a| v.get(a).copied().unwrap_or_default()).collect()
        }
        f.x = arrange(&f.x, &order);
        f.u = arrange(&f.u, &order);
        f.p = arrange(&f.p, &order);
        f.free_surface = arrange(&f.free_surface, &order);
        f.scalars = scalars.into_iter().map(|(n, v)| (n.to_string(), arrange(&v, &order))).collect();
        f.vectors = vectors.into_iter().map(|(n, v)| (n.to_string(), arrange(&v, &order))).collect();
        f
    }
}

/// A vector's first three components (zero-padded).
fn three<const D: usize>(v: &Vector<D>) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(v.iter()) {
        *o = *x;
    }
    out
}
