//! The sharp first test of the projection (NUMERICS.md): for a linear velocity field the
//! first PPE solve must return the analytical pressure of the flow.

mod common;

use serde_json::json;

/// Centre pressure after one step of the drop, relative to p_c = ρ A0² R² / 2.
fn first_solve_error(dx: f64, divergence: &str) -> f64 {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(dx);
        v["time"]["end"] = json!(2e-5);
        v["output"]["probe_every"] = json!(1);
        v["scheme"]["isph"]["divergence"] = json!(divergence);
        v["scheme"]["isph"]["ppe"] = json!({"solver": "cg", "tolerance": 1e-10, "max_iterations": 5000});
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let p = report.probes.get("pressure_at", "p").expect("pressure probe");
    // Exact centre pressure after one step (A barely changes): 4.99958e6 Pa at t = 2e-5 s.
    let reference = meniscus_reference_pc(2e-5);
    (p[p.len() - 1] - reference) / reference
}

/// p_c(t) from the reference crate.
fn meniscus_reference_pc(t: f64) -> f64 {
    let drop =
        meniscus_reference::elliptical_drop::EllipticalDrop::new(1.0, 100.0, 1000.0).expect("valid drop");
    drop.state_at(t).expect("integrates").pc
}

#[test]
fn corrected_divergence_recovers_the_drop_pressure_and_converges() {
    let e04 = first_solve_error(0.04, "corrected");
    let e02 = first_solve_error(0.02, "corrected");
    assert!(e04.abs() < 0.03, "dx = 0.04: {e04}");
    assert!(e02.abs() < 0.01, "dx = 0.02: {e02}");
    assert!(e02.abs() < e04.abs(), "no convergence: {e04} -> {e02}");
}

#[test]
fn standard_divergence_bias_is_documented() {
    // Qiu eq. 10 on the deformed lattice: a dx-independent bias of about −26 % (see
    // docs/notes/divergence-operator.md). If this changes, the note must change with it.
    let e = first_solve_error(0.04, "standard");
    assert!((-0.35..-0.15).contains(&e), "{e}");
}

#[test]
fn solver_probe_reports_the_largest_pressure_of_the_fluid() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["time"]["end"] = json!(1e-4);
        v["output"]["probe_every"] = json!(1);
        v["probes"] = json!([{"solver": {}}]);
    });
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("scene builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let p_max = report.probes.get("solver", "p_max").expect("p_max quantity");
    assert_eq!(p_max.len(), report.probes.t.len());
    let frame = &report.final_frame;
    let largest = frame.p.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    // The same numbers, so the same bits.
    assert_eq!(p_max[p_max.len() - 1].to_bits(), largest.to_bits());
    // The pressure peaks at the centre, p_c ≈ 5e6 Pa (ρ A0² R² / 2), which this scene's
    // Qiu eq. 10 divergence underestimates by about a quarter in the first solves
    // (`standard_divergence_bias_is_documented`): 3.7e6 Pa measured.
    assert!((3.0e6..6.0e6).contains(&largest), "{largest}");
    assert!(p_max.iter().all(|v| v.is_finite() && *v > 0.0), "{p_max:?}");
}

/// The assembled PPE matrix of the deformed drop is symmetric to the bit (each pair
/// coefficient is rounded to the stored `f32` once, the same from both ends), and each row
/// with no free-surface neighbour sums to zero to `f64` rounding: the diagonal is the sum
/// of the rounded coefficients (`linalg::CsrMatrix`).
#[test]
fn assembled_matrix_is_symmetric_with_zero_interior_row_sums() {
    let scene = common::drop_scene(|v| {
        v["dx"] = json!(0.04);
        v["scheme"]["isph"]["divergence"] = json!("corrected");
    });
    let mut stepper = meniscus::profile::Stepper::<2>::new(&scene).expect("scene builds");
    let assemble = stepper.stage_index("ppe_assemble").expect("an ISPH scene assembles a PPE");
    let (checked, interior) = meniscus::profile::on_worker(|| {
        for _ in 0..20 {
            stepper.step_once().expect("stable");
        }
        let ctx = stepper.begin_step().expect("a time step");
        stepper.run_stages_before(assemble + 1, &ctx).expect("stages run");
        let st = stepper.state();
        let own = stepper.simulation().method().own();
        let sys = &own.downcast_ref::<meniscus::isph::IsphData>().expect("an ISPH run").ppe;
        let a = &sys.matrix;
        let entry = |i: usize, j: u32| -> f64 { a.row(i).filter(|&(c, _)| c == j).map(|(_, v)| v).sum() };
        let (mut checked, mut interior) = (0, 0);
        for i in 0..a.n() {
            let mut off = 0.0;
            for (j, v) in a.row(i).skip(1) {
                assert_eq!(v.to_bits(), entry(j as usize, i as u32).to_bits(), "A[{i}][{j}] != A[{j}][{i}]");
                off += v;
                checked += 1;
            }
            let particle = sys.particle_of[i] as usize;
            let all_rows = st.neighbours.of(particle).iter().all(|&b| sys.row_of[b as usize] != u32::MAX);
            if all_rows {
                let d = a.row(i).next().expect("a diagonal").1;
                assert!((d + off).abs() <= 1e-13 * d, "row {i}: diagonal {d}, off-diagonal sum {off}");
                interior += 1;
            }
        }
        (checked, interior)
    });
    assert!(checked > 10_000 && interior > 1_000, "{checked} entries, {interior} interior rows");
}
