//! `brdfprof compare FILE.json ...`: saved `profile` and `inspect` reports (from different machines, a CI
//! matrix of GPUs, compile-only targets) merged into one cost table, its JSON and a PNG chart.

use super::check_output;
use anyhow::Result;
use brdfprof::{compare, export::json, io};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct CompareArgs {
    /// `brdfprof profile` or `brdfprof inspect` JSON reports (one device or several each), or `check`
    /// baselines. Files whose kernels differ (SPIR-V hash of a model) are refused.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// JSON output (default results/compare.json).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Markdown output (default results/compare.md).
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// PNG chart of each model's net cost relative to ggx per device (default results/compare.png).
    #[arg(long)]
    pub chart: Option<PathBuf>,
}

impl super::Run for CompareArgs {
    fn run(&self) -> Result<ExitCode> {
        compare(self)
    }
}

pub fn compare(args: &CompareArgs) -> Result<ExitCode> {
    check_output("--json", args.json.as_deref(), "results", "compare.json")?;
    check_output("--markdown", args.markdown.as_deref(), "results", "compare.md")?;
    check_output("--chart", args.chart.as_deref(), "results", "compare.png")?;
    let asked = [
        ("--json", args.json.as_deref()),
        ("--markdown", args.markdown.as_deref()),
        ("--chart", args.chart.as_deref()),
    ];
    super::checked_outputs(&asked, &args.files.iter().map(|f| ("FILE", f.as_path())).collect::<Vec<_>>())?;
    let table = compare::from_files(&args.files)?;
    let json = args.json.clone().unwrap_or_else(|| PathBuf::from("results/compare.json"));
    let markdown = args.markdown.clone().unwrap_or_else(|| PathBuf::from("results/compare.md"));
    let chart = args.chart.clone().unwrap_or_else(|| PathBuf::from("results/compare.png"));
    let files: Vec<String> = args.files.iter().map(|f| f.display().to_string()).collect();
    let text = format!("# brdfprof compare\n\n{}\n\n{}", files.join(", "), table.markdown());
    json::write_report(&json, json::Kind::Compare, &table)?;
    io::write_markdown(&markdown, &text)?;
    table.chart(&chart)?;
    out!("{text}");
    outln!("{}", super::written(&[json, markdown, chart]));
    Ok(ExitCode::SUCCESS)
}
