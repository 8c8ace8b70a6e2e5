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
//! Each run loop is compiled twice, for the baseline target and for AVX2 and FMA
//! ([`crate::cpu::multiversioned`]). A pass's closure is `#[inline(always)]`, and so are the
//! per-patch functions it calls where the wider build pays (the screen tolerance's), so that
//! they are compiled into both: a box's eight corners then take four-lane vectors.

use rayon::prelude::*;

/// Rows per task: a run of patches' rows is a few kilobytes.
const RUN: usize = 1024;

/// Writes every row `i` of `rows` with `fill(i, &mut rows[i])`, in parallel. Cost: one call
/// of `fill` per row.
pub(crate) fn fill<T: Send>(rows: &mut [T], fill: impl Fn(usize, &mut T) + Sync) {
    // Inlined into both builds, with its rows still arguments (inlining keeps what they do
    // not overlap).
    #[inline(always)]
    fn run<T>(first: usize, rows: &mut [T], fill: &impl Fn(usize, &mut T)) {
        for (i, row) in rows.iter_mut().enumerate() {
            fill(first + i, row);
        }
    }
    let (runs, fill) = (rows.par_chunks_mut(RUN).enumerate(), &fill);
    runs.for_each(|(c, rows)| {
        crate::cpu::multiversioned(
            #[inline(always)]
            move || run(c * RUN, rows, fill),
        )
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
    fn run<A, B>(first: usize, a: &mut [A], b: &mut [B], fill: &impl Fn(usize, &mut A, &mut B)) {
        for (i, (a, b)) in a.iter_mut().zip(b).enumerate() {
            fill(first + i, a, b);
        }
    }
    let (runs, fill) = (a.par_chunks_mut(RUN).zip(b.par_chunks_mut(RUN)).enumerate(), &fill);
    runs.for_each(|(c, (a, b))| {
        crate::cpu::multiversioned(
            #[inline(always)]
            move || run(c * RUN, a, b, fill),
        )
    });
}
