//! What the driver says about a compiled pipeline, through VK_KHR_pipeline_executable_properties (RADV, ANV,
//! NVIDIA, ...; not lavapipe 22.3): every statistic of every executable, verbatim, its subgroup size, and the
//! internal representations (e.g. ACO's IR and disassembly) when the kernel was created to capture them.

use super::Kernel;
use anyhow::{Context, Result};
use ash::vk;
use std::ffi::CStr;

/// One statistic as the driver reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct DriverStat {
    /// The executable's name (e.g. "Compute Shader"), then the statistic's.
    pub executable: String,
    pub name: String,
    pub description: String,
    pub value: f64,
}

/// One executable of a pipeline (a compute pipeline has one): its statistics, subgroup (wave) size and, when
/// captured, internal representations as (name, text).
#[derive(Clone, Debug, Default)]
pub struct PipelineExecutable {
    pub name: String,
    pub subgroup_size: u32,
    pub stats: Vec<DriverStat>,
    pub representations: Vec<(String, String)>,
}

/// The executable name of statistics a driver printed on stderr (`GpuOptions::compiler_log`).
pub const LOGGED_EXECUTABLE: &str = "Compute Shader";

fn text(r: std::result::Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    r.map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn value(s: &vk::PipelineExecutableStatisticKHR) -> f64 {
    // SAFETY: `format` says which member of the union the driver wrote.
    unsafe {
        match s.format {
            vk::PipelineExecutableStatisticFormatKHR::BOOL32 => f64::from(s.value.b32),
            vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64 as f64,
            vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64 as f64,
            vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => s.value.f64,
            _ => f64::NAN,
        }
    }
}

impl Kernel<'_> {
    /// The pipeline's executables, or None when the device lacks VK_KHR_pipeline_executable_properties.
    pub fn executables(&self) -> Result<Option<Vec<PipelineExecutable>>> {
        let beside = self.gpu.compiler_log.is_some_and(|l| l.beside_properties);
        if let (Some(stats), false) = (&self.logged_stats, beside) {
            return Ok(Some(vec![PipelineExecutable {
                name: LOGGED_EXECUTABLE.into(),
                subgroup_size: 0,
                stats: stats.clone(),
                representations: Vec::new(),
            }]));
        }
        let Some(ext) = &self.gpu.executable_properties else { return Ok(None) };
        let info = vk::PipelineInfoKHR::default().pipeline(self.pipeline);
        // SAFETY: the pipeline was created on this device with CAPTURE_STATISTICS (Kernel::new sets it whenever
        // the extension is enabled) and lives through these calls.
        let executables =
            unsafe { ext.get_pipeline_executable_properties(&info) }.context("vkGetPipelineExecutablePropertiesKHR")?;
        let mut out = Vec::new();
        for (index, exe) in executables.iter().enumerate() {
            let name = text(exe.name_as_c_str());
            let exe_info =
                vk::PipelineExecutableInfoKHR::default().pipeline(self.pipeline).executable_index(index as u32);
            // SAFETY: as above; index < the executable count the driver returned.
            let stats = unsafe { ext.get_pipeline_executable_statistics(&exe_info) }
                .context("vkGetPipelineExecutableStatisticsKHR")?;
            let mut stats: Vec<DriverStat> = stats
                .iter()
                .map(|s| DriverStat {
                    executable: name.clone(),
                    name: text(s.name_as_c_str()),
                    description: text(s.description_as_c_str()),
                    value: value(s),
                })
                .collect();
            let mut representations = Vec::new();
            if self.captures_ir || self.gpu.representation_stats.is_some() {
                representations = self.representations(ext, &exe_info)?;
            }
            if let Some(reader) = self.gpu.representation_stats {
                let (_, ir) = representations.iter().find(|(n, _)| n == reader.name).with_context(|| {
                    format!("{}: the driver returned no internal representation `{}`", self.name, reader.name)
                })?;
                let read = (reader.read)(ir).with_context(|| format!("{}: its {}", self.name, reader.name))?;
                stats.extend(read.into_iter().map(|(stat, value)| DriverStat {
                    executable: name.clone(),
                    description: format!("read from the driver's {}", reader.name),
                    name: stat,
                    value,
                }));
            }
            if !self.captures_ir {
                representations.clear();
            }
            out.push(PipelineExecutable { name, subgroup_size: exe.subgroup_size, stats, representations });
        }
        // Logged statistics beside the extension's join the (one) compute executable's, under its name.
        if let (Some(logged), Some(first)) = (&self.logged_stats, out.first_mut()) {
            first.stats.extend(logged.iter().map(|s| DriverStat { executable: first.name.clone(), ..s.clone() }));
        }
        Ok(Some(out))
    }

    /// The textual internal representations of one executable (the two-call idiom: sizes, then data).
    fn representations(
        &self,
        ext: &ash::khr::pipeline_executable_properties::Device,
        exe: &vk::PipelineExecutableInfoKHR,
    ) -> Result<Vec<(String, String)>> {
        let fp = ext.fp();
        let device = self.gpu.device.handle();
        let mut count = 0u32;
        // SAFETY: first call with a null array asks for the count.
        unsafe {
            (fp.get_pipeline_executable_internal_representations_khr)(device, exe, &mut count, std::ptr::null_mut())
        }
        .result()
        .context("vkGetPipelineExecutableInternalRepresentationsKHR")?;
        let mut reps = vec![vk::PipelineExecutableInternalRepresentationKHR::default(); count as usize];
        // SAFETY: second call fills `count` entries with their sizes (p_data null).
        unsafe {
            (fp.get_pipeline_executable_internal_representations_khr)(device, exe, &mut count, reps.as_mut_ptr())
        }
        .result()
        .context("vkGetPipelineExecutableInternalRepresentationsKHR")?;
        let mut buffers: Vec<Vec<u8>> = reps.iter().map(|r| vec![0u8; r.data_size]).collect();
        for (r, b) in reps.iter_mut().zip(&mut buffers) {
            r.p_data = b.as_mut_ptr().cast();
        }
        // SAFETY: third call writes into the buffers, each as large as the driver asked for; they outlive it.
        unsafe {
            (fp.get_pipeline_executable_internal_representations_khr)(device, exe, &mut count, reps.as_mut_ptr())
        }
        .result()
        .context("vkGetPipelineExecutableInternalRepresentationsKHR")?;
        Ok(reps
            .iter()
            .zip(buffers)
            .filter(|(r, _)| r.is_text == vk::TRUE)
            .map(|(r, b)| {
                let end = b.iter().position(|&c| c == 0).unwrap_or(b.len());
                (text(r.name_as_c_str()), String::from_utf8_lossy(&b[..end]).into_owned())
            })
            .collect())
    }
}
