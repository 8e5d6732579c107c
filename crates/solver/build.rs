//! The solver fingerprint ([`meniscus::SOLVER_FINGERPRINT`], from
//! `MENISCUS_SOLVER_FINGERPRINT`): SHA-256 of what a run's result depends on — this
//! crate's sources and manifest, the workspace's `Cargo.toml` and `Cargo.lock` (so a
//! dependency added anywhere in the workspace changes it) and the compiler's version — and
//! of no source file of the harness or the command line. The harness
//! keys its cached runs by it (a change to the harness, its metrics or its reports
//! re-evaluates the cached runs instead of rerunning them: issue #33), and the `meniscus`
//! binary prints it (`meniscus --version`), so that runs handed to it by the Slurm executor
//! are known to come from the same solver.

use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

fn main() {
    let manifest =
        PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let root = manifest.join("../..");
    let solver = root.join("crates/solver");
    let mut files = vec![solver.join("Cargo.toml"), root.join("Cargo.lock"), root.join("Cargo.toml")];
    sources(&solver.join("src"), &mut files);
    files.sort();
    let mut hash = Sha256::new();
    for file in &files {
        println!("cargo:rerun-if-changed={}", file.display());
        let rel = file.strip_prefix(&root).unwrap_or(file);
        hash.update(rel.to_string_lossy().as_bytes());
        hash.update([0]);
        hash.update(std::fs::read(file).unwrap_or_default());
        hash.update([0]);
    }
    println!("cargo:rerun-if-changed={}", solver.join("src").display());
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let version = std::process::Command::new(rustc).arg("-vV").output().map(|o| o.stdout).unwrap_or_default();
    hash.update(&version);
    let hex: String = hash.finalize().iter().map(|b| format!("{b:02x}")).collect();
    println!("cargo:rustc-env=MENISCUS_SOLVER_FINGERPRINT={hex}");
    let version = std::env::var("CARGO_PKG_VERSION").unwrap_or_default();
    println!("cargo:rustc-env=MENISCUS_VERSION={version} (solver {hex})");
}

/// Every file under `dir`, recursively.
fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            sources(&path, out);
        } else {
            out.push(path);
        }
    }
}
