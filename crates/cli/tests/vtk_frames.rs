//! `meniscus run --vtk-every 1` writes frames that read back (through `vtkio`'s reader) as
//! the state the run's JSON snapshots hold at the same steps: positions, velocities,
//! pressures and free-surface flags.

use std::path::{Path, PathBuf};
use std::process::Command;
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece, VertexNumbers, Vtk};

/// The DESIGN.md scene.
const DROP: &str = include_str!("../../../validation/scenes/elliptical_drop.json");

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("vtk_frames").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// The point-data arrays of a `.vtu` file by name, its points, and its cell types.
struct Frame {
    points: Vec<f64>,
    types: Vec<CellType>,
    arrays: Vec<(String, IOBuffer)>,
}

impl Frame {
    fn read(path: &Path) -> Frame {
        let vtk = Vtk::import(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let DataSet::UnstructuredGrid { mut pieces, .. } = vtk.data else {
            panic!("not an unstructured grid")
        };
        let Piece::Inline(piece) = pieces.remove(0) else { panic!("piece not inline") };
        let n = piece.num_points() as u64;
        let VertexNumbers::XML { connectivity, offsets } = &piece.cells.cell_verts else {
            panic!("legacy cells")
        };
        assert_eq!(connectivity, &(0..n).collect::<Vec<_>>());
        assert_eq!(offsets, &(1..=n).collect::<Vec<_>>());
        let arrays = piece
            .data
            .point
            .into_iter()
            .map(|a| match a {
                Attribute::DataArray(d) => (d.name, d.data),
                Attribute::Field { name, .. } => panic!("field attribute {name}"),
            })
            .collect();
        Frame { points: piece.points.into_vec().expect("Float64 points"), types: piece.cells.types, arrays }
    }

    fn array(&self, name: &str) -> &IOBuffer {
        &self.arrays.iter().find(|(n, _)| n == name).unwrap_or_else(|| panic!("no array `{name}`")).1
    }

    fn f64s(&self, name: &str) -> Vec<f64> {
        match self.array(name) {
            IOBuffer::F64(v) => v.clone(),
            other => panic!("`{name}` is not Float64: {other:?}"),
        }
    }
}

/// Equal up to the last bit of a best-effort decimal parse of the JSON snapshot.
fn assert_close(got: &[f64], want: &[f64], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: length");
    for (i, (a, b)) in got.iter().zip(want).enumerate() {
        assert!((a - b).abs() <= f64::EPSILON * a.abs().max(b.abs()), "{what}[{i}]: {a} vs {b}");
    }
}

fn json_f64s(v: &serde_json::Value) -> Vec<f64> {
    let one = |x: &serde_json::Value| x.as_f64().expect("number");
    v.as_array()
        .expect("array")
        .iter()
        .flat_map(|x| match x.as_array() {
            Some(c) => c.iter().map(one).collect(),
            None => vec![one(x)],
        })
        .collect()
}

#[test]
fn frames_read_back_as_the_snapshots_at_the_same_steps() {
    let mut scene: serde_json::Value = serde_json::from_str(DROP).expect("scene JSON");
    scene["dx"] = serde_json::json!(0.1);
    scene["time"]["end"] = serde_json::json!(6e-5);
    scene["output"]["snapshot_times"] = serde_json::json!([0.0, 4e-5]);
    frames_match_snapshots("frames", &scene);
}

/// A 3D run's frames (a falling WCSPH ball of spherical shells with Hu–Adams surface
/// tension) read back as its snapshots: three coordinates and velocity components a point.
#[test]
fn frames_of_a_3d_run_read_back_as_its_snapshots() {
    let scene = serde_json::json!({
        "name": "ball", "dimension": 3, "dx": 0.25,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": 1000.0, "viscosity": 1e-3, "surface_tension": 0.07 },
        "body_force": [0.0, 0.0, -9.81],
        "bodies": [{ "role": "fluid", "shape": { "sphere": { "center": [0.0, 0.0, 0.0], "radius": 1.2 } },
                     "packing": "shells",
                     "velocity": { "affine": { "gradient": [[0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, -0.2]],
                                               "offset": [0.0, 0.0, -1.0] } } }],
        "scheme": { "wcsph": { "sound_speed": 20.0 } },
        "time": { "end": 0.01, "step": { "adaptive": { "cfl": 0.25, "viscous": 0.2, "max": 1e-3 } } },
        "output": { "snapshot_times": [0.0, 0.005] }
    });
    frames_match_snapshots("frames_3d", &scene);
}

/// Runs `scene` with a frame every step and compares the frames at the snapshots' steps with
/// the snapshots.
fn frames_match_snapshots(name: &str, scene: &serde_json::Value) {
    let dir = scratch(name);
    let scene_path = dir.join("scene.json");
    std::fs::write(&scene_path, scene.to_string()).unwrap();
    let out = dir.join("out");
    let res = Command::new(env!("CARGO_BIN_EXE_meniscus"))
        .args(["run", scene_path.to_str().unwrap(), "--out", out.to_str().unwrap(), "--vtk-every", "1"])
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("the meniscus binary runs");
    assert!(res.status.success(), "{}", String::from_utf8_lossy(&res.stderr));

    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let steps = summary["steps"].as_u64().unwrap();
    let mut files: Vec<String> = std::fs::read_dir(out.join("frames"))
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    files.sort();
    let want: Vec<String> = (0..=steps).map(|s| format!("frame_{s:06}.vtu")).collect();
    assert_eq!(files, want, "one frame a step, no temporary file left");

    for i in 0..2 {
        let path = out.join(format!("snapshots/snapshot_{i:03}.json"));
        let snap: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let step = snap["step"].as_u64().unwrap();
        let frame = Frame::read(&out.join(format!("frames/frame_{step:06}.vtu")));
        let n = snap["p"].as_array().unwrap().len();
        assert!(n > 100, "{n} particles");
        assert_eq!(frame.points.len(), 3 * n, "three coordinates a point");
        if scene["dimension"] == 3 {
            // A ball: its particles' z spans about its diameter (a lost z would be all 0).
            let z: Vec<f64> = frame.points.chunks(3).map(|p| p[2]).collect();
            let span = z.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                - z.iter().copied().fold(f64::INFINITY, f64::min);
            assert!(span > 1.5, "z spans {span}");
        }
        assert_eq!(frame.types, vec![CellType::Vertex; n]);
        assert_close(&frame.points, &json_f64s(&snap["x"]), "positions");
        assert_close(&frame.f64s("velocity"), &json_f64s(&snap["u"]), "velocity");
        assert_close(&frame.f64s("pressure"), &json_f64s(&snap["p"]), "pressure");
        let flags: Vec<u8> =
            snap["free_surface"].as_array().unwrap().iter().map(|f| u8::from(f.as_bool().unwrap())).collect();
        assert_eq!(frame.array("free_surface"), &IOBuffer::U8(flags), "free-surface flags");
    }
}
