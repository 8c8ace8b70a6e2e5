//! glTF 2.0 binary (GLB): tessera's own mesh files, read and written.
//!
//! **Writing** ([`write_glb`]): one buffer, one mesh with one indexed triangle primitive, one
//! node and one scene, so that the Khronos glTF validator reports no error, no warning and no
//! unused object. Attributes: `POSITION` (with the min/max glTF requires), `NORMAL`, and the
//! application-specific `_PATCH_UV` (the vertex's patch parameters, two floats) and `_PATCH`
//! (its patch id as a float); indices are `u32`. The patch parameters are not `TEXCOORD_0`:
//! they are no texture coordinates, and without a material using them the validator reports
//! them unused.
//!
//! Triangle patches and corner params have no glTF accessor (glTF forbids `UNSIGNED_INT`
//! accessors outside `primitive.indices`, a float accessor would round patch ids above 2^24,
//! and glTF has no per-triangle attributes). They are byte ranges of buffer 0 named in the
//! primitive's `extras`: `{"tessera": {"trianglePatch": {"byteOffset": o, "byteLength": l},
//! "cornerParams": {...}}}` (the second key only when [`Mesh::corner_params`] is set). The
//! first holds one little-endian `u32` per triangle, the second two little-endian `f32` (u, v)
//! per triangle corner, in index order. They are not buffer views because a buffer view no
//! accessor uses is an unused object to the validator.
//!
//! **Reading** ([`parse_glb`]) takes the layout above and the one tessera wrote before
//! (`TEXCOORD_0` for the vertex parameters, `trianglePatchView`/`cornerParamsView` naming
//! buffer views): one mesh with one triangle primitive, `POSITION`, optional `NORMAL`, vertex
//! parameters and `_PATCH`, `u8`/`u16`/`u32` indices (or none), and tessera's triangle patches
//! and corner params. A file without meshes gives an empty mesh. It is written by hand rather than with the `gltf` crate because it reads
//! tessera's own data (the `_PATCH` attributes and the ranges in `extras`), and because it
//! checks every count and offset before use: the `gltf` crate's accessor iterators compute
//! `stride * (count - 1)` unchecked (a count of 0 underflows) and trust the component type,
//! which a fuzzed or lying file breaks. Outside glTF files (`.gltf` or `.glb`, any number of
//! meshes and nodes) are read as PN-triangle input by [`read_gltf_triangles`], which does use
//! the `gltf` crate, after the same checks.

use std::io::{self, Read, Write};
use std::path::Path;

use gltf::accessor::{DataType, Dimensions};
use gltf_json as gj;
use gltf_json::accessor::{ComponentType, Type};
use gltf_json::validation::{Checked, USize64};

use super::binary::{all_finite, fill_missing, put_u32, put_words, to_u32, write_chunks, BIN_CHUNK};
use super::Format;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::{PolygonFace, PolygonMesh};

/// Largest integer an `f32` holds exactly (and with it every smaller one): the bound on vertex
/// patch ids in the GLB `_PATCH` attribute, which glTF requires to be a float.
const MAX_EXACT_F32_INT: u32 = 1 << 24;

const GLB_VERSION: u32 = 2;
const GLB_HEADER_LEN: u64 = 12;
const GLB_CHUNK_HEADER_LEN: u64 = 8;

const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_CHUNK_JSON: u32 = u32::from_le_bytes(*b"JSON");
const GLB_CHUNK_BIN: u32 = u32::from_le_bytes(*b"BIN\0");

/// Parses glTF binary `data`; `file` only labels errors. Reads the layout `write_glb`
/// produces, and the one it wrote before (see the module documentation); whatever the file
/// lacks is filled in as [`read_mesh`](super::read_mesh) says.
///
/// Preconditions: none; any bytes give a mesh or an error. Errors carry line 0 and, for the
/// binary container, the byte offset; JSON errors carry serde's line and column in the JSON
/// chunk.
///
/// Cost: O(`data.len()`) time; memory proportional to the accessors actually present.
pub fn parse_glb(data: &[u8], file: &Path) -> Result<Mesh> {
    let err = |reason: String| Error::parse(file, 0, reason);
    let u32_at =
        |offset: usize| data.get(offset..offset + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    if data.len() < 12 {
        return Err(err(format!("file is {} bytes, shorter than the 12-byte GLB header", data.len())));
    }
    if &data[..4] != GLB_MAGIC {
        return Err(err("not a GLB file (magic is not \"glTF\")".into()));
    }
    let version = u32_at(4).unwrap_or(0);
    if version != 2 {
        return Err(Error::unsupported(file, 0, format!("GLB version {version}; only 2 is read")));
    }
    let total = u32_at(8).unwrap_or(0) as usize;
    if total != data.len() {
        return Err(err(format!(
            "GLB header at byte offset 8 gives a length of {total} bytes, but the file has {}",
            data.len()
        )));
    }
    let mut json = None;
    let mut bin = None;
    let mut offset = 12;
    while offset < data.len() {
        let (Some(len), Some(kind)) = (u32_at(offset), u32_at(offset + 4)) else {
            return Err(err(format!("truncated chunk header at byte offset {offset}")));
        };
        let start = offset + 8;
        let Some(chunk) = data.get(start..start.saturating_add(len as usize)) else {
            return Err(err(format!(
                "chunk at byte offset {offset} claims {len} bytes, past the end of the file"
            )));
        };
        match kind {
            GLB_CHUNK_JSON if json.is_none() && offset == 12 => json = Some(chunk),
            GLB_CHUNK_JSON => return Err(err(format!("unexpected JSON chunk at byte offset {offset}"))),
            GLB_CHUNK_BIN if bin.is_none() => bin = Some((chunk, start)),
            GLB_CHUNK_BIN => return Err(err(format!("second BIN chunk at byte offset {offset}"))),
            // The spec tells readers to skip chunks of unknown types.
            _ => {}
        }
        offset = start + chunk.len();
    }
    let Some(json) = json else {
        return Err(err("GLB file has no JSON chunk at byte offset 12".into()));
    };
    let root = gj::Root::from_slice(json)
        .map_err(|e| err(format!("invalid glTF JSON in the chunk at byte offset 20: {e}")))?;
    let glb = Glb { root: &root, bin, file };
    glb.mesh()
}

/// A parsed GLB: its JSON and its binary chunk (with the chunk's offset in the file).
struct Glb<'a> {
    root: &'a gj::Root,
    bin: Option<(&'a [u8], usize)>,
    file: &'a Path,
}

/// An accessor's elements located in the binary chunk, bounds already checked.
struct Elements<'a> {
    bytes: &'a [u8],
    stride: usize,
    count: usize,
    component: ComponentType,
    components: usize,
}

impl Elements<'_> {
    /// Component `c` of element `i`, widened to f64 (exact for every glTF component type).
    fn get(&self, i: usize, c: usize) -> f64 {
        let at = i * self.stride + c * self.component.size();
        let b = &self.bytes[at..at + self.component.size()];
        match self.component {
            ComponentType::I8 => f64::from(b[0] as i8),
            ComponentType::U8 => f64::from(b[0]),
            ComponentType::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            ComponentType::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            ComponentType::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            ComponentType::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        }
    }
}

impl<'a> Glb<'a> {
    fn err(&self, reason: String) -> Error {
        Error::parse(self.file, 0, reason)
    }

    fn unsupported(&self, reason: String) -> Error {
        Error::unsupported(self.file, 0, reason)
    }

    fn mesh(&self) -> Result<Mesh> {
        let root = self.root;
        let Some(gltf_mesh) = root.meshes.first() else {
            return Ok(Mesh::default());
        };
        if root.meshes.len() > 1 || gltf_mesh.primitives.len() != 1 {
            return Err(self.unsupported(format!(
                "{} meshes with {} primitives in the first; tessera reads one mesh with one \
                 primitive",
                root.meshes.len(),
                gltf_mesh.primitives.len()
            )));
        }
        let primitive = &gltf_mesh.primitives[0];
        if primitive.mode != Checked::Valid(gj::mesh::Mode::Triangles) {
            return Err(self.unsupported("primitive mode is not TRIANGLES".into()));
        }
        let attribute =
            |semantic: gj::mesh::Semantic| primitive.attributes.get(&Checked::Valid(semantic)).copied();
        use gj::mesh::Semantic;
        let Some(position_index) = attribute(Semantic::Positions) else {
            return Err(self.err("primitive has no POSITION attribute".into()));
        };
        let positions = self.floats::<3>(position_index, "POSITION", Type::Vec3)?;
        let n = positions.len();
        let mut mesh = Mesh { positions, ..Default::default() };
        if let Some(index) = attribute(Semantic::Normals) {
            mesh.normals = self.floats::<3>(index, "NORMAL", Type::Vec3)?;
            self.check_count("NORMAL", mesh.normals.len(), n)?;
        }
        // `_PATCH_UV` since tessera stopped writing the parameters as TEXCOORD_0, which files
        // written before still have.
        let uv = match attribute(Semantic::Extras("PATCH_UV".to_string())) {
            Some(index) => Some((index, "_PATCH_UV")),
            None => attribute(Semantic::TexCoords(0)).map(|index| (index, "TEXCOORD_0")),
        };
        if let Some((index, name)) = uv {
            mesh.uvs = self.floats::<2>(index, name, Type::Vec2)?;
            self.check_count(name, mesh.uvs.len(), n)?;
        }
        if let Some(index) = attribute(Semantic::Extras("PATCH".to_string())) {
            let e = self.elements(index, "_PATCH", Type::Scalar)?;
            self.check_count("_PATCH", e.count, n)?;
            mesh.vertex_patch = (0..e.count)
                .map(|i| {
                    let v = e.get(i, 0);
                    to_u32(v).ok_or_else(|| self.err(format!("_PATCH of vertex {i} is {v}")))
                })
                .collect::<Result<_>>()?;
        }
        mesh.indices = match primitive.indices {
            Some(index) => {
                let e = self.elements(index, "indices", Type::Scalar)?;
                if e.component == ComponentType::F32
                    || e.component == ComponentType::I8
                    || e.component == ComponentType::I16
                {
                    return Err(self.err(format!(
                        "indices have component type {:?}; glTF allows u8, u16 and u32",
                        e.component
                    )));
                }
                (0..e.count)
                    .map(|i| {
                        let v = e.get(i, 0) as u64;
                        if v < n as u64 {
                            Ok(v as u32)
                        } else {
                            Err(self.err(format!("index {i} is {v}, but there are {n} vertices")))
                        }
                    })
                    .collect::<Result<_>>()?
            }
            // Non-indexed: every three consecutive vertices form a triangle.
            None => (0..n as u64).map(|i| i as u32).collect(),
        };
        if mesh.indices.len() % 3 != 0 {
            return Err(self.err(format!("{} indices do not form whole triangles", mesh.indices.len())));
        }
        self.read_extras(primitive, &mut mesh)?;
        fill_missing(&mut mesh);
        Ok(mesh)
    }

    fn check_count(&self, what: &str, count: usize, vertices: usize) -> Result<()> {
        if count == vertices {
            return Ok(());
        }
        Err(self.err(format!("{what} has {count} elements for {vertices} vertices")))
    }

    /// Reads tessera's triangle patches and corner params from the byte ranges the primitive's
    /// extras name (`trianglePatch`, `cornerParams`), or from the buffer views files written
    /// before named (`trianglePatchView`, `cornerParamsView`).
    fn read_extras(&self, primitive: &gj::mesh::Primitive, mesh: &mut Mesh) -> Result<()> {
        let Some(raw) = &primitive.extras else {
            return Ok(());
        };
        let Ok(value) = serde_json::from_str::<serde_json::Value>(raw.get()) else {
            return Ok(());
        };
        let Some(tessera) = value.get("tessera") else {
            return Ok(());
        };
        let bytes_of = |key: &str, old_key: &str| -> Result<Option<&'a [u8]>> {
            if let Some(range) = tessera.get(key) {
                let field = |name: &str| {
                    range.get(name).and_then(serde_json::Value::as_u64).ok_or_else(|| {
                        self.err(format!("extras.tessera.{key}.{name} is missing or not a byte count"))
                    })
                };
                let (offset, len) = (field("byteOffset")?, field("byteLength")?);
                return self.buffer_bytes(0, offset, len, &format!("extras.tessera.{key}")).map(Some);
            }
            match tessera.get(old_key) {
                None => Ok(None),
                Some(v) => match v.as_u64().and_then(|v| usize::try_from(v).ok()) {
                    Some(view) => self.view_bytes(view, old_key).map(Some),
                    None => {
                        Err(self.err(format!("extras.tessera.{old_key} is {v}, not a buffer view index")))
                    }
                },
            }
        };
        let t = mesh.indices.len() / 3;
        if let Some(bytes) = bytes_of("trianglePatch", "trianglePatchView")? {
            if bytes.len() != 4 * t {
                return Err(
                    self.err(format!("the triangle patches have {} bytes for {t} triangles", bytes.len()))
                );
            }
            mesh.triangle_patch =
                bytes.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        }
        if let Some(bytes) = bytes_of("cornerParams", "cornerParamsView")? {
            if bytes.len() != 24 * t {
                return Err(
                    self.err(format!("the corner params have {} bytes for {t} triangles", bytes.len()))
                );
            }
            let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            let params: Vec<[f32; 2]> = bytes.chunks_exact(8).map(|b| [f(&b[..4]), f(&b[4..])]).collect();
            if let Some(k) = params.iter().position(|p| !all_finite(p)) {
                return Err(self.err(format!("corner param {k} is not finite")));
            }
            mesh.corner_params = Some(params);
        }
        Ok(())
    }

    /// The bytes of buffer view `index`, checked to lie in the BIN chunk.
    fn view_bytes(&self, index: usize, what: &str) -> Result<&'a [u8]> {
        let Some(view) = self.root.buffer_views.get(index) else {
            return Err(self.err(format!(
                "{what} refers to buffer view {index}, but there are {}",
                self.root.buffer_views.len()
            )));
        };
        let start = view.byte_offset.map_or(0, |o| o.0);
        self.buffer_bytes(view.buffer.value(), start, view.byte_length.0, &format!("buffer view {index}"))
    }

    /// Bytes `start..start + len` of buffer `buffer_index`, checked to lie in the buffer and
    /// the buffer in the BIN chunk; `what` names the range in errors.
    fn buffer_bytes(&self, buffer_index: usize, start: u64, len: u64, what: &str) -> Result<&'a [u8]> {
        let Some(buffer) = self.root.buffers.get(buffer_index) else {
            return Err(self.err(format!("{what} refers to missing buffer {buffer_index}")));
        };
        if buffer_index != 0 || buffer.uri.is_some() {
            return Err(
                self.unsupported(format!("{what} uses an external buffer; only the GLB's own is read"))
            );
        }
        let Some((bin, bin_offset)) = self.bin else {
            return Err(self.err(format!("{what} needs a BIN chunk, but there is none")));
        };
        let end = start.checked_add(len);
        if buffer.byte_length.0 > bin.len() as u64 || end.is_none_or(|e| e > buffer.byte_length.0) {
            return Err(self.err(format!(
                "{what} spans bytes {start}..{} of a {}-byte buffer (BIN chunk of {} bytes at byte \
                 offset {bin_offset})",
                start.saturating_add(len),
                buffer.byte_length.0,
                bin.len()
            )));
        }
        // Both bounds are within bin.len(), so they fit in usize.
        Ok(&bin[start as usize..(start + len) as usize])
    }

    /// Locates accessor `index` and checks it has type `ty` and lies inside its view.
    fn elements(&self, index: gj::Index<gj::Accessor>, what: &str, ty: Type) -> Result<Elements<'a>> {
        let Some(accessor) = self.root.get(index) else {
            return Err(self.err(format!(
                "{what} refers to accessor {}, but there are {}",
                index.value(),
                self.root.accessors.len()
            )));
        };
        if accessor.sparse.is_some() {
            return Err(self.unsupported(format!("{what} uses a sparse accessor")));
        }
        if accessor.normalized {
            return Err(self.unsupported(format!("{what} uses a normalized accessor")));
        }
        let Checked::Valid(gj::accessor::GenericComponentType(component)) = accessor.component_type else {
            return Err(self.err(format!("{what} has an invalid component type")));
        };
        if accessor.type_ != Checked::Valid(ty) {
            return Err(self.err(format!("{what} is not of type {ty:?}")));
        }
        let Some(view_index) = accessor.buffer_view else {
            return Err(self.unsupported(format!("{what} has no buffer view")));
        };
        let view_index = view_index.value();
        let bytes = self.view_bytes(view_index, what)?;
        let components = match ty {
            Type::Scalar => 1,
            Type::Vec2 => 2,
            Type::Vec3 => 3,
            _ => 4,
        };
        let element = (components * component.size()) as u64;
        let view = &self.root.buffer_views[view_index];
        let stride = view.byte_stride.map_or(element, |s| s.0 as u64);
        if stride < element {
            return Err(self.err(format!("{what}: byte stride {stride} below element size")));
        }
        let count = accessor.count.0;
        let offset = accessor.byte_offset.map_or(0, |o| o.0);
        // The last element needs only its own size, not a whole stride.
        let needed = match count {
            0 => Some(offset),
            _ => (count - 1)
                .checked_mul(stride)
                .and_then(|s| s.checked_add(element))
                .and_then(|s| s.checked_add(offset)),
        };
        if needed.is_none_or(|end| end > bytes.len() as u64) {
            return Err(self.err(format!(
                "{what}: {count} elements of {element} bytes from offset {offset} with stride \
                 {stride} do not fit in the {}-byte buffer view {view_index}",
                bytes.len()
            )));
        }
        Ok(Elements {
            bytes: &bytes[offset as usize..],
            stride: stride as usize,
            count: count as usize,
            component,
            components,
        })
    }

    /// Reads a float accessor of `N` components, refusing non-finite values.
    fn floats<const N: usize>(
        &self,
        index: gj::Index<gj::Accessor>,
        what: &str,
        ty: Type,
    ) -> Result<Vec<[f32; N]>> {
        let e = self.elements(index, what, ty)?;
        if e.component != ComponentType::F32 || e.components != N {
            return Err(self.unsupported(format!("{what} is not made of floats")));
        }
        let mut out = Vec::with_capacity(e.count);
        for i in 0..e.count {
            let v: [f32; N] = std::array::from_fn(|c| e.get(i, c) as f32);
            if !all_finite(&v) {
                return Err(self.err(format!("{what} element {i} is not finite: {v:?}")));
            }
            out.push(v);
        }
        Ok(out)
    }
}

// =============================================================================================
// Outside glTF files as PN-triangle input

/// Reads every triangle primitive of the glTF file at `path` (`.glb`, or `.gltf` with its
/// buffers in `.bin` files next to it or in base64 `data:` URIs) as one triangle mesh in world
/// coordinates, the input of PN triangles. Nodes of the default scene (else the first scene;
/// without scenes, every mesh untransformed) are instanced with their transforms; normals,
/// where a primitive has `NORMAL`, go through the inverse transpose, and mirroring transforms
/// reverse the winding so that the front side stays the front. Primitives in `POINTS` or
/// `LINES` modes are skipped and counted in [`PolygonMesh::skipped_primitives`]; every other attribute (texture coordinates, colours, tessera's
/// `_PATCH`) is ignored. Every face gets line 0 (binary data has no lines).
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read and [`Error::Referenced`] (naming both files)
/// when an external buffer cannot; [`Error::Unsupported`] for a buffer URI that `scope`
/// refuses (outside the model's folder, not a regular file, not local); [`Error::Parse`]
/// naming `path` and the reason for a buffer file shorter than its `byteLength` for invalid JSON or GLB, a glTF validation error, an accessor that
/// does not fit its buffer view, a position or normal that is not a finite `f32` `VEC3`, an
/// index out of range, an index count that is not a multiple of 3, or a node that appears
/// twice in the hierarchy; [`Error::Unsupported`] for sparse or normalized accessors, triangle
/// strips and fans, accessors without a buffer view, a singular node transform, a rotation
/// that is not a unit quaternion, a projective node matrix, a scene that
/// instances more than 2^27 vertices, and a file without any triangle.
///
/// Cost: reads the file and at most each buffer's `byteLength` of its buffer files into
/// memory, then O(file size + instanced triangles).
pub fn read_gltf_triangles(path: &Path, scope: UriScope) -> Result<PolygonMesh> {
    let data = super::read_input(path)?;
    parse_gltf_triangles(&data, path, path.parent(), scope)
}

/// Parses glTF `data` (GLB or JSON) as [`read_gltf_triangles`] does; `file` labels errors and
/// `dir`, when given, is where relative buffer URIs are resolved, under `scope` (without it,
/// only the GLB's own buffer and `data:` URIs can be read).
///
/// Preconditions: none; any bytes give a mesh or an error, never a panic: every accessor is
/// checked against its view and buffer (with overflow-checked arithmetic) before the `gltf`
/// crate's reader touches it, because that reader computes `stride * (count - 1)` unchecked
/// and assumes the component type.
///
/// Cost: O(`data.len()` + buffers + instanced triangles).
pub fn parse_gltf_triangles(
    data: &[u8],
    file: &Path,
    dir: Option<&Path>,
    scope: UriScope,
) -> Result<PolygonMesh> {
    let err = |reason: String| Error::parse(file, 0, reason);
    // The gltf crate subtracts the 12-byte header from the GLB's declared length unchecked
    // (an overflow panic with overflow checks on), so a shorter length is refused here.
    if data.starts_with(GLB_MAGIC) {
        let declared = data.get(8..12).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
        if declared.is_none_or(|len| len < GLB_HEADER_LEN as u32) {
            return Err(err(format!(
                "invalid glTF: GLB header of {} bytes declares less than its own 12",
                data.len().min(12)
            )));
        }
    }
    let unchecked =
        gltf::Gltf::from_slice_without_validation(data).map_err(|e| err(format!("invalid glTF: {e}")))?;
    // gltf-json's validation indexes `accessors` with a primitive's POSITION index before it
    // has checked that index (it panics on a file whose POSITION names a missing accessor;
    // found by fuzzing), so that one index is checked here first.
    let json = unchecked.document.as_json();
    for (m, mesh) in json.meshes.iter().enumerate() {
        for (k, primitive) in mesh.primitives.iter().enumerate() {
            let position =
                primitive.attributes.get(&gj::validation::Checked::Valid(gj::mesh::Semantic::Positions));
            if let Some(index) = position.filter(|i| i.value() >= json.accessors.len()) {
                return Err(err(format!(
                    "mesh {m} primitive {k}: POSITION refers to accessor {}, but there are {}",
                    index.value(),
                    json.accessors.len()
                )));
            }
        }
    }
    let blob = unchecked.blob;
    let gltf = gltf::Document::from_json(unchecked.document.into_json())
        .map_err(|e| err(format!("invalid glTF: {e}")))?;
    let mut buffers: Vec<Vec<u8>> = Vec::new();
    for buffer in gltf.buffers() {
        let bytes = match buffer.source() {
            gltf::buffer::Source::Bin => match &blob {
                Some(blob) => blob.clone(),
                None => {
                    return Err(err(format!(
                        "buffer {} refers to a GLB BIN chunk, but there is none",
                        buffer.index()
                    )))
                }
            },
            gltf::buffer::Source::Uri(uri) => {
                resolve_uri(uri, buffer.index(), buffer.length(), file, dir, scope)?
            }
        };
        if bytes.len() < buffer.length() {
            return Err(err(format!(
                "buffer {} declares {} bytes but its data has {}",
                buffer.index(),
                buffer.length(),
                bytes.len()
            )));
        }
        buffers.push(bytes);
    }

    // (mesh index, world matrix) pairs, from the scene hierarchy.
    let mut instances: Vec<(usize, glam::DMat4)> = Vec::new();
    let scene = gltf.default_scene().or_else(|| gltf.scenes().next());
    match scene {
        Some(scene) => {
            let mut visited = vec![false; gltf.nodes().len()];
            let mut stack: Vec<(gltf::Node, glam::DMat4)> =
                scene.nodes().map(|n| (n, glam::DMat4::IDENTITY)).collect();
            while let Some((node, parent)) = stack.pop() {
                if std::mem::replace(&mut visited[node.index()], true) {
                    return Err(err(format!("node {} appears twice in the scene hierarchy", node.index())));
                }
                check_node_transform(&node, file)?;
                let local = glam::Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
                let world = parent * local;
                if let Some(mesh) = node.mesh() {
                    instances.push((mesh.index(), world));
                }
                stack.extend(node.children().map(|c| (c, world)));
            }
        }
        None => instances.extend(gltf.meshes().map(|m| (m.index(), glam::DMat4::IDENTITY))),
    }

    let meshes: Vec<gltf::Mesh> = gltf.meshes().collect();
    let mut out = PolygonMesh::default();
    let mut skipped = std::collections::HashSet::new();
    for (mesh_index, world) in instances {
        let linear = glam::DMat3::from_mat4(world);
        let det = linear.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err(Error::unsupported(
                file,
                0,
                format!("a node of mesh {mesh_index} has a singular transform"),
            ));
        }
        let normal_matrix = linear.inverse().transpose();
        for primitive in meshes[mesh_index].primitives() {
            use gltf::mesh::Mode;
            let what = format!("mesh {mesh_index} primitive {}", primitive.index());
            match primitive.mode() {
                Mode::Triangles => {}
                Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => {
                    // Counted once however many nodes instance its mesh.
                    if skipped.insert((mesh_index, primitive.index())) {
                        out.skipped_primitives += 1;
                    }
                    continue;
                }
                other => {
                    return Err(Error::unsupported(
                        file,
                        0,
                        format!("{what} has mode {other:?}; only TRIANGLES are read"),
                    ))
                }
            }
            let Some(position) = primitive.get(&gltf::Semantic::Positions) else {
                return Err(err(format!("{what} has no POSITION attribute")));
            };
            let n = check_accessor(&position, &buffers, file, &format!("{what} POSITION"), &[FLOAT_VEC3])?;
            let normal = primitive.get(&gltf::Semantic::Normals);
            if let Some(a) = &normal {
                let count = check_accessor(a, &buffers, file, &format!("{what} NORMAL"), &[FLOAT_VEC3])?;
                if count != n {
                    return Err(err(format!("{what}: NORMAL has {count} elements for {n} vertices")));
                }
            }
            if let Some(a) = primitive.indices() {
                check_accessor(&a, &buffers, file, &format!("{what} indices"), &INDEX_TYPES)?;
            }
            let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
            let base = out.positions.len();
            // Instancing multiplies a small file's vertices by its node count, so the bound is
            // on the result, not on the file.
            if base + n > MAX_INSTANCED_VERTICES {
                return Err(Error::unsupported(
                    file,
                    0,
                    format!("the scene instances more than {MAX_INSTANCED_VERTICES} vertices"),
                ));
            }
            for (i, p) in reader.read_positions().into_iter().flatten().enumerate() {
                if !all_finite(&p) {
                    return Err(err(format!("{what}: POSITION element {i} is not finite")));
                }
                let q = world.transform_point3(glam::DVec3::from(p.map(f64::from)));
                if !q.is_finite() || q.abs().max_element() > f64::from(f32::MAX) {
                    return Err(err(format!(
                        "{what}: vertex {i} lies beyond the f32 range once transformed"
                    )));
                }
                out.positions.push(q);
            }
            let normal_base = out.normals.len();
            if normal.is_some() {
                for (i, v) in reader.read_normals().into_iter().flatten().enumerate() {
                    if !all_finite(&v) {
                        return Err(err(format!("{what}: NORMAL element {i} is not finite")));
                    }
                    let n = normal_matrix * glam::DVec3::from(v.map(f64::from));
                    if !n.is_finite() {
                        return Err(err(format!("{what}: normal {i} is not finite once transformed")));
                    }
                    out.normals.push(n);
                }
            }
            let indices: Vec<u32> = match reader.read_indices() {
                Some(ix) => ix.into_u32().collect(),
                None => (0..n as u32).collect(),
            };
            if indices.len() % 3 != 0 {
                return Err(err(format!("{what}: {} indices do not form whole triangles", indices.len())));
            }
            if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
                return Err(err(format!("{what}: index {k} is {}, but there are {n} vertices", indices[k])));
            }
            for t in indices.chunks_exact(3) {
                let mut t = [t[0], t[1], t[2]];
                if det < 0.0 {
                    t.swap(1, 2);
                }
                out.faces.push(PolygonFace {
                    positions: t.iter().map(|&i| base as u32 + i).collect(),
                    normals: normal
                        .as_ref()
                        .map(|_| t.iter().map(|&i| (normal_base + i as usize) as u32).collect()),
                    line: 0,
                });
            }
        }
    }
    if out.faces.is_empty() {
        return Err(Error::unsupported(
            file,
            0,
            "the glTF file has no triangle (no TRIANGLES primitive in its scene)",
        ));
    }
    Ok(out)
}

/// Refuses a node transform glTF does not allow and the reader would otherwise take silently:
/// a rotation that is not a unit quaternion (a zero one turns into the identity) and a matrix
/// whose last row is not `0 0 0 1` (a projective one: glTF node matrices must decompose into
/// translation, rotation and scale). Cost: O(1).
fn check_node_transform(node: &gltf::Node, file: &Path) -> Result<()> {
    match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => {
            let last_row = [matrix[0][3], matrix[1][3], matrix[2][3], matrix[3][3]];
            if last_row != [0.0, 0.0, 0.0, 1.0] {
                return Err(Error::unsupported(
                    file,
                    0,
                    format!(
                        "node {} has a projective matrix (last row {last_row:?}, not [0, 0, 0, 1]); glTF node matrices are affine",
                        node.index()
                    ),
                ));
            }
        }
        gltf::scene::Transform::Decomposed { rotation, .. } => {
            let length = rotation.iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>().sqrt();
            // Exporters round unit quaternions to f32; anything further off is not one.
            if !(length.is_finite() && (length - 1.0).abs() <= 1e-3) {
                return Err(Error::unsupported(
                    file,
                    0,
                    format!(
                        "node {} has the rotation {rotation:?} of length {length}; glTF rotations are unit quaternions",
                        node.index()
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// The most vertices [`parse_gltf_triangles`] instantiates (2^27: 3 GiB of positions), far
/// below the `u32` index range.
const MAX_INSTANCED_VERTICES: usize = 1 << 27;

const FLOAT_VEC3: (DataType, Dimensions) = (DataType::F32, Dimensions::Vec3);
const INDEX_TYPES: [(DataType, Dimensions); 3] = [
    (DataType::U8, Dimensions::Scalar),
    (DataType::U16, Dimensions::Scalar),
    (DataType::U32, Dimensions::Scalar),
];

/// Checks that accessor `a` has one of the `allowed` types, is dense and not normalized, and
/// that all its elements lie inside its view and the view inside its buffer's data; returns
/// its count. After this the `gltf` crate's reader neither overflows nor reads out of bounds.
fn check_accessor(
    a: &gltf::Accessor,
    buffers: &[Vec<u8>],
    file: &Path,
    what: &str,
    allowed: &[(DataType, Dimensions)],
) -> Result<usize> {
    let err = |reason: String| Error::parse(file, 0, format!("{what}: {reason}"));
    if a.sparse().is_some() {
        return Err(Error::unsupported(file, 0, format!("{what} uses a sparse accessor")));
    }
    if a.normalized() {
        return Err(Error::unsupported(file, 0, format!("{what} uses a normalized accessor")));
    }
    if !allowed.contains(&(a.data_type(), a.dimensions())) {
        return Err(err(format!(
            "has type {:?} {:?}, expected one of {allowed:?}",
            a.data_type(),
            a.dimensions()
        )));
    }
    let Some(view) = a.view() else {
        return Err(Error::unsupported(file, 0, format!("{what} has no buffer view")));
    };
    let count = a.count();
    if count == 0 {
        return Err(err("has count 0 (glTF requires at least 1)".into()));
    }
    let element = a.size();
    let stride = view.stride().unwrap_or(element);
    if stride < element {
        return Err(err(format!("byte stride {stride} is below the element size {element}")));
    }
    let data_len = buffers.get(view.buffer().index()).map_or(0, Vec::len);
    let view_end = view.offset().checked_add(view.length());
    if view_end.is_none_or(|e| e > data_len) {
        return Err(err(format!(
            "buffer view {} spans bytes {}..{} of a {data_len}-byte buffer",
            view.index(),
            view.offset(),
            view.offset().saturating_add(view.length())
        )));
    }
    let needed = (count - 1)
        .checked_mul(stride)
        .and_then(|s| s.checked_add(element))
        .and_then(|s| s.checked_add(a.offset()));
    if needed.is_none_or(|end| end > view.length()) {
        return Err(err(format!(
            "{count} elements of {element} bytes from offset {} with stride {stride} do not fit in the {}-byte buffer view {}",
            a.offset(),
            view.length(),
            view.index()
        )));
    }
    Ok(count)
}

/// Where the external files a `.gltf` names (its buffer URIs) may be.
///
/// glTF lets a buffer's `uri` be any relative path, and readers that follow it blindly read
/// whatever it names: `../../etc/passwd`, `/dev/zero`, a 3 GB file for a 96-byte buffer. So
/// by default a URI must resolve (symbolic links followed) to a regular file inside the
/// folder of the `.gltf`; `Anywhere` lifts the folder rule for models whose buffers are kept
/// elsewhere on purpose (`--allow-outside-uris`). Either way only regular files are read,
/// and never more than the buffer's `byteLength`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UriScope {
    /// Only files inside the folder of the `.gltf` (the default).
    #[default]
    ModelFolder,
    /// Any regular file the process may read.
    Anywhere,
}

/// The bytes of buffer `index`: a base64 `data:` URI, or a relative path (percent-decoded)
/// resolved against `dir` under `scope`, of which at most `byte_length` bytes are read.
/// Errors name the `.gltf` (`file`) and the file the URI names.
fn resolve_uri(
    uri: &str,
    index: usize,
    byte_length: usize,
    file: &Path,
    dir: Option<&Path>,
    scope: UriScope,
) -> Result<Vec<u8>> {
    let refuse = |reason: String| Error::unsupported(file, 0, format!("buffer {index}: {reason}"));
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err(refuse("a data: URI that is not base64".into()));
        };
        return decode_base64(payload).ok_or_else(|| {
            Error::parse(file, 0, format!("buffer {index}: a data: URI holds invalid base64"))
        });
    }
    if uri.contains("://") {
        return Err(refuse(format!("URI `{uri}` is not a local file")));
    }
    let Some(dir) = dir else {
        return Err(refuse(format!("URI `{uri}` needs the file's folder")));
    };
    let named = dir.join(percent_decode(uri));
    let cannot = |what: &str, source: io::Error| Error::Referenced {
        file: file.to_path_buf(),
        referenced: named.clone(),
        what: format!("buffer {index} (URI `{uri}`): {what}"),
        source,
    };
    // Resolved before anything is opened, so a link inside the folder to a file outside it
    // is judged by where it leads.
    let resolved = named.canonicalize().map_err(|e| cannot("cannot find it", e))?;
    if scope == UriScope::ModelFolder {
        let folder = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        let folder = folder.canonicalize().map_err(|e| cannot("cannot resolve the model's folder", e))?;
        if !resolved.starts_with(&folder) {
            return Err(refuse(format!(
                "URI `{uri}` names {}, outside the model's folder {} (--allow-outside-uris reads it)",
                resolved.display(),
                folder.display()
            )));
        }
    }
    let metadata = std::fs::metadata(&resolved).map_err(|e| cannot("cannot read it", e))?;
    if !metadata.is_file() {
        return Err(refuse(format!("URI `{uri}` names {}, which is not a regular file", resolved.display())));
    }
    if metadata.len() < byte_length as u64 {
        return Err(Error::parse(
            file,
            0,
            format!(
                "buffer {index} declares {byte_length} bytes but {} has {}",
                resolved.display(),
                metadata.len()
            ),
        ));
    }
    // `take` bounds the read by the declared length whatever the file grows to meanwhile;
    // the capacity is bounded by the file's size checked above.
    let mut bytes = Vec::with_capacity(byte_length);
    std::fs::File::open(&resolved)
        .and_then(|f| f.take(byte_length as u64).read_to_end(&mut bytes))
        .map_err(|e| cannot("cannot read it", e))?;
    Ok(bytes)
}

/// Decodes `%XX` escapes (URIs in glTF are percent-encoded); invalid escapes stay as they are.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (with or without padding); `None` on any other character. Written here
/// because it is the only use, and a dependency for 20 lines is not worth it.
fn decode_base64(s: &str) -> Option<Vec<u8>> {
    let value = |c: u8| -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            _ => return None,
        } as u32)
    };
    let s = s.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(s.len() / 4 * 3 + 2);
    for chunk in s.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            acc |= value(c)? << (18 - 6 * k);
        }
        let bytes = acc.to_be_bytes();
        match chunk.len() {
            4 => out.extend_from_slice(&bytes[1..4]),
            3 => out.extend_from_slice(&bytes[1..3]),
            2 => out.push(bytes[1]),
            _ => return None,
        }
    }
    Some(out)
}

// =============================================================================================
// Writing

/// Writes `mesh` as glTF 2.0 binary (GLB) to `w`: one buffer, one mesh with one indexed
/// triangle primitive (`POSITION` with min/max, `NORMAL`, the vertex's patch parameters
/// `_PATCH_UV`, the float vertex patch id `_PATCH`, `u32` indices), one node and one scene.
/// Triangle patches and corner params go to byte ranges of the buffer named in the
/// primitive's extras (see the module documentation). A mesh
/// without triangles is written as a file holding only the asset, since glTF forbids empty
/// accessors; any vertices are dropped.
///
/// Preconditions: as [`write_mesh`](super::write_mesh), vertex patch ids at most 2^24 (exact in the float
/// `_PATCH`), and a file under 4 GiB; otherwise [`Error::InvalidMesh`] or [`Error::FormatLimit`]. I/O errors are
/// [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time; the JSON is built in memory (a few KiB, independent of
/// the mesh size); the mesh's arrays are written as they are in memory (one `write` each on a
/// little-endian machine), the float patch ids converted in parallel chunks.
pub fn write_glb<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    super::write_to(mesh, Format::Glb, w)
}

// GLB

/// The GLB's JSON chunk (already padded) and binary chunk length, fixed before writing because
/// the header carries the total length.
pub(super) struct GlbPlan {
    json: Vec<u8>,
    bin_len: u64,
}

/// One buffer view's place in the binary chunk.
struct Span {
    offset: u64,
    len: u64,
}

pub(super) fn plan_glb(mesh: &Mesh) -> Result<GlbPlan> {
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
        // object to the glTF validator (see the module documentation).
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
            // "_PATCH_UV": patch parameters, not texture coordinates (module documentation).
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

pub(super) fn emit_glb<W: Write>(mesh: &Mesh, plan: &GlbPlan, w: &mut W) -> io::Result<()> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::binary::test_meshes::*;

    #[test]
    fn glb_round_trip() {
        for with_params in [false, true] {
            let mesh = grid(5, with_params);
            let read = parse_glb(&bytes(|w| write_glb(&mesh, w)), label()).unwrap();
            assert_eq!(read, mesh);
        }
        let empty = Mesh::default();
        assert_eq!(parse_glb(&bytes(|w| write_glb(&empty, w)), label()).unwrap(), empty);
    }

    /// Builds a GLB from a JSON text and a BIN chunk.
    fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
        let mut json = json.as_bytes().to_vec();
        json.resize(json.len().next_multiple_of(4), b' ');
        let mut bin = bin.to_vec();
        bin.resize(bin.len().next_multiple_of(4), 0);
        let total = 12 + 8 + json.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
        let mut out = b"glTF".to_vec();
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((json.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(&json);
        if !bin.is_empty() {
            out.extend((bin.len() as u32).to_le_bytes());
            out.extend(b"BIN\0");
            out.extend(&bin);
        }
        out
    }

    /// One triangle, u16 indices, positions only: everything else is filled in.
    fn minimal_glb(index_count: u32, position_count: u32, index_value: u16) -> Vec<u8> {
        let mut bin = Vec::new();
        for c in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
            bin.extend(c.to_le_bytes());
        }
        for i in [0u16, 1, index_value] {
            bin.extend(i.to_le_bytes());
        }
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"byteLength":42}}],
            "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":{position_count},"type":"VEC3"}},
                         {{"bufferView":1,"componentType":5123,"count":{index_count},"type":"SCALAR"}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}]}}"#
        );
        glb(&json, &bin)
    }

    #[test]
    fn glb_fills_missing_attributes() {
        let mesh = parse_glb(&minimal_glb(3, 3, 2), label()).unwrap();
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.indices, [0, 1, 2]);
        assert_eq!(mesh.normals, [[0.0; 3]; 3]);
        assert_eq!(mesh.uvs, [[0.0; 2]; 3]);
        assert_eq!(mesh.vertex_patch, [0; 3]);
        assert_eq!(mesh.triangle_patch, [0]);
        assert_eq!(mesh.corner_params, None);
    }

    #[test]
    fn glb_errors() {
        let reason = |data: &[u8]| parse_error(parse_glb(data, label())).1;
        assert!(reason(&minimal_glb(3, 3, 7)).contains("index 2 is 7, but there are 3 vertices"));
        assert!(reason(&minimal_glb(3, 4, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(3, 1 << 30, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(1 << 31, 3, 2)).contains("do not fit"));
        assert!(reason(&minimal_glb(2, 3, 2)).contains("whole triangles"));
        assert!(reason(&glb("{\"asset\":", &[])).contains("invalid glTF JSON"));
        assert!(reason(b"glTB\x02\0\0\0\x0c\0\0\0").contains("not a GLB"));
        let mut data = minimal_glb(3, 3, 2);
        data.push(0);
        assert!(reason(&data).contains("gives a length of"));

        let mesh = grid(2, true);
        let good = bytes(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&good);
        let json = std::str::from_utf8(json).unwrap().trim_end();
        let edit = |change: &dyn Fn(&mut serde_json::Value)| {
            let mut v: serde_json::Value = serde_json::from_str(json).unwrap();
            change(&mut v);
            glb(&v.to_string(), bin)
        };
        let far = edit(&|v| extras(v)["trianglePatch"]["byteOffset"] = 100000.into());
        assert!(reason(&far).contains("extras.tessera.trianglePatch spans bytes 100000.."));
        let bad = edit(&|v| extras(v)["trianglePatch"] = "x".into());
        assert!(reason(&bad).contains("trianglePatch.byteOffset is missing or not a byte count"));
        let old_key = |value: serde_json::Value| {
            edit(&move |v| {
                let e = extras(v).as_object_mut().unwrap();
                e.remove("trianglePatch");
                e.insert("trianglePatchView".into(), value.clone());
            })
        };
        assert!(reason(&old_key(50.into())).contains("buffer view 50"));
        assert!(reason(&old_key("x".into())).contains("not a buffer view"));
        let big = edit(&|v| v["buffers"][0]["byteLength"] = 100000.into());
        assert!(reason(&big).contains("spans bytes"));
        match parse_glb(&edit(&|v| v["buffers"][0]["uri"] = "x.bin".into()), label()) {
            Err(Error::Unsupported { reason, .. }) => assert!(reason.contains("external buffer")),
            other => panic!("{other:?}"),
        }
        let mut nan = good.clone();
        let at = good.len() - bin.len();
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(reason(&nan).contains("POSITION element 0 is not finite"));
    }

    #[test]
    fn gltf_reader_reads_tessera_output_and_refuses_short_headers() {
        let mesh = grid(3, true);
        let read =
            parse_gltf_triangles(&bytes(|w| write_glb(&mesh, w)), label(), None, UriScope::ModelFolder)
                .unwrap();
        let positions: Vec<[f32; 3]> = read.positions.iter().map(|p| p.as_vec3().to_array()).collect();
        assert_eq!(positions, mesh.positions);
        let indices: Vec<u32> = read.faces.iter().flat_map(|f| f.positions.clone()).collect();
        assert_eq!(indices, mesh.indices);
        assert!(read.faces.iter().all(|f| f.normals.as_ref() == Some(&f.positions)));
        for short in [&b"glTF"[..], b"glTF\x02\0\0\0\x05\0\0\0", b"glTF\x02\0\0\0\0\0\0\0JSON"] {
            let e = parse_gltf_triangles(short, label(), None, UriScope::ModelFolder).unwrap_err();
            assert!(e.to_string().contains("invalid glTF"), "{e}");
        }
    }

    /// tessera's part of a GLB primitive's extras, in the JSON of a GLB.
    fn extras(v: &mut serde_json::Value) -> &mut serde_json::Value {
        &mut v["meshes"][0]["primitives"][0]["extras"]["tessera"]
    }

    #[test]
    fn glb_truncation_and_corruption_never_panic() {
        let data = bytes(|w| write_glb(&grid(2, true), w));
        check_truncations(&data, parse_glb, true);
        check_corruptions(&data, parse_glb);
        let data = minimal_glb(3, 3, 2);
        check_truncations(&data, parse_glb, true);
        check_corruptions(&data, parse_glb);
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
        let bytes = bytes(|w| write_glb(&mesh, w));
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
            [("POSITION", "VEC3"), ("NORMAL", "VEC3"), ("_PATCH_UV", "VEC2"), ("_PATCH", "SCALAR")]
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
        let range = |key: &str| {
            let r = &extras["tessera"][key];
            (r["byteOffset"].as_u64().unwrap() as usize, r["byteLength"].as_u64().unwrap() as usize)
        };
        let (start, len) = range("trianglePatch");
        let patches: Vec<u32> = bin[start..start + len]
            .chunks_exact(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(patches, mesh.triangle_patch);
        assert_eq!(range("cornerParams").1, 24 * mesh.triangle_count());
        assert!(json.windows(8).any(|w| w == b"\"_PATCH\""));
        assert!(!json.windows(10).any(|w| w == b"TEXCOORD_0"));
    }

    /// What the Khronos validator reports as unused objects, checked without it: every
    /// accessor, buffer view, buffer, mesh and node must be referenced, the scene must be the
    /// default one, and POSITION must carry min and max.
    #[test]
    fn glb_has_no_unused_objects() {
        for with_params in [false, true] {
            let mesh = grid(4, with_params);
            let data = bytes(|w| write_glb(&mesh, w));
            let (json, _) = glb_chunks(&data);
            let v: serde_json::Value = serde_json::from_slice(json).unwrap();
            let len = |key: &str| v[key].as_array().map_or(0, Vec::len);
            let mut accessors = vec![false; len("accessors")];
            let mut views = vec![false; len("bufferViews")];
            let mut buffers = vec![false; len("buffers")];
            let mut meshes = vec![false; len("meshes")];
            let mut nodes = vec![false; len("nodes")];
            let mark = |used: &mut Vec<bool>, index: &serde_json::Value| {
                let i = index.as_u64().expect("an index") as usize;
                assert!(i < used.len(), "index {i} out of range");
                used[i] = true;
            };
            assert_eq!(v["scene"], 0);
            for scene in v["scenes"].as_array().unwrap() {
                for n in scene["nodes"].as_array().unwrap() {
                    mark(&mut nodes, n);
                }
            }
            for node in v["nodes"].as_array().unwrap() {
                mark(&mut meshes, &node["mesh"]);
            }
            for m in v["meshes"].as_array().unwrap() {
                for p in m["primitives"].as_array().unwrap() {
                    for (name, a) in p["attributes"].as_object().unwrap() {
                        assert!(
                            ["POSITION", "NORMAL"].contains(&name.as_str()) || name.starts_with('_'),
                            "{name}: a standard semantic no material uses is unused"
                        );
                        mark(&mut accessors, a);
                    }
                    mark(&mut accessors, &p["indices"]);
                    let position = &v["accessors"][p["attributes"]["POSITION"].as_u64().unwrap() as usize];
                    assert_eq!(position["min"].as_array().map(Vec::len), Some(3));
                    assert_eq!(position["max"].as_array().map(Vec::len), Some(3));
                }
            }
            for a in v["accessors"].as_array().unwrap() {
                mark(&mut views, &a["bufferView"]);
            }
            for view in v["bufferViews"].as_array().unwrap() {
                mark(&mut buffers, &view["buffer"]);
            }
            for (what, used) in [
                ("accessor", accessors),
                ("buffer view", views),
                ("buffer", buffers),
                ("mesh", meshes),
                ("node", nodes),
            ] {
                assert!(!used.is_empty(), "no {what}");
                assert!(used.iter().all(|&u| u), "an unused {what}: {used:?}");
            }
        }
    }

    /// Files tessera wrote before this layout (TEXCOORD_0, buffer views named in extras)
    /// still read back to the same mesh.
    #[test]
    fn glb_of_the_old_layout_is_still_read() {
        let mesh = grid(3, true);
        let data = bytes(|w| write_glb(&mesh, w));
        let (json, bin) = glb_chunks(&data);
        let mut v: serde_json::Value = serde_json::from_slice(json).unwrap();
        let primitive = &mut v["meshes"][0]["primitives"][0];
        let uv = primitive["attributes"].as_object_mut().unwrap().remove("_PATCH_UV").unwrap();
        primitive["attributes"]["TEXCOORD_0"] = uv;
        let tessera = primitive["extras"]["tessera"].take();
        let views = v["bufferViews"].as_array_mut().unwrap();
        let mut extras = serde_json::Map::new();
        for (key, old) in [("trianglePatch", "trianglePatchView"), ("cornerParams", "cornerParamsView")] {
            let r = &tessera[key];
            views.push(serde_json::json!({"buffer": 0, "byteOffset": r["byteOffset"], "byteLength": r["byteLength"]}));
            extras.insert(old.into(), (views.len() - 1).into());
        }
        v["meshes"][0]["primitives"][0]["extras"] = serde_json::json!({ "tessera": extras });
        assert_eq!(parse_glb(&glb(&v.to_string(), bin), label()).unwrap(), mesh);
    }

    #[test]
    fn glb_of_an_empty_mesh_holds_only_the_asset() {
        let bytes = bytes(|w| write_glb(&Mesh::default(), w));
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
        assert!(matches!(&err, Error::FormatLimit { reason, .. } if reason.contains("vertex 2")), "{err}");
        mesh.vertex_patch[2] = 1 << 24;
        write_glb(&mesh, Vec::new()).unwrap();
    }
}
