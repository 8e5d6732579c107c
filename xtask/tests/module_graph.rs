//! The harness's modules import each other without a cycle (issue #32): the graph of
//! `crate::<module>` paths between the top-level modules of `crates/harness/src`, as
//! `cargo xtask deps` prints it.

use std::path::Path;
use xtask::deps::{find_cycle, layers, module_graph};

#[test]
fn harness_modules_form_no_import_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/harness/src");
    let graph = module_graph(&src).expect("the harness sources read");
    for module in ["report", "validate", "stability", "runner", "results", "checks"] {
        assert!(graph.contains_key(module), "no module `{module}` in {graph:?}");
    }
    if let Some(cycle) = find_cycle(&graph) {
        panic!("import cycle among the harness's modules: {}", cycle.join(" -> "));
    }
    let placed: usize = layers(&graph).iter().map(Vec::len).sum();
    assert_eq!(placed, graph.len(), "every module has a layer");
    // The report is presentation: it renders what the studies hand it.
    for study in ["validate", "stability", "work_precision"] {
        assert!(!graph["report"].contains(study), "report uses {study}");
    }
}

/// The solver's modules import each other without a cycle, and the layering the
/// architecture promises holds: the linear algebra and the per-particle field declarations
/// depend on nothing of the solver (not on the scene schema), the driver and the profiler
/// know no scheme (they step a `Method`; the registry is the one dispatch), no scheme uses
/// another, and the scene schema knows no stage or scheme.
#[test]
fn solver_modules_form_no_import_cycle() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("../crates/solver/src");
    let graph = module_graph(&src).expect("the solver sources read");
    for module in
        ["run", "scheme", "registry", "isph", "wcsph", "mps", "linalg", "stages", "operators", "ppe"]
    {
        assert!(graph.contains_key(module), "no module `{module}` in {graph:?}");
    }
    if let Some(cycle) = find_cycle(&graph) {
        panic!("import cycle among the solver's modules: {}", cycle.join(" -> "));
    }
    for leaf in ["linalg", "fields", "kernel", "neighbours", "boundary_map"] {
        assert!(graph[leaf].is_empty(), "{leaf} uses {:?}", graph[leaf]);
    }
    let schemes = ["isph", "wcsph", "mps"];
    for driver in ["run", "profile", "guard", "scheme", "stages", "ppe"] {
        for scheme in schemes {
            assert!(!graph[driver].contains(scheme), "{driver} uses {scheme}");
        }
    }
    // A scheme shares code through `stages`, `operators` and `ppe`, never with another scheme.
    for a in schemes {
        for b in schemes {
            assert!(a == b || !graph[a].contains(b), "{a} uses {b}");
        }
    }
    for upper in ["stages", "isph", "wcsph", "mps", "run", "registry", "setup"] {
        assert!(!graph["scene"].contains(upper), "scene uses {upper}");
    }
}
