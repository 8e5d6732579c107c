//! The study's SVG figures (plotters, SVG backend), drawn from the run rows alone.
//!
//! The report's chart functions (`crate::report::plots`) take validation `RunResult`s and
//! draw one kind of chart each; these four need other data (Pareto fronts, stacked stage
//! times, fits against particle count, speed-ups), so they live here with the same look
//! (size, fonts, palette, legend on a translucent box, the scheme's marker).

use super::channel::{ChannelRow, PRESET};
use super::pipe::PipeRow;
use super::record::{CostFit, RunRow, SpeedUp};
use super::targets::thresholds;
use crate::error::{HarnessError, Result};
use crate::report::plots::{colour, scheme_marker};
use plotters::coord::Shift;
use plotters::prelude::*;

/// Figure size in pixels.
const SIZE: (u32, u32) = (820, 480);

type DrawResult = std::result::Result<(), Box<dyn std::fmt::Debug>>;

/// A chart with the page's caption font, margin and label areas (every figure here).
fn chart_builder<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    caption: impl AsRef<str>,
) -> ChartBuilder<'a, 'b, SVGBackend<'b>> {
    let mut b = ChartBuilder::on(root);
    b.caption(caption, ("sans-serif", 18)).margin(12).x_label_area_size(42).y_label_area_size(64);
    b
}

fn boxed<E: std::fmt::Debug + 'static>(e: E) -> Box<dyn std::fmt::Debug> {
    Box::new(e)
}

/// Draws into an SVG string of [`SIZE`] on white; errors name the figure.
fn svg(file: &str, draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> DrawResult) -> Result<String> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, SIZE).into_drawing_area();
        let r = root
            .fill(&WHITE)
            .map_err(boxed)
            .and_then(|_| draw(&root))
            .and_then(|_| root.present().map_err(boxed));
        r.map_err(|e| HarnessError::Plot { file: file.to_string(), message: format!("{e:?}") })?;
    }
    Ok(out)
}

/// `(lo, hi)` of the positive finite values widened by `factor` each side, for a log axis.
fn log_range(values: impl Iterator<Item = f64>, factor: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if lo.is_finite() { (lo / factor, hi * factor) } else { (0.1, 10.0) }
}

fn legend<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> DrawResult {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(boxed)
}

/// A relative error as a percentage with two significant digits.
fn percent(v: f64) -> String {
    let p = 100.0 * v;
    let digits = if p > 0.0 { (1.0 - p.log10().floor()).max(0.0) as usize } else { 0 };
    format!("{p:.digits$} %")
}

/// Distinct spacings, coarse to fine.
fn spacings(dx: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut dx: Vec<f64> = dx.collect();
    dx.sort_by(|a, b| b.total_cmp(a));
    dx.dedup_by(|a, b| (*a - *b).abs() < 1e-12);
    dx
}

/// One point of a work-precision chart.
struct Point<'a> {
    id: &'a str,
    /// The run's scheme (its marker, and its Pareto front).
    scheme: &'a str,
    /// The legend entry of the scheme's points: `isph` for the ISPH option sets, the
    /// series of another scheme's points (`mps · mps`).
    series: String,
    dx: f64,
    error: f64,
    wall_s: f64,
    /// Text drawn at the point (the presets), if any.
    label: Option<String>,
    /// Marker size \[px\]: the ISPH option sets small ([`OPTION_SET`]), the other schemes'
    /// few points larger ([`PRESET_POINT`]).
    size: i32,
}

/// Marker size of an ISPH option set among many \[px\].
const OPTION_SET: i32 = 3;

/// Marker size of a lone point (another scheme's, or one of few) \[px\].
const PRESET_POINT: i32 = 5;

/// The marker size of a run of `scheme` in the drop's and the channel's charts.
fn size_of(scheme: &str) -> i32 {
    if scheme == "isph" { OPTION_SET } else { PRESET_POINT }
}

/// A spacing rounded for a legend (D/36 = 0.005556).
fn dx_text(dx: f64) -> String {
    format!("{}", (dx * 1e6).round() / 1e6)
}

/// Wall time against error (log-log), one colour per spacing and one marker per scheme
/// (`scheme_marker!`, with a legend entry per series); each scheme's Pareto front (ids in
/// `front`, each scheme's cheapest first) joined by a black line; labelled points; the
/// dashed target box (error ≤ `target.0` within `target.1` s), if any.
fn front_chart(
    file: &str,
    title: &str,
    x_desc: &str,
    pts: &[Point],
    front: &[String],
    target: Option<(f64, f64, &str)>,
) -> Result<String> {
    let dxs = spacings(pts.iter().map(|p| p.dx));
    let mut series: Vec<(&str, &str)> = Vec::new();
    for p in pts {
        if !series.contains(&(p.scheme, p.series.as_str())) {
            series.push((p.scheme, p.series.as_str()));
        }
    }
    let (x0, x1) = log_range(pts.iter().map(|p| p.error).chain(target.map(|t| t.0)), 1.6);
    let (y0, y1) = log_range(pts.iter().map(|p| p.wall_s).chain(target.map(|t| t.1)), 1.6);
    // Room above the slowest run for the legend (upper right, about 18 px a row of the
    // plot's 380), so that it hides no point.
    let rows = usize::from(target.is_some()) + dxs.len() + series.len() + 1;
    let legend_share = ((18 * rows + 10) as f64 / 380.0).min(0.6);
    let y1 = y0 * (y1 / y0).powf(1.0 / (1.0 - legend_share));
    svg(file, |root| {
        let mut chart = chart_builder(root, title)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(boxed)?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc("wall time [s]")
            .x_label_formatter(&|v| percent(*v))
            .y_label_formatter(&|v| format!("{v:.2}"))
            .draw()
            .map_err(boxed)?;
        if let Some((err, wall, text)) = target {
            let grey = RGBColor(120, 120, 120);
            chart
                .draw_series(DashedLineSeries::new(
                    [(x0, wall), (err, wall), (err, y0)],
                    6,
                    4,
                    grey.stroke_width(1),
                ))
                .map_err(boxed)?
                .label(text)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
        }
        for (i, dx) in dxs.iter().enumerate() {
            let c = colour(i);
            // The ISPH option sets small, the other schemes' few points larger and on top.
            let mut mine: Vec<&Point> = pts.iter().filter(|p| (p.dx - dx).abs() < 1e-12).collect();
            mine.sort_by_key(|p| p.scheme != "isph");
            chart
                .draw_series(mine.iter().map(|p| -> DynElement<SVGBackend, (f64, f64)> {
                    scheme_marker!(p.scheme, (p.error, p.wall_s), p.size, c.mix(0.75))
                }))
                .map_err(boxed)?
                .label(format!("Δx = {} ({} runs)", dx_text(*dx), mine.len()))
                .legend(move |(x, y)| Rectangle::new([(x + 4, y - 4), (x + 12, y + 4)], c.filled()));
        }
        // One legend entry per series, its marker in grey.
        let grey = RGBColor(90, 90, 90);
        for &(scheme, name) in &series {
            let n = pts.iter().filter(|p| p.series == name).count();
            let marker = scheme.to_string();
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(boxed)?
                .label(format!("{name} ({n} runs)"))
                .legend(move |(x, y)| -> DynElement<SVGBackend, (i32, i32)> {
                    scheme_marker!(marker.as_str(), (x + 8, y), 4, grey)
                });
        }
        let mut schemes: Vec<&str> = Vec::new();
        for id in front {
            if let Some(p) = pts.iter().find(|p| p.id == id)
                && !schemes.contains(&p.scheme)
            {
                schemes.push(p.scheme);
            }
        }
        let on_front: Vec<&Point> = front.iter().filter_map(|id| pts.iter().find(|p| p.id == id)).collect();
        for (k, scheme) in schemes.iter().enumerate() {
            let line: Vec<(f64, f64)> =
                on_front.iter().filter(|p| p.scheme == *scheme).map(|p| (p.error, p.wall_s)).collect();
            let drawn = chart.draw_series(LineSeries::new(line, BLACK.stroke_width(2))).map_err(boxed)?;
            if k == 0 {
                drawn
                    .label(format!("Pareto front of each scheme ({} runs)", on_front.len()))
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
            }
        }
        chart
            .draw_series(on_front.iter().map(|p| Circle::new((p.error, p.wall_s), 6, BLACK.stroke_width(2))))
            .map_err(boxed)?;
        chart
            .draw_series(pts.iter().filter_map(|p| {
                p.label.as_ref().map(|name| Text::new(name.clone(), (p.error, p.wall_s), ("sans-serif", 11)))
            }))
            .map_err(boxed)?;
        legend(&mut chart, SeriesLabelPosition::UpperRight)
    })
}

/// The legend entry of a run's scheme: `isph` for every ISPH option set, `scheme · series`
/// for another scheme's named series.
fn series(scheme: &str, name: Option<String>) -> String {
    match name {
        Some(name) if scheme != "isph" => format!("{scheme} · {name}"),
        _ => scheme.to_string(),
    }
}

/// The drop's chart: wall time against b error at t = 0.008 s (finished runs), the
/// presets labelled, the target box (b error ≤ 0.5 % within 1 s, the ISPH target).
pub fn work_precision(file: &str, runs: &[&RunRow], front: &[String]) -> Result<String> {
    let pts: Vec<Point> = runs
        .iter()
        .filter(|r| r.ok())
        .filter_map(|r| {
            r.b_err.filter(|e| *e > 0.0).map(|error| Point {
                id: &r.id,
                scheme: &r.scheme,
                series: series(&r.scheme, r.preset.clone()),
                dx: r.dx,
                error,
                wall_s: r.cost.wall_s,
                label: r.preset.as_ref().map(|name| format!("{name} Δx={}", r.dx)),
                size: size_of(&r.scheme),
            })
        })
        .collect();
    front_chart(
        file,
        "Work-precision: wall time against b error at t = 0.008 s",
        "relative b error at t = 0.008 s",
        &pts,
        front,
        Some((thresholds::B_ERR, thresholds::B_ERR_WALL_S, "ISPH target: b error ≤ 0.5 % within 1 s")),
    )
}

/// The channel's chart: wall time against the steady profile error at τ = 1 (finished
/// runs), the case's presets (`re4`, `re4_implicit`) and the other schemes' points
/// labelled.
pub fn channel_work_precision(file: &str, runs: &[&ChannelRow], front: &[String]) -> Result<String> {
    let pts: Vec<Point> = runs
        .iter()
        .filter(|r| r.ok())
        .filter_map(|r| {
            r.error.filter(|e| *e > 0.0).map(|error| Point {
                id: &r.id,
                scheme: &r.scheme,
                series: match r.series() {
                    Some(name) if r.scheme != "isph" => name,
                    _ => r.scheme.clone(),
                },
                dx: r.dx,
                error,
                wall_s: r.cost.wall_s,
                label: r.preset.as_ref().map(|name| {
                    let name =
                        if r.scheme == "isph" { name.clone() } else { format!("{} · {PRESET}", r.scheme) };
                    format!("{name} Δx={}", dx_text(r.dx))
                }),
                size: size_of(&r.scheme),
            })
        })
        .collect();
    front_chart(
        file,
        "Periodic channel (Re = 4): wall time against the steady profile error",
        "relative L2 error of the velocity profile at τ = 1",
        &pts,
        front,
        None,
    )
}

/// The pipe's chart: wall time against the steady profile error at ν t/R² = 1 (finished
/// runs), one marker per scheme, one colour per spacing, each point labelled with its
/// preset and R/Δx; no Pareto front (one run per scheme and spacing).
pub fn pipe_work_precision(file: &str, runs: &[&PipeRow]) -> Result<String> {
    let pts: Vec<Point> = runs
        .iter()
        .filter(|r| r.ok())
        .filter_map(|r| {
            r.error.filter(|e| *e > 0.0).map(|error| Point {
                id: &r.id,
                scheme: &r.scheme,
                series: format!("{} · {}", r.scheme, r.preset),
                dx: r.dx,
                error,
                wall_s: r.cost.wall_s,
                label: Some(format!("{} R/{}", r.preset, r.r_over_dx)),
                size: PRESET_POINT,
            })
        })
        .collect();
    front_chart(
        file,
        "3D pipe (Re = 1): wall time against the steady profile error",
        "relative L2 error of the radial velocity profile at ν t/R² = 1",
        &pts,
        &[],
        None,
    )
}

/// Horizontal stacked bars: microseconds per particle and step spent in each stage, for
/// each row in `bars` (label, run).
pub fn stage_breakdown(file: &str, bars: &[(String, &RunRow)]) -> Result<String> {
    let mut stages: Vec<String> = bars.iter().flat_map(|(_, r)| r.cost.stages.keys().cloned()).collect();
    stages.sort();
    stages.dedup();
    // Largest total first in the legend.
    let total = |s: &str| bars.iter().map(|(_, r)| r.cost.stages.get(s).copied().unwrap_or(0.0)).sum::<f64>();
    stages.sort_by(|a, b| total(b).total_cmp(&total(a)));
    let per = |r: &RunRow, s: &str| {
        let work = (r.cost.particles * r.cost.steps.max(1)) as f64;
        1e6 * r.cost.stages.get(s).copied().unwrap_or(0.0) / work
    };
    let width = bars.iter().map(|(_, r)| stages.iter().map(|s| per(r, s)).sum::<f64>()).fold(0.0, f64::max);
    let n = bars.len().max(1);
    let labels: Vec<String> = bars.iter().map(|(l, _)| l.clone()).collect();
    svg(file, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption("Time per particle and step, by stage", ("sans-serif", 18))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(220)
            .build_cartesian_2d(0.0..width * 1.35 + 1e-9, -0.5..(n as f64 - 0.5))
            .map_err(boxed)?;
        let label_of = |v: &f64| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 {
                labels.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        };
        chart
            .configure_mesh()
            .disable_y_mesh()
            .y_labels(n)
            .y_label_formatter(&label_of)
            .x_desc("µs per particle-step")
            .draw()
            .map_err(boxed)?;
        for (k, s) in stages.iter().enumerate() {
            let c = colour(k);
            let rects: Vec<Rectangle<(f64, f64)>> = bars
                .iter()
                .enumerate()
                .map(|(i, (_, r))| {
                    let start: f64 = stages[..k].iter().map(|t| per(r, t)).sum();
                    let y = i as f64;
                    Rectangle::new([(start, y - 0.35), (start + per(r, s), y + 0.35)], c.filled())
                })
                .collect();
            chart
                .draw_series(rects)
                .map_err(boxed)?
                .label(s.clone())
                .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 12, y + 5)], c.filled()));
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)
    })
}

/// Seconds per step against particle count (log-log), one colour per preset: the
/// main-thread runs with their fitted power law (exponent in the legend), one-thread runs
/// as hollow markers.
pub fn cost_scaling(file: &str, fits: &[CostFit], one_thread: &[&RunRow]) -> Result<String> {
    let all_n = fits.iter().flat_map(|f| f.particles.iter().map(|&p| p as f64));
    let (x0, x1) = log_range(all_n.chain(one_thread.iter().map(|r| r.cost.particles as f64)), 1.5);
    let (y0, y1) = log_range(
        fits.iter()
            .flat_map(|f| f.cost_per_step_s.iter().copied())
            .chain(one_thread.iter().filter_map(|r| r.cost.per_step())),
        2.0,
    );
    svg(file, |root| {
        let mut chart = chart_builder(root, "Cost per step against particle count")
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(boxed)?;
        chart
            .configure_mesh()
            .x_desc("particles")
            .y_desc("seconds per step")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .y_label_formatter(&|v| format!("{v:.0e}"))
            .draw()
            .map_err(boxed)?;
        for (i, f) in fits.iter().enumerate() {
            let c = colour(i);
            let pts: Vec<(f64, f64)> =
                f.particles.iter().zip(&f.cost_per_step_s).map(|(&n, &s)| (n as f64, s)).collect();
            let label = match f.exponent {
                Some(p) => format!("{} ({} threads): fitted exponent {p:.3}", f.preset, f.threads),
                None => format!("{} ({} threads): no fit", f.preset, f.threads),
            };
            chart
                .draw_series(pts.iter().map(|&p| Circle::new(p, 5, c.filled())))
                .map_err(boxed)?
                .label(label)
                .legend(move |(x, y)| Circle::new((x + 10, y), 5, c.filled()));
            if let (Some(p), Some(k)) = (f.exponent, f.constant) {
                let line: Vec<(f64, f64)> =
                    [x0 * 1.2, x1 / 1.2].iter().map(|&n| (n, k * n.powf(p))).collect();
                chart.draw_series(LineSeries::new(line, c.stroke_width(1))).map_err(boxed)?;
            }
            let ones: Vec<(f64, f64)> = one_thread
                .iter()
                .filter(|r| r.preset.as_deref() == Some(f.preset.as_str()))
                .filter_map(|r| r.cost.per_step().map(|s| (r.cost.particles as f64, s)))
                .collect();
            if !ones.is_empty() {
                chart
                    .draw_series(ones.iter().map(|&p| Circle::new(p, 5, c.stroke_width(2))))
                    .map_err(boxed)?
                    .label(format!("{} (1 thread)", f.preset))
                    .legend(move |(x, y)| Circle::new((x + 10, y), 5, c.stroke_width(2)));
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)
    })
}

/// Speed-up of the main thread count over one thread against particle count, one line per
/// preset, with the target (1.7) and the ideal (the thread count).
pub fn speedup(file: &str, ups: &[SpeedUp], threads: usize) -> Result<String> {
    let (x0, x1) = log_range(ups.iter().map(|s| s.particles as f64), 1.5);
    let top = ups.iter().map(|s| s.speedup).fold(threads as f64, f64::max) * 1.15;
    svg(file, |root| {
        let mut chart = chart_builder(root, format!("Speed-up, 1 → {threads} threads"))
            .build_cartesian_2d((x0..x1).log_scale(), 0.0..top)
            .map_err(boxed)?;
        chart
            .configure_mesh()
            .x_desc("particles")
            .y_desc("wall time (1 thread) / wall time")
            .x_label_formatter(&|v| format!("{v:.0}"))
            .draw()
            .map_err(boxed)?;
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, thresholds::SPEEDUP), (x1, thresholds::SPEEDUP)],
                6,
                4,
                RED.stroke_width(1),
            ))
            .map_err(boxed)?
            .label(format!("target {} at Δx = 0.01", thresholds::SPEEDUP))
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED));
        chart
            .draw_series(DashedLineSeries::new(
                [(x0, threads as f64), (x1, threads as f64)],
                2,
                4,
                grey.stroke_width(1),
            ))
            .map_err(boxed)?
            .label(format!("ideal ({threads})"))
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], grey));
        let mut presets: Vec<&str> = ups.iter().map(|s| s.preset.as_str()).collect();
        presets.dedup();
        for (i, p) in presets.iter().enumerate() {
            let c = colour(i);
            let mut pts: Vec<(f64, f64, f64)> = ups
                .iter()
                .filter(|s| s.preset == *p)
                .map(|s| (s.particles as f64, s.speedup, s.dx))
                .collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            chart
                .draw_series(LineSeries::new(pts.iter().map(|q| (q.0, q.1)), c.stroke_width(2)))
                .map_err(boxed)?
                .label(p.to_string())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
            chart.draw_series(pts.iter().map(|q| Circle::new((q.0, q.1), 4, c.filled()))).map_err(boxed)?;
            chart
                .draw_series(
                    pts.iter().map(|q| {
                        Text::new(format!("Δx={} ({:.2})", q.2, q.1), (q.0, q.1), ("sans-serif", 11))
                    }),
                )
                .map_err(boxed)?;
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)
    })
}
