//! Timestamp queries. A timestamp at BOTTOM_OF_PIPE is written once all earlier work has completed, so
//! `end - start` around a dispatch (with barriers between dispatches) is that dispatch's execution time.
//! Ticks are masked to timestampValidBits and scaled by timestampPeriod.

use super::{Commands, Gpu};
use anyhow::{Result, bail};
use ash::vk;

pub struct Timestamps<'g> {
    gpu: &'g Gpu,
    pool: vk::QueryPool,
    pub capacity: u32,
}

impl<'g> Timestamps<'g> {
    pub fn new(gpu: &'g Gpu, capacity: u32) -> Result<Self> {
        if gpu.info.timestamp_valid_bits == 0 {
            bail!("device {} has no timestamps on its compute queue", gpu.info.name);
        }
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity);
        // SAFETY: device is live; the pool is destroyed in Drop.
        let pool = unsafe { gpu.device.create_query_pool(&info, None) }?;
        Ok(Timestamps { gpu, pool, capacity })
    }

    /// Resets every query; record before the first `write` of a submission.
    pub fn reset(&self, cmd: &Commands) {
        // SAFETY: cmd is recording, outside a render pass.
        unsafe { self.gpu.device.cmd_reset_query_pool(cmd.raw, self.pool, 0, self.capacity) };
    }

    pub fn write(&self, cmd: &Commands, index: u32) {
        assert!(index < self.capacity);
        // SAFETY: cmd is recording; the query was reset in this command buffer.
        unsafe {
            self.gpu.device.cmd_write_timestamp(cmd.raw, vk::PipelineStageFlags::BOTTOM_OF_PIPE, self.pool, index)
        };
    }

    /// Nanoseconds between query pairs (start, end), read after the submission completed.
    pub fn intervals_ns(&self, pairs: &[(u32, u32)]) -> Result<Vec<f64>> {
        let count = pairs.iter().map(|&(a, b)| a.max(b) + 1).max().unwrap_or(0);
        let mut ticks = vec![0u64; count as usize];
        // SAFETY: the queries were written by a completed submission.
        unsafe {
            self.gpu.device.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }?;
        let bits = self.gpu.info.timestamp_valid_bits;
        let mask = if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 };
        let period = self.gpu.info.timestamp_period as f64;
        // Wrapping subtraction under the mask handles a counter that wrapped between the two reads.
        Ok(pairs
            .iter()
            .map(|&(a, b)| ((ticks[b as usize] & mask).wrapping_sub(ticks[a as usize] & mask) & mask) as f64 * period)
            .collect())
    }
}

impl Drop for Timestamps<'_> {
    fn drop(&mut self) {
        // SAFETY: no pending submission uses the pool.
        unsafe { self.gpu.device.destroy_query_pool(self.pool, None) };
    }
}
