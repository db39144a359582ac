//! The synthetic G-buffer and lights of the default profile: what a deferred lighting pass reads.
//!
//! The picture is a grid of spheres in front of a floor, seen by a pinhole camera, like the thesis' material
//! rows (Fig. 5.2): roughness rises along a row, rows alternate metal and dielectric base colours, so every
//! model meets the whole range of roughness, normal and view angles, and some back-facing lights.
//!
//! Two layouts of the same pixels. `Packed` is what engines store (thesis 4.5.1, UE5's GBufferA/B/C): an
//! octahedral normal in snorm 16:16, RGBA8 (metallic, specular, roughness, shading model), RGBA8 (base colour,
//! AO) and the depth; the kernel reads them through typed texel views (texelFetch, as a lighting pass reads
//! its render targets), reconstructs the view vector from the pixel's position and the camera, and writes
//! the radiance as R11G11B10F (an HDR lighting target of UE5, Frostbite and others): 16 bytes in, 4 out.
//! `Float` keeps every value as an f32 in storage buffers (48 bytes in, 16 out), for comparison.

use crate::brdf::samples::hash01;
use glam::{Vec2, Vec3};
use rayon::prelude::*;
use serde::Serialize;

pub use crate::kernels::shade::{GBufferFormat, PIXEL_FLOATS};

/// Floats per light: (l.xyz, 0), (rgb, 0).
pub const LIGHT_FLOATS: usize = 8;

/// One pixel's surface, as the float layout stores it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    pub normal: Vec3,
    pub view: Vec3,
    pub roughness: f32,
    pub metallic: f32,
    pub base: Vec3,
}

/// The pinhole camera at the origin looking down -z, 30 degrees vertical half-angle: pixel (x, y) sees along
/// (sx, sy, -1) with sx = (x + 0.5) scale.x + offset.x, sy = (y + 0.5) scale.y + offset.y, so V =
/// normalize(-sx, -sy, 1). The packed kernel reconstructs V from these four numbers (a push constant).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Camera {
    pub scale: [f32; 2],
    pub offset: [f32; 2],
}

impl Camera {
    pub fn new(width: u32, height: u32) -> Self {
        let tan_half_fov = (30f32).to_radians().tan();
        let aspect = width as f32 / height as f32;
        Camera {
            scale: [2.0 / width as f32 * aspect * tan_half_fov, -2.0 / height as f32 * tan_half_fov],
            offset: [-aspect * tan_half_fov, tan_half_fov],
        }
    }

    /// V at pixel (x, y), in f32 as the kernel computes it (before its normalisation).
    pub fn view(&self, x: u32, y: u32) -> Vec3 {
        let s = (Vec2::new(x as f32, y as f32) + 0.5) * Vec2::from(self.scale) + Vec2::from(self.offset);
        Vec3::new(-s.x, -s.y, 1.0)
    }
}

const SPHERE_COLUMNS: u32 = 8;
const SPHERE_ROWS: u32 = 4;

/// Base colours of the sphere rows: gold and aluminium metals, red plastic, black rubber (thesis Fig. 5.3-5.5).
const ROW_MATERIALS: [([f32; 3], f32); SPHERE_ROWS as usize] =
    [([1.0, 0.78, 0.34], 1.0), ([0.91, 0.92, 0.92], 1.0), ([0.6, 0.05, 0.04], 0.0), ([0.02, 0.02, 0.02], 0.0)];

/// The surface at pixel (x, y) of a width x height picture.
pub fn surface(camera: &Camera, width: u32, height: u32, x: u32, y: u32) -> Surface {
    let view = camera.view(x, y).normalize();
    // Which sphere cell, and where inside it.
    let cu = (x as f32 + 0.5) / width as f32 * SPHERE_COLUMNS as f32;
    let cv = (y as f32 + 0.5) / height as f32 * SPHERE_ROWS as f32;
    let (col, rowi) = (cu.floor() as u32, cv.floor() as u32);
    let (px, py) = ((cu.fract() - 0.5) * 2.2, (0.5 - cv.fract()) * 2.2);
    let d2 = px * px + py * py;
    let id = y.wrapping_mul(width).wrapping_add(x);
    let noise = hash01(id);
    if d2 < 1.0 {
        let r = (col as f32 + 0.5) / SPHERE_COLUMNS as f32;
        let (base, metallic) = ROW_MATERIALS[rowi.min(SPHERE_ROWS - 1) as usize];
        Surface {
            normal: Vec3::new(px, py, (1.0 - d2).sqrt()).normalize(),
            view,
            roughness: (r + 0.04 * (noise - 0.5)).clamp(0.0, 1.0),
            metallic,
            base: base.into(),
        }
    } else {
        // Floor: a bumpy plane facing the camera at a grazing tilt.
        let jitter = Vec2::new(hash01(id ^ 0x9e37_79b9) - 0.5, hash01(id ^ 0x7f4a_7c15) - 0.5);
        let normal = Vec3::new(0.15 * jitter.x, 0.8 + 0.15 * jitter.y, 0.6).normalize();
        Surface { normal, view, roughness: 0.3 + 0.6 * noise, metallic: 0.0, base: Vec3::new(0.5, 0.45, 0.4) }
    }
}

/// The picture, in one of the two layouts, as the shading kernel reads it.
pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    pub format: GBufferFormat,
    pub camera: Camera,
    /// Packed: 4 words per pixel; float: PIXEL_FLOATS f32 bits per pixel. Row-major.
    pub words: Vec<u32>,
}

impl GBuffer {
    pub fn pixel_count(&self) -> u64 {
        self.width as u64 * self.height as u64
    }

    pub fn words_per_pixel(&self) -> usize {
        (self.format.bytes_in() / 4) as usize
    }
}

/// Octahedral encoding of a unit vector [Cigolle et al. 2014, Listing 1]: its projection on the octahedron,
/// the lower half folded over.
pub fn octahedral_encode(n: Vec3) -> Vec2 {
    let p = Vec2::new(n.x, n.y) / (n.x.abs() + n.y.abs() + n.z.abs());
    if n.z >= 0.0 { p } else { (Vec2::ONE - Vec2::new(p.y.abs(), p.x.abs())) * Vec2::new(p.x.signum(), p.y.signum()) }
}

/// GLSL's packSnorm2x16 and packUnorm4x8.
fn pack_snorm2x16(v: Vec2) -> u32 {
    let q = |x: f32| ((x.clamp(-1.0, 1.0) * 32767.0).round() as i16) as u16 as u32;
    q(v.x) | (q(v.y) << 16)
}

fn pack_unorm4x8(v: [f32; 4]) -> u32 {
    v.iter().enumerate().map(|(i, x)| ((x.clamp(0.0, 1.0) * 255.0).round() as u32) << (8 * i)).fold(0, |a, b| a | b)
}

/// The surface as the packed layout stores it: (normal, (metallic, specular 0.5, roughness, shading model 1),
/// (base colour, AO 1), depth 1).
pub fn pack(s: &Surface) -> [u32; 4] {
    [
        pack_snorm2x16(octahedral_encode(s.normal)),
        pack_unorm4x8([s.metallic, 0.5, s.roughness, 1.0 / 255.0]),
        pack_unorm4x8([s.base.x, s.base.y, s.base.z, 1.0]),
        1f32.to_bits(),
    ]
}

/// The surface the packed kernel decodes from `words` at pixel (x, y): what the packing leaves of it.
pub fn unpack(words: &[u32], camera: &Camera, x: u32, y: u32) -> Surface {
    let snorm = |w: u32| (w as u16 as i16 as f32 / 32767.0).max(-1.0);
    let e = Vec2::new(snorm(words[0]), snorm(words[0] >> 16));
    let mut n = Vec3::new(e.x, e.y, 1.0 - e.x.abs() - e.y.abs());
    let t = (-n.z).max(0.0);
    n.x += if n.x >= 0.0 { -t } else { t };
    n.y += if n.y >= 0.0 { -t } else { t };
    let unorm = |w: u32, i: u32| ((w >> (8 * i)) & 0xff) as f32 / 255.0;
    Surface {
        normal: n.normalize(),
        view: camera.view(x, y).normalize(),
        roughness: unorm(words[1], 2),
        metallic: unorm(words[1], 0),
        base: Vec3::new(unorm(words[2], 0), unorm(words[2], 1), unorm(words[2], 2)),
    }
}

/// One unsigned float of VK_FORMAT_B10G11R11_UFLOAT_PACK32 (5-bit exponent, `mantissa` bits, no sign;
/// Vulkan spec "Unsigned 11-Bit / 10-Bit Floating-Point Numbers").
fn small_ufloat(bits: u32, mantissa: u32) -> f32 {
    let (e, m) = (bits >> mantissa, (bits & ((1 << mantissa) - 1)) as f32 / (1 << mantissa) as f32);
    match e {
        0 => m * (-14f32).exp2(),
        31 if m == 0.0 => f32::INFINITY,
        31 => f32::NAN,
        _ => (1.0 + m) * (e as f32 - 15.0).exp2(),
    }
}

/// The rgb of one R11G11B10F texel (red in the low 11 bits, blue in the high 10).
pub fn unpack_r11g11b10(w: u32) -> [f32; 3] {
    [small_ufloat(w & 0x7ff, 6), small_ufloat((w >> 11) & 0x7ff, 6), small_ufloat(w >> 22, 5)]
}

/// Largest relative rounding error of a value stored as R11G11B10F (blue's 5-bit mantissa; the spec lets
/// the conversion round either way, so one whole step).
pub const R11G11B10_REL_ERROR: f32 = 1.0 / 32.0;

fn float_words(s: &Surface) -> [u32; PIXEL_FLOATS] {
    let (n, v, b) = (s.normal, s.view, s.base);
    [n.x, n.y, n.z, s.roughness, v.x, v.y, v.z, s.metallic, b.x, b.y, b.z, 1.0].map(f32::to_bits)
}

/// The synthetic picture in `format`.
pub fn synthetic(width: u32, height: u32, format: GBufferFormat) -> GBuffer {
    let camera = Camera::new(width, height);
    let per = (format.bytes_in() / 4) as usize;
    let mut words = vec![0u32; width as usize * height as usize * per];
    words.par_chunks_mut(width as usize * per).enumerate().for_each(|(y, row)| {
        for (x, px) in row.chunks_exact_mut(per).enumerate() {
            let s = surface(&camera, width, height, x as u32, y as u32);
            match format {
                GBufferFormat::Packed => px.copy_from_slice(&pack(&s)),
                GBufferFormat::Float => px.copy_from_slice(&float_words(&s)),
            }
        }
    });
    GBuffer { width, height, format, camera, words }
}

/// `count` directional lights spread over the sphere by a golden-angle spiral biased towards the camera,
/// so most light most pixels but some come from behind; colours and intensities vary. Directions are unit
/// vectors in f32 (the kernel does not normalise them).
pub fn lights(count: u32) -> Vec<f32> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .flat_map(|i| {
            let t = (i as f32 + 0.5) / count as f32;
            let z = 1.0 - 1.6 * t; // from the camera side (z = 1) to partly behind (z = -0.6)
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            let dir = Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize();
            let warm = hash01(i * 7919 + 1);
            let intensity = 0.5 + 2.0 * hash01(i * 104729 + 3);
            let colour = [intensity * (0.8 + 0.2 * warm), intensity * 0.9, intensity * (1.0 - 0.2 * warm)];
            [dir[0], dir[1], dir[2], 0.0, colour[0], colour[1], colour[2], 0.0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gbuffer_is_deterministic_and_plausible() {
        let a = synthetic(64, 36, GBufferFormat::Float);
        assert_eq!(a.words, synthetic(64, 36, GBufferFormat::Float).words);
        let mut visible = 0;
        for p in a.words.chunks_exact(PIXEL_FLOATS) {
            let p: Vec<f32> = p.iter().map(|w| f32::from_bits(*w)).collect();
            let nov = p[0] * p[4] + p[1] * p[5] + p[2] * p[6];
            assert!((0.0..=1.0).contains(&p[3]), "roughness {}", p[3]);
            visible += (nov > 0.0) as u32;
        }
        assert!(visible as usize > a.words.len() / PIXEL_FLOATS * 9 / 10, "most pixels face the camera");
    }

    /// The angle between two unit vectors, well conditioned near zero (1 - dot is not, in f32).
    fn angle(a: Vec3, b: Vec3) -> f32 {
        a.cross(b).length().atan2(a.dot(b))
    }

    #[test]
    fn packing_keeps_each_value_to_its_quantisation() {
        let (w, h) = (97, 53);
        let packed = synthetic(w, h, GBufferFormat::Packed);
        let camera = Camera::new(w, h);
        for y in 0..h {
            for x in 0..w {
                let s = surface(&camera, w, h, x, y);
                let i = (y * w + x) as usize * 4;
                let u = unpack(&packed.words[i..i + 4], &camera, x, y);
                // snorm16 octahedral: < 1e-4 rad; unorm8: half a step.
                assert!(angle(u.normal, s.normal) < 1e-4, "normal at ({x}, {y}): {:?} vs {:?}", u.normal, s.normal);
                assert!(
                    (u.roughness - s.roughness).abs() <= 0.5 / 255.0 + 1e-6
                        && (u.metallic - s.metallic).abs() <= 0.5 / 255.0 + 1e-6
                );
                assert!((u.base - s.base).abs().max_element() <= 0.5 / 255.0 + 1e-6);
                assert_eq!(u.view, s.view, "V is reconstructed exactly as it was made");
            }
        }
    }

    #[test]
    fn octahedral_encoding_round_trips_the_lower_hemisphere() {
        for n in [Vec3::new(0.3, -0.4, -0.866), Vec3::new(-0.7, 0.1, -0.7), -Vec3::Z, Vec3::X] {
            let n = n.normalize();
            let words = [pack_snorm2x16(octahedral_encode(n)), 0, 0, 0];
            let u = unpack(&words, &Camera::new(1, 1), 0, 0);
            assert!(angle(u.normal, n) < 1e-4, "{n:?} -> {:?}", u.normal);
        }
    }
}
