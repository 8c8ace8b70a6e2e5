//! Non-temporal (streaming) stores of `u32` runs: written to memory without first reading
//! the lines into the cache. Hand-written because no crate of the field offers them; the
//! instructions are std's (`_mm_stream_si128`, SSE2, every x86-64).
//!
//! **Why.** A frame's index buffer can far exceed the cache (the torus at factor 64: 268 MB
//! of indices and triangle patch ids), and a plain store first reads its line from memory
//! (write-allocate): each such byte crossed the memory bus twice. Streamed, the index pass of
//! that frame took half the time (37–41 → 20 ms on one thread, 19.5–20.5 → 10.5 ms on two;
//! at factor 32, 151 MB of output, 10.5 → 6.0 and 4.7–5.2 → 3.0 ms; a 2-core Intel Xeon VM
//! whose L3 is reported as 480 MiB, shared with the host's other cores). But a frame about
//! the size of a typical cache (factor 16, 36 MB) lost a third (1.55 → 2.05 ms on one
//! thread): a loop writing into the same buffers finds much of them still cached, which a
//! streaming store gives up. So a frame streams its indices only where its output passes
//! twice the cache a core can count on ([`index_writes`]); the values are the same either way.

use std::sync::OnceLock;

/// The most of the last-level cache [`index_writes`] counts on: a large L3 is shared by many
/// cores (the 480 MiB the VM above reports held far less of a frame than that), and the L3
/// of the machines most users have is 16–64 MiB.
const CACHE_COUNTED_ON: u64 = 64 << 20;

/// The cache size [`index_writes`] assumes where the system does not say.
const ASSUMED_CACHE_BYTES: u64 = 32 << 20;

/// How a frame writes its triangles ([`index_writes`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum IndexWrites {
    /// In the vertex pass, each patch's after its vertices: an output within the cache, of
    /// small patterns.
    WithVertices,
    /// In a pass of their own, by plain stores: an output past the cache, or of large
    /// patterns. Bursts into the index arrays between each patch's vertex writes broke the
    /// store streams the two passes keep: the torus at factor 16 (36 MB, 512 triangles a
    /// patch) 1.35 → 1.66 ms on two threads with its triangles in the vertex pass (a 32 MiB
    /// L3), and at 0.001 % of its diagonal (15 MB, 214 a patch) 17 % slower on one thread
    /// beside another process, where the cow's frames (29 to 73 a patch) gained 1.5–3 %.
    OwnPass,
    /// In a pass of their own, by streaming stores: an output past twice the cache.
    Streamed,
}

/// Patterns of more triangles than this on average keep their triangles in a pass of their
/// own ([`IndexWrites::OwnPass`]).
const WITH_VERTICES_TRIANGLES: u64 = 128;

/// How a frame of `output_bytes` (vertices, indices, triangle patches, parameters),
/// `triangles` over `patches` patches, writes its triangles, by the last-level cache
/// ([`last_level_cache_bytes`], asked once a process), counted at most
/// [`CACHE_COUNTED_ON`]: streamed past twice the cache, in their own pass past it or where
/// patterns average more than [`WITH_VERTICES_TRIANGLES`], else with the vertices. Cost: O(1).
pub(crate) fn index_writes(output_bytes: u64, triangles: u64, patches: u64) -> IndexWrites {
    #[cfg(test)]
    if let Some(forced) = FORCED.get() {
        return forced;
    }
    static CACHE: OnceLock<u64> = OnceLock::new();
    let cache =
        *CACHE.get_or_init(|| last_level_cache_bytes().unwrap_or(ASSUMED_CACHE_BYTES).min(CACHE_COUNTED_ON));
    if output_bytes > 2 * cache {
        IndexWrites::Streamed
    } else if output_bytes > cache || triangles > WITH_VERTICES_TRIANGLES * patches {
        IndexWrites::OwnPass
    } else {
        IndexWrites::WithVertices
    }
}

#[cfg(test)]
thread_local! {
    /// [`index_writes`]' answer on this thread where a test sets it ([`force_on_this_thread`]).
    static FORCED: std::cell::Cell<Option<IndexWrites>> = const { std::cell::Cell::new(None) };
}

/// Makes [`index_writes`] answer `forced` on this thread (None: by the frame's size again),
/// so a test can write one frame every way.
#[cfg(test)]
pub(crate) fn force_on_this_thread(forced: Option<IndexWrites>) {
    FORCED.set(forced);
}

/// The size of the last-level (L3) cache of CPU 0 in bytes, from Linux's sysfs; None where
/// it does not say (another system, or a processor without one). Cost: a few small file
/// reads.
pub fn last_level_cache_bytes() -> Option<u64> {
    let dir = std::path::Path::new("/sys/devices/system/cpu/cpu0/cache");
    std::fs::read_dir(dir).ok()?.flatten().find_map(|entry| {
        let level = std::fs::read_to_string(entry.path().join("level")).ok()?;
        if level.trim() != "3" {
            return None;
        }
        parse_cache_size(&std::fs::read_to_string(entry.path().join("size")).ok()?)
    })
}

/// A sysfs cache size (`"36608K"`, `"260M"`, `"512"`) in bytes.
fn parse_cache_size(text: &str) -> Option<u64> {
    let t = text.trim();
    let (digits, unit) = match t.char_indices().find(|(_, c)| !c.is_ascii_digit()) {
        Some((i, _)) => t.split_at(i),
        None => (t, ""),
    };
    let n: u64 = digits.parse().ok()?;
    let scale = match unit.trim() {
        "" => 1,
        "K" | "k" => 1 << 10,
        "M" => 1 << 20,
        "G" => 1 << 30,
        _ => return None,
    };
    n.checked_mul(scale)
}

/// Copies `src` into `dst` (the same length), with streaming stores for the 16-byte-aligned
/// middle of `dst` and plain stores for its ends. Call [`fence`] before another thread
/// reads `dst`. Cost: O(n), one pass.
#[inline]
pub(crate) fn copy(dst: &mut [u32], src: &[u32]) {
    assert_eq!(dst.len(), src.len(), "one source value per destination slot");
    let (head, middle, tail) = aligned(dst);
    let (src_head, rest) = src.split_at(head.len());
    let (src_middle, src_tail) = rest.split_at(middle.len() * 4);
    head.copy_from_slice(src_head);
    tail.copy_from_slice(src_tail);
    #[cfg(target_arch = "x86_64")]
    for (out, four) in middle.iter_mut().zip(src_middle.chunks_exact(4)) {
        use std::arch::x86_64::*;
        // SAFETY: SSE2 is part of x86-64; `out` is 16-byte aligned (`Four`)
        // and `four` holds four values (read unaligned).
        unsafe {
            let v = _mm_loadu_si128(four.as_ptr().cast());
            _mm_stream_si128((out as *mut Four).cast(), v);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (out, four) in middle.iter_mut().zip(src_middle.chunks_exact(4)) {
        out.0.copy_from_slice(four);
    }
}

/// Fills `dst` with `value` as [`copy`] writes. Call [`fence`] before another thread reads
/// `dst`. Cost: O(n).
#[inline]
pub(crate) fn fill(dst: &mut [u32], value: u32) {
    let (head, middle, tail) = aligned(dst);
    head.fill(value);
    tail.fill(value);
    #[cfg(target_arch = "x86_64")]
    for out in middle.iter_mut() {
        use std::arch::x86_64::*;
        // SAFETY: as in `copy`.
        unsafe { _mm_stream_si128((out as *mut Four).cast(), _mm_set1_epi32(value as i32)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    middle.iter_mut().for_each(|out| out.0 = [value; 4]);
}

/// Orders this thread's streaming stores before its later stores (they are weakly ordered),
/// so that a thread that sees the later ones (the end of a parallel task) sees them too.
#[inline]
pub(crate) fn fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86-64.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

/// Four values at a 16-byte boundary: what one streaming store writes.
#[repr(C, align(16))]
struct Four([u32; 4]);

/// `dst` as its unaligned head, its 16-byte-aligned middle in fours and its tail.
fn aligned(dst: &mut [u32]) -> (&mut [u32], &mut [Four], &mut [u32]) {
    // SAFETY: `Four` is four `u32`s (no invalid bit patterns, no padding), and `align_to_mut`
    // keeps every element in one of the three parts.
    unsafe { dst.align_to_mut::<Four>() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cache_sizes_parse_as_sysfs_writes_them() {
        assert_eq!(parse_cache_size("36608K\n"), Some(36608 * 1024));
        assert_eq!(parse_cache_size("260M"), Some(260 << 20));
        assert_eq!(parse_cache_size("512"), Some(512));
        assert_eq!(parse_cache_size("big"), None);
        assert_eq!(parse_cache_size("12X"), None);
    }

    /// Every length and offset: the copy is the source, the fill the value, with nothing
    /// written outside the slice.
    #[test]
    fn copies_and_fills_every_length_at_every_alignment() {
        for offset in 0..8 {
            for n in 0..70 {
                let src: Vec<u32> = (0..n as u32).map(|i| i * 7 + 1).collect();
                let mut buf = vec![u32::MAX; n + 16];
                copy(&mut buf[offset..offset + n], &src);
                fence();
                assert_eq!(&buf[offset..offset + n], &src[..], "copy of {n} at {offset}");
                assert!(buf[..offset].iter().chain(&buf[offset + n..]).all(|&x| x == u32::MAX));
                fill(&mut buf[offset..offset + n], 5);
                fence();
                assert!(buf[offset..offset + n].iter().all(|&x| x == 5), "fill of {n} at {offset}");
                assert!(buf[..offset].iter().chain(&buf[offset + n..]).all(|&x| x == u32::MAX));
            }
        }
    }
}
