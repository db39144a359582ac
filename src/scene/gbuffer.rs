//! The scene's G-buffer: per pixel a world position, normal, tangent, perceptual roughness, base colour,
//! metallic and material. Procedural scenes are ray-cast on the CPU (spheres, boxes and planes); image G-buffers
//! are decoded from PNG (8/16 bit) and EXR files, with view vectors derived from depth or position and the camera.

use super::format::{Camera, GBufferSource, ImageFiles, MAX_SIZE, Procedural, Scene};
use crate::brdf::samples::hash01;
use anyhow::{Result, anyhow, bail};
use glam::Vec3;
use image::{ColorType, DynamicImage, ImageDecoder, ImageFormat};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

/// Material index of pixels no surface covers (not shaded).
pub const BACKGROUND: u32 = u32::MAX;

/// Bytes per pixel of the pixel binding on the device (3 vec4: the scene kernel's `Pixel`).
pub(crate) const PIXEL_BYTES: u64 = 48;

/// One G-buffer pixel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Pixel {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub tangent: [f32; 3],
    pub roughness: f32,
    pub base_colour: [f32; 3],
    pub metallic: f32,
    pub material: u32,
}

#[derive(Clone, Debug)]
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub camera: Camera,
    /// Row-major, top row first.
    pub pixels: Vec<Pixel>,
}

impl GBuffer {
    pub fn pixel_count(&self) -> usize {
        self.pixels.len()
    }
}

type V3 = Vec3;

/// A tangent orthogonal to unit `n` [Duff et al. 2017, "Building an Orthonormal Basis, Revisited", as glam's
/// `any_orthonormal_pair`].
pub fn frame_tangent(n: V3) -> V3 {
    n.any_orthonormal_pair().0
}

/// The camera's basis and the direction through a pixel centre, scaled so that its component along the
/// forward axis is 1 (so position = eye + dir * view depth).
pub struct Rays {
    eye: V3,
    forward: V3,
    right: V3,
    up: V3,
    tan_half: f32,
    width: u32,
    height: u32,
}

impl Rays {
    pub fn new(camera: &Camera, width: u32, height: u32) -> Rays {
        let eye = Vec3::from(camera.position);
        let forward = (Vec3::from(camera.look_at) - eye).normalize_or_zero();
        let mut right = forward.cross(Vec3::from(camera.up)).normalize_or_zero();
        if right == Vec3::ZERO {
            right = frame_tangent(forward);
        }
        let up = right.cross(forward);
        Rays { eye, forward, right, up, tan_half: (camera.fov_y_deg.to_radians() * 0.5).tan(), width, height }
    }

    pub fn dir(&self, x: u32, y: u32) -> V3 {
        let aspect = self.width as f32 / self.height as f32;
        let sx = ((x as f32 + 0.5) / self.width as f32 * 2.0 - 1.0) * aspect * self.tan_half;
        let sy = (1.0 - (y as f32 + 0.5) / self.height as f32 * 2.0) * self.tan_half;
        self.forward + self.right * sx + self.up * sy
    }
}

// ---- Procedural geometry ------------------------------------------------------------------------------

#[derive(Clone, Copy, Debug)]
enum Shape {
    Sphere {
        centre: V3,
        radius: f32,
    },
    /// Axis-aligned box.
    Box {
        min: V3,
        max: V3,
    },
    /// Plane through `point` facing `normal` (unit), one-sided.
    Plane {
        point: V3,
        normal: V3,
    },
}

#[derive(Clone, Copy, Debug)]
struct Object {
    shape: Shape,
    material: u32,
    /// Overrides the material's roughness (the sphere grid's columns).
    roughness: Option<f32>,
    /// Roughness and brightness noise amplitude (rough, dirty surfaces).
    noise: f32,
}

struct Hit {
    t: f32,
    normal: V3,
    tangent: V3,
}

fn intersect(shape: &Shape, o: V3, d: V3) -> Option<Hit> {
    match *shape {
        Shape::Sphere { centre, radius } => {
            let oc = o - centre;
            let (a, b, c) = (d.dot(d), oc.dot(d), oc.dot(oc) - radius * radius);
            let disc = b * b - a * c;
            if disc < 0.0 {
                return None;
            }
            let t = (-b - disc.sqrt()) / a;
            if t <= 1e-4 {
                return None;
            }
            let n = (o + d * t - centre).normalize_or_zero();
            // Tangent along the parallels (brushed around the vertical axis).
            let mut tangent = Vec3::Y.cross(n).normalize_or_zero();
            if tangent == Vec3::ZERO {
                tangent = frame_tangent(n);
            }
            Some(Hit { t, normal: n, tangent })
        }
        Shape::Box { min, max } => {
            let (mut t0, mut t1, mut axis, mut sign) = (f32::NEG_INFINITY, f32::INFINITY, 0, 0.0);
            for k in 0..3 {
                let inv = 1.0 / d[k];
                let (mut a, mut b) = ((min[k] - o[k]) * inv, (max[k] - o[k]) * inv);
                let s = if inv < 0.0 {
                    std::mem::swap(&mut a, &mut b);
                    1.0
                } else {
                    -1.0
                };
                if a > t0 {
                    t0 = a;
                    axis = k;
                    sign = s;
                }
                t1 = t1.min(b);
            }
            if t0 > t1 || t0 <= 1e-4 {
                return None;
            }
            let mut n = Vec3::ZERO;
            n[axis] = sign;
            let tangent = if axis == 1 { Vec3::X } else { Vec3::Y };
            Some(Hit { t: t0, normal: n, tangent })
        }
        Shape::Plane { point, normal } => {
            let denom = normal.dot(d);
            if denom >= 0.0 {
                return None;
            }
            let t = (point - o).dot(normal) / denom;
            (t > 1e-4).then(|| Hit { t, normal, tangent: frame_tangent(normal) })
        }
    }
}

struct Layout {
    objects: Vec<Object>,
    camera: Camera,
}

fn sphere(centre: [f32; 3], radius: f32, material: u32) -> Object {
    Object { shape: Shape::Sphere { centre: centre.into(), radius }, material, roughness: None, noise: 0.0 }
}
fn cuboid(min: [f32; 3], max: [f32; 3], material: u32, noise: f32) -> Object {
    Object { shape: Shape::Box { min: min.into(), max: max.into() }, material, roughness: None, noise }
}
fn plane(point: [f32; 3], normal: [f32; 3], material: u32, noise: f32) -> Object {
    Object {
        shape: Shape::Plane { point: point.into(), normal: Vec3::from(normal).normalize() },
        material,
        roughness: None,
        noise,
    }
}

fn sphere_grid(scene: &Scene, rows: &[String], columns: u32, floor: &str, aspect: f32) -> Layout {
    let idx = |n: &str| scene.material_index(n).unwrap() as u32;
    let mut objects = Vec::new();
    let n_rows = rows.len() as f32;
    for (r, name) in rows.iter().enumerate() {
        for c in 0..columns {
            let x = c as f32 - (columns as f32 - 1.0) / 2.0;
            let y = (n_rows - 1.0) / 2.0 - r as f32;
            let mut s = sphere([x, y, 0.0], 0.45, idx(name));
            s.roughness = Some((c as f32 + 0.5) / columns as f32);
            objects.push(s);
        }
    }
    objects.push(plane([0.0, 0.0, -0.6], [0.0, 0.0, 1.0], idx(floor), 0.0));
    let fov = 30f32;
    let half_h = (n_rows / 2.0 + 0.15).max((columns as f32 / 2.0 + 0.15) / aspect);
    let dist = half_h / (fov.to_radians() / 2.0).tan() + 0.45;
    Layout {
        objects,
        camera: Camera { position: [0.0, 0.0, dist], look_at: [0.0, 0.0, 0.0], up: [0.0, 1.0, 0.0], fov_y_deg: fov },
    }
}

fn statues(scene: &Scene, names: &[String], floor: &str) -> Layout {
    let idx = |n: &str| scene.material_index(n).unwrap() as u32;
    let mut objects = vec![plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], idx(floor), 0.05)];
    let n = names.len() as f32;
    for (i, name) in names.iter().enumerate() {
        let m = idx(name);
        // An arc of statues facing the camera.
        let u = if names.len() == 1 { 0.0 } else { i as f32 / (n - 1.0) - 0.5 };
        let (x, z) = (u * 1.6 * n, -1.2 * (u * 2.0).powi(2));
        objects.push(cuboid([x - 0.45, 0.0, z - 0.45], [x + 0.45, 0.5, z + 0.45], m, 0.0));
        objects.push(sphere([x, 1.05, z], 0.55, m));
        objects.push(sphere([x, 1.85, z], 0.3, m));
        objects.push(sphere([x + 0.42, 1.3, z + 0.1], 0.17, m));
        objects.push(sphere([x - 0.42, 1.3, z + 0.1], 0.17, m));
    }
    let width = 1.6 * n + 1.0;
    Layout {
        objects,
        camera: Camera {
            position: [0.0, 2.6, width * 0.95 + 1.5],
            look_at: [0.0, 0.9, -0.6],
            up: [0.0, 1.0, 0.0],
            fov_y_deg: 40.0,
        },
    }
}

fn old_west(scene: &Scene, ground: &str, walls: &[String], roofs: &str) -> Layout {
    let idx = |n: &str| scene.material_index(n).unwrap() as u32;
    let mut objects = vec![plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], idx(ground), 0.15)];
    let roof = idx(roofs);
    for side in [-1.0f32, 1.0] {
        for k in 0..6 {
            let wall = idx(&walls[(k + (side > 0.0) as usize) % walls.len()]);
            let z0 = -4.0 - 5.5 * k as f32;
            let h = 3.0 + 1.4 * hash01(k as u32 * 7 + (side > 0.0) as u32);
            let (x0, x1) = if side < 0.0 { (-10.0, -3.0) } else { (3.0, 10.0) };
            objects.push(cuboid([x0, 0.0, z0 - 5.0], [x1, h, z0], wall, 0.12));
            // A flat roof with an overhang over the street, and a porch post.
            let (rx0, rx1) = if side < 0.0 { (-10.2, -2.2) } else { (2.2, 10.2) };
            objects.push(cuboid([rx0, h, z0 - 5.2], [rx1, h + 0.25, z0 + 0.2], roof, 0.1));
            let px = if side < 0.0 { -2.35 } else { 2.35 };
            objects.push(cuboid([px - 0.1, 0.0, z0 - 0.1], [px + 0.1, h, z0 + 0.1], wall, 0.12));
        }
    }
    // Barrels (spheres) and a water tower tank at the end of the street.
    for (i, x) in [-2.4f32, 2.5, -2.0].iter().enumerate() {
        objects.push(sphere([*x, 0.45, -7.0 - 9.0 * i as f32], 0.45, idx(&walls[0])));
    }
    objects.push(sphere([0.0, 7.0, -40.0], 3.0, roof));
    Layout {
        objects,
        camera: Camera { position: [0.0, 1.7, 4.0], look_at: [0.0, 2.2, -20.0], up: [0.0, 1.0, 0.0], fov_y_deg: 55.0 },
    }
}

fn ray_cast(scene: &Scene, layout: &Layout, camera: &Camera, width: u32, height: u32) -> Vec<Pixel> {
    let rays = Rays::new(camera, width, height);
    let mats = &scene.file.materials;
    let mut pixels = vec![Pixel::default(); width as usize * height as usize];
    pixels.par_chunks_mut(width as usize).enumerate().for_each(|(y, row)| {
        for (x, px) in row.iter_mut().enumerate() {
            let d = rays.dir(x as u32, y as u32);
            let mut best: Option<(Hit, &Object)> = None;
            for obj in &layout.objects {
                if let Some(h) = intersect(&obj.shape, rays.eye, d) {
                    if best.as_ref().is_none_or(|(b, _)| h.t < b.t) {
                        best = Some((h, obj));
                    }
                }
            }
            *px = match best {
                None => Pixel {
                    position: (rays.eye + d * 1e4).to_array(),
                    normal: (-d.normalize()).to_array(),
                    material: BACKGROUND,
                    ..Default::default()
                },
                Some((h, obj)) => {
                    let m = &mats[obj.material as usize];
                    let id = (y as u32).wrapping_mul(width).wrapping_add(x as u32);
                    let noise = hash01(id) - 0.5;
                    let roughness = obj.roughness.unwrap_or(m.roughness.0);
                    let shade = 1.0 + obj.noise * 2.0 * (hash01(id ^ 0x9e37_79b9) - 0.5);
                    Pixel {
                        position: (rays.eye + d * h.t).to_array(),
                        normal: h.normal.to_array(),
                        tangent: h.tangent.to_array(),
                        roughness: (roughness + obj.noise * noise).clamp(0.0, 1.0),
                        base_colour: m.base_colour.0.map(|c| (c * shade).clamp(0.0, 1.0)),
                        metallic: m.metallic.0,
                        material: obj.material,
                    }
                }
            };
        }
    });
    pixels
}

/// A single sphere of `material` filling a square picture (the comparison grid's tiles).
pub fn closeup(scene: &Scene, material: u32, size: u32) -> GBuffer {
    let layout = Layout {
        objects: vec![sphere([0.0, 0.0, 0.0], 1.0, material)],
        camera: Camera { position: [0.0, 0.0, 4.2], look_at: [0.0; 3], up: [0.0, 1.0, 0.0], fov_y_deg: 30.0 },
    };
    let pixels = ray_cast(scene, &layout, &layout.camera, size, size);
    GBuffer { width: size, height: size, camera: layout.camera, pixels }
}

/// Host bytes per pixel of a scene run: the G-buffer, the pixels and extras uploaded (3 + 2 vec4) and the
/// radiance read back (1 vec4); on a CPU driver the device's copies are host memory too.
const HOST_BYTES_PER_PIXEL: u64 = std::mem::size_of::<Pixel>() as u64 + 2 * (5 * 16) + 2 * 16;

/// Refuses a G-buffer that would not fit in the memory available (`host_cpu::memory_budget`), before building it.
fn check_memory(file: &str, width: u32, height: u32) -> Result<()> {
    let Some((available, source)) = crate::host_cpu::memory_budget() else { return Ok(()) };
    let need = width as u64 * height as u64 * HOST_BYTES_PER_PIXEL;
    if need > available {
        bail!(
            "{file}: gbuffer.procedural.size [{width}, {height}]: a scene run needs about {need} bytes ({HOST_BYTES_PER_PIXEL} per pixel) and {available} are available ({source}); at most about {} pixels here",
            available / HOST_BYTES_PER_PIXEL
        );
    }
    Ok(())
}

/// Host bytes per pixel of decoding image planes: each plane's decoded pixels are kept as RGBA f32 (16 bytes)
/// until the G-buffer is built; while one decodes, its native pixels and two RGBA f32 copies exist at once.
fn decode_bytes_per_pixel(planes: &[PlaneHeader]) -> u64 {
    let peak = planes.iter().map(|p| p.native_bytes + 32).max().unwrap_or(0);
    16 * planes.len() as u64 + peak
}

/// Refuses image planes whose decoding and scene run would not fit in the memory available, from their
/// headers, before any pixel is decoded.
fn check_image_memory(file: &str, planes: &[PlaneHeader]) -> Result<()> {
    let Some((available, source)) = crate::host_cpu::memory_budget() else { return Ok(()) };
    let (w, h) = (planes[0].width as u64, planes[0].height as u64);
    let per_pixel = decode_bytes_per_pixel(planes) + HOST_BYTES_PER_PIXEL;
    let need = w * h * per_pixel;
    if need > available {
        bail!(
            "{file}: gbuffer.images: decoding its {} images of {w}x{h} and running the scene needs about {need} bytes ({per_pixel} per pixel) and {available} are available ({source}); at most about {} pixels here",
            planes.len(),
            available / per_pixel
        );
    }
    Ok(())
}

/// Refuses, before anything is built or decoded, a G-buffer that would not fit in the memory available: a
/// procedural one from its size, an image one from its images' headers.
pub fn check_host(scene: &Scene) -> Result<()> {
    match &scene.file.gbuffer {
        GBufferSource::Images(files) => check_headers(scene, files),
        GBufferSource::Procedural(_) => {
            let (w, h) = size(scene)?;
            check_memory(&scene.path.display().to_string(), w, h)
        }
    }
}

/// The G-buffer's size, from the scene file or its normal image's header.
pub fn size(scene: &Scene) -> Result<(u32, u32)> {
    match &scene.file.gbuffer {
        GBufferSource::Procedural(
            Procedural::SphereGrid { size, .. } | Procedural::Statues { size, .. } | Procedural::OldWest { size, .. },
        ) => Ok((size.0[0], size.0[1])),
        GBufferSource::Images(files) => {
            plane_header(&scene.dir.join(&files.normal), "normal", PlaneKind::Vector).map(|h| (h.width, h.height))
        }
    }
}

/// Refuses, before the G-buffer is built, a scene whose per-pixel buffer cannot be one allocation on the
/// device: `render` shades every pixel with one model, so one kernel's buffer holds all of them.
pub fn check_device(scene: &Scene, info: &crate::gpu::DeviceInfo) -> Result<()> {
    let (w, h) = size(scene)?;
    let padded = (w as u64 * h as u64).div_ceil(crate::gpu::WORKGROUP as u64) * crate::gpu::WORKGROUP as u64;
    let bytes = padded * PIXEL_BYTES;
    if info.max_memory_allocation_size > 0 && bytes > info.max_memory_allocation_size {
        bail!(
            "{}: a {w}x{h} G-buffer needs a {bytes}-byte buffer of pixels on `{}`, more than one allocation may be ({} bytes, maxMemoryAllocationSize); at most {} pixels there",
            scene.path.display(),
            info.name,
            info.max_memory_allocation_size,
            info.max_memory_allocation_size / PIXEL_BYTES
        );
    }
    Ok(())
}

/// The scene's G-buffer.
pub fn build(scene: &Scene) -> Result<GBuffer> {
    match &scene.file.gbuffer {
        GBufferSource::Procedural(p) => {
            let (size, layout) = match p {
                Procedural::SphereGrid { size, rows, columns, floor } => {
                    (size.0, sphere_grid(scene, rows, *columns, floor, size.0[0] as f32 / size.0[1] as f32))
                }
                Procedural::Statues { size, statues: s, floor } => (size.0, statues(scene, s, floor)),
                Procedural::OldWest { size, ground, walls, roofs } => (size.0, old_west(scene, ground, walls, roofs)),
            };
            check_memory(&scene.path.display().to_string(), size[0], size[1])?;
            let camera = scene.file.camera.unwrap_or(layout.camera);
            let pixels = ray_cast(scene, &layout, &camera, size[0], size[1]);
            Ok(GBuffer { width: size[0], height: size[1], camera, pixels })
        }
        GBufferSource::Images(files) => {
            check_headers(scene, files)?;
            load_images(scene, files)
        }
    }
}

/// `build`, after checking that the G-buffer fits the host's memory and one allocation on the device
/// (`check_host`, `check_device`), before building anything.
pub fn build_for(scene: &Scene, info: &crate::gpu::DeviceInfo) -> Result<GBuffer> {
    check_host(scene)?;
    check_device(scene, info)?;
    build(scene)
}

// ---- Image G-buffers ----------------------------------------------------------------------------------

/// A decoded plane: width, height, channels (RGBA, as f32) and whether the file stored floats (EXR).
pub struct Plane {
    pub width: u32,
    pub height: u32,
    pub float: bool,
    /// Normalised values c = value / max for integer images; as stored for float images. RGBA per pixel.
    pub rgba: Vec<[f32; 4]>,
    pub path: PathBuf,
}

/// What each G-buffer plane may be stored as (docs/scenes.md; `scene --explain`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaneKind {
    /// Normals and tangents: PNG 8/16-bit RGB (or RGBA, alpha ignored), n = 2c - 1; EXR float RGB.
    Vector,
    /// Roughness and metallic: PNG 8/16-bit grey (alpha ignored); EXR, R.
    Grey,
    /// Base colour: PNG 8/16-bit, sRGB-encoded; EXR linear.
    Colour,
    /// View-space depth: EXR, R; or 16-bit PNG (with `depth_range`).
    Depth,
    /// World-space position: EXR RGB.
    Position,
    /// Material index: 8-bit grey PNG.
    MaterialId,
}

impl PlaneKind {
    /// What the plane needs, as the error says it.
    fn needs(self) -> &'static str {
        match self {
            PlaneKind::Vector => "RGB or RGBA: a PNG (8 or 16 bit) or an EXR",
            PlaneKind::Grey => "grey: a PNG (8 or 16 bit) or an EXR (R is read)",
            PlaneKind::Colour => "a PNG (8 or 16 bit, sRGB-encoded) or an EXR (linear)",
            PlaneKind::Depth => "an EXR (R is read) or a 16-bit PNG",
            PlaneKind::Position => "an EXR (float RGB)",
            PlaneKind::MaterialId => "an 8-bit grey PNG",
        }
    }

    fn accepts(self, float: bool, colour: ColorType) -> bool {
        let bits = bits_per_channel(colour);
        let rgb = colour.has_color();
        match self {
            PlaneKind::Vector => float || rgb,
            PlaneKind::Grey => float || !rgb,
            PlaneKind::Colour => true,
            PlaneKind::Depth => float || bits == 16,
            PlaneKind::Position => float,
            PlaneKind::MaterialId => !float && !rgb && bits == 8,
        }
    }
}

fn bits_per_channel(c: ColorType) -> u16 {
    u16::from(c.bytes_per_pixel()) * 8 / u16::from(c.channel_count())
}

/// "an 8-bit grey PNG", "a 16-bit RGBA PNG", "a float RGB EXR": what a file holds, for errors.
fn describe(format: Option<ImageFormat>, colour: ColorType) -> String {
    let channels = match (colour.has_color(), colour.has_alpha()) {
        (false, false) => "grey",
        (false, true) => "grey+alpha",
        (true, false) => "RGB",
        (true, true) => "RGBA",
    };
    let depth = if matches!(colour, ColorType::Rgb32F | ColorType::Rgba32F) {
        "float".to_string()
    } else {
        format!("{}-bit", bits_per_channel(colour))
    };
    let format = format.map_or("image", |f| f.extensions_str().first().copied().unwrap_or("image"));
    let article = if depth.starts_with('8') { "an" } else { "a" };
    format!("{article} {depth} {channels} {}", format.to_uppercase())
}

/// What a plane's header says: its size and the bytes per pixel of its decoded native pixels.
pub struct PlaneHeader {
    pub width: u32,
    pub height: u32,
    pub native_bytes: u64,
}

/// Opens an image and checks its header against the size limit and what the plane needs, so that a file that
/// does not fit is refused without being decoded. Errors name the file.
fn open_plane(path: &Path, what: &str, kind: PlaneKind) -> Result<(impl ImageDecoder, PlaneHeader, bool)> {
    let shown = path.display();
    let (file, _) = crate::io::open_regular(path).map_err(|e| anyhow!("image: {e:#}"))?;
    let mut reader = image::ImageReader::new(std::io::BufReader::new(file));
    if let Ok(format) = image::ImageFormat::from_path(path) {
        reader.set_format(format);
    }
    let mut reader = reader.with_guessed_format().map_err(|e| anyhow!("cannot read image {shown}: {e}"))?;
    let format = reader.format();
    // The size is checked here, from the header, instead of by the image crate's allocation limit (512 MiB,
    // less than a 16384 x 16384 plane needs).
    reader.no_limits();
    let decoder = reader.into_decoder().map_err(|e| anyhow!("cannot decode image {shown}: {e}"))?;
    let ((width, height), colour) = (decoder.dimensions(), decoder.color_type());
    if width == 0 || height == 0 || width > MAX_SIZE || height > MAX_SIZE {
        bail!(
            "{shown}: the {what} image is {width}x{height}; G-buffer images must be 1 to {MAX_SIZE} pixels wide and high"
        );
    }
    let float = matches!(colour, ColorType::Rgb32F | ColorType::Rgba32F);
    if !kind.accepts(float, colour) {
        bail!("{shown}: the {what} image must be {}; this file is {}", kind.needs(), describe(format, colour));
    }
    Ok((decoder, PlaneHeader { width, height, native_bytes: u64::from(colour.bytes_per_pixel()) }, float))
}

/// A plane's header, checked as `read_plane` checks it, without decoding a pixel.
pub fn plane_header(path: &Path, what: &str, kind: PlaneKind) -> Result<PlaneHeader> {
    open_plane(path, what, kind).map(|(_, header, _)| header)
}

/// Reads a plane of kind `kind` (`what` names it: "normal", "depth", ...) from a PNG or EXR file, its header
/// checked first (`open_plane`). Errors name the file.
pub fn read_plane(path: &Path, what: &str, kind: PlaneKind) -> Result<Plane> {
    let (decoder, header, float) = open_plane(path, what, kind)?;
    let img =
        DynamicImage::from_decoder(decoder).map_err(|e| anyhow!("cannot decode image {}: {e}", path.display()))?;
    let rgba: Vec<[f32; 4]> = img.into_rgba32f().pixels().map(|p| p.0).collect();
    Ok(Plane { width: header.width, height: header.height, float, rgba, path: path.to_path_buf() })
}

/// The sRGB EOTF (IEC 61966-2-1): display-encoded c in [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
}

/// Every pixel of a material image names a material of the scene (or 255: background).
fn check_material_ids(m: &Plane, w: u32, materials: usize) -> Result<()> {
    let bad = m.rgba.iter().enumerate().find(|(_, c)| {
        let k = (c[0] * 255.0).round() as usize;
        k != 255 && k >= materials
    });
    if let Some((i, c)) = bad {
        bail!(
            "{}: pixel ({}, {}) names material {} but the scene has {materials} materials",
            m.path.display(),
            i as u32 % w,
            i as u32 / w,
            (c[0] * 255.0).round()
        );
    }
    Ok(())
}

/// Every plane of the scene's images: (file, what it is, its kind).
fn planes(files: &ImageFiles) -> Vec<(&PathBuf, &'static str, PlaneKind)> {
    let optional = [
        (&files.roughness, "roughness", PlaneKind::Grey),
        (&files.base_colour, "base_colour", PlaneKind::Colour),
        (&files.metallic, "metallic", PlaneKind::Grey),
        (&files.depth, "depth", PlaneKind::Depth),
        (&files.position, "position", PlaneKind::Position),
        (&files.material, "material", PlaneKind::MaterialId),
        (&files.tangent, "tangent", PlaneKind::Vector),
    ];
    std::iter::once((&files.normal, "normal", PlaneKind::Vector))
        .chain(optional.into_iter().filter_map(|(p, what, kind)| p.as_ref().map(|p| (p, what, kind))))
        .collect()
}

/// Every plane's header: the same size as the normal image's, and the memory to decode them available.
fn check_headers(scene: &Scene, files: &ImageFiles) -> Result<()> {
    let planes = planes(files);
    let headers = planes
        .iter()
        .map(|(p, what, kind)| plane_header(&scene.dir.join(p), what, *kind))
        .collect::<Result<Vec<_>>>()?;
    let (w, h) = (headers[0].width, headers[0].height);
    for ((p, _, _), header) in planes.iter().zip(&headers).skip(1) {
        if (header.width, header.height) != (w, h) {
            bail!(
                "{} is {}x{}, but the normal image {} is {w}x{h}",
                scene.dir.join(p).display(),
                header.width,
                header.height,
                scene.dir.join(&files.normal).display()
            );
        }
    }
    check_image_memory(&scene.path.display().to_string(), &headers)
}

/// Pixel `i` of a normal or tangent image as a unit vector (an 8-bit image stores `0.5 * (v + 1)`).
fn decode_vector(plane: &Plane, i: usize) -> V3 {
    let c = Vec3::from_slice(&plane.rgba[i][..3]);
    if plane.float { c.normalize_or_zero() } else { (2.0 * c - Vec3::ONE).normalize_or_zero() }
}

/// `plane`, or an error where its size is not the normal image's.
fn same_size(plane: Plane, normal: &Plane) -> Result<Plane> {
    let (w, h) = (normal.width, normal.height);
    if (plane.width, plane.height) != (w, h) {
        bail!(
            "{} is {}x{}, but the normal image {} is {w}x{h}",
            plane.path.display(),
            plane.width,
            plane.height,
            normal.path.display()
        );
    }
    Ok(plane)
}

/// Pixel `i`'s position: along its ray `dir` from the camera at `eye` to the depth image's distance (a PNG's
/// scaled to `depth_range`), or else read from the position image.
fn image_position(
    depth: Option<&Plane>,
    position: Option<&Plane>,
    depth_range: Option<[f32; 2]>,
    eye: [f32; 3],
    dir: V3,
    i: usize,
) -> [f32; 3] {
    match (depth, position) {
        (Some(d), _) => {
            let c = d.rgba[i][0];
            let z = if d.float {
                c
            } else {
                let [near, far] = depth_range.unwrap();
                near + c * (far - near)
            };
            (Vec3::from(eye) + dir * z).to_array()
        }
        (_, Some(p)) => [p.rgba[i][0], p.rgba[i][1], p.rgba[i][2]],
        _ => unreachable!("checked: depth or position"),
    }
}

/// Pixel `i`'s base colour from the base colour image (an 8-bit one is sRGB), or the material's `default`.
fn image_base_colour(base: Option<&Plane>, default: [f32; 3], i: usize) -> [f32; 3] {
    base.map_or(default, |b| {
        let c = b.rgba[i];
        if b.float { [c[0], c[1], c[2]] } else { [srgb_to_linear(c[0]), srgb_to_linear(c[1]), srgb_to_linear(c[2])] }
    })
}

fn load_images(scene: &Scene, files: &ImageFiles) -> Result<GBuffer> {
    let camera = scene.file.camera.expect("checked: image G-buffers have a camera");
    let open = |p: &PathBuf, what: &str, kind: PlaneKind| read_plane(&scene.dir.join(p), what, kind);
    let normal = open(&files.normal, "normal", PlaneKind::Vector)?;
    let (w, h) = (normal.width, normal.height);
    let same = |plane: Plane| same_size(plane, &normal);
    let optional = |p: &Option<PathBuf>, what: &str, kind: PlaneKind| {
        p.as_ref().map(|p| open(p, what, kind).and_then(same)).transpose()
    };
    let roughness = optional(&files.roughness, "roughness", PlaneKind::Grey)?;
    let base = optional(&files.base_colour, "base_colour", PlaneKind::Colour)?;
    let metallic = optional(&files.metallic, "metallic", PlaneKind::Grey)?;
    let depth = optional(&files.depth, "depth", PlaneKind::Depth)?;
    let position = optional(&files.position, "position", PlaneKind::Position)?;
    let material = optional(&files.material, "material", PlaneKind::MaterialId)?;
    let tangent = optional(&files.tangent, "tangent", PlaneKind::Vector)?;
    if let Some(d) = &depth {
        if !d.float && files.depth_range.is_none() {
            bail!("{}: a PNG depth needs gbuffer.images.depth_range [near, far]", d.path.display());
        }
    }
    if let Some(m) = &material {
        check_material_ids(m, w, scene.file.materials.len())?;
    }
    let mats = &scene.file.materials;
    let rays = Rays::new(&camera, w, h);
    let pixels = (0..(w as usize * h as usize))
        .into_par_iter()
        .map(|i| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let mat = material.as_ref().map_or(0, |m| (m.rgba[i][0] * 255.0).round() as u32);
            let dir = rays.dir(x, y);
            let pos = image_position(depth.as_ref(), position.as_ref(), files.depth_range, camera.position, dir, i);
            if mat == 255 {
                return Pixel {
                    position: pos,
                    normal: (-dir.normalize()).to_array(),
                    material: BACKGROUND,
                    ..Default::default()
                };
            }
            let m = &mats[mat as usize];
            let n = decode_vector(&normal, i);
            let t =
                tangent.as_ref().map(|t| decode_vector(t, i)).filter(|t| *t != Vec3::ZERO && t.dot(n).abs() < 0.999);
            let base_colour = image_base_colour(base.as_ref(), m.base_colour.0, i);
            Pixel {
                position: pos,
                normal: n.to_array(),
                tangent: t.unwrap_or_else(|| frame_tangent(n)).to_array(),
                roughness: roughness.as_ref().map_or(m.roughness.0, |r| r.rgba[i][0].clamp(0.0, 1.0)),
                base_colour: base_colour.map(|c| c.clamp(0.0, 1.0)),
                metallic: metallic.as_ref().map_or(m.metallic.0, |r| r.rgba[i][0].clamp(0.0, 1.0)),
                material: mat,
            }
        })
        .collect();
    Ok(GBuffer { width: w, height: h, camera, pixels })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_frame_is_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::new(1.0, 2.0, -3.0).normalize(), Vec3::X] {
            let t = frame_tangent(n);
            assert!(t.dot(n).abs() < 1e-6 && (t.length_squared() - 1.0).abs() < 1e-6, "{n:?} {t:?}");
        }
    }

    /// A PNG of `w` x `h` grey pixels whose image data is cut short: its header is valid, its pixels are not.
    fn png_header_only(w: u32, h: u32) -> Vec<u8> {
        fn crc32(bytes: &[u8]) -> u32 {
            let mut c = !0u32;
            for &b in bytes {
                c ^= u32::from(b);
                for _ in 0..8 {
                    c = if c & 1 != 0 { (c >> 1) ^ 0xEDB8_8320 } else { c >> 1 };
                }
            }
            !c
        }
        let chunk = |out: &mut Vec<u8>, kind: &[u8], data: &[u8]| {
            out.extend_from_slice(&(data.len() as u32).to_be_bytes());
            let body = [kind, data].concat();
            out.extend_from_slice(&body);
            out.extend_from_slice(&crc32(&body).to_be_bytes());
        };
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let ihdr = [&w.to_be_bytes()[..], &h.to_be_bytes(), &[8, 0, 0, 0, 0]].concat();
        chunk(&mut png, b"IHDR", &ihdr);
        chunk(&mut png, b"IDAT", &[0x78, 0x9c, 0x63, 0x00]);
        chunk(&mut png, b"IEND", &[]);
        png
    }

    #[test]
    fn planes_are_refused_unless_stored_as_the_readme_says() {
        use image::{ImageBuffer, Luma, Rgb};
        let dir = tempfile::tempdir().unwrap();
        let p = |n: &str| dir.path().join(n);
        ImageBuffer::<Luma<u8>, _>::from_raw(2, 2, vec![1u8; 4]).unwrap().save(p("grey8.png")).unwrap();
        ImageBuffer::<Luma<u16>, _>::from_raw(2, 2, vec![1u16; 4]).unwrap().save(p("grey16.png")).unwrap();
        ImageBuffer::<Rgb<u8>, _>::from_raw(2, 2, vec![1u8; 12]).unwrap().save(p("rgb8.png")).unwrap();
        ImageBuffer::<Rgb<f32>, _>::from_raw(2, 2, vec![1f32; 12]).unwrap().save(p("rgb.exr")).unwrap();
        let refused = |file: &str, what: &str, kind: PlaneKind| {
            read_plane(&p(file), what, kind).err().map(|e| e.to_string()).unwrap_or_default()
        };
        let e = refused("grey8.png", "normal", PlaneKind::Vector);
        assert_eq!(
            e,
            format!(
                "{}: the normal image must be RGB or RGBA: a PNG (8 or 16 bit) or an EXR; this file is an 8-bit grey PNG",
                p("grey8.png").display()
            )
        );
        let e = refused("grey8.png", "depth", PlaneKind::Depth);
        assert!(
            e.contains(
                "grey8.png: the depth image must be an EXR (R is read) or a 16-bit PNG; this file is an 8-bit grey PNG"
            ),
            "{e}"
        );
        let e = refused("rgb8.png", "roughness", PlaneKind::Grey);
        assert!(e.contains("the roughness image must be grey") && e.contains("8-bit RGB PNG"), "{e}");
        let e = refused("grey16.png", "material", PlaneKind::MaterialId);
        assert!(e.contains("an 8-bit grey PNG; this file is a 16-bit grey PNG"), "{e}");
        let e = refused("grey16.png", "position", PlaneKind::Position);
        assert!(e.contains("the position image must be an EXR"), "{e}");
        for (file, kind) in [
            ("rgb8.png", PlaneKind::Vector),
            ("rgb.exr", PlaneKind::Vector),
            ("grey16.png", PlaneKind::Depth),
            ("rgb.exr", PlaneKind::Depth),
            ("grey8.png", PlaneKind::Grey),
            ("grey8.png", PlaneKind::MaterialId),
            ("grey8.png", PlaneKind::Colour),
        ] {
            assert!(read_plane(&p(file), "plane", kind).is_ok(), "{file} as {kind:?}");
        }
    }

    #[test]
    fn an_image_over_the_size_limit_is_refused_from_its_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        // 16385 x 16385 would decode to 268 MB; the data is cut short, so only a header check can name the size.
        std::fs::write(&path, png_header_only(MAX_SIZE + 1, MAX_SIZE + 1)).unwrap();
        let e = read_plane(&path, "normal", PlaneKind::Vector).err().unwrap().to_string();
        assert_eq!(
            e,
            format!(
                "{}: the normal image is 16385x16385; G-buffer images must be 1 to 16384 pixels wide and high",
                path.display()
            )
        );
        std::fs::write(&path, png_header_only(MAX_SIZE, 2)).unwrap();
        let e = read_plane(&path, "normal", PlaneKind::Grey).err().unwrap().to_string();
        assert!(
            e.starts_with(&format!("cannot decode image {}", path.display())),
            "within the limit, the (cut) data is decoded: {e}"
        );
    }

    #[test]
    fn rays_hit_a_box_and_a_plane_from_outside() {
        let b = Shape::Box { min: Vec3::splat(-1.0), max: Vec3::ONE };
        let h = intersect(&b, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
        assert_eq!((h.t, h.normal), (4.0, Vec3::Z));
        let p = Shape::Plane { point: Vec3::ZERO, normal: Vec3::Y };
        assert!(intersect(&p, Vec3::Y, Vec3::Y).is_none());
        assert_eq!(intersect(&p, Vec3::Y, -Vec3::Y).unwrap().t, 1.0);
    }
}
