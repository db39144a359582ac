//! The brdfprof command line: one file and function per command (`cli/<command>.rs`; the arguments several
//! share in `cli/args.rs`), each parsing its arguments, calling the library and writing its reports. Exit
//! status: 0 success; 1 the command ran and found a problem (stability, regression); 2 bad input or anything
//! that stopped the command from measuring.

mod cli;

use clap::{CommandFactory, Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "brdfprof", version, about = "Evaluate and profile specular BRDFs in Vulkan compute kernels")]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Seconds any one compilation may take (glslang, the driver's pipeline creation, a compile-only child)
    /// before the command stops with exit status 2, naming it (default 60; also BRDFPROF_COMPILE_TIMEOUT).
    #[arg(long, global = true, value_name = "SECONDS", value_parser = cli::args::compile_timeout)]
    compile_timeout: Option<std::time::Duration>,
    /// Every note about the models' files on its own line (by default alike notes are one line with a count,
    /// and those that need nothing done, such as a loop within lavapipe's limit, are left out).
    #[arg(long, global = true)]
    verbose: bool,
}

/// The one list of commands: clap derives the command line from it (each variant's doc comment is its help),
/// and `commands!` the dispatch, through each arguments type's `cli::Run`. A new command is a line here and its
/// file `cli/<command>.rs`.
macro_rules! commands {
    ($($(#[$meta:meta])* $variant:ident($args:ty),)*) => {
        #[derive(Subcommand)]
        enum Command {
            $($(#[$meta])* $variant($args),)*
        }

        impl Command {
            fn args(&self) -> &dyn cli::Run {
                match self {
                    $(Command::$variant(a) => a,)*
                }
            }
        }
    };
}

commands! {
    /// List Vulkan devices with the properties that matter for profiling.
    Devices(cli::devices::DevicesArgs),
    /// List the terms (with citations) and presets that model specs can name.
    Models(cli::models::ModelsArgs),
    /// Evaluate f_s of one model on the GPU for every row of a CSV file.
    Eval(cli::eval::EvalArgs),
    /// Evaluate two models on the same inputs (a CSV or seeded samples) and report how far B is from A: per
    /// channel max and RMS relative and absolute difference, the worst rows, a histogram; optional CSV of both
    /// outputs, JSON report and a picture (lit spheres, difference maps, lobes). Exit 1 above --tolerance.
    Diff(cli::diff::DiffArgs),
    /// Measure the cost per BRDF evaluation of models over a synthetic G-buffer lit by several lights.
    Profile(cli::profile::ProfileArgs),
    /// Time and measure the accuracy of many model specs in one interleaved run: table, JSON and a chart of
    /// error against cost with the Pareto frontier, under --out (default results/).
    Sweep(cli::sweep::SweepArgs),
    /// Run the hard-case catalogue, dense grids, reciprocity and energy checks on the GPU for every spec
    /// (default: every D x Vis and every Fresnel on ggx, fp32 and fp16). Exit 1 when any spec yields NaN, Inf
    /// or a negative value on a valid input.
    Stability(cli::stability::StabilityArgs),
    /// Instruction counts of each model's specialised shading kernel: SPIR-V by class (glslang and
    /// spirv-opt -O), naga's analysis, driver statistics, and on lavapipe the CPU instructions executed per
    /// BRDF evaluation (callgrind).
    Inspect(cli::inspect::InspectArgs),
    /// Measures the counts and a short timing run and compares them with a saved baseline: exit 0 no
    /// regression, 1 regression, 2 could not measure.
    Check(cli::check::CheckArgs),
    /// Merge saved profile and inspect JSON reports (other machines, GPUs, compile-only targets) into one
    /// cost table across devices with rank correlations, its JSON and a PNG chart; refuses reports whose
    /// kernels differ.
    Compare(cli::compare::CompareArgs),
    /// One self-contained HTML page (opens from file://) of saved profile, sweep, stability, inspect and
    /// compare reports: provenance, cost tables with CIs, the table across devices, the accuracy-against-cost
    /// chart, lobes, lit spheres and albedo per model (evaluated on the device now), stability heat maps.
    Report(cli::report::ReportArgs),
    /// Check a scene file and say what it compiles in; --explain prints the scene format with an example.
    Scene(cli::scene::SceneArgs),
    /// Render a scene: a tone-mapped sRGB PNG per model, the comparison grid, difference heat maps against ggx
    /// and polar lobe plots, under --out (default results/scenes/<scene name>/).
    Render(cli::render::RenderArgs),
    /// The disk cache of compiled kernels: `show` (directory, entries, size) or `clear`.
    Cache(cli::cache::CacheArgs),
    /// Print a completion script for SHELL on stdout (`make install` installs bash's, zsh's and fish's).
    Completions(Completions),
    /// Writes the man pages (brdfprof.1 and one per command) into DIR (`make install` runs it).
    #[command(name = "__man", hide = true)]
    Man(cli::hidden::Man),
    #[command(name = "__callgrind-child", hide = true)]
    CallgrindChild(cli::hidden::CallgrindChild),
    #[command(name = "__noop-child", hide = true)]
    NoopChild(cli::hidden::NoopChild),
    #[command(name = "__run-translation", hide = true)]
    RunTranslation(cli::hidden::RunTranslation),
    #[command(name = "__probe-vulkan", hide = true)]
    ProbeVulkan(cli::hidden::ProbeVulkan),
    /// Writes glsl/generated/ from the Rust term tables (`make spv` runs it).
    #[command(name = "__generate-glsl", hide = true)]
    GenerateGlsl(cli::hidden::GenerateGlsl),
}

/// `completions SHELL`, here with the whole command line it describes.
#[derive(clap::Args)]
struct Completions {
    #[arg(value_enum)]
    shell: clap_complete::Shell,
}

impl cli::Run for Completions {
    fn run(&self) -> anyhow::Result<ExitCode> {
        clap_complete::generate(self.shell, &mut Cli::command(), "brdfprof", &mut std::io::stdout());
        Ok(ExitCode::SUCCESS)
    }
}

impl cli::Run for cli::hidden::Man {
    fn run(&self) -> anyhow::Result<ExitCode> {
        cli::hidden::man(Cli::command(), &self.dir)
    }
}

fn main() -> ExitCode {
    cli::command_started();
    let cli = Cli::parse();
    brdfprof::messages::set_verbose(cli.verbose);
    let args = cli.command.args();
    if let Err(e) = cli::prepare(args.child(), cli.compile_timeout) {
        return cli::finish(Err(e));
    }
    cli::finish(args.run())
}
