//! The free-surface pressure placed at the surface (`scheme.isph.free_surface_pressure:
//! extrapolated`): the Dirichlet value of the surface particles, that the solve keeps it,
//! that Young–Laplace adds to it, and the scene rules.

use meniscus::Scene;
use meniscus::profile::Stepper;
use serde_json::json;

const RHO: f64 = 1000.0;
const G: f64 = 9.81;
const DX: f64 = 0.005;

/// A free block 0.2 m × 0.1 m under gravity whose initial pressure is hydrostatic with its
/// zero 1 cm above the top (`p = ρ g (0.11 − y)`), so that the surface particles start
/// away from the extrapolated value.
fn block(gradient: &str) -> serde_json::Value {
    json!({
        "name": "block", "dimension": 2, "dx": DX,
        "kernel": { "kind": "cubic_spline", "h_over_dx": 1.5 },
        "fluid": { "density": RHO, "viscosity": 1e-3 },
        "body_force": [0.0, -G],
        "bodies": [ { "role": "fluid", "shape": { "rectangle": { "min": [0.0, 0.0], "max": [0.2, 0.1] } },
                      "pressure": { "hydrostatic": { "surface_point": [0.0, 0.11] } } } ],
        "scheme": { "isph": { "ppe": { "solver": "cg", "tolerance": 1e-8, "max_iterations": 2000 },
                              "pressure_gradient": gradient, "divergence": "corrected",
                              "free_surface_pressure": "extrapolated" } },
        "time": { "end": 0.01, "step": { "fixed": 1e-4 } }
    })
}

#[test]
fn surface_particles_carry_the_linear_extrapolation_to_the_surface() {
    // The kernel-corrected gradient is exact for the linear field, and on the flat sides
    // of the lattice the colour normal is exact by symmetry: the top row (Δx/2 below the
    // top of the volume) gets ρ g Δx/2, the side columns ∂p/∂n = 0, the bottom row
    // −ρ g Δx/2 (the field extrapolated down to the bottom face), whatever they held.
    let scene = Scene::from_json(&block("corrected").to_string()).expect("valid scene");
    let mut st = Stepper::<2>::new(&scene).expect("builds");
    let ctx = st.begin_step().expect("step");
    let i = st.stage_index("surface_extrapolation").expect("stage built");
    st.run_stages_before(i + 1, &ctx).expect("runs");
    let s = st.state();
    let half = 0.5 * RHO * G * DX;
    let (mut top, mut side, mut bottom) = (0, 0, 0);
    for a in (0..s.particles.fluid).filter(|&a| s.particles.free_surface[a]) {
        let (x, y, p) = (s.particles.x[a][0], s.particles.x[a][1], s.particles.p[a]);
        // Away from the corners, where the normal is diagonal.
        let inner_x = (0.02..0.18).contains(&x);
        let inner_y = (0.02..0.08).contains(&y);
        if inner_x && y > 0.1 - DX {
            assert!((p - half).abs() < 1e-9 * half, "top ({x}, {y}): {p} Pa against {half}");
            top += 1;
        } else if inner_x && y < DX {
            assert!((p + half).abs() < 1e-9 * half, "bottom ({x}, {y}): {p} Pa against {}", -half);
            bottom += 1;
        } else if inner_y {
            assert!(p.abs() < 1e-9 * half, "side ({x}, {y}): {p} Pa");
            side += 1;
        }
    }
    assert_eq!((top, bottom), (32, 32), "surface rows found");
    assert!(side >= 2 * 12, "{side} side particles");
    // The default condition, for contrast: no such stage.
    let mut zero = block("corrected");
    zero["scheme"]["isph"]["free_surface_pressure"] = json!("zero");
    let sim =
        meniscus::AnySimulation::new(&Scene::from_json(&zero.to_string()).expect("valid")).expect("builds");
    assert!(!sim.stage_names().contains(&"surface_extrapolation"), "{:?}", sim.stage_names());
}

#[test]
fn extrapolated_surface_pressure_needs_a_difference_form_gradient() {
    // The symmetric gradient adds p_a Σ_b V_b ∇_aW_ab on a surface particle whose pressure
    // is not zero: an outward push (measured on the elliptical drop: semi-axis a 0.33 %
    // off against 0.20 % at Δx = 0.02). Without the kernel-gradient correction the plain
    // gradient sees about half of ∂p/∂n on a surface row.
    let err = Scene::from_json(&block("symmetric").to_string()).expect_err("rejected").to_string();
    assert!(
        err.contains("scheme.isph.free_surface_pressure")
            && err.contains("extrapolated")
            && err.contains("difference"),
        "{err}"
    );
    for gradient in ["difference", "corrected"] {
        Scene::from_json(&block(gradient).to_string()).expect("valid scene");
    }
    let mut plain = block("difference");
    plain["scheme"]["isph"]["divergence"] = json!("standard");
    let err = Scene::from_json(&plain.to_string()).expect_err("rejected").to_string();
    assert!(err.contains("scheme.isph.free_surface_pressure") && err.contains("correction"), "{err}");
}

/// The free-surface values of the stepper's state.
fn surface_values(st: &Stepper<2>) -> Vec<(usize, f64)> {
    let s = st.state();
    (0..s.particles.fluid).filter(|&a| s.particles.free_surface[a]).map(|a| (a, s.particles.p[a])).collect()
}

#[test]
fn the_solve_keeps_the_extrapolated_values() {
    // The PPE takes them as known values: after the solve the surface particles hold what
    // the stage set, and the interior moved (the block's pressure starts 1 cm too high).
    let scene = Scene::from_json(&block("corrected").to_string()).expect("valid scene");
    let mut st = Stepper::<2>::new(&scene).expect("builds");
    let ctx = st.begin_step().expect("step");
    let set = st.stage_index("surface_extrapolation").expect("stage built") + 1;
    st.run_stages_before(set, &ctx).expect("runs");
    let before = surface_values(&st);
    let interior = st.state().particles.p.clone();
    let solve = st.stage_index("ppe_solve").expect("stage built");
    (set..=solve).try_for_each(|i| st.run_stage(i, &ctx)).expect("runs");
    assert_eq!(surface_values(&st), before);
    let s = st.state();
    let moved = (0..s.particles.fluid)
        .filter(|&a| !s.particles.free_surface[a] && (s.particles.p[a] - interior[a]).abs() > 1e-6);
    assert!(moved.count() > s.particles.fluid / 2, "the interior was not solved for");
}

#[test]
fn young_laplace_adds_sigma_kappa_to_the_extrapolated_value() {
    // The static drop of tests/young_laplace.rs (R = 0.2, σ = 1, Δx = R/10, corrected
    // divergence) from a parabolic pressure, with and without the extrapolation: on the
    // first step the curvature does not depend on it, so the two surface values differ by
    // exactly the extrapolated one.
    let drop = |mode: &str| {
        let v = json!({
            "name": "drop", "dimension": 2, "dx": 0.02,
            "kernel": { "kind": "cubic_spline", "h_over_dx": 1.8 },
            "fluid": { "density": 1.0, "viscosity": 0.5, "surface_tension": 1.0,
                       "surface_tension_model": "young_laplace", "surface_tension_threshold": 0.1 },
            "bodies": [ { "role": "fluid", "shape": { "circle": { "center": [0.0, 0.0], "radius": 0.2 } },
                          "pressure": { "quadratic": { "center": [0.0, 0.0], "value": 5.0,
                                                       "hessian": [[-50.0, 0.0], [0.0, -50.0]] } } } ],
            "scheme": { "isph": { "ppe": { "solver": "cg", "tolerance": 1e-8, "max_iterations": 2000 },
                                  "pressure_gradient": "difference", "divergence": "corrected",
                                  "viscosity": "implicit", "free_surface_pressure": mode } },
            "time": { "end": 0.1, "step": { "adaptive": { "cfl": 0.25, "max": 1e-3 } } }
        });
        Stepper::<2>::new(&Scene::from_json(&v.to_string()).expect("valid scene")).expect("builds")
    };
    let (mut with, mut without) = (drop("extrapolated"), drop("zero"));
    let ctx = with.begin_step().expect("step");
    let extrapolated = with.stage_index("surface_extrapolation").expect("stage built") + 1;
    with.run_stages_before(extrapolated, &ctx).expect("runs");
    let offset = surface_values(&with);
    let yl = with.stage_index("surface_pressure").expect("stage built");
    (extrapolated..=yl).try_for_each(|i| with.run_stage(i, &ctx)).expect("runs");
    let total = surface_values(&with);
    let yl0 = without.stage_index("surface_pressure").expect("stage built");
    without.run_stages_before(yl0 + 1, &ctx).expect("runs");
    let sigma_kappa = surface_values(&without);
    assert!(offset.len() > 30, "{} surface particles", offset.len());
    // p = 5 − 25 r²: ∂p/∂n = 50 r ≈ 10 Pa/m inward at the rim, (Δx/2) ∂p/∂n ≈ 0.1 Pa.
    assert!(offset.iter().any(|&(_, p)| p > 0.05), "{offset:?}");
    for ((a, o), ((b, t), (c, k))) in offset.iter().zip(total.iter().zip(&sigma_kappa)) {
        assert!(a == b && b == c, "the same particles");
        assert!((t - (o + k)).abs() < 1e-12, "particle {a}: {t} against {o} + {k}");
    }
}

#[test]
fn mirror_walls_see_the_surface_values_through_their_mirrors() {
    // The block at rest between mirror walls (x = 0 and 0.2), free above and below, no
    // gravity, from p = ½ H (y − 0.5)²: the surface rows' extrapolated values do not depend
    // on x, div u* = 0, so the solve's interior pressure (harmonic, ∂p/∂n = 0 at the walls)
    // does not either — also next to the walls, where the Laplacian reads the surface
    // values through the mirrors of the surface particles.
    let mut v = block("corrected");
    v["body_force"] = json!([0.0, 0.0]);
    v["bodies"][0]["pressure"] = json!({ "quadratic": { "center": [0.1, 0.5], "value": 0.0, "hessian": [[0.0, 0.0], [0.0, 2000.0]] } });
    v["boundaries"] = json!({ "walls": [ { "axis": 0, "position": 0.0, "fluid_side": "above" },
                                         { "axis": 0, "position": 0.2, "fluid_side": "below" } ] });
    let scene = Scene::from_json(&v.to_string()).expect("valid scene");
    let mut st = Stepper::<2>::new(&scene).expect("builds");
    let ctx = st.begin_step().expect("step");
    let solve = st.stage_index("ppe_solve").expect("stage built");
    st.run_stages_before(solve + 1, &ctx).expect("runs");
    let s = st.state();
    // The top row's value: (Δx/2) H (0.5 − y) ≈ 1 Pa.
    let top: Vec<f64> = surface_values(&st)
        .into_iter()
        .filter(|&(a, _)| s.particles.x[a][1] > 0.1 - DX)
        .map(|(_, p)| p)
        .collect();
    assert!(top.iter().all(|&p| (p - top[0]).abs() < 1e-9 && p > 0.5), "{top:?}");
    for row in 1..19 {
        let y = (row as f64 + 0.5) * DX;
        let p: Vec<f64> = (0..s.particles.fluid)
            .filter(|&a| (s.particles.x[a][1] - y).abs() < 0.25 * DX)
            .map(|a| s.particles.p[a])
            .collect();
        assert_eq!(p.len(), 40, "row {row}");
        let (lo, hi) = p.iter().fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(hi - lo < 1e-6 * top[0], "row {row}: p from {lo} to {hi} Pa");
    }
}
