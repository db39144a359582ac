//! A Mesa Vulkan driver on Mesa's noop drm-shim, as data: the files of the build `make mesa` made, the
//! variable that picks the GPU, the families, and the driver's cost rule. `adreno.rs`, `mali.rs`, `anv.rs` and
//! `nak.rs` are one `Shim` each; the child process, its environment checks and crash handling are `mesa_noop`'s.

use super::NoopDriver;
use crate::gpu::{CompilerLog, RepresentationStats};
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use crate::targets::{Family, Request, Run, Vendor, mesa_noop};
use anyhow::Result;
use std::collections::BTreeMap;

/// One GPU a shim impersonates.
pub struct ShimFamily {
    /// The name after the prefix (`a660`).
    pub name: &'static str,
    /// The value of the driver's GPU variable (`660`, `0x7212`, `tgl`).
    pub gpu_id: &'static str,
    pub architecture: &'static str,
    pub products: &'static str,
    /// What else identifies it (the GPU id, the compiler generation).
    pub detail: &'static str,
    /// In `PREFIX:all`.
    pub default: bool,
    /// The Mesa build whose driver compiles for it.
    pub build: &'static mesa_noop::builds::MesaBuild,
    /// Why the validation layer cannot judge the driver's compilations for it, where it cannot.
    pub without_validation: Option<&'static str>,
}

impl ShimFamily {
    /// A family in `PREFIX:all` whose driver `build` made, validated by the Khronos layer.
    pub const fn on(
        build: &'static mesa_noop::builds::MesaBuild,
        name: &'static str,
        gpu_id: &'static str,
        architecture: &'static str,
        products: &'static str,
        detail: &'static str,
    ) -> ShimFamily {
        ShimFamily { name, gpu_id, architecture, products, detail, default: true, build, without_validation: None }
    }

    /// The same, compiled without the validation layer, for `why`.
    pub const fn unvalidated(self, why: &'static str) -> ShimFamily {
        ShimFamily { without_validation: Some(why), ..self }
    }
}

/// A driver on a noop drm-shim.
pub struct Shim {
    pub prefix: &'static str,
    /// The GPU vendor ("Qualcomm").
    pub vendor: &'static str,
    pub title: &'static str,
    /// Mesa's driver ("Turnip").
    pub driver: &'static str,
    /// The compiler ("ir3").
    pub compiler: &'static str,
    /// Under the build directory (`mesa_noop::builds::build_dir`): the driver's devenv ICD file, the driver library it
    /// names and the shim (scripts/mesa-noop.sh builds exactly these; a test ties the two lists).
    pub icd: &'static str,
    pub library: &'static str,
    pub shim: &'static str,
    /// The shim's variable that picks the GPU, and any other variable the driver needs.
    pub gpu_var: &'static str,
    pub extra_env: &'static [(&'static str, &'static str)],
    pub families: &'static [ShimFamily],
    /// The cost table of a report of this driver (its family's `ShimFamily`).
    pub cost: fn(&Shim, &ShimFamily, &InspectReport) -> Option<TargetCost>,
    /// Statistics the compiler prints on stderr, for a driver without VK_KHR_pipeline_executable_properties.
    pub compiler_log: Option<CompilerLog>,
    /// Statistics read from one of the driver's internal representations (NAK's assembly).
    pub representation_stats: Option<RepresentationStats>,
}

impl Shim {
    /// The cost table's header for a report of `family`: the rule text, unit and columns are the driver's.
    pub fn header(
        &self,
        family: &ShimFamily,
        report: &InspectReport,
        model: String,
        unit: &str,
        columns: &[&str],
    ) -> TargetCost {
        TargetCost {
            device: report.provenance["device"]["name"].as_str().unwrap_or("?").to_string(),
            target: Some(format!("{}:{}", self.prefix, family.name)),
            family: Some(family.name.to_string()),
            architecture: Some(family.architecture.to_string()),
            compiler: format!(
                "{} (Mesa {}, on the noop drm-shim)",
                self.compiler,
                mesa_noop::driver_version(report).trim_start_matches("Mesa ")
            ),
            model,
            unit: unit.to_string(),
            lights_per_kernel: 0,
            columns: columns.iter().map(|c| c.to_string()).collect(),
            rows: Vec::new(),
            absent: Vec::new(),
            failed: Vec::new(),
            checked: None,
        }
    }
}

impl Vendor for Shim {
    fn prefix(&self) -> &'static str {
        self.prefix
    }

    fn name(&self) -> &'static str {
        self.vendor
    }

    fn title(&self) -> &'static str {
        self.title
    }

    fn families(&self) -> Vec<Family> {
        self.families
            .iter()
            .map(|f| Family {
                name: f.name,
                architecture: f.architecture,
                products: f.products,
                detail: f.detail.to_string(),
                default: f.default,
            })
            .collect()
    }

    fn status(&self) -> Result<String> {
        // Per Mesa build: its families are ready, or why not; the vendor is ready where any build is.
        let mut ready: Vec<String> = Vec::new();
        let mut missing: Vec<(String, anyhow::Error)> = Vec::new();
        let mut seen: Vec<&mesa_noop::builds::MesaBuild> = Vec::new();
        for (k, f) in self.families.iter().enumerate() {
            if seen.iter().any(|b| std::ptr::eq(*b, f.build)) {
                continue;
            }
            seen.push(f.build);
            let names = self
                .families
                .iter()
                .filter(|g| std::ptr::eq(g.build, f.build))
                .map(|g| g.name)
                .collect::<Vec<_>>()
                .join(", ");
            match self.environment(k) {
                Ok(_) => ready.push(format!("{} ({names})", f.build.dir().display())),
                Err(e) => missing.push((names, e)),
            }
        }
        if ready.is_empty() {
            return Err(missing
                .into_iter()
                .next()
                .map(|(_, e)| e)
                .unwrap_or_else(|| anyhow::anyhow!("{}: no family", self.prefix)));
        }
        let mut text = format!(
            "Mesa's {} ({} compiler) on its noop drm-shim, built by make mesa in {}",
            self.driver,
            self.compiler,
            ready.join(" and ")
        );
        for (names, e) in missing {
            text += &format!("; not built for {names}: {e:#}");
        }
        Ok(text)
    }

    fn needs_verification(&self) -> bool {
        false
    }

    fn compile(&self, families: &[usize], request: &Request) -> Result<Vec<Run>> {
        mesa_noop::parent::compile(self.prefix, families, &[], request)
    }

    fn compile_raw(
        &self,
        families: &[usize],
        kernels: &[crate::targets::RawKernel],
        request: &Request,
    ) -> Result<Vec<Run>> {
        if kernels.is_empty() {
            anyhow::bail!("{}: no raw kernel to compile", self.prefix);
        }
        mesa_noop::parent::compile(self.prefix, families, kernels, request)
    }

    fn cost(&self, report: &InspectReport) -> Option<TargetCost> {
        let family = mesa_noop::family_of(self, report)?;
        (self.cost)(self, &self.families[family], report)
    }

    fn family_of(&self, report: &InspectReport) -> Option<usize> {
        mesa_noop::family_of(self, report)
    }

    fn fingerprint(&self, report: &InspectReport) -> BTreeMap<String, String> {
        mesa_noop::fingerprint(report)
    }

    fn noop(&self) -> Option<&dyn NoopDriver> {
        Some(self)
    }
}

impl NoopDriver for Shim {
    fn compiler(&self) -> &'static str {
        self.compiler
    }

    fn environment(&self, family: usize) -> Result<Vec<(String, String)>> {
        let mut extra: Vec<(&str, String)> = vec![(self.gpu_var, self.families[family].gpu_id.to_string())];
        extra.extend(self.extra_env.iter().map(|(k, v)| (*k, v.to_string())));
        let f = &self.families[family];
        mesa_noop::builds::shim_environment(
            &format!("{}:{} (Mesa's {})", self.prefix, f.name, self.driver),
            f.build,
            self.icd,
            self.library,
            self.shim,
            &extra,
        )
    }

    fn install_hint(&self) -> String {
        format!(
            "`make mesa` builds Mesa's drivers and their noop shims (once per machine, ~20 min); `brdfprof devices --targets` says whether {}: is ready",
            self.prefix
        )
    }

    fn compiler_log(&self) -> Option<CompilerLog> {
        self.compiler_log
    }

    fn representation_stats(&self) -> Option<RepresentationStats> {
        self.representation_stats
    }

    fn without_validation(&self, family: usize) -> Option<&'static str> {
        self.families[family].without_validation
    }
}
