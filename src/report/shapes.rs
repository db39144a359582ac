//! What each model looks like, evaluated at report time by the GPU kernels (`kernels::eval`,
//! `stability::energy::energy_of`) on the report's device: BRDF Explorer-style polar plots of f_s in the plane
//! of incidence at several incidence angles (linear and log), lit spheres at three roughnesses, and the
//! directional albedo E(NoV) per roughness. Built-in specs and `.brdf` files go through the same kernels.

use super::{Input, Loaded};
use crate::brdf::Sample;
use crate::export::html::{self, Axis, Curve, esc};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model;
use crate::stability::energy;
use anyhow::Result;
use std::fmt::Write;

/// The most models drawn (each costs a few kernel compilations and ~5M albedo evaluations).
pub const MAX_MODELS: usize = 16;
/// Incidence angles of the lobe slices, degrees.
pub const INCIDENCE: [f64; 4] = [0.0, 30.0, 60.0, 80.0];
/// Roughness and F0 of the lobes.
pub const LOBE_ROUGHNESS: f32 = 0.3;
pub const LOBE_F0: [f32; 3] = [0.04; 3];
/// Outgoing angles of a slice: -89..89 degrees in 1 degree steps.
const SLICE: std::ops::RangeInclusive<i32> = -89..=89;
/// Roughnesses of the lit spheres, their size in pixels, their F0 (copper-like, so that Fresnel shows).
pub const SPHERE_ROUGHNESS: [f32; 3] = [0.15, 0.4, 0.75];
pub const SPHERE_PX: u32 = 64;
pub const SPHERE_F0: [f32; 3] = [0.95, 0.64, 0.54];
/// The spheres' light (toward it), before normalisation.
const LIGHT: [f32; 3] = [-0.5, 0.6, 0.62];
/// The log plots' range below the peak, in decades.
pub const LOG_DECADES: f64 = 3.0;

/// The models to draw, each once by canonical spec, in input order: the profile's models, the sweep's
/// Pareto frontier, the inspected models, the stability specs that fail; at most MAX_MODELS. Returns
/// (canonical spec, label).
pub fn models_of(inputs: &[Input]) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    // One card per model however many reports name it, in whatever form (`summary::model_key`).
    let mut keys: Vec<String> = Vec::new();
    let mut add = |spec: &str, label: &str| {
        let key = super::summary::model_key(spec);
        if !keys.contains(&key) {
            keys.push(key);
            out.push((spec.to_string(), label.to_string()));
        }
    };
    for input in inputs {
        match &input.loaded {
            Loaded::Profile(p) => {
                p.rows.iter().filter_map(|r| r.spec.as_deref().map(|s| (s, &r.model))).for_each(|(s, m)| add(s, m))
            }
            Loaded::Sweep(w) => w.rows.iter().filter(|r| r.pareto).for_each(|r| add(&r.canonical, &r.label)),
            Loaded::Inspect(reports, _) => reports
                .iter()
                .flat_map(|r| &r.rows)
                .filter_map(|r| r.spec.as_deref().map(|s| (s, &r.model)))
                .for_each(|(s, m)| add(s, m)),
            // `--unguarded`'s variants are the same model without brdfprof's guards: no card of their own.
            Loaded::Stability(st) => st
                .specs
                .iter()
                .filter(|s| s.fails() && !crate::stability::is_guard_variant(&s.spec))
                .for_each(|s| add(&s.spec, s.label())),
            Loaded::Diff(d) => [&d.a, &d.b].into_iter().for_each(|m| add(&m.canonical, &m.name)),
            Loaded::DiffSet(d) => std::iter::once(&d.reference)
                .chain(d.diffs.iter().map(|x| &x.b))
                .for_each(|m| add(&m.canonical, &m.name)),
            Loaded::Costs(_) => {}
        }
    }
    out
}

fn unit(v: [f32; 3]) -> [f32; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    v.map(|c| c / n)
}

/// The lobe samples: per incidence angle, light at -theta_i in the x-z plane, view over the slice.
fn lobe_samples() -> Vec<Sample> {
    let mut out = Vec::new();
    for ti in INCIDENCE {
        let ti = ti.to_radians();
        let l = [-(ti.sin()) as f32, 0.0, ti.cos() as f32];
        for a in SLICE {
            let a = (a as f64).to_radians();
            out.push(Sample {
                n: [0.0, 0.0, 1.0],
                v: [a.sin() as f32, 0.0, a.cos() as f32],
                l,
                roughness: LOBE_ROUGHNESS,
                f0: LOBE_F0,
            });
        }
    }
    out
}

/// The sphere samples: for each roughness, each pixel inside the disc (orthographic view along +z); returns
/// the samples and, per sample, (sphere, pixel index, NoL).
fn sphere_samples() -> (Vec<Sample>, Vec<(usize, usize, f32)>) {
    let l = unit(LIGHT);
    let (mut samples, mut at) = (Vec::new(), Vec::new());
    for (k, &r) in SPHERE_ROUGHNESS.iter().enumerate() {
        for p in 0..(SPHERE_PX * SPHERE_PX) as usize {
            let (px, py) = (p as u32 % SPHERE_PX, p as u32 / SPHERE_PX);
            let x = (px as f32 + 0.5) / SPHERE_PX as f32 * 2.0 - 1.0;
            let y = 1.0 - (py as f32 + 0.5) / SPHERE_PX as f32 * 2.0;
            let rr = x * x + y * y;
            if rr >= 1.0 {
                continue;
            }
            let n = [x, y, (1.0 - rr).sqrt()];
            let nol = n[0] * l[0] + n[1] * l[1] + n[2] * l[2];
            samples.push(Sample { n, v: [0.0, 0.0, 1.0], l, roughness: r, f0: SPHERE_F0 });
            at.push((k, p, nol));
        }
    }
    (samples, at)
}

/// The lobe plots of one model (linear and log), from f_s over `lobe_samples` (channel 0).
fn lobes_svg(values: &[[f32; 3]]) -> String {
    let n = SLICE.count();
    let curves: Vec<Curve> = INCIDENCE
        .iter()
        .enumerate()
        .map(|(i, ti)| Curve {
            label: format!("light at {ti} deg"),
            points: SLICE
                .zip(&values[i * n..(i + 1) * n])
                .map(|(a, f)| ((a as f64).to_radians(), f64::from(f[0])))
                .collect(),
        })
        .collect();
    let peak =
        curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)).filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    let marks: Vec<(f64, String)> = INCIDENCE.iter().map(|t| (-t.to_radians(), format!("L{t}"))).collect();
    let marks: Vec<(f64, &str)> = marks.iter().map(|(a, l)| (*a, l.as_str())).collect();
    let linear = html::polar_svg(
        &format!("f_s, linear (peak {})", crate::export::markdown::sig(peak, 3)),
        &curves,
        &marks,
        None,
    );
    let log = html::polar_svg(
        &format!("f_s, log ({LOG_DECADES} decades below the peak)"),
        &curves,
        &marks,
        Some(LOG_DECADES),
    );
    let legend: Vec<String> = INCIDENCE
        .iter()
        .enumerate()
        .map(|(i, t)| format!("<span style=\"color:{}\">&#9632; light at {t}&deg;</span>", html::colour(i)))
        .collect();
    format!("<figure><div class=\"row\">{linear}{log}</div><figcaption>{}</figcaption></figure>", legend.join(" "))
}

/// The lit spheres of one model: f_s NoL times pi (a white Lambertian would read 1), tone-mapped.
fn spheres_html(values: &[[f32; 3]], at: &[(usize, usize, f32)]) -> Result<String> {
    let px = (SPHERE_PX * SPHERE_PX) as usize;
    let mut images = vec![vec![40u8; px * 3]; SPHERE_ROUGHNESS.len()];
    for (f, &(k, p, nol)) in values.iter().zip(at) {
        let radiance = f.map(|c| if c.is_finite() { c * nol.max(0.0) * std::f32::consts::PI } else { f32::NAN });
        // NaN or Inf shows magenta: a sphere must say where the model breaks.
        let rgb = if radiance.iter().all(|c| c.is_finite()) {
            crate::export::raster::tone_map(radiance, 1.0)
        } else {
            [255, 0, 255]
        };
        images[k][p * 3..p * 3 + 3].copy_from_slice(&rgb);
    }
    let mut s = String::from("<div class=\"row\">");
    for (img, r) in images.iter().zip(SPHERE_ROUGHNESS) {
        let uri = html::png_data_uri(SPHERE_PX, SPHERE_PX, img)?;
        let _ = write!(
            s,
            "<figure>{}<figcaption>r = {r}</figcaption></figure>",
            html::img(&uri, SPHERE_PX, SPHERE_PX, 2, &format!("lit sphere, roughness {r}"))
        );
    }
    Ok(s + "</div>")
}

/// E(NoV) per roughness (F = 1), from the albedo kernel.
fn albedo_svg(e: &energy::Energy) -> String {
    let curves: Vec<Curve> =
        e.e.iter()
            .zip(energy::ROUGHNESS)
            .map(|(row, r)| Curve {
                label: format!("r = {r}"),
                points: energy::NOV.iter().zip(row).map(|(v, x)| (f64::from(*v), f64::from(*x))).collect(),
            })
            .collect();
    let top = e.max_e.unwrap_or(1.0).max(1.0) * 1.05;
    html::lines_svg(
        &curves,
        Axis { lo: 0.0, hi: 1.0, log: false },
        Axis { lo: 0.0, hi: top, log: false },
        "NoV",
        "directional albedo E (F = 1)",
        html::SMALL,
    )
}

/// One model's card, and its lobe values (for the overlay).
fn model_card(gpu: &Gpu, spec: &str, label: &str) -> Result<(String, Vec<[f32; 3]>)> {
    let model = Model::parse(spec)?;
    let lobes = lobe_samples();
    let (spheres, at) = sphere_samples();
    let all: Vec<Sample> = lobes.iter().chain(&spheres).copied().collect();
    let values = kernels::eval(gpu, &model, &all, RunLimits::default())?;
    let (lobe_values, sphere_values) = values.split_at(lobes.len());
    let e = energy::energy_of(gpu, &model)?;
    let card = format!(
        "<div class=\"model\" data-model=\"{}\"><h3>{}</h3><p class=\"note\"><code>{}</code></p>{}<div class=\"row\">{}{}</div></div>",
        esc(spec),
        esc(label),
        esc(spec),
        lobes_svg(lobe_values),
        spheres_html(sphere_values, &at)?,
        albedo_svg(&e)
    );
    Ok((card, lobe_values.to_vec()))
}

/// Incidence angles (of `INCIDENCE`) of the overlay of every model's lobe.
const OVERLAY_INCIDENCE: [usize; 2] = [1, 2];

/// Every model's lobe at incidence `INCIDENCE[i]`; `per_peak` divides each by its own peak (shapes only).
fn overlay_curves(lobes: &[(String, Vec<[f32; 3]>)], i: usize, per_peak: bool) -> Vec<Curve> {
    let n = SLICE.count();
    lobes
        .iter()
        .map(|(label, v)| {
            let values: Vec<f64> = v[i * n..(i + 1) * n].iter().map(|f| f64::from(f[0])).collect();
            let peak = values.iter().copied().filter(|x| x.is_finite()).fold(0.0f64, f64::max);
            let scale = if per_peak && peak > 0.0 { 1.0 / peak } else { 1.0 };
            Curve {
                label: label.clone(),
                points: SLICE.zip(values).map(|(a, f)| ((a as f64).to_radians(), f * scale)).collect(),
            }
        })
        .collect()
}

/// The linear and log plots of the overlay at each of `OVERLAY_INCIDENCE`.
fn overlay_plots(lobes: &[(String, Vec<[f32; 3]>)], per_peak: bool) -> String {
    let mut plots = String::new();
    for i in OVERLAY_INCIDENCE {
        let curves = overlay_curves(lobes, i, per_peak);
        let rim =
            curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)).filter(|v| v.is_finite()).fold(0.0, f64::max);
        let t = INCIDENCE[i];
        let marks = [(-t.to_radians(), format!("L{t}"))];
        let marks: Vec<(f64, &str)> = marks.iter().map(|(a, l)| (*a, l.as_str())).collect();
        let scale = if per_peak {
            "each to its peak".to_string()
        } else {
            format!("rim f_s = {}", crate::export::markdown::sig(rim, 3))
        };
        plots += &html::polar_svg(&format!("light at {t} deg, linear, {scale}"), &curves, &marks, None);
        plots += &html::polar_svg(
            &format!("light at {t} deg, log ({LOG_DECADES} decades)"),
            &curves,
            &marks,
            Some(LOG_DECADES),
        );
    }
    plots
}

/// Every model's lobe in one plot per incidence angle (linear and log), a colour per model, on one common scale
/// (a model 4x brighter than another draws 4x larger); each model scaled to its own peak, to compare shapes,
/// folded below.
fn overlay_svg(lobes: &[(String, Vec<[f32; 3]>)]) -> String {
    let legend: Vec<String> = lobes
        .iter()
        .enumerate()
        .map(|(k, (label, _))| format!("<span class=\"key\">{}{}</span>", html::series_swatch(k), esc(label)))
        .collect();
    format!(
        "<div class=\"model overlay\" data-model=\"overlay\"><h3>All models overlaid</h3><p class=\"note\">One scale for all models: the rim is the largest f_s of any model at that incidence, so a model brighter or darker than another draws so.</p><figure data-scale=\"common\"><div class=\"row\">{}</div><figcaption>{}</figcaption></figure><details><summary>Each model scaled to its own peak (shapes only)</summary><figure data-scale=\"peak\"><div class=\"row\">{}</div></figure></details></div>",
        overlay_plots(lobes, false),
        legend.join(" "),
        overlay_plots(lobes, true)
    )
}

/// The section: a card per model (a model that cannot be evaluated, e.g. a `.brdf` file no longer there,
/// says why in its place).
pub fn section(gpu: &Gpu, models: &[(String, String)]) -> Result<String> {
    let mut s = format!(
        "<p class=\"note\">Evaluated now on {} by the same kernels that were measured. Lobes: f_s in the plane of incidence, roughness {LOBE_ROUGHNESS}, F0 {}, light at each incidence angle on the left (dashed), view over the plane; each card's plots scaled to that model's peak, the overlay of all models to one common scale. Spheres: f_s NoL pi, F0 ({}, {}, {}), one directional light, tone-mapped (ACES, sRGB); magenta where a value is NaN or Inf. Albedo: E(NoV) with F = 1.</p>",
        esc(&gpu.info.name),
        LOBE_F0[0],
        SPHERE_F0[0],
        SPHERE_F0[1],
        SPHERE_F0[2]
    );
    let mut cards = String::new();
    let mut lobes = Vec::new();
    for (spec, label) in models.iter().take(MAX_MODELS) {
        match model_card(gpu, spec, label) {
            Ok((card, lobe)) => {
                cards += &card;
                lobes.push((label.clone(), lobe));
            }
            Err(e) => {
                crate::messages::warning(format!("report: {label}: not drawn: {e:#}"));
                let _ = write!(
                    cards,
                    "<div class=\"model\"><h3>{}</h3><p class=\"err\">Not drawn: {}</p></div>",
                    esc(label),
                    esc(&format!("{e:#}"))
                );
            }
        }
    }
    if lobes.len() > 1 {
        s += &overlay_svg(&lobes);
    }
    let drawn = models.len().min(MAX_MODELS);
    let cards = format!("<div class=\"models\">{cards}</div>");
    // With one model its card is the section; with several the overlay says the most, the cards fold.
    if drawn > 1 {
        s += &crate::export::html::fold(
            &format!(
                "One card per model ({drawn}): lobes at 0, 30, 60 and 80 degrees, lit spheres, directional albedo"
            ),
            &cards,
        );
    } else {
        s += &cards;
    }
    if models.len() > MAX_MODELS {
        let _ = write!(
            s,
            "<p class=\"note\">{} more model(s) not drawn (at most {MAX_MODELS}).</p>",
            models.len() - MAX_MODELS
        );
    }
    Ok(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn peak(c: &Curve) -> f64 {
        c.points.iter().map(|p| p.1).fold(0.0, f64::max)
    }

    #[test]
    fn the_overlay_keeps_one_scale_and_folds_the_per_peak_view() {
        let n = SLICE.count() * INCIDENCE.len();
        let base: Vec<[f32; 3]> = (0..n).map(|k| [1.0 + (k % 7) as f32; 3]).collect();
        let bright: Vec<[f32; 3]> = base.iter().map(|v| v.map(|c| 4.0 * c)).collect();
        let lobes = vec![("a".to_string(), base), ("four-a".to_string(), bright)];
        let i = OVERLAY_INCIDENCE[0];
        let common = overlay_curves(&lobes, i, false);
        assert_eq!(peak(&common[1]) / peak(&common[0]), 4.0, "a model 4x another draws 4x on the common scale");
        let shapes = overlay_curves(&lobes, i, true);
        assert!(shapes.iter().all(|c| peak(c) == 1.0), "each scaled to its own peak");
        let html = overlay_svg(&lobes);
        let (common_at, peak_at) =
            (html.find("data-scale=\"common\"").unwrap(), html.find("data-scale=\"peak\"").unwrap());
        let details = html.find("<details>").unwrap();
        assert!(common_at < details && details < peak_at, "the per-peak view is the folded option");
        assert!(html.contains("rim f_s = 28.0"), "the common scale's rim in values (4 x 7)");
    }
}
