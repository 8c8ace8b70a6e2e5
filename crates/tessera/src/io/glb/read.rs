//! Reading tessera's own GLB layout (and the one it wrote before), by hand, every count and
//! offset checked before use (see the module documentation of `io::glb`).

use std::path::Path;

use gltf_json as gj;
use gltf_json::accessor::{ComponentType, Type};
use gltf_json::validation::Checked;

use crate::error::{Error, Result};
use crate::io::binary::{all_finite, fill_missing, to_u32};
use crate::mesh::Mesh;

use super::*;

/// Parses glTF binary `data`; `file` only labels errors. Reads the layout `write_glb`
/// produces, and the one it wrote before (see [`io::glb`](super)); whatever the file
/// lacks is filled in as [`read_mesh`](crate::io::read_mesh) says.
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
