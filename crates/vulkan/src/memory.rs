//! Storage buffers: device-local where the device has such memory (uploads and downloads go through a
//! staging buffer when it is not host-visible), host-visible and mapped otherwise.

use super::Gpu;
use anyhow::{Context, Result, anyhow};
use ash::vk;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemoryKind {
    /// For kernel inputs and outputs: DEVICE_LOCAL preferred.
    Device,
    /// For staging and readback: HOST_VISIBLE | HOST_COHERENT, HOST_CACHED preferred.
    Host,
}

pub struct Buffer<'g> {
    gpu: &'g Gpu,
    pub(super) buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    pub size: u64,
    mapped: Option<*mut u8>,
}

/// Staging granule for devices whose kernel buffers are not host-visible.
const STAGING_BYTES: u64 = 64 << 20;

impl Gpu {
    fn memory_type(
        &self,
        bits: u32,
        required: vk::MemoryPropertyFlags,
        preferred: vk::MemoryPropertyFlags,
    ) -> Option<u32> {
        let props = &self.memory_properties;
        let types = &props.memory_types[..props.memory_type_count as usize];
        let candidates =
            || types.iter().enumerate().filter(|(i, t)| bits & (1 << i) != 0 && t.property_flags.contains(required));
        candidates()
            .find(|(_, t)| t.property_flags.contains(preferred))
            .or_else(|| candidates().next())
            .map(|(i, _)| i as u32)
    }
}

impl<'g> Buffer<'g> {
    pub fn new(gpu: &'g Gpu, size: u64, kind: MemoryKind) -> Result<Self> {
        let size = size.max(16);
        if size > gpu.info.max_memory_allocation_size && gpu.info.max_memory_allocation_size > 0 {
            return Err(anyhow!(
                "a {size}-byte buffer exceeds the device's maxMemoryAllocationSize ({})",
                gpu.info.max_memory_allocation_size
            ));
        }
        // Every buffer may back a uniform or texel-buffer window too (the shading kernel's light blocks and G-buffer planes): the flag costs nothing.
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::UNIFORM_BUFFER
            | vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER
            | vk::BufferUsageFlags::STORAGE_TEXEL_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST;
        let info = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        let device = &gpu.device;
        // SAFETY: all handles come from `device`; memory is bound once, before any use.
        unsafe {
            let buffer = device.create_buffer(&info, None)?;
            let req = device.get_buffer_memory_requirements(buffer);
            let host = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
            let index = match kind {
                MemoryKind::Device => {
                    gpu.memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::DEVICE_LOCAL, host)
                }
                MemoryKind::Host => gpu.memory_type(req.memory_type_bits, host, vk::MemoryPropertyFlags::HOST_CACHED),
            }
            .or_else(|| gpu.memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::empty(), host))
            .ok_or_else(|| anyhow!("no memory type for a storage buffer"))?;
            let alloc = vk::MemoryAllocateInfo::default().allocation_size(req.size).memory_type_index(index);
            let memory = device
                .allocate_memory(&alloc, None)
                .with_context(|| format!("allocating {} MiB of device memory", req.size >> 20))?;
            device.bind_buffer_memory(buffer, memory, 0)?;
            let flags = gpu.memory_properties.memory_types[index as usize].property_flags;
            let mapped = if flags.contains(host) {
                Some(device.map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())? as *mut u8)
            } else {
                None
            };
            Ok(Buffer { gpu, buffer, memory, size, mapped })
        }
    }

    /// A buffer holding `data`.
    pub fn with_data(gpu: &'g Gpu, data: &[u8], kind: MemoryKind) -> Result<Self> {
        let buffer = Buffer::new(gpu, data.len() as u64, kind)?;
        buffer.write(0, data)?;
        Ok(buffer)
    }

    /// Copies `data` to `offset`, through a staging buffer when this one is not mapped.
    pub fn write(&self, offset: u64, data: &[u8]) -> Result<()> {
        assert!(offset + data.len() as u64 <= self.size, "write past the end of a buffer");
        if let Some(ptr) = self.mapped {
            // SAFETY: the range is inside the mapped allocation (asserted) and no kernel is running on it.
            unsafe { std::ptr::copy_nonoverlapping(data.as_ptr(), ptr.add(offset as usize), data.len()) };
            return Ok(());
        }
        let staging = Buffer::new(self.gpu, STAGING_BYTES.min(data.len() as u64), MemoryKind::Host)?;
        for (i, chunk) in data.chunks(STAGING_BYTES as usize).enumerate() {
            staging.write(0, chunk)?;
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: offset + i as u64 * STAGING_BYTES,
                size: chunk.len() as u64,
            };
            // SAFETY: both buffers are live and the region lies within them.
            self.gpu.submit(|cmd| unsafe {
                self.gpu.device.cmd_copy_buffer(cmd.raw, staging.buffer, self.buffer, &[region])
            })?;
        }
        Ok(())
    }

    /// Reads `len` bytes from `offset`.
    pub fn read(&self, offset: u64, len: u64) -> Result<Vec<u8>> {
        assert!(offset + len <= self.size, "read past the end of a buffer");
        if let Some(ptr) = self.mapped {
            // SAFETY: inside the mapped allocation; the caller waited for the writing submission.
            return Ok(unsafe { std::slice::from_raw_parts(ptr.add(offset as usize), len as usize) }.to_vec());
        }
        let staging = Buffer::new(self.gpu, STAGING_BYTES.min(len), MemoryKind::Host)?;
        let mut out = Vec::with_capacity(len as usize);
        let mut done = 0;
        while done < len {
            let n = STAGING_BYTES.min(len - done);
            let region = vk::BufferCopy { src_offset: offset + done, dst_offset: 0, size: n };
            // SAFETY: both buffers are live and the region lies within them.
            self.gpu.submit(|cmd| unsafe {
                self.gpu.device.cmd_copy_buffer(cmd.raw, self.buffer, staging.buffer, &[region])
            })?;
            out.extend_from_slice(&staging.read(0, n)?);
            done += n;
        }
        Ok(out)
    }

    /// Reads the whole buffer as plain values.
    pub fn read_as<T: bytemuck::Pod>(&self, offset: u64, count: usize) -> Result<Vec<T>> {
        let bytes = self.read(offset, (count * std::mem::size_of::<T>()) as u64)?;
        Ok(bytemuck::pod_collect_to_vec(&bytes))
    }
}

impl Drop for Buffer<'_> {
    fn drop(&mut self) {
        // SAFETY: the buffer is not in use (every submission waits for its fence) and is destroyed once.
        unsafe {
            if self.mapped.is_some() {
                self.gpu.device.unmap_memory(self.memory);
            }
            self.gpu.device.destroy_buffer(self.buffer, None);
            self.gpu.device.free_memory(self.memory, None);
        }
    }
}
