//! Runs a scene file and prints the last probe values (development aid).
fn main() {
    let path = std::env::args().nth(1).expect("scene path");
    let mut scene = meniscus::Scene::from_path(std::path::Path::new(&path)).unwrap();
    if let Some(dx) = std::env::args().nth(2) {
        scene.dx = dx.parse().unwrap();
    }
    let r = meniscus::run(&scene, &mut meniscus::Quiet).unwrap();
    println!("{}", serde_json::to_string_pretty(&r.summary).unwrap());
    if let Some(out) = std::env::args().nth(3) {
        std::fs::write(out, serde_json::to_vec(&r.probes).unwrap()).unwrap();
    }
    for (k, q) in &r.probes.series {
        for (name, v) in q {
            println!("{k}.{name}: first {:.6e} last {:.6e}", v[0], v[v.len() - 1]);
        }
    }
}
