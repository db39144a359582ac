//! The layer order of src/: no module names (`crate::X`, in a `use` line or a path) a top-level module above
//! it, and no circle runs among the files and folders of any folder (`super::X` / `crate::DIR::X`, through any
//! number of steps). Below src/, the leaf crates of crates/ are kept apart by the compiler; the test here holds what each may depend on.

use crate::common;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Top-level modules of src/, lowest first: a module may use only those before it. Written once, here.
const LAYERS: &[&str] = &[
    "host_cpu",
    "stats",
    "io",
    "shaders",
    "spirv",
    "model",
    "kernels",
    "accuracy",
    "export",
    "schema",
    "kernel_stats",
    "measure",
    "profile",
    "translate",
    "targets",
    "compare",
    "inspect",
    "check",
    "sweep",
    "stability",
    "scene",
    "diff",
    "report",
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

/// A file's module path under src/ (`model/brdf_file/mod.rs` -> [model, brdf_file]).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel.with_extension("").iter().map(|p| p.to_string_lossy().to_string()).collect();
    if parts.last().is_some_and(|l| l == "mod") || parts == ["lib"] || parts == ["main"] {
        parts.pop();
    }
    parts
}

/// Every module path `text` names: `crate::a::b`, `super::a` (from module `own`), and each of a `{a, b::c}` group.
fn paths_named(text: &str, own: &[String]) -> BTreeSet<Vec<String>> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| s.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect::<String>();
    for line in text.lines().map(|l| l.split("//").next().unwrap_or("")) {
        for (i, _) in line.match_indices("crate::").chain(line.match_indices("super::")) {
            // Only the start of a path: `super::super::x` is read once, from its first `super::`.
            if line[..i].ends_with("super::") || line[..i].ends_with("crate::") {
                continue;
            }
            let (mut base, mut rest) = (Vec::new(), &line[i..]);
            if let Some(r) = rest.strip_prefix("crate::") {
                rest = r;
            } else {
                base = own.to_vec();
                while let Some(r) = rest.strip_prefix("super::") {
                    base.pop();
                    rest = r;
                }
            }
            loop {
                if let Some(group) = rest.strip_prefix('{') {
                    for part in group.split('}').next().unwrap_or("").split(',') {
                        let n = ident(part.trim());
                        if !n.is_empty() && n != "self" {
                            out.insert([base.clone(), vec![n]].concat());
                        }
                    }
                    out.insert(base.clone());
                    break;
                }
                let n = ident(rest);
                if n.is_empty() {
                    out.insert(base.clone());
                    break;
                }
                base.push(n.clone());
                match rest[n.len()..].strip_prefix("::") {
                    Some(r) => rest = r,
                    None => {
                        out.insert(base.clone());
                        break;
                    }
                }
            }
        }
    }
    out
}

/// The circles among the children (files and folders) of every folder of src/: A uses B when a file in or
/// under A names a module in or under B. Tarjan's strongly connected components, per folder.
#[test]
fn no_circle_among_the_files_and_folders_of_any_folder() {
    let files = sources();
    let modules: BTreeSet<Vec<String>> = files.iter().map(|(rel, _)| module_path(rel)).collect();
    let mut edges: BTreeMap<Vec<String>, BTreeMap<String, BTreeSet<String>>> = BTreeMap::new();
    for (rel, text) in &files {
        let own = module_path(rel);
        for named in paths_named(text, &own) {
            // The longest module the path names (the rest are items in it).
            let Some(target) = (0..=named.len()).rev().map(|k| &named[..k]).find(|p| modules.contains(*p)) else {
                continue;
            };
            let common = own.iter().zip(target).take_while(|(a, b)| a == b).count();
            if common == own.len() || common == target.len() {
                continue; // a module and its own parent or child
            }
            let folder = own[..common].to_vec();
            edges.entry(folder).or_default().entry(own[common].clone()).or_default().insert(target[common].clone());
        }
    }
    let mut circles = Vec::new();
    for (folder, graph) in &edges {
        for component in strongly_connected(graph).into_iter().filter(|c| c.len() > 1) {
            circles.push(format!("src/{}: {} use each other", folder.join("/"), component.join(", ")));
        }
    }
    assert!(circles.is_empty(), "circles among modules:\n{}", circles.join("\n"));
}

fn strongly_connected(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, (usize, usize)>,
        stack: Vec<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, (i, i));
        s.stack.push(v);
        for w in s.graph.get(v).into_iter().flatten() {
            match s.index.get(w.as_str()) {
                None => {
                    visit(s, w);
                    let low = s.index[w.as_str()].1.min(s.index[v].1);
                    s.index.get_mut(v).unwrap().1 = low;
                }
                Some(&(wi, _)) if s.stack.contains(&w.as_str()) => {
                    let low = wi.min(s.index[v].1);
                    s.index.get_mut(v).unwrap().1 = low;
                }
                _ => {}
            }
        }
        if s.index[v].0 == s.index[v].1 {
            let at = s.stack.iter().rposition(|x| *x == v).unwrap();
            let mut component: Vec<String> = s.stack.drain(at..).map(String::from).collect();
            component.sort();
            s.out.push(component);
        }
    }
    let mut s = State { graph, index: BTreeMap::new(), stack: Vec::new(), out: Vec::new() };
    for v in graph.keys() {
        if !s.index.contains_key(v.as_str()) {
            visit(&mut s, v);
        }
    }
    s.out
}

#[test]
fn the_circle_search_finds_a_circle_across_folders() {
    let a = paths_named(
        "use crate::model::file_model::X;\nuse super::{front, brdf_file::{self, Y}};",
        &["model".into(), "brdf_file".into()],
    );
    assert!(a.contains(&vec!["model".to_string(), "file_model".to_string(), "X".to_string()]), "{a:?}");
    assert!(a.contains(&vec!["model".to_string(), "front".to_string()]), "{a:?}");
    let graph: BTreeMap<String, BTreeSet<String>> =
        [("brdf_file", &["file_model", "front"][..]), ("file_model", &["brdf_file"][..]), ("front", &[][..])]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v.iter().map(|x| x.to_string()).collect()))
            .collect();
    let circles: Vec<_> = strongly_connected(&graph).into_iter().filter(|c| c.len() > 1).collect();
    assert_eq!(circles, vec![vec!["brdf_file".to_string(), "file_model".to_string()]]);
}

/// The crates below the application and the heavy dependencies each may name: only the Vulkan backend touches
/// ash, only the shader front ends naga and naga_oil; none names plotters, the application, or a crate beside it
/// that it does not list (the cost rule and its listing parsers, `isa-cost`, name nothing at all).
#[test]
fn leaf_crates_keep_their_dependencies() {
    const HEAVY: &[&str] = &["ash", "naga", "naga_oil", "plotters", "brdfprof"];
    const ALLOWED: &[(&str, &[&str])] = &[
        ("brdf", &[]),
        ("files", &["brdfprof-process"]),
        ("front", &["naga", "naga_oil", "brdfprof-files", "brdfprof-process"]),
        ("isa-cost", &[]),
        ("process", &[]),
        ("spirv-c", &[]),
        ("vulkan", &["ash", "brdfprof-process"]),
    ];
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

/// The application crate holds at most 70% of the product's Rust (src/ against src/ and crates/ together):
/// what needs nothing above it lives in a leaf crate with its own tests.
#[test]
fn the_application_holds_at_most_70_percent_of_the_rust_lines() {
    let lines = |dir: &str| {
        let mut files = Vec::new();
        rust_files(&common::repo_root().join(dir), &mut files);
        files.iter().map(|f| std::fs::read_to_string(f).unwrap().lines().count()).sum::<usize>()
    };
    let (app, leaves) = (lines("src"), lines("crates"));
    let share = app as f64 / (app + leaves) as f64;
    assert!(share <= 0.70, "src/ holds {app} of {} Rust lines ({:.1}%)", app + leaves, share * 100.0);
}

/// Every dependency a manifest declares is named in its crate's code (comments left out): the application's
/// in src/, build.rs or tests/, a leaf crate's in its src/ or tests/.
#[test]
fn every_dependency_is_used() {
    let root = common::repo_root();
    let mut crates = vec![(root.join("Cargo.toml"), vec![root.join("src"), root.join("tests"), root.join("build.rs")])];
    for e in std::fs::read_dir(root.join("crates")).unwrap() {
        let dir = e.unwrap().path();
        crates.push((dir.join("Cargo.toml"), vec![dir.join("src"), dir.join("tests")]));
    }
    let mut unused = Vec::new();
    for (manifest, places) in crates {
        let text = std::fs::read_to_string(&manifest).unwrap();
        let mut code = String::new();
        for place in places.iter().filter(|p| p.exists()) {
            let mut files = Vec::new();
            if place.is_dir() {
                rust_files(place, &mut files);
            } else {
                files.push(place.clone());
            }
            for f in files {
                for line in std::fs::read_to_string(f).unwrap().lines() {
                    code.push_str(line.split("//").next().unwrap_or(""));
                    code.push('\n');
                }
            }
        }
        for section in ["[dependencies]", "[dev-dependencies]"] {
            let deps = text.split(section).nth(1).unwrap_or("").split("\n[").next().unwrap_or("");
            for line in deps.lines().filter(|l| !l.trim().is_empty() && !l.starts_with('#')) {
                let dep = line.split(|c: char| c == '=' || c == '.' || c.is_whitespace()).next().unwrap_or("");
                // The application's own test-only features are the dev-dependency on itself.
                if dep.is_empty() || dep == "brdfprof" {
                    continue;
                }
                let ident = dep.replace('-', "_");
                // A path into the crate (`name::`) or a `use name as ...`, not its name in a string or a comment.
                let path = format!("{ident}::");
                let named = code.match_indices(&path).any(|(i, _)| {
                    code[..i].chars().next_back().is_none_or(|c| !c.is_alphanumeric() && c != '_' && c != '"')
                }) || code.contains(&format!("use {ident} as "));
                if !named {
                    unused.push(format!("{}: {dep} ({section})", manifest.strip_prefix(&root).unwrap().display()));
                }
            }
        }
    }
    assert!(unused.is_empty(), "dependencies no code names:\n{}", unused.join("\n"));
}
