//! The key under which a compile-only child's report is cached (`cache.rs`'s rule: everything that reaches
//! the compiler). A child's figures depend on the kernels it compiles, the driver that compiles them and the
//! environment the driver reads; the key holds:
//! - every kernel's SPIR-V and selecting constants (`kernel_hash`, the models' and the memory-only one; a raw
//!   kernel's words and interface), the models' spec texts, the light count, whether validation ran;
//! - the driver: the child's environment (family variable, ICD, shim), each Vulkan ICD file the loader of the
//!   child reads and the library it names, and every `LD_PRELOAD` file, each by path, size and modification
//!   time (a rebuilt Mesa, or another installed one, is another key);
//! - the variables of this process that Mesa, the loader or the dynamic linker read (`MESA_*`, `RADV_*`,
//!   `ACO_*`, `TU_*`, `IR3_*`, `PAN_*`, `PANVK_*`, `BIFROST_*`, `INTEL_*`, `ANV_*`, `NIR_*`, `VK_*`, `LD_*`,
//!   `XDG_DATA_*`, `XDG_CONFIG_*`, `HOME`...), which the child inherits;
//! - with `--validate`, each validation layer manifest the child's loader may read and its library;
//! - spirv-opt's version (the report's `spirv-O` counts are its output);
//! - brdfprof's executable by size and modification time (the child's analyses are its code).
//!
//! A request that writes files (`--isa`) or asks the child to crash (the containment test) is never cached
//! (`mesa_noop::parent::compile` decides).

use crate::cache::{Key, KeyBuilder};
use crate::kernels::shade::{GBufferFormat, kernel_hash};
use crate::model::Model;
use crate::shaders::Shaders;
use crate::targets::RawKernel;
use anyhow::Result;
use std::path::{Path, PathBuf};

/// The cache kind of a child's report.
pub const KIND: &str = "noop_report";

/// Prefixes of the variables a Mesa driver, the Vulkan loader or the dynamic linker may read.
const DRIVER_PREFIXES: [&str; 21] = [
    "MESA_",
    "RADV_",
    "ACO_",
    "TU_",
    "IR3_",
    "FD_",
    "PAN_",
    "PANVK_",
    "BIFROST_",
    "MIDGARD_",
    "INTEL_",
    "ANV_",
    "BRW_",
    "NIR_",
    "GALLIUM_",
    "LP_",
    "VK_",
    "LD_",
    "XDG_DATA",
    "XDG_CONFIG",
    "HOME",
];

/// The Vulkan loader's system folders (where no variable names the files), under which `vulkan/icd.d` holds
/// the drivers' manifests and `vulkan/explicit_layer.d` the layers' (the user's `~/.local/share` too).
const VULKAN_DIRS: [&str; 5] = ["/etc/xdg", "/etc", "/usr/local/share", "/usr/share", "/usr/local/etc"];

/// The system folders of `kind` (`icd.d`), and the user's.
fn vulkan_dirs(kind: &str, environment: &std::collections::BTreeMap<String, String>) -> Vec<PathBuf> {
    let home = environment.get("HOME").map(|h| PathBuf::from(h).join(".local/share"));
    VULKAN_DIRS.iter().map(PathBuf::from).chain(home).map(|d| d.join("vulkan").join(kind)).collect()
}

/// Every JSON manifest under `dirs`, sorted.
fn manifests(dirs: &[PathBuf]) -> Vec<PathBuf> {
    let mut all: Vec<PathBuf> =
        dirs.iter().flat_map(|d| std::fs::read_dir(d).into_iter().flatten().flatten().map(|e| e.path())).collect();
    all.sort();
    all
}

/// The validation layer's manifests and the libraries they name (`--validate` runs it in the child).
fn layer_files(environment: &std::collections::BTreeMap<String, String>) -> Vec<PathBuf> {
    let dirs: Vec<PathBuf> = match environment.get("VK_LAYER_PATH").filter(|s| !s.is_empty()) {
        Some(list) => std::env::split_paths(list).collect(),
        None => vulkan_dirs("explicit_layer.d", environment),
    };
    manifests(&dirs).into_iter().flat_map(|m| [manifest_library(&m, "layer"), Some(m)]).flatten().collect()
}

/// The part of a child's key that every family of one request shares: brdfprof's executable, spirv-opt's
/// version, the light count, whether validation runs, and every kernel's SPIR-V (computed once per request).
pub fn request_digest(
    models: &[Model],
    raw: &[RawKernel],
    lights: u32,
    validate: bool,
    shaders: &Shaders,
) -> Result<String> {
    let exe = crate::cleanup::own_executable()?;
    let mut key = KeyBuilder::new(KIND)
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("executable", identity(&exe))
        // The SPIR-V counts of the report are spirv-opt's.
        .part("spirv-opt", crate::spirv::spirv_opt_version().unwrap_or_default())
        .part("lights", lights.to_le_bytes())
        .part("validate", [validate as u8]);
    // Both G-buffer forms: the report's static rows read the float one too (naga's analysis).
    for model in models {
        key = key.part("model", model.name());
        for format in [GBufferFormat::Packed, GBufferFormat::Float] {
            key = key.part("kernel", kernel_hash(Some(model), format, shaders)?);
        }
    }
    if raw.is_empty() {
        for format in [GBufferFormat::Packed, GBufferFormat::Float] {
            key = key.part("memory-only kernel", kernel_hash(None, format, shaders)?);
        }
    }
    for r in raw {
        let interface = format!("{} {} {} {}", r.label, r.model.name(), r.storage_buffers, r.push_bytes);
        key = key.part("raw", interface).part("raw words", bytemuck::cast_slice::<u32, u8>(&r.spirv));
    }
    Ok(key.finish().hex().to_string())
}

/// The key of one child's report: the request's digest, the target (`adreno:a660`) and its driver
/// environment, with the files and variables the child's driver and loader read.
pub fn key(request_digest: &str, target: &str, driver_environment: &[(String, String)], validate: bool) -> Key {
    let mut key = KeyBuilder::new(KIND).part("request", request_digest).part("target", target);
    let mut environment: std::collections::BTreeMap<String, String> =
        std::env::vars().filter(|(k, _)| DRIVER_PREFIXES.iter().any(|p| k.starts_with(p))).collect();
    environment.extend(driver_environment.iter().cloned());
    for (k, v) in &environment {
        key = key.part("env", format!("{k}={v}"));
    }
    for file in driver_files(&environment) {
        key = key.part("driver file", identity(&file));
    }
    if validate {
        for file in layer_files(&environment) {
            key = key.part("layer file", identity(&file));
        }
    }
    key.finish()
}

/// A file by its path, size and modification time (nanoseconds), or that it is absent.
fn identity(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(m) => {
            let mtime = m
                .modified()
                .ok()
                .and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos());
            format!("{} {} {mtime}", path.display(), m.len())
        }
        Err(_) => format!("{} absent", path.display()),
    }
}

/// The ICD files the child's loader reads (the variables' list, else the system directories), the library
/// each names, and the preloaded files.
fn driver_files(environment: &std::collections::BTreeMap<String, String>) -> Vec<PathBuf> {
    let named =
        ["VK_DRIVER_FILES", "VK_ICD_FILENAMES"].iter().find_map(|v| environment.get(*v).filter(|s| !s.is_empty()));
    let icds: Vec<PathBuf> = match named {
        Some(list) => std::env::split_paths(list).collect(),
        None => manifests(&vulkan_dirs("icd.d", environment)),
    };
    let mut files = Vec::new();
    for icd in icds {
        if let Some(library) = manifest_library(&icd, "ICD") {
            files.push(library);
        }
        files.push(icd);
    }
    if let Some(preload) = environment.get("LD_PRELOAD") {
        files.extend(preload.split([' ', ':']).filter(|s| !s.is_empty()).map(PathBuf::from));
    }
    files
}

/// The library a manifest's `section` (`ICD`, `layer`) names: relative to the manifest's folder when it is a
/// relative path; a bare name as the dynamic linker finds it in the system's library folders.
fn manifest_library(manifest: &Path, section: &str) -> Option<PathBuf> {
    let text = std::fs::read_to_string(manifest).ok()?;
    let json: serde_json::Value = serde_json::from_str(&text).ok()?;
    let library = Path::new(json[section]["library_path"].as_str()?);
    if library.is_absolute() {
        return Some(library.to_path_buf());
    }
    if library.components().count() > 1 {
        return Some(manifest.parent()?.join(library));
    }
    let system = ["/usr/lib/x86_64-linux-gnu", "/usr/lib", "/lib/x86_64-linux-gnu", "/usr/local/lib"];
    system.iter().map(|d| Path::new(d).join(library)).find(|p| p.exists()).or_else(|| Some(library.to_path_buf()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_changes_its_identity_when_rewritten() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("lib.so");
        assert!(identity(&path).ends_with("absent"));
        std::fs::write(&path, b"one").unwrap();
        let first = identity(&path);
        std::fs::write(&path, b"three").unwrap();
        assert_ne!(first, identity(&path));
    }

    #[test]
    fn an_icd_names_its_library_and_the_preloaded_shim_counts() {
        let dir = tempfile::tempdir().unwrap();
        let icd = dir.path().join("x_icd.json");
        std::fs::write(&icd, r#"{"file_format_version": "1.0.0", "ICD": {"library_path": "./lib/libvulkan_x.so", "api_version": "1.3"}}"#).unwrap();
        let env = [
            ("VK_ICD_FILENAMES".to_string(), icd.display().to_string()),
            ("LD_PRELOAD".to_string(), "/s/shim.so".to_string()),
        ]
        .into();
        let files = driver_files(&env);
        assert_eq!(files, vec![dir.path().join("./lib/libvulkan_x.so"), icd, PathBuf::from("/s/shim.so")]);
    }
}
