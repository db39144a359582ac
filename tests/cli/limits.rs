//! Requests too big for the machine are refused before anything is allocated, naming the size and the limit.

use crate::common;

#[test]
fn a_profile_larger_than_one_allocation_is_refused_up_front() {
    let started = std::time::Instant::now();
    let r = common::run(&["profile", "--size", "100000x100000", "--budget", "5"]).fails(2, "--size 100000x100000: the packed G-buffer is 160000000000 bytes");
    assert!(r.stderr.contains("maxMemoryAllocationSize") && r.stderr.contains("at most"), "{}", r.stderr);
    // Refused before the 160 GB picture is built (which aborted the process before this check existed).
    assert!(started.elapsed().as_secs() < 30, "refused up front");
    common::run(&["profile", "--size", "20000x20000", "--gbuffer", "float", "--budget", "5"]).fails(2, "the float G-buffer is 19200000000 bytes");
}

#[test]
fn a_scene_larger_than_memory_is_refused_before_it_is_built() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(common::repo_root().join("scenes/sphere-grid.json")).unwrap()).unwrap();
    // 16384^2 needs about 68 GB here; refused unless the machine really has that much available.
    scene["gbuffer"]["procedural"]["size"] = serde_json::json!([16384, 16384]);
    let path = dir.path().join("big.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    let available = brdfprof::host::available_memory().expect("Linux reports MemAvailable");
    if available > 80 << 30 {
        eprintln!("skipped: {available} bytes available");
        return;
    }
    let out = dir.path().join("out");
    common::run(&["render", "--scene", path.to_str().unwrap(), "--out", out.to_str().unwrap()]).fails(2, "big.json: gbuffer.procedural.size [16384, 16384]: a scene run needs about");
    assert!(!out.exists(), "nothing written");
}

#[test]
fn a_scene_with_more_lights_than_compile_in_seconds_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut scene: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(common::repo_root().join("scenes/sphere-grid.json")).unwrap()).unwrap();
    let n = brdfprof::scene::format::MAX_LIGHTS + 1;
    scene["lights"] = serde_json::Value::Array((0..n).map(|i| serde_json::json!({"type": "point", "position": [i as f64 * 0.01, 3.0, 1.0]})).collect());
    let path = dir.path().join("many.json");
    std::fs::write(&path, scene.to_string()).unwrap();
    common::run(&["scene", path.to_str().unwrap()]).fails(2, &format!("many.json: lights: at most {} lights ({n} given)", n - 1));
}
