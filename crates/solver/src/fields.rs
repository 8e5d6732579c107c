//! Per-particle fields declared once ([`particle_fields!`](crate::particle_fields)): every operation that must
//! touch every per-particle array — the cell reorder's permutation, the open boundaries'
//! compaction, the profiler's snapshot and restore, the last-good copy and the frames
//! written as VTK — visits the arrays a declaration lists, so a field added to a
//! declaration is permuted, saved and (if marked) written without another edit.
//!
//! A declaration lists each array with its element kind ([`Ids`] `u32`, [`Scalars`] `f64`,
//! [`Vectors`] `Vector<D>`, [`Flags`] `bool`) and, for the fields a frame shows, the name
//! it is written under (`=> "density"`).
//!
//! [`Ids`]: ColumnRef::Ids
//! [`Scalars`]: ColumnRef::Scalars
//! [`Vectors`]: ColumnRef::Vectors
//! [`Flags`]: ColumnRef::Flags

use nalgebra::{SMatrix, SVector};

/// Vector type of the solver (positions, velocities, …) \[SI units of the field\].
pub type Vector<const D: usize> = SVector<f64, D>;

/// A D × D matrix (kernel-gradient corrections, velocity gradients, …).
pub type Matrix<const D: usize> = SMatrix<f64, D, D>;

/// One per-particle array, read-only.
#[derive(Debug, Clone, Copy)]
pub enum ColumnRef<'a, const D: usize> {
    /// Particle ids.
    Ids(&'a [u32]),
    /// Scalars.
    Scalars(&'a [f64]),
    /// Vectors.
    Vectors(&'a [Vector<D>]),
    /// Flags.
    Flags(&'a [bool]),
}

/// One per-particle array, writable.
#[derive(Debug)]
pub enum ColumnMut<'a, const D: usize> {
    /// Particle ids.
    Ids(&'a mut Vec<u32>),
    /// Scalars.
    Scalars(&'a mut Vec<f64>),
    /// Vectors.
    Vectors(&'a mut Vec<Vector<D>>),
    /// Flags.
    Flags(&'a mut Vec<bool>),
}

/// A declared field: its name in the source, the name a frame shows it under (`None`: not
/// shown) and its array.
#[derive(Debug)]
pub struct Field<C> {
    /// The field's name in its declaration.
    pub name: &'static str,
    /// The name frames and VTK files give it, when they show it.
    pub output: Option<&'static str>,
    /// The array.
    pub column: C,
}

/// A set of per-particle arrays, visited in declaration order (written by
/// [`particle_fields!`](crate::particle_fields); a hand-written implementation must visit every array).
pub trait Fields<const D: usize> {
    /// Calls `f` with every array.
    fn visit(&self, f: &mut dyn FnMut(Field<ColumnRef<'_, D>>));
    /// Calls `f` with every array, writable.
    fn visit_mut(&mut self, f: &mut dyn FnMut(Field<ColumnMut<'_, D>>));
}

/// No per-particle arrays (a scheme whose own data is all rebuilt every step).
impl<const D: usize> Fields<D> for () {
    fn visit(&self, _: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {}
    fn visit_mut(&mut self, _: &mut dyn FnMut(Field<ColumnMut<'_, D>>)) {}
}

/// Declares a struct of per-particle arrays and implements [`Fields`] for it. Plain
/// members (not per particle) may come first, in braces before `per_particle { … }`.
///
/// ```
/// meniscus::particle_fields! {
///     /// Data of a scheme.
///     pub struct Mine<const D: usize> {
///         /// Density [kg/m³], written to frames as `density`.
///         pub rho: Scalars => "density",
///         /// Acceleration [m/s²].
///         pub accel: Vectors,
///     }
/// }
/// let m = Mine::<2>::default();
/// assert!(m.rho.is_empty() && m.accel.is_empty());
/// ```
#[macro_export]
macro_rules! particle_fields {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident<const D: usize> {
            $(
                $(#[$fmeta:meta])*
                $fvis:vis $field:ident : $kind:ident $(=> $out:literal)?
            ),* $(,)?
        }
    ) => {
        $crate::particle_fields! {
            $(#[$meta])*
            $vis struct $name<const D: usize> {} per_particle {
                $( $(#[$fmeta])* $fvis $field : $kind $(=> $out)? ),*
            }
        }
    };
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident<const D: usize> {
            $(
                $(#[$pmeta:meta])*
                $pvis:vis $plain:ident : $ptype:ty
            ),* $(,)?
        } per_particle {
            $(
                $(#[$fmeta:meta])*
                $fvis:vis $field:ident : $kind:ident $(=> $out:literal)?
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Default)]
        $vis struct $name<const D: usize> {
            $(
                $(#[$pmeta])*
                $pvis $plain: $ptype,
            )*
            $(
                $(#[$fmeta])*
                $fvis $field: $crate::particle_fields!(@type $kind),
            )*
        }

        impl<const D: usize> $crate::fields::Fields<D> for $name<D> {
            fn visit(&self, f: &mut dyn FnMut($crate::fields::Field<$crate::fields::ColumnRef<'_, D>>)) {
                $(
                    f($crate::fields::Field {
                        name: stringify!($field),
                        output: $crate::particle_fields!(@output $($out)?),
                        column: $crate::fields::ColumnRef::$kind(&self.$field),
                    });
                )*
            }

            fn visit_mut(
                &mut self,
                f: &mut dyn FnMut($crate::fields::Field<$crate::fields::ColumnMut<'_, D>>),
            ) {
                $(
                    f($crate::fields::Field {
                        name: stringify!($field),
                        output: $crate::particle_fields!(@output $($out)?),
                        column: $crate::fields::ColumnMut::$kind(&mut self.$field),
                    });
                )*
            }
        }
    };
    (@type Ids) => { Vec<u32> };
    (@type Scalars) => { Vec<f64> };
    (@type Vectors) => { Vec<$crate::fields::Vector<D>> };
    (@type Flags) => { Vec<bool> };
    (@output) => { None };
    (@output $out:literal) => { Some($out) };
}

/// Reusable buffers of [`permute`], one per element kind.
#[derive(Debug, Clone, Default)]
pub struct PermuteScratch<const D: usize> {
    ids: Vec<u32>,
    scalars: Vec<f64>,
    vectors: Vec<Vector<D>>,
    flags: Vec<bool>,
}

/// Applies the permutation `perm` (new → old) to the leading `perm.len()` entries of every
/// array of `fields` that has that many (shorter arrays, such as a field a scheme has not
/// filled yet, are left alone), through the buffers of `scratch` (no allocation once warm).
pub fn permute<const D: usize>(fields: &mut impl Fields<D>, perm: &[u32], scratch: &mut PermuteScratch<D>) {
    fn apply<T: Copy>(v: &mut [T], perm: &[u32], tmp: &mut Vec<T>) {
        if v.len() >= perm.len() {
            tmp.clear();
            tmp.extend(perm.iter().map(|&i| v[i as usize]));
            v[..perm.len()].copy_from_slice(tmp);
        }
    }
    fields.visit_mut(&mut |field| match field.column {
        ColumnMut::Ids(v) => apply(v, perm, &mut scratch.ids),
        ColumnMut::Scalars(v) => apply(v, perm, &mut scratch.scalars),
        ColumnMut::Vectors(v) => apply(v, perm, &mut scratch.vectors),
        ColumnMut::Flags(v) => apply(v, perm, &mut scratch.flags),
    });
}

/// Keeps, of the leading `keep.len()` entries of every array of `fields` that has that
/// many, those with `keep[a]`, in order, and drops everything after them (the open
/// boundaries' compaction of the fluid); returns the number kept.
pub fn retain<const D: usize>(fields: &mut impl Fields<D>, keep: &[bool]) -> usize {
    fn apply<T: Copy>(v: &mut Vec<T>, keep: &[bool]) {
        if v.len() >= keep.len() {
            let mut kept = 0;
            for (a, &k) in keep.iter().enumerate() {
                if k {
                    v[kept] = v[a];
                    kept += 1;
                }
            }
            v.truncate(kept);
        }
    }
    fields.visit_mut(&mut |field| match field.column {
        ColumnMut::Ids(v) => apply(v, keep),
        ColumnMut::Scalars(v) => apply(v, keep),
        ColumnMut::Vectors(v) => apply(v, keep),
        ColumnMut::Flags(v) => apply(v, keep),
    });
    keep.iter().filter(|&&k| k).count()
}

/// Copies of the arrays of a field set, in visiting order (the profiler's snapshot and
/// the driver's last-good copy): filled by [`Columns::save`], put back by
/// [`Columns::restore`], reusing its storage (no allocation once warm).
#[derive(Debug, Clone, Default)]
pub struct Columns<const D: usize> {
    ids: Vec<Vec<u32>>,
    scalars: Vec<Vec<f64>>,
    vectors: Vec<Vec<Vector<D>>>,
    flags: Vec<Vec<bool>>,
}

/// Which entries [`Columns::save`] copies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extent {
    /// Every array whole.
    All,
    /// The first `n` entries of the fields a frame shows (and the ids): what a frame of
    /// `n` fluid particles needs.
    Output(usize),
}

impl<const D: usize> Columns<D> {
    /// Copies the arrays of `fields` (all of each, or the shown fields' first `n`).
    pub fn save(&mut self, fields: &impl Fields<D>, extent: Extent) {
        fn copy<T: Copy>(slots: &mut Vec<Vec<T>>, k: &mut usize, src: &[T], n: usize) {
            if slots.len() == *k {
                slots.push(Vec::new());
            }
            let dst = &mut slots[*k];
            dst.clear();
            dst.extend_from_slice(&src[..n.min(src.len())]);
            *k += 1;
        }
        let mut k = [0usize; 4];
        fields.visit(&mut |field| {
            let n = match extent {
                Extent::All => usize::MAX,
                Extent::Output(_) if field.output.is_none() && !matches!(field.column, ColumnRef::Ids(_)) => {
                    0
                }
                Extent::Output(n) => n,
            };
            match field.column {
                ColumnRef::Ids(v) => copy(&mut self.ids, &mut k[0], v, n),
                ColumnRef::Scalars(v) => copy(&mut self.scalars, &mut k[1], v, n),
                ColumnRef::Vectors(v) => copy(&mut self.vectors, &mut k[2], v, n),
                ColumnRef::Flags(v) => copy(&mut self.flags, &mut k[3], v, n),
            }
        });
    }

    /// Puts the saved arrays back into `fields` (saved from a field set of the same type).
    pub fn restore(&self, fields: &mut impl Fields<D>) {
        fn put<T: Copy>(slots: &[Vec<T>], k: &mut usize, dst: &mut Vec<T>) {
            dst.clone_from(&slots[*k]);
            *k += 1;
        }
        let mut k = [0usize; 4];
        fields.visit_mut(&mut |field| match field.column {
            ColumnMut::Ids(v) => put(&self.ids, &mut k[0], v),
            ColumnMut::Scalars(v) => put(&self.scalars, &mut k[1], v),
            ColumnMut::Vectors(v) => put(&self.vectors, &mut k[2], v),
            ColumnMut::Flags(v) => put(&self.flags, &mut k[3], v),
        });
    }

    /// The saved arrays as a field set's view: calls `f` with each array of `fields`'s
    /// declaration (its name and output name) holding the saved values.
    pub fn visit_as(&self, fields: &impl Fields<D>, f: &mut dyn FnMut(Field<ColumnRef<'_, D>>)) {
        let mut k = [0usize; 4];
        fields.visit(&mut |field| {
            let column = match field.column {
                ColumnRef::Ids(_) => ColumnRef::Ids(&self.ids[next(&mut k[0])]),
                ColumnRef::Scalars(_) => ColumnRef::Scalars(&self.scalars[next(&mut k[1])]),
                ColumnRef::Vectors(_) => ColumnRef::Vectors(&self.vectors[next(&mut k[2])]),
                ColumnRef::Flags(_) => ColumnRef::Flags(&self.flags[next(&mut k[3])]),
            };
            f(Field { name: field.name, output: field.output, column });
        });
    }
}

/// Returns `*k` and increments it.
fn next(k: &mut usize) -> usize {
    *k += 1;
    *k - 1
}

/// Test helper (also for the schemes' own declarations): fills every array of `fields`
/// by index, applies a permutation and panics, naming the field, if an array did not move
/// with it.
#[cfg(test)]
pub(crate) fn check_permutes_every_field<const D: usize>(fields: &mut impl Fields<D>) {
    let n = 7;
    fields.visit_mut(&mut |field| match field.column {
        ColumnMut::Ids(v) => *v = (0..n as u32).collect(),
        ColumnMut::Scalars(v) => *v = (0..n).map(|i| i as f64).collect(),
        ColumnMut::Vectors(v) => *v = (0..n).map(|i| Vector::<D>::repeat(i as f64)).collect(),
        ColumnMut::Flags(v) => *v = (0..n).map(|i| i % 2 == 0).collect(),
    });
    let perm: Vec<u32> = vec![3, 0, 6, 1, 5, 2, 4];
    permute(fields, &perm, &mut PermuteScratch::default());
    fields.visit(&mut |field| {
        for (a, &i) in perm.iter().enumerate() {
            let moved = match field.column {
                ColumnRef::Ids(v) => v[a] == i,
                ColumnRef::Scalars(v) => v[a].to_bits() == (i as f64).to_bits(),
                ColumnRef::Vectors(v) => v[a] == Vector::<D>::repeat(i as f64),
                ColumnRef::Flags(v) => v[a] == (i % 2 == 0),
            };
            assert!(moved, "field `{}` not permuted", field.name);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::particle_fields! {
        /// A test declaration with one array of each kind.
        pub struct Probe<const D: usize> {
            /// Ids.
            pub id: Ids,
            /// Scalars, shown.
            pub s: Scalars => "s",
            /// Vectors.
            pub v: Vectors,
            /// Flags, shown.
            pub f: Flags => "f",
        }
    }

    /// Fills every array of `fields` with values that encode the index (length `n`).
    fn fill_by_index<const D: usize>(fields: &mut impl Fields<D>, n: usize) {
        fields.visit_mut(&mut |field| match field.column {
            ColumnMut::Ids(v) => *v = (0..n as u32).collect(),
            ColumnMut::Scalars(v) => *v = (0..n).map(|i| i as f64 + 0.5).collect(),
            ColumnMut::Vectors(v) => *v = (0..n).map(|i| Vector::<D>::repeat(i as f64)).collect(),
            ColumnMut::Flags(v) => *v = (0..n).map(|i| i % 3 == 0).collect(),
        });
    }

    /// Asserts that entry `a` of every array of `fields` holds the value of index `from[a]`.
    fn assert_moved<const D: usize>(fields: &impl Fields<D>, from: &[usize]) {
        fields.visit(&mut |field| {
            for (a, &i) in from.iter().enumerate() {
                let ok = match field.column {
                    ColumnRef::Ids(v) => v[a] == i as u32,
                    ColumnRef::Scalars(v) => v[a].to_bits() == (i as f64 + 0.5).to_bits(),
                    ColumnRef::Vectors(v) => v[a] == Vector::<D>::repeat(i as f64),
                    ColumnRef::Flags(v) => v[a] == (i % 3 == 0),
                };
                assert!(ok, "field `{}` entry {a} does not hold index {i}", field.name);
            }
        });
    }

    /// Every array of a declaration is permuted (the check a scheme's own declaration
    /// gets in its module: [`check_permutes_every_field`]).
    #[test]
    fn every_declared_field_is_permuted_retained_and_restored() {
        let mut p = Probe::<2>::default();
        check_permutes_every_field(&mut p);
        fill_by_index(&mut p, 6);
        assert_eq!(retain(&mut p, &[true, false, true, true, false, false]), 3);
        assert_moved(&p, &[0, 2, 3]);
        let mut saved = Columns::default();
        saved.save(&p, Extent::All);
        fill_by_index(&mut p, 2);
        saved.restore(&mut p);
        assert_moved(&p, &[0, 2, 3]);
        let mut out = Columns::default();
        out.save(&p, Extent::Output(2));
        let mut lens = Vec::new();
        out.visit_as(&p, &mut |field| {
            let len = match field.column {
                ColumnRef::Ids(v) => v.len(),
                ColumnRef::Scalars(v) => v.len(),
                ColumnRef::Vectors(v) => v.len(),
                ColumnRef::Flags(v) => v.len(),
            };
            lens.push((field.name, len));
        });
        assert_eq!(lens, [("id", 2), ("s", 2), ("v", 0), ("f", 2)]);
    }
}
