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
