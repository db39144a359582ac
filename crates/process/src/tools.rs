//! Where brdfprof finds the tools `make setup` and `make mesa` install for it (NVIDIA's NVRTC and nvdisasm,
//! Slang's slangc, the link to IGA's library, the Mesa builds), each a folder of its own name (`nvidia`, `slang`,
//! `intel`, `mesa`, `mesa25`, `mesa25-nvk`), the first that exists of:
//! 1. the folder the tool's variable names (`BRDFPROF_NVIDIA_DIR`, ...), an override;
//! 2. beside an installed binary: `<prefix>/share/brdfprof/tools/NAME` for `<prefix>/bin/brdfprof` (`make
//!    install`);
//! 3. the per-user data directory `$XDG_DATA_HOME/brdfprof/tools/NAME` (default `~/.local/share/...`), which
//!    `make setup` and `make mesa` fill, so that a binary built anywhere (`cargo install --path .`) finds them;
//! 4. the build checkout's `.tools/NAME`, while the checkout is where it was built.
//!
//! So a binary installed or copied elsewhere, its build checkout moved or deleted, still finds them.

use std::path::{Path, PathBuf};

/// Each tool folder with the variable that overrides it and the one command that installs it.
pub const TOOLS: [(&str, &str, &str); 6] = [
    ("nvidia", "BRDFPROF_NVIDIA_DIR", "make setup"),
    ("slang", "BRDFPROF_SLANG_DIR", "make setup"),
    ("intel", "BRDFPROF_INTEL_DIR", "make setup"),
    ("mesa", "BRDFPROF_MESA_DIR", "make mesa"),
    ("mesa25", "BRDFPROF_MESA25_DIR", "make mesa"),
    ("mesa25-nvk", "BRDFPROF_MESA25_NVK_DIR", "make mesa"),
];

/// The per-user data directory's tools folder: `$XDG_DATA_HOME/brdfprof/tools`, else
/// `$HOME/.local/share/brdfprof/tools` (the XDG Base Directory default).
pub fn data_dir() -> Option<PathBuf> {
    let nonempty = |v: &str| std::env::var_os(v).filter(|d| !d.is_empty()).map(PathBuf::from);
    let base = nonempty("XDG_DATA_HOME").or_else(|| nonempty("HOME").map(|h| h.join(".local/share")))?;
    Some(base.join("brdfprof/tools"))
}

/// The tools folder beside the running binary: `<prefix>/share/brdfprof/tools` for `<prefix>/bin/brdfprof`.
fn beside_binary() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    Some(exe.parent()?.parent()?.join("share/brdfprof/tools"))
}

/// The build checkout's `.tools` (this crate lives in `crates/process` of it).
fn checkout() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../.tools")
}

/// Where tool `name` (a folder of `TOOLS`) is looked for, in order, each with how it was found.
pub fn candidates(name: &str) -> Vec<(PathBuf, String)> {
    let var = TOOLS.iter().find(|t| t.0 == name).map_or("", |t| t.1);
    let mut out = Vec::new();
    if let Some(d) = std::env::var_os(var).filter(|d| !d.is_empty()) {
        out.push((PathBuf::from(d), format!("${var}")));
    }
    if let Some(d) = beside_binary() {
        out.push((d.join(name), "beside the binary (make install)".into()));
    }
    if let Some(d) = data_dir() {
        out.push((d.join(name), "the per-user data directory".into()));
    }
    out.push((checkout().join(name), "the build checkout".into()));
    out
}

/// Where tool `name` is: the first candidate that exists (a variable's folder is taken as given, existing or
/// not, so that its error names it), else where `make setup`/`make mesa` puts it (the data directory), with how
/// it was found (or "not installed").
pub fn locate(name: &str) -> (PathBuf, String) {
    let all = candidates(name);
    if let Some((d, how)) = all.first().filter(|(_, how)| how.starts_with('$')) {
        return (d.clone(), how.clone());
    }
    if let Some((d, how)) = all.iter().find(|(d, _)| d.exists()) {
        return (normal(d), how.clone());
    }
    let fallback = data_dir().map_or_else(|| checkout().join(name), |d| d.join(name));
    (fallback, "not installed".into())
}

/// `a/b/../c` as `a/c` (no file system access), so that a path a message names reads plainly.
fn normal(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            std::path::Component::ParentDir if out.file_name().is_some() => {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// The folder of tool `name` (`locate`).
pub fn dir(name: &str) -> PathBuf {
    locate(name).0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_tool_has_a_variable_and_the_checkout_comes_last() {
        for (name, var, install) in TOOLS {
            assert!(var.starts_with("BRDFPROF_") && install.starts_with("make "), "{name}");
            let all = candidates(name);
            assert!(all.last().unwrap().0.ends_with(format!(".tools/{name}")), "{all:?}");
        }
        assert_eq!(normal(Path::new("/a/b/../c/./d")), PathBuf::from("/a/c/d"));
    }
}
