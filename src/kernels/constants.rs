//! Every kernel-level specialisation constant, named once: `glsl()` declares them in
//! glsl/generated/kernel_constants.glsl (included by every kernel) and the host sets them by these names.
//! Ids 0..2 select the terms and 3..15 are the term parameters (`brdf::terms::PARAMS`); these start at 16.

use crate::brdf::glsl_gen;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConstantKind {
    Int,
    Float,
}

/// One specialisation constant: its GLSL name, id, type, default and what it means.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant {
    pub name: &'static str,
    pub id: u32,
    pub kind: ConstantKind,
    pub default: f64,
    pub about: &'static str,
}

const fn int(name: &'static str, id: u32, default: i32, about: &'static str) -> Constant {
    Constant { name, id, kind: ConstantKind::Int, default: default as f64, about }
}

pub const NUM_LIGHTS: Constant =
    int("NUM_LIGHTS", 16, 8, "shade.glsl: directional lights per dispatch (a block of the profile's lights)");
pub const BASELINE: Constant = int("BASELINE", 17, 0, "shade.comp: 1 = the memory-only kernel (no BRDF)");
pub const ALBEDO_N: Constant = int("ALBEDO_N", 18, 256, "albedo estimator: columns per component and azimuth rows");
pub const NUM_DIRECTIONAL: Constant = int("NUM_DIRECTIONAL", 19, 1, "scene.comp: directional lights");
pub const NUM_POINT: Constant = int("NUM_POINT", 20, 0, "scene.comp: point lights");
pub const NUM_SPOT: Constant = int("NUM_SPOT", 21, 0, "scene.comp: spot lights");
pub const NUM_SPHERE: Constant = int("NUM_SPHERE", 22, 0, "scene.comp: sphere lights");
pub const ANISOTROPY: Constant =
    int("ANISOTROPY", 23, 0, "scene effect: 0 off, 1 on (per-pixel strength; 0 = isotropic)");
pub const ENERGY_COMPENSATION: Constant =
    int("ENERGY_COMPENSATION", 24, 0, "scene effect: 0 off, 1 every pixel, 2 per-pixel flag");
pub const DIFFUSE: Constant = int("DIFFUSE", 25, 0, "scene effect: 0 none, 1 Lambert, 2 Burley, 3 per-pixel choice");
pub const CLEAR_COAT: Constant =
    int("CLEAR_COAT", 26, 0, "scene effect: 0 off, 1 on (per-pixel strength and roughness)");
pub const E_TABLE_MU: Constant = int("E_TABLE_MU", 27, 32, "E(mu, r) table: mu nodes (mu_i = (i + 0.5) / N)");
pub const E_TABLE_R: Constant = int("E_TABLE_R", 28, 16, "E(mu, r) table: r nodes (r_j = j / (M - 1))");
pub const ACCUMULATE: Constant =
    int("ACCUMULATE", 29, 0, "shade.glsl: 1 = add to the radiance an earlier light block wrote");

/// Lights per dispatch of the profiling kernel at most (a compile-time size in the GLSL: `#define LIGHT_BLOCK`).
pub const LIGHT_BLOCK: u32 = 8;

pub const ALL: &[Constant] = &[
    NUM_LIGHTS,
    BASELINE,
    ALBEDO_N,
    NUM_DIRECTIONAL,
    NUM_POINT,
    NUM_SPOT,
    NUM_SPHERE,
    ANISOTROPY,
    ENERGY_COMPENSATION,
    DIFFUSE,
    CLEAR_COAT,
    E_TABLE_MU,
    E_TABLE_R,
    ACCUMULATE,
];

/// glsl/generated/kernel_constants.glsl: every constant of `ALL` and `LIGHT_BLOCK`.
pub fn glsl() -> String {
    let mut out = format!(
        "{}// Kernel-level specialisation constants (src/kernels/constants.rs), declared for every kernel.\n#ifndef KERNEL_CONSTANTS_GLSL\n#define KERNEL_CONSTANTS_GLSL\n",
        glsl_gen::HEADER
    );
    for c in ALL {
        let (ty, value) = match c.kind {
            ConstantKind::Int => ("int", format!("{}", c.default as i64)),
            ConstantKind::Float => ("float", glsl_gen::float(c.default)),
        };
        out += &format!("layout(constant_id = {}) const {ty} {} = {value}; // {}\n", c.id, c.name, c.about);
    }
    out += &format!("#define LIGHT_BLOCK {LIGHT_BLOCK} // shade.glsl: lights per dispatch at most\n#endif\n");
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::terms::PARAMS;

    #[test]
    fn ids_are_unique_and_above_the_term_constants() {
        let mut ids: Vec<u32> = ALL
            .iter()
            .map(|c| c.id)
            .chain(PARAMS.iter().map(|p| p.constant_id))
            .chain([0, 1, 2, crate::brdf::guards::GUARDS_CONSTANT_ID])
            .collect();
        let n = ids.len();
        ids.sort();
        ids.dedup();
        assert_eq!(ids.len(), n, "specialisation constant ids collide");
        assert!(ALL.iter().all(|c| c.id >= 16) && PARAMS.iter().all(|p| (3..16).contains(&p.constant_id)));
    }
}
