//! Parallel passes that write one row per patch (or edge) from a closure that reads many
//! arrays: the proposals, the check's first patterns.
//!
//! Why not `par_iter_mut().for_each`: its rows are written through an iterator's raw
//! pointer, which the compiler must assume may overlap whatever the closure reads, so a
//! closure that reads a dozen arrays read the pointers to them again for every row (the
//! resolved edges of the torus grid spent a third of their pass on that). Here each run of
//! rows is an argument of a function of its own, which the compiler knows overlaps nothing
//! else: the pointers stay in registers.
//!
//! Each run loop is compiled twice: for the baseline target (SSE2 on x86-64) and for AVX2 and
//! FMA, chosen at run time ([`crate::cpu::has_avx2_fma`]). What a closure calls is compiled
//! for AVX2 too where it is inlined into the loop (the per-patch functions of these passes
//! are `#[inline(always)]` for that): a screen tolerance's eight box corners then take
//! four-lane vectors, and the torus grid's tolerances took 0.74 of their time (two threads).
//! The arithmetic is the same, operation for operation: Rust fuses no multiply-add on its
//! own, so every result keeps its bits.

use rayon::prelude::*;

/// Rows per task: a run of patches' rows is a few kilobytes.
const RUN: usize = 1024;

/// Writes every row `i` of `rows` with `fill(i, &mut rows[i])`, in parallel. Cost: one call
/// of `fill` per row.
pub(crate) fn fill<T: Send>(rows: &mut [T], fill: impl Fn(usize, &mut T) + Sync) {
    #[inline(always)]
    fn body<T>(first: usize, rows: &mut [T], fill: &impl Fn(usize, &mut T)) {
        for (i, row) in rows.iter_mut().enumerate() {
            fill(first + i, row);
        }
    }
    #[inline(never)]
    fn run<T>(first: usize, rows: &mut [T], fill: &impl Fn(usize, &mut T)) {
        body(first, rows, fill)
    }
    /// [`run`] for AVX2 and FMA. Safety: the CPU must have them.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    unsafe fn run_wide<T>(first: usize, rows: &mut [T], fill: &impl Fn(usize, &mut T)) {
        body(first, rows, fill)
    }
    let wide = crate::cpu::has_avx2_fma();
    rows.par_chunks_mut(RUN).enumerate().for_each(|(c, rows)| {
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: `wide` says the CPU has AVX2 and FMA.
            return unsafe { run_wide(c * RUN, rows, &fill) };
        }
        let _ = wide;
        run(c * RUN, rows, &fill)
    });
}

/// [`fill`] of two rows at once: `fill(i, &mut a[i], &mut b[i])`. Precondition: `a` and `b`
/// have the same length. Cost: one call of `fill` per row.
pub(crate) fn fill_pairs<A: Send, B: Send>(
    a: &mut [A],
    b: &mut [B],
    fill: impl Fn(usize, &mut A, &mut B) + Sync,
) {
    debug_assert_eq!(a.len(), b.len());
    #[inline(always)]
    fn body<A, B>(first: usize, a: &mut [A], b: &mut [B], fill: &impl Fn(usize, &mut A, &mut B)) {
        for (i, (a, b)) in a.iter_mut().zip(b).enumerate() {
            fill(first + i, a, b);
        }
    }
    #[inline(never)]
    fn run<A, B>(first: usize, a: &mut [A], b: &mut [B], fill: &impl Fn(usize, &mut A, &mut B)) {
        body(first, a, b, fill)
    }
    /// [`run`] for AVX2 and FMA. Safety: the CPU must have them.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    #[inline(never)]
    unsafe fn run_wide<A, B>(first: usize, a: &mut [A], b: &mut [B], fill: &impl Fn(usize, &mut A, &mut B)) {
        body(first, a, b, fill)
    }
    let wide = crate::cpu::has_avx2_fma();
    let runs = a.par_chunks_mut(RUN).zip(b.par_chunks_mut(RUN)).enumerate();
    runs.for_each(|(c, (a, b))| {
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: `wide` says the CPU has AVX2 and FMA.
            return unsafe { run_wide(c * RUN, a, b, &fill) };
        }
        let _ = wide;
        run(c * RUN, a, b, &fill)
    });
}
