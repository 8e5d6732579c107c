//! VTK XML unstructured-grid frames (`frames/frame_NNNNNN.vtu`) through the `vtkio` crate (0.7):
//! one vertex cell per particle with velocity, pressure and the free-surface flag, which
//! ParaView opens directly.

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
    let n = frame.x.len();
    let points: Vec<f64> = frame.x.iter().flatten().copied().collect();
    let velocity: Vec<f64> = frame.u.iter().flatten().copied().collect();
    let surface: Vec<u8> = frame.free_surface.iter().map(|&f| u8::from(f)).collect();
    let piece = UnstructuredGridPiece {
        points: points.into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: (0..n as u64).collect(),
                offsets: (1..=n as u64).collect(),
            },
            types: vec![CellType::Vertex; n],
        },
        data: Attributes {
            point: vec![
                Attribute::vectors("velocity").with_data(velocity),
                Attribute::scalars("pressure", 1).with_data(frame.p.clone()),
                Attribute::scalars("free_surface", 1).with_data(surface),
            ],
            cell: vec![],
        },
    };
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        title: format!("meniscus step {} t = {:e} s", frame.step, frame.time),
        byte_order: ByteOrder::LittleEndian,
        data: DataSet::inline(piece),
        file_path: None,
    };
    let path = dir.join(format!("{stem}.vtu"));
    let tmp = dir.join(format!(".{stem}.tmp.vtu"));
    vtk.export(&tmp).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, &path).with_context(|| format!("renaming to {}", path.display()))?;
    Ok(path)
}
