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

/// Runs `f`, compiled for AVX2 and FMA where the CPU has them ([`has_avx2_fma`]), else for
/// the baseline target (SSE2 on x86-64). `f` is compiled twice, and what it calls is compiled
/// for AVX2 too where it is inlined into it: mark the closure `#[inline(always)]`, and the
/// functions it calls that matter. The arithmetic is the same in both builds, operation for
/// operation (Rust fuses no multiply-add on its own), so every result keeps its bits; the
/// wider build takes four `f64` lanes an instruction where the compiler vectorizes, and
/// three-operand instructions everywhere. Cost: one call; the test is an atomic load.
#[inline(always)]
pub(crate) fn multiversioned<R>(f: impl FnOnce() -> R) -> R {
    #[inline(never)]
    fn baseline<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    /// Safety: the CPU must have AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    unsafe fn wide<R>(f: impl FnOnce() -> R) -> R {
        f()
    }
    #[cfg(target_arch = "x86_64")]
    if has_avx2_fma() {
        // SAFETY: the CPU has AVX2 and FMA.
        return unsafe { wide(f) };
    }
    baseline(f)
}
