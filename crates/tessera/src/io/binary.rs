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
    if let Some(k) = mesh.indices.iter().position(|&i| i as usize >= n) {
        return invalid(format!(
            "triangle {} refers to vertex {} but the mesh has {n} vertices",
            k / 3,
            mesh.indices[k]
        ));
    }
    let finite = |c: &[f32]| c.iter().all(|x| x.is_finite());
    if let Some(i) = mesh.positions.iter().position(|p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite position {:?}", mesh.positions[i]));
    }
    if let Some(i) = mesh.normals.iter().position(|p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite normal {:?}", mesh.normals[i]));
    }
    if let Some(i) = mesh.uvs.iter().position(|p| !finite(p)) {
        return invalid(format!("vertex {i} has a non-finite uv {:?}", mesh.uvs[i]));
    }
    if let Some(params) = &mesh.corner_params {
        if let Some(k) = params.iter().position(|p| !finite(p)) {
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

pub(crate) fn put_f32s<W: Write>(w: &mut W, values: &[f32]) -> io::Result<()> {
    for v in values {
        w.write_all(&v.to_le_bytes())?;
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
