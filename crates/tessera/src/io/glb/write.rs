//! The GLB writer: the JSON and the layout planned first (the header carries the total
//! length), then the mesh's arrays written as they are.

use std::io::{self, Write};

use gltf_json as gj;
use gltf_json::validation::{Checked, USize64};

use crate::error::{Error, Result};
use crate::io::binary::{put_u32, put_words, write_chunks, BIN_CHUNK};
use crate::io::Format;
use crate::mesh::Mesh;

use super::*;

/// Writes `mesh` as glTF 2.0 binary (GLB) to `w`: one buffer, one mesh with one indexed
/// triangle primitive (`POSITION` with min/max, `NORMAL`, the vertex's patch parameters
/// `_PATCH_UV`, the float vertex patch id `_PATCH`, `u32` indices), one node and one scene.
/// Triangle patches and corner params go to byte ranges of the buffer named in the
/// primitive's extras (see [`io::glb`](super)). A mesh
/// without triangles is written as a file holding only the asset, since glTF forbids empty
/// accessors; any vertices are dropped.
///
/// Preconditions: as [`write_mesh`](crate::io::write_mesh), vertex patch ids at most 2^24 (exact in the float
/// `_PATCH`), and a file under 4 GiB; otherwise [`Error::InvalidMesh`] or [`Error::FormatLimit`]. I/O errors are
/// [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time; the JSON is built in memory (a few KiB, independent of
/// the mesh size); the mesh's arrays are written as they are in memory (one `write` each on a
/// little-endian machine), the float patch ids converted in parallel chunks.
pub fn write_glb<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    crate::io::write_to(mesh, Format::Glb, w)
}

// GLB

/// The GLB's JSON chunk (already padded) and binary chunk length, fixed before writing because
/// the header carries the total length.
pub(in crate::io) struct GlbPlan {
    json: Vec<u8>,
    bin_len: u64,
}

/// One buffer view's place in the binary chunk.
struct Span {
    offset: u64,
    len: u64,
}

pub(in crate::io) fn plan_glb(mesh: &Mesh) -> Result<GlbPlan> {
    let n = mesh.vertex_count() as u64;
    let t = mesh.triangle_count() as u64;
    let mut root = gj::Root {
        asset: gj::Asset { generator: Some("tessera".to_string()), ..Default::default() },
        ..Default::default()
    };
    let mut bin_len = 0u64;
    if t > 0 {
        if let Some(i) = mesh.vertex_patch.iter().position(|&p| p > MAX_EXACT_F32_INT) {
            return Err(Error::FormatLimit {
                format: "glTF",
                reason: format!(
                    "vertex {i} has patch id {}, above 2^24, the largest a float glTF attribute \
                     holds exactly",
                    mesh.vertex_patch[i]
                ),
            });
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

        // Byte ranges of the buffer, not buffer views: a view no accessor uses is an unused
        // object to the glTF validator (see `io::glb`'s documentation).
        let range = |s: &Span| serde_json::json!({ "byteOffset": s.offset, "byteLength": s.len });
        let mut extras = serde_json::Map::new();
        extras.insert("trianglePatch".into(), range(&triangle_patch));
        if let Some(s) = &corner_params {
            extras.insert("cornerParams".into(), range(s));
        }
        let mut wrapper = serde_json::Map::new();
        wrapper.insert("tessera".into(), extras.into());
        let extras = serde_json::value::to_raw_value(&wrapper).map_err(|e| Error::FormatLimit {
            format: "glTF",
            reason: format!("cannot encode the extras: {e}"),
        })?;

        use gj::mesh::Semantic;
        let attributes = [
            (Semantic::Positions, a_positions),
            (Semantic::Normals, a_normals),
            // "_PATCH_UV": patch parameters, not texture coordinates (`io::glb`'s documentation).
            (Semantic::Extras("PATCH_UV".to_string()), a_uvs),
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

    let mut json = root
        .to_vec()
        .map_err(|e| Error::FormatLimit { format: "glTF", reason: format!("cannot encode the JSON: {e}") })?;
    // The GLB spec pads the JSON chunk with spaces so that it stays valid JSON.
    json.resize(json.len().next_multiple_of(4), b' ');
    let total = glb_total_len(json.len() as u64, bin_len);
    if total > u64::from(u32::MAX) {
        return Err(Error::FormatLimit {
            format: "GLB",
            reason: format!("the mesh needs a {total}-byte GLB, above the format's 4 GiB limit"),
        });
    }
    Ok(GlbPlan { json, bin_len })
}

fn glb_total_len(json_len: u64, bin_len: u64) -> u64 {
    let bin = if bin_len > 0 { GLB_CHUNK_HEADER_LEN + bin_len.next_multiple_of(4) } else { 0 };
    GLB_HEADER_LEN + GLB_CHUNK_HEADER_LEN + json_len + bin
}

pub(super) fn position_bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
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

pub(in crate::io) fn emit_glb<W: Write>(mesh: &Mesh, plan: &GlbPlan, w: &mut W) -> io::Result<()> {
    // Both fit in u32: plan_glb checked the total.
    let total = glb_total_len(plan.json.len() as u64, plan.bin_len) as u32;
    w.write_all(GLB_MAGIC)?;
    put_u32(w, GLB_VERSION)?;
    put_u32(w, total)?;
    put_u32(w, plan.json.len() as u32)?;
    w.write_all(&GLB_CHUNK_JSON.to_le_bytes())?;
    w.write_all(&plan.json)?;
    if plan.bin_len == 0 {
        return Ok(());
    }
    let padded = plan.bin_len.next_multiple_of(4);
    put_u32(w, padded as u32)?;
    w.write_all(&GLB_CHUNK_BIN.to_le_bytes())?;
    // Every section but the float patch ids is one of the mesh's arrays as it is in memory:
    // written straight from it, without a copy on a little-endian machine.
    put_words(w, &mesh.positions)?;
    put_words(w, &mesh.normals)?;
    put_words(w, &mesh.uvs)?;
    write_chunks(w, mesh.vertex_patch.len(), BIN_CHUNK, |range, out| {
        // Exact: plan_glb bounded the ids by 2^24.
        out.extend(mesh.vertex_patch[range].iter().flat_map(|&p| (p as f32).to_le_bytes()));
    })?;
    put_words(w, &mesh.indices)?;
    put_words(w, &mesh.triangle_patch)?;
    if let Some(params) = &mesh.corner_params {
        put_words(w, params)?;
    }
    // The BIN chunk is padded with zeros; with the current layout the padding is empty.
    w.write_all(&[0u8; 3][..(padded - plan.bin_len) as usize])
}
