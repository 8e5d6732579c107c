//! The `meniscus` binary fails clearly on bad paths: a non-zero exit code and a message
//! that names the path, for a missing or unreadable scene, an output directory that cannot
//! be created or written, and a full disk; a diverged run writes `frames/last_good.vtu`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The DESIGN.md scene.
const DROP: &str = include_str!("../../../validation/scenes/elliptical_drop.json");

/// A fresh scratch directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_errors").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// A small, fast scene (dx = 0.1, three steps) written to `dir/scene.json`.
fn small_scene(dir: &Path, edit: impl FnOnce(&mut serde_json::Value)) -> PathBuf {
    let mut v: serde_json::Value = serde_json::from_str(DROP).expect("scene JSON");
    v["dx"] = serde_json::json!(0.1);
    v["time"]["end"] = serde_json::json!(6e-5);
    edit(&mut v);
    let path = dir.join("scene.json");
    std::fs::write(&path, v.to_string()).expect("write scene");
    path
}

fn meniscus(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meniscus"))
        .args(args)
        .env("RAYON_NUM_THREADS", "1")
        .output()
        .expect("the meniscus binary runs")
}

/// Asserts the exit code and that stderr names every one of `words`; returns stderr.
fn fails_with(out: &Output, code: i32, words: &[&str]) -> String {
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(code), "exit code; stderr: {err}");
    for w in words {
        assert!(err.contains(w), "stderr does not name `{w}`: {err}");
    }
    err
}

fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

#[test]
fn missing_scene_file_names_the_path() {
    let dir = scratch("missing");
    let scene = dir.join("no_such_scene.json");
    for cmd in ["run", "check"] {
        let out =
            meniscus(&[cmd, s(&scene), "--out", s(&dir.join("out"))][..if cmd == "run" { 4 } else { 2 }]);
        fails_with(&out, 2, &[s(&scene), "cannot read scene file"]);
    }
    assert!(!dir.join("out").exists(), "nothing is created for a scene that cannot be read");
}

#[test]
fn unreadable_scene_file_names_the_path() {
    let dir = scratch("unreadable");
    // A directory where the file should be: unreadable as a file even for root.
    let scene = dir.join("scene_dir.json");
    std::fs::create_dir_all(&scene).unwrap();
    fails_with(&meniscus(&["check", s(&scene)]), 2, &[s(&scene)]);
    // Not UTF-8.
    let binary = dir.join("binary.json");
    std::fs::write(&binary, [0xff, 0xfe, 0x00, 0x7b]).unwrap();
    fails_with(&meniscus(&["check", s(&binary)]), 2, &[s(&binary)]);
}

#[test]
fn invalid_scene_names_the_field() {
    let dir = scratch("invalid");
    let scene = small_scene(&dir, |v| v["fluid"]["density"] = serde_json::json!(-1.0));
    fails_with(&meniscus(&["check", s(&scene)]), 2, &["fluid.density", "-1", "positive"]);
    fails_with(&meniscus(&["run", s(&scene), "--out", s(&dir.join("out"))]), 2, &["fluid.density"]);
}

#[test]
fn output_directory_that_cannot_be_created_names_the_path() {
    let dir = scratch("uncreatable");
    let scene = small_scene(&dir, |_| {});
    // Below a regular file: fails for every user, root included.
    let file = dir.join("a_file");
    std::fs::write(&file, "x").unwrap();
    let out = file.join("out");
    fails_with(&meniscus(&["run", s(&scene), "--out", s(&out)]), 1, &[s(&out), "output directory"]);
    // A device, not a directory.
    if Path::new("/dev/full").exists() {
        fails_with(
            &meniscus(&["run", s(&scene), "--out", "/dev/full"]),
            1,
            &["/dev/full", "output directory"],
        );
    }
}

#[test]
fn read_only_output_directory_names_the_path_or_is_written_by_root() {
    let dir = scratch("read_only");
    let scene = small_scene(&dir, |_| {});
    let out = dir.join("ro");
    std::fs::create_dir_all(&out).unwrap();
    let mut perms = std::fs::metadata(&out).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&out, perms.clone()).unwrap();
    // Root (CI containers) writes into read-only directories: then the run must succeed
    // there, as any writable directory; otherwise it must fail naming the directory.
    let probe = out.join("probe");
    let writable = std::fs::write(&probe, "x").is_ok();
    let res = meniscus(&["run", s(&scene), "--out", s(&out)]);
    if writable {
        let _ = std::fs::remove_file(&probe);
        let err = String::from_utf8_lossy(&res.stderr);
        assert_eq!(res.status.code(), Some(0), "writable for this user (root): {err}");
        assert!(out.join("summary.json").is_file(), "the run wrote its summary");
    } else {
        fails_with(&res, 1, &[s(&out), "cannot write"]);
    }
    #[allow(clippy::permissions_set_readonly_false)]
    perms.set_readonly(false);
    std::fs::set_permissions(&out, perms).unwrap();
}

#[cfg(unix)]
#[test]
fn full_disk_names_the_file() {
    if !Path::new("/dev/full").exists() {
        eprintln!("skipped: no /dev/full");
        return;
    }
    let dir = scratch("full_disk");
    let scene = small_scene(&dir, |_| {});
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // The temporary file of probes.json leads to a device that is always full (ENOSPC).
    std::os::unix::fs::symlink("/dev/full", out.join("probes.json.tmp")).unwrap();
    let err = fails_with(&meniscus(&["run", s(&scene), "--out", s(&out)]), 1, &[s(&out.join("probes.json"))]);
    assert!(err.to_lowercase().contains("no space"), "{err}");
}

#[test]
fn diverged_run_writes_the_last_good_state() {
    let dir = scratch("diverged");
    // Δt 100 times the CFL limit: the run blows up within a few steps.
    let scene = small_scene(&dir, |v| {
        v["dx"] = serde_json::json!(0.04);
        v["time"] = serde_json::json!({"end": 0.1, "step": {"fixed": 2e-2}});
    });
    let out = dir.join("out");
    let res = meniscus(&["run", s(&scene), "--out", s(&out), "--vtk-every", "1"]);
    let last_good = out.join("frames/last_good.vtu");
    let err = fails_with(&res, 3, &["diverged at step", "in stage", s(&last_good)]);
    assert!(last_good.is_file(), "{err}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "diverged");
    let steps = summary["steps"].as_u64().unwrap();
    // The last good state is the start of the failing step, the last regular frame's step.
    assert!(err.contains(&format!("start of step {}", steps + 1)), "{err}");
    let vtu = std::fs::read_to_string(&last_good).unwrap();
    assert!(vtu.contains("pressure") && !vtu.contains("NaN"), "last_good.vtu holds finite data");
    // It reads back, with finite positions, velocities and pressures for every particle.
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtkio::Vtk::import(&last_good).unwrap().data
    else {
        panic!("not an unstructured grid")
    };
    let Some(vtkio::model::Piece::Inline(piece)) = pieces.first() else { panic!("no inline piece") };
    let n = piece.num_points();
    assert!(n > 0 && piece.points.cast_into::<f64>().unwrap().iter().all(|x| x.is_finite()));
    for a in &piece.data.point {
        let vtkio::model::Attribute::DataArray(d) = a else { panic!("field attribute") };
        let values = d.data.cast_into::<f64>().unwrap();
        assert_eq!(values.len(), n * d.elem.num_comp() as usize, "{}", d.name);
        assert!(values.iter().all(|x| x.is_finite()), "{} finite", d.name);
    }
    // Without frames it is written too.
    let out2 = dir.join("out2");
    let res = meniscus(&["run", s(&scene), "--out", s(&out2)]);
    let last_good2 = out2.join("frames/last_good.vtu");
    fails_with(&res, 3, &[s(&last_good2)]);
    assert_eq!(std::fs::read_to_string(&last_good2).unwrap(), vtu, "the same state either way");
}

#[test]
fn run_writes_the_requested_snapshots() {
    let dir = scratch("snapshots");
    let scene = small_scene(&dir, |v| v["output"]["snapshot_times"] = serde_json::json!([0.0, 4e-5]));
    let out_dir = dir.join("out");
    let out = meniscus(&["run", s(&scene), "--out", s(&out_dir)]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let read = |i: usize| -> serde_json::Value {
        let path = out_dir.join(format!("snapshots/snapshot_{i:03}.json"));
        serde_json::from_str(&std::fs::read_to_string(&path).expect("snapshot written")).expect("JSON")
    };
    let (first, second) = (read(0), read(1));
    assert_eq!(first["step"], 0);
    assert!((second["time"].as_f64().unwrap() - 4e-5).abs() < 1e-15, "{}", second["time"]);
    assert_eq!(first["x"].as_array().unwrap().len(), second["p"].as_array().unwrap().len());
    assert!(!out_dir.join("snapshots/snapshot_002.json").exists());
}
