//! Mesh readers for PLY, STL and glTF binary (GLB); OBJ input is parsed by `io::obj`.
//!
//! The readers take untrusted files: every count, offset and index is checked against the bytes
//! actually present before it is used, so a truncated or lying file gives an [`Error`] naming
//! the file (and, for text, the line; for binary, the byte offset in the reason), never a panic
//! or an allocation sized by a header. Coordinates, normals and parameters must be finite.
//!
//! Attributes a file does not carry are filled so that the result is always a consistent
//! [`Mesh`]: normals and uvs with zeros, vertex and triangle patches with 0, and
//! [`Mesh::corner_params`] with `None`.

use std::collections::HashMap;
use std::path::Path;

use gltf_json as gj;
use gltf_json::accessor::{ComponentType, Type};
use gltf_json::validation::Checked;

use super::Mesh;
use crate::error::{Error, Result};

/// The extensions [`read_mesh`] understands, for error messages.
const SUPPORTED: &str = ".ply, .stl, .glb";

/// Reads the mesh in `path`, choosing the format by the extension (case-insensitive):
///
/// - `.ply`: ASCII, binary little- or big-endian. The `vertex` element needs `x y z`; it may
///   carry `nx ny nz`, `u v` (or `s t`, `texture_u texture_v`) and `patch`. The `face` element
///   needs `vertex_indices` (or `vertex_index`); it may carry `patch` and `texcoord` (2 values
///   per corner), which fills [`Mesh::corner_params`] only when every face has it. Other
///   elements and properties, in any order and of any PLY type, are skipped. Polygons are
///   split into triangle fans. In ASCII files each record must end with its line, which
///   catches a header that disagrees with the data.
/// - `.stl`: binary, or ASCII (`solid ...`, recognised when the binary size does not match).
///   Corners with equal positions (bit-identical, with `-0.0` equal to `0.0`) are welded into
///   one vertex, in order of first appearance. Facet normals are not kept.
/// - `.glb`: the layout [`write_glb`](super::write::write_glb) produces: one mesh with one
///   triangle primitive, `POSITION`, optional `NORMAL`, `TEXCOORD_0` and `_PATCH`, `u8`/`u16`/
///   `u32` indices (or none), and tessera's triangle-patch and corner-param buffer views.
///   A file without meshes gives an empty mesh.
///
/// Whatever the file lacks is filled in: zero normals and uvs, patch 0 for vertices and
/// triangles, no corner params.
///
/// Errors: an unknown extension is [`Error::InvalidArgument`]; an unreadable file is
/// [`Error::Io`]; malformed, truncated or out-of-range content is [`Error::Parse`], and valid
/// content beyond what the reader handles (sparse accessors, several primitives, ...) is
/// [`Error::Unsupported`]; all name `path`.
///
/// Cost: reads the whole file into memory, then O(file size) time; STL welding adds a hash map
/// of the distinct positions.
pub fn read_mesh(path: &Path) -> Result<Mesh> {
    let ext = path.extension().map(|e| e.to_string_lossy().to_ascii_lowercase());
    let parse: fn(&[u8], &Path) -> Result<Mesh> = match ext.as_deref() {
        Some("ply") => parse_ply,
        Some("stl") => parse_stl,
        Some("glb") => parse_glb,
        Some(other) => {
            return Err(Error::InvalidArgument(format!(
                "{}: unsupported input extension \".{other}\"; supported: {SUPPORTED}",
                path.display()
            )))
        }
        None => {
            return Err(Error::InvalidArgument(format!(
                "{}: input file has no extension; supported: {SUPPORTED}",
                path.display()
            )))
        }
    };
    let data = std::fs::read(path).map_err(|source| Error::Io { path: path.to_path_buf(), source })?;
    parse(&data, path)
}

/// Fills the attributes a format lacks so that every vector has its documented length.
fn fill_missing(mesh: &mut Mesh) {
    let n = mesh.positions.len();
    mesh.normals.resize(n, [0.0; 3]);
    mesh.uvs.resize(n, [0.0; 2]);
    mesh.vertex_patch.resize(n, 0);
    mesh.triangle_patch.resize(mesh.indices.len() / 3, 0);
}

/// Converts a number read from a file to a `u32` index or id, refusing fractions, negatives,
/// NaN and values past `u32::MAX` (which `as` would silently saturate).
fn to_u32(v: f64) -> Option<u32> {
    (v.fract() == 0.0 && (0.0..=f64::from(u32::MAX)).contains(&v)).then_some(v as u32)
}

fn all_finite(values: &[f32]) -> bool {
    values.iter().all(|v| v.is_finite())
}

// =============================================================================================
// PLY

/// Parses PLY `data` (ASCII or binary, either byte order); `file` only labels errors.
/// See [`read_mesh`] for what is read and what is filled in.
///
/// Preconditions: none; any bytes give a mesh or an error. Errors in the header and in ASCII
/// bodies carry the line; errors in binary bodies carry line 0 and the byte offset.
///
/// Cost: O(`data.len()`) time; memory proportional to the mesh, never to header counts that
/// the data cannot back.
pub fn parse_ply(data: &[u8], file: &Path) -> Result<Mesh> {
    let header = PlyHeader::parse(data, file)?;
    let body = &data[header.body_start..];
    match header.encoding {
        Encoding::Ascii => {
            let mut src = AsciiSource { text: body, pos: 0, line: header.body_line, file };
            read_ply_body(&header, &mut src, file)
        }
        Encoding::BinaryLe | Encoding::BinaryBe => {
            let mut src = BinarySource {
                data,
                pos: header.body_start,
                big_endian: header.encoding == Encoding::BinaryBe,
                file,
            };
            read_ply_body(&header, &mut src, file)
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum PropKind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: PropKind,
    line: usize,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    line: usize,
}

impl Element {
    /// Bytes one record takes at least: a list takes at least its count.
    fn min_record_bytes(&self, encoding: Encoding) -> usize {
        match encoding {
            // One character per value; separators only add.
            Encoding::Ascii => self.props.len(),
            _ => self
                .props
                .iter()
                .map(|p| match p.kind {
                    PropKind::Scalar(s) => s.size(),
                    PropKind::List { count, .. } => count.size(),
                })
                .sum(),
        }
    }

    /// Capacity to reserve for `per_record` items per record: the declared count, but no more
    /// than the remaining bytes could hold, so a lying header cannot force a huge allocation.
    fn capacity(&self, encoding: Encoding, remaining: usize, per_record: usize) -> usize {
        let fit = remaining / self.min_record_bytes(encoding).max(1);
        (self.count.min(fit as u64) as usize).saturating_mul(per_record)
    }
}

#[derive(Debug)]
struct PlyHeader {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Byte offset of the first byte after `end_header`'s line.
    body_start: usize,
    /// Line number of the first body line (ASCII bodies).
    body_line: usize,
}

impl PlyHeader {
    fn parse(data: &[u8], file: &Path) -> Result<PlyHeader> {
        let mut pos = 0;
        let mut line_no = 0;
        let mut encoding = None;
        let mut elements: Vec<Element> = Vec::new();
        loop {
            let Some(len) = data[pos..].iter().position(|&b| b == b'\n') else {
                let reason = if line_no == 0 { "not a PLY file" } else { "header has no end_header" };
                return Err(Error::parse(file, line_no.max(1), reason));
            };
            line_no += 1;
            let raw = &data[pos..pos + len];
            pos += len + 1;
            let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
            let err = |reason: String| Error::parse(file, line_no, reason);
            let Ok(line) = std::str::from_utf8(raw) else {
                return Err(err("header line is not valid UTF-8".into()));
            };
            let tokens: Vec<&str> = line.split_whitespace().collect();
            if line_no == 1 {
                if tokens != ["ply"] {
                    return Err(err("not a PLY file (first line is not \"ply\")".into()));
                }
                continue;
            }
            match tokens.as_slice() {
                [] | ["comment", ..] | ["obj_info", ..] => {}
                ["format", kind, version] => {
                    if encoding.is_some() {
                        return Err(err("second format line".into()));
                    }
                    if *version != "1.0" {
                        return Err(Error::unsupported(
                            file,
                            line_no,
                            format!("PLY version {version}; only 1.0 is supported"),
                        ));
                    }
                    encoding = Some(match *kind {
                        "ascii" => Encoding::Ascii,
                        "binary_little_endian" => Encoding::BinaryLe,
                        "binary_big_endian" => Encoding::BinaryBe,
                        _ => return Err(err(format!("unknown PLY format {kind:?}"))),
                    });
                }
                ["element", name, count] => {
                    let count = count
                        .parse::<u64>()
                        .map_err(|_| err(format!("element count {count:?} is not a number")))?;
                    if elements.iter().any(|e| e.name == *name) {
                        return Err(err(format!("element {name:?} declared twice")));
                    }
                    elements.push(Element {
                        name: name.to_string(),
                        count,
                        props: Vec::new(),
                        line: line_no,
                    });
                }
                ["property", rest @ ..] => {
                    let Some(element) = elements.last_mut() else {
                        return Err(err("property before any element".into()));
                    };
                    let scalar = |name: &str| {
                        Scalar::parse(name).ok_or_else(|| err(format!("unknown property type {name:?}")))
                    };
                    let (kind, name) = match rest {
                        ["list", count, item, name] => {
                            let count = scalar(count)?;
                            if matches!(count, Scalar::F32 | Scalar::F64) {
                                return Err(err("list count type must be an integer".into()));
                            }
                            (PropKind::List { count, item: scalar(item)? }, name)
                        }
                        [ty, name] => (PropKind::Scalar(scalar(ty)?), name),
                        _ => return Err(err(format!("malformed property line {line:?}"))),
                    };
                    element.props.push(Property { name: name.to_string(), kind, line: line_no });
                }
                ["end_header"] => break,
                _ => return Err(err(format!("unexpected header line {line:?}"))),
            }
        }
        let Some(encoding) = encoding else {
            return Err(Error::parse(file, line_no, "header has no format line"));
        };
        Ok(PlyHeader { encoding, elements, body_start: pos, body_line: line_no + 1 })
    }
}

/// A stream of PLY values, binary or ASCII; errors carry the current location.
trait Source {
    /// The next value of type `ty`, widened to f64 (exact for every PLY type).
    fn value(&mut self, ty: Scalar) -> Result<f64>;
    /// A parse error at the current location.
    fn error(&self, reason: String) -> Error;
    /// Bytes left, to bound preallocation.
    fn remaining(&self) -> usize;
    /// Called after each record. ASCII records end with their line: a value left over means
    /// the header and the data disagree, which would otherwise shift every later value.
    fn end_record(&mut self, what: &str) -> Result<()>;
}

struct BinarySource<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
    file: &'a Path,
}

impl Source for BinarySource<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64> {
        let size = ty.size();
        let Some(bytes) = self.data.get(self.pos..self.pos + size) else {
            return Err(self
                .error(format!("file ends inside a {size}-byte value (file is {} bytes)", self.data.len())));
        };
        let mut b = [0u8; 8];
        b[..size].copy_from_slice(bytes);
        if self.big_endian {
            b[..size].reverse();
        }
        self.pos += size;
        Ok(match ty {
            Scalar::I8 => f64::from(b[0] as i8),
            Scalar::U8 => f64::from(b[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([b[0], b[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([b[0], b[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            Scalar::F64 => f64::from_le_bytes(b),
        })
    }

    fn error(&self, reason: String) -> Error {
        Error::parse(self.file, 0, format!("{reason} at byte offset {}", self.pos))
    }

    fn remaining(&self) -> usize {
        self.data.len().saturating_sub(self.pos)
    }

    fn end_record(&mut self, _what: &str) -> Result<()> {
        Ok(())
    }
}

struct AsciiSource<'a> {
    text: &'a [u8],
    pos: usize,
    line: usize,
    file: &'a Path,
}

impl Source for AsciiSource<'_> {
    fn value(&mut self, ty: Scalar) -> Result<f64> {
        let line_before = self.line;
        while let Some(&c) = self.text.get(self.pos) {
            if !c.is_ascii_whitespace() {
                break;
            }
            if c == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self.text.get(self.pos).is_some_and(|c| !c.is_ascii_whitespace()) {
            self.pos += 1;
        }
        if start == self.pos {
            // Blame the last line with content, not the empty one after the final newline.
            self.line = line_before;
            return Err(self.error("file ends before the last element".into()));
        }
        let token = &self.text[start..self.pos];
        let parsed = std::str::from_utf8(token).ok().and_then(|t| t.parse::<f64>().ok());
        let Some(v) = parsed else {
            return Err(self.error(format!("expected a number, found {:?}", String::from_utf8_lossy(token))));
        };
        // Integer properties must hold integers; float ones may hold anything parseable.
        let integral = !matches!(ty, Scalar::F32 | Scalar::F64);
        if integral && v.fract() != 0.0 {
            return Err(self.error(format!("expected an integer, found {v}")));
        }
        Ok(v)
    }

    fn error(&self, reason: String) -> Error {
        Error::parse(self.file, self.line, reason)
    }

    fn remaining(&self) -> usize {
        self.text.len().saturating_sub(self.pos)
    }

    fn end_record(&mut self, what: &str) -> Result<()> {
        let rest = &self.text[self.pos..];
        let line_end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
        if rest[..line_end].iter().all(u8::is_ascii_whitespace) {
            return Ok(());
        }
        Err(self.error(format!("{what} has more values than the header declares")))
    }
}

/// Reads a list's length, bounded by the bytes left so that a corrupt count fails at once.
fn list_len(src: &mut impl Source, count: Scalar, item: Scalar, what: &str) -> Result<usize> {
    let v = src.value(count)?;
    let Some(n) = to_u32(v) else {
        return Err(src.error(format!("{what} has list length {v}")));
    };
    let n = n as usize;
    if n.saturating_mul(item.size().min(2)) > src.remaining() {
        return Err(src.error(format!("{what} has list length {n}, past the end of the file")));
    }
    Ok(n)
}

fn skip_property(src: &mut impl Source, kind: PropKind, what: &str) -> Result<()> {
    match kind {
        PropKind::Scalar(ty) => {
            src.value(ty)?;
        }
        PropKind::List { count, item } => {
            for _ in 0..list_len(src, count, item, what)? {
                src.value(item)?;
            }
        }
    }
    Ok(())
}

/// What a vertex property feeds.
#[derive(Clone, Copy)]
enum VertexRole {
    Position(usize),
    Normal(usize),
    Uv(usize),
    Patch,
    Skip,
}

/// What a face property feeds.
#[derive(Clone, Copy)]
enum FaceRole {
    Indices,
    Patch,
    TexCoord,
    Skip,
}

fn read_ply_body(header: &PlyHeader, src: &mut impl Source, file: &Path) -> Result<Mesh> {
    let Some(vertex) = header.elements.iter().find(|e| e.name == "vertex") else {
        return Err(Error::parse(file, 0, "PLY header declares no vertex element"));
    };
    let vertex_count = vertex.count;
    let mut mesh = Mesh::default();
    // Whether each face so far carried per-corner params; decided once all faces are read.
    let mut corner_params: Option<Vec<[f32; 2]>> = None;
    for element in &header.elements {
        let what = |i: u64| format!("{} {i}", element.name);
        if element.props.is_empty() {
            // Nothing to read, however large the count: skipping it must not loop.
            continue;
        }
        if header.encoding != Encoding::Ascii {
            let need = element.count.saturating_mul(element.min_record_bytes(header.encoding) as u64);
            if need > src.remaining() as u64 {
                return Err(src.error(format!(
                    "element {} declares {} records needing at least {need} bytes, but only {} \
                     remain",
                    element.name,
                    element.count,
                    src.remaining()
                )));
            }
        }
        match element.name.as_str() {
            "vertex" => read_ply_vertices(element, header.encoding, src, file, &mut mesh)?,
            "face" => {
                corner_params = read_ply_faces(element, header.encoding, vertex_count, src, file, &mut mesh)?;
            }
            "tristrips" => read_ply_strips(element, vertex_count, src, &mut mesh)?,
            _ => {
                for i in 0..element.count {
                    for p in &element.props {
                        skip_property(src, p.kind, &what(i))?;
                    }
                    src.end_record(&what(i))?;
                }
            }
        }
    }
    mesh.corner_params = corner_params;
    if let Some(strips) = &mesh.strips {
        if !header.elements.iter().any(|e| e.name == "face") {
            // Strips only: the decoded list becomes the triangles.
            let tris = crate::mesh::strips::decode(strips);
            mesh.indices = tris.iter().flatten().copied().collect();
            mesh.triangle_patch = vec![0; tris.len()];
        }
    }
    fill_missing(&mut mesh);
    Ok(mesh)
}

/// Reads the Stanford `tristrips` element (`vertex_indices` lists, `-1` between strips) into
/// [`Mesh::strips`], records joined by a restart.
fn read_ply_strips(
    element: &Element,
    vertex_count: u64,
    src: &mut impl Source,
    mesh: &mut Mesh,
) -> Result<()> {
    let restart = crate::mesh::strips::RESTART;
    let mut strips: Vec<u32> = Vec::new();
    for i in 0..element.count {
        let what = format!("tristrips {i}");
        for prop in &element.props {
            match (prop.name.as_str(), prop.kind) {
                ("vertex_indices", PropKind::List { count, item }) => {
                    if !strips.is_empty() && strips.last() != Some(&restart) {
                        strips.push(restart);
                    }
                    for _ in 0..list_len(src, count, item, &what)? {
                        let v = src.value(item)?;
                        if v == -1.0 {
                            strips.push(restart);
                            continue;
                        }
                        match to_u32(v) {
                            Some(k) if u64::from(k) < vertex_count => strips.push(k),
                            _ => {
                                return Err(src.error(format!(
                                "tristrips {i} refers to vertex {v}, but there are {vertex_count} vertices"
                            )))
                            }
                        }
                    }
                }
                _ => skip_property(src, prop.kind, &what)?,
            }
        }
        src.end_record(&what)?;
    }
    mesh.strips = Some(strips);
    Ok(())
}

fn read_ply_vertices(
    element: &Element,
    encoding: Encoding,
    src: &mut impl Source,
    file: &Path,
    mesh: &mut Mesh,
) -> Result<()> {
    let mut roles = Vec::with_capacity(element.props.len());
    let (mut has_normal, mut has_uv, mut has_patch, mut has_xyz) = (false, false, false, [false; 3]);
    for p in &element.props {
        let role = match p.name.as_str() {
            "x" => VertexRole::Position(0),
            "y" => VertexRole::Position(1),
            "z" => VertexRole::Position(2),
            "nx" => VertexRole::Normal(0),
            "ny" => VertexRole::Normal(1),
            "nz" => VertexRole::Normal(2),
            "u" | "s" | "texture_u" => VertexRole::Uv(0),
            "v" | "t" | "texture_v" => VertexRole::Uv(1),
            "patch" => VertexRole::Patch,
            _ => VertexRole::Skip,
        };
        if !matches!(role, VertexRole::Skip) && matches!(p.kind, PropKind::List { .. }) {
            return Err(Error::parse(file, p.line, format!("vertex property {} must not be a list", p.name)));
        }
        match role {
            VertexRole::Position(k) => has_xyz[k] = true,
            VertexRole::Normal(_) => has_normal = true,
            VertexRole::Uv(_) => has_uv = true,
            VertexRole::Patch => has_patch = true,
            VertexRole::Skip => {}
        }
        roles.push(role);
    }
    if let Some(k) = has_xyz.iter().position(|&h| !h) {
        return Err(Error::parse(
            file,
            element.line,
            format!("vertex element has no property {}", ["x", "y", "z"][k]),
        ));
    }
    let cap = element.capacity(encoding, src.remaining(), 1);
    mesh.positions.reserve(cap);
    if has_normal {
        mesh.normals.reserve(cap);
    }
    if has_uv {
        mesh.uvs.reserve(cap);
    }
    if has_patch {
        mesh.vertex_patch.reserve(cap);
    }
    for i in 0..element.count {
        let (mut p, mut n, mut uv, mut patch) = ([0f32; 3], [0f32; 3], [0f32; 2], 0u32);
        for (prop, &role) in element.props.iter().zip(&roles) {
            let PropKind::Scalar(ty) = prop.kind else {
                skip_property(src, prop.kind, &format!("vertex {i}"))?;
                continue;
            };
            let v = src.value(ty)?;
            match role {
                VertexRole::Position(k) => p[k] = v as f32,
                VertexRole::Normal(k) => n[k] = v as f32,
                VertexRole::Uv(k) => uv[k] = v as f32,
                VertexRole::Patch => {
                    patch = to_u32(v).ok_or_else(|| src.error(format!("vertex {i} has patch id {v}")))?;
                }
                VertexRole::Skip => {}
            }
        }
        src.end_record(&format!("vertex {i}"))?;
        // Checked after the record so the error names all of it; `as f32` turned values past
        // the f32 range into infinities, which this catches too.
        if !all_finite(&p) || !all_finite(&n) || !all_finite(&uv) {
            return Err(src.error(format!(
                "vertex {i} has a non-finite value (position {p:?}, normal {n:?}, uv {uv:?})"
            )));
        }
        mesh.positions.push(p);
        if has_normal {
            mesh.normals.push(n);
        }
        if has_uv {
            mesh.uvs.push(uv);
        }
        if has_patch {
            mesh.vertex_patch.push(patch);
        }
    }
    Ok(())
}

/// Reads the face element into `mesh`'s indices and triangle patches; returns the corner
/// params when every face carried a full `texcoord` list.
fn read_ply_faces(
    element: &Element,
    encoding: Encoding,
    vertex_count: u64,
    src: &mut impl Source,
    file: &Path,
    mesh: &mut Mesh,
) -> Result<Option<Vec<[f32; 2]>>> {
    let mut roles = Vec::with_capacity(element.props.len());
    let mut has_indices = false;
    let mut has_texcoord = false;
    for p in &element.props {
        let role = match (p.name.as_str(), p.kind) {
            ("vertex_indices" | "vertex_index", PropKind::List { .. }) => FaceRole::Indices,
            ("patch", PropKind::Scalar(_)) => FaceRole::Patch,
            ("texcoord", PropKind::List { .. }) => FaceRole::TexCoord,
            ("vertex_indices" | "vertex_index" | "patch" | "texcoord", _) => {
                return Err(Error::parse(
                    file,
                    p.line,
                    format!("face property {} has the wrong shape (list or scalar)", p.name),
                ));
            }
            _ => FaceRole::Skip,
        };
        has_indices |= matches!(role, FaceRole::Indices);
        has_texcoord |= matches!(role, FaceRole::TexCoord);
        roles.push(role);
    }
    if !has_indices {
        return Err(Error::parse(file, element.line, "face element has no vertex_indices list"));
    }
    let cap = element.capacity(encoding, src.remaining(), 1);
    mesh.indices.reserve(cap.saturating_mul(3));
    mesh.triangle_patch.reserve(cap);
    let mut params = if has_texcoord { Some(Vec::with_capacity(cap * 3)) } else { None };
    let mut polygon: Vec<u32> = Vec::new();
    let mut texcoord: Vec<f32> = Vec::new();
    for i in 0..element.count {
        polygon.clear();
        texcoord.clear();
        let mut patch = 0u32;
        let what = format!("face {i}");
        for (prop, &role) in element.props.iter().zip(&roles) {
            match (role, prop.kind) {
                (FaceRole::Indices, PropKind::List { count, item }) => {
                    for _ in 0..list_len(src, count, item, &what)? {
                        let v = src.value(item)?;
                        match to_u32(v) {
                            Some(k) if u64::from(k) < vertex_count => polygon.push(k),
                            _ => {
                                return Err(src.error(format!(
                                    "face {i} refers to vertex {v}, but there are {vertex_count} \
                                     vertices"
                                )))
                            }
                        }
                    }
                }
                (FaceRole::TexCoord, PropKind::List { count, item }) => {
                    for _ in 0..list_len(src, count, item, &what)? {
                        texcoord.push(src.value(item)? as f32);
                    }
                }
                (FaceRole::Patch, PropKind::Scalar(ty)) => {
                    let v = src.value(ty)?;
                    patch = to_u32(v).ok_or_else(|| src.error(format!("face {i} has patch id {v}")))?;
                }
                _ => skip_property(src, prop.kind, &what)?,
            }
        }
        src.end_record(&what)?;
        let n = polygon.len();
        if n < 3 {
            return Err(src.error(format!("face {i} has {n} vertices; at least 3 are needed")));
        }
        if let Some(out) = &mut params {
            if texcoord.is_empty() {
                // One face without params makes the whole set unusable.
                params = None;
            } else if texcoord.len() != 2 * n {
                return Err(
                    src.error(format!("face {i} has {} texcoord values for {n} corners", texcoord.len()))
                );
            } else if !all_finite(&texcoord) {
                return Err(src.error(format!("face {i} has a non-finite texcoord")));
            } else {
                let corner = |k: usize| [texcoord[2 * k], texcoord[2 * k + 1]];
                for k in 1..n - 1 {
                    out.extend([corner(0), corner(k), corner(k + 1)]);
                }
            }
        }
        // A fan keeps the polygon's orientation; exact for the convex polygons PLY writers emit.
        for k in 1..n - 1 {
            mesh.indices.extend([polygon[0], polygon[k], polygon[k + 1]]);
            mesh.triangle_patch.push(patch);
        }
    }
    Ok(params)
}

// =============================================================================================
// STL

/// Size of a binary STL header plus the triangle count.
const STL_HEADER: usize = 84;
/// Size of one binary STL triangle record.
const STL_RECORD: usize = 50;

/// Parses STL `data`, binary or ASCII; `file` only labels errors. Binary is assumed when the
/// size matches the header's triangle count or the file does not start with `solid`.
/// See [`read_mesh`] for welding and what is filled in.
///
/// Preconditions: none; any bytes give a mesh or an error.
///
/// Cost: O(`data.len()`) expected time (one hash lookup per corner); memory proportional to
/// the triangles present, never to a header count the data cannot back.
pub fn parse_stl(data: &[u8], file: &Path) -> Result<Mesh> {
    let declared = data.get(80..STL_HEADER).map(|b| u64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])));
    let binary_len = declared.map(|n| STL_HEADER as u64 + STL_RECORD as u64 * n);
    let starts_solid = {
        let text = data.trim_ascii_start();
        text.len() >= 5 && text[..5].eq_ignore_ascii_case(b"solid")
    };
    // "solid" also starts the header of some binary files, so an exact binary size wins.
    if binary_len != Some(data.len() as u64) && starts_solid {
        return parse_stl_ascii(data, file);
    }
    let (Some(count), Some(need)) = (declared, binary_len) else {
        return Err(Error::parse(
            file,
            0,
            format!("file is {} bytes, shorter than the {STL_HEADER}-byte binary STL header", data.len()),
        ));
    };
    if need > data.len() as u64 {
        return Err(Error::parse(
            file,
            0,
            format!(
                "binary STL header at byte offset 80 declares {count} triangles needing {need} \
                 bytes, but the file has {}",
                data.len()
            ),
        ));
    }
    let mut welder = Welder::with_capacity(count as usize);
    for (t, record) in data[STL_HEADER..need as usize].chunks_exact(STL_RECORD).enumerate() {
        let f = |k: usize| {
            let b = &record[4 * k..4 * k + 4];
            f32::from_le_bytes([b[0], b[1], b[2], b[3]])
        };
        for corner in 0..3 {
            // Floats 0..3 are the facet normal, which is derived data and not kept.
            let base = 3 + 3 * corner;
            let p = [f(base), f(base + 1), f(base + 2)];
            let offset = STL_HEADER + STL_RECORD * t + 4 * base;
            welder.push(p).map_err(|reason| {
                Error::parse(file, 0, format!("triangle {t}: {reason} at byte offset {offset}"))
            })?;
        }
    }
    Ok(welder.finish())
}

/// Merges equal corner positions into shared vertices.
struct Welder {
    mesh: Mesh,
    ids: HashMap<[u32; 3], u32>,
}

impl Welder {
    fn with_capacity(triangles: usize) -> Welder {
        let mut mesh = Mesh::default();
        mesh.indices.reserve(triangles.saturating_mul(3));
        // Closed meshes have about half as many vertices as triangles.
        mesh.positions.reserve(triangles / 2);
        Welder { mesh, ids: HashMap::with_capacity(triangles / 2) }
    }

    fn push(&mut self, p: [f32; 3]) -> std::result::Result<(), String> {
        if !all_finite(&p) {
            return Err(format!("non-finite vertex {p:?}"));
        }
        // Adding +0.0 turns -0.0 into +0.0, so the two zeros weld.
        let key = p.map(|c| (c + 0.0).to_bits());
        let next = self.mesh.positions.len();
        let id = match self.ids.get(&key) {
            Some(&id) => id,
            None => {
                let id = u32::try_from(next).map_err(|_| "more than 2^32 distinct vertices".to_string())?;
                self.ids.insert(key, id);
                self.mesh.positions.push(p);
                id
            }
        };
        self.mesh.indices.push(id);
        Ok(())
    }

    fn finish(mut self) -> Mesh {
        fill_missing(&mut self.mesh);
        self.mesh
    }
}

fn parse_stl_ascii(data: &[u8], file: &Path) -> Result<Mesh> {
    #[derive(PartialEq)]
    enum State {
        /// Between solids: expect `solid` or the end of the file.
        Outside,
        /// Inside a solid: expect `facet` or `endsolid`.
        Solid,
        /// After `facet`: expect `outer loop`.
        Facet,
        /// Inside a loop: expect `vertex` or `endloop`.
        Loop,
        /// After `endloop`: expect `endfacet`.
        EndLoop,
    }
    let mut state = State::Outside;
    let mut solids = 0usize;
    let mut corners = 0usize;
    // Each facet takes well over 100 bytes of text; the bound only limits preallocation.
    let mut welder = Welder::with_capacity(data.len() / 100);
    let mut line_no = 0;
    // Without the final newline, split would yield one empty line past the end of the file.
    let text = data.strip_suffix(b"\n").unwrap_or(data);
    for raw in text.split(|&b| b == b'\n') {
        line_no += 1;
        let err = |reason: String| Error::parse(file, line_no, reason);
        let Ok(line) = std::str::from_utf8(raw) else {
            return Err(err("line is not valid UTF-8".into()));
        };
        let mut tokens = line.split_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let keyword = keyword.to_ascii_lowercase();
        match (&state, keyword.as_str()) {
            (State::Outside, "solid") => {
                state = State::Solid;
                solids += 1;
            }
            (State::Solid, "facet") => state = State::Facet,
            (State::Solid, "endsolid") => state = State::Outside,
            (State::Facet, "outer") => {
                if !tokens.next().is_some_and(|t| t.eq_ignore_ascii_case("loop")) {
                    return Err(err("expected \"outer loop\"".into()));
                }
                state = State::Loop;
                corners = 0;
            }
            (State::Loop, "vertex") => {
                let coords: Vec<&str> = tokens.collect();
                let parsed: Vec<f32> = coords.iter().filter_map(|t| t.parse().ok()).collect();
                if coords.len() != 3 || parsed.len() != 3 {
                    return Err(err(format!("expected 3 numbers after vertex, found {coords:?}")));
                }
                corners += 1;
                if corners > 3 {
                    return Err(err("facet has more than 3 vertices".into()));
                }
                welder.push([parsed[0], parsed[1], parsed[2]]).map_err(err)?;
            }
            (State::Loop, "endloop") => {
                if corners != 3 {
                    return Err(err(format!("facet has {corners} vertices; 3 are needed")));
                }
                state = State::EndLoop;
            }
            (State::EndLoop, "endfacet") => state = State::Solid,
            _ => {
                let expected = match state {
                    State::Outside => "solid",
                    State::Solid => "facet or endsolid",
                    State::Facet => "outer loop",
                    State::Loop => "vertex or endloop",
                    State::EndLoop => "endfacet",
                };
                return Err(err(format!("expected {expected}, found {keyword:?}")));
            }
        }
    }
    if state != State::Outside || solids == 0 {
        return Err(Error::parse(file, line_no, "file ends inside a solid (missing endsolid); truncated?"));
    }
    Ok(welder.finish())
}

// =============================================================================================
// GLB

const GLB_MAGIC: &[u8; 4] = b"glTF";
const GLB_CHUNK_JSON: u32 = u32::from_le_bytes(*b"JSON");
const GLB_CHUNK_BIN: u32 = u32::from_le_bytes(*b"BIN\0");

/// Parses glTF binary `data`; `file` only labels errors. Reads the layout `write_glb`
/// produces; see [`read_mesh`] for what else is accepted and what is filled in.
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
        if let Some(index) = attribute(Semantic::TexCoords(0)) {
            mesh.uvs = self.floats::<2>(index, "TEXCOORD_0", Type::Vec2)?;
            self.check_count("TEXCOORD_0", mesh.uvs.len(), n)?;
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

    /// Reads tessera's triangle patches and corner params from the views the primitive's
    /// extras name.
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
        let view_of =
            |key: &str| -> Result<Option<usize>> {
                match tessera.get(key) {
                    None => Ok(None),
                    Some(v) => v.as_u64().and_then(|v| usize::try_from(v).ok()).map(Some).ok_or_else(|| {
                        self.err(format!("extras.tessera.{key} is {v}, not a buffer view index"))
                    }),
                }
            };
        let t = mesh.indices.len() / 3;
        if let Some(view) = view_of("trianglePatchView")? {
            let bytes = self.view_bytes(view, "trianglePatchView")?;
            if bytes.len() != 4 * t {
                return Err(self
                    .err(format!("triangle patch view {view} has {} bytes for {t} triangles", bytes.len())));
            }
            mesh.triangle_patch =
                bytes.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        }
        if let Some(view) = view_of("cornerParamsView")? {
            let bytes = self.view_bytes(view, "cornerParamsView")?;
            if bytes.len() != 24 * t {
                return Err(self
                    .err(format!("corner params view {view} has {} bytes for {t} triangles", bytes.len())));
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
        let buffer_index = view.buffer.value();
        let Some(buffer) = self.root.buffers.get(buffer_index) else {
            return Err(self.err(format!("buffer view {index} refers to missing buffer")));
        };
        if buffer_index != 0 || buffer.uri.is_some() {
            return Err(self.unsupported(format!(
                "buffer view {index} uses an external buffer; only the GLB's own is read"
            )));
        }
        let Some((bin, bin_offset)) = self.bin else {
            return Err(self.err(format!("buffer view {index} needs a BIN chunk, but there is none")));
        };
        let start = view.byte_offset.map_or(0, |o| o.0);
        let len = view.byte_length.0;
        let end = start.checked_add(len);
        if buffer.byte_length.0 > bin.len() as u64 || end.is_none_or(|e| e > buffer.byte_length.0) {
            return Err(self.err(format!(
                "buffer view {index} spans bytes {start}..{} of a {}-byte buffer (BIN chunk of {} \
                 bytes at byte offset {bin_offset})",
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::write::tests::{glb_chunks, grid};
    use crate::mesh::write::{write_glb, write_mesh, write_ply, write_stl};

    fn bytes(f: impl FnOnce(&mut Vec<u8>) -> Result<()>) -> Vec<u8> {
        let mut out = Vec::new();
        f(&mut out).expect("writing to memory succeeds");
        out
    }

    fn label() -> &'static Path {
        Path::new("<test>")
    }

    /// The location and reason of a parse error, failing the test on anything else.
    fn parse_error(r: Result<Mesh>) -> (usize, String) {
        match r {
            Err(Error::Parse { at, reason }) => {
                assert_eq!(at.file, label());
                (at.line, reason)
            }
            other => panic!("expected a parse error, got {other:?}"),
        }
    }

    /// Every strict prefix of `data` must give an error (when `all_fail`) and never panic.
    fn check_truncations(data: &[u8], parse: fn(&[u8], &Path) -> Result<Mesh>, all_fail: bool) {
        assert!(parse(data, label()).is_ok());
        for len in 0..data.len() {
            let r = parse(&data[..len], label());
            if all_fail {
                assert!(r.is_err(), "prefix of {len} bytes parsed");
            }
        }
    }

    /// Corrupting any single byte must not panic, whatever the result.
    fn check_corruptions(data: &[u8], parse: fn(&[u8], &Path) -> Result<Mesh>) {
        let mut copy = data.to_vec();
        for i in 0..data.len() {
            for value in [data[i] ^ 0xff, 0, b'9'] {
                copy[i] = value;
                let _ = parse(&copy, label());
            }
            copy[i] = data[i];
        }
    }

    #[test]
    fn ply_round_trip() {
        for with_params in [false, true] {
            let mesh = grid(4, with_params);
            let read = parse_ply(&bytes(|w| write_ply(&mesh, w)), label()).unwrap();
            assert_eq!(read, mesh);
        }
        let empty = Mesh::default();
        assert_eq!(parse_ply(&bytes(|w| write_ply(&empty, w)), label()).unwrap(), empty);
    }

    #[test]
    fn stl_round_trip_up_to_welding() {
        let mesh = grid(4, false);
        let read = parse_stl(&bytes(|w| write_stl(&mesh, w)), label()).unwrap();
        assert_eq!(read.vertex_count(), mesh.vertex_count(), "all grid positions are distinct");
        assert_eq!(read.indices.len(), mesh.indices.len());
        for (a, b) in read.indices.iter().zip(&mesh.indices) {
            assert_eq!(read.positions[*a as usize], mesh.positions[*b as usize]);
        }
        assert_eq!(read.normals, vec![[0.0; 3]; read.vertex_count()]);
        assert_eq!(read.uvs, vec![[0.0; 2]; read.vertex_count()]);
        assert_eq!(read.vertex_patch, vec![0; read.vertex_count()]);
        assert_eq!(read.triangle_patch, vec![0; read.triangle_count()]);
        assert_eq!(read.corner_params, None);
    }

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

    #[test]
    fn read_mesh_dispatches_by_extension_and_names_the_file() {
        let dir = std::env::temp_dir().join(format!("tessera-read-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = grid(3, true);
        for name in ["m.ply", "m.GLB"] {
            let path = dir.join(name);
            write_mesh(&mesh, &path).unwrap();
            assert_eq!(read_mesh(&path).unwrap(), mesh, "{name}");
        }
        let stl = dir.join("m.Stl");
        write_mesh(&mesh, &stl).unwrap();
        assert_eq!(read_mesh(&stl).unwrap().triangle_count(), mesh.triangle_count());

        let err = read_mesh(&dir.join("m.obj")).unwrap_err();
        assert!(matches!(&err, Error::InvalidArgument(m) if m.contains(".ply, .stl, .glb")), "{err}");
        let missing = dir.join("absent.ply");
        assert!(matches!(read_mesh(&missing), Err(Error::Io { path, .. }) if path == missing));
        let broken = dir.join("broken.ply");
        std::fs::write(&broken, "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n")
            .unwrap();
        match read_mesh(&broken) {
            Err(Error::Parse { at, reason }) => {
                assert_eq!(at.file, broken);
                assert_eq!(at.line, 3);
                assert!(reason.contains("no property y"), "{reason}");
            }
            other => panic!("{other:?}"),
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    const ASCII_PLY: &str = "ply\r
format ascii 1.0\r
comment made by hand\r
element vertex 5\r
property float confidence\r
property double z\r
property float x\r
property float y\r
property list uchar int junk\r
property float s\r
property float t\r
property uchar patch\r
property float nz\r
property float nx\r
property float ny\r
element edge 1\r
property int vertex1\r
property int vertex2\r
element face 2\r
property int patch\r
property list uchar float texcoord\r
property list uchar uint vertex_index\r
end_header\r
0.5 0 0 0 2 7 7 0 0 3 1 0 0\r
0.5 0 1 0 0 1 0 5 1 0 0\r
0.5 0 1 1 1 9 1 1 4 1 0 0\r
0.5 0 0 1 0 0 1 4 1 0 0\r
0.5 2.5 0.5 0.5 0 0.5 0.5 9 0.6 0.8 0\r
0 1\r
6 8 0 0 1 0 1 1 0 1 4 0 1 2 3\r
9 6 0.5 0.5 1 0 1 1 3 4 2 1\r
";

    #[test]
    fn ascii_ply_with_other_layout() {
        let mesh = parse_ply(ASCII_PLY.as_bytes(), label()).unwrap();
        assert_eq!(
            mesh.positions,
            [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [0.5, 0.5, 2.5]]
        );
        assert_eq!(mesh.normals[0], [0.0, 0.0, 1.0]);
        assert_eq!(mesh.normals[4], [0.8, 0.0, 0.6]);
        assert_eq!(mesh.uvs[1], [1.0, 0.0]);
        assert_eq!(mesh.vertex_patch, [3, 5, 4, 4, 9]);
        // The quad becomes a fan of two triangles.
        assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3, 4, 2, 1]);
        assert_eq!(mesh.triangle_patch, [6, 6, 9]);
        let params = mesh.corner_params.unwrap();
        assert_eq!(params[..3], [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
        assert_eq!(params[3..6], [[0.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        assert_eq!(params[6..], [[0.5, 0.5], [1.0, 0.0], [1.0, 1.0]]);
    }

    #[test]
    fn ascii_ply_errors_name_the_line() {
        let replace = |from: &str, to: &str| ASCII_PLY.replacen(from, to, 1);
        let cases = [
            (replace("0.5 0 1 0 0 1", "0.5 0 1 x 0 1"), 25, "expected a number"),
            (replace("0.5 0 1 0 0 1", "0.5 0 1 nan 0 1"), 25, "non-finite"),
            (replace("3 4 2 1\r", "3 4 2 5\r"), 31, "refers to vertex 5"),
            (replace("3 4 2 1\r", "2 4 2\r"), 31, "2 vertices"),
            (replace("4 0 1 2 3", "4 0 1 2 3.5"), 30, "expected an integer"),
            (replace("6 8 0 0 1 0 1 1 0 1 4", "6 6 0 0 1 0 1 1 4"), 30, "6 texcoord values for 4 corners"),
            (replace("9 6 0.5", "-9 6 0.5"), 31, "patch id -9"),
            (replace("format ascii", "format asci"), 2, "unknown PLY format"),
            (replace("property float s\r", "property flt s\r"), 10, "unknown property type"),
            (replace("end_header", "end_headr"), 23, "unexpected header line"),
            (replace("ply", "plx"), 1, "not a PLY file"),
            (
                replace("0.5 0 1 0 0 1 0 5 1 0 0\r", "0.5 0 1 0 0 1 0 5 1 0 0 0\r"),
                25,
                "vertex 1 has more values",
            ),
            (replace("0 1\r", "0 1 2\r"), 29, "edge 0 has more values"),
            (ASCII_PLY[..ASCII_PLY.len() - 5].to_string(), 31, "past the end"),
            (ASCII_PLY[..ASCII_PLY.find("0.5 0 1 1 1 9").unwrap() + 7].to_string(), 26, "file ends"),
        ];
        for (text, line, expected) in cases {
            let (at, reason) = parse_error(parse_ply(text.as_bytes(), label()));
            assert!(reason.contains(expected), "{reason:?} lacks {expected:?}");
            assert_eq!(at, line, "{reason}");
        }
        // A face without texcoord makes the corner params unusable, not an error.
        let mesh = parse_ply(replace("6 8 0 0 1 0 1 1 0 1", "6 0").as_bytes(), label()).unwrap();
        assert_eq!(mesh.corner_params, None);
        assert_eq!(mesh.triangle_count(), 3);
    }

    #[test]
    fn big_endian_ply_with_doubles() {
        let mut data = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\n\
            property double y\nproperty double z\nelement face 1\nproperty list ushort int vertex_indices\nend_header\n"
            .to_vec();
        for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.25]] {
            for c in p {
                data.extend(c.to_be_bytes());
            }
        }
        data.extend(3u16.to_be_bytes());
        for i in [0i32, 1, 2] {
            data.extend(i.to_be_bytes());
        }
        let mesh = parse_ply(&data, label()).unwrap();
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.25]]);
        assert_eq!(mesh.indices, [0, 1, 2]);
        assert_eq!(mesh.normals, [[0.0; 3]; 3]);
        assert_eq!(mesh.triangle_patch, [0]);
        check_truncations(&data, parse_ply, true);
    }

    /// Offset of the first body byte of a PLY written by write_ply.
    fn ply_body(data: &[u8]) -> usize {
        data.windows(11).position(|w| w == b"end_header\n").unwrap() + 11
    }

    #[test]
    fn binary_ply_errors_give_byte_offsets() {
        let mesh = grid(2, true);
        let data = bytes(|w| write_ply(&mesh, w));
        let body = ply_body(&data);
        let faces = body + 36 * mesh.vertex_count();

        let mut bad = data.clone();
        bad[faces + 1..faces + 5].copy_from_slice(&99u32.to_le_bytes());
        let (line, reason) = parse_error(parse_ply(&bad, label()));
        assert_eq!(line, 0);
        assert!(reason.contains("face 0 refers to vertex 99") && reason.contains("byte offset"), "{reason}");

        let mut bad = data.clone();
        bad[body + 36 + 4..body + 36 + 8].copy_from_slice(&f32::INFINITY.to_le_bytes());
        let (_, reason) = parse_error(parse_ply(&bad, label()));
        assert!(reason.contains("vertex 1 has a non-finite value"), "{reason}");

        let mut bad = data.clone();
        bad[faces + 17] = 5;
        let (_, reason) = parse_error(parse_ply(&bad, label()));
        assert!(reason.contains("5 texcoord values for 3 corners"), "{reason}");
    }

    #[test]
    fn lying_ply_counts_fail_fast_without_huge_allocations() {
        let text = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000000\nproperty float x\n\
                    property float y\nproperty float z\nend_header\n\0\0\0\0";
        let (_, reason) = parse_error(parse_ply(text.as_bytes(), label()));
        assert!(reason.contains("needing at least"), "{reason}");
        let text = "ply\nformat ascii 1.0\nelement vertex 4000000000000\nproperty float x\n\
                    property float y\nproperty float z\nend_header\n1 2 3\n";
        let (line, reason) = parse_error(parse_ply(text.as_bytes(), label()));
        assert!(reason.contains("file ends"), "{reason}");
        assert_eq!(line, 8);
        // An element without properties takes no bytes: a huge count must not loop.
        let text = "ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
                    property float y\nproperty float z\nelement void 18446744073709551615\nend_header\n";
        assert_eq!(parse_ply(text.as_bytes(), label()).unwrap(), Mesh::default());
        // A list length past the end of the file.
        let mut data = b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
            property float y\nproperty float z\nelement face 1\nproperty list uint uint vertex_indices\nend_header\n"
            .to_vec();
        data.extend(u32::MAX.to_le_bytes());
        let (_, reason) = parse_error(parse_ply(&data, label()));
        assert!(reason.contains("past the end"), "{reason}");
    }

    #[test]
    fn ply_truncation_and_corruption_never_panic() {
        let data = bytes(|w| write_ply(&grid(2, true), w));
        check_truncations(&data, parse_ply, true);
        check_corruptions(&data, parse_ply);
        check_truncations(ASCII_PLY.as_bytes(), parse_ply, false);
        check_corruptions(ASCII_PLY.as_bytes(), parse_ply);
    }

    const ASCII_STL: &str = "solid square
  facet normal 0 0 1
    outer loop
      vertex 0 0 0
      vertex 1 0 0
      vertex 1 1 0
    endloop
  endfacet
  FACET NORMAL 0 0 1
    OUTER LOOP
      VERTEX 0 0 -0
      VERTEX 1 1 0
      VERTEX 0 1 0
    ENDLOOP
  ENDFACET
endsolid square
solid second

endsolid
";

    #[test]
    fn ascii_stl_is_welded() {
        let mesh = parse_stl(ASCII_STL.as_bytes(), label()).unwrap();
        assert_eq!(mesh.positions, [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        assert_eq!(mesh.indices, [0, 1, 2, 0, 2, 3], "-0 welds with 0");
        assert_eq!(mesh.triangle_patch, [0, 0]);
    }

    #[test]
    fn ascii_stl_errors_name_the_line() {
        let replace = |from: &str, to: &str| ASCII_STL.replacen(from, to, 1);
        let cases = [
            (replace("vertex 1 0 0", "vertex 1 0"), 5, "expected 3 numbers"),
            (replace("vertex 1 0 0", "vertex 1 0 inf"), 5, "non-finite"),
            (replace("vertex 1 0 0", "vertex 1 0 0\nvertex 2 2 2"), 7, "more than 3"),
            (replace("      vertex 1 1 0\n", ""), 6, "2 vertices"),
            (replace("outer loop", "outer lop"), 3, "outer loop"),
            (replace("endfacet", "endfacets"), 8, "expected endfacet"),
            (ASCII_STL[..ASCII_STL.len() - 9].to_string(), 18, "missing endsolid"),
        ];
        for (text, line, expected) in cases {
            let (at, reason) = parse_error(parse_stl(text.as_bytes(), label()));
            assert!(reason.contains(expected), "{reason:?} lacks {expected:?}");
            assert_eq!(at, line, "{reason}");
        }
    }

    #[test]
    fn binary_stl_checks() {
        let mesh = grid(2, false);
        let data = bytes(|w| write_stl(&mesh, w));
        // A binary header that happens to start with "solid" is still binary when the size fits.
        let mut solid = data.clone();
        solid[..7].copy_from_slice(b"solid x");
        assert_eq!(parse_stl(&solid, label()).unwrap(), parse_stl(&data, label()).unwrap());

        let mut lying = data.clone();
        lying[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let (line, reason) = parse_error(parse_stl(&lying, label()));
        assert_eq!(line, 0);
        assert!(reason.contains("4294967295 triangles"), "{reason}");

        let mut nan = data.clone();
        nan[84 + 50 + 16..84 + 50 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
        let (_, reason) = parse_error(parse_stl(&nan, label()));
        assert!(reason.contains("triangle 1") && reason.contains("byte offset 146"), "{reason}");

        let (_, reason) = parse_error(parse_stl(b"tiny", label()));
        assert!(reason.contains("shorter than the 84-byte"), "{reason}");
    }

    #[test]
    fn stl_truncation_and_corruption_never_panic() {
        let data = bytes(|w| write_stl(&grid(2, false), w));
        check_truncations(&data, parse_stl, true);
        check_corruptions(&data, parse_stl);
        check_truncations(ASCII_STL.as_bytes(), parse_stl, false);
        check_corruptions(ASCII_STL.as_bytes(), parse_stl);
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
        let edit = |from: &str, to: &str| {
            assert!(json.contains(from), "{from}");
            glb(&json.replacen(from, to, 1), bin)
        };
        assert!(
            reason(&edit("\"trianglePatchView\":5", "\"trianglePatchView\":50")).contains("buffer view 50")
        );
        assert!(reason(&edit("\"trianglePatchView\":5", "\"trianglePatchView\":\"x\""))
            .contains("not a buffer view"));
        let length = format!("\"byteLength\":{}}}", bin.len());
        assert!(reason(&edit(&length, "\"byteLength\":100000}")).contains("spans bytes"));
        match parse_glb(&edit(&length, &length.replace('}', ",\"uri\":\"x.bin\"}")), label()) {
            Err(Error::Unsupported { reason, .. }) => assert!(reason.contains("external buffer")),
            other => panic!("{other:?}"),
        }
        let mut nan = good.clone();
        let at = good.len() - bin.len();
        nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
        assert!(reason(&nan).contains("POSITION element 0 is not finite"));
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
}
