//! `meniscus reference`: the README's commands print what the references say (checked
//! against closed forms computed here, not against the library that prints them), the
//! tables have their headers, and bad arguments exit with code 2 naming the argument.

use serde_json::Value;
use std::f64::consts::PI;
use std::process::{Command, Output};

fn reference(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_meniscus"))
        .arg("reference")
        .args(args)
        .output()
        .expect("the meniscus binary runs")
}

/// The JSON a successful command prints.
fn json(args: &[&str]) -> Value {
    let out = reference(args);
    assert_eq!(out.status.code(), Some(0), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).expect("JSON on stdout")
}

fn close(got: &Value, want: f64, rel: f64) {
    let got = got.as_f64().unwrap_or(f64::NAN);
    assert!((got - want).abs() <= rel * want.abs(), "got {got}, want {want}");
}

/// README: `reference elliptical-drop --radius 1 --a0 100 --density 1000 --times 0.002,0.0076 --json`.
#[test]
fn elliptical_drop_keeps_its_area() {
    let v = json(&[
        "elliptical-drop",
        "--radius",
        "1",
        "--a0",
        "100",
        "--density",
        "1000",
        "--times",
        "0,0.002,0.0076",
        "--json",
    ]);
    let rows = v.as_array().expect("an array");
    assert_eq!(rows.len(), 3);
    close(&rows[0]["a"], 1.0, 1e-12);
    close(&rows[0]["strain_rate"], 100.0, 1e-12);
    for r in rows {
        // Incompressible: a b = R².
        let (a, b) = (r["a"].as_f64().unwrap(), r["b"].as_f64().unwrap());
        assert!((a * b - 1.0).abs() < 1e-9, "a b = {}", a * b);
    }
    // The README's second time: a has shrunk to about half.
    close(&rows[2]["a"], 0.514266, 1e-5);
}

/// README: `reference poiseuille-startup --width 1e-3 --viscosity 1e-6 --force 2e-4 --y 0.0005 --times 0.1125 --json`,
/// against the Fourier series of the start-up (Morris et al. 1997) summed here.
#[test]
fn poiseuille_startup_matches_its_series() {
    let v = json(&[
        "poiseuille-startup",
        "--width",
        "1e-3",
        "--viscosity",
        "1e-6",
        "--force",
        "2e-4",
        "--y",
        "0.0005",
        "--times",
        "0.1125",
        "--json",
    ]);
    let (f, nu, d, y, t) = (2e-4, 1e-6, 1e-3, 5e-4, 0.1125);
    let mut u = f / (2.0 * nu) * y * (d - y);
    for k in (1..400).step_by(2) {
        let k = k as f64;
        u -= 4.0 * f * d * d / (nu * PI.powi(3) * k.powi(3))
            * (k * PI * y / d).sin()
            * (-k * k * PI * PI * nu * t / (d * d)).exp();
    }
    close(&v[0]["u"], u, 1e-8);
    close(&v[0]["u"], 1.649982768958e-5, 1e-9);
}

#[test]
fn pipe_startup_reaches_hagen_poiseuille() {
    // τ = ν t / R² = 10: developed, u = G (R² − r²) / 4ν.
    let v = json(&[
        "pipe-startup",
        "--radius",
        "0.01",
        "--viscosity",
        "1e-6",
        "--gradient",
        "1e-4",
        "--r",
        "0,0.005",
        "--times",
        "1000",
        "--json",
    ]);
    close(&v[0]["u"], 1e-4 * 1e-4 / 4e-6, 1e-8);
    close(&v[1]["u"], 1e-4 * 0.75e-4 / 4e-6, 1e-8);
}

#[test]
fn rotating_square_centre_pressure_matches_its_series() {
    // p(0, 0) = −(32 ρ ω² L² / π⁴) Σ_{m,n odd} (−1)^((m+n)/2 − 1) / (m n (m² + n²)).
    let v = json(&["rotating-square", "--side", "1", "--omega", "1", "--density", "1000", "--json"]);
    let mut s = 0.0;
    for m in (1..1200).step_by(2) {
        for n in (1..1200).step_by(2) {
            let sign = if ((m - 1) / 2 + (n - 1) / 2) % 2 == 0 { 1.0 } else { -1.0 };
            let (m, n) = (m as f64, n as f64);
            s += sign / (m * n * (m * m + n * n));
        }
    }
    close(&v[0]["p"], -32.0 * 1000.0 / PI.powi(4) * s, 1e-6);
}

#[test]
fn capillary_modes_of_a_cylindrical_drop() {
    // 2D: Δp = σ/R, ω² = n(n² − 1) σ / (ρ R³), damping 2 ν n (n − 1) / R².
    let v = json(&[
        "capillary",
        "--dim",
        "2",
        "--radius",
        "0.2",
        "--sigma",
        "1",
        "--density",
        "1",
        "--viscosity",
        "5e-3",
        "--modes",
        "2,3",
        "--json",
    ]);
    close(&v["laplace_pressure"], 5.0, 1e-12);
    for (i, n) in [2.0f64, 3.0].into_iter().enumerate() {
        let omega = (n * (n * n - 1.0) / 0.008f64).sqrt();
        close(&v["modes"][i]["omega"], omega, 1e-12);
        close(&v["modes"][i]["period"], 2.0 * PI / omega, 1e-12);
        close(&v["modes"][i]["damping_rate"], 2.0 * 5e-3 * n * (n - 1.0) / 0.04, 1e-12);
    }
}

#[test]
fn entrance_lengths_of_durst_and_chen() {
    // Durst et al. 2005 (REFERENCES.md §3c): channel L/H = 0.631 / (1 + 0.044 Re) + 0.0442 Re,
    // pipe L/D = (0.619^1.6 + (0.0567 Re)^1.6)^(1/1.6); Chen 1973 with D_h = 2H; 0.06 Re.
    let v = json(&["entrance-length", "--reynolds", "400", "--json"]);
    close(&v[0]["channel_durst"], 0.631 / (1.0 + 0.044 * 400.0) + 0.0442 * 400.0, 1e-12);
    close(&v[0]["channel_chen"], 2.0 * (0.315 / (1.0 + 0.0175 * 800.0) + 0.011 * 800.0), 1e-12);
    close(&v[0]["pipe_durst"], (0.619f64.powf(1.6) + (0.0567f64 * 400.0).powf(1.6)).powf(1.0 / 1.6), 1e-12);
    close(&v[0]["pipe_classical"], 24.0, 1e-12);
}

#[test]
fn tables_have_headers() {
    let out = reference(&[
        "elliptical-drop",
        "--radius",
        "1",
        "--a0",
        "100",
        "--density",
        "1000",
        "--times",
        "0.002",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8_lossy(&out.stdout);
    for word in ["t [s]", "a [m]", "b [m]", "pc [Pa]", "0.002"] {
        assert!(text.contains(word), "no `{word}` in {text}");
    }
}

/// Bad arguments exit with 2 and name the argument (and the rule).
#[test]
fn bad_arguments_exit_2_naming_the_argument() {
    let poiseuille = |width: &str, y: &str, t: &str| {
        reference(&[
            "poiseuille-startup",
            "--width",
            width,
            "--viscosity",
            "1e-6",
            "--force",
            "2e-4",
            "--y",
            y,
            "--times",
            t,
        ])
    };
    for (out, says) in [
        (poiseuille("-1", "0", "1"), "--width"),
        (poiseuille("1e-3", "0.002", "1"), "--y"),
        (poiseuille("1e-3", "0", "-1"), "--times"),
        (poiseuille("1e-3", "0", "x"), "--times"),
        (reference(&["capillary", "--dim", "4", "--radius", "1", "--sigma", "1", "--density", "1"]), "--dim"),
        (
            reference(&[
                "capillary",
                "--dim",
                "2",
                "--radius",
                "1",
                "--sigma",
                "1",
                "--density",
                "1",
                "--modes",
                "1",
            ]),
            "--modes",
        ),
        (reference(&["entrance-length", "--reynolds", "-4"]), "--reynolds"),
        (reference(&["elliptical-drop", "--radius", "1", "--a0", "100", "--density", "1000"]), "--times"),
        (reference(&["no-such-reference"]), "no-such-reference"),
    ] {
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "stderr: {err}");
        assert!(err.contains(says), "stderr does not name `{says}`: {err}");
    }
}
