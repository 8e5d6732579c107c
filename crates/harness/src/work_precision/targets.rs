//! Derived quantities (Pareto fronts, cost-per-step fits, speed-ups) and the evaluation of
//! the performance issue's targets, from the run rows alone. The targets, fits and
//! speed-ups are the ISPH presets' (the issue's); the other schemes' rows enter the Pareto
//! fronts, one per scheme.

use super::pareto;
use super::record::{CostFit, RunRow, SpeedUp, Target};
use crate::fit::fit_power_law;

/// Thresholds of the performance issue.
pub mod thresholds {
    /// Paper preset at Δx = 0.02 with two threads: wall time \[s\].
    pub const PAPER_WALL_S: f64 = 1.5;
    /// The b error the best run must reach.
    pub const B_ERR: f64 = 0.005;
    /// ... within this wall time \[s\].
    pub const B_ERR_WALL_S: f64 = 1.0;
    /// Finest spacing of the range the cost exponent is judged over (0.04 → 0.005).
    pub const COST_RANGE_FINE: f64 = 0.005;
    /// Largest exponent of cost per step against particle count.
    pub const COST_EXPONENT: f64 = 1.15;
    /// Smallest two-thread speed-up at Δx = 0.01.
    pub const SPEEDUP: f64 = 1.7;
}

/// The presets whose fits and speed-ups are reported.
pub const PRESETS: [&str; 2] = ["paper", "tuned"];

/// The runs with `threads` threads that finished with a finite error, and their
/// (b error, wall time) points.
fn finished(runs: &[RunRow], threads: usize) -> Vec<(&RunRow, (f64, f64))> {
    runs.iter()
        .filter(|r| r.threads == threads && r.ok())
        .filter_map(|r| r.b_err.filter(|e| e.is_finite()).map(|e| (r, (e, r.cost.wall_s))))
        .collect()
}

/// Ids of the Pareto-optimal runs in (b error, wall time) of each scheme among the
/// finished runs with `threads` threads ([`pareto::fronts_by_scheme`]), each scheme's
/// cheapest first.
pub fn pareto_ids(runs: &[RunRow], threads: usize) -> Vec<String> {
    let pts = finished(runs, threads);
    let schemes: Vec<&str> = pts.iter().map(|p| p.0.scheme.as_str()).collect();
    let xy: Vec<(f64, f64)> = pts.iter().map(|p| p.1).collect();
    pareto::fronts_by_scheme(&schemes, &xy).into_iter().map(|i| pts[i].0.id.clone()).collect()
}

/// Cost per step against particle count for each preset, over its finished runs with
/// `threads` threads (one per spacing).
pub fn cost_fits(runs: &[RunRow], threads: usize) -> Vec<CostFit> {
    PRESETS
        .iter()
        .map(|&preset| {
            let mut mine: Vec<&RunRow> = runs
                .iter()
                .filter(|r| r.preset.as_deref() == Some(preset) && r.threads == threads && r.ok())
                .collect();
            mine.sort_by(|a, b| b.dx.total_cmp(&a.dx));
            mine.dedup_by(|a, b| (a.dx - b.dx).abs() < 1e-12);
            let particles: Vec<usize> = mine.iter().map(|r| r.cost.particles).collect();
            let cost: Vec<f64> = mine.iter().filter_map(|r| r.cost.per_step()).collect();
            let n: Vec<f64> = particles.iter().map(|&p| p as f64).collect();
            let fit = if cost.len() == n.len() { fit_power_law(&n, &cost) } else { None };
            CostFit {
                preset: preset.to_string(),
                threads,
                exponent: fit.map(|f| f.order),
                constant: fit.map(|f| f.constant),
                dx: mine.iter().map(|r| r.dx).collect(),
                particles,
                cost_per_step_s: cost,
            }
        })
        .collect()
}

/// One-thread against `threads`-thread wall times of each preset at each spacing where
/// both finished.
pub fn speedups(runs: &[RunRow], threads: usize) -> Vec<SpeedUp> {
    let mut out = Vec::new();
    for preset in PRESETS {
        let mut dxs: Vec<f64> =
            runs.iter().filter(|r| r.preset.as_deref() == Some(preset)).map(|r| r.dx).collect();
        dxs.sort_by(|a, b| b.total_cmp(a));
        dxs.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
        for dx in dxs {
            let one = runs.iter().find(|r| r.is(preset, dx, 1) && r.ok());
            let many = runs.iter().find(|r| r.is(preset, dx, threads) && r.ok());
            if let (Some(one), Some(many)) = (one, many)
                && threads > 1
                && many.cost.wall_s > 0.0
            {
                out.push(SpeedUp {
                    preset: preset.to_string(),
                    dx,
                    particles: many.cost.particles,
                    threads,
                    wall_1_s: one.cost.wall_s,
                    wall_n_s: many.cost.wall_s,
                    speedup: one.cost.wall_s / many.cost.wall_s,
                });
            }
        }
    }
    out
}

fn max_target(name: String, value: Option<f64>, threshold: f64, unit: &str, note: String) -> Target {
    Target {
        name,
        value,
        unit: unit.to_string(),
        kind: "max".into(),
        threshold,
        pass: value.map(|v| v <= threshold),
        note,
    }
}

fn min_target(name: String, value: Option<f64>, threshold: f64, unit: &str, note: String) -> Target {
    Target {
        name,
        value,
        unit: unit.to_string(),
        kind: "min".into(),
        threshold,
        pass: value.map(|v| v >= threshold),
        note,
    }
}

/// Evaluates the targets of the performance issue on the runs (main runs with `threads`
/// threads). `finest_dx` is the finest spacing of the tier (the fit's range).
pub fn evaluate(runs: &[RunRow], threads: usize, finest_dx: f64) -> Vec<Target> {
    use thresholds::*;
    let mut out = Vec::new();

    // 1. Paper preset at Δx = 0.02 within 1.5 s.
    let paper = runs.iter().find(|r| r.is("paper", 0.02, threads));
    out.push(max_target(
        format!("paper preset, Δx = 0.02, wall time with {threads} threads ≤ {PAPER_WALL_S} s"),
        paper.filter(|r| r.ok()).map(|r| r.cost.wall_s),
        PAPER_WALL_S,
        "s",
        match paper {
            Some(r) if r.ok() => {
                format!(
                    "{} steps, {:.2} ms per step",
                    r.cost.steps,
                    1e3 * r.cost.wall_s / r.cost.steps as f64
                )
            }
            Some(r) => format!("the run did not finish: {}", r.status),
            None => "not run".into(),
        },
    ));

    // 2. The fastest ISPH run reaching b error ≤ 0.5 % takes ≤ 1 s (the issue is about the
    // ISPH solver: another scheme's run does not meet it for ISPH).
    let best = finished(runs, threads)
        .into_iter()
        .filter(|(r, (e, _))| r.scheme == "isph" && *e <= B_ERR)
        .min_by(|a, b| a.1.1.total_cmp(&b.1.1).then(a.1.0.total_cmp(&b.1.0)));
    let mut t = max_target(
        format!(
            "fastest ISPH run with b error ≤ {} % at t = 0.008 s: wall time ≤ {B_ERR_WALL_S} s",
            B_ERR * 100.0
        ),
        best.map(|(r, _)| r.cost.wall_s),
        B_ERR_WALL_S,
        "s",
        match best {
            Some((r, (e, _))) => format!("{} (b error {})", r.id, crate::numbers::percent(e)),
            None => format!("no ISPH run reached b error ≤ {} %", B_ERR * 100.0),
        },
    );
    t.pass = Some(t.pass == Some(true));
    out.push(t);

    // 3. Cost per step grows at most like N^1.15.
    let range = format!("Δx 0.04 → {finest_dx}");
    let issue_range = if finest_dx > COST_RANGE_FINE + 1e-12 {
        "; not judged: the issue's range 0.04 → 0.005 needs --full"
    } else {
        ""
    };
    for fit in cost_fits(runs, threads) {
        let note = match (fit.exponent, fit.dx.first(), fit.dx.last()) {
            (Some(_), Some(&coarse), Some(&fine)) => {
                // A spacing of the tier that diverged is not in the fit: say so, and what
                // the fit would be with that run's cost per step over the steps it took.
                let missing = if fine > finest_dx + 1e-12 {
                    let stopped = runs.iter().find(|r| r.is(&fit.preset, finest_dx, threads) && !r.ok());
                    match stopped.and_then(|r| r.cost.per_step().map(|c| (r, c))) {
                        Some((r, c)) => {
                            let mut n: Vec<f64> = fit.particles.iter().map(|&p| p as f64).collect();
                            let mut cost = fit.cost_per_step_s.clone();
                            n.push(r.cost.particles as f64);
                            cost.push(c);
                            let with = fit_power_law(&n, &cost).map_or(String::new(), |f| {
                                format!("; with its cost per step over them, {:.3}", f.order)
                            });
                            format!(
                                "; Δx = {finest_dx} did not finish: it stopped after {} steps{with}",
                                r.cost.steps
                            )
                        }
                        None => format!("; Δx = {finest_dx} did not finish"),
                    }
                } else {
                    String::new()
                };
                format!(
                    "least squares in log-log over {} spacings (Δx {coarse} → {fine}{missing}{issue_range}), \
                     {threads} threads",
                    fit.dx.len()
                )
            }
            _ => format!("fewer than two finished spacings ({range})"),
        };
        let mut t = max_target(
            format!("cost-per-step exponent vs particles ≤ {COST_EXPONENT} ({} preset)", fit.preset),
            fit.exponent,
            COST_EXPONENT,
            "",
            note,
        );
        // The issue asked for the range 0.04 → 0.005: a fit over less is no verdict when
        // the tier does not reach 0.005, and a failure when it does (a run did not finish).
        let covers = fit.dx.first().is_some_and(|&d| d >= 0.04 - 1e-12)
            && fit.dx.last().is_some_and(|&d| d <= COST_RANGE_FINE + 1e-12);
        if !covers {
            t.pass = if finest_dx > COST_RANGE_FINE + 1e-12 { None } else { Some(false) };
        }
        out.push(t);
    }

    // 4. Two-thread speed-up at Δx = 0.01.
    let ups = speedups(runs, threads);
    for preset in PRESETS {
        let up = ups.iter().find(|s| s.preset == preset && (s.dx - 0.01).abs() < 1e-12);
        out.push(min_target(
            format!("speed-up 1 → {threads} threads at Δx = 0.01 ≥ {SPEEDUP} ({preset} preset)"),
            up.map(|s| s.speedup),
            SPEEDUP,
            "×",
            match up {
                Some(s) => format!("{:.2} s with 1 thread, {:.2} s with {threads}", s.wall_1_s, s.wall_n_s),
                None if finest_dx > 0.01 + 1e-12 => "Δx = 0.01 is not in this tier".into(),
                None => "a run of the pair is missing or did not finish".into(),
            },
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::work_precision::design::Variant;
    use crate::work_precision::record::Cost;

    fn row(preset: Option<Variant>, dx: f64, threads: usize, wall_s: f64, b_err: Option<f64>) -> RunRow {
        let variant = preset.unwrap_or(Variant { dt: super::super::design::Dt::Adaptive, ..Variant::PAPER });
        let particles = (1976.0 * (0.04 / dx) * (0.04 / dx)) as usize;
        RunRow {
            id: format!("dx{dx}_t{threads}_{}", variant.label().replace(' ', "-")),
            dx,
            scheme: "isph".into(),
            variant: Some(variant),
            preset: variant.preset().map(str::to_string),
            expected_divergence: None,
            threads,
            groups: vec![],
            cost: Cost {
                particles,
                steps: 400,
                t_end: 0.008,
                wall_s,
                ppe_iterations_mean: 10.0,
                ..Cost::default()
            },
            b_err,
            b_err_max: b_err,
            a_err: b_err,
            status: if b_err.is_some() { "ok".into() } else { "diverged: guard at step 3".into() },
            reused: false,
        }
    }

    #[test]
    fn targets_pass_and_fail() {
        let p = Some(Variant::PAPER);
        let t = Some(Variant::TUNED);
        // Paper cost per step ∝ N (exponent 1); tuned ∝ N^1.5.
        let mut runs = vec![
            row(p, 0.04, 2, 0.4, Some(0.007)),
            row(p, 0.02, 2, 1.6, Some(0.003)),
            row(p, 0.01, 2, 6.4, Some(0.008)),
            row(t, 0.04, 2, 0.4, Some(0.004)),
            row(t, 0.02, 2, 0.4 * 8.0, Some(0.002)),
            row(t, 0.01, 2, 0.4 * 64.0, Some(0.001)),
            row(p, 0.01, 1, 12.0, Some(0.008)),
            row(t, 0.01, 1, 0.4 * 64.0 * 1.5, Some(0.001)),
            row(None, 0.04, 2, 0.1, None),
        ];
        let ts = evaluate(&runs, 2, 0.01);
        assert_eq!(ts.len(), 6);
        assert_eq!((ts[0].value, ts[0].pass), (Some(1.6), Some(false)));
        // Fastest run under 0.5 %: tuned at 0.04 (0.4 s), not the diverged one.
        assert_eq!((ts[1].value, ts[1].pass), (Some(0.4), Some(true)));
        assert!(ts[1].note.contains("dx0.04_t2_cg_two_level_1e-3-sym-corr-fickian-fixed"), "{}", ts[1].note);
        // Exponents measured over 0.04 → 0.01, but not judged: the range asked is → 0.005.
        assert!((ts[2].value.unwrap() - 1.0).abs() < 1e-2, "{:?}", ts[2]);
        assert_eq!(ts[2].pass, None);
        assert!((ts[3].value.unwrap() - 1.5).abs() < 1e-2, "{:?}", ts[3]);
        assert_eq!(ts[3].pass, None);
        assert!(ts[3].note.contains("not judged") && ts[3].note.contains("needs --full"));
        assert!((ts[4].value.unwrap() - 12.0 / 6.4).abs() < 1e-12);
        assert_eq!(ts[4].pass, Some(true));
        assert!((ts[5].value.unwrap() - 1.5).abs() < 1e-12);
        assert_eq!(ts[5].pass, Some(false));

        // Nothing reaches 0.5 %, the paper run at 0.02 diverged, no 0.01 runs (quick).
        runs.retain(|r| r.dx > 0.015);
        for r in &mut runs {
            if r.b_err.is_some() {
                r.b_err = Some(0.02);
            }
        }
        runs[1].status = "diverged: ppe_solve".into();
        let ts = evaluate(&runs, 2, 0.02);
        assert_eq!((ts[0].value, ts[0].pass), (None, None));
        assert!(ts[0].note.contains("did not finish"));
        assert_eq!((ts[1].value, ts[1].pass), (None, Some(false)), "no run reaching 0.5 % is a fail");
        assert_eq!(ts[4].pass, None);
        assert!(ts[4].note.contains("not in this tier"));
    }

    /// The cost exponent is judged over 0.04 → 0.005 only: a finest run that did not
    /// finish is a failure, not a fit over what is left.
    #[test]
    fn the_cost_exponent_needs_the_whole_range() {
        let p = Some(Variant::PAPER);
        let mut runs: Vec<RunRow> = [(0.04, 0.4), (0.02, 1.6), (0.01, 6.4), (0.005, 25.6)]
            .map(|(dx, s)| row(p, dx, 2, s, Some(0.004)))
            .into();
        let ts = evaluate(&runs, 2, 0.005);
        assert!((ts[2].value.unwrap() - 1.0).abs() < 1e-2, "{:?}", ts[2]);
        assert_eq!(ts[2].pass, Some(true));
        runs[3].status = "diverged: guard at step 870".into();
        let ts = evaluate(&runs, 2, 0.005);
        assert!((ts[2].value.unwrap() - 1.0).abs() < 1e-2, "still measured over three: {:?}", ts[2]);
        assert_eq!(ts[2].pass, Some(false), "{}", ts[2].note);
    }

    /// The fit's note names the spacings it covers, and a finest spacing that diverged.
    #[test]
    fn the_cost_fit_says_which_spacings_it_covers() {
        let p = Some(Variant::PAPER);
        let mut runs = vec![
            row(p, 0.04, 2, 0.4, Some(0.007)),
            row(p, 0.02, 2, 1.6, Some(0.003)),
            row(p, 0.01, 2, 6.4, Some(0.008)),
        ];
        runs[2].status = "diverged: guard at step 870".into();
        runs[2].cost.steps = 200;
        let ts = evaluate(&runs, 2, 0.01);
        assert!((ts[2].value.unwrap() - 1.0).abs() < 1e-2, "{:?}", ts[2]);
        assert!(
            ts[2].note.contains(
                "over 2 spacings (Δx 0.04 → 0.02; Δx = 0.01 did not finish: it stopped after 200 steps"
            ),
            "{}",
            ts[2].note
        );
        // 6.4 s over 200 steps is twice the cost per step of a linear law: exponent 1.25 with it.
        let with: f64 =
            ts[2].note.split("with its cost per step over them, ").nth(1).unwrap()[..5].parse().unwrap();
        assert!(with > 1.1 && with < 1.4, "{}", ts[2].note);
    }

    /// Another scheme's rows have their own Pareto front and meet no ISPH target.
    #[test]
    fn other_schemes_have_their_own_front_and_no_target() {
        let p = Some(Variant::PAPER);
        let mut mps = row(None, 0.04, 2, 0.05, Some(0.001));
        (mps.id, mps.scheme, mps.variant, mps.preset) =
            ("dx0.04_t2_mps-mps".into(), "mps".into(), None, Some("mps".into()));
        let runs = vec![row(p, 0.04, 2, 0.5, Some(0.004)), row(p, 0.02, 2, 2.0, Some(0.003)), mps];
        // The MPS run dominates both ISPH runs, which stay on the ISPH front.
        assert_eq!(pareto_ids(&runs, 2), vec![runs[0].id.clone(), runs[1].id.clone(), runs[2].id.clone()]);
        let ts = evaluate(&runs, 2, 0.02);
        assert_eq!(ts[1].value, Some(0.5), "the fastest ISPH run under 0.5 %: {}", ts[1].note);
        assert_eq!(ts.len(), 6, "no target for the other scheme");
    }

    #[test]
    fn pareto_and_speedups() {
        let p = Some(Variant::PAPER);
        let runs = vec![
            row(p, 0.04, 2, 0.5, Some(0.01)),
            row(p, 0.02, 2, 2.0, Some(0.004)),
            row(None, 0.02, 2, 1.0, Some(0.02)),
            row(None, 0.01, 2, 3.0, Some(0.005)),
            row(p, 0.02, 1, 3.0, Some(0.004)),
        ];
        assert_eq!(pareto_ids(&runs, 2), vec![runs[0].id.clone(), runs[1].id.clone()]);
        let ups = speedups(&runs, 2);
        assert_eq!(ups.len(), 1);
        assert!((ups[0].speedup - 1.5).abs() < 1e-12);
        assert!(speedups(&runs, 1).is_empty());
    }
}
