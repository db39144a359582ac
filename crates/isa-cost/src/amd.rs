//! The AMD families RADV compiles for without the hardware (`RADV_FORCE_FAMILY`), and the names it gives
//! their null devices: the table both `radv` (the target) and `radv_child` (the child process that runs RADV
//! with the variable set) read, below both so neither names the other for it.

use anyhow::Result;

/// One family RADV can compile for without the hardware.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Family {
    /// RADV_FORCE_FAMILY's name for it (Mesa's `ac_get_family_name`, lower case).
    pub family: &'static str,
    /// The graphics IP level ACO compiles for.
    pub gfx: &'static str,
    /// The architecture, as AMD names it.
    pub architecture: &'static str,
    /// Products built on it.
    pub products: &'static str,
    /// The subgroup (wave) size RADV compiles compute shaders for on this family by default (Mesa 22.3:
    /// wave64 everywhere; RDNA runs wave32 natively too, with RADV_PERFTEST=cswave32). A test checks it
    /// against the subgroupSize the driver reports for every family.
    pub wave_size: u32,
    /// In `radv:all`.
    pub default: bool,
}

const fn t(
    family: &'static str,
    gfx: &'static str,
    architecture: &'static str,
    products: &'static str,
    default: bool,
) -> Family {
    Family { family, gfx, architecture, products, wave_size: 64, default }
}

/// Every family Mesa 22.3.6 accepted in RADV_FORCE_FAMILY (navi31, gfx1030 and gfx900 it did not), oldest
/// first.
pub const FAMILIES: [Family; 12] = [
    t("tahiti", "GFX6", "GCN 1", "Radeon HD 7970", true),
    t("bonaire", "GFX7", "GCN 2", "Radeon R7 260X, HD 7790", false),
    t("polaris10", "GFX8", "GCN 4", "Radeon RX 470/480/570/580", true),
    t("vega10", "GFX9", "GFX9 Vega", "Radeon RX Vega 56/64", true),
    t("raven", "GFX9", "GFX9 Vega APU", "Ryzen 2000/3000 APUs (Vega graphics)", false),
    t("navi10", "GFX10", "RDNA 1", "Radeon RX 5700 (XT)", true),
    t("navi14", "GFX10", "RDNA 1", "Radeon RX 5500 (XT)", false),
    t("navi21", "GFX10.3", "RDNA 2", "Radeon RX 6800/6900 (XT)", true),
    t("navi22", "GFX10.3", "RDNA 2", "Radeon RX 6700 (XT)", false),
    t("vangogh", "GFX10.3", "RDNA 2 Steam Deck APU", "Steam Deck (Van Gogh)", true),
    t("rembrandt", "GFX10.3", "RDNA 2 APU", "Ryzen 6000 APUs (Radeon 680M)", false),
    // Mesa 22.3's ACO models GFX11 as GFX10.3 (no dual issue, the same cost table): its figures are RDNA 2's
    // model of RDNA 3 code, not RDNA 3's.
    t("gfx1100", "GFX11", "RDNA 3 as Mesa 22.3 models it", "Radeon RX 7900 (XT/XTX, Navi 31)", true),
];

impl Family {
    /// The graphics IP major version (`GFX10.3`: 10).
    pub fn gfx_major(&self) -> u32 {
        self.gfx.trim_start_matches("GFX").split('.').next().and_then(|v| v.parse().ok()).unwrap_or(0)
    }

    /// Whether ACO's cost model gives it full-rate v_fma_f32 before GFX10 (`has_fast_fma32` in Mesa 22.3's
    /// aco_ir.cpp: GFX9 and later, and Tahiti, Hawaii and Carrizo).
    pub fn fast_fma(&self) -> bool {
        self.gfx_major() >= 9 || ["tahiti", "hawaii", "carrizo"].contains(&self.family)
    }
}

/// A family by its name (case-insensitive).
pub fn lookup(family: &str) -> Result<&'static Family> {
    FAMILIES
        .iter()
        .find(|t| t.family.eq_ignore_ascii_case(family.trim()))
        .ok_or_else(|| anyhow::anyhow!("unknown AMD family `{family}`"))
}

/// The compile-only devices' name as RADV gives it: "Null hardware (RADV NAVI21)".
pub fn null_device_name(t: &Family) -> String {
    format!("Null hardware (RADV {})", t.family.to_ascii_uppercase())
}

/// The family of a RADV null device's name, if it is one.
pub fn family_of_device(name: &str) -> Option<&'static Family> {
    let inner = name.strip_prefix("Null hardware (RADV ")?.strip_suffix(')')?;
    FAMILIES.iter().find(|t| t.family.eq_ignore_ascii_case(inner))
}

/// The environment variable RADV reads.
pub const FORCE_FAMILY_VAR: &str = "RADV_FORCE_FAMILY";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn null_device_names_round_trip() {
        for t in &FAMILIES {
            assert_eq!(family_of_device(&null_device_name(t)), Some(t));
        }
        assert_eq!(family_of_device("llvmpipe (LLVM 15.0.6, 256 bits)"), None);
    }
}
