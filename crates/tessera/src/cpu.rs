//! What the processor running the process can do, asked once: whether code compiled for AVX2
//! and FMA may run. The engine's evaluation kernels and the plan's per-patch passes each
//! keep a baseline build and one for AVX2 and FMA, and call this to choose.

/// True when the CPU has AVX2 and FMA, so code compiled for them may run. Cost: an atomic
/// load after the first call (the standard library keeps the answer).
pub(crate) fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}
