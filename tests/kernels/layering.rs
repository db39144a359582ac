//! The layer order of src/: no module names (`crate::X`, in a `use` line or a path) a top-level module above
//! it, and no two files of one folder name each other (`super::X` / `crate::DIR::X`). Below src/, the leaf
//! crates of crates/ are kept apart by the compiler; the test here holds what each may depend on.

use crate::common;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules of src/, lowest first: a module may use only those before it. Written once, here.
const LAYERS: &[&str] = &[
    "host_cpu",
    "stats",
    "io",
    "cache",
    "shaders",
    "model",
    "kernels",
    "spirv",
    "accuracy",
    "export",
    "schema",
    "kernel_stats",
    "profile",
    "translate",
    "targets",
    "inspect",
    "compare",
    "across_devices",
    "check",
    "sweep",
    "sweep_cost",
    "stability",
    "scene",
    "diff",
    "report_page",
];

pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every `PREFIX::name` in `text` (code only: `//` comments dropped).
fn names_after(text: &str, prefix: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for line in text.lines().map(|l| l.split("//").next().unwrap_or("")) {
        for (i, _) in line.match_indices(prefix) {
            let rest = &line[i + prefix.len()..];
            let name: String = rest.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                out.insert(name);
            }
            // `use crate::{a, b}` / `use super::{a, b}`
            if let Some(group) = rest.strip_prefix('{') {
                for part in group.split('}').next().unwrap_or("").split(',') {
                    let n: String =
                        part.trim().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                    if !n.is_empty() {
                        out.insert(n);
                    }
                }
            }
        }
    }
    out
}

fn sources() -> Vec<(PathBuf, String)> {
    let src = common::repo_root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files
        .into_iter()
        .map(|f| (f.strip_prefix(&src).unwrap().to_path_buf(), std::fs::read_to_string(&f).unwrap()))
        .collect()
}

#[test]
fn no_module_uses_one_above_it() {
    let mut bad = Vec::new();
    for (rel, text) in sources() {
        let top = rel.components().next().unwrap().as_os_str().to_string_lossy().trim_end_matches(".rs").to_string();
        if ["main", "lib", "cli"].contains(&top.as_str()) {
            continue;
        }
        let own = LAYERS.iter().position(|l| *l == top).unwrap_or_else(|| {
            panic!("src/{}: module `{top}` is not in LAYERS (tests/kernels/layering.rs)", rel.display())
        });
        for used in names_after(&text, "crate::") {
            match LAYERS.iter().position(|l| *l == used) {
                Some(i) if i > own => {
                    bad.push(format!("src/{} ({top}) uses crate::{used}, a layer above it", rel.display()))
                }
                _ => {}
            }
        }
    }
    assert!(bad.is_empty(), "arrows running back up:\n{}", bad.join("\n"));
}

#[test]
fn no_two_files_of_a_folder_use_each_other() {
    let mut edges: BTreeMap<(String, String), BTreeSet<String>> = BTreeMap::new();
    for (rel, text) in sources() {
        let Some(dir) = rel.parent().filter(|d| !d.as_os_str().is_empty()) else { continue };
        let stem = rel.file_stem().unwrap().to_string_lossy().to_string();
        if stem == "mod" {
            continue;
        }
        let dir = dir.to_string_lossy().replace('/', "::");
        let mut used = names_after(&text, "super::");
        used.extend(names_after(&text, &format!("crate::{dir}::")));
        used.remove(&stem);
        edges.insert((dir, stem), used);
    }
    let mut circles = Vec::new();
    for ((dir, a), used) in &edges {
        for b in used {
            if a < b && edges.get(&(dir.clone(), b.clone())).is_some_and(|u| u.contains(a)) {
                circles.push(format!("src/{dir}: {a} and {b} use each other"));
            }
        }
    }
    assert!(circles.is_empty(), "{}", circles.join("\n"));
}

/// The crates below the application and the heavy dependencies each may name: only the Vulkan backend touches
/// ash; none of them names naga, naga_oil or plotters, nor the application or a crate beside it that it does not list.
#[test]
fn leaf_crates_keep_their_dependencies() {
    const HEAVY: &[&str] = &["ash", "naga", "naga_oil", "plotters", "brdfprof"];
    const ALLOWED: &[(&str, &[&str])] =
        &[("brdf", &[]), ("process", &[]), ("spirv-c", &[]), ("vulkan", &["ash", "brdfprof-process"])];
    let root = common::repo_root().join("crates");
    let mut found = BTreeSet::new();
    for e in std::fs::read_dir(&root).unwrap() {
        let dir = e.unwrap().path();
        let name = dir.file_name().unwrap().to_string_lossy().to_string();
        let allowed = ALLOWED
            .iter()
            .find(|(n, _)| *n == name)
            .unwrap_or_else(|| panic!("crates/{name} is not in ALLOWED (tests/kernels/layering.rs)"))
            .1;
        found.insert(name.clone());
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
        let deps = manifest.split("[dependencies]").nth(1).unwrap_or("").split("\n[").next().unwrap_or("");
        for line in deps.lines() {
            let dep = line.split(|c: char| c == '=' || c == '.' || c.is_whitespace()).next().unwrap_or("");
            let forbidden = (HEAVY.contains(&dep) || dep.starts_with("brdfprof-")) && !allowed.contains(&dep);
            assert!(!forbidden, "crates/{name} depends on {dep}, which it may not name");
        }
    }
    assert_eq!(found.len(), ALLOWED.len(), "a crate of ALLOWED is missing from crates/");
}
