//! Small helpers shared by several modules.

/// Integer hash to [0, 1) (PCG-style), so synthetic G-buffers and pictures are identical on every run and
/// machine.
pub fn hash01(mut x: u32) -> f32 {
    x = x.wrapping_mul(747796405).wrapping_add(2891336453);
    x = ((x >> ((x >> 28) + 4)) ^ x).wrapping_mul(277803737);
    x = (x >> 22) ^ x;
    (x >> 8) as f32 / (1u32 << 24) as f32
}
