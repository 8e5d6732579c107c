//! The cost per particle-step of each scheme's presets on each case of the study, and its
//! ratio to the performance floor of `NUMERICS.md`
//! ([`FLOOR_CORE_US_PER_PARTICLE_PASS`]: one fused pair pass, about 2.2 ns per pair, takes
//! 0.42 ms over the drop's 7860 particles at Δx = 0.02 on two threads, 0.107 core-µs per
//! particle). The cost is a run's CPU time over its particles × steps, so it compares
//! schemes whose step counts and particle counts differ; the ratio is how many such pair
//! passes a step is worth.

use super::record::{Cost, SchemeCost, SpacingCost, Study};
use crate::results::{FLOOR_CORE_US_PER_PARTICLE_PASS, core_us_per_particle_step};

/// The schemes in the order the table lists them (another scheme after them).
const SCHEMES: [&str; 3] = ["isph", "wcsph", "mps"];

/// A finished run of a named series.
struct Point<'a> {
    scheme: &'a str,
    series: String,
    dx: f64,
    cost: &'a Cost,
}

/// The cost per particle-step of each named series of the drop (its presets: `paper`,
/// `tuned`, `wcsph_tuned`, `mps`) and of the channel (`re4`, `re4_implicit`, the MPS
/// point), over their finished runs with the study's main thread count: the drop's first,
/// each case's by scheme (`SCHEMES`) and then in the order run.
pub fn scheme_costs(study: &Study) -> Vec<SchemeCost> {
    let main = |ok: bool, threads: usize| ok && threads == study.threads;
    let drop = study.runs.iter().filter(|r| main(r.ok(), r.threads)).filter_map(|r| {
        Some(Point { scheme: &r.scheme, series: r.preset.clone()?, dx: r.dx, cost: &r.cost })
    });
    let mut out = by_series(&study.case, study.threads, drop.collect());
    if let Some(c) = &study.channel {
        let channel =
            c.runs.iter().filter(|r| main(r.ok(), r.threads)).filter_map(|r| {
                Some(Point { scheme: &r.scheme, series: r.series()?, dx: r.dx, cost: &r.cost })
            });
        out.extend(by_series(&c.case, study.threads, channel.collect()));
    }
    out
}

/// One [`SchemeCost`] per series of `points`, its spacings coarse to fine.
fn by_series(case: &str, threads: usize, mut points: Vec<Point>) -> Vec<SchemeCost> {
    points.sort_by(|a, b| b.dx.total_cmp(&a.dx));
    let mut series: Vec<(&str, &str)> = Vec::new();
    for p in &points {
        if !series.contains(&(p.scheme, p.series.as_str())) {
            series.push((p.scheme, p.series.as_str()));
        }
    }
    series.sort_by_key(|(scheme, _)| SCHEMES.iter().position(|s| s == scheme).unwrap_or(SCHEMES.len()));
    series
        .into_iter()
        .map(|(scheme, name)| {
            let mine: Vec<&Point> =
                points.iter().filter(|p| p.scheme == scheme && p.series == name).collect();
            let cpu_s: Option<f64> = mine.iter().map(|p| p.cost.cpu_s).sum();
            let particle_steps: f64 = mine.iter().map(|p| (p.cost.particles * p.cost.steps) as f64).sum();
            let core = core_us_per_particle_step(cpu_s, particle_steps);
            SchemeCost {
                case: case.to_string(),
                scheme: scheme.to_string(),
                series: name.to_string(),
                threads,
                spacings: mine
                    .iter()
                    .map(|p| SpacingCost {
                        dx: p.dx,
                        particles: p.cost.particles,
                        steps: p.cost.steps,
                        cpu_s: p.cost.cpu_s,
                        core_us_per_particle_step: p.cost.core_us_per_particle_step(),
                        floor_ratio: p.cost.floor_ratio(),
                    })
                    .collect(),
                core_us_per_particle_step: core,
                floor_ratio: core.map(|c| c / FLOOR_CORE_US_PER_PARTICLE_PASS),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::work_precision::channel::{ChannelRow, ChannelStudy, ChannelVariant};
    use crate::work_precision::design::Variant;
    use crate::work_precision::record::RunRow;

    fn cost(particles: usize, steps: usize, cpu_s: Option<f64>) -> Cost {
        Cost { particles, steps, t_end: 0.008, wall_s: 1.0, cpu_s, ..Cost::default() }
    }

    fn drop_row(
        scheme: &str,
        preset: Option<&str>,
        dx: f64,
        threads: usize,
        c: Cost,
        status: &str,
    ) -> RunRow {
        RunRow {
            id: format!("dx{dx}_t{threads}_{scheme}-{preset:?}"),
            dx,
            scheme: scheme.into(),
            variant: (scheme == "isph").then_some(Variant::PAPER),
            preset: preset.map(str::to_string),
            expected_divergence: None,
            threads,
            groups: vec![],
            cost: c,
            b_err: None,
            b_err_max: None,
            a_err: None,
            status: status.into(),
            reused: false,
        }
    }

    fn channel_row(scheme: &str, preset: &str, dx: f64, c: Cost) -> ChannelRow {
        ChannelRow {
            id: format!("channel_dx{dx}_{scheme}"),
            dx,
            scheme: scheme.into(),
            variant: (scheme == "isph").then_some(ChannelVariant::EXPLICIT),
            preset: Some(preset.into()),
            threads: 2,
            cost: c,
            error: Some(0.01),
            error_startup_max: None,
            status: "ok".into(),
            reused: false,
        }
    }

    #[test]
    fn one_cost_per_series_of_each_case() {
        let mut channel = ChannelStudy::new("test".into());
        channel.runs = vec![
            channel_row("mps", "mps", 0.004, cost(1000, 100, Some(0.3))),
            channel_row("isph", "re4", 0.004, cost(1000, 100, Some(0.1))),
        ];
        let study = Study::for_test(
            vec![],
            vec![
                drop_row("mps", Some("mps"), 0.02, 2, cost(8000, 400, Some(3.2)), "ok"),
                drop_row("mps", Some("mps"), 0.04, 2, cost(2000, 400, Some(0.8)), "ok"),
                // A diverged run, a one-thread run and an unnamed option set are left out.
                drop_row("mps", Some("mps"), 0.01, 2, cost(32000, 300, Some(30.0)), "diverged: guard"),
                drop_row("isph", Some("paper"), 0.02, 1, cost(8000, 400, Some(1.0)), "ok"),
                drop_row("isph", None, 0.02, 2, cost(8000, 400, Some(1.0)), "ok"),
                drop_row("isph", Some("paper"), 0.02, 2, cost(8000, 400, Some(0.64)), "ok"),
                drop_row("wcsph", Some("wcsph_tuned"), 0.02, 2, cost(8000, 1200, None), "ok"),
            ],
            Some(channel),
        );
        let costs = scheme_costs(&study);
        let names: Vec<(&str, &str, &str)> =
            costs.iter().map(|c| (c.case.as_str(), c.scheme.as_str(), c.series.as_str())).collect();
        assert_eq!(
            names,
            [
                ("elliptical_drop", "isph", "paper"),
                ("elliptical_drop", "wcsph", "wcsph_tuned"),
                ("elliptical_drop", "mps", "mps"),
                ("poiseuille_periodic", "isph", "re4"),
                ("poiseuille_periodic", "mps", "mps (options of the mps preset) · re4"),
            ]
        );
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12 * b);
        // Paper: 0.64 core-s over 3.2e6 particle-steps.
        assert!(close(costs[0].core_us_per_particle_step, 0.2));
        assert!(close(costs[0].floor_ratio, 0.2 / FLOOR_CORE_US_PER_PARTICLE_PASS));
        // No CPU time: no cost, the run still listed.
        assert_eq!((costs[1].core_us_per_particle_step, costs[1].spacings.len()), (None, 1));
        // MPS: both finished spacings, coarse first, pooled (4.0 core-s over 4e6).
        let mps = &costs[2];
        assert_eq!(mps.spacings.iter().map(|s| s.dx).collect::<Vec<_>>(), [0.04, 0.02]);
        assert!(close(mps.spacings[0].core_us_per_particle_step, 1.0));
        assert!(close(mps.core_us_per_particle_step, 1.0));
        assert!(close(costs[4].core_us_per_particle_step, 3.0));
        assert_eq!(costs[4].threads, 2);
    }
}
