//! Compute kernels: a pipeline specialised with constants, its buffer bindings, and the chunking that
//! keeps every binding inside maxStorageBufferRange and every dispatch inside maxComputeWorkGroupCount.

use super::{Buffer, Commands, DeviceInfo, Gpu};
use anyhow::{Context, Result, anyhow, bail};
use ash::vk;

/// Specialisation constants, in the order they are added.
#[derive(Clone, Debug, Default)]
pub struct SpecConstants {
    entries: Vec<(u32, [u8; 4])>,
}

impl SpecConstants {
    /// Sets constant `id` (replacing an earlier value of the same id).
    pub fn int(self, id: u32, value: i32) -> Self {
        self.set(id, value.to_ne_bytes())
    }
    pub fn float(self, id: u32, value: f32) -> Self {
        self.set(id, value.to_ne_bytes())
    }
    fn set(mut self, id: u32, bytes: [u8; 4]) -> Self {
        match self.entries.iter_mut().find(|(i, _)| *i == id) {
            Some(e) => e.1 = bytes,
            None => self.entries.push((id, bytes)),
        }
        self
    }
    /// (id, value as u32 bits), for reports and for spirv-opt's --set-spec-const-default-value.
    pub fn values(&self) -> Vec<(u32, [u8; 4])> {
        self.entries.clone()
    }
}

/// A descriptor set: the buffer windows one dispatch reads and writes.
#[derive(Clone, Copy, Debug)]
pub struct Bindings(vk::DescriptorSet);

/// What a binding of a kernel is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Binding {
    /// A storage buffer (read or written per invocation).
    Storage,
    /// A uniform buffer whose offset is given at each dispatch (data every invocation reads alike, e.g. one
    /// block of lights: drivers load it as scalars).
    UniformDynamic,
    /// A buffer read through a typed view (`samplerBuffer` + texelFetch): the format conversion is the
    /// texture path's, as a G-buffer render target's is.
    TexelRead(TexelFormat),
    /// A buffer read and written through a typed view (`imageBuffer` + imageLoad/imageStore).
    TexelStorage(TexelFormat),
}

/// The formats of texel-buffer views the kernels use, named here so that no caller needs Vulkan's types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFormat {
    /// Four 32-bit unsigned integers (a packed G-buffer texel).
    Rgba32Uint,
    /// Packed unsigned 11/11/10-bit floats (an HDR radiance target).
    B10g11r11Ufloat,
}

impl TexelFormat {
    fn vk(self) -> vk::Format {
        match self {
            TexelFormat::Rgba32Uint => vk::Format::R32G32B32A32_UINT,
            TexelFormat::B10g11r11Ufloat => vk::Format::B10G11R11_UFLOAT_PACK32,
        }
    }
}

impl Binding {
    /// `n` storage buffers.
    pub fn storage(n: u32) -> Vec<Binding> {
        vec![Binding::Storage; n as usize]
    }

    fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            Binding::Storage => vk::DescriptorType::STORAGE_BUFFER,
            Binding::UniformDynamic => vk::DescriptorType::UNIFORM_BUFFER_DYNAMIC,
            Binding::TexelRead(_) => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
            Binding::TexelStorage(_) => vk::DescriptorType::STORAGE_TEXEL_BUFFER,
        }
    }

    fn texel_format(self) -> Option<vk::Format> {
        match self {
            Binding::TexelRead(f) | Binding::TexelStorage(f) => Some(f.vk()),
            _ => None,
        }
    }
}

pub struct Kernel<'g> {
    pub(super) gpu: &'g Gpu,
    pub name: String,
    pub(super) pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    bindings: Vec<Binding>,
    /// The typed views of the texel-buffer bindings handed out (destroyed with the sets).
    views: std::cell::RefCell<Vec<vk::BufferView>>,
    push_bytes: u32,
    /// Invocations per workgroup (local_size_x of every brdfprof kernel).
    pub workgroup: u32,
    /// Created with CAPTURE_INTERNAL_REPRESENTATIONS (`executables` returns them).
    pub(super) captures_ir: bool,
    /// The statistics the driver printed on stderr while compiling it (`GpuOptions::compiler_log`).
    pub(super) logged_stats: Option<Vec<super::DriverStat>>,
    /// Whether a dispatch of it was ever recorded (`Commands::first_dispatches`).
    dispatched: std::cell::Cell<bool>,
}

/// Descriptor sets one kernel can hold at a time (one per chunk of a dispatch).
const SETS_PER_KERNEL: u32 = 256;
/// local_size_x of every kernel in glsl/.
pub const WORKGROUP: u32 = 64;

/// An error naming the first texel buffer of `bindings` whose format `gpu` cannot use as such.
fn check_texel_formats(gpu: &Gpu, name: &str, bindings: &[Binding]) -> Result<()> {
    for b in bindings {
        if let Some(format) = b.texel_format() {
            let storage = matches!(b, Binding::TexelStorage(_));
            if !gpu.texel_buffer_support(format, storage) {
                bail!(
                    "{name}: {} cannot use {format:?} as a {} texel buffer",
                    gpu.info.name,
                    if storage { "storage" } else { "uniform" }
                );
            }
        }
    }
    Ok(())
}

/// The descriptor set layout bindings of `bindings`: binding 0, 1, ..., one descriptor each, for compute.
fn layout_bindings(bindings: &[Binding]) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
    bindings
        .iter()
        .enumerate()
        .map(|(b, kind)| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b as u32)
                .descriptor_type(kind.descriptor_type())
                .descriptor_count(1)
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
        })
        .collect()
}

/// The descriptor pool sizes for `SETS_PER_KERNEL` sets of `bindings`, one entry per descriptor type.
fn pool_sizes(bindings: &[Binding]) -> Vec<vk::DescriptorPoolSize> {
    let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
    for b in bindings {
        match sizes.iter_mut().find(|s| s.ty == b.descriptor_type()) {
            Some(s) => s.descriptor_count += SETS_PER_KERNEL,
            None => sizes.push(vk::DescriptorPoolSize { ty: b.descriptor_type(), descriptor_count: SETS_PER_KERNEL }),
        }
    }
    sizes
}

impl<'g> Kernel<'g> {
    /// A pipeline for the SPIR-V `words` (named `name` in errors), specialised, with the buffers of `bindings`
    /// (binding 0, 1, ...) and `push_bytes` of push constants. With `capture_ir` the driver keeps its internal
    /// representations (`PipelineExecutable::representations`).
    pub fn new(
        gpu: &'g Gpu,
        name: &str,
        words: &[u32],
        spec: &SpecConstants,
        bindings: &[Binding],
        push_bytes: u32,
    ) -> Result<Self> {
        Self::with_capture(gpu, name, words, spec, bindings, push_bytes, false)
    }

    pub fn with_capture(
        gpu: &'g Gpu,
        name: &str,
        words: &[u32],
        spec: &SpecConstants,
        bindings: &[Binding],
        push_bytes: u32,
        capture_ir: bool,
    ) -> Result<Self> {
        check_texel_formats(gpu, name, bindings)?;
        let device = &gpu.device;
        let binding_info = layout_bindings(bindings);
        let map: Vec<_> = spec
            .entries
            .iter()
            .enumerate()
            .map(|(i, (id, _))| vk::SpecializationMapEntry { constant_id: *id, offset: 4 * i as u32, size: 4 })
            .collect();
        let data: Vec<u8> = spec.entries.iter().flat_map(|(_, v)| *v).collect();
        // SAFETY: every create info and what it points to outlives its call; handles are destroyed in Drop.
        unsafe {
            let module = device.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(words), None)?;
            let set_layout = device.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&binding_info),
                None,
            )?;
            let set_layouts = [set_layout];
            let ranges =
                [vk::PushConstantRange { stage_flags: vk::ShaderStageFlags::COMPUTE, offset: 0, size: push_bytes }];
            let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
            if push_bytes > 0 {
                layout_info = layout_info.push_constant_ranges(&ranges);
            }
            let layout = device.create_pipeline_layout(&layout_info, None)?;
            let mut flags = vk::PipelineCreateFlags::empty();
            if gpu.executable_properties.is_some() {
                flags |= vk::PipelineCreateFlags::CAPTURE_STATISTICS_KHR;
                if capture_ir || gpu.representation_stats.is_some() {
                    flags |= vk::PipelineCreateFlags::CAPTURE_INTERNAL_REPRESENTATIONS_KHR;
                }
            }
            let (pipeline, logged_stats) = create_logged_pipeline(gpu, name, module, layout, &map, &data, flags)?;
            device.destroy_shader_module(module, None);
            let sizes = pool_sizes(bindings);
            let pool = device.create_descriptor_pool(
                &vk::DescriptorPoolCreateInfo::default().max_sets(SETS_PER_KERNEL).pool_sizes(&sizes),
                None,
            )?;
            let captures_ir = capture_ir && gpu.executable_properties.is_some();
            Ok(Kernel {
                gpu,
                name: name.into(),
                pipeline,
                layout,
                set_layout,
                pool,
                bindings: bindings.to_vec(),
                views: Default::default(),
                push_bytes,
                workgroup: WORKGROUP,
                captures_ir,
                logged_stats,
                dispatched: Default::default(),
            })
        }
    }

    /// A descriptor set binding each `(buffer, offset, range)` window to bindings 0, 1, ... (for a dynamic
    /// uniform buffer the offset is added to the one each dispatch gives).
    pub fn bind(&self, windows: &[(&Buffer, u64, u64)]) -> Result<Bindings> {
        assert_eq!(windows.len(), self.bindings.len(), "{}: wrong number of bindings", self.name);
        let layouts = [self.set_layout];
        let alloc = vk::DescriptorSetAllocateInfo::default().descriptor_pool(self.pool).set_layouts(&layouts);
        // SAFETY: pool and layout belong to this kernel; the infos outlive the update.
        unsafe {
            let set = self
                .gpu
                .device
                .allocate_descriptor_sets(&alloc)
                .with_context(|| format!("{}: more than {SETS_PER_KERNEL} chunks bound at once", self.name))?[0];
            let infos: Vec<[vk::DescriptorBufferInfo; 1]> = windows
                .iter()
                .map(|(b, offset, range)| {
                    [vk::DescriptorBufferInfo { buffer: b.buffer, offset: *offset, range: *range }]
                })
                .collect();
            let mut views = self.views.borrow_mut();
            let texel_views: Vec<Option<[vk::BufferView; 1]>> = windows
                .iter()
                .zip(&self.bindings)
                .map(|((b, offset, range), kind)| {
                    kind.texel_format()
                        .map(|format| {
                            let info = vk::BufferViewCreateInfo::default()
                                .buffer(b.buffer)
                                .format(format)
                                .offset(*offset)
                                .range(*range);
                            let view = self.gpu.device.create_buffer_view(&info, None)?;
                            views.push(view);
                            Ok::<_, vk::Result>([view])
                        })
                        .transpose()
                })
                .collect::<std::result::Result<_, _>>()?;
            let writes: Vec<_> = infos
                .iter()
                .zip(&texel_views)
                .enumerate()
                .map(|(i, (info, view))| {
                    let w = vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(i as u32)
                        .descriptor_type(self.bindings[i].descriptor_type());
                    match view {
                        Some(v) => w.texel_buffer_view(v),
                        None => w.buffer_info(info),
                    }
                })
                .collect();
            self.gpu.device.update_descriptor_sets(&writes, &[]);
            Ok(Bindings(set))
        }
    }

    /// Frees every descriptor set this kernel handed out.
    pub fn reset_bindings(&self) -> Result<()> {
        // SAFETY: callers only reset once the sets' submissions have completed.
        unsafe {
            self.gpu.device.reset_descriptor_pool(self.pool, vk::DescriptorPoolResetFlags::empty())?;
            for v in self.views.borrow_mut().drain(..) {
                self.gpu.device.destroy_buffer_view(v, None);
            }
        }
        Ok(())
    }

    /// Records a dispatch of `invocations` threads (rounded up to whole workgroups).
    pub fn dispatch(&self, cmd: &Commands, set: Bindings, push: &[u8], invocations: u64) {
        self.dispatch_at(cmd, set, &[], push, invocations)
    }

    /// As `dispatch`, with the offsets of the dynamic uniform buffers (in binding order).
    pub fn dispatch_at(&self, cmd: &Commands, set: Bindings, offsets: &[u32], push: &[u8], invocations: u64) {
        assert_eq!(push.len() as u32, self.push_bytes, "{}: wrong push-constant size", self.name);
        assert_eq!(
            offsets.len(),
            self.bindings.iter().filter(|b| **b == Binding::UniformDynamic).count(),
            "{}: wrong number of dynamic offsets",
            self.name
        );
        let groups = invocations.div_ceil(self.workgroup as u64) as u32;
        assert!(
            groups <= self.gpu.info.max_compute_work_group_count[0],
            "dispatch past maxComputeWorkGroupCount: chunk it"
        );
        if !self.dispatched.replace(true) {
            cmd.first_dispatches.borrow_mut().push(self.name.clone());
        }
        let device = &self.gpu.device;
        let raw = cmd.raw;
        // SAFETY: cmd is recording; set and layout match this pipeline.
        unsafe {
            device.cmd_bind_pipeline(raw, vk::PipelineBindPoint::COMPUTE, self.pipeline);
            device.cmd_bind_descriptor_sets(raw, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[set.0], offsets);
            if !push.is_empty() {
                device.cmd_push_constants(raw, self.layout, vk::ShaderStageFlags::COMPUTE, 0, push);
            }
            device.cmd_dispatch(raw, groups, 1, 1);
        }
    }
}

/// The compute pipeline of `module` specialised with `map`/`data`. The driver compiles here (RADV: ACO; lavapipe
/// only prepares, and compiles at the first dispatch: `Gpu::submit`), in a call that cannot be interrupted: it
/// runs under the compile limit on a worker thread (`compile_limit::bounded`).
/// `create_pipeline`, with the statistics the driver printed on stderr meanwhile where it reports them there
/// (`GpuOptions::compiler_log`).
fn create_logged_pipeline(
    gpu: &Gpu,
    name: &str,
    module: vk::ShaderModule,
    layout: vk::PipelineLayout,
    map: &[vk::SpecializationMapEntry],
    data: &[u8],
    flags: vk::PipelineCreateFlags,
) -> Result<(vk::Pipeline, Option<Vec<super::DriverStat>>)> {
    let Some(read) = gpu.compiler_log else {
        return Ok((create_pipeline(gpu, name, module, layout, map, data, flags)?, None));
    };
    let (pipeline, log) =
        super::stderr_capture::capture(|| create_pipeline(gpu, name, module, layout, map, data, flags))?;
    let pipeline = pipeline?;
    let read = (read.read)(&log)
        .with_context(|| format!("{name}: the statistics {} printed while compiling it", gpu.info.name));
    // SAFETY: the pipeline was just created on this device and nothing uses it.
    let (stats, rest) = read.inspect_err(|_| unsafe { gpu.device.destroy_pipeline(pipeline, None) })?;
    super::stderr_capture::pass_on(&rest);
    Ok((pipeline, Some(stats)))
}

fn create_pipeline(
    gpu: &Gpu,
    name: &str,
    module: vk::ShaderModule,
    layout: vk::PipelineLayout,
    map: &[vk::SpecializationMapEntry],
    data: &[u8],
    flags: vk::PipelineCreateFlags,
) -> Result<vk::Pipeline> {
    let device = &gpu.device;
    let what = format!("{name} (pipeline creation on {})", gpu.info.name);
    let created = brdfprof_process::launch::bounded(&what, || {
        let spec_info = vk::SpecializationInfo::default().map_entries(map).data(data);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec_info);
        let info = vk::ComputePipelineCreateInfo::default().stage(stage).layout(layout).flags(flags);
        // SAFETY: the module and layout belong to this device; the create info and what it points to live
        // through the call.
        unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) }
            .map(|p| p[0])
            .map_err(|(_, e)| e)
    });
    created.map_err(|e| anyhow!("creating the {name} pipeline: {e}"))
}

impl Drop for Kernel<'_> {
    fn drop(&mut self) {
        // SAFETY: no submission using these handles is pending (every submit waits).
        unsafe {
            let d = &self.gpu.device;
            d.destroy_descriptor_pool(self.pool, None);
            for v in self.views.get_mut().drain(..) {
                d.destroy_buffer_view(v, None);
            }
            d.destroy_pipeline(self.pipeline, None);
            d.destroy_pipeline_layout(self.layout, None);
            d.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// How `n` elements split into dispatches whose bindings fit maxStorageBufferRange and whose workgroup
/// counts fit maxComputeWorkGroupCount.x.
#[derive(Clone, Debug, PartialEq)]
pub struct ChunkPlan {
    /// (first element, element count) per chunk.
    pub chunks: Vec<(u64, u64)>,
    pub max_chunk: u64,
}

/// Chunk sizes are multiples of this many elements, so window offsets (1024 x a stride of 16 bytes or more)
/// meet any minStorageBufferOffsetAlignment (at most 256 bytes by the spec) and workgroups stay whole.
const CHUNK_GRANULE: u64 = 1024;

impl ChunkPlan {
    /// `strides`: bytes per element of each bound buffer. `cap` lowers the chunk size (tests use it).
    pub fn new(info: &DeviceInfo, n: u64, strides: &[u64], cap: Option<u64>) -> Self {
        let by_range = strides.iter().map(|s| info.max_storage_buffer_range as u64 / s).min().unwrap_or(u64::MAX);
        let by_groups = info.max_compute_work_group_count[0] as u64 * WORKGROUP as u64;
        let max = by_range.min(by_groups).min(cap.unwrap_or(u64::MAX));
        let max_chunk = (max / CHUNK_GRANULE * CHUNK_GRANULE).max(CHUNK_GRANULE);
        let chunks = (0..n).step_by(max_chunk as usize).map(|first| (first, max_chunk.min(n - first))).collect();
        ChunkPlan { chunks, max_chunk }
    }
}
