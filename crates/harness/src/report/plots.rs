//! SVG figures (plotters, SVG backend only; text is emitted as `<text>` elements, so no
//! font library is needed). Every function draws from `results.json` data only.

use crate::checks::same_spacing;
use crate::error::{HarnessError, Result};
use crate::fit::fit_power_law;
use crate::results::RunResult;
use plotters::coord::Shift;
use plotters::coord::combinators::LogCoord;
use plotters::prelude::*;

/// Figure size in pixels.
const SIZE: (u32, u32) = (760, 440);

/// Line colours, one per resolution (or metric).
const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

/// The `i`-th colour of the palette (cycling), shared by every chart of the harness.
pub(crate) fn colour(i: usize) -> RGBColor {
    COLOURS[i % COLOURS.len()]
}

fn plot_err(file: &str) -> impl Fn(Box<dyn std::fmt::Debug>) -> HarnessError + '_ {
    move |e| HarnessError::Plot { file: file.to_string(), message: format!("{e:?}") }
}

/// `(min, max)` of the finite values, padded by `pad` of the span (never empty).
fn range(values: impl Iterator<Item = f64>, pad: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let span = if hi > lo { hi - lo } else { lo.abs().max(1.0) * 0.1 };
    (lo - pad * span, hi + pad * span)
}

/// `(min, max)` of the positive finite values for a log axis, widened by `factor` each side.
fn log_range(values: impl Iterator<Item = f64>, factor: f64) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
    if !lo.is_finite() { (1e-3, 1.0) } else { (lo / factor, hi * factor) }
}

fn finite_points(x: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    x.iter().zip(y).filter(|(a, b)| a.is_finite() && b.is_finite()).map(|(a, b)| (*a, *b)).collect()
}

fn svg(
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> std::result::Result<(), Box<dyn std::fmt::Debug>>,
) -> std::result::Result<String, Box<dyn std::fmt::Debug>> {
    svg_sized(SIZE, draw)
}

/// Like [`svg`] with another size in pixels.
fn svg_sized(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<SVGBackend, Shift>) -> std::result::Result<(), Box<dyn std::fmt::Debug>>,
) -> std::result::Result<String, Box<dyn std::fmt::Debug>> {
    let mut out = String::new();
    {
        let root = SVGBackend::with_string(&mut out, size).into_drawing_area();
        root.fill(&WHITE).map_err(boxed)?;
        draw(&root)?;
        root.present().map_err(boxed)?;
    }
    Ok(out)
}

/// A chart builder with the report's caption font, margin and label areas.
fn builder<'a, 'b>(
    root: &'a DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
) -> ChartBuilder<'a, 'b, SVGBackend<'b>> {
    let mut b = ChartBuilder::on(root);
    b.caption(title, ("sans-serif", 18)).margin(12).x_label_area_size(40).y_label_area_size(70);
    b
}

/// An axis of a chart.
#[derive(Clone, Copy, PartialEq)]
enum Axis {
    X,
    Y,
}

/// A log-log chart over `x` × `y` with its mesh drawn, the axes described by `desc` and the
/// tick labels of `powers` written as powers of ten (`1e-3`).
fn log_log<'b, 'c>(
    root: &DrawingArea<SVGBackend<'b>, Shift>,
    title: &str,
    x: (f64, f64),
    y: (f64, f64),
    desc: (&str, &str),
    powers: Axis,
) -> std::result::Result<LogLog<'c, 'b>, Box<dyn std::fmt::Debug>> {
    let mut chart = builder(root, title)
        .build_cartesian_2d((x.0..x.1).log_scale(), (y.0..y.1).log_scale())
        .map_err(boxed)?;
    let power = |v: &f64| format!("{v:.0e}");
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(desc.0).y_desc(desc.1);
    if powers == Axis::X {
        mesh.x_label_formatter(&power);
    } else {
        mesh.y_label_formatter(&power);
    }
    mesh.draw().map_err(boxed)?;
    Ok(chart)
}

/// A log-log chart (`'c`: its series' lifetime).
type LogLog<'c, 'b> = ChartContext<'c, SVGBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Draws the series legend at `position` on a translucent white box.
fn legend<'a, CT: plotters::coord::CoordTranslate>(
    chart: &mut ChartContext<'a, SVGBackend<'a>, CT>,
    position: SeriesLabelPosition,
) -> std::result::Result<(), Box<dyn std::fmt::Debug>> {
    chart
        .configure_series_labels()
        .position(position)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(boxed)
}

fn boxed<E: std::fmt::Debug + 'static>(e: E) -> Box<dyn std::fmt::Debug> {
    Box::new(e)
}

/// The abscissa series of a [`history`] figure and the axis labels.
#[derive(Debug, Clone, Copy)]
pub struct Axes<'a> {
    /// Run series on the x axis (`t` for a time history).
    pub x: &'a str,
    /// x-axis label.
    pub x_label: &'a str,
    /// y-axis label.
    pub y_label: &'a str,
}

/// Time histories (or profiles): `series` of every run against the `axes.x` series (one
/// colour per run, solid for the first series, dashed for the others) and the `reference`
/// series of the finest run in black.
pub fn history(
    file: &str,
    title: &str,
    axes: &Axes<'_>,
    runs: &[&RunResult],
    series: &[String],
    reference: Option<&str>,
) -> Result<String> {
    let t_of = |r: &RunResult| r.series.get(axes.x).cloned().unwrap_or_default();
    let mut all_y = Vec::new();
    let mut all_t = Vec::new();
    for r in runs {
        all_t.extend(t_of(r));
        for s in series.iter().map(String::as_str).chain(reference) {
            all_y.extend(r.series.get(s).into_iter().flatten().copied());
        }
    }
    let (t0, t1) = range(all_t.into_iter(), 0.0);
    let (y0, y1) = range(all_y.into_iter(), 0.05);
    let finest = runs.iter().filter(|r| r.ok()).min_by(|a, b| a.dx.total_cmp(&b.dx)).or(runs.first());
    svg(|root| {
        let mut chart = builder(root, title).build_cartesian_2d(t0..t1, y0..y1).map_err(boxed)?;
        chart.configure_mesh().x_desc(axes.x_label).y_desc(axes.y_label).draw().map_err(boxed)?;
        if let (Some(r), Some(name)) = (finest, reference)
            && let Some(v) = r.series.get(name)
        {
            chart
                .draw_series(LineSeries::new(finite_points(&t_of(r), v), BLACK.stroke_width(2)))
                .map_err(boxed)?
                .label(format!("{name} (reference)"))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.stroke_width(2)));
        }
        for (i, r) in runs.iter().enumerate() {
            let c = colour(i);
            let t = t_of(r);
            for (j, s) in series.iter().enumerate() {
                let Some(v) = r.series.get(s) else { continue };
                let pts = finite_points(&t, v);
                let label = format!(
                    "{s}, {} dx={}{}{}",
                    r.preset,
                    crate::numbers::format_dx(r.dx),
                    start_label(r),
                    if r.ok() { "" } else { " (diverged)" }
                );
                if j == 0 {
                    chart
                        .draw_series(LineSeries::new(pts, c.stroke_width(2)))
                        .map_err(boxed)?
                        .label(label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(2)));
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(pts, 6, 4, c.stroke_width(1)))
                        .map_err(boxed)?
                        .label(label)
                        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], c.stroke_width(1)));
                }
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
        Ok(())
    })
    .map_err(plot_err(file))
}

/// Relative errors `|s / ref − 1|` against time on a log axis: one colour per run, solid
/// for the first pair and dashed for the others. Samples where the error is zero or not
/// finite are left out (a log axis cannot show them).
pub fn error_history(file: &str, title: &str, runs: &[&RunResult], pairs: &[[String; 2]]) -> Result<String> {
    /// (run index, pair index, points).
    type Curve = (usize, usize, Vec<(f64, f64)>);
    let curves: Vec<Curve> = runs
        .iter()
        .enumerate()
        .flat_map(|(i, r)| {
            let t = r.series.get("t").cloned().unwrap_or_default();
            pairs.iter().enumerate().filter_map(move |(j, [s, reference])| {
                let (v, e) = (r.series.get(s)?, r.series.get(reference)?);
                let pts = t
                    .iter()
                    .zip(v.iter().zip(e))
                    .map(|(t, (v, e))| (*t, (v / e - 1.0).abs()))
                    .filter(|(t, y)| t.is_finite() && y.is_finite() && *y > 0.0)
                    .collect();
                Some((i, j, pts))
            })
        })
        .collect();
    let (t0, t1) = range(curves.iter().flat_map(|c| c.2.iter().map(|p| p.0)), 0.0);
    let (y0, y1) = log_range(curves.iter().flat_map(|c| c.2.iter().map(|p| p.1)), 1.5);
    svg(|root| {
        let mut chart =
            builder(root, title).build_cartesian_2d(t0..t1, (y0..y1).log_scale()).map_err(boxed)?;
        chart.configure_mesh().x_desc("t [s]").y_desc("relative error").draw().map_err(boxed)?;
        for (i, j, pts) in curves {
            let (r, c) = (runs[i], colour(i));
            let [s, reference] = &pairs[j];
            let label = format!(
                "{s} vs {reference}, dx={}{}{}",
                crate::numbers::format_dx(r.dx),
                start_label(r),
                if r.ok() { "" } else { " (diverged)" }
            );
            let width = if j == 0 { 2 } else { 1 };
            let series = if j == 0 {
                chart.draw_series(LineSeries::new(pts, c.stroke_width(width))).map_err(boxed)?
            } else {
                chart
                    .draw_series(DashedLineSeries::new(pts, 2 + 3 * j as u32, 4, c.stroke_width(width)))
                    .map_err(boxed)?
            };
            series
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c.stroke_width(width)));
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        Ok(())
    })
    .map_err(plot_err(file))
}

/// `, start <seed>` for a perturbed start (legend labels), empty otherwise.
fn start_label(r: &RunResult) -> String {
    r.start.map(|seed| format!(", start {seed}")).unwrap_or_default()
}

/// A series' legend name: `scheme · preset`, so that the schemes read apart on a case page
/// (the presets of a case name what they change, not always the method).
fn series_name(scheme: &str, preset: &str) -> String {
    format!("{scheme} · {preset}")
}

/// The marker of a run of scheme `$scheme` at `$p` (a `DynElement` in the caller's
/// coordinates): a disc for ISPH, a triangle for WCSPH, a cross for MPS (another scheme:
/// a ring), so that a scheme's points read apart when the palette repeats. A
/// macro, not a function: plotters ties a dynamic element's lifetime to its backend's.
macro_rules! scheme_marker {
    ($scheme:expr, $p:expr, $size:expr, $c:expr) => {
        match $scheme {
            "isph" => Circle::new($p, $size, $c.filled()).into_dyn(),
            "wcsph" => TriangleMarker::new($p, $size + 1, $c.filled()).into_dyn(),
            "mps" => Cross::new($p, $size, $c.stroke_width(2)).into_dyn(),
            _ => Circle::new($p, $size, $c.stroke_width(2)).into_dyn(),
        }
    };
}
/// The work-precision study's figures mark their schemes the same way.
pub(crate) use scheme_marker;

/// Error against dx in log-log: one line per metric and preset (a perturbed-start ensemble
/// by its mean), labelled with the fitted order, and a reference line of slope `slope` through the finest point of the first.
pub fn convergence(
    file: &str,
    title: &str,
    runs: &[&RunResult],
    metrics: &[String],
    slope: Option<f64>,
) -> Result<String> {
    let mut presets: Vec<(&str, &str)> =
        runs.iter().map(|r| (r.preset.as_str(), r.scheme.as_str())).collect();
    presets.sort_unstable();
    presets.dedup();
    // (label, colour index, preset index, scheme, points coarse -> fine)
    let mut lines = Vec::new();
    for (mi, m) in metrics.iter().enumerate() {
        for (pi, &(p, scheme)) in presets.iter().enumerate() {
            let mine: Vec<&RunResult> = runs.iter().copied().filter(|r| r.preset == p).collect();
            let pts: Vec<(f64, f64)> = crate::checks::per_spacing(&mine, m)
                .into_iter()
                .filter_map(|(d, v)| Some((d, v?)))
                .filter(|(d, v)| *d > 0.0 && *v > 0.0)
                .collect();
            if pts.is_empty() {
                continue;
            }
            let (dx, e): (Vec<f64>, Vec<f64>) = pts.iter().copied().unzip();
            let order = fit_power_law(&dx, &e).map_or("n/a".to_string(), |f| format!("{:.2}", f.order));
            lines.push((format!("{m} ({}): order {order}", series_name(scheme, p)), mi, pi, scheme, pts));
        }
    }
    let (x0, x1) = log_range(lines.iter().flat_map(|l| l.4.iter().map(|p| p.0)), 1.3);
    let (y0, y1) = log_range(lines.iter().flat_map(|l| l.4.iter().map(|p| p.1)), 2.0);
    svg(|root| {
        let mut chart = log_log(root, title, (x0, x1), (y0, y1), ("dx [m]", "relative error"), Axis::Y)?;
        for (label, mi, pi, scheme, pts) in &lines {
            // Colour per metric, then per preset; the first preset's line bold; the marker
            // names the scheme.
            let c = colour(mi + pi);
            let style = if *pi == 0 { c.stroke_width(2) } else { c.stroke_width(1) };
            chart
                .draw_series(LineSeries::new(pts.clone(), style))
                .map_err(boxed)?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
            chart
                .draw_series(
                    pts.iter()
                        .map(|&p| -> DynElement<SVGBackend, (f64, f64)> { scheme_marker!(*scheme, p, 4, c) }),
                )
                .map_err(boxed)?;
        }
        if let (Some(s), Some(first)) = (slope, lines.first()) {
            let &(dxf, ef) = first.4.last().expect("non-empty");
            let c = ef / dxf.powf(s);
            let pts: Vec<(f64, f64)> = [x0 * 1.1, x1 / 1.1].iter().map(|&d| (d, c * d.powf(s))).collect();
            let grey = RGBColor(120, 120, 120);
            chart
                .draw_series(DashedLineSeries::new(pts, 6, 4, grey.stroke_width(1)))
                .map_err(boxed)?
                .label(format!("reference slope dx^{s}"))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 8, y)], grey));
        }
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
        Ok(())
    })
    .map_err(plot_err(file))
}

/// Run time against `metric` (work-precision): one point per run, and per scheme and preset
/// a line through the means of its spacings (coarse to fine), one colour each; the marker
/// names the scheme (`scheme_marker!`).
pub fn cost(file: &str, title: &str, runs: &[&RunResult], metric: &str) -> Result<String> {
    // (preset, scheme, dx, error, wall time)
    let pts: Vec<(&str, &str, f64, f64, f64)> = runs
        .iter()
        .filter(|r| r.ok())
        .filter_map(|r| r.metric(metric).map(|e| (r.preset.as_str(), r.scheme.as_str(), r.dx, e, r.wall_s)))
        .filter(|p| p.3 > 0.0 && p.3.is_finite() && p.4 > 0.0)
        .collect();
    let mut series: Vec<(&str, &str)> = pts.iter().map(|p| (p.0, p.1)).collect();
    series.sort_unstable();
    series.dedup();
    let (x0, x1) = log_range(pts.iter().map(|p| p.3), 2.0);
    let (y0, y1) = log_range(pts.iter().map(|p| p.4), 2.0);
    svg(|root| {
        let mut chart = log_log(root, title, (x0, x1), (y0, y1), (metric, "wall time [s]"), Axis::X)?;
        for (i, &(preset, scheme)) in series.iter().enumerate() {
            let c = colour(i);
            let mine: Vec<&(&str, &str, f64, f64, f64)> = pts.iter().filter(|q| q.0 == preset).collect();
            // The mean point of each spacing (several with perturbed starts), coarse to fine.
            let mut dxs: Vec<f64> = mine.iter().map(|q| q.2).collect();
            dxs.sort_by(|a, b| b.total_cmp(a));
            dxs.dedup_by(|a, b| same_spacing(*a, *b));
            let line: Vec<(f64, f64)> = dxs
                .iter()
                .map(|&d| {
                    let at: Vec<_> = mine.iter().filter(|q| same_spacing(q.2, d)).collect();
                    let n = at.len() as f64;
                    (at.iter().map(|q| q.3).sum::<f64>() / n, at.iter().map(|q| q.4).sum::<f64>() / n)
                })
                .collect();
            chart.draw_series(LineSeries::new(line, c.stroke_width(1))).map_err(boxed)?;
            let marker = scheme.to_string();
            chart
                .draw_series(mine.iter().map(|q| -> DynElement<SVGBackend, (f64, f64)> {
                    scheme_marker!(scheme, (q.3, q.4), 5, c)
                }))
                .map_err(boxed)?
                .label(series_name(scheme, preset))
                .legend(move |(x, y)| -> DynElement<SVGBackend, (i32, i32)> {
                    scheme_marker!(marker.as_str(), (x + 10, y), 5, c)
                });
            chart
                .draw_series(mine.iter().map(|q| {
                    Text::new(
                        format!("dx={}", crate::numbers::format_dx(q.2)),
                        (q.3, q.4),
                        ("sans-serif", 12),
                    )
                }))
                .map_err(boxed)?;
        }
        legend(&mut chart, SeriesLabelPosition::UpperRight)?;
        Ok(())
    })
    .map_err(plot_err(file))
}

/// Light variants of the palette's colours (Tableau 20's light half): the overview's
/// cases after the first eight, since the suite has more cases than a figure has series.
const LIGHT_COLOURS: [RGBColor; 8] = [
    RGBColor(174, 199, 232),
    RGBColor(255, 187, 120),
    RGBColor(152, 223, 138),
    RGBColor(255, 152, 150),
    RGBColor(197, 176, 213),
    RGBColor(196, 156, 148),
    RGBColor(247, 182, 210),
    RGBColor(158, 218, 229),
];

/// The overview's colour of its `i`-th case: the palette, then its light variants.
fn case_colour(i: usize) -> RGBColor {
    if i < COLOURS.len() { COLOURS[i] } else { LIGHT_COLOURS[(i - COLOURS.len()) % LIGHT_COLOURS.len()] }
}

/// The suite at a glance: every case's headline error \[%\] against wall time \[s\]
/// (log-log), one colour per case, one marker per scheme (`scheme_marker!`), a line
/// through each scheme's spacings; the legend (cases, then schemes) beside the chart.
pub fn overview(file: &str, title: &str, curves: &[super::matrix::Curve]) -> Result<String> {
    let mut cases: Vec<&str> = curves.iter().map(|c| c.case.as_str()).collect();
    cases.dedup();
    let mut schemes: Vec<&str> = curves.iter().map(|c| c.scheme.as_str()).collect();
    schemes.sort_unstable();
    schemes.dedup();
    let pts = || curves.iter().flat_map(|c| c.points.iter().map(|&(w, e)| (w, 100.0 * e)));
    let (x0, x1) = log_range(pts().map(|p| p.0), 2.0);
    let (y0, y1) = log_range(pts().map(|p| p.1), 2.0);
    let case_colour = |case: &str| case_colour(cases.iter().position(|c| *c == case).unwrap_or(0));
    svg_sized((1000, 520), |root| {
        let (plot, side) = root.split_horizontally(760);
        let mut chart = log_log(
            &plot,
            title,
            (x0, x1),
            (y0, y1),
            ("wall time of the run [s]", "headline error [%]"),
            Axis::Y,
        )?;
        for c in curves {
            let colour = case_colour(&c.case);
            let line: Vec<(f64, f64)> =
                c.points.iter().map(|&(w, e)| (w, 100.0 * e)).filter(|p| p.0 > 0.0 && p.1 > 0.0).collect();
            chart.draw_series(LineSeries::new(line.clone(), colour.stroke_width(1))).map_err(boxed)?;
            chart
                .draw_series(line.iter().map(|&p| -> DynElement<SVGBackend, (f64, f64)> {
                    scheme_marker!(c.scheme.as_str(), p, 5, colour)
                }))
                .map_err(boxed)?;
        }
        // The legend: a line per case in its colour, then a grey marker per scheme.
        let text = ("sans-serif", 13).into_font();
        let grey = RGBColor(90, 90, 90);
        let mut y = 30;
        for case in &cases {
            let c = case_colour(case);
            side.draw(&PathElement::new(vec![(8, y), (30, y)], c.stroke_width(3))).map_err(boxed)?;
            side.draw(&Text::new(case.to_string(), (36, y - 7), text.clone())).map_err(boxed)?;
            y += 20;
        }
        y += 10;
        for scheme in &schemes {
            let marker: DynElement<SVGBackend, (i32, i32)> = scheme_marker!(*scheme, (19, y), 5, grey);
            side.draw(&marker).map_err(boxed)?;
            side.draw(&Text::new(scheme.to_string(), (36, y - 7), text.clone())).map_err(boxed)?;
            y += 20;
        }
        Ok(())
    })
    .map_err(plot_err(file))
}

/// Control points of the viridis colour map (matplotlib), evenly spaced on [0, 1].
const VIRIDIS: [(u8, u8, u8); 9] = [
    (68, 1, 84),
    (71, 44, 122),
    (59, 81, 139),
    (44, 113, 142),
    (33, 144, 141),
    (39, 173, 129),
    (92, 200, 99),
    (170, 220, 50),
    (253, 231, 37),
];

/// Viridis at `s` in [0, 1] (clamped), linear between the control points.
pub(crate) fn viridis(s: f64) -> RGBColor {
    let s = if s.is_finite() { s.clamp(0.0, 1.0) } else { 0.0 };
    let x = s * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |p: u8, q: u8| (p as f64 + f * (q as f64 - p as f64)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The `q`-quantile (0–1) of the finite values (nearest rank); `None` when there are none.
fn quantile(values: &[f64], q: f64) -> Option<f64> {
    let mut v: Vec<f64> = values.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[((v.len() - 1) as f64 * q).round() as usize])
}

/// Particle scatter plots coloured by pressure: one square panel per `(label, view)` side
/// by side (a 2D snapshot or the cut of a 3D one, [`crate::snapshots::Snapshot::view`]),
/// the same axes (those of the first view) and colour scale for all (the 1st–99th
/// percentile of the pressures, so that a few outliers do not wash out the rest), and a
/// colour bar.
pub fn snapshots(file: &str, title: &str, panels: &[(String, &crate::snapshots::View)]) -> Result<String> {
    const PANEL: u32 = 430;
    const BAR: u32 = 140;
    let [x_desc, y_desc] =
        panels.first().map_or([0, 1], |(_, v)| v.axes).map(|a| format!("{} [m]", crate::snapshots::AXES[a]));
    let all_p: Vec<f64> = panels.iter().flat_map(|(_, s)| s.p.iter().copied()).collect();
    let (mut p0, mut p1) = (quantile(&all_p, 0.01).unwrap_or(0.0), quantile(&all_p, 0.99).unwrap_or(1.0));
    if p1 - p0 <= 1e-12 * p0.abs().max(p1.abs()).max(1e-300) {
        let pad = p0.abs().max(1.0) * 0.5;
        (p0, p1) = (p0 - pad, p1 + pad);
    }
    let (x0, x1) = range(panels.iter().flat_map(|(_, s)| s.h.iter().copied()), 0.04);
    let (y0, y1) = range(panels.iter().flat_map(|(_, s)| s.v.iter().copied()), 0.04);
    // Equal scales on both axes: a square panel shows the larger extent on both.
    let half = 0.5 * (x1 - x0).max(y1 - y0);
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (xr, yr) = ((cx - half)..(cx + half), (cy - half)..(cy + half));
    let n = panels.len().max(1) as u32;
    svg_sized((PANEL * n + BAR, PANEL + 40), |root| {
        let root = root.titled(title, ("sans-serif", 14)).map_err(boxed)?;
        let (left, bar) = root.split_horizontally(PANEL * n);
        for (area, (label, snap)) in left.split_evenly((1, n as usize)).iter().zip(panels) {
            let mut chart = ChartBuilder::on(area)
                .caption(label, ("sans-serif", 15))
                .margin(8)
                .x_label_area_size(30)
                .y_label_area_size(45)
                .build_cartesian_2d(xr.clone(), yr.clone())
                .map_err(boxed)?;
            chart.configure_mesh().disable_mesh().x_desc(&x_desc).y_desc(&y_desc).draw().map_err(boxed)?;
            let pts =
                snap.h.iter().zip(&snap.v).zip(&snap.p).filter(|((x, y), _)| x.is_finite() && y.is_finite());
            chart
                .draw_series(
                    pts.map(|((&x, &y), &p)| Circle::new((x, y), 2, viridis((p - p0) / (p1 - p0)).filled())),
                )
                .map_err(boxed)?;
        }
        let mut scale = ChartBuilder::on(&bar)
            .margin_top(40)
            .margin_bottom(38)
            .margin_left(10)
            .right_y_label_area_size(95)
            .build_cartesian_2d(0.0..1.0, p0..p1)
            .map_err(boxed)?;
        scale
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc("p [Pa]")
            .y_label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 14))
            .y_label_formatter(&|v| format!("{v:.2e}"))
            .draw()
            .map_err(boxed)?;
        const SLICES: usize = 64;
        scale
            .draw_series((0..SLICES).map(|k| {
                let (a, b) = (k as f64 / SLICES as f64, (k + 1) as f64 / SLICES as f64);
                let (lo, hi) = (p0 + a * (p1 - p0), p0 + b * (p1 - p0));
                Rectangle::new([(0.0, lo), (1.0, hi)], viridis(0.5 * (a + b)).filled())
            }))
            .map_err(boxed)?;
        Ok(())
    })
    .map_err(plot_err(file))
}

#[cfg(test)]
mod snapshot_tests {
    use super::*;
    use crate::snapshots::Snapshot;

    #[test]
    fn viridis_ends_and_clamps() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(2.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        assert_eq!(viridis(0.5), RGBColor(33, 144, 141));
    }

    #[test]
    fn scatter_has_a_point_per_particle_and_a_colour_bar() {
        let snap = |shift: f64| Snapshot {
            time: 0.01,
            step: 100,
            x: (0..50).map(|i| (i % 10) as f64 * 0.1 + shift).collect(),
            y: (0..50).map(|i| (i / 10) as f64 * 0.1).collect(),
            z: Vec::new(),
            p: (0..50).map(|i| -1e5 * i as f64).collect(),
        };
        let (a, b) = (snap(0.0).view(1, 0.1), snap(0.01).view(1, 0.1));
        let svg =
            snapshots("s.svg", "Snapshots", &[("shifting".into(), &a), ("no_shifting".into(), &b)]).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("no_shifting") && svg.contains("p [Pa]"));
        assert!(svg.contains("x [m]") && svg.contains("y [m]"));
        assert_eq!(svg.matches("<circle").count(), 100, "one marker per particle");
        // A uniform field (t = 0: p = 0 everywhere) still draws.
        let flat = Snapshot { p: vec![0.0; 50], ..snap(0.0) }.view(1, 0.1);
        assert!(snapshots("f.svg", "t = 0", &[("shifting".into(), &flat)]).is_ok());
    }

    /// A 3D lattice ball cut by each plane through its centre: one marker per particle of
    /// that plane (49 of 257), the plane's two axes on the panel.
    #[test]
    fn a_3d_snapshot_draws_its_cut() {
        let ball = crate::snapshots::tests::ball(0.01, [0.0, 0.0, 0.05]);
        for (axis, [h, v]) in [(0, ["y", "z"]), (1, ["x", "z"]), (2, ["x", "y"])] {
            let view = ball.view(axis, 0.01);
            let svg = snapshots("c.svg", "Cut", &[("paper".into(), &view), ("tuned".into(), &view)]).unwrap();
            assert_eq!(svg.matches("<circle").count(), 2 * 49, "axis {axis}");
            assert!(
                svg.contains(&format!(">\n{h} [m]\n<")) && svg.contains(&format!(">\n{v} [m]\n<")),
                "axis {axis}"
            );
        }
    }
}
