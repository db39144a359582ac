//! README and docs/ against the tree: README stays short, its Layout names every top-level folder and
//! everything directly in `src/` and `crates/` and nothing that does not exist, every docs page (docs/targets/ too) is linked
//! from README, and every relative link (with its `#anchor`) of README and docs/ leads somewhere.

use crate::common;
use std::collections::BTreeSet;
use std::path::Path;

/// The most lines README may have (a README a newcomer reads to the end).
const README_MAX_LINES: usize = 250;

fn read(rel: &str) -> String {
    std::fs::read_to_string(common::repo_root().join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Markdown text without its HTML comments (README keeps the lines of pages still to land in one).
fn without_comments(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find("<!--") {
        out += &rest[..start];
        rest = rest[start..].find("-->").map_or("", |end| &rest[start + end + 3..]);
    }
    out + rest
}

/// The paths README's Layout names: the first word of each line of its code block that starts in column 0.
fn layout_paths(readme: &str) -> Vec<String> {
    let section = readme.split("\n## Layout\n").nth(1).expect("README has a `## Layout` section");
    let block = section.split("```").nth(1).expect("README's Layout has a code block");
    block
        .lines()
        .filter(|l| !l.is_empty() && !l.starts_with(' '))
        .map(|l| l.split_whitespace().next().unwrap().to_string())
        .collect()
}

/// Top-level names `.gitignore` ignores (its anchored one-name patterns: `/target`, `/gpu-run/`).
fn ignored_top_level(root: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(root.join(".gitignore")).unwrap_or_default();
    text.lines()
        .filter_map(|l| l.strip_prefix('/'))
        .map(|l| l.trim_end_matches('/'))
        .filter(|l| !l.is_empty() && !l.contains(['/', '*', '!']))
        .map(str::to_string)
        .collect()
}

fn entries(dir: &Path) -> Vec<(String, bool)> {
    let mut v: Vec<(String, bool)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path().is_dir()))
        .collect();
    v.sort();
    v
}

#[test]
fn readme_is_short_and_its_test_command_is_what_ci_runs() {
    let readme = read("README.md");
    let lines = readme.lines().count();
    assert!(
        lines <= README_MAX_LINES,
        "README.md has {lines} lines, more than {README_MAX_LINES}: move detail to docs/"
    );
    let ci = read(".ci/run");
    let command =
        ci.lines().map(str::trim).rfind(|l| !l.is_empty() && !l.starts_with('#')).expect(".ci/run runs a command");
    let first_screen: String = readme.lines().take(40).collect::<Vec<_>>().join("\n");
    assert!(
        first_screen.contains(&format!("\n{command} ")),
        "README's first screen must show `{command}`, what .ci/run runs"
    );
    assert!(first_screen.contains("\nmake run "), "README's first screen must show `make run`");
}

#[test]
fn readme_layout_names_every_top_level_folder_src_and_crates_entry_and_only_real_paths() {
    let root = common::repo_root();
    let named = layout_paths(&read("README.md"));
    let missing: Vec<&String> = named.iter().filter(|p| !root.join(p).exists()).collect();
    assert!(missing.is_empty(), "README's Layout names paths that do not exist: {missing:?}");
    let named: BTreeSet<String> = named.iter().map(|p| p.trim_end_matches('/').to_string()).collect();
    let ignored = ignored_top_level(&root);
    let mut unnamed = Vec::new();
    for (name, is_dir) in entries(&root) {
        if is_dir && name != ".git" && !ignored.contains(&name) && !named.contains(&name) {
            unnamed.push(format!("{name}/"));
        }
    }
    for folder in ["src", "crates"] {
        for (name, _) in entries(&root.join(folder)) {
            if !named.contains(&format!("{folder}/{name}")) {
                unnamed.push(format!("{folder}/{name}"));
            }
        }
    }
    assert!(unnamed.is_empty(), "README's Layout misses {unnamed:?}: give each a line");
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces to hyphens.
fn anchor(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The relative link targets of a Markdown text (`](target)`), outside HTML comments.
fn relative_links(text: &str) -> Vec<String> {
    let text = without_comments(text);
    text.split("](")
        .skip(1)
        .filter_map(|s| s.split(')').next())
        .filter(|t| !t.contains("://") && !t.starts_with("mailto:"))
        .map(str::to_string)
        .collect()
}

/// The Markdown pages under `folder` and its folders (docs/targets/: one page per compile-only vendor), as paths
/// from the repository root.
fn docs_pages(root: &Path, folder: &str) -> Vec<String> {
    let mut pages = Vec::new();
    for (name, is_dir) in entries(&root.join(folder)) {
        let path = format!("{folder}/{name}");
        if is_dir {
            pages.extend(docs_pages(root, &path));
        } else if name.ends_with(".md") {
            pages.push(path);
        }
    }
    pages
}

#[test]
fn every_docs_page_is_linked_from_readme_and_every_relative_link_leads_somewhere() {
    let root = common::repo_root();
    let mut pages = vec!["README.md".to_string()];
    let mut docs = BTreeSet::new();
    for page in docs_pages(&root, "docs") {
        docs.insert(page.clone());
        pages.push(page);
    }
    pages.push("glsl/README.md".to_string());
    let linked: BTreeSet<String> =
        relative_links(&read("README.md")).iter().map(|t| t.split('#').next().unwrap().to_string()).collect();
    let unlinked: Vec<&String> = docs.iter().filter(|d| !linked.contains(*d)).collect();
    assert!(unlinked.is_empty(), "docs pages README does not link: {unlinked:?}");
    let mut broken = Vec::new();
    for page in &pages {
        let dir = Path::new(page).parent().unwrap();
        for target in relative_links(&read(page)) {
            let (file, fragment) = target.split_once('#').unwrap_or((&target, ""));
            let path = if file.is_empty() { page.clone() } else { dir.join(file).to_string_lossy().into_owned() };
            let full = root.join(&path);
            if !full.exists() {
                broken.push(format!("{page}: {target} (no {path})"));
            } else if !fragment.is_empty() && path.ends_with(".md") {
                let text = std::fs::read_to_string(&full).unwrap();
                if !text
                    .lines()
                    .filter_map(|l| l.strip_prefix('#'))
                    .map(|l| anchor(l.trim_start_matches('#')))
                    .any(|a| a == fragment)
                {
                    broken.push(format!("{page}: {target} (no heading #{fragment} in {path})"));
                }
            }
        }
    }
    assert!(broken.is_empty(), "broken relative links:\n{}", broken.join("\n"));
}

/// Every environment variable brdfprof reads (a `"BRDFPROF_..."` string in src/ or crates/ that is not
/// a macro of the translation's C preludes) is in docs/commands.md's table of them.
#[test]
fn every_environment_variable_brdfprof_reads_is_documented() {
    fn walk(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else {
                out.push(p);
            }
        }
    }
    let table = read("docs/commands.md");
    let mut files = Vec::new();
    for dir in common::source_dirs() {
        walk(&dir, &mut files);
    }
    let macros: String = files
        .iter()
        .filter(|f| f.extension().is_some_and(|x| x == "h"))
        .map(|f| std::fs::read_to_string(f).unwrap())
        .collect();
    let mut missing = BTreeSet::new();
    for f in files.iter().filter(|f| f.extension().is_some_and(|x| x == "rs")) {
        let text = std::fs::read_to_string(f).unwrap();
        for (i, _) in text.match_indices("\"BRDFPROF_") {
            let name: String = text[i + 1..]
                .chars()
                .take_while(|c| c.is_ascii_uppercase() || c.is_ascii_digit() || *c == '_')
                .collect();
            if !macros.contains(&name) && !table.contains(&format!("| `{name}")) {
                missing.insert(name);
            }
        }
    }
    assert!(missing.is_empty(), "not in docs/commands.md's table of environment variables: {missing:?}");
}
