//! The executor flags' errors, before anything runs: `--executor slurm` on a machine
//! without Slurm's commands, and a Slurm option without `--executor slurm` (the errors that
//! need a cluster are in crates/harness/tests/slurm.rs).

use std::process::Command;

/// Runs `cargo xtask validate --quick --case elliptical_drop <args>` with `path` as PATH;
/// returns the exit code and standard error.
fn validate(args: &[&str], path: &str) -> (Option<i32>, String) {
    let out_dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("executor_flags");
    let out = Command::new(env!("CARGO_BIN_EXE_xtask"))
        .args(["validate", "--quick", "--case", "elliptical_drop", "--no-progress", "--out"])
        .arg(&out_dir)
        .args(args)
        .env("PATH", path)
        .output()
        .expect("xtask runs");
    (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn slurm_without_its_commands_is_an_error_naming_sbatch() {
    let (code, stderr) = validate(&["--executor", "slurm"], "/nonexistent");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("`sbatch` is not on PATH"), "{stderr}");
}

#[test]
fn slurm_options_need_the_slurm_executor() {
    let path = std::env::var("PATH").unwrap_or_default();
    for (flag, value) in [("--partition", "debug"), ("--spool", "/tmp/spool"), ("--max-tasks", "4")] {
        let (code, stderr) = validate(&[flag, value], &path);
        assert_eq!(code, Some(2), "{stderr}");
        assert!(stderr.contains(&format!("{flag} applies to `--executor slurm` only")), "{stderr}");
    }
}
