//! Particle snapshots of a run (`output.snapshot_times` of its scene): positions and
//! pressures at the requested times, cached with the run and written to
//! `reports/<case>/snapshots/<slug>.json` for the report's scatter plots
//! ([`crate::report::plots::snapshots`]). A 3D snapshot is drawn as a cut ([`View`]).

use crate::error::Result;
use crate::io;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The names of the axes, by index (0 = x, 1 = y, 2 = z).
pub const AXES: [&str; 3] = ["x", "y", "z"];

/// The particles of a run at one time (in initial-id order).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Snapshot {
    /// Time \[s\].
    pub time: f64,
    /// Steps taken.
    pub step: usize,
    /// x coordinates \[m\].
    pub x: Vec<f64>,
    /// y coordinates \[m\].
    pub y: Vec<f64>,
    /// z coordinates \[m\] of a 3D run (one per particle); empty, and absent from the
    /// JSON, for a 2D run.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub z: Vec<f64>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
}

impl Snapshot {
    /// The snapshot of `frame`, a frame of a `dimension`-dimensional run (z kept in 3D).
    pub fn new(frame: &meniscus::Frame, dimension: usize) -> Self {
        let along = |a: usize| frame.x.iter().map(|x| x[a]).collect();
        Snapshot {
            time: frame.time,
            step: frame.step,
            x: along(0),
            y: along(1),
            z: if dimension == 3 { along(2) } else { Vec::new() },
            p: frame.p.clone(),
        }
    }

    /// Whether the snapshot is of a 3D run (it has z coordinates).
    pub fn is_3d(&self) -> bool {
        !self.z.is_empty()
    }

    /// The coordinates along `axis` (0 = x, 1 = y, otherwise z).
    fn along(&self, axis: usize) -> &[f64] {
        match axis {
            0 => &self.x,
            1 => &self.y,
            _ => &self.z,
        }
    }

    /// What a figure draws of the snapshot: a 2D snapshot as it is, in the x–y plane; a 3D
    /// one cut by the plane normal to axis `cut_axis` (0, 1 or 2; checked when the case
    /// loads) through the fluid's centroid, keeping the particles within half the spacing
    /// `dx` \[m\] of it (see [`Cut`]), seen in that plane (its two other axes in
    /// increasing order: x–z for `cut_axis` = 1).
    pub fn view(&self, cut_axis: usize, dx: f64) -> View {
        if !self.is_3d() {
            return View { axes: [0, 1], h: self.x.clone(), v: self.y.clone(), p: self.p.clone(), cut: None };
        }
        let axes = match cut_axis {
            0 => [1, 2],
            1 => [0, 2],
            _ => [0, 1],
        };
        let normal = self.along(cut_axis);
        let (sum, n) =
            normal.iter().filter(|s| s.is_finite()).fold((0.0, 0usize), |(sum, n), s| (sum + s, n + 1));
        let cut = Cut { axis: cut_axis, centre: sum / n as f64, half_width: 0.5 * dx };
        let kept: Vec<usize> = (0..normal.len()).filter(|&i| cut.contains(normal[i])).collect();
        let pick = |values: &[f64]| kept.iter().map(|&i| values[i]).collect();
        View {
            axes,
            h: pick(self.along(axes[0])),
            v: pick(self.along(axes[1])),
            p: pick(&self.p),
            cut: Some(cut),
        }
    }
}

/// The slab of a 3D [`View`]: the particles with `−half_width ≤ s − centre < half_width`,
/// `s` their coordinate along `axis` (half-open, so that a lattice of spacing Δx has
/// exactly one layer in a slab of thickness Δx).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cut {
    /// The plane's normal (0 = x, 1 = y, 2 = z).
    pub axis: usize,
    /// The plane's coordinate along the normal: the mean of the particles' \[m\] (the
    /// fluid's centroid; NaN when no particle has a finite coordinate).
    pub centre: f64,
    /// Half the slab's thickness, Δx/2 \[m\].
    pub half_width: f64,
}

impl Cut {
    /// Whether coordinate `s` \[m\] along the normal lies in the slab (never when NaN).
    pub fn contains(&self, s: f64) -> bool {
        let d = s - self.centre;
        d >= -self.half_width && d < self.half_width
    }
}

/// The particles a snapshot panel draws: positions in the plane of the figure and their
/// pressures (see [`Snapshot::view`]).
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// The horizontal and vertical axes (0 = x, 1 = y, 2 = z).
    pub axes: [usize; 2],
    /// Horizontal coordinates \[m\].
    pub h: Vec<f64>,
    /// Vertical coordinates \[m\].
    pub v: Vec<f64>,
    /// Pressures \[Pa\].
    pub p: Vec<f64>,
    /// The slab kept of a 3D snapshot (`None` in 2D: every particle).
    pub cut: Option<Cut>,
}

/// `reports/<case>/snapshots/<slug>.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SnapshotFile {
    /// Run slug.
    pub slug: String,
    /// Preset.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// The run's status (`ok` or `diverged: …`).
    pub status: String,
    /// The snapshots, in time order.
    pub frames: Vec<Snapshot>,
}

/// Where the snapshots of run `slug` of a case live.
pub fn path(case_dir: &Path, slug: &str) -> PathBuf {
    case_dir.join("snapshots").join(format!("{slug}.json"))
}

/// Writes `file` atomically as compact JSON (thousands of numbers per frame).
pub fn store(case_dir: &Path, file: &SnapshotFile) -> Result<()> {
    let p = path(case_dir, &file.slug);
    let bytes = serde_json::to_vec(file)
        .map_err(|source| crate::error::HarnessError::Json { path: p.clone(), source })?;
    io::write_atomic(&p, &bytes)
}

/// The snapshots of run `slug`, when written.
pub fn load(case_dir: &Path, slug: &str) -> Option<SnapshotFile> {
    io::read_json(&path(case_dir, slug)).ok()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::io::testing::Scratch;

    #[test]
    fn round_trip_through_the_case_directory() {
        let dir = Scratch::new("snapshots");
        let frame = meniscus::Frame {
            step: 3,
            time: 0.01,
            x: vec![[0.1, 0.2, 0.0], [0.3, -0.4, 0.0]],
            u: vec![[0.0; 3]; 2],
            p: vec![-5.0, 7.5],
            free_surface: vec![false, true],
            ..Default::default()
        };
        let file = SnapshotFile {
            slug: "isph-shifting_dx0.02".into(),
            preset: "shifting".into(),
            dx: 0.02,
            status: "ok".into(),
            frames: vec![Snapshot::new(&frame, 2)],
        };
        store(dir.path(), &file).unwrap();
        assert_eq!(load(dir.path(), "isph-shifting_dx0.02"), Some(file.clone()));
        assert_eq!(file.frames[0].y, [0.2, -0.4]);
        // A 2D snapshot has no z, in memory or in the file.
        assert!(file.frames[0].z.is_empty());
        assert!(!std::fs::read_to_string(path(dir.path(), &file.slug)).unwrap().contains("\"z\""));
        assert!(load(dir.path(), "isph-other_dx0.02").is_none());
    }

    /// A lattice ball of spacing `dx` and radius 4 dx centred on `centre` (a lattice point),
    /// pressure the height `z` \[Pa\]: 257 particles, 49 in each central plane.
    pub(crate) fn ball(dx: f64, centre: [f64; 3]) -> Snapshot {
        let mut frame = meniscus::Frame { time: 0.5, step: 7, ..Default::default() };
        for i in -4i32..=4 {
            for j in -4i32..=4 {
                for k in -4i32..=4 {
                    if i * i + j * j + k * k <= 16 {
                        let [a, b, c] = [i, j, k].map(|n| n as f64 * dx);
                        frame.x.push([centre[0] + a, centre[1] + b, centre[2] + c]);
                        frame.p.push(centre[2] + c);
                    }
                }
            }
        }
        Snapshot::new(&frame, 3)
    }

    #[test]
    fn a_3d_snapshot_keeps_z() {
        let dir = Scratch::new("snapshots-3d");
        let snap = ball(0.01, [0.1, 0.2, 0.3]);
        assert_eq!(snap.z.len(), 257);
        assert!(snap.is_3d() && (snap.z[0] - 0.3).abs() < 1e-12, "{}", snap.z[0]);
        let file = SnapshotFile {
            slug: "isph-paper_dx0.01".into(),
            preset: "paper".into(),
            dx: 0.01,
            status: "ok".into(),
            frames: vec![snap],
        };
        store(dir.path(), &file).unwrap();
        assert_eq!(load(dir.path(), &file.slug), Some(file));
    }

    /// The cut keeps the one lattice plane through the centroid, whichever the normal, and
    /// shows the two other axes; a 2D snapshot is shown whole in x–y.
    #[test]
    fn the_cut_keeps_the_plane_through_the_centroid() {
        let dx = 0.01;
        let centre = [0.1, 0.2, 0.3];
        let snap = ball(dx, centre);
        for (axis, axes) in [(0, [1, 2]), (1, [0, 2]), (2, [0, 1])] {
            let view = snap.view(axis, dx);
            let cut = view.cut.unwrap();
            assert_eq!((view.axes, cut.axis, cut.half_width), (axes, axis, 0.005));
            assert!((cut.centre - centre[axis]).abs() < 1e-12, "{cut:?}");
            assert_eq!((view.h.len(), view.v.len(), view.p.len()), (49, 49, 49), "axis {axis}");
            // The kept particles are those of the plane, with their own pressures.
            let kept = (0..257).filter(|&i| (snap.along(axis)[i] - centre[axis]).abs() < 0.5 * dx);
            let p: Vec<f64> = kept.map(|i| snap.p[i]).collect();
            assert_eq!(view.p, p);
        }
        // A NaN coordinate is dropped from the centroid and from the cut (particle 0 is
        // (-4 dx, 0, 0) from the centre, in the plane y = 0.2).
        let mut broken = snap.clone();
        broken.y[0] = f64::NAN;
        let view = broken.view(1, dx);
        assert!((view.cut.unwrap().centre - 0.2).abs() < 1e-12 && view.h.len() == 48);
        // A centroid half-way between two planes (4 × 4 × 4 cube, spacing 0.25, exact in
        // binary): the half-open slab [0.25, 0.5) keeps the lower of the two.
        let at = |n: usize| (n % 4) as f64 * 0.25;
        let cube = Snapshot {
            time: 0.0,
            step: 0,
            x: (0..64).map(at).collect(),
            y: (0..64).map(|n| at(n / 4)).collect(),
            z: (0..64).map(|n| at(n / 16)).collect(),
            p: vec![0.0; 64],
        };
        let view = cube.view(1, 0.25);
        assert_eq!(view.cut.unwrap().centre.to_bits(), 0.375f64.to_bits());
        assert_eq!(view.h.len(), 16);
        let kept = (0..64).filter(|&n| view.cut.unwrap().contains(cube.y[n]));
        assert!(kept.clone().all(|n| cube.y[n].to_bits() == 0.25f64.to_bits()) && kept.count() == 16);
        let flat = Snapshot { z: Vec::new(), ..snap.clone() };
        let view = flat.view(1, dx);
        assert_eq!((view.axes, view.cut, view.h.len()), ([0, 1], None, 257));
        assert_eq!((view.h, view.v, view.p), (flat.x, flat.y, flat.p));
    }
}
