//! Helpers shared by the binary mesh formats ([`ply`](super::ply), [`stl`](super::stl),
//! [`glb`](super::glb)) and the text OBJ writer: the consistency check every writer runs
//! before its first byte, little-endian output, and the filling-in of attributes a file lacks.

use std::io::{self, Write};

use crate::error::{Error, Result};
use crate::mesh::Mesh;

/// Large enough that the per-call overhead of the underlying writer is amortised, small enough
/// not to matter next to the mesh itself.
pub(crate) const BUF_CAPACITY: usize = 1 << 16;

/// Label of the output in [`Error::Write`] when the caller gave a writer rather than a path.
pub(crate) const WRITER_LABEL: &str = "<writer>";

/// Rejects meshes whose buffers disagree or hold non-finite numbers: every format would either
/// index out of bounds or write a file its readers refuse.
pub(crate) fn check_mesh(mesh: &Mesh) -> Result<()> {
    // The scans are parallel (`first_where` keeps the first offender, as a sequential scan
    // would): on a large mesh they would otherwise cost as much as the binary writing itself.
    let invalid = |reason: String| Err(Error::InvalidMesh { reason });
    let n = mesh.positions.len();
    for (what, len) in [
        ("normals", mesh.normals.len()),
        ("uvs", mesh.uvs.len()),
        ("vertex patches", mesh.vertex_patch.len()),
    ] {
        if len != n {
            return invalid(format!("mesh has {len} {what} for {n} vertices"));
        }
    }
    if mesh.indices.len() % 3 != 0 {
        return invalid(format!("mesh has {} indices, not a multiple of 3", mesh.indices.len()));
    }
    let t = mesh.triangle_count();
    if mesh.triangle_patch.len() != t {
        return invalid(format!("mesh has {} triangle patches for {t} triangles", mesh.triangle_patch.len()));
    }
    if let Some(params) = &mesh.corner_params {
        if params.len() != mesh.indices.len() {
            return invalid(format!(
                "mesh has {} corner params for {} triangle corners",
                params.len(),
                mesh.indices.len()
            ));
        }
    }
    if let Some(strips) = &mesh.strips {
        let restart = crate::mesh::strips::RESTART;
        if let Some(&i) = strips.iter().find(|&&i| i != restart && (i as usize >= n || i > i32::MAX as u32)) {
            return invalid(format!("strips refer to vertex {i} but the mesh has {n} vertices"));
        }
        if u32::try_from(strips.len()).is_err() {
            return invalid(format!("{} strip indices exceed the PLY list limit", strips.len()));
        }
    }
    if let Some(k) = first_where(&mesh.indices, |&i| i as usize >= n) {
        return invalid(format!(
            "triangle {} refers to vertex {} but the mesh has {n} vertices",
            k / 3,
            mesh.indices[k]
        ));
    }
    let finite = |c: &[f32]| c.iter().all(|x| x.is_finite());
    if let Some(i) = first_where(&mesh.positions, |p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite position {:?}", mesh.positions[i]));
    }
    if let Some(i) = first_where(&mesh.normals, |p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite normal {:?}", mesh.normals[i]));
    }
    if let Some(i) = first_where(&mesh.uvs, |p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite uv {:?}", mesh.uvs[i]));
    }
    if let Some(params) = &mesh.corner_params {
        if let Some(k) = first_where(params, |p| !finite(p)) {
            return invalid(format!(
                "corner {} of triangle {} has non-finite params {:?}",
                k % 3,
                k / 3,
                params[k]
            ));
        }
    }
    Ok(())
}

/// The index of the first item of `items` for which `bad` holds, scanning in parallel chunks.
/// Why not rayon's `position_first`: it checks for an earlier hit after every item, which
/// made the check of a million-triangle mesh slower than writing it.
fn first_where<T: Sync>(items: &[T], bad: impl Fn(&T) -> bool + Sync) -> Option<usize> {
    use rayon::prelude::*;
    const CHUNK: usize = 1 << 16;
    items
        .par_chunks(CHUNK)
        .enumerate()
        .find_map_first(|(c, chunk)| chunk.iter().position(&bad).map(|k| c * CHUNK + k))
}

/// Writes `data`, made of 4-byte words (`f32`, `u32` and arrays of them), as little-endian
/// words. On a little-endian machine the slice's own bytes go out in one call, so a large
/// array costs one copy (the kernel's); elsewhere the words are swapped chunk by chunk.
pub(crate) fn put_words<W: Write, T: bytemuck::Pod>(w: &mut W, data: &[T]) -> io::Result<()> {
    let words: &[u32] = bytemuck::cast_slice(data);
    if cfg!(target_endian = "little") {
        return w.write_all(bytemuck::cast_slice(words));
    }
    write_chunks(w, words.len(), BIN_CHUNK, |range, out| {
        out.extend(words[range].iter().flat_map(|x| x.to_le_bytes()));
    })
}

/// Copies the words of `values` into `dst` as little-endian bytes; `dst` is `4 * N` long.
/// Compiles to a plain copy on little-endian machines.
#[inline]
pub(crate) fn le_words<const N: usize>(dst: &mut [u8], values: [u32; N]) {
    for (d, v) in dst.chunks_exact_mut(4).zip(values) {
        d.copy_from_slice(&v.to_le_bytes());
    }
}

/// [`le_words`] for floats.
#[inline]
pub(crate) fn le_floats<const N: usize>(dst: &mut [u8], values: [f32; N]) {
    le_words(dst, values.map(f32::to_bits));
}

/// Items per chunk of the binary writers: records of 12 to 50 bytes, so a chunk is a few
/// hundred KiB, big enough to amortise a task and a `write` call, small enough to stay in cache.
pub(crate) const BIN_CHUNK: usize = 1 << 14;

/// Most chunks formatted ahead of the writer per thread-batch, whatever the thread count, so
/// that the buffers stay a few MiB (two batches live at a time).
const MAX_BATCH: usize = 16;

/// Writes `count` items to `w` in order: `fill(range, buf)` appends the bytes of the items in
/// `range` to the (cleared) `buf`. The items are cut into chunks of `per_chunk`, and a batch
/// of chunks (two per rayon thread, at most 16) is formatted in parallel into their own
/// buffers, then written in chunk order while the next batch is formatted.
///
/// Why: formatting dominates text output and is independent per item, while the `write`
/// calls must stay in order. The bytes depend only on `count` and `per_chunk`, never on the
/// number of threads or on scheduling.
///
/// Preconditions: `per_chunk > 0`; `fill` appends exactly the bytes of its items (it is
/// called once per chunk). Errors: the first error of `w`, after which nothing more is
/// written. Cost: the formatting work spread over the rayon threads, plus one `write_all`
/// per chunk; memory: two batches of chunk buffers, reused.
pub(crate) fn write_chunks<W, F>(w: &mut W, count: usize, per_chunk: usize, fill: F) -> io::Result<()>
where
    W: Write + ?Sized,
    F: Fn(std::ops::Range<usize>, &mut Vec<u8>) + Sync,
{
    use rayon::prelude::*;
    assert!(per_chunk > 0, "chunks must hold items");
    let chunks = count.div_ceil(per_chunk);
    if chunks == 0 {
        return Ok(());
    }
    let batch = (2 * rayon::current_num_threads()).clamp(2, MAX_BATCH).min(chunks);
    // Formats the batch whose first chunk is `first` into `bufs`; buffers past the last chunk
    // are left empty.
    let format = |first: usize, bufs: &mut [Vec<u8>]| {
        bufs.par_iter_mut().enumerate().for_each(|(k, buf)| {
            buf.clear();
            let c = first + k;
            if c < chunks {
                fill(c * per_chunk..((c + 1) * per_chunk).min(count), buf);
            }
        })
    };
    let mut current = vec![Vec::new(); batch];
    let mut next = vec![Vec::new(); batch];
    format(0, &mut current);
    for first in (0..chunks).step_by(batch) {
        let following = first + batch;
        let mut written = Ok(());
        // In place: this thread writes (`w` need not be `Send`) while the pool formats the
        // next batch.
        rayon::in_place_scope(|s| {
            if following < chunks {
                let next = &mut next;
                let format = &format;
                s.spawn(move |_| format(following, next));
            }
            written = current.iter().try_for_each(|buf| w.write_all(buf));
        });
        written?;
        std::mem::swap(&mut current, &mut next);
    }
    Ok(())
}

pub(crate) fn put_u32<W: Write>(w: &mut W, v: u32) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}

/// Fills the attributes a format lacks so that every vector has its documented length.
pub(crate) fn fill_missing(mesh: &mut Mesh) {
    let n = mesh.positions.len();
    mesh.normals.resize(n, [0.0; 3]);
    mesh.uvs.resize(n, [0.0; 2]);
    mesh.vertex_patch.resize(n, 0);
    mesh.triangle_patch.resize(mesh.indices.len() / 3, 0);
}

/// Converts a number read from a file to a `u32` index or id, refusing fractions, negatives,
/// NaN and values past `u32::MAX` (which `as` would silently saturate).
pub(crate) fn to_u32(v: f64) -> Option<u32> {
    (v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&v)).then_some(v as u32)
}

/// `true` when every value is finite (no NaN, no infinity).
pub(crate) fn all_finite(values: &[f32]) -> bool {
    values.iter().all(|v| v.is_finite())
}

/// Meshes and helpers shared by the tests of the format modules.
#[cfg(test)]
pub(crate) mod test_meshes {
    use std::path::Path;

    use crate::error::{Error, Result};
    use crate::mesh::Mesh;

    /// A wavy grid of `k`×`k` quads split into two patches by column, so that the triangle
    /// patch changes several times along the index order; uv and corner params are distinct
    /// per vertex and corner.
    pub(crate) fn grid(k: u32, corner_params: bool) -> Mesh {
        let mut m = Mesh::default();
        for j in 0..=k {
            for i in 0..=k {
                let (x, y) = (i as f32 / k as f32, j as f32 / k as f32);
                m.positions.push([x, y, 0.1 * (3.0 * x).sin() * (2.0 * y).cos()]);
                let n = glam::Vec3::new(-0.3 * x, 0.2 * y, 1.0).normalize();
                m.normals.push(n.to_array());
                m.uvs.push([x, 1.0 - y]);
                m.vertex_patch.push(if 2 * i < k { 3 } else { 7 });
            }
        }
        let id = |i: u32, j: u32| j * (k + 1) + i;
        for j in 0..k {
            for i in 0..k {
                let patch = if 2 * i < k { 3 } else { 7 };
                m.indices.extend([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                m.indices.extend([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
                m.triangle_patch.extend([patch, patch]);
            }
        }
        if corner_params {
            let params = m.indices.iter().enumerate().map(|(c, &v)| {
                let uv = m.uvs[v as usize];
                [uv[0] * 0.5 + c as f32 * 1e-3, uv[1] * 0.25]
            });
            m.corner_params = Some(params.collect());
        }
        m
    }

    /// The bytes a writer produces for a mesh.
    pub(crate) fn bytes(f: impl FnOnce(&mut Vec<u8>) -> Result<()>) -> Vec<u8> {
        let mut out = Vec::new();
        f(&mut out).expect("writing to memory succeeds");
        out
    }

    /// The file label the tests give the parsers.
    pub(crate) fn label() -> &'static Path {
        Path::new("<test>")
    }

    /// The location and reason of a parse error, failing the test on anything else.
    pub(crate) fn parse_error(r: Result<Mesh>) -> (usize, String) {
        match r {
            Err(Error::Parse { at, reason }) => {
                assert_eq!(at.file, label());
                (at.line, reason)
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    /// Every strict prefix of `data` must give an error (when `all_fail`) and never panic.
    pub(crate) fn check_truncations(data: &[u8], parse: fn(&[u8], &Path) -> Result<Mesh>, all_fail: bool) {
        assert!(parse(data, label()).is_ok());
        for len in 0..data.len() {
            let r = parse(&data[..len], label());
            if all_fail {
                assert!(r.is_err(), "prefix of {len} bytes parsed");
            }
        }
    }

    /// Corrupting any single byte must not panic, whatever the result.
    pub(crate) fn check_corruptions(data: &[u8], parse: fn(&[u8], &Path) -> Result<Mesh>) {
        let mut copy = data.to_vec();
        for i in 0..data.len() {
            for value in [data[i] ^ 0xff, 0, b'9'] {
                copy[i] = value;
                let _ = parse(&copy, label());
            }
            copy[i] = data[i];
        }
    }
}
