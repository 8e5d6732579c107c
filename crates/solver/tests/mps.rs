//! The MPS scheme (MPS.md): its scene rules, its wall particles, its particle count, and
//! results that do not depend on the thread count.

mod common;

use meniscus::profile::Stepper;
use meniscus::{Scene, SceneError};
use serde_json::{Value, json};

/// MPS options as the cases use them (Lan's weight and radii, γ = 0.01).
fn mps() -> Value {
    json!({"gamma": 0.01, "ppe": {"solver": "cg", "tolerance": 1e-6, "max_iterations": 2000}})
}

/// The periodic channel (Re 40, D/36) with MPS, edited by `edit`.
fn channel(edit: impl FnOnce(&mut Value)) -> Scene {
    common::periodic_channel_scene(|v| {
        v["scheme"] = json!({"mps": mps()});
        v["output"] = json!({"probe_every": 10});
        edit(v);
    })
}

fn error_of(edit: impl FnOnce(&mut Value)) -> SceneError {
    let mut v: Value = serde_json::from_str(common::DROP).expect("scene JSON");
    v["scheme"] = json!({"mps": mps()});
    edit(&mut v);
    Scene::from_json(&v.to_string()).expect_err("scene should be rejected")
}

/// Every bad MPS input names its field: a radius below l0, γ outside [0, 1], options of
/// another scheme inside `mps` (and MPS options inside `isph` or `wcsph`), the physics and
/// boundaries MPS does not have.
#[test]
fn bad_mps_input_names_the_field() {
    type Edit = Box<dyn FnOnce(&mut Value)>;
    let radii = |l: f64| json!({"number_density": 2.1, "gradient": 2.1, "laplacian": l});
    let cases: Vec<(&str, Edit)> = vec![
        ("scheme.mps.gamma", Box::new(|v| v["scheme"]["mps"]["gamma"] = json!(1.5))),
        ("scheme.mps.gamma", Box::new(|v| v["scheme"]["mps"]["gamma"] = json!(-0.01))),
        ("scheme.mps.radii.laplacian", Box::new(move |v| v["scheme"]["mps"]["radii"] = radii(0.9))),
        ("scheme.mps.radii.laplacian", Box::new(move |v| v["scheme"]["mps"]["radii"] = radii(1.0))),
        ("scheme.mps.compressibility", Box::new(|v| v["scheme"]["mps"]["compressibility"] = json!(-1e-9))),
        (
            "scheme.mps.free_surface.beta",
            Box::new(|v| v["scheme"]["mps"]["free_surface"]["beta"] = json!(1.2)),
        ),
        ("scheme.mps.ppe.tolerance", Box::new(|v| v["scheme"]["mps"]["ppe"]["tolerance"] = json!(0.0))),
        (
            "scheme.mps.shifting.xu.coefficient",
            Box::new(|v| v["scheme"]["mps"]["shifting"] = json!({"xu": {"coefficient": 2.0}})),
        ),
        // An ISPH option inside `mps`, and MPS options inside `isph` and `wcsph`.
        ("free_surface_threshold", Box::new(|v| v["scheme"]["mps"]["free_surface_threshold"] = json!(1.5))),
        (
            "gamma",
            Box::new(|v| {
                v["scheme"] = json!({"isph": {"ppe": {"solver": "cg", "tolerance": 1e-3, "max_iterations": 100},
                                              "free_surface_threshold": 1.5, "gamma": 0.01}})
            }),
        ),
        (
            "radii",
            Box::new(move |v| v["scheme"] = json!({"wcsph": {"sound_speed": 100.0, "radii": radii(4.1)}})),
        ),
        ("fluid.surface_tension", Box::new(|v| v["fluid"]["surface_tension"] = json!(0.07))),
    ];
    for (field, edit) in cases {
        let msg = error_of(edit).to_string();
        assert!(msg.contains(field), "message `{msg}` does not name `{field}`");
    }
    let dummy =
        common::periodic_channel_scene(|v| v["scheme"] = json!({"isph": v["scheme"]["isph"].clone()}));
    assert!(dummy.boundaries.walls.len() == 2);
    let mut v: Value = serde_json::to_value(&dummy).expect("serialisable");
    v["scheme"] = json!({"mps": mps()});
    v["boundaries"]["wall_model"] = json!("dummy");
    let msg = Scene::from_json(&v.to_string()).expect_err("dummy walls with mps").to_string();
    assert!(msg.contains("boundaries.wall_model"), "{msg}");
}

/// The wall layers cover the Laplacian radius behind each wall (four layers for 4.1 l0,
/// three for the classic 3.1), and the number of particles never changes in a periodic
/// channel: asserted after every step.
#[test]
fn wall_layers_cover_the_laplacian_and_the_count_is_kept() {
    for (weight, layers) in [("lan", 4), ("classic", 3)] {
        let scene = channel(|v| {
            v["scheme"]["mps"]["weight"] = json!(weight);
            v["time"]["end"] = json!(200.0);
        });
        let mut stepper = Stepper::<2>::new(&scene).expect("builds");
        let (fluid, total) = (stepper.state().particles.fluid, stepper.state().particles.total());
        // 18 columns in the period, `layers` rows behind each of the two walls.
        assert_eq!(total - fluid, 2 * 18 * layers, "{weight}");
        for _ in 0..40 {
            stepper.step_once().expect("steps");
            let p = &stepper.state().particles;
            assert_eq!((p.fluid, p.total()), (fluid, total), "{weight}: particle count changed");
        }
    }
}

/// MPS gives bit-identical probes and frames with one and two threads, with walls and
/// shifting (the periodic channel) and with a free surface (the drop).
#[test]
fn mps_is_thread_independent() {
    let run = |scene: &Scene, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().expect("pool");
        pool.install(|| meniscus::run(scene, &mut meniscus::Quiet).expect("scene builds"))
    };
    let channel = channel(|v| {
        v["scheme"]["mps"]["shifting"] = json!({"xu": {"coefficient": 0.02}});
        v["scheme"]["mps"]["ppe"]["preconditioner"] = json!("two_level");
        v["time"]["end"] = json!(2000.0);
    });
    let drop = common::drop_scene(|v| {
        v["dx"] = json!(0.05);
        v["time"]["end"] = json!(1e-3);
        v["scheme"] = json!({"mps": {"weight": "classic", "gamma": 0.01, "divergence": "corrected",
                                     "pressure_gradient": "minimum", "clip_negative_pressure": true,
                                     "ppe": {"solver": "cg", "tolerance": 1e-3, "max_iterations": 500}}});
        v["probes"] = json!([{"ellipse_axes": {}}, {"pressure_at": {"point": [0.0, 0.0]}}, {"solver": {}}]);
    });
    for scene in [channel, drop] {
        let (a, b) = (run(&scene, 1), run(&scene, 2));
        assert!(a.error.is_none() && b.error.is_none(), "{:?}", a.error);
        let json = |r: &meniscus::RunReport| serde_json::to_string(&r.probes).expect("serialisable");
        assert_eq!(json(&a), json(&b), "{}: probes differ between 1 and 2 threads", scene.name);
        assert_eq!(a.final_frame, b.final_frame);
    }
}

/// Lan's open channel (a 2 D × D channel at `rows` rows, Re 40, a plug at U at the start)
/// with the stabilised MPS options of the `poiseuille_channel` case; periodic across
/// instead of walled when `walls` is false.
fn open_channel(rows: usize, walls: bool, end: f64) -> Scene {
    open_channel_at(rows, walls, end, 2e-4)
}

/// As [`open_channel`] at inflow speed `u` \[m/s\] (Re = 200 u / (m/s)).
fn open_channel_at(rows: usize, walls: bool, end: f64, u: f64) -> Scene {
    open_channel_of(2.0, rows, walls, end, u)
}

/// As [`open_channel_at`], `length` channel widths long.
fn open_channel_of(length: f64, rows: usize, walls: bool, end: f64, u: f64) -> Scene {
    let d = 0.2;
    let dx = d / rows as f64;
    let mut boundaries = json!({
        "inflow": {"axis": 0, "position": 0.0, "velocity": u},
        "outflow": {"axis": 0, "position": length * d}
    });
    if walls {
        boundaries["walls"] = json!([{"axis": 1, "position": 0.0, "fluid_side": "above"},
                                     {"axis": 1, "position": d, "fluid_side": "below"}]);
    } else {
        boundaries["periodic"] = json!([{"axis": 1, "min": 0.0, "max": d}]);
    }
    let v = json!({
        "name": "open", "dimension": 2, "dx": dx,
        "kernel": {"kind": "cubic_spline", "h_over_dx": 1.5},
        "fluid": {"density": 1000.0, "viscosity": 1e-3},
        "bodies": [{"role": "fluid", "shape": {"rectangle": {"min": [0.0, 0.0], "max": [length * d, d]}},
                    "velocity": {"affine": {"gradient": [[0.0, 0.0], [0.0, 0.0]], "offset": [u, 0.0]}}}],
        "boundaries": boundaries,
        "scheme": {"mps": {"weight": "classic", "gamma": 0.01, "divergence": "corrected",
                           "pressure_gradient": "minimum", "clip_negative_pressure": true,
                           "shifting": {"xu": {"coefficient": 0.02}},
                           "ppe": {"solver": "cg", "tolerance": 1e-6, "max_iterations": 2000}}},
        "time": {"end": end, "step": {"adaptive": {"cfl": 0.2, "viscous": 0.2, "max": 0.2 * dx / u}}},
        "probes": [{"mass_balance": {}}],
        "output": {"probe_every": 1}
    });
    Scene::from_json(&v.to_string()).expect("valid scene")
}

/// The pressure spans the channel at Re = 4, where the Poiseuille drop is large (12 L/(Re D)
/// = 45 ρU² over the case's 15 D): over U t/D = 1 the outlet passes what the plate pushes
/// in, to one column (measured 2026-12-06: in 12.0 columns, out 11.8). With the type-2
/// walls in the PPE at their extrapolated pressures of the step before (Dirichlet values a
/// step behind), the pressure built up over many steps instead of at once: in 11.0, out 4.8,
/// and the full-tier channel at Re 4 compressed until its ghost reserve ran out
/// (docs/notes/mps.md).
#[test]
fn the_outlet_keeps_pace_with_the_plate_at_low_reynolds_number() {
    let (rows, d, u) = (12, 0.2, 2e-5);
    let mut scene = open_channel_of(15.0, rows, true, d / u, u);
    let meniscus::scene::Scheme::Mps(opts) = &mut scene.scheme else { unreachable!("an MPS scene") };
    opts.viscosity = meniscus::scene::ViscousIntegration::Implicit;
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let balance = &report.probes.series["mass_balance"];
    let column = 1000.0 * (d / rows as f64).powi(2) * rows as f64;
    let (inflow, outflow) = (balance["inflow"].last().unwrap(), balance["outflow"].last().unwrap());
    assert!(*inflow >= 11.0 * column, "the plate pushed {:.1} columns in", inflow / column);
    assert!(
        (inflow - outflow).abs() <= column,
        "in {:.1} columns, out {:.1}",
        inflow / column,
        outflow / column
    );
}

/// The pushing plate and the outlet change the fluid only through the boundaries: after
/// every step, fluid plus ghosts is the starting count, the fluid count is the start plus
/// the columns that entered minus the particles that left (the mass-balance fluxes), the
/// plate and wall particles keep their number, and the plate stays within one stroke of
/// its start. Over a flow-through of half the channel both planes have passed particles.
#[test]
fn the_open_channel_conserves_the_particle_count() {
    let rows = 12;
    let scene = open_channel(rows, true, 0.5 * 0.4 / 2e-4);
    let mut stepper = Stepper::<2>::new(&scene).expect("builds");
    let (fluid0, total0) = (stepper.state().particles.fluid, stepper.state().particles.total());
    let (ghosts0, plate) = (own(&stepper).ghosts.len(), own(&stepper).plate);
    assert_eq!(plate.rows, rows);
    assert_eq!(
        plate.type1 + plate.type2,
        3 * rows,
        "three plate columns for the classic Laplacian radius 3.1 l0"
    );
    let front0 = stepper.state().particles.x[fluid0][0];
    let mass = 1000.0 * (0.2 / rows as f64).powi(2);
    while stepper.time() < scene.time.end {
        stepper.step_once().expect("steps");
        let s = stepper.state();
        let (fluid, ghosts) = (s.particles.fluid, own(&stepper).ghosts.len());
        assert_eq!(
            fluid + ghosts,
            fluid0 + ghosts0,
            "a particle was lost or created at step {}",
            stepper.steps()
        );
        let through = ((s.flux.inflow - s.flux.outflow) / mass).round() as i64;
        assert_eq!(
            fluid as i64 - fluid0 as i64,
            through,
            "step {}: fluid count against the fluxes",
            stepper.steps()
        );
        assert_eq!(
            s.particles.total() - fluid,
            total0 - fluid0,
            "boundary particles at step {}",
            stepper.steps()
        );
        let front = s.particles.x[fluid][0];
        assert!(front >= front0 - 1e-12 && front < front0 + 0.2 / rows as f64, "plate front at {front}");
    }
    let flux = stepper.state().flux;
    assert!(flux.inflow > 0.4 * 1000.0 * 2e-4 * 0.2 * scene.time.end, "inflow {}", flux.inflow);
    assert!(flux.outflow > 0.4 * 1000.0 * 2e-4 * 0.2 * scene.time.end, "outflow {}", flux.outflow);
}

/// The MPS scheme's own data of a run.
fn own(st: &Stepper<2>) -> &meniscus::mps::MpsData<2> {
    st.simulation().method().own().downcast_ref().expect("an MPS run")
}

/// Without walls (periodic across) a plug at U stays a plug through the pushing plate and
/// the outlet: the plate and the entering columns continue the lattice, so no particle is
/// pushed off U (within 1e-6 U over a flow-through; an entering column misplaced by 0.2 l0
/// kicks the plug by 6 % of U).
#[test]
fn a_plug_stays_a_plug_through_the_open_channel() {
    let scene = open_channel(10, false, 0.4 / 2e-4);
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let f = &report.final_frame;
    let worst = f.u.iter().map(|u| ((u[0] - 2e-4).abs()).max(u[1].abs())).fold(0.0, f64::max);
    assert!(worst < 1e-6 * 2e-4, "largest departure from the plug {worst:e} m/s");
    assert!(f.x.iter().all(|x| (0.0..0.4).contains(&x[0])), "every fluid particle in the channel");
}

/// The implicit viscous predictor solves backward Euler with the explicit predictor's
/// Laplacian, fluid, wall images and plate alike: after it, on the walled open channel,
/// `u* − Δt ν ⟨∇²u*⟩ = uⁿ + Δt g` holds for every fluid particle with `⟨∇²⟩` evaluated by
/// `mps::viscosity::Terms` (within 1e-6 of the viscous change, which the walls and the
/// plate make a sizeable part of U in the first step).
#[test]
fn the_implicit_predictor_solves_backward_euler() {
    use meniscus::mps::{operators::Operators, viscosity::Terms, walls::Mirror, weight::Classic};
    let mut scene = open_channel(12, true, 1.0);
    let meniscus::scene::Scheme::Mps(opts) = &mut scene.scheme else { unreachable!("an MPS scene") };
    opts.viscosity = meniscus::scene::ViscousIntegration::Implicit;
    let (radii, nu) = (opts.radii(), scene.fluid.viscosity / scene.fluid.density);
    let mut stepper = Stepper::<2>::new(&scene).expect("builds");
    let ctx = stepper.begin_step().expect("a step");
    let end = stepper.stage_index("predictor_implicit").expect("the implicit predictor") + 1;
    stepper.run_stages_before(end, &ctx).expect("runs");
    let (s, own) = (stepper.state(), own(&stepper));
    let ops = Operators::<Classic, 2>::new(radii, scene.dx);
    let mirror = Mirror::new(&scene.boundaries.walls);
    let terms = Terms {
        ops: &ops,
        mirror: &mirror,
        list: &s.neighbours,
        x: &s.particles.x_old,
        fluid: s.particles.fluid,
        plate: own.plate,
        type1: own.type1,
        domain: s.domain,
    };
    let (u, u_old) = (&s.particles.u, &s.particles.u_old);
    let (mut worst, mut change) = (0.0_f64, 0.0_f64);
    for i in 0..s.particles.fluid {
        let viscous = terms.laplacian(i, u) * (ctx.dt * nu);
        worst = worst.max((u[i] - viscous - u_old[i]).norm());
        change = change.max(viscous.norm());
    }
    assert!(change > 0.05 * 2e-4, "the viscous change is a sizeable part of U: {change:e} m/s");
    assert!(worst < 1e-6 * change, "backward-Euler residual {worst:e} m/s against a change of {change:e}");
}

/// Implicit viscosity at six times the explicit viscous limit follows the explicit run: the
/// periodic channel's start-up (Re 4, D/36, from rest, the classic weight) at
/// t = 0.05 D²/ν: the streamwise velocity profile (12 slabs) within 0.5 % of the largest
/// velocity (measured 2026-12-06 at Δt 23 s against the explicit 3.77 s: 0.26 %). Single
/// particles differ by more (1.9 % at equal steps): particle-level noise of the projection.
#[test]
fn implicit_viscosity_follows_the_explicit_start_up() {
    let run = |implicit: bool| {
        let scene = channel(|v| {
            v["body_force"] = json!([6e-9, 0.0]);
            v["scheme"]["mps"]["weight"] = json!("classic");
            if implicit {
                v["scheme"]["mps"]["viscosity"] = json!("implicit");
                v["time"]["step"] = json!({"fixed": 23.0});
            }
            v["time"]["end"] = json!(2000.0);
        });
        let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("builds");
        assert!(report.error.is_none(), "{:?}", report.error);
        report.final_frame
    };
    let (explicit, implicit) = (run(false), run(true));
    assert!(explicit.step > 5 * implicit.step, "steps {} and {}", explicit.step, implicit.step);
    // The streamwise velocity profile: means over 12 slabs across the channel (D = 0.2 m).
    let profile = |f: &meniscus::Frame| {
        let mut bins = [(0.0, 0.0); 12];
        for (x, u) in f.x.iter().zip(&f.u) {
            let b = &mut bins[((x[1] / 0.2 * 12.0) as usize).min(11)];
            *b = (b.0 + u[0], b.1 + 1.0);
        }
        bins.map(|(sum, n)| sum / n)
    };
    let (a, b) = (profile(&explicit), profile(&implicit));
    let top = a.iter().copied().fold(0.0, f64::max);
    let worst = a.iter().zip(&b).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(top > 0.0 && worst < 5e-3 * top, "profiles differ by {:.3} % of u_max", 100.0 * worst / top);
}

/// At Re = 4 the inlet's pressure is several times the dynamic pressure (12 L/(Re D) = 6
/// for the Poiseuille drop over 2 D), and the channel still holds its fluid between the
/// walls: to U t/D = 1 (implicit viscosity) every fluid particle stays inside the channel
/// and the fluid mass within 1 % (measured 2026-12-06: +0.69 %). With the walls beside the
/// plate read as surface (the void behind it), P = 0 was pinned next to the inlet corner
/// and the same run gained 2.78 % (the full-tier Re 40 channel diverged there).
#[test]
fn the_inlet_corners_hold_at_low_reynolds_number() {
    let (d, u) = (0.2, 2e-5);
    let mut scene = open_channel_at(12, true, d / u, u);
    let meniscus::scene::Scheme::Mps(opts) = &mut scene.scheme else { unreachable!("an MPS scene") };
    opts.viscosity = meniscus::scene::ViscousIntegration::Implicit;
    let report = meniscus::run(&scene, &mut meniscus::Quiet).expect("builds");
    assert!(report.error.is_none(), "{:?}", report.error);
    let f = &report.final_frame;
    assert!(f.x.iter().all(|x| x[1] > 0.0 && x[1] < d && x[0] > -0.01 * d), "a particle left through a wall");
    let mass = f.x.len() as f64 / (2.0 * 12.0 * 12.0) - 1.0;
    assert!(mass.abs() < 0.01, "fluid mass changed by {:.2} %", 100.0 * mass);
}
