//! Outside glTF files (`.gltf` or `.glb`, any meshes and nodes) as PN-triangle input,
//! through the `gltf` crate after checks of its own.

use std::path::Path;

use gltf::accessor::{DataType, Dimensions};
use gltf_json as gj;

use crate::error::{Error, Result};
use crate::io::binary::all_finite;
use crate::surface::{PolygonFace, PolygonMesh};

use super::uri::resolve_uri;
use super::*;

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
    let data = crate::io::read_input(path)?;
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
    let (gltf, blob) = open_document(data, file)?;
    let buffers = load_buffers(&gltf, blob, file, dir, scope)?;
    let instances = scene_instances(&gltf, file)?;
    let meshes: Vec<gltf::Mesh> = gltf.meshes().collect();
    let mut out = PolygonMesh::default();
    let mut skipped = std::collections::HashSet::new();
    for (mesh_index, world) in instances {
        let placement = Placement::new(world, mesh_index, file)?;
        for primitive in meshes[mesh_index].primitives() {
            let what = format!("mesh {mesh_index} primitive {}", primitive.index());
            if !is_triangle_list(&primitive, file, &what)? {
                // Counted once however many nodes instance its mesh.
                if skipped.insert((mesh_index, primitive.index())) {
                    out.skipped_primitives += 1;
                }
                continue;
            }
            append_primitive(&mut out, &primitive, &placement, &buffers, file, &what)?;
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

/// The validated glTF document of `data` and the GLB's BIN chunk, if any. Two checks come
/// before the `gltf` crate's own, on inputs that make it panic.
fn open_document(data: &[u8], file: &Path) -> Result<(gltf::Document, Option<Vec<u8>>)> {
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
    Ok((gltf, blob))
}

/// The bytes of every buffer, in order: the GLB's BIN chunk (`blob`) or what its URI names,
/// each at least its declared `byteLength`.
fn load_buffers(
    gltf: &gltf::Document,
    blob: Option<Vec<u8>>,
    file: &Path,
    dir: Option<&Path>,
    scope: UriScope,
) -> Result<Vec<Vec<u8>>> {
    let err = |reason: String| Error::parse(file, 0, reason);
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
    Ok(buffers)
}

/// (mesh index, world matrix) pairs: the meshes the default scene's node hierarchy (else the
/// first scene's) instances, or every mesh untransformed in a file without scenes.
fn scene_instances(gltf: &gltf::Document, file: &Path) -> Result<Vec<(usize, glam::DMat4)>> {
    let Some(scene) = gltf.default_scene().or_else(|| gltf.scenes().next()) else {
        return Ok(gltf.meshes().map(|m| (m.index(), glam::DMat4::IDENTITY)).collect());
    };
    let mut instances = Vec::new();
    let mut visited = vec![false; gltf.nodes().len()];
    let mut stack: Vec<(gltf::Node, glam::DMat4)> =
        scene.nodes().map(|n| (n, glam::DMat4::IDENTITY)).collect();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut visited[node.index()], true) {
            return Err(Error::parse(
                file,
                0,
                format!("node {} appears twice in the scene hierarchy", node.index()),
            ));
        }
        check_node_transform(&node, file)?;
        let local = glam::Mat4::from_cols_array_2d(&node.transform().matrix()).as_dmat4();
        let world = parent * local;
        if let Some(mesh) = node.mesh() {
            instances.push((mesh.index(), world));
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(instances)
}

/// Where one instance of a mesh goes: its world matrix, the matrix for its normals, and
/// whether it mirrors (its triangles' winding is then reversed to keep the front side).
struct Placement {
    world: glam::DMat4,
    normal_matrix: glam::DMat3,
    mirrors: bool,
}

impl Placement {
    /// Refuses a singular transform (it has no normal matrix, and flattens the mesh).
    fn new(world: glam::DMat4, mesh_index: usize, file: &Path) -> Result<Self> {
        let linear = glam::DMat3::from_mat4(world);
        let det = linear.determinant();
        if !(det.is_finite() && det != 0.0) {
            return Err(Error::unsupported(
                file,
                0,
                format!("a node of mesh {mesh_index} has a singular transform"),
            ));
        }
        Ok(Placement { world, normal_matrix: linear.inverse().transpose(), mirrors: det < 0.0 })
    }
}

/// True for a `TRIANGLES` primitive, false for points and lines (skipped); refuses strips and
/// fans.
fn is_triangle_list(primitive: &gltf::Primitive, file: &Path, what: &str) -> Result<bool> {
    use gltf::mesh::Mode;
    match primitive.mode() {
        Mode::Triangles => Ok(true),
        Mode::Points | Mode::Lines | Mode::LineLoop | Mode::LineStrip => Ok(false),
        other => {
            Err(Error::unsupported(file, 0, format!("{what} has mode {other:?}; only TRIANGLES are read")))
        }
    }
}

/// Appends one instance of a triangle primitive to `out`: its accessors checked, its
/// vertices placed, its triangles offset to `out`'s numbering.
fn append_primitive(
    out: &mut PolygonMesh,
    primitive: &gltf::Primitive,
    placement: &Placement,
    buffers: &[Vec<u8>],
    file: &Path,
    what: &str,
) -> Result<()> {
    let (n, has_normals) = check_primitive_accessors(primitive, buffers, file, what)?;
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let base = out.positions.len();
    // Instancing multiplies a small file's vertices by its node count, so the bound is on the
    // result, not on the file.
    if base + n > MAX_INSTANCED_VERTICES {
        return Err(Error::unsupported(
            file,
            0,
            format!("the scene instances more than {MAX_INSTANCED_VERTICES} vertices"),
        ));
    }
    append_positions(out, reader.read_positions().into_iter().flatten(), placement, file, what)?;
    let normal_base = out.normals.len();
    if has_normals {
        append_normals(out, reader.read_normals().into_iter().flatten(), placement, file, what)?;
    }
    let indices: Vec<u32> = match reader.read_indices() {
        Some(ix) => ix.into_u32().collect(),
        None => (0..n as u32).collect(),
    };
    check_indices(&indices, n, file, what)?;
    let normal_base = has_normals.then_some(normal_base);
    append_triangles(out, &indices, base, normal_base, placement.mirrors);
    Ok(())
}

/// Checks the primitive's `POSITION`, `NORMAL` and index accessors against their buffers
/// (see [`check_accessor`]); returns the vertex count and whether it has normals.
fn check_primitive_accessors(
    primitive: &gltf::Primitive,
    buffers: &[Vec<u8>],
    file: &Path,
    what: &str,
) -> Result<(usize, bool)> {
    let Some(position) = primitive.get(&gltf::Semantic::Positions) else {
        return Err(Error::parse(file, 0, format!("{what} has no POSITION attribute")));
    };
    let n = check_accessor(&position, buffers, file, &format!("{what} POSITION"), &[FLOAT_VEC3])?;
    let normal = primitive.get(&gltf::Semantic::Normals);
    if let Some(a) = &normal {
        let count = check_accessor(a, buffers, file, &format!("{what} NORMAL"), &[FLOAT_VEC3])?;
        if count != n {
            return Err(Error::parse(
                file,
                0,
                format!("{what}: NORMAL has {count} elements for {n} vertices"),
            ));
        }
    }
    if let Some(a) = primitive.indices() {
        check_accessor(&a, buffers, file, &format!("{what} indices"), &INDEX_TYPES)?;
    }
    Ok((n, normal.is_some()))
}

/// Appends the positions in world coordinates; each must be finite before and within the
/// `f32` range after the transform.
fn append_positions(
    out: &mut PolygonMesh,
    positions: impl Iterator<Item = [f32; 3]>,
    placement: &Placement,
    file: &Path,
    what: &str,
) -> Result<()> {
    for (i, p) in positions.enumerate() {
        if !all_finite(&p) {
            return Err(Error::parse(file, 0, format!("{what}: POSITION element {i} is not finite")));
        }
        let q = placement.world.transform_point3(glam::DVec3::from(p.map(f64::from)));
        if !q.is_finite() || q.abs().max_element() > f64::from(f32::MAX) {
            return Err(Error::parse(
                file,
                0,
                format!("{what}: vertex {i} lies beyond the f32 range once transformed"),
            ));
        }
        out.positions.push(q);
    }
    Ok(())
}

/// Appends the normals through the placement's normal matrix; each must be finite before and
/// after.
fn append_normals(
    out: &mut PolygonMesh,
    normals: impl Iterator<Item = [f32; 3]>,
    placement: &Placement,
    file: &Path,
    what: &str,
) -> Result<()> {
    for (i, v) in normals.enumerate() {
        if !all_finite(&v) {
            return Err(Error::parse(file, 0, format!("{what}: NORMAL element {i} is not finite")));
        }
        let n = placement.normal_matrix * glam::DVec3::from(v.map(f64::from));
        if !n.is_finite() {
            return Err(Error::parse(file, 0, format!("{what}: normal {i} is not finite once transformed")));
        }
        out.normals.push(n);
    }
    Ok(())
}

/// Refuses indices that do not form whole triangles or name a vertex past the primitive's
/// `n`.
fn check_indices(indices: &[u32], n: usize, file: &Path, what: &str) -> Result<()> {
    if indices.len() % 3 != 0 {
        return Err(Error::parse(
            file,
            0,
            format!("{what}: {} indices do not form whole triangles", indices.len()),
        ));
    }
    if let Some(k) = indices.iter().position(|&i| i as usize >= n) {
        return Err(Error::parse(
            file,
            0,
            format!("{what}: index {k} is {}, but there are {n} vertices", indices[k]),
        ));
    }
    Ok(())
}

/// Appends the triangles of `indices` as faces: positions from `base`, normals (when the
/// primitive has them) from `normal_base`, the winding reversed when `mirrors`.
fn append_triangles(
    out: &mut PolygonMesh,
    indices: &[u32],
    base: usize,
    normal_base: Option<usize>,
    mirrors: bool,
) {
    for t in indices.chunks_exact(3) {
        let mut t = [t[0], t[1], t[2]];
        if mirrors {
            t.swap(1, 2);
        }
        out.faces.push(PolygonFace {
            positions: t.iter().map(|&i| base as u32 + i).collect(),
            normals: normal_base.map(|nb| t.iter().map(|&i| (nb + i as usize) as u32).collect()),
            line: 0,
        });
    }
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
