//! `--device mali:FAMILY`: Arm Mali Bifrost (the installed Mesa 22.3) and Valhall (bookworm-backports' Mesa 25.0)
//! through Mesa's PanVK driver on the panfrost noop drm-shim (`PAN_GPU_ID`). PanVK 22.3 is marked
//! non-conformant (it needs PAN_I_WANT_A_BROKEN_VULKAN_DRIVER=1); its shader compiler is Panfrost's Bifrost
//! backend, the production one Panfrost's OpenGL ES driver uses (Mesa 25.0's compiles Valhall too). PanVK 22.3
//! has no VK_KHR_pipeline_executable_properties (25.0's has, without statistics): with
//! BIFROST_MESA_DEBUG=shaderdb the compiler prints one `SHADER-DB:` line per shader on stderr, which the child captures for each pipeline (`gpu::GpuOptions::
//! compiler_log`) and reads here.
//!
//! The cost is the compiler's own (`bi_print_stats` in src/panfrost/bifrost/bifrost_compile.c, Mesa 22.3):
//! per-pipe cycles per thread, normalised to 24 arithmetic tuples, 2 texture messages, 16 16-bit varying
//! channels and 1 load/store message per cycle ("seem to match Arm Mobile Studio's heuristic"), with the bound
//! the busiest pipe, the shape of Arm's Mali Offline Compiler report. They count the program's instructions
//! once each: a loop's body is counted once, a branch's two sides both. `cycles/eval = bound / lights per
//! kernel`; the net figure is the pipe-parallel bound of the work the BRDF adds, `max over pipes of (kernel's
//! pipe - memory-only kernel's pipe) / lights`, with the pipe that binds it named: a max of pipes does not
//! subtract, so the bound of the memory-only kernel (load/store) is not taken from the BRDF's (arithmetic).
//! Valhall's statistics are `va_print_stats`' (same file, Mesa 25.0): FMA and CVT at 64 per cycle, SFU 16,
//! varying 16, texture 4, load/store 1 ("Mali G78 peak performance"), the bound their max, read by the same rule.

use super::cost;
use super::mesa_noop::builds::{MESA_25_UNVALIDATED, MESA_BACKPORTS, MESA_DEBIAN};
use super::mesa_noop::shim::{Shim, ShimFamily};
use crate::gpu::{CompilerLog, DriverStat};
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use anyhow::Result;
use brdfprof_isa_cost::mali::{pipes, pipes_of, read_shaderdb, rolled};

const SHOWN_BIFROST: [&str; 6] =
    ["Instructions", "Tuples", "Clauses", "Arithmetic cycles", "Load-store cycles", "Threads"];
const SHOWN_VALHALL: [&str; 6] =
    ["Instructions", "FMA cycles", "CVT cycles", "SFU cycles", "Load-store cycles", "Threads"];

/// Why PanVK 22.3 (Bifrost) runs unvalidated; Mesa 25.0's PanVK (Vulkan 1.1) for `MESA_25_UNVALIDATED`'s reason.
const PANVK_22_UNVALIDATED: &str = "PanVK 22.3 is a Vulkan 1.0 driver, and brdfprof's kernels are SPIR-V 1.3 (Vulkan 1.1), which the layer refuses on a 1.0 device; the driver compiles them (Mesa's SPIR-V front end reads any version), so its figures stand, unvalidated";

pub static MALI: Shim = Shim {
    prefix: "mali",
    vendor: "Arm",
    title: "Arm Mali: Mesa's PanVK driver (Panfrost's Bifrost compiler) on the panfrost noop drm-shim, in a child process (it compiles, nothing executes)",
    driver: "PanVK",
    compiler: "Bifrost",
    icd: "src/panfrost/vulkan/panfrost_devenv_icd.x86_64.json",
    library: "src/panfrost/vulkan/libvulkan_panfrost.so",
    shim: "src/panfrost/drm-shim/libpanfrost_noop_drm_shim.so",
    gpu_var: "PAN_GPU_ID",
    extra_env: &[("PAN_I_WANT_A_BROKEN_VULKAN_DRIVER", "1"), ("BIFROST_MESA_DEBUG", "shaderdb")],
    // Bifrost v7's G76 (0x7211) and G31 (0x7093) gave G52's statistics for every kernel of the presets and
    // the sweep; v6's G72 schedules differently (5 of the sweep's 58 kernels within 1.5% in cycles) and runs one
    // thread per core where v7 runs two (bi_print_stats: two only on v7 with <= 32 work registers), so it is
    // listed and they are not (docs/targets/mali.md).
    families: &[
        ShimFamily {
            name: "g52",
            gpu_id: "0x7212",
            architecture: "Bifrost (v7)",
            products: "Mali-G52 (Rockchip RK3566/RK3568, Amlogic S922X)",
            detail: "PAN_GPU_ID=0x7212, Bifrost v7",
            default: true,
            build: &MESA_DEBIAN,
            without_validation: Some(PANVK_22_UNVALIDATED),
        },
        ShimFamily {
            name: "g72",
            gpu_id: "0x6221",
            architecture: "Bifrost (v6)",
            products: "Mali-G72 (Exynos 9810, Kirin 970, Helio P60)",
            detail: "PAN_GPU_ID=0x6221, Bifrost v6",
            default: true,
            build: &MESA_DEBIAN,
            without_validation: Some(PANVK_22_UNVALIDATED),
        },
        ShimFamily {
            name: "g610",
            gpu_id: "0xa867",
            architecture: "Valhall (v10)",
            products: "Mali-G610 (Rockchip RK3588, MediaTek Dimensity 1080)",
            detail: "PAN_GPU_ID=0xa867, Valhall v10, Mesa 25.0",
            default: true,
            build: &MESA_BACKPORTS,
            without_validation: Some(MESA_25_UNVALIDATED),
        },
    ],
    cost: cost_table,
    compiler_log: Some(CompilerLog { read: read_log, beside_properties: false }),
    representation_stats: None,
};

/// One pipeline's stderr: its compute shader's `SHADER-DB:` line as the logged executable's statistics.
fn read_log(log: &str) -> Result<(Vec<DriverStat>, Vec<String>)> {
    let (stats, rest) = read_shaderdb(log)?;
    Ok((super::logged(stats), rest))
}

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let valhall = family.architecture.starts_with("Valhall");
    let (rule, shown) = if valhall {
        (
            "cycles/eval = Valhall's bound (max of its FMA, CVT, SFU, varying, texture and load/store cycles per thread, va_print_stats) per evaluation; net = kernel - memory-only kernel, each pipe's difference beside it",
            &SHOWN_VALHALL,
        )
    } else {
        (
            "cycles/eval = Bifrost's bound (max of its arithmetic, texture, varying and load/store cycles per thread, bi_print_stats) per evaluation; net = kernel - memory-only kernel, each pipe's difference beside it",
            &SHOWN_BIFROST,
        )
    };
    let rule = format!(
        "{rule}; per evaluation = / lights per kernel where the light loop is unrolled; where the compiler keeps it (Loops > 0 and not a multiple of the lights: its body, one light, counted once), the per-pixel work (the memory-only kernel's pipes) / lights and the rest whole"
    );
    let unit = if valhall { "Valhall cycles per thread" } else { "Bifrost cycles per thread" };
    let per_pixel = report
        .rows
        .iter()
        .find(|r| {
            r.model == crate::model::BASELINE_LABEL
                && rolled(&r.stats, crate::kernels::shade::steady_block(report.lights).0)
        })
        .and_then(|r| pipes(&r.stats));
    cost::bound_table(report, shim.header(family, report, rule, unit, shown), |stats, lights| {
        pipes_of(stats, lights, per_pixel.as_deref())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::BASELINE_LABEL;
    use crate::schema::Row;

    /// A row with the compiler's statistics `stats` (name, value).
    fn pipe_row(model: &str, stats: &[(&str, f64)]) -> Row {
        Row {
            model: model.into(),
            spec: None,
            stats: stats.iter().map(|(k, v)| (format!("driver/Compute Shader/{k}"), *v)).collect(),
            notes: Default::default(),
        }
    }

    /// The cost table of `rows` as `target`'s child would report them.
    fn cost_of(target: &str, device: &str, rows: Vec<Row>) -> TargetCost {
        let mut report = crate::schema::tests::empty_report(device);
        report.provenance["target"] = target.into();
        report.rows = rows;
        super::super::Vendor::cost(&MALI, &report).unwrap()
    }

    const VALHALL: &str = "SHADER-DB: MESA_SHADER_COMPUTE shader: 809 inst, 18.000000 cycles, 7.921875 fma, 3.546875 cvt, 3.500000 sfu, 0.000000 v, 0.250000 t, 18.000000 ls, 408 quadwords, 1 threads, 0 loops, 0:0 spills:fills";

    #[test]
    fn reads_valhalls_line_and_prices_its_fma_pipe() {
        let (stats, _) = read_shaderdb(VALHALL).unwrap();
        let get = |n: &str| stats.iter().find(|s| s.name == n).map(|s| s.value);
        assert_eq!(
            (
                get("FMA cycles"),
                get("SFU cycles"),
                get("Texture cycles"),
                get("Load-store cycles"),
                get("Bound cycles")
            ),
            (Some(7.921875), Some(3.5), Some(0.25), Some(18.0), Some(18.0))
        );
        let row = |model: &str, fma: f64, sfu: f64| {
            pipe_row(
                model,
                &[
                    ("FMA cycles", fma),
                    ("CVT cycles", 1.0),
                    ("SFU cycles", sfu),
                    ("Texture cycles", 0.0),
                    ("Varying cycles", 0.0),
                    ("Load-store cycles", 18.0),
                    ("Bound cycles", 18.0),
                ],
            )
        };
        let t = cost_of(
            "mali:g610",
            "Mali-G610 (Panfrost)",
            vec![row("ggx", 20.0, 3.5), row("flat", 1.6, 1.0), row(BASELINE_LABEL, 1.5, 1.0)],
        );
        let lights = f64::from(t.lights_per_kernel);
        // FMA binds the kernel (20), load/store the memory-only one (18).
        assert_eq!(t.rows[0].net_cycles_per_eval, Some((20.0 - 18.0) / lights));
        assert_eq!(t.rows[0].bound.as_deref(), Some("FMA"));
        assert!(t.rows[0].net_terms.iter().any(|(n, v)| n == "FMA" && *v == (20.0 - 1.5) / lights));
        // Load/store binds both kernels: a net of 0, said so.
        assert_eq!(t.rows[1].net_cycles_per_eval, Some(0.0));
        assert!(t.markdown().contains("flat: net cost not above zero"), "{}", t.markdown());
        assert!(t.model.contains("va_print_stats") && t.columns.iter().any(|c| c == "FMA cycles"), "{}", t.model);
    }

    #[test]
    fn net_is_the_difference_of_the_bounds_and_a_kept_loop_is_one_evaluation_per_pass() {
        let row = |model: &str, arith: f64, ldst: f64, loops: f64| {
            pipe_row(
                model,
                &[
                    ("Arithmetic cycles", arith),
                    ("Texture cycles", 0.0),
                    ("Varying cycles", 0.0),
                    ("Load-store cycles", ldst),
                    ("Bound cycles", arith.max(ldst)),
                    ("Loops", loops),
                ],
            )
        };
        let t = cost_of(
            "mali:g52",
            "Mali-G52 (Panfrost)",
            vec![row("ggx", 5.75, 8.0, 0.0), row("rolled", 12.0, 8.0, 1.0), row(BASELINE_LABEL, 1.5, 8.0, 0.0)],
        );
        let lights = f64::from(t.lights_per_kernel);
        assert_eq!(t.rows[0].cycles_per_eval, 8.0 / lights);
        // The bounds (8 and 8) subtract to nothing, the net never above that; the arithmetic it adds is the
        // breakdown's.
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(0.0));
        assert_eq!(t.rows[0].bound.as_deref(), Some("load/store"));
        assert!(t.rows[0].net_terms.iter().any(|(n, v)| n == "arithmetic" && *v == 4.25 / lights));
        // A kept loop's body is one light: one pass is one evaluation.
        assert_eq!(t.rows[1].cycles_per_eval, 12.0);
        assert_eq!(t.rows[1].net_cycles_per_eval, Some(12.0 - 8.0 / lights));
        assert_eq!(t.rows[1].bound.as_deref(), Some("arithmetic"));
        assert!(t.markdown().contains("bound by"));
    }

    #[test]
    fn a_rolled_loop_charges_the_per_pixel_work_once_per_pixel() {
        let row = |model: &str, arith: f64, ldst: f64| {
            pipe_row(
                model,
                &[
                    ("Arithmetic cycles", arith),
                    ("Texture cycles", 0.0),
                    ("Varying cycles", 0.0),
                    ("Load-store cycles", ldst),
                    ("Bound cycles", arith.max(ldst)),
                    ("Loops", 1.0),
                ],
            )
        };
        let t = cost_of("mali:g52", "Mali-G52 (Panfrost)", vec![row("small", 3.5, 8.0), row(BASELINE_LABEL, 1.5, 8.0)]);
        let lights = f64::from(t.lights_per_kernel);
        assert!(lights > 1.0);
        // The memory-only kernel: its loads and store once per pixel, / lights.
        assert_eq!(t.rows[1].cycles_per_eval, 8.0 / lights);
        // A BRDF's 2 arithmetic cycles are the light's whole: it no longer hides under the per-pixel loads.
        let small = 2.0 + 1.5 / lights;
        assert_eq!(t.rows[0].cycles_per_eval, small);
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(small - 8.0 / lights));
        assert_eq!(t.rows[0].bound.as_deref(), Some("arithmetic"));
    }
}
