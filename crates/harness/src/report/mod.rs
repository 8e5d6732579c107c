//! The report: SVG figures ([`plots`]) and self-contained HTML pages ([`html`]), rendered
//! from the JSON in the output directory only (`cargo xtask report` runs nothing).
//!
//! Layout: `reports/index.html` (one row per case), `reports/summary.json`,
//! `reports/summary.md` ([`markdown`], for CI job summaries), and per case
//! `reports/<case>/index.html` with its figures `reports/<case>/*.svg` (relative links).
//! With a baseline ([`crate::baseline`]), the pages and `summary.md` also show what moved.

pub mod header;
pub mod html;
pub mod markdown;
pub mod matrix;
pub mod plots;
pub mod timing;

pub use html::ExtraPage;

use crate::baseline::{self, Comparison, NoiseBand};
use crate::case::{CaseRecord, Figure};
use crate::checks::same_spacing;
use crate::error::{HarnessError, Result};
use crate::io;
use crate::results::{CaseResults, RunResult, Summary, case_dirs};
use crate::snapshots::AXES;
use header::Header;
use matrix::Matrix;
use std::path::{Path, PathBuf};

/// A figure written next to a case page.
#[derive(Debug, Clone, PartialEq)]
pub struct FigureFile {
    /// File name relative to the case directory (`history_b_paper.svg`).
    pub file: String,
    /// Caption.
    pub caption: String,
}

/// Renders the figures and the page of one case into `case_dir`; `record` (the case file
/// and provenance) supplies the figure list, parameters, errata and provenance when present;
/// `comparison` adds the "Compared with baseline" section.
pub fn render_case(
    case_dir: &Path,
    results: &CaseResults,
    record: Option<&CaseRecord>,
    comparison: Option<&Comparison>,
) -> Result<Vec<FigureFile>> {
    let mut figures = Vec::new();
    let runs: Vec<&RunResult> = results.runs.iter().collect();
    let mut presets: Vec<&str> = Vec::new();
    for r in &runs {
        if !presets.contains(&r.preset.as_str()) {
            presets.push(&r.preset);
        }
    }
    for fig in record.map(|r| r.case.figures.as_slice()).unwrap_or(&[]) {
        match fig {
            Figure::History { file, title, y_label, series, reference, x, x_label } => {
                let x = x.as_deref().unwrap_or("t");
                let x_label =
                    x_label.clone().unwrap_or_else(|| if x == "t" { "t [s]".into() } else { x.into() });
                per_preset(case_dir, &runs, &presets, file, title, &mut figures, |name, caption, mine| {
                    let axes = plots::Axes { x, x_label: &x_label, y_label };
                    plots::history(name, caption, &axes, mine, series, reference.as_deref())
                })?;
            }
            Figure::ErrorHistory { file, title, pairs } => {
                per_preset(case_dir, &runs, &presets, file, title, &mut figures, |name, caption, mine| {
                    plots::error_history(name, caption, mine, pairs)
                })?;
            }
            Figure::Convergence { file, title, metrics, slope } => {
                let name = format!("{file}.svg");
                let svg = plots::convergence(&name, title, &runs, metrics, *slope)?;
                io::write_atomic(&case_dir.join(&name), svg.as_bytes())?;
                figures.push(FigureFile { file: name, caption: title.clone() });
            }
            Figure::Cost { file, title, metric } => {
                let name = format!("{file}.svg");
                let svg = plots::cost(&name, title, &runs, metric)?;
                io::write_atomic(&case_dir.join(&name), svg.as_bytes())?;
                figures.push(FigureFile { file: name, caption: title.clone() });
            }
            Figure::Snapshots { file, title, presets, dx, cut_axis } => {
                fig.check()
                    .map_err(|m| HarnessError::case(&results.case, format!("figure `{file}`: {m}")))?;
                let spec = SnapshotSpec {
                    file,
                    title,
                    presets,
                    dx: *dx,
                    cut_axis: cut_axis.unwrap_or(Figure::DEFAULT_CUT_AXIS),
                };
                snapshot_figures(case_dir, &runs, &spec, &mut figures)?;
            }
        }
    }
    let page = html::case_page(results, record, &figures, comparison);
    io::write_atomic(&case_dir.join("index.html"), page.as_bytes())?;
    Ok(figures)
}

/// Draws one figure per preset (`<file>_<preset>.svg`, runs coarse to fine) with `draw`.
fn per_preset(
    case_dir: &Path,
    runs: &[&RunResult],
    presets: &[&str],
    file: &str,
    title: &str,
    figures: &mut Vec<FigureFile>,
    draw: impl Fn(&str, &str, &[&RunResult]) -> Result<String>,
) -> Result<()> {
    for p in presets {
        let mut mine: Vec<&RunResult> = runs.iter().copied().filter(|r| r.preset == *p).collect();
        mine.sort_by(|a, b| b.dx.total_cmp(&a.dx));
        let name = format!("{file}_{p}.svg");
        let caption = format!("{title} — preset {p}");
        let svg = draw(&name, &caption, &mine)?;
        io::write_atomic(&case_dir.join(&name), svg.as_bytes())?;
        figures.push(FigureFile { file: name, caption });
    }
    Ok(())
}

/// The fields of a [`Figure::Snapshots`], its cut axis resolved.
struct SnapshotSpec<'a> {
    file: &'a str,
    title: &'a str,
    presets: &'a [String],
    dx: Option<f64>,
    cut_axis: usize,
}

/// Draws the snapshot figures of `spec.presets` (see [`Figure::Snapshots`]): one SVG per
/// snapshot time, the presets' panels side by side; a 3D run cut by the plane normal to
/// `spec.cut_axis` through the fluid's centroid.
fn snapshot_figures(
    case_dir: &Path,
    runs: &[&RunResult],
    spec: &SnapshotSpec,
    figures: &mut Vec<FigureFile>,
) -> Result<()> {
    let SnapshotSpec { file, title, presets, dx, cut_axis } = *spec;
    let with_snapshots: Vec<(&RunResult, crate::snapshots::SnapshotFile)> = runs
        .iter()
        .filter(|r| presets.contains(&r.preset) && dx.is_none_or(|d| same_spacing(r.dx, d)))
        .filter_map(|r| crate::snapshots::load(case_dir, &r.slug()).map(|s| (*r, s)))
        .collect();
    let Some(finest) = with_snapshots.iter().map(|(r, _)| r.dx).min_by(f64::total_cmp) else {
        return Ok(());
    };
    // Presets in the figure's order, at the chosen spacing.
    let shown: Vec<&crate::snapshots::SnapshotFile> = presets
        .iter()
        .filter_map(|p| with_snapshots.iter().find(|(r, _)| &r.preset == p && same_spacing(r.dx, finest)))
        .map(|(_, s)| s)
        .collect();
    let times = shown.iter().map(|s| s.frames.len()).max().unwrap_or(0);
    for i in 0..times {
        let panels: Vec<(String, f64, crate::snapshots::View)> = shown
            .iter()
            .filter_map(|s| {
                let f = s.frames.get(i)?;
                let view = f.view(cut_axis, s.dx);
                let note = if s.status == "ok" { "" } else { " (diverged later)" };
                let plane = view.cut.map_or(String::new(), |c| {
                    format!(", cut {} = {} m", AXES[c.axis], plane_coordinate(c.centre, s.dx))
                });
                Some((format!("{}, t = {:.4} s{plane}{note}", s.preset, f.time), f.time, view))
            })
            .collect();
        let t = panels.first().map_or(0.0, |p| p.1);
        let name = format!("{file}_{i}.svg");
        let mut caption = format!(
            "{title} — t = {t:.4} s, dx = {}; colour: pressure [Pa], one scale for both panels \
             (clipped to the 1st–99th percentile)",
            crate::numbers::format_dx(finest)
        );
        let mut heading = format!("{title}, dx = {}", crate::numbers::format_dx(finest));
        if let Some((_, _, view)) = panels.iter().find(|(_, _, v)| v.cut.is_some()) {
            let [n, h, v] = [cut_axis, view.axes[0], view.axes[1]].map(|a| AXES[a]);
            heading.push_str(&format!("; cut −Δx/2 ≤ {n} − {n}_c < Δx/2"));
            caption.push_str(&format!(
                "; 3D: the particles within Δx/2 of the plane {n} = {n}_c through the fluid's \
                 centroid (−Δx/2 ≤ {n} − {n}_c < Δx/2, {n}_c in each panel's title), seen in the \
                 {h}–{v} plane"
            ));
        }
        let views: Vec<(String, &crate::snapshots::View)> =
            panels.iter().map(|(label, _, view)| (label.clone(), view)).collect();
        let svg = plots::snapshots(&name, &heading, &views)?;
        io::write_atomic(&case_dir.join(&name), svg.as_bytes())?;
        figures.push(FigureFile { file: name, caption });
    }
    Ok(())
}

/// The coordinate `c` \[m\] of a cut plane, to a hundredth of the spacing `dx` (no `-0`).
fn plane_coordinate(c: f64, dx: f64) -> String {
    let digits = (2.0 - dx.log10().floor()).clamp(0.0, 12.0) as usize;
    let scale = 10f64.powi(digits as i32);
    let rounded = (c * scale).round() / scale;
    format!("{:.digits$}", if rounded == 0.0 { 0.0 } else { rounded })
}

/// Every `<out>/<case>/results.json` present, sorted by case name.
pub fn collect(out: &Path) -> Result<Vec<(CaseResults, Option<CaseRecord>)>> {
    collect_cases(out, None)
}

/// Like [`collect`], restricted to the directories named in `cases` when given (see
/// [`case_dirs`]).
pub fn collect_cases(out: &Path, cases: Option<&[String]>) -> Result<Vec<(CaseResults, Option<CaseRecord>)>> {
    let mut found = Vec::new();
    for d in case_dirs(out, cases) {
        let results: CaseResults = io::read_json(&d.join("results.json"))?;
        let record: Option<CaseRecord> = io::read_json(&d.join("provenance.json")).ok();
        found.push((results, record));
    }
    Ok(found)
}

/// A loaded baseline: the directory and the results found there.
#[derive(Debug, Clone, PartialEq)]
pub struct Baseline {
    /// The previous `reports/` directory.
    pub dir: PathBuf,
    /// Its results files.
    pub results: Vec<CaseResults>,
}

impl Baseline {
    /// Reads `dir` (see [`baseline::load`]); an empty directory is an error.
    pub fn load(dir: &Path, cases: Option<&[String]>) -> Result<Self> {
        Ok(Baseline { dir: dir.to_path_buf(), results: baseline::load(dir, cases)? })
    }
}

/// What [`render`] renders besides the results.
#[derive(Debug, Clone, Default)]
pub struct RenderOptions {
    /// Render only these cases (the case files of `validation/`); every
    /// `<out>/<case>/results.json` when `None`.
    pub cases: Option<Vec<String>>,
    /// Compare with this baseline.
    pub baseline: Option<Baseline>,
    /// Pages beside the cases that the index links (the stability envelope's).
    pub extras: Vec<ExtraPage>,
    /// Wall time of the last invocation that ran runs \[s\] (shown beside the runs' summed
    /// times).
    pub elapsed_s: Option<f64>,
}

/// What [`render`] produced.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The results rendered, sorted by case name.
    pub results: Vec<CaseResults>,
    /// The comparison with the baseline, when one was given.
    pub comparison: Option<Comparison>,
}

/// The overview figure beside `index.html`.
pub const OVERVIEW: &str = "overview.svg";

/// Re-renders every case page, `summary.json` and `index.html` in `out` from the results
/// files there; returns the results found.
pub fn render_all(out: &Path) -> Result<Vec<CaseResults>> {
    Ok(render(out, &RenderOptions::default())?.results)
}

/// Renders every case page, `summary.json`, `summary.md` and `index.html` in `out` from the
/// results files there (restricted to `opts.cases`), compared with `opts.baseline`; the
/// index links `opts.extras`.
pub fn render(out: &Path, opts: &RenderOptions) -> Result<Rendered> {
    let found = collect_cases(out, opts.cases.as_deref())?;
    let results: Vec<CaseResults> = found.iter().map(|f| f.0.clone()).collect();
    let comparison =
        opts.baseline.as_ref().map(|b| baseline::compare(&b.dir, &results, &b.results, NoiseBand::default()));
    for (results, record) in &found {
        render_case(&out.join(&results.case), results, record.as_ref(), comparison.as_ref())?;
    }
    let summary = Summary { elapsed_s: opts.elapsed_s, ..Summary::of(&results) };
    io::write_json(&out.join("summary.json"), &summary)?;
    let records: Vec<Option<&CaseRecord>> = found.iter().map(|f| f.1.as_ref()).collect();
    let header =
        Header::of(&results, &records, opts.elapsed_s, opts.baseline.as_ref().map(|b| b.dir.as_path()));
    let matrix = Matrix::of(&results, &records);
    let curves = matrix.curves(&results);
    let overview = (!curves.is_empty()).then_some(OVERVIEW);
    if overview.is_some() {
        let title = "Headline error against wall time, every case and scheme";
        let svg = plots::overview(OVERVIEW, title, &curves)?;
        io::write_atomic(&out.join(OVERVIEW), svg.as_bytes())?;
    } else {
        // No stale figure beside an index that does not show it.
        let _ = std::fs::remove_file(out.join(OVERVIEW));
    }
    let parts = html::IndexParts { header: &header, matrix: &matrix, overview, extras: &opts.extras };
    let page = html::index_page(&results, &summary, comparison.as_ref(), &parts);
    io::write_atomic(&out.join("index.html"), page.as_bytes())?;
    let md = markdown::summary(&results, &header, &matrix, &summary, comparison.as_ref());
    io::write_atomic(&out.join("summary.md"), md.as_bytes())?;
    Ok(Rendered { results, comparison })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::testing::Scratch;
    use crate::provenance::Provenance;

    /// A small hand-written results.json (two spacings, one diverged tuned run).
    const FIXTURE: &str = r#"{
      "case": "elliptical_drop", "scheme": "isph", "tier": "quick",
      "runs": [
        { "scheme": "isph", "preset": "paper", "dx": 0.04, "particles": 1976, "steps": 400, "wall_s": 1.2,
          "status": "ok",
          "metrics": { "particles": 1976, "a_rel_err_max": 0.012, "b_rel_err_max": 0.016, "pc_rel_err_final": 0.04, "ke_drift": 0.003 },
          "series": { "t": [0.0, 0.004, 0.008], "b_moment": [1.003, 1.47, 2.01], "b_extent": [0.98, 1.45, 1.99],
                      "b_ref": [1.0, 1.4647738, 1.9993020], "a_moment": [1.003, 0.69, 0.51], "a_ref": [1.0, 0.6827, 0.5002],
                      "p": [5.0e6, 2.9e6, 1.1e6], "pc_ref": [5.0e6, 2.93e6, 1.108e6] } },
        { "scheme": "isph", "preset": "paper", "dx": 0.02, "particles": 7860, "steps": 400, "wall_s": 6.5,
          "status": "ok",
          "metrics": { "particles": 7860, "a_rel_err_max": 0.004, "b_rel_err_max": 0.004, "pc_rel_err_final": 0.02, "ke_drift": 0.001 },
          "series": { "t": [0.0, 0.004, 0.008], "b_moment": [1.001, 1.466, 2.003], "b_extent": [0.99, 1.46, 1.995],
                      "b_ref": [1.0, 1.4647738, 1.9993020], "a_moment": [1.001, 0.684, 0.502], "a_ref": [1.0, 0.6827, 0.5002],
                      "p": [5.0e6, 2.92e6, 1.105e6], "pc_ref": [5.0e6, 2.93e6, 1.108e6] } },
        { "scheme": "isph", "preset": "tuned", "dx": 0.04, "particles": 1976, "steps": 120, "wall_s": 0.4,
          "status": "diverged: diverged in stage `ppe` at step 120 (t = 2.4e-3 s): PPE did not converge",
          "metrics": { "particles": 1976, "b_rel_err_max": null },
          "series": { "t": [0.0, 0.002], "b_moment": [1.003, null] } }
      ],
      "convergence": { "b_rel_err_max": { "order": 2.0, "preset": "paper", "dx": [0.04, 0.02], "values": [0.016, 0.004], "by_preset": { "paper": 2.0 } } },
      "checks": [
        { "name": "b error (moments, max over history) at dx=0.02 ≤ 1%", "value": 0.004, "threshold": 0.01, "pass": true,
          "judges": { "metric": "b_rel_err_max", "kind": "max", "select": { "dx": 0.02, "preset": "paper" } } },
        { "name": "tuned b error ≤ 1%", "value": null, "threshold": 0.01, "pass": false, "note": "diverged: isph-tuned_dx0.04" }
      ]
    }"#;

    #[test]
    fn renders_case_page_index_and_svgs_from_fixture() {
        let dir = Scratch::new("report");
        let out = dir.path();
        let results: CaseResults = serde_json::from_str(FIXTURE).unwrap();
        io::write_json(&out.join("elliptical_drop/results.json"), &results).unwrap();
        let case = crate::case::testing::committed("elliptical_drop");
        let record = CaseRecord {
            case,
            provenance: Provenance {
                git_commit: Some("0123abc".into()),
                threads: 2,
                date_utc: "2025-01-01T00:00:00Z".into(),
                ..Default::default()
            },
            scene_hashes: [("isph-paper_dx0.04".to_string(), "f00d".to_string())].into(),
        };
        io::write_json(&out.join("elliptical_drop/provenance.json"), &record).unwrap();

        let all = render_all(out).unwrap();
        assert_eq!(all.len(), 1);
        let page = std::fs::read_to_string(out.join("elliptical_drop/index.html")).unwrap();
        for needle in [
            "<!DOCTYPE html>",
            "elliptical_drop",
            "isph-<wbr>paper_<wbr>dx0.02",
            "b_<wbr>rel_<wbr>err_<wbr>max",
            "0.400 %",
            "1.00 %",
            "class=\"fail\"",
            "class=\"pass\"",
            "diverged: isph-tuned_dx0.04",
            "history_b_paper.svg",
            "convergence.svg",
            "cost.svg",
            "erratum 1",
            "0123abc",
            "2025-01-01T00:00:00Z",
            "f00d",
            "&quot;bicgstab&quot;",
            "2.00",
        ] {
            assert!(page.contains(needle), "case page lacks {needle:?}");
        }
        assert!(!page.contains("<script"), "self-contained, no scripts");
        for svg in [
            "history_b_paper.svg",
            "history_a_tuned.svg",
            "pressure_paper.svg",
            "convergence.svg",
            "cost.svg",
        ] {
            let text = std::fs::read_to_string(out.join("elliptical_drop").join(svg)).unwrap();
            assert!(text.starts_with("<svg") && text.contains("</svg>"), "{svg}");
        }
        let conv = std::fs::read_to_string(out.join("elliptical_drop/convergence.svg")).unwrap();
        assert!(conv.contains("b_rel_err_max (isph · paper): order 2.00"), "legend shows the fitted order");
        let cost = std::fs::read_to_string(out.join("elliptical_drop/cost.svg")).unwrap();
        // The first series' line, in the palette's first colour (the axes are black).
        let line = "<polyline fill=\"none\" opacity=\"1\" stroke=\"#1F77B4\"";
        assert!(cost.contains("isph · paper") && cost.contains(line), "one line per scheme and preset");
        assert!(conv.contains("reference slope dx^2"));
        let hist = std::fs::read_to_string(out.join("elliptical_drop/history_b_paper.svg")).unwrap();
        assert!(hist.contains("b_ref (reference)") && hist.contains("dx=0.02"));

        let index = std::fs::read_to_string(out.join("index.html")).unwrap();
        for needle in [
            "elliptical_drop/index.html",
            "isph",
            "0.04, 0.02",
            "1 / 2",
            "FAIL",
            "2.00",
            // The header, the matrix (the judged value with its bound) and the overview.
            "0123abc",
            "2025-01-01T00:00:00Z",
            "Schemes by case",
            "<b>0.400 %</b> ≤ 1.00 % <small>pass</small>",
            "paper, dx 0.02",
            "src=\"overview.svg\"",
        ] {
            assert!(index.contains(needle), "index lacks {needle:?}");
        }
        let overview = std::fs::read_to_string(out.join("overview.svg")).unwrap();
        assert!(overview.contains("elliptical_drop") && overview.contains("headline error [%]"));
        let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
        for needle in ["- commit: 0123abc", "| case | headline metric | ISPH |", "**0.400 %** ≤ 1.00 % ✅"]
        {
            assert!(md.contains(needle), "summary.md lacks {needle:?}:\n{md}");
        }
        let summary: crate::results::Summary = io::read_json(&out.join("summary.json")).unwrap();
        assert!(!summary.pass);
        assert_eq!((summary.passed, summary.failed), (1, 1));
        assert_eq!(summary.cases[0].diverged, 1);
    }

    #[test]
    fn snapshot_figures_pair_the_presets_per_time() {
        let dir = Scratch::new("report-snapshots");
        let case = crate::case::testing::committed("rotating_square");
        let mut results: CaseResults = serde_json::from_str(FIXTURE).unwrap();
        results.case = "rotating_square".into();
        results.runs.truncate(2);
        results.runs[0].preset = "shifting".into();
        results.runs[1].preset = "no_shifting".into();
        for r in &mut results.runs {
            r.dx = 0.02;
        }
        for (r, status) in results.runs.iter().zip(["ok", "diverged: at step 9"]) {
            let frame = |t: f64| crate::snapshots::Snapshot {
                time: t,
                step: 1,
                x: vec![0.0, 0.1],
                y: vec![0.0, 0.1],
                z: Vec::new(),
                p: vec![-1.0, 0.0],
            };
            let file = crate::snapshots::SnapshotFile {
                slug: r.slug(),
                preset: r.preset.clone(),
                dx: r.dx,
                status: status.into(),
                frames: vec![frame(0.0), frame(0.05)],
            };
            crate::snapshots::store(dir.path(), &file).unwrap();
        }
        let record = CaseRecord { case, provenance: Provenance::default(), scene_hashes: Default::default() };
        let figs = render_case(dir.path(), &results, Some(&record), None).unwrap();
        let snaps: Vec<&FigureFile> = figs.iter().filter(|f| f.file.starts_with("snapshots")).collect();
        // Two times of the mu = 1000 pair; the inviscid pair has no snapshots: no figure.
        assert_eq!(
            snaps.iter().map(|f| f.file.as_str()).collect::<Vec<_>>(),
            ["snapshots_0.svg", "snapshots_1.svg"]
        );
        assert!(snaps[1].caption.contains("t = 0.0500 s"), "{}", snaps[1].caption);
        let svg = std::fs::read_to_string(dir.path().join("snapshots_1.svg")).unwrap();
        assert!(
            svg.contains("shifting, t = 0.0500 s")
                && svg.contains("no_shifting, t = 0.0500 s (diverged later)")
        );
        assert!(
            !svg.contains("cut") && svg.contains(">\nx [m]\n<") && svg.contains(">\ny [m]\n<"),
            "2D: no cut"
        );
        let page = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(page.contains("snapshots_1.svg"));
    }

    /// 3D snapshots are cut by the plane y = y_c (the default `cut_axis`) through the
    /// fluid's centroid, and the figure says so: a lattice ball of 257 particles shows the
    /// 49 of its central plane in each panel, in x–z.
    #[test]
    fn snapshot_figures_cut_3d_runs() {
        let dir = Scratch::new("report-snapshots-3d");
        let mut case = crate::case::testing::committed("rotating_square");
        case.figures = vec![Figure::Snapshots {
            file: "cut".into(),
            title: "Ball".into(),
            presets: vec!["shifting".into(), "no_shifting".into()],
            dx: None,
            cut_axis: None,
        }];
        let mut results: CaseResults = serde_json::from_str(FIXTURE).unwrap();
        results.runs.truncate(2);
        results.runs[0].preset = "shifting".into();
        results.runs[1].preset = "no_shifting".into();
        for r in &mut results.runs {
            r.dx = 0.02;
            let file = crate::snapshots::SnapshotFile {
                slug: r.slug(),
                preset: r.preset.clone(),
                dx: r.dx,
                status: "ok".into(),
                frames: vec![crate::snapshots::tests::ball(0.02, [0.1, 0.2, 0.3])],
            };
            crate::snapshots::store(dir.path(), &file).unwrap();
        }
        let record = CaseRecord { case, provenance: Provenance::default(), scene_hashes: Default::default() };
        let figs = render_case(dir.path(), &results, Some(&record), None).unwrap();
        assert_eq!(figs.len(), 1);
        assert!(figs[0].caption.contains("plane y = y_c") && figs[0].caption.contains("x–z plane"));
        let svg = std::fs::read_to_string(dir.path().join("cut_0.svg")).unwrap();
        assert_eq!(svg.matches("<circle").count(), 2 * 49, "the central plane of each ball");
        assert!(svg.contains("shifting, t = 0.5000 s, cut y = 0.2000 m"), "{svg}");
        assert!(svg.contains("cut −Δx/2 ≤ y − y_c &lt; Δx/2"));
        assert!(svg.contains(">\nx [m]\n<") && svg.contains(">\nz [m]\n<") && !svg.contains(">\ny [m]\n<"));
        // A cut axis beyond z (a hand-edited provenance.json) is an error naming the field.
        let mut bad = record.clone();
        if let Figure::Snapshots { cut_axis, .. } = &mut bad.case.figures[0] {
            *cut_axis = Some(3);
        }
        let e = render_case(dir.path(), &results, Some(&bad), None).unwrap_err().to_string();
        assert!(e.contains("figure `cut`: `snapshots.cut_axis` = 3: must be 0, 1 or 2"), "{e}");
    }

    #[test]
    fn plane_coordinates_are_rounded_to_the_spacing() {
        assert_eq!(plane_coordinate(0.012_345, 0.02), "0.0123");
        assert_eq!(plane_coordinate(-1e-17, 0.02), "0.0000");
        assert_eq!(plane_coordinate(0.2, 0.01), "0.2000");
        assert_eq!(plane_coordinate(1.5e-3, 1e-4), "0.001500");
        assert_eq!(plane_coordinate(12.0, 2.0), "12.00");
    }

    #[test]
    fn renders_without_a_provenance_record() {
        let dir = Scratch::new("report-bare");
        let results: CaseResults = serde_json::from_str(FIXTURE).unwrap();
        let figs = render_case(dir.path(), &results, None, None).unwrap();
        assert!(figs.is_empty());
        let page = std::fs::read_to_string(dir.path().join("index.html")).unwrap();
        assert!(page.contains("isph-<wbr>paper_<wbr>dx0.04"));
    }
}
