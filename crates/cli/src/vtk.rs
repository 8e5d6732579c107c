//! VTK XML unstructured-grid frames (`frames/frame_NNNNNN.vtu`, `frames/last_good.vtu`)
//! through the `vtkio` crate (0.7 line: nom 8 and quick-xml 0.36, nothing that a future
//! Rust rejects): one vertex cell per particle with point data `velocity`, `pressure` and
//! `free_surface` (0 / 1), Float64 / UInt8 arrays base64-encoded inline, which ParaView
//! opens directly.

use anyhow::Context;
use meniscus::Frame;
use std::path::{Path, PathBuf};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataSet, UnstructuredGridPiece, Version,
    VertexNumbers, Vtk,
};

/// Writes `frame` to `dir/frame_<step>.vtu` atomically (temporary file, then rename).
pub fn write_frame(dir: &Path, frame: &Frame) -> anyhow::Result<PathBuf> {
    write_frame_as(dir, &format!("frame_{:06}", frame.step), frame)
}

/// Writes `frame` to `dir/<stem>.vtu` atomically (temporary file, then rename).
pub fn write_frame_as(dir: &Path, stem: &str, frame: &Frame) -> anyhow::Result<PathBuf> {
    // The scheme's further declared fields (div r, WCSPH's density, ...).
    let scalars: Vec<(&str, &[f64])> = frame.scalars.iter().map(|(n, v)| (n.as_str(), &v[..])).collect();
    let vectors: Vec<(&str, &[[f64; 3]])> = frame.vectors.iter().map(|(n, v)| (n.as_str(), &v[..])).collect();
    write_vtu(dir, stem, frame, &scalars, &vectors)
}

/// Writes `frame` to `dir/<stem>.vtu` atomically with, after the fixed arrays, the point-data
/// arrays `scalars` (one value per particle) and `vectors` (three components per particle),
/// in the order given.
///
/// Fails, before anything is written, if an array's length is not the number of particles or
/// a name is used twice (the fixed names included). The file is serialised in memory and then
/// written and renamed, so that a write error (a full disk) is reported rather than lost in a
/// dropped buffer, and readers never see a partial file.
fn write_vtu(
    dir: &Path,
    stem: &str,
    frame: &Frame,
    scalars: &[(&str, &[f64])],
    vectors: &[(&str, &[[f64; 3]])],
) -> anyhow::Result<PathBuf> {
    let n = frame.x.len();
    let fixed = [
        ("velocity", frame.u.len()),
        ("pressure", frame.p.len()),
        ("free_surface", frame.free_surface.len()),
    ];
    let extra = scalars
        .iter()
        .map(|(name, v)| (*name, v.len()))
        .chain(vectors.iter().map(|(name, v)| (*name, v.len())));
    let mut names: Vec<&str> = Vec::new();
    for (name, len) in fixed.into_iter().chain(extra) {
        anyhow::ensure!(len == n, "VTK array `{name}` has {len} values for {n} particles");
        anyhow::ensure!(!names.contains(&name), "VTK array name `{name}` used twice");
        names.push(name);
    }

    let flat = |v: &[[f64; 3]]| -> Vec<f64> { v.iter().flatten().copied().collect() };
    let surface: Vec<u8> = frame.free_surface.iter().map(|&f| u8::from(f)).collect();
    let mut point = vec![
        Attribute::vectors("velocity").with_data(flat(&frame.u)),
        Attribute::scalars("pressure", 1).with_data(frame.p.clone()),
        Attribute::scalars("free_surface", 1).with_data(surface),
    ];
    point.extend(scalars.iter().map(|(name, v)| Attribute::scalars(*name, 1).with_data(v.to_vec())));
    point.extend(vectors.iter().map(|(name, v)| Attribute::vectors(*name).with_data(flat(v))));
    let piece = UnstructuredGridPiece {
        points: flat(&frame.x).into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: (0..n as u64).collect(),
                offsets: (1..=n as u64).collect(),
            },
            types: vec![CellType::Vertex; n],
        },
        data: Attributes { point, cell: vec![] },
    };
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        title: format!("meniscus step {} t = {:e} s", frame.step, frame.time),
        byte_order: ByteOrder::LittleEndian,
        data: DataSet::inline(piece),
        file_path: None,
    };
    let path = dir.join(format!("{stem}.vtu"));
    let mut bytes = Vec::new();
    vtkio::xml::VTKFile::try_from(vtk)
        .and_then(|file| file.write(&mut bytes))
        .with_context(|| format!("encoding {}", path.display()))?;
    let tmp = dir.join(format!(".{stem}.tmp.vtu"));
    if let Err(e) = std::fs::write(&tmp, &bytes) {
        let _ = std::fs::remove_file(&tmp);
        return Err(e).with_context(|| format!("writing {} (through {})", path.display(), tmp.display()));
    }
    std::fs::rename(&tmp, &path)
        .with_context(|| format!("renaming {} to {}", tmp.display(), path.display()))?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use vtkio::model::{IOBuffer, Piece};

    /// A fresh scratch directory for one test.
    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("meniscus-cli-vtk-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch directory");
        dir
    }

    /// Values that a decimal or single-precision path would not keep bit for bit.
    const AWKWARD: [f64; 8] = [
        0.1,
        -0.0,
        std::f64::consts::PI,
        1e-310,
        -1.7976931348623157e308,
        f64::INFINITY,
        f64::NAN,
        2.0 / 3.0,
    ];

    fn frame(n: usize) -> Frame {
        let v = |i: usize, k: usize| AWKWARD[(3 * i + k) % AWKWARD.len()] * (1.0 + i as f64 * 1e-3);
        Frame {
            step: 42,
            time: 1.25e-3,
            x: (0..n).map(|i| [v(i, 0), v(i, 1), 0.0]).collect(),
            u: (0..n).map(|i| [v(i, 2), v(i, 3), v(i, 4)]).collect(),
            p: (0..n).map(|i| v(i, 5)).collect(),
            free_surface: (0..n).map(|i| i % 3 == 1).collect(),
            ..Default::default()
        }
    }

    /// What a `.vtu` file reads back as: points, cell connectivity / offsets / types, and the
    /// point-data arrays by name (as f64, or as u8 for `free_surface`), in file order.
    struct ReadBack {
        points: Vec<f64>,
        connectivity: Vec<u64>,
        offsets: Vec<u64>,
        types: Vec<CellType>,
        arrays: Vec<(String, u32, IOBuffer)>,
    }

    fn read_back(path: &Path) -> ReadBack {
        let vtk = Vtk::import(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let DataSet::UnstructuredGrid { mut pieces, .. } = vtk.data else {
            panic!("not an unstructured grid")
        };
        assert_eq!(pieces.len(), 1);
        let piece = match pieces.remove(0) {
            Piece::Inline(p) => *p,
            _ => panic!("piece not inline"),
        };
        let VertexNumbers::XML { connectivity, offsets } = piece.cells.cell_verts else {
            panic!("legacy cells")
        };
        let arrays = piece
            .data
            .point
            .into_iter()
            .map(|a| match a {
                Attribute::DataArray(d) => (d.name, d.elem.num_comp(), d.data),
                Attribute::Field { name, .. } => panic!("field attribute {name}"),
            })
            .collect();
        ReadBack {
            points: piece.points.into_vec().expect("Float64 points"),
            connectivity,
            offsets,
            types: piece.cells.types,
            arrays,
        }
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn flat(v: &[[f64; 3]]) -> Vec<f64> {
        v.iter().flatten().copied().collect()
    }

    /// Checks that `back` holds `frame` bit for bit, then the `extra` arrays, and nothing else.
    fn assert_same(back: &ReadBack, frame: &Frame, extra: &[(&str, u32, Vec<f64>)]) {
        let n = frame.x.len();
        assert_eq!(bits(&back.points), bits(&flat(&frame.x)), "positions");
        assert_eq!(back.connectivity, (0..n as u64).collect::<Vec<_>>());
        assert_eq!(back.offsets, (1..=n as u64).collect::<Vec<_>>());
        assert_eq!(back.types, vec![CellType::Vertex; n]);
        let surface: Vec<u8> = frame.free_surface.iter().map(|&f| u8::from(f)).collect();
        let mut expected = vec![
            ("velocity", 3, IOBuffer::F64(flat(&frame.u))),
            ("pressure", 1, IOBuffer::F64(frame.p.clone())),
            ("free_surface", 1, IOBuffer::U8(surface)),
        ];
        expected.extend(extra.iter().map(|(name, comp, v)| (*name, *comp, IOBuffer::F64(v.clone()))));
        assert_eq!(back.arrays.len(), expected.len(), "number of point-data arrays");
        for ((name, comp, data), (want_name, want_comp, want)) in back.arrays.iter().zip(&expected) {
            assert_eq!((name.as_str(), *comp), (*want_name, *want_comp));
            match (data, want) {
                (IOBuffer::F64(got), IOBuffer::F64(want)) => assert_eq!(bits(got), bits(want), "{name}"),
                (IOBuffer::U8(got), IOBuffer::U8(want)) => assert_eq!(got, want, "{name}"),
                _ => panic!("{name}: read back as {data:?}"),
            }
        }
    }

    #[test]
    fn frames_read_back_bit_for_bit() {
        let dir = scratch("round_trip");
        let f = frame(37);
        let path = write_frame(&dir, &f).unwrap();
        assert_eq!(path, dir.join("frame_000042.vtu"));
        assert_same(&read_back(&path), &f, &[]);
        let last = write_frame_as(&dir, "last_good", &f).unwrap();
        assert_eq!(last, dir.join("last_good.vtu"));
        assert_eq!(std::fs::read(&last).unwrap(), std::fs::read(&path).unwrap());
        let mut left: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().file_name()).collect();
        left.sort();
        assert_eq!(left, ["frame_000042.vtu", "last_good.vtu"], "no temporary file left");
        // The header ParaView needs, and the particle arrays under their names.
        let text = std::fs::read_to_string(&path).unwrap();
        for s in [
            r#"<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian""#,
            r#"<Piece NumberOfPoints="37" NumberOfCells="37""#,
            r#"<PointData Scalars="pressure" Vectors="velocity">"#,
            r#"<DataArray type="Float64" Name="velocity" NumberOfComponents="3" format="binary""#,
            r#"<DataArray type="UInt8" Name="free_surface" format="binary""#,
        ] {
            assert!(text.contains(s), "{s} not in {text}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn extra_arrays_read_back_after_the_fixed_ones() {
        let dir = scratch("extra");
        let f = frame(11);
        let density: Vec<f64> = (0..11).map(|i| 1000.0 + AWKWARD[i % AWKWARD.len()]).collect();
        let kernel_sum: Vec<f64> = (0..11).map(|i| 0.1 * i as f64).collect();
        let normal: Vec<[f64; 3]> = (0..11).map(|i| [AWKWARD[i % 8], -(i as f64), 1.0 / 3.0]).collect();
        let path = write_vtu(
            &dir,
            "x",
            &f,
            &[("density", &density), ("kernel_sum", &kernel_sum)],
            &[("normal", &normal)],
        )
        .unwrap();
        let extra = [
            ("density", 1, density.clone()),
            ("kernel_sum", 1, kernel_sum.clone()),
            ("normal", 3, flat(&normal)),
        ];
        assert_same(&read_back(&path), &f, &extra);

        let short = &density[..10];
        let err = write_vtu(&dir, "y", &f, &[("density", short)], &[]).unwrap_err().to_string();
        assert!(err.contains("`density` has 10 values for 11 particles"), "{err}");
        let err = write_vtu(&dir, "y", &f, &[("pressure", &density)], &[]).unwrap_err().to_string();
        assert!(err.contains("`pressure` used twice"), "{err}");
        let err = write_vtu(&dir, "y", &f, &[("a", &density)], &[("a", &normal)]).unwrap_err().to_string();
        assert!(err.contains("`a` used twice"), "{err}");
        assert!(!dir.join("y.vtu").exists() && !dir.join(".y.tmp.vtu").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_empty_frame_reads_back() {
        let dir = scratch("empty");
        let f = frame(0);
        let path = write_frame(&dir, &f).unwrap();
        assert_same(&read_back(&path), &f, &[]);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_full_disk_is_reported_and_leaves_the_old_frame() {
        if !Path::new("/dev/full").exists() {
            eprintln!("skipped: no /dev/full");
            return;
        }
        let dir = scratch("full_disk");
        let f = frame(5);
        let path = write_frame_as(&dir, "last_good", &f).unwrap();
        let before = std::fs::read(&path).unwrap();
        std::os::unix::fs::symlink("/dev/full", dir.join(".last_good.tmp.vtu")).unwrap();
        let err = format!("{:#}", write_frame_as(&dir, "last_good", &frame(6)).unwrap_err());
        assert!(err.contains("last_good.vtu") && err.to_lowercase().contains("no space"), "{err}");
        assert_eq!(std::fs::read(&path).unwrap(), before, "the old file is untouched");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
