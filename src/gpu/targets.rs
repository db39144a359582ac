//! Compile-only AMD targets: the GPU families whose real compiler (Mesa RADV's ACO) brdfprof can run on a
//! machine without an AMD GPU. With `RADV_FORCE_FAMILY=<family>` in the environment before the Vulkan loader
//! starts, RADV offers a "Null hardware (RADV <FAMILY>)" device: it has no queue that executes anything, but
//! pipeline creation runs ACO for that family and VK_KHR_pipeline_executable_properties returns ACO's
//! statistics. `--device radv:FAMILY` runs brdfprof itself as a child with the variable set
//! (`inspect::radv`), so neither the user's environment nor the parent's devices change.
//!
//! This table is the one list of families; `devices --targets`, `--device radv:...` and `radv:all` read it.

use anyhow::{bail, Result};

/// One family RADV can compile for without the hardware.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Target {
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

const fn t(family: &'static str, gfx: &'static str, architecture: &'static str, products: &'static str, default: bool) -> Target {
    Target { family, gfx, architecture, products, wave_size: 64, default }
}

/// Every family Mesa 22.3.6 accepted in RADV_FORCE_FAMILY (navi31, gfx1030 and gfx900 it did not), oldest
/// first.
pub const TARGETS: [Target; 12] = [
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
    t("gfx1100", "GFX11", "RDNA 3", "Radeon RX 7900 (XT/XTX, Navi 31)", true),
];

/// The prefix of a compile-only device in `--device`.
pub const PREFIX: &str = "radv:";
/// `radv:all`: the default set.
pub const ALL: &str = "all";

/// The families of `radv:all`.
pub fn default_set() -> Vec<&'static Target> {
    TARGETS.iter().filter(|t| t.default).collect()
}

pub fn known() -> String {
    TARGETS.iter().map(|t| t.family).collect::<Vec<_>>().join(", ")
}

/// A family by its name (case-insensitive).
pub fn lookup(family: &str) -> Result<&'static Target> {
    let name = family.trim().to_ascii_lowercase();
    match TARGETS.iter().find(|t| t.family == name) {
        Some(t) => Ok(t),
        None => bail!("unknown AMD family `{family}`; known: {} (or `{PREFIX}{ALL}` for {})", known(), default_set().iter().map(|t| t.family).collect::<Vec<_>>().join(", ")),
    }
}

/// Whether a `--device` value names compile-only targets (`radv:...`).
pub fn is_compile_only(device: &str) -> bool {
    device.trim().to_ascii_lowercase().starts_with(PREFIX)
}

/// The targets a `--device radv:FAMILY` (or `radv:all`, or `radv:a,b`) names; None for any other device.
pub fn parse(device: &str) -> Result<Option<Vec<&'static Target>>> {
    if !is_compile_only(device) {
        return Ok(None);
    }
    let rest = &device.trim()[PREFIX.len()..];
    if rest.trim().is_empty() {
        bail!("`{device}`: give a family after `{PREFIX}`; known: {} (or `{PREFIX}{ALL}`)", known());
    }
    let mut out: Vec<&'static Target> = Vec::new();
    for name in rest.split(',') {
        let found = if name.trim().eq_ignore_ascii_case(ALL) { default_set() } else { vec![lookup(name)?] };
        for t in found {
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    Ok(Some(out))
}

/// The compile-only devices' name as RADV gives it: "Null hardware (RADV NAVI21)".
pub fn null_device_name(t: &Target) -> String {
    format!("Null hardware (RADV {})", t.family.to_ascii_uppercase())
}

/// The family of a RADV null device's name, if it is one.
pub fn family_of_device(name: &str) -> Option<&'static Target> {
    let inner = name.strip_prefix("Null hardware (RADV ")?.strip_suffix(')')?;
    TARGETS.iter().find(|t| t.family.eq_ignore_ascii_case(inner))
}

/// The environment variable RADV reads.
pub const FORCE_FAMILY_VAR: &str = "RADV_FORCE_FAMILY";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_families_all_and_lists() {
        assert_eq!(parse("0").unwrap(), None);
        assert_eq!(parse("llvmpipe").unwrap(), None);
        assert_eq!(parse("radv:navi21").unwrap().unwrap()[0].family, "navi21");
        assert_eq!(parse("RADV:Vangogh").unwrap().unwrap()[0].architecture, "RDNA 2 Steam Deck APU");
        let all = parse("radv:all").unwrap().unwrap();
        assert!(all.len() >= 6 && all.iter().any(|t| t.family == "vega10") && all.iter().any(|t| t.family == "gfx1100"));
        assert_eq!(parse("radv:navi21,navi21,vega10").unwrap().unwrap().len(), 2);
        let e = parse("radv:navi31").unwrap_err().to_string();
        assert!(e.contains("unknown AMD family `navi31`") && e.contains("tahiti") && e.contains("gfx1100"), "{e}");
        assert!(parse("radv:").unwrap_err().to_string().contains("give a family"));
    }

    #[test]
    fn null_device_names_round_trip() {
        for t in &TARGETS {
            assert_eq!(family_of_device(&null_device_name(t)), Some(t));
        }
        assert_eq!(family_of_device("llvmpipe (LLVM 15.0.6, 256 bits)"), None);
    }
}
