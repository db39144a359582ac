//! Vulkan plumbing: instance and device selection, validation-message capture, buffers, compute kernels,
//! chunked dispatch and timestamp queries. Nothing here knows about BRDFs.

mod driver_stats;
mod kernel;
mod memory;
mod stderr_capture;
mod timing;

pub use driver_stats::{DriverStat, LOGGED_EXECUTABLE, PipelineExecutable};
pub use kernel::{Binding, Bindings, ChunkPlan, Kernel, SpecConstants, TexelFormat, WORKGROUP};
pub use memory::{Buffer, MemoryKind};
pub use timing::Timestamps;

use anyhow::{Context, Result, anyhow, bail};
use ash::vk;
use serde::{Deserialize, Deserializer, Serialize};
use std::ffi::{CStr, c_void};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";
const EXECUTABLE_PROPERTIES_EXT: &CStr = ash::khr::pipeline_executable_properties::NAME;

/// How long a submission may take before the device counts as hung: far above any one submission brdfprof
/// makes (a host batch is at most 1 GiB of input), far below forever.
pub const DEFAULT_FENCE_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(600);
/// Seconds that replace `DEFAULT_FENCE_TIMEOUT` (tests use a tiny one).
pub const FENCE_TIMEOUT_ENV: &str = "BRDFPROF_FENCE_TIMEOUT";

/// The fence timeout in force: `FENCE_TIMEOUT_ENV` when it holds seconds (more than 0), else the default.
pub fn fence_timeout() -> std::time::Duration {
    std::env::var(FENCE_TIMEOUT_ENV)
        .ok()
        .and_then(|t| t.trim().parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s > 0.0 && *s <= 86_400.0)
        .map_or(DEFAULT_FENCE_TIMEOUT, std::time::Duration::from_secs_f64)
}

/// How to open a device.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Index from `brdfprof devices`, or a case-insensitive substring of the device name.
    pub device: Option<String>,
    /// Enable the Khronos validation layer and record every message it reports.
    pub validation: bool,
    /// A driver that prints its compiler's statistics on stderr instead of VK_KHR_pipeline_executable_properties
    /// (PanVK with BIFROST_MESA_DEBUG=shaderdb): what each pipeline creation writes there is captured and read
    /// into statistics by this function (`Kernel::executables`).
    pub compiler_log: Option<CompilerLog>,
    /// Statistics read from one of the driver's internal representations (NVK's "NAK assembly"): every
    /// pipeline is created to capture them, and `Kernel::executables` adds what this reads to its statistics.
    pub representation_stats: Option<RepresentationStats>,
}

/// How to read statistics from an internal representation of a pipeline executable.
#[derive(Clone, Copy, Debug)]
pub struct RepresentationStats {
    /// The representation's name as the driver gives it ("NAK assembly").
    pub name: &'static str,
    /// Its statistics, named as the executable's own are.
    pub read: fn(&str) -> Result<Vec<(String, f64)>>,
}

/// How to read a driver's stderr output of one pipeline creation.
#[derive(Clone, Copy, Debug)]
pub struct CompilerLog {
    /// Its statistics (executable "Compute Shader") and the lines that are not its statistics (they go on to
    /// the real stderr).
    pub read: fn(&str) -> Result<(Vec<DriverStat>, Vec<String>)>,
    /// The statistics join those of VK_KHR_pipeline_executable_properties (ACO's perfinfo schedule beside ACO's
    /// statistics) instead of standing for them (PanVK's shader-db line).
    pub beside_properties: bool,
}

/// Set in a process whose Vulkan devices are drivers on Mesa's noop kernel shims (`targets::mesa_noop`'s child).
static COMPILE_ONLY_PROCESS: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Every device of this process compiles only: nothing is ever submitted, timed or read back.
pub fn mark_compile_only_process() {
    COMPILE_ONLY_PROCESS.store(true, std::sync::atomic::Ordering::Relaxed);
}

/// What `brdfprof devices` lists, and what every report records about the device it measured. Read back
/// from saved reports too: a field an older or a compile-only target's report lacks reads as its default.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct DeviceInfo {
    pub index: usize,
    pub name: String,
    pub device_type: String,
    pub vendor_id: u32,
    pub device_id: u32,
    pub driver_name: String,
    pub driver_info: String,
    pub driver_version: String,
    pub api_version: String,
    /// Nanoseconds per timestamp tick (NaN where the device's is not finite, written as null).
    #[serde(deserialize_with = "null_as_nan")]
    pub timestamp_period: f32,
    /// Valid bits of timestamps on the compute queue (0: no timestamps).
    pub timestamp_valid_bits: u32,
    pub max_storage_buffer_range: u32,
    pub max_texel_buffer_elements: u32,
    pub max_compute_work_group_count: [u32; 3],
    pub max_compute_work_group_invocations: u32,
    pub min_storage_buffer_offset_alignment: u64,
    pub max_memory_allocation_size: u64,
    pub shader_float16: bool,
    pub shader_float64: bool,
    pub pipeline_executable_properties: bool,
}

/// JSON writes a non-finite float as null; it reads back as NaN rather than failing the whole report.
fn null_as_nan<'de, D: Deserializer<'de>>(d: D) -> Result<f32, D::Error> {
    Ok(Option::<f32>::deserialize(d)?.unwrap_or(f32::NAN))
}

impl DeviceInfo {
    /// Mesa and LLVM versions where the driver states them (lavapipe: "Mesa 22.3.6 (LLVM 15.0.6)").
    pub fn mesa_llvm(&self) -> (Option<String>, Option<String>) {
        let find = |key: &str| {
            let text = format!("{} {}", self.driver_info, self.name);
            text.split(key)
                .nth(1)
                .and_then(|rest| rest.split([' ', ')', ',']).find(|w| !w.is_empty()))
                .map(str::to_string)
        };
        (find("Mesa "), find("LLVM "))
    }

    pub fn is_cpu(&self) -> bool {
        self.device_type == "cpu"
    }

    /// A device that compiles pipelines but cannot execute them: RADV's "Null hardware" device
    /// (RADV_FORCE_FAMILY), whose timestampPeriod is not even finite, and every device of a process that runs a
    /// Mesa driver on a noop kernel shim (`mark_compile_only_process`), whose submissions execute nothing.
    pub fn compile_only(&self) -> bool {
        self.name.starts_with("Null hardware")
            || !self.timestamp_period.is_finite()
            || COMPILE_ONLY_PROCESS.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// Validation messages recorded by the debug messenger (warnings and errors of any type).
type Messages = Arc<Mutex<Vec<String>>>;

pub struct Gpu {
    _entry: ash::Entry,
    instance: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT, *mut Messages)>,
    messages: Messages,
    pub(crate) physical: vk::PhysicalDevice,
    pub info: DeviceInfo,
    pub(crate) device: ash::Device,
    pub(crate) executable_properties: Option<ash::khr::pipeline_executable_properties::Device>,
    pub(crate) compiler_log: Option<CompilerLog>,
    pub(crate) representation_stats: Option<RepresentationStats>,
    queue: vk::Queue,
    command_pool: vk::CommandPool,
    memory_properties: vk::PhysicalDeviceMemoryProperties,
    /// Whether anything was ever submitted: a compile-only device (RADV's null winsys) has no queue to wait
    /// on, and its vkDeviceWaitIdle calls through a null pointer, so teardown waits only for real work.
    submitted: std::sync::atomic::AtomicBool,
}

/// A command buffer being recorded (`Gpu::submit`); kernels, barriers and timestamps record into it.
pub struct Commands {
    raw: vk::CommandBuffer,
    /// Kernels dispatched for the first time in this command buffer: lavapipe compiles a pipeline (LLVM) at
    /// its first dispatch, inside the submission, so that submission's wait is a compilation's.
    first_dispatches: std::cell::RefCell<Vec<String>>,
}

fn load_entry() -> Result<ash::Entry> {
    // SAFETY: loading the system Vulkan loader; no Vulkan call is made before it succeeds.
    unsafe { ash::Entry::load() }.map_err(|e| {
        anyhow!(
            "no Vulkan loader ({e}). Install one with a driver, e.g. on Debian/Ubuntu as root: \
             `apt-get install libvulkan1 mesa-vulkan-drivers` (lavapipe, Mesa's CPU Vulkan driver), \
             or run `make setup`"
        )
    })
}

fn version_string(v: u32) -> String {
    format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
}

fn driver_version_string(vendor_id: u32, driver_id: vk::DriverId, v: u32) -> String {
    if vendor_id == 0x10de {
        // NVIDIA packs 10.8.8.6 bits.
        return format!("{}.{}.{}.{}", v >> 22, (v >> 14) & 0xff, (v >> 6) & 0xff, v & 0x3f);
    }
    let _ = driver_id;
    version_string(v)
}

fn device_type_name(t: vk::PhysicalDeviceType) -> &'static str {
    match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => "discrete-gpu",
        vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated-gpu",
        vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual-gpu",
        vk::PhysicalDeviceType::CPU => "cpu",
        _ => "other",
    }
}

/// The compute queue family, preferring one with timestamps.
fn compute_queue_family(instance: &ash::Instance, pd: vk::PhysicalDevice) -> Option<(u32, u32)> {
    // SAFETY: pd comes from this instance.
    let families = unsafe { instance.get_physical_device_queue_family_properties(pd) };
    let compute = |f: &vk::QueueFamilyProperties| f.queue_flags.contains(vk::QueueFlags::COMPUTE);
    families
        .iter()
        .enumerate()
        .filter(|(_, f)| compute(f))
        .max_by_key(|(_, f)| (f.timestamp_valid_bits > 0, !f.queue_flags.contains(vk::QueueFlags::GRAPHICS)))
        .map(|(i, f)| (i as u32, f.timestamp_valid_bits))
}

fn describe(instance: &ash::Instance, index: usize, pd: vk::PhysicalDevice) -> DeviceInfo {
    // SAFETY: pd comes from this instance; the chained structs outlive the calls.
    unsafe {
        let props = instance.get_physical_device_properties(pd);
        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        // Vulkan 1.1's guaranteed minimum, for a Vulkan 1.0 device (PanVK 22.3), which cannot state it.
        let mut maint3 =
            vk::PhysicalDeviceMaintenance3Properties { max_memory_allocation_size: 1 << 30, ..Default::default() };
        let mut f16 = vk::PhysicalDeviceShaderFloat16Int8Features::default();
        let features = if vk::api_version_minor(props.api_version) >= 1 || vk::api_version_major(props.api_version) > 1
        {
            let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver).push_next(&mut maint3);
            instance.get_physical_device_properties2(pd, &mut props2);
            let mut features2 = vk::PhysicalDeviceFeatures2::default().push_next(&mut f16);
            instance.get_physical_device_features2(pd, &mut features2);
            features2.features
        } else {
            // The *2 queries are Vulkan 1.1's: a 1.0 device has neither driver properties nor fp16 arithmetic here.
            instance.get_physical_device_features(pd)
        };
        let shader_float64 = features.shader_float64 == vk::TRUE;
        let shader_float16 = f16.shader_float16 == vk::TRUE;
        let extensions = instance.enumerate_device_extension_properties(pd).unwrap_or_default();
        let has_ext = |name: &CStr| extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
        let l = props.limits;
        let text =
            |r: std::result::Result<&CStr, _>| r.map(|s: &CStr| s.to_string_lossy().into_owned()).unwrap_or_default();
        DeviceInfo {
            index,
            // NVK on the noop shim names itself "NVK " (no chip name to append).
            name: text(props.device_name_as_c_str()).trim().to_string(),
            device_type: device_type_name(props.device_type).into(),
            vendor_id: props.vendor_id,
            device_id: props.device_id,
            driver_name: text(driver.driver_name_as_c_str()),
            driver_info: text(driver.driver_info_as_c_str()),
            driver_version: driver_version_string(props.vendor_id, driver.driver_id, props.driver_version),
            api_version: version_string(props.api_version),
            timestamp_period: l.timestamp_period,
            timestamp_valid_bits: compute_queue_family(instance, pd).map_or(0, |(_, bits)| bits),
            max_storage_buffer_range: l.max_storage_buffer_range,
            max_texel_buffer_elements: l.max_texel_buffer_elements,
            max_compute_work_group_count: l.max_compute_work_group_count,
            max_compute_work_group_invocations: l.max_compute_work_group_invocations,
            min_storage_buffer_offset_alignment: l.min_storage_buffer_offset_alignment,
            max_memory_allocation_size: maint3.max_memory_allocation_size,
            shader_float16,
            shader_float64,
            pipeline_executable_properties: has_ext(EXECUTABLE_PROPERTIES_EXT),
        }
    }
}

unsafe extern "system" fn on_validation_message(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid callback data; `user` is the Messages box that Gpu owns.
    let text = unsafe { data.as_ref() }
        .and_then(|d| unsafe { d.message_as_c_str() })
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    brdfprof_process::messages::line(&format!("vulkan validation [{severity:?}]: {text}"));
    if let Some(messages) = unsafe { (user as *const Messages).as_ref() } {
        messages.lock().unwrap().push(text);
    }
    vk::FALSE
}

fn create_instance(entry: &ash::Entry, validation: bool) -> Result<ash::Instance> {
    let app = vk::ApplicationInfo::default().application_name(c"brdfprof").api_version(vk::API_VERSION_1_2);
    let mut layers = Vec::new();
    let mut extensions = Vec::new();
    if validation {
        // SAFETY: plain enumeration.
        let available = unsafe { entry.enumerate_instance_layer_properties() }?;
        if !available.iter().any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER)) {
            bail!(
                "validation was requested but VK_LAYER_KHRONOS_validation is not installed \
                 (Debian: `apt-get install vulkan-validationlayers`)"
            );
        }
        layers.push(VALIDATION_LAYER.as_ptr());
        extensions.push(ash::ext::debug_utils::NAME.as_ptr());
    }
    let info = vk::InstanceCreateInfo::default()
        .application_info(&app)
        .enabled_layer_names(&layers)
        .enabled_extension_names(&extensions);
    // SAFETY: the create info and the names it points to live through the call.
    unsafe { entry.create_instance(&info, None) }.context("vkCreateInstance failed")
}

fn no_device_error() -> anyhow::Error {
    anyhow!(
        "no Vulkan device found. For a CPU device install lavapipe (Mesa's CPU Vulkan driver): \
         on Debian/Ubuntu as root `apt-get install mesa-vulkan-drivers libvulkan1`, or run `make setup`"
    )
}

/// Every Vulkan device the loader sees, in `--device INDEX` order.
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    let entry = load_entry()?;
    let instance = create_instance(&entry, false)?;
    // SAFETY: instance is live until destroyed below.
    let devices = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
    let infos = devices.iter().enumerate().map(|(i, pd)| describe(&instance, i, *pd)).collect();
    // SAFETY: nothing else uses the instance.
    unsafe { instance.destroy_instance(None) };
    Ok(infos)
}

/// Picks a device: by index or name substring when asked, else the first discrete or integrated GPU, else the
/// first CPU device (lavapipe), else the first device.
pub fn select_device(infos: &[DeviceInfo], wanted: Option<&str>) -> Result<usize> {
    if infos.is_empty() {
        return Err(no_device_error());
    }
    let listing = || {
        infos.iter().map(|d| format!("  {}: {} ({})", d.index, d.name, d.device_type)).collect::<Vec<_>>().join("\n")
    };
    if let Some(w) = wanted {
        // Every name contains the empty string: a blank choice would silently pick device 0.
        if w.trim().is_empty() {
            bail!("device `{w}`: empty; give an index or a name substring (see `brdfprof devices`)");
        }
        if let Ok(i) = w.parse::<usize>() {
            return if i < infos.len() {
                Ok(i)
            } else {
                bail!("no device with index {i}; devices are:\n{}", listing())
            };
        }
        let needle = w.to_lowercase();
        return infos
            .iter()
            .position(|d| d.name.to_lowercase().contains(&needle))
            .ok_or_else(|| anyhow!("no device whose name contains `{w}`; devices are:\n{}", listing()));
    }
    let runs = |d: &&DeviceInfo| !d.compile_only();
    let gpu = infos.iter().filter(runs).find(|d| d.device_type == "discrete-gpu" || d.device_type == "integrated-gpu");
    let chosen = gpu.or_else(|| infos.iter().filter(runs).find(|d| d.is_cpu())).or_else(|| infos.iter().find(runs));
    chosen
        .map(|d| d.index)
        .ok_or_else(|| anyhow!("every Vulkan device here compiles only (RADV's null device); none can run kernels"))
}

/// The logical device: one compute queue, fp16 arithmetic and pipeline executable properties where available.
fn create_device(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    family: u32,
    info: &DeviceInfo,
) -> Result<ash::Device> {
    let priorities = [1.0f32];
    let queues = [vk::DeviceQueueCreateInfo::default().queue_family_index(family).queue_priorities(&priorities)];
    let mut extensions = Vec::new();
    if info.pipeline_executable_properties {
        extensions.push(EXECUTABLE_PROPERTIES_EXT.as_ptr());
    }
    let api_1_2 = vk::api_version_minor(
        // SAFETY: physical is valid.
        unsafe { instance.get_physical_device_properties(physical) }.api_version,
    ) >= 2;
    let mut f16 = vk::PhysicalDeviceShaderFloat16Int8Features::default().shader_float16(info.shader_float16);
    let mut exec = vk::PhysicalDevicePipelineExecutablePropertiesFeaturesKHR::default()
        .pipeline_executable_info(info.pipeline_executable_properties);
    // fp64 where the device has it: a .brdf shader may compute in double (validation refuses the Float64
    // capability on a device that did not enable it).
    let features = vk::PhysicalDeviceFeatures::default().shader_float64(info.shader_float64);
    let mut create = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queues)
        .enabled_extension_names(&extensions)
        .enabled_features(&features);
    if api_1_2 && info.shader_float16 {
        create = create.push_next(&mut f16);
    }
    if info.pipeline_executable_properties {
        create = create.push_next(&mut exec);
    }
    // SAFETY: create info and chained structs outlive the call.
    unsafe { instance.create_device(physical, &create, None) }.context("vkCreateDevice failed")
}

impl Gpu {
    /// Whether the device returns pipeline executables (VK_KHR_pipeline_executable_properties): its
    /// compiler's statistics and internal representations.
    pub fn has_executable_properties(&self) -> bool {
        self.executable_properties.is_some()
    }

    pub fn new(options: &GpuOptions) -> Result<Self> {
        let entry = load_entry()?;
        let instance = create_instance(&entry, options.validation)?;
        let messages: Messages = Arc::default();
        let mut debug = None;
        if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
            let user = Box::into_raw(Box::new(messages.clone()));
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(
                    vk::DebugUtilsMessageSeverityFlagsEXT::WARNING | vk::DebugUtilsMessageSeverityFlagsEXT::ERROR,
                )
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(on_validation_message))
                .user_data(user as *mut c_void);
            // SAFETY: `user` stays alive until the messenger is destroyed in Drop.
            let messenger = unsafe { loader.create_debug_utils_messenger(&info, None) }?;
            debug = Some((loader, messenger, user));
        }
        // SAFETY: instance is live.
        let physicals = unsafe { instance.enumerate_physical_devices() }.unwrap_or_default();
        let infos: Vec<DeviceInfo> = physicals.iter().enumerate().map(|(i, pd)| describe(&instance, i, *pd)).collect();
        let index = select_device(&infos, options.device.as_deref())?;
        let physical = physicals[index];
        let info = infos[index].clone();
        let (family, _) = compute_queue_family(&instance, physical)
            .ok_or_else(|| anyhow!("device {} has no compute queue", info.name))?;

        let device = create_device(&instance, physical, family, &info)?;
        // SAFETY: family was requested with one queue.
        let queue = unsafe { device.get_device_queue(family, 0) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: device is live.
        let command_pool = unsafe { device.create_command_pool(&pool_info, None) }?;
        // SAFETY: physical is valid.
        let memory_properties = unsafe { instance.get_physical_device_memory_properties(physical) };
        let executable_properties = info
            .pipeline_executable_properties
            .then(|| ash::khr::pipeline_executable_properties::Device::new(&instance, &device));
        Ok(Gpu {
            _entry: entry,
            instance,
            debug,
            messages,
            physical,
            info,
            device,
            executable_properties,
            compiler_log: options.compiler_log,
            representation_stats: options.representation_stats,
            queue,
            command_pool,
            memory_properties,
            submitted: std::sync::atomic::AtomicBool::new(false),
        })
    }

    /// Validation messages recorded so far (empty without validation).
    /// Whether the device can use `format` as a uniform texel buffer (`storage`: a storage texel buffer).
    pub(crate) fn texel_buffer_support(&self, format: vk::Format, storage: bool) -> bool {
        // SAFETY: the physical device belongs to this instance.
        let props = unsafe { self.instance.get_physical_device_format_properties(self.physical, format) };
        let wanted = if storage {
            vk::FormatFeatureFlags::STORAGE_TEXEL_BUFFER
        } else {
            vk::FormatFeatureFlags::UNIFORM_TEXEL_BUFFER
        };
        props.buffer_features.contains(wanted)
    }

    /// Whether its pipelines report compiler statistics (`Kernel::executables`): through
    /// VK_KHR_pipeline_executable_properties or on stderr (`GpuOptions::compiler_log`).
    pub fn reports_statistics(&self) -> bool {
        self.executable_properties.is_some() || self.compiler_log.is_some()
    }

    pub fn validation_messages(&self) -> Vec<String> {
        self.messages.lock().unwrap().clone()
    }

    /// Fails when the validation layer reported anything.
    pub fn check_validation(&self) -> Result<()> {
        let messages = self.validation_messages();
        if messages.is_empty() {
            Ok(())
        } else {
            bail!("{} Vulkan validation message(s), the first: {}", messages.len(), messages[0])
        }
    }

    /// Records commands into a one-time command buffer, submits it and waits for it to finish.
    pub fn submit<T>(&self, record: impl FnOnce(&Commands) -> T) -> Result<T> {
        if self.info.compile_only() {
            bail!("{} compiles only: it cannot run kernels", self.info.name);
        }
        self.submitted.store(true, std::sync::atomic::Ordering::Relaxed);
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.command_pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: every handle belongs to this device; the fence wait ends the command buffer's use
        // before it is freed.
        unsafe {
            let cmd = self.device.allocate_command_buffers(&alloc)?[0];
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.device.begin_command_buffer(cmd, &begin)?;
            let commands = Commands { raw: cmd, first_dispatches: Default::default() };
            let out = record(&commands);
            let compiling = if self.info.is_cpu() { commands.first_dispatches.take() } else { Vec::new() };
            self.device.end_command_buffer(cmd)?;
            let fence = self.device.create_fence(&vk::FenceCreateInfo::default(), None)?;
            let cmds = [cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            let result = self.device.queue_submit(self.queue, &[submit], fence).and_then(|_| {
                if compiling.is_empty() { self.wait(fence) } else { self.wait_compiling(fence, &compiling) }
            });
            self.device.destroy_fence(fence, None);
            self.device.free_command_buffers(self.command_pool, &cmds);
            result.context("queue submission failed")?;
            Ok(out)
        }
    }

    /// Waits for `fence` at most `fence_timeout()`. Past it the submission is still pending on a device that
    /// may be hung: nothing it uses can be freed, so the command stops (`cleanup::stop`, exit status 2).
    fn wait(&self, fence: vk::Fence) -> ash::prelude::VkResult<()> {
        let limit = fence_timeout();
        // SAFETY: the fence belongs to this device and was just submitted with work.
        match unsafe { self.device.wait_for_fences(&[fence], true, limit.as_nanos().min(u64::MAX as u128) as u64) } {
            Err(vk::Result::TIMEOUT) => brdfprof_process::cleanup::stop(
                2,
                &format!(
                    "brdfprof: error: {} did not finish a submission within {} s ({FENCE_TIMEOUT_ENV}; default {} s): the device may be hung; stopped",
                    self.info.name,
                    limit.as_secs_f64(),
                    DEFAULT_FENCE_TIMEOUT.as_secs()
                ),
            ),
            other => other,
        }
    }

    /// Waits for a submission in which lavapipe compiles `kernels` (their first dispatch): under the compile
    /// limit, saying what compiles once it takes a while (`compile_limit::Watch`); past the limit the command
    /// stops (`cleanup::stop`, exit status 2), as a pipeline creation past it does.
    fn wait_compiling(&self, fence: vk::Fence, kernels: &[String]) -> ash::prelude::VkResult<()> {
        let limit = brdfprof_process::launch::limit();
        let what = format!("{} (lavapipe compiles a pipeline at its first dispatch)", kernels.join(", "));
        let mut watch = brdfprof_process::launch::Watch::new(&what);
        loop {
            // SAFETY: the fence belongs to this device and was just submitted with work.
            match unsafe { self.device.wait_for_fences(&[fence], true, 100_000_000) } {
                Err(vk::Result::TIMEOUT) => {}
                other => return other,
            }
            if watch.elapsed() >= limit {
                brdfprof_process::cleanup::stop(
                    2,
                    &format!("brdfprof: error: {}", brdfprof_process::launch::over_limit(&what, limit)),
                );
            }
            watch.tick(limit);
        }
    }

    /// A compute-to-compute and compute-to-transfer memory barrier: every dispatch after it sees every write
    /// before it.
    pub fn barrier(&self, cmd: &Commands) {
        let barrier = vk::MemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(
                vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_READ,
            );
        // SAFETY: cmd is recording.
        unsafe {
            self.device.cmd_pipeline_barrier(
                cmd.raw,
                vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[barrier],
                &[],
                &[],
            )
        };
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        // SAFETY: everything created from this device and instance is destroyed here, in order, after the
        // device is idle; the messenger's user box is freed after the messenger.
        unsafe {
            if self.submitted.load(std::sync::atomic::Ordering::Relaxed) {
                let _ = self.device.device_wait_idle();
            }
            self.device.destroy_command_pool(self.command_pool, None);
            self.device.destroy_device(None);
            if let Some((loader, messenger, user)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
                drop(Box::from_raw(user));
            }
            self.instance.destroy_instance(None);
        }
    }
}
