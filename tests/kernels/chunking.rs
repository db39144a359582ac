//! Inputs larger than one binding or one dispatch may hold are chunked: an eval whose input buffer is past
//! lavapipe's 128 MiB maxStorageBufferRange, and one forced into many small chunks, both agree with the
//! unchunked result at every element (including each chunk boundary) and with the f64 twin.

use crate::common;
use brdfprof::brdf::{ModelSpec, samples};
use brdfprof::gpu::ChunkPlan;
use brdfprof::kernels::{self, RunLimits};

#[test]
fn eval_past_max_storage_buffer_range() {
    let gpu = common::gpu();
    let range = gpu.info.max_storage_buffer_range as usize;
    // 64 bytes per sample: enough samples for the input to exceed one binding window.
    let n = range / 64 + 300_001;
    assert!(n * 64 > 128 << 20 || n * 64 > range);
    let base = samples::well_conditioned(50_000, 5, 0.05, 0.2..1.0);
    let samples: Vec<_> = (0..n).map(|i| base[(i * 7919) % base.len()]).collect();
    assert!(
        ChunkPlan::new(&gpu.info, n as u64, &[64, 16], None).chunks.len() > 1,
        "the input must need several bindings"
    );
    let spec = ModelSpec::preset("cook-torrance").unwrap();
    let big = kernels::eval(&gpu, &common::model(spec), &samples, RunLimits::default()).unwrap();
    let small = kernels::eval(&gpu, &common::model(spec), &base, RunLimits::default()).unwrap();
    assert_eq!(big.len(), n);
    for (i, got) in big.iter().enumerate() {
        assert_eq!(
            *got,
            small[(i * 7919) % base.len()],
            "element {i} differs from the same sample evaluated unchunked"
        );
    }
    for (s, g) in base.iter().zip(&small).step_by(97) {
        let want = spec.eval(s);
        assert!((0..3).all(|c| common::rel_err(g[c] as f64, want[c]) <= 1e-3));
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn many_small_chunks_equal_one_dispatch() {
    let gpu = common::gpu();
    let s = samples::well_conditioned(100_003, 6, 0.05, 0.2..1.0);
    let spec = common::model(ModelSpec::preset("burley").unwrap());
    let whole = kernels::eval(&gpu, &spec, &s, RunLimits::default()).unwrap();
    let chunked = kernels::eval(&gpu, &spec, &s, RunLimits { max_chunk: Some(5_000) }).unwrap();
    assert_eq!(whole, chunked);
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn chunk_plan_respects_workgroup_count_and_range() {
    let gpu = common::gpu();
    let mut info = gpu.info.clone();
    info.max_compute_work_group_count = [1000, 1, 1]; // 64,000 invocations per dispatch
    info.max_storage_buffer_range = 1 << 30;
    let plan = ChunkPlan::new(&info, 1_000_000, &[16, 16], None);
    assert!(plan.max_chunk <= 64_000, "{plan:?}");
    assert_eq!(plan.chunks.iter().map(|c| c.1).sum::<u64>(), 1_000_000);
    assert!(plan.chunks.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0));
    info.max_storage_buffer_range = 1 << 20; // 16,384 elements of 64 bytes
    let plan = ChunkPlan::new(&info, 100_000, &[64, 16], None);
    assert!(plan.max_chunk * 64 <= 1 << 20 && plan.chunks.len() == 100_000usize.div_ceil(plan.max_chunk as usize));
}
