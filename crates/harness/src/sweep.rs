//! Expands a case into runs (tier spacings × presets): the scene, slug and hash of each.

use crate::cache::sha256_hex;
use crate::case::Case;
use crate::checks::same_spacing;
use crate::error::{HarnessError, Result};
use crate::patch::merge_patch;
use crate::results::{slug, start_slug};
use crate::tier::Tier;

/// One parameter point of a sweep (or of a study), with its effective scene.
#[derive(Debug, Clone)]
pub struct RunSpec {
    /// The case (or study) the run belongs to, for error messages.
    pub case: String,
    /// Scheme (the key of the scene's `scheme` object).
    pub scheme: String,
    /// Preset name.
    pub preset: String,
    /// Spacing \[m\].
    pub dx: f64,
    /// The jitter seed of a perturbed start (none for the unperturbed run).
    pub start: Option<u64>,
    /// Stable slug, e.g. `isph-paper_dx0.02`.
    pub slug: String,
    /// The parsed and validated effective scene.
    pub scene: meniscus::Scene,
    /// The effective scene as JSON (canonical: the typed scene re-serialised, defaults
    /// included), which is what `hash` covers.
    pub scene_json: serde_json::Value,
    /// SHA-256 of the build fingerprint and the canonical scene JSON: a cached run is
    /// reused only for the same scene computed by the same build of the solver.
    pub hash: String,
}

impl RunSpec {
    /// The cache record of this run once it finished: its summary, probes and snapshots,
    /// and how it ran (CPU seconds, threads).
    pub fn record(
        &self,
        summary: meniscus::Summary,
        probes: crate::cache::CachedProbes,
        snapshots: Vec<crate::snapshots::Snapshot>,
        cpu_s: Option<f64>,
        threads: usize,
    ) -> crate::cache::RunRecord {
        crate::cache::RunRecord {
            completed: true,
            slug: self.slug.clone(),
            scheme: self.scheme.clone(),
            preset: self.preset.clone(),
            dx: self.dx,
            scene_hash: self.hash.clone(),
            scene: self.scene_json.clone(),
            summary,
            probes,
            snapshots,
            cpu_s,
            threads: Some(threads),
        }
    }

    /// The run `slug` of `case` (or of a study) with preset `preset` at spacing `dx` and the
    /// checked `scene`, which it canonicalises and hashes.
    pub fn new(case: &str, slug: String, preset: &str, dx: f64, scene: meniscus::Scene) -> Result<RunSpec> {
        let canonical = serde_json::to_value(&scene)
            .map_err(|e| HarnessError::case(case, format!("run {slug}: scene does not serialise: {e}")))?;
        let hash = sha256_hex(&format!("{}\n{canonical}", build_fingerprint()));
        Ok(RunSpec {
            case: case.to_string(),
            scheme: scene.scheme.key().to_string(),
            preset: preset.to_string(),
            dx,
            start: None,
            slug,
            scene,
            scene_json: canonical,
            hash,
        })
    }

    /// [`RunSpec::new`] from the scene's JSON, which the solver's parser checks (its error
    /// names the case and the run).
    pub fn from_json(
        case: &str,
        slug: String,
        preset: &str,
        dx: f64,
        scene: &serde_json::Value,
    ) -> Result<RunSpec> {
        let parsed = meniscus::Scene::from_json(&scene.to_string())
            .map_err(|source| HarnessError::Scene { case: case.to_string(), run: slug.clone(), source })?;
        RunSpec::new(case, slug, preset, dx, parsed)
    }
}

/// The effective scene JSON of `preset` at spacing `dx`: template, merge patch, `dx`, and
/// the fixed Δt scaled down with `dx` when the sweep asks for it.
pub fn effective_scene(case: &Case, preset: &str, dx: f64) -> Result<serde_json::Value> {
    let p = case
        .sweep
        .presets
        .iter()
        .find(|p| p.name == preset)
        .ok_or_else(|| HarnessError::case(&case.case, format!("no preset `{preset}`")))?;
    let mut scene = case.scene.clone();
    merge_patch(&mut scene, &p.patch);
    let template_dx = scene["dx"].as_f64();
    scene["dx"] = serde_json::json!(dx);
    if case.sweep.scale_dt_with_dx
        && let (Some(dx0), Some(dt0)) = (template_dx, scene["time"]["step"]["fixed"].as_f64())
        && dx < dx0
    {
        scene["time"]["step"]["fixed"] = serde_json::json!(dt0 * dx / dx0);
    }
    Ok(scene)
}

/// The scheme of an effective scene (the key of its `scheme` object; the case's when absent).
fn scheme_of(case: &Case, scene: &serde_json::Value) -> String {
    scene["scheme"].as_object().and_then(|m| m.keys().next().cloned()).unwrap_or_else(|| case.scheme.clone())
}

/// Builds the run of `preset` at `dx` (the scene is checked by the solver's parser).
pub fn spec(case: &Case, preset: &str, dx: f64) -> Result<RunSpec> {
    let value = effective_scene(case, preset, dx)?;
    RunSpec::from_json(&case.case, slug(&scheme_of(case, &value), preset, dx), preset, dx, &value)
}

/// The solver's fingerprint (SHA-256 of its sources, manifest, `Cargo.lock` and the
/// compiler version; [`meniscus::SOLVER_FINGERPRINT`]): any change of the solver's code invalidates cached runs,
/// a change of the harness alone (metrics, checks, reports) does not — the records hold the
/// runs' probes, from which the harness recomputes everything.
pub fn build_fingerprint() -> &'static str {
    meniscus::SOLVER_FINGERPRINT
}

/// The run of `preset` at `dx` from the start perturbed with jitter seed `seed`
/// (`perturbed_starts`): every fluid body's lattice jittered by `fraction · dx`.
pub fn perturbed_spec(case: &Case, preset: &str, dx: f64, seed: u64) -> Result<RunSpec> {
    let mut value = effective_scene(case, preset, dx)?;
    let Some(fraction) = case
        .sweep
        .presets
        .iter()
        .find(|p| p.name == preset)
        .and_then(|p| p.perturbed_starts.as_ref())
        .map(|s| s.fraction)
    else {
        return Err(HarnessError::case(&case.case, format!("preset `{preset}` has no `perturbed_starts`")));
    };
    let slug = start_slug(&slug(&scheme_of(case, &value), preset, dx), Some(seed));
    let fluid: Vec<&mut serde_json::Value> = value["bodies"]
        .as_array_mut()
        .map(|bodies| bodies.iter_mut().filter(|b| b["role"] == "fluid").collect())
        .unwrap_or_default();
    if fluid.is_empty() {
        return Err(HarnessError::case(
            &case.case,
            format!(
                "run {slug}: `perturbed_starts` jitters the bodies with role `fluid`; the scene has none"
            ),
        ));
    }
    for body in fluid {
        if body.get("jitter").is_some() {
            return Err(HarnessError::case(
                &case.case,
                format!("run {slug}: a fluid body already has `jitter`; a perturbed start would replace it"),
            ));
        }
        body["jitter"] = serde_json::json!({"fraction": fraction, "seed": seed});
    }
    let mut run = RunSpec::from_json(&case.case, slug, preset, dx, &value)?;
    run.start = Some(seed);
    Ok(run)
}

/// Every run of `case` in `tier`: spacings from coarse to fine, presets in file order, each
/// preset's perturbed starts after its run.
pub fn expand(case: &Case, tier: Tier) -> Result<Vec<RunSpec>> {
    if case.spacings(tier).is_empty() {
        return Err(HarnessError::case(&case.case, format!("no spacings for tier `{tier}` in sweep.dx")));
    }
    let presets: Vec<&crate::case::Preset> = case.presets(tier).collect();
    // The union of the presets' spacings (a preset may have its own, `presets[].dx`).
    let dx = case.selected_spacings(None, tier);
    let mut out = Vec::with_capacity(dx.len() * presets.len());
    for &d in &dx {
        for p in presets.iter().filter(|p| case.preset_spacings(p, tier).iter().any(|&s| same_spacing(s, d)))
        {
            out.push(spec(case, &p.name, d)?);
            for &seed in p.starts_at(d) {
                out.push(perturbed_spec(case, &p.name, d, seed)?);
            }
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::case::Case;
    use crate::case::testing::committed;

    #[test]
    fn expands_tier_into_slugged_runs() {
        let runs = expand(&committed("elliptical_drop"), Tier::Quick).unwrap();
        let slugs: Vec<&str> = runs.iter().map(|r| r.slug.as_str()).collect();
        assert_eq!(
            slugs,
            [
                "isph-paper_dx0.04",
                "isph-tuned_dx0.04",
                "isph-tuned_h18_dx0.04",
                "wcsph-wcsph_paper_dx0.04",
                "wcsph-wcsph_tuned_dx0.04",
                "mps-mps_paper_dx0.04",
                "mps-mps_dx0.04",
                "isph-paper_dx0.02",
                "isph-tuned_dx0.02",
                "isph-tuned_h18_dx0.02",
                "wcsph-wcsph_paper_dx0.02",
                "wcsph-wcsph_tuned_dx0.02",
                "mps-mps_paper_dx0.02",
                "mps-mps_dx0.02"
            ]
        );
        assert!((runs[7].scene.dx - 0.02).abs() < 1e-15);
        // The tuned preset's merge patch replaces Xu shifting by Fickian shifting.
        assert_eq!(runs[1].scene_json["scheme"]["isph"]["divergence"], "corrected");
        assert!(runs[1].scene_json["scheme"]["isph"]["shifting"].get("xu").is_none());
        assert_eq!(runs[1].scene_json["scheme"]["isph"]["shifting"]["fickian"]["coefficient"], 2.0);
        assert!(runs[0].scene_json["scheme"]["isph"]["shifting"].get("xu").is_some());
        // tuned_h18 widens the kernel.
        assert_eq!(runs[2].scene_json["kernel"]["h_over_dx"], 1.8);
        // The WCSPH presets replace the scheme (and the fixed step by the adaptive one).
        assert!(runs[3].scene_json["scheme"].get("isph").is_none());
        assert_eq!(runs[3].scene_json["scheme"]["wcsph"]["sound_speed"], 1000.0);
        assert!(runs[3].scene_json["time"]["step"].get("adaptive").is_some());
        assert_eq!(runs[0].hash.len(), 64);
        assert_ne!(runs[0].hash, runs[1].hash);
        assert_ne!(runs[0].hash, runs[7].hash);
        // The MPS presets replace the scheme too.
        assert_eq!(runs[6].scene_json["scheme"]["mps"]["gamma"], 0.01);
        // Seven presets at 0.04 … 0.005, the 20 ms run at 0.01, tuned_h18 alone at 0.0025.
        let full = expand(&committed("elliptical_drop"), Tier::Full).unwrap();
        assert_eq!(full.len(), 30);
        assert_eq!(full[17].slug, "isph-tuned_h18_20ms_dx0.01");
        assert_eq!(full[29].slug, "isph-tuned_h18_dx0.0025");
        // Δt scales with dx below the template's 0.02 (CFL number kept), not above it.
        let dt = |r: &RunSpec| r.scene_json["time"]["step"]["fixed"].as_f64().unwrap();
        assert!((dt(&full[0]) - 2e-5).abs() < 1e-18, "dx = 0.04 keeps the paper's dt");
        assert!((dt(&full[7]) - 2e-5).abs() < 1e-18);
        assert!((dt(&full[22]) - 5e-6).abs() < 1e-18, "dx = 0.005: {}", dt(&full[22]));
        assert!((dt(&full[29]) - 2.5e-6).abs() < 1e-18, "dx = 0.0025: {}", dt(&full[29]));
    }

    /// A preset with its own spacings runs them, and only it runs the spacings the sweep
    /// lacks; a check across spacings on it may list a tier where the sweep has one.
    #[test]
    fn a_preset_may_run_its_own_spacings() {
        let mut v = serde_json::to_value(committed("elliptical_drop")).unwrap();
        v["sweep"]["dx"]["quick"] = serde_json::json!([0.04]);
        v["sweep"]["presets"][1]["dx"] = serde_json::json!({"quick": [0.04, 0.02, 0.01]});
        v["checks"][0] = serde_json::json!({"name": "tuned converges", "kind": "decreasing", "metric": "b_rel_err_max",
                                            "select": {"preset": "tuned"}, "tiers": ["quick"]});
        let c = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap();
        let runs = expand(&c, Tier::Quick).unwrap();
        let slugs: Vec<&str> = runs.iter().map(|r| r.slug.as_str()).collect();
        assert_eq!(slugs.len(), 10, "{slugs:?}");
        assert_eq!(slugs[7..], ["isph-tuned_dx0.02", "isph-tuned_h18_dx0.02", "isph-tuned_dx0.01"]);
        assert!((runs[9].scene.dx - 0.01).abs() < 1e-15);
        // Other tiers keep the sweep's spacings for it (0.04, 0.02: 7 presets each), and
        // tuned_h18 its own (with its 20 ms run at 0.01).
        assert_eq!(expand(&c, Tier::Default).unwrap().len(), 17);
        // The same check on the paper preset, which has one quick spacing, is refused.
        v["checks"][0]["select"]["preset"] = "paper".into();
        let e = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap_err();
        assert!(e.to_string().contains("one spacing"), "{e}");
        v["checks"][0]["select"]["preset"] = "tuned".into();
        v["sweep"]["presets"][1]["dx"] = serde_json::json!({"quick": []});
        let e = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap_err();
        assert!(e.to_string().contains("`dx.quick` is empty"), "{e}");
    }

    #[test]
    fn perturbed_starts_add_jittered_runs() {
        let mut c = committed("elliptical_drop");
        let mut v = serde_json::to_value(&c).unwrap();
        v["sweep"]["presets"][0]["perturbed_starts"] =
            serde_json::json!({"dx": [0.02], "seeds": [1, 2], "reason": "the final pressure is a draw"});
        c = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap();
        let runs = expand(&c, Tier::Quick).unwrap();
        let slugs: Vec<&str> = runs.iter().map(|r| r.slug.as_str()).collect();
        assert_eq!(
            slugs[7..10],
            ["isph-paper_dx0.02", "isph-paper_dx0.02_start1", "isph-paper_dx0.02_start2"]
        );
        assert_eq!(runs.len(), 16, "two more runs at 0.02, none at 0.04");
        assert_eq!((runs[8].start, runs[9].start), (Some(1), Some(2)));
        let jitter = &runs[9].scene_json["bodies"][0]["jitter"];
        assert_eq!((jitter["fraction"].as_f64(), jitter["seed"].as_u64()), (Some(1e-12), Some(2)));
        assert!(runs[7].scene_json["bodies"][0].get("jitter").is_none_or(|j| j.is_null()));
        assert!(runs[7].hash != runs[8].hash && runs[8].hash != runs[9].hash);
        // Malformed ensembles are rejected when the case loads, naming the field.
        for (bad, field) in [
            (serde_json::json!({"dx": [0.03], "seeds": [1], "reason": "r"}), "perturbed_starts.dx"),
            (serde_json::json!({"dx": [0.02], "seeds": [], "reason": "r"}), "perturbed_starts.seeds"),
            (serde_json::json!({"dx": [0.02], "seeds": [3, 3], "reason": "r"}), "perturbed_starts.seeds"),
            (serde_json::json!({"dx": [0.02], "seeds": [1], "reason": " "}), "perturbed_starts.reason"),
            (
                serde_json::json!({"dx": [0.02], "seeds": [1], "fraction": 0.1, "reason": "r"}),
                "perturbed_starts.fraction",
            ),
        ] {
            v["sweep"]["presets"][0]["perturbed_starts"] = bad;
            let e = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap_err().to_string();
            assert!(e.contains(field) && e.contains("`paper`"), "{field}: {e}");
        }
        // A spacing of a tier the preset does not run in would never run.
        v["sweep"]["presets"][0]["tiers"] = serde_json::json!(["quick"]);
        v["sweep"]["presets"][0]["perturbed_starts"] =
            serde_json::json!({"dx": [0.005], "seeds": [1], "reason": "r"});
        let e = Case::from_json(&v.to_string(), std::path::Path::new("x.json")).unwrap_err().to_string();
        assert!(e.contains("perturbed_starts.dx") && e.contains("0.005"), "{e}");
        // The start jitters the fluid: a fluid body with its own jitter, or none, is an error.
        let mut jittered = c.clone();
        jittered.scene["bodies"][0]["jitter"] = serde_json::json!({"fraction": 0.1, "seed": 3});
        let e = expand(&jittered, Tier::Quick).unwrap_err().to_string();
        assert!(e.contains("isph-paper_dx0.02_start1") && e.contains("already has `jitter`"), "{e}");
        let mut dry = c.clone();
        dry.scene["bodies"][0]["role"] = serde_json::json!("wall");
        let e = perturbed_spec(&dry, "paper", 0.02, 1).unwrap_err().to_string();
        assert!(e.contains("role `fluid`"), "{e}");
        let e = perturbed_spec(&dry, "tuned", 0.02, 1).unwrap_err().to_string();
        assert!(e.contains("`tuned` has no `perturbed_starts`"), "{e}");
    }

    #[test]
    fn hash_is_stable_and_follows_the_scene() {
        let c = committed("elliptical_drop");
        let a = spec(&c, "paper", 0.04).unwrap();
        assert_eq!(a.hash, spec(&c, "paper", 0.04).unwrap().hash);
        let mut changed = c.clone();
        changed.scene["time"]["end"] = serde_json::json!(0.004);
        assert_ne!(a.hash, spec(&changed, "paper", 0.04).unwrap().hash);
    }

    #[test]
    fn the_fingerprint_is_a_sha256_of_the_solver() {
        let f = build_fingerprint();
        assert_eq!(f.len(), 64, "{f}");
        assert!(f.bytes().all(|b| b.is_ascii_hexdigit()), "{f}");
    }

    #[test]
    fn bad_preset_patch_names_the_run() {
        let mut c = committed("elliptical_drop");
        c.sweep.presets[1].patch = serde_json::json!({"fluid": {"density": -1.0}});
        let e = expand(&c, Tier::Quick).unwrap_err().to_string();
        assert!(e.contains("isph-tuned_dx0.04") && e.contains("density"), "{e}");
    }
}
