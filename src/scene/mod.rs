//! Scenes (`brdfprof profile --scene`, `brdfprof render`, `brdfprof scene`): a G-buffer (procedural or from
//! image files), a camera, lights and materials with effects, compiled into one kernel per model present with
//! only the light types and effects the scene uses (`plan`), run on the device (`run`), timed effect by effect
//! (`profile`) and drawn (`render`).

pub mod compile;
pub mod effects;
pub mod format;
pub mod gbuffer;
pub mod plan;
pub mod profile;
pub mod render;
pub mod run;
pub mod spirv;
pub mod terms;

pub use format::{Scene, explain_text};

/// `brdfprof scene FILE`: checks the scene, builds its G-buffer and says what would be compiled in (no device).
pub fn check(path: &std::path::Path) -> anyhow::Result<String> {
    let scene = Scene::load(path)?;
    let g = gbuffer::build(&scene)?;
    let p = plan::plan(&scene, &g, None);
    let shaded: usize = p.kernels.iter().map(|k| k.pixels.len()).sum();
    let mut out = format!(
        "{}: {}x{} G-buffer, {} pixels shaded, {} lights\ncompiled in:\n",
        scene.name(),
        g.width,
        g.height,
        shaded,
        p.counts.total()
    );
    for line in p.describe(&scene).iter().chain(&p.notes) {
        out += &format!("  {line}\n");
    }
    Ok(out)
}

/// `brdfprof scene --explain`: the format, then the built-in sphere grid as an example.
pub fn explain() -> String {
    format!("{}{}", explain_text(), include_str!("../../scenes/sphere-grid.json"))
}
