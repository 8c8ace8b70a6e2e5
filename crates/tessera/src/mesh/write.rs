//! Mesh writers: OBJ, binary PLY, binary STL and glTF binary (GLB).
//!
//! Every writer first checks that the mesh is consistent (attribute lengths, indices in range,
//! finite numbers) and fits the format's limits, so a bad mesh fails with a typed error before
//! the first byte is written instead of producing a file that other tools reject later.
//! Each writer buffers internally, so callers may pass an unbuffered `File` without paying one
//! system call per number.
//!
//! What each format keeps:
//!
//! | format | positions | normals | uvs | vertex patch | triangle patch | corner params |
//! |--------|-----------|---------|-----|--------------|----------------|---------------|
//! | OBJ    | yes       | yes     | yes | no           | `g patch_<id>` | no            |
//! | PLY    | yes       | yes     | yes | yes          | yes            | `texcoord`    |
//!
//! Triangle strips ([`Mesh::strips`]) go to PLY only, as a `tristrips` element (one `int`
//! list, `-1` between strips) after the face list; the other formats, which cannot store
//! strips, keep the decoded triangle list that `indices` always holds.
//! | STL    | yes       | facet   | no  | no           | no             | no            |
//! | GLB    | yes       | yes     | yes | `_PATCH`     | extras         | extras        |
//!
//! GLB extras: the primitive's `extras` is `{"tessera": {"trianglePatchView": i,
//! "cornerParamsView": j}}` (the second key only when [`Mesh::corner_params`] is set). View `i`
//! holds one little-endian `u32` per triangle, view `j` two little-endian `f32` (u, v) per
//! triangle corner, in index order. They are buffer views without accessors because glTF
//! forbids `UNSIGNED_INT` accessors outside `primitive.indices`, and a float accessor would
//! round patch ids above 2^24.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use glam::DVec3;
use gltf_json as gj;
use gltf_json::validation::{Checked, USize64};

use super::Mesh;
use crate::error::{Error, Result};

/// Large enough that the per-call overhead of the underlying writer is amortised, small enough
/// not to matter next to the mesh itself.
const BUF_CAPACITY: usize = 1 << 16;

/// The extensions [`write_mesh`] understands, for error messages.
const SUPPORTED: &str = ".obj, .ply, .stl, .glb";

/// Label of the output in [`Error::Write`] when the caller gave a writer rather than a path.
const WRITER_LABEL: &str = "<writer>";

/// Largest integer an `f32` holds exactly (and with it every smaller one): the bound on vertex
/// patch ids in the GLB `_PATCH` attribute, which glTF requires to be a float.
const MAX_EXACT_F32_INT: u32 = 1 << 24;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_VERSION: u32 = 2;
const GLB_CHUNK_JSON: &[u8; 4] = b"JSON";
const GLB_CHUNK_BIN: &[u8; 4] = b"BIN\0";
const GLB_HEADER_LEN: u64 = 12;
const GLB_CHUNK_HEADER_LEN: u64 = 8;

/// Output formats, chosen by file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Format {
    Obj,
    Ply,
    Stl,
    Glb,
}

impl Format {
    fn from_path(path: &Path) -> Result<Format> {
        let Some(ext) = path.extension() else {
            return Err(Error::InvalidArgument(format!(
                "{}: output file has no extension; supported: {SUPPORTED}",
                path.display()
            )));
        };
        let ext = ext.to_string_lossy();
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Ok(Format::Obj),
            "ply" => Ok(Format::Ply),
            "stl" => Ok(Format::Stl),
            "glb" => Ok(Format::Glb),
            _ => Err(Error::InvalidArgument(format!(
                "{}: unsupported output extension \".{ext}\"; supported: {SUPPORTED}",
                path.display()
            ))),
        }
    }
}

/// Checks that `path` names a supported output format, so a caller can refuse a bad output
/// name before doing the work. Cost: O(1).
pub fn check_output_path(path: &Path) -> Result<()> {
    Format::from_path(path).map(|_| ())
}

/// Writes `mesh` to `path`, choosing the format by the extension (case-insensitive): `.obj`,
/// `.ply` (binary little-endian), `.stl` (binary) or `.glb`. See the module documentation for
/// what each format keeps.
///
/// Preconditions: the mesh is consistent (one normal, uv and vertex patch per position, one
/// triangle patch per triangle, `corner_params` parallel to `indices`, indices in range, finite
/// numbers); otherwise [`Error::InvalidArgument`], checked before the file is created. An
/// unknown or missing extension is [`Error::InvalidArgument`] naming it and the supported list.
/// I/O failures are [`Error::Write`] naming `path`; a failure part-way leaves a partial file.
///
/// Cost: O(vertices + triangles) time; memory: a 64 KiB buffer, plus the GLB JSON (a few KiB,
/// independent of the mesh size).
pub fn write_mesh(mesh: &Mesh, path: &Path) -> Result<()> {
    let format = Format::from_path(path)?;
    let prepared = prepare(mesh, format)?;
    let write_error = |source| Error::Write { path: path.to_path_buf(), source };
    let file = File::create(path).map_err(write_error)?;
    emit(mesh, &prepared, file).map_err(write_error)
}

/// Writes `mesh` as Wavefront OBJ text to `w`: a `# tessera` header, `v`, `vn` and `vt` lines
/// (the vertex's own uv), then `f a/a/a b/b/b c/c/c` faces (1-based), with a `g patch_<id>` line
/// before each run of triangles of the same patch. Floats are printed in the shortest form that
/// reads back to the same `f32`.
///
/// Preconditions: as [`write_mesh`]. I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time; no allocation beyond a 64 KiB buffer.
pub fn write_obj<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    write_to(mesh, Format::Obj, w)
}

/// Writes `mesh` as binary little-endian PLY to `w`. Vertex properties: `float x y z`,
/// `float nx ny nz`, `float u v`, `uint patch`; face properties:
/// `list uchar uint vertex_indices`, `uint patch` and, when [`Mesh::corner_params`] is set,
/// `list uchar float texcoord` with the six values u0 v0 u1 v1 u2 v2 (MeshLab's name for
/// per-corner texture coordinates).
///
/// Preconditions: as [`write_mesh`]. I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time; no allocation beyond a 64 KiB buffer.
pub fn write_ply<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    write_to(mesh, Format::Ply, w)
}

/// Writes `mesh` as binary STL to `w`: an 80-byte header starting with `tessera`, the triangle
/// count, and per triangle the unit facet normal computed from the positions (zero for a
/// degenerate triangle), its three corners and a zero attribute word. Vertex normals, uvs and
/// patches are not stored.
///
/// Preconditions: as [`write_mesh`], and at most `u32::MAX` triangles, else
/// [`Error::InvalidArgument`]. I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(triangles) time; no allocation beyond a 64 KiB buffer.
pub fn write_stl<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    write_to(mesh, Format::Stl, w)
}

/// Writes `mesh` as glTF 2.0 binary (GLB) to `w`: one buffer, one mesh with one indexed
/// triangle primitive (`POSITION` with min/max, `NORMAL`, `TEXCOORD_0`, the float vertex patch
/// id `_PATCH`, `u32` indices), one node and one scene. Triangle patches and corner params go
/// to buffer views named in the primitive's extras (see the module documentation). A mesh
/// without triangles is written as a file holding only the asset, since glTF forbids empty
/// accessors; any vertices are dropped.
///
/// Preconditions: as [`write_mesh`], vertex patch ids at most 2^24 (exact in the float
/// `_PATCH`), and a file under 4 GiB; otherwise [`Error::InvalidArgument`]. I/O errors are
/// [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time; the JSON is built in memory (a few KiB, independent of
/// the mesh size), the binary data is streamed through a 64 KiB buffer.
pub fn write_glb<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    write_to(mesh, Format::Glb, w)
}

fn write_to<W: Write>(mesh: &Mesh, format: Format, w: W) -> Result<()> {
    let prepared = prepare(mesh, format)?;
    emit(mesh, &prepared, w).map_err(|source| Error::Write { path: PathBuf::from(WRITER_LABEL), source })
}

/// What a format needs computed, and checked, before its first byte is written.
enum Prepared {
    Obj,
    Ply,
    Stl { count: u32 },
    Glb(GlbPlan),
}

fn prepare(mesh: &Mesh, format: Format) -> Result<Prepared> {
    check_mesh(mesh)?;
    Ok(match format {
        Format::Obj => Prepared::Obj,
        Format::Ply => Prepared::Ply,
        Format::Stl => {
            let count = u32::try_from(mesh.triangle_count()).map_err(|_| {
                Error::InvalidArgument(format!(
                    "{} triangles exceed the binary STL limit of {}",
                    mesh.triangle_count(),
                    u32::MAX
                ))
            })?;
            Prepared::Stl { count }
        }
        Format::Glb => Prepared::Glb(plan_glb(mesh)?),
    })
}

fn emit<W: Write>(mesh: &Mesh, prepared: &Prepared, w: W) -> io::Result<()> {
    let mut w = BufWriter::with_capacity(BUF_CAPACITY, w);
    match prepared {
        Prepared::Obj => emit_obj(mesh, &mut w)?,
        Prepared::Ply => emit_ply(mesh, &mut w)?,
        Prepared::Stl { count } => emit_stl(mesh, *count, &mut w)?,
        Prepared::Glb(plan) => emit_glb(mesh, plan, &mut w)?,
    }
    // An explicit flush, because BufWriter's drop would swallow the error of the last write.
    w.flush()
}

/// Rejects meshes whose buffers disagree or hold non-finite numbers: every format would either
/// index out of bounds or write a file its readers refuse.
fn check_mesh(mesh: &Mesh) -> Result<()> {
    let invalid = |reason: String| Err(Error::InvalidArgument(reason));
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
        let restart = super::strips::RESTART;
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

fn put_f32s<W: Write>(w: &mut W, values: &[f32]) -> io::Result<()> {
    for v in values {
        w.write_all(&v.to_le_bytes())?;
    }
    Ok(())
}

fn put_u32<W: Write>(w: &mut W, v: u32) -> io::Result<()> {
    w.write_all(&v.to_le_bytes())
}

// ---------------------------------------------------------------------------------------------
// OBJ

fn emit_obj<W: Write>(mesh: &Mesh, w: &mut W) -> io::Result<()> {
    writeln!(w, "# tessera")?;
    writeln!(w, "# {} vertices, {} triangles", mesh.vertex_count(), mesh.triangle_count())?;
    for p in &mesh.positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for n in &mesh.normals {
        writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
    }
    for uv in &mesh.uvs {
        writeln!(w, "vt {} {}", uv[0], uv[1])?;
    }
    let mut group = None;
    for (tri, &patch) in mesh.indices.chunks_exact(3).zip(&mesh.triangle_patch) {
        if group != Some(patch) {
            writeln!(w, "g patch_{patch}")?;
            group = Some(patch);
        }
        // u64 because index u32::MAX would overflow when made 1-based.
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(|i| u64::from(i) + 1);
        writeln!(w, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}")?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// PLY

fn emit_ply<W: Write>(mesh: &Mesh, w: &mut W) -> io::Result<()> {
    write!(
        w,
        "ply\n\
         format binary_little_endian 1.0\n\
         comment tessera\n\
         element vertex {}\n\
         property float x\n\
         property float y\n\
         property float z\n\
         property float nx\n\
         property float ny\n\
         property float nz\n\
         property float u\n\
         property float v\n\
         property uint patch\n\
         element face {}\n\
         property list uchar uint vertex_indices\n\
         property uint patch\n",
        mesh.vertex_count(),
        mesh.triangle_count()
    )?;
    if mesh.corner_params.is_some() {
        writeln!(w, "property list uchar float texcoord")?;
    }
    if mesh.strips.is_some() {
        // The Stanford `tristrips` convention: one list, strips separated by -1.
        writeln!(w, "element tristrips 1\nproperty list uint int vertex_indices")?;
    }
    writeln!(w, "end_header")?;
    for (((p, n), uv), &patch) in
        mesh.positions.iter().zip(&mesh.normals).zip(&mesh.uvs).zip(&mesh.vertex_patch)
    {
        put_f32s(w, p)?;
        put_f32s(w, n)?;
        put_f32s(w, uv)?;
        put_u32(w, patch)?;
    }
    for (t, (tri, &patch)) in mesh.indices.chunks_exact(3).zip(&mesh.triangle_patch).enumerate() {
        w.write_all(&[3])?;
        for &i in tri {
            put_u32(w, i)?;
        }
        put_u32(w, patch)?;
        if let Some(params) = &mesh.corner_params {
            w.write_all(&[6])?;
            for uv in &params[3 * t..3 * t + 3] {
                put_f32s(w, uv)?;
            }
        }
    }
    if let Some(strips) = &mesh.strips {
        put_u32(w, strips.len() as u32)?;
        for &i in strips {
            let v = if i == super::strips::RESTART { -1 } else { i as i32 };
            w.write_all(&v.to_le_bytes())?;
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// STL

fn emit_stl<W: Write>(mesh: &Mesh, count: u32, w: &mut W) -> io::Result<()> {
    let mut header = [0u8; 80];
    header[..7].copy_from_slice(b"tessera");
    w.write_all(&header)?;
    put_u32(w, count)?;
    let position = |i: u32| mesh.positions[i as usize];
    for tri in mesh.indices.chunks_exact(3) {
        let [a, b, c] = [tri[0], tri[1], tri[2]].map(position);
        // In f64 so that tiny but valid triangles do not underflow to a zero normal.
        let [da, db, dc] = [a, b, c].map(|p| DVec3::from(p.map(f64::from)));
        let n = (db - da).cross(dc - da).normalize_or_zero().as_vec3();
        put_f32s(w, &n.to_array())?;
        for p in [a, b, c] {
            put_f32s(w, &p)?;
        }
        w.write_all(&[0, 0])?;
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// GLB

/// The GLB's JSON chunk (already padded) and binary chunk length, fixed before writing because
/// the header carries the total length.
struct GlbPlan {
    json: Vec<u8>,
    bin_len: u64,
}

/// One buffer view's place in the binary chunk.
struct Span {
    offset: u64,
    len: u64,
}

fn plan_glb(mesh: &Mesh) -> Result<GlbPlan> {
    let n = mesh.vertex_count() as u64;
    let t = mesh.triangle_count() as u64;
    let mut root = gj::Root {
        asset: gj::Asset { generator: Some("tessera".to_string()), ..Default::default() },
        ..Default::default()
    };
    let mut bin_len = 0u64;
    if t > 0 {
        if let Some(i) = mesh.vertex_patch.iter().position(|&p| p > MAX_EXACT_F32_INT) {
            return Err(Error::InvalidArgument(format!(
                "vertex {i} has patch id {}, above 2^24, the largest a float glTF attribute \
                 holds exactly",
                mesh.vertex_patch[i]
            )));
        }
        // Every section is a whole number of 4-byte words, so each stays aligned for its
        // component type without padding between them.
        let mut next = 0u64;
        let mut span = |len: u64| {
            let s = Span { offset: next, len };
            next += len;
            s
        };
        let positions = span(12 * n);
        let normals = span(12 * n);
        let uvs = span(8 * n);
        let patches = span(4 * n);
        let indices = span(12 * t);
        let triangle_patch = span(4 * t);
        let corner_params = mesh.corner_params.as_ref().map(|_| span(24 * t));
        bin_len = next;

        let buffer = root.push(gj::Buffer {
            byte_length: USize64(bin_len),
            uri: None,
            extensions: None,
            extras: Default::default(),
        });
        let mut view = |s: &Span, target: Option<gj::buffer::Target>| {
            root.push(gj::buffer::View {
                buffer,
                byte_length: USize64(s.len),
                byte_offset: Some(USize64(s.offset)),
                byte_stride: None,
                target: target.map(Checked::Valid),
                extensions: None,
                extras: Default::default(),
            })
        };
        let array = Some(gj::buffer::Target::ArrayBuffer);
        let v_positions = view(&positions, array);
        let v_normals = view(&normals, array);
        let v_uvs = view(&uvs, array);
        let v_patches = view(&patches, array);
        let v_indices = view(&indices, Some(gj::buffer::Target::ElementArrayBuffer));
        let v_triangle_patch = view(&triangle_patch, None);
        let v_corner_params = corner_params.as_ref().map(|s| view(s, None));

        let (min, max) = position_bounds(&mesh.positions);
        let mut accessor = |view, count, component, type_, bounds: Option<([f32; 3], [f32; 3])>| {
            root.push(gj::Accessor {
                buffer_view: Some(view),
                byte_offset: None,
                count: USize64(count),
                component_type: Checked::Valid(gj::accessor::GenericComponentType(component)),
                extensions: None,
                extras: Default::default(),
                type_: Checked::Valid(type_),
                min: bounds.map(|(lo, _)| serde_json::Value::from(lo.to_vec())),
                max: bounds.map(|(_, hi)| serde_json::Value::from(hi.to_vec())),
                normalized: false,
                sparse: None,
            })
        };
        use gj::accessor::{ComponentType as C, Type as T};
        let a_positions = accessor(v_positions, n, C::F32, T::Vec3, Some((min, max)));
        let a_normals = accessor(v_normals, n, C::F32, T::Vec3, None);
        let a_uvs = accessor(v_uvs, n, C::F32, T::Vec2, None);
        let a_patches = accessor(v_patches, n, C::F32, T::Scalar, None);
        let a_indices = accessor(v_indices, 3 * t, C::U32, T::Scalar, None);

        let mut extras = serde_json::Map::new();
        extras.insert("trianglePatchView".into(), v_triangle_patch.value().into());
        if let Some(v) = v_corner_params {
            extras.insert("cornerParamsView".into(), v.value().into());
        }
        let mut wrapper = serde_json::Map::new();
        wrapper.insert("tessera".into(), extras.into());
        let extras = serde_json::value::to_raw_value(&wrapper)
            .map_err(|e| Error::InvalidArgument(format!("cannot encode glTF extras: {e}")))?;

        use gj::mesh::Semantic;
        let attributes = [
            (Semantic::Positions, a_positions),
            (Semantic::Normals, a_normals),
            (Semantic::TexCoords(0), a_uvs),
            // Serialised as "_PATCH": glTF requires application attributes to start with '_'.
            (Semantic::Extras("PATCH".to_string()), a_patches),
        ]
        .into_iter()
        .map(|(s, a)| (Checked::Valid(s), a))
        .collect();
        let gltf_mesh = root.push(gj::Mesh {
            extensions: None,
            extras: Default::default(),
            primitives: vec![gj::mesh::Primitive {
                attributes,
                extensions: None,
                extras: Some(extras),
                indices: Some(a_indices),
                material: None,
                mode: Checked::Valid(gj::mesh::Mode::Triangles),
                targets: None,
            }],
            weights: None,
        });
        let node = root.push(gj::Node { mesh: Some(gltf_mesh), ..Default::default() });
        let scene = root.push(gj::Scene { extensions: None, extras: Default::default(), nodes: vec![node] });
        root.scene = Some(scene);
    }
    // Without triangles the file holds only the asset: glTF forbids empty accessors, and
    // gltf-json cannot read back a scene without nodes.

    let mut json =
        root.to_vec().map_err(|e| Error::InvalidArgument(format!("cannot encode glTF JSON: {e}")))?;
    // The GLB spec pads the JSON chunk with spaces so that it stays valid JSON.
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = glb_total_len(json.len() as u64, bin_len);
    if total > u64::from(u32::MAX) {
        return Err(Error::InvalidArgument(format!(
            "the mesh needs a {total}-byte GLB, above the format's 4 GiB limit"
        )));
    }
    Ok(GlbPlan { json, bin_len })
}

fn glb_total_len(json_len: u64, bin_len: u64) -> u64 {
    let bin = if bin_len > 0 { GLB_CHUNK_HEADER_LEN + bin_len.next_multiple_of(4) } else { 0 };
    GLB_HEADER_LEN + GLB_CHUNK_HEADER_LEN + json_len + bin
}

fn position_bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    (min, max)
}

fn emit_glb<W: Write>(mesh: &Mesh, plan: &GlbPlan, w: &mut W) -> io::Result<()> {
    // Both fit in u32: plan_glb checked the total.
    let total = glb_total_len(plan.json.len() as u64, plan.bin_len) as u32;
    w.write_all(GLB_MAGIC)?;
    put_u32(w, GLB_VERSION)?;
    put_u32(w, total)?;
    put_u32(w, plan.json.len() as u32)?;
    w.write_all(GLB_CHUNK_JSON)?;
    w.write_all(&plan.json)?;
    if plan.bin_len == 0 {
        return Ok(());
    }
    let padded = plan.bin_len.next_multiple_of(4);
    put_u32(w, padded as u32)?;
    w.write_all(GLB_CHUNK_BIN)?;
    for p in &mesh.positions {
        put_f32s(w, p)?;
    }
    for n in &mesh.normals {
        put_f32s(w, n)?;
    }
    for uv in &mesh.uvs {
        put_f32s(w, uv)?;
    }
    for &p in &mesh.vertex_patch {
        // Exact: plan_glb bounded the ids by 2^24.
        put_f32s(w, &[p as f32])?;
    }
    for &i in &mesh.indices {
        put_u32(w, i)?;
    }
    for &p in &mesh.triangle_patch {
        put_u32(w, p)?;
    }
    if let Some(params) = &mesh.corner_params {
        for uv in params {
            put_f32s(w, uv)?;
        }
    }
    // The BIN chunk is padded with zeros; with the current layout the padding is empty.
    w.write_all(&[0u8; 3][..(padded - plan.bin_len) as usize])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

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

    fn to_vec(f: impl FnOnce(&mut Vec<u8>) -> Result<()>) -> Vec<u8> {
        let mut out = Vec::new();
        f(&mut out).expect("writing to memory succeeds");
        out
    }

    #[test]
    fn obj_lines_match_the_mesh() {
        let mesh = grid(4, false);
        let text = String::from_utf8(to_vec(|w| write_obj(&mesh, w))).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("# tessera"));
        let (mut v, mut vn, mut vt, mut f, mut groups) = (vec![], vec![], vec![], vec![], vec![]);
        let mut group = None;
        for line in lines {
            let mut tokens = line.split_whitespace();
            let floats =
                |t: std::str::SplitWhitespace| t.map(|x| x.parse::<f32>().unwrap()).collect::<Vec<_>>();
            match tokens.next() {
                Some("#") => {}
                Some("v") => v.push(floats(tokens)),
                Some("vn") => vn.push(floats(tokens)),
                Some("vt") => vt.push(floats(tokens)),
                Some("g") => {
                    let name = tokens.next().unwrap();
                    group = Some(name.strip_prefix("patch_").unwrap().parse::<u32>().unwrap());
                    groups.push(group.unwrap());
                }
                Some("f") => {
                    let corners: Vec<u32> = tokens
                        .map(|c| {
                            let parts: Vec<u32> = c.split('/').map(|x| x.parse().unwrap()).collect();
                            assert_eq!(parts.len(), 3);
                            assert!(parts.iter().all(|&p| p == parts[0]), "v/vt/vn agree: {c}");
                            parts[0]
                        })
                        .collect();
                    assert_eq!(corners.len(), 3);
                    f.push((corners, group.expect("a g line precedes the first face")));
                }
                other => panic!("unexpected line {other:?}"),
            }
        }
        let as_vecs = |a: &[[f32; 3]]| a.iter().map(|p| p.to_vec()).collect::<Vec<_>>();
        assert_eq!(v, as_vecs(&mesh.positions), "floats read back exactly");
        assert_eq!(vn, as_vecs(&mesh.normals));
        assert_eq!(vt, mesh.uvs.iter().map(|p| p.to_vec()).collect::<Vec<_>>());
        assert_eq!(f.len(), mesh.triangle_count());
        for (t, (corners, patch)) in f.iter().enumerate() {
            let expected: Vec<u32> = mesh.triangle(t).iter().map(|i| i + 1).collect();
            assert_eq!(corners, &expected);
            assert_eq!(*patch, mesh.triangle_patch[t]);
        }
        // One g line per run: the patch alternates 3,7 on each of the 4 rows.
        assert_eq!(groups, [3, 7, 3, 7, 3, 7, 3, 7]);
    }

    #[test]
    fn ply_header_and_size() {
        for with_params in [false, true] {
            let mesh = grid(3, with_params);
            let bytes = to_vec(|w| write_ply(&mesh, w));
            let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
            let header = std::str::from_utf8(&bytes[..end]).unwrap();
            assert!(header.starts_with("ply\nformat binary_little_endian 1.0\ncomment tessera\n"));
            assert!(header.contains("element vertex 16\n"));
            assert!(header.contains("element face 18\n"));
            assert!(header.contains("property list uchar uint vertex_indices\nproperty uint patch\n"));
            assert_eq!(header.contains("property list uchar float texcoord\n"), with_params);
            let face = 1 + 12 + 4 + if with_params { 1 + 24 } else { 0 };
            assert_eq!(bytes.len() - end, 16 * 36 + 18 * face);
        }
    }

    #[test]
    fn stl_layout_and_normals() {
        let mut mesh = grid(2, false);
        // Make the last triangle degenerate: its normal must be zero, not NaN.
        let last = mesh.triangle(mesh.triangle_count() - 1);
        mesh.indices.truncate(mesh.indices.len() - 3);
        mesh.indices.extend([last[0], last[0], last[1]]);
        let bytes = to_vec(|w| write_stl(&mesh, w));
        let t = mesh.triangle_count();
        assert_eq!(bytes.len(), 84 + 50 * t);
        assert!(bytes.starts_with(b"tessera"));
        assert_eq!(u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize, t);
        for (k, rec) in bytes[84..].chunks_exact(50).enumerate() {
            let f = |i: usize| f32::from_le_bytes(rec[4 * i..4 * i + 4].try_into().unwrap());
            let n = glam::Vec3::new(f(0), f(1), f(2));
            let corner = |c: usize| glam::Vec3::new(f(3 + 3 * c), f(4 + 3 * c), f(5 + 3 * c));
            let tri = mesh.triangle(k);
            for (c, &i) in tri.iter().enumerate() {
                assert_eq!(corner(c).to_array(), mesh.positions[i as usize]);
            }
            assert_eq!(&rec[48..], &[0, 0]);
            if k == t - 1 {
                assert_eq!(n, glam::Vec3::ZERO);
            } else {
                assert!((n.length() - 1.0).abs() < 1e-6);
                let geometric = (corner(1) - corner(0)).cross(corner(2) - corner(0)).normalize();
                assert!(n.dot(geometric) > 0.9999, "normal follows the counter-clockwise order");
            }
        }
    }

    /// Splits a GLB into its JSON and BIN chunks, checking the container on the way.
    pub(crate) fn glb_chunks(bytes: &[u8]) -> (&[u8], &[u8]) {
        let word = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
        assert_eq!(&bytes[..4], b"glTF");
        assert_eq!(word(4), 2);
        assert_eq!(word(8), bytes.len());
        let json_len = word(12);
        assert_eq!(&bytes[16..20], b"JSON");
        assert_eq!(json_len % 4, 0);
        let json = &bytes[20..20 + json_len];
        let rest = &bytes[20 + json_len..];
        if rest.is_empty() {
            return (json, &[]);
        }
        let bin_len = word(20 + json_len);
        assert_eq!(bin_len % 4, 0);
        assert_eq!(&rest[4..8], b"BIN\0");
        assert_eq!(rest.len(), 8 + bin_len);
        (json, &rest[8..])
    }

    #[test]
    fn glb_json_is_valid_gltf_with_exact_accessors() {
        let mesh = grid(5, true);
        let bytes = to_vec(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&bytes);
        assert!(std::str::from_utf8(json).unwrap().ends_with(['}', ' ']));
        let root = gj::Root::from_slice(json).unwrap();
        let mut problems = Vec::new();
        gj::validation::Validate::validate(&root, &root, gj::Path::new, &mut |path, error| {
            problems.push(format!("{}: {error:?}", path()))
        });
        assert!(problems.is_empty(), "{problems:?}");
        assert_eq!(root.buffers.len(), 1);
        assert_eq!(root.buffers[0].byte_length.0 as usize, bin.len());
        assert!(root.buffers[0].uri.is_none());
        assert_eq!((root.meshes.len(), root.nodes.len(), root.scenes.len()), (1, 1, 1));
        let primitive = &root.meshes[0].primitives[0];
        let attr = |name: &str| {
            let (_, index) = primitive.attributes.iter().find(|(s, _)| s.to_string() == name).unwrap();
            &root.accessors[index.value()]
        };
        let n = mesh.vertex_count() as u64;
        for (name, ty) in
            [("POSITION", "VEC3"), ("NORMAL", "VEC3"), ("TEXCOORD_0", "VEC2"), ("_PATCH", "SCALAR")]
        {
            let a = attr(name);
            assert_eq!(a.count.0, n, "{name}");
            assert_eq!(serde_json::to_value(a.type_).unwrap(), ty);
            assert_eq!(serde_json::to_value(a.component_type).unwrap(), gj::accessor::FLOAT);
        }
        let (lo, hi) = position_bounds(&mesh.positions);
        let bound = |v: &Option<serde_json::Value>| -> Vec<f32> {
            v.as_ref().unwrap().as_array().unwrap().iter().map(|x| x.as_f64().unwrap() as f32).collect()
        };
        assert_eq!(bound(&attr("POSITION").min), lo);
        assert_eq!(bound(&attr("POSITION").max), hi);
        assert_eq!(lo, [0.0, 0.0, lo[2]]);
        assert_eq!(hi[..2], [1.0, 1.0]);
        let indices = &root.accessors[primitive.indices.unwrap().value()];
        assert_eq!(indices.count.0 as usize, mesh.indices.len());
        assert_eq!(serde_json::to_value(indices.component_type).unwrap(), gj::accessor::UNSIGNED_INT);
        // The index data is where its view says.
        let view = &root.buffer_views[indices.buffer_view.unwrap().value()];
        let start = view.byte_offset.unwrap().0 as usize;
        let read: Vec<u32> = bin[start..start + view.byte_length.0 as usize]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(read, mesh.indices);
        let extras: serde_json::Value =
            serde_json::from_str(primitive.extras.as_ref().unwrap().get()).unwrap();
        assert!(extras["tessera"]["trianglePatchView"].is_u64());
        assert!(extras["tessera"]["cornerParamsView"].is_u64());
        assert!(json.windows(8).any(|w| w == b"\"_PATCH\""));
    }

    #[test]
    fn glb_of_an_empty_mesh_holds_only_the_asset() {
        let bytes = to_vec(|w| write_glb(&Mesh::default(), w));
        let (json, bin) = glb_chunks(&bytes);
        assert!(bin.is_empty());
        let root = gj::Root::from_slice(json).unwrap();
        assert!(root.meshes.is_empty() && root.buffers.is_empty() && root.accessors.is_empty());
        assert!(root.scenes.is_empty());
    }

    #[test]
    fn glb_refuses_patch_ids_a_float_cannot_hold() {
        let mut mesh = grid(1, false);
        mesh.vertex_patch[2] = (1 << 24) + 1;
        let err = write_glb(&mesh, Vec::new()).unwrap_err();
        assert!(matches!(&err, Error::InvalidArgument(m) if m.contains("vertex 2")), "{err}");
        mesh.vertex_patch[2] = 1 << 24;
        write_glb(&mesh, Vec::new()).unwrap();
    }

    #[test]
    fn inconsistent_meshes_are_refused_before_writing() {
        let good = grid(2, true);
        type Breaker = fn(&mut Mesh);
        let cases: [(Breaker, &str); 11] = [
            (|m| m.normals.truncate(1), "normals"),
            (|m| m.uvs.truncate(1), "uvs"),
            (|m| m.vertex_patch.truncate(1), "vertex patches"),
            (|m| m.indices.truncate(4), "multiple of 3"),
            (|m| m.triangle_patch.truncate(1), "triangle patches"),
            (|m| m.corner_params.iter_mut().for_each(|p| p.truncate(1)), "corner params"),
            (|m| m.indices[4] = 9, "triangle 1 refers to vertex 9"),
            (|m| m.positions[5][1] = f32::NAN, "vertex 5 has a non-finite position"),
            (|m| m.normals[1][0] = f32::INFINITY, "non-finite normal"),
            (|m| m.uvs[0][1] = f32::NAN, "non-finite uv"),
            (|m| m.corner_params.iter_mut().for_each(|p| p[7][0] = f32::NAN), "corner 1 of triangle 2"),
        ];
        for (break_it, expected) in cases {
            let mut mesh = good.clone();
            break_it(&mut mesh);
            for format in [Format::Obj, Format::Ply, Format::Stl, Format::Glb] {
                let mut out = Vec::new();
                match write_to(&mesh, format, &mut out) {
                    Err(Error::InvalidArgument(m)) => assert!(m.contains(expected), "{m} lacks {expected}"),
                    other => panic!("expected InvalidArgument({expected}), got {other:?}"),
                }
                assert!(out.is_empty(), "nothing is written for an invalid mesh");
            }
        }
    }

    struct Failing;
    impl Write for Failing {
        fn write(&mut self, _: &[u8]) -> io::Result<usize> {
            Err(io::Error::other("disk on fire"))
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn writer_errors_are_typed() {
        let mesh = grid(1, false);
        let err = write_ply(&mesh, Failing).unwrap_err();
        assert!(matches!(&err, Error::Write { path, .. } if path == Path::new("<writer>")), "{err}");
        assert!(err.to_string().contains("disk on fire"));
    }

    #[test]
    fn write_mesh_picks_the_format_by_extension() {
        let dir = std::env::temp_dir().join(format!("tessera-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = grid(2, true);
        for (name, expected) in [
            ("a.obj", to_vec(|w| write_obj(&mesh, w))),
            ("b.PLY", to_vec(|w| write_ply(&mesh, w))),
            ("c.Stl", to_vec(|w| write_stl(&mesh, w))),
            ("d.glb", to_vec(|w| write_glb(&mesh, w))),
        ] {
            let path = dir.join(name);
            write_mesh(&mesh, &path).unwrap();
            assert_eq!(std::fs::read(&path).unwrap(), expected, "{name}");
        }
        for name in ["e.gltf", "noext"] {
            let path = dir.join(name);
            let err = write_mesh(&mesh, &path).unwrap_err();
            let Error::InvalidArgument(m) = &err else { panic!("{err:?}") };
            assert!(m.contains(".obj, .ply, .stl, .glb"), "{m}");
            assert!(m.contains(name), "{m}");
            assert!(!path.exists());
        }
        let missing = dir.join("no/such/dir/f.obj");
        let err = write_mesh(&mesh, &missing).unwrap_err();
        assert!(matches!(&err, Error::Write { path, .. } if path == &missing), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
