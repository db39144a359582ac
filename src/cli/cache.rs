//! `brdfprof cache show|clear`: brdfprof's disk cache of compiled kernels (`brdfprof::cache`).

use anyhow::Result;
use brdfprof::cache::Store;
use clap::{Args, Subcommand};
use std::process::ExitCode;

#[derive(Args)]
pub struct CacheArgs {
    #[command(subcommand)]
    pub action: CacheAction,
}

#[derive(Subcommand)]
pub enum CacheAction {
    /// The cache directory, its entries (per kind, damaged ones named) and their total size.
    Show,
    /// Removes brdfprof's entries from the cache directory (other files there stay).
    Clear,
}

/// Where the directory comes from, for `show`.
fn origin() -> &'static str {
    if std::env::var_os("BRDFPROF_CACHE_DIR").is_some() {
        "BRDFPROF_CACHE_DIR"
    } else if std::env::var_os("XDG_CACHE_HOME").is_some_and(|d| !d.is_empty()) {
        "$XDG_CACHE_HOME/brdfprof/kernels"
    } else {
        "~/.cache/brdfprof/kernels"
    }
}

impl super::Run for CacheArgs {
    fn run(&self) -> Result<ExitCode> {
        cache(self)
    }
}

pub fn cache(args: &CacheArgs) -> Result<ExitCode> {
    let Some(store) = Store::open_default() else {
        outln!(
            "the disk cache is off (BRDFPROF_CACHE_DIR is empty, or no home directory is known): nothing to show or clear"
        );
        return Ok(ExitCode::SUCCESS);
    };
    match args.action {
        CacheAction::Show => show(&store),
        CacheAction::Clear => {
            let (files, bytes) = store.clear()?;
            outln!(
                "removed {files} cache entr{} ({bytes} bytes) from {}",
                if files == 1 { "y" } else { "ies" },
                store.dir().display()
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn show(store: &Store) {
    let entries = store.entries().unwrap_or_else(|e| {
        brdfprof::messages::warning(format!("{e:#}"));
        Vec::new()
    });
    let bytes: u64 = entries.iter().map(|e| e.bytes).sum();
    let mut kinds: std::collections::BTreeMap<String, usize> = std::collections::BTreeMap::new();
    for e in &entries {
        let kind = if e.legacy { format!("{} (older brdfprof, unused)", e.kind) } else { e.kind.clone() };
        *kinds.entry(kind).or_default() += 1;
    }
    outln!("directory: {} ({})", store.dir().display(), origin());
    let per_kind = kinds.iter().map(|(k, n)| format!("{k}: {n}")).collect::<Vec<_>>().join(", ");
    outln!("entries: {}{}", entries.len(), if per_kind.is_empty() { String::new() } else { format!(" ({per_kind})") });
    let human = if bytes >= 1 << 20 {
        format!("{:.1} MiB", bytes as f64 / (1u64 << 20) as f64)
    } else {
        format!("{:.1} KiB", bytes as f64 / 1024.0)
    };
    outln!("total size: {bytes} bytes ({human})");
    for e in entries.iter().filter(|e| e.damaged.is_some()) {
        outln!("damaged (replaced when next used): {} ({})", e.path.display(), e.damaged.as_deref().unwrap_or(""));
    }
}
