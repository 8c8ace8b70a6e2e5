//! Stanford PLY: reading (ASCII, binary little- and big-endian) and writing (binary
//! little-endian).
//!
//! **Reading** takes untrusted files: every count, offset and index is checked against the
//! bytes actually present before it is used, so a truncated or lying file gives an [`Error`]
//! naming the file (and, for the header and ASCII bodies, the line; for binary bodies, the byte
//! offset in the reason), never a panic or an allocation sized by a header. The `vertex`
//! element needs `x y z`; it may carry `nx ny nz`, `u v` (or `s t`, `texture_u texture_v`) and
//! `patch`. The `face` element needs `vertex_indices` (or `vertex_index`); it may carry `patch`
//! and the per-corner patch parameters `patch_uv` (or, as tessera wrote them before, `texcoord`;
//! 2 values per corner), which fill [`Mesh::corner_params`] only when every face has them.
//! Other elements and properties, in any order and of any PLY type, are skipped. Polygons are
//! split into triangle fans. In ASCII files each record must end with its line, which catches a
//! header that disagrees with the data. Whatever the file lacks is filled in: zero normals and
//! uvs, patch 0 for vertices and triangles, no corner params.
//!
//! **Writing** ([`write_ply`]) keeps everything a [`Mesh`] holds: positions, normals, uvs and
//! vertex patches per vertex; triangle patches and, when set, corner params per face; and
//! triangle strips ([`Mesh::strips`]) as a `tristrips` element (one `int` list, `-1` between
//! strips) after the face list. The per-corner parameters are called `patch_uv`, not
//! `texcoord`: standard clients (trimesh, MeshLab) read a face `texcoord` list as per-corner
//! texture coordinates and split every vertex into one per corner, so a closed mesh loaded
//! there would have three times the vertices and no longer be watertight.

use std::io::{self, Write};
use std::path::Path;

use super::binary::{
    all_finite, fill_missing, le_floats, le_words, put_u32, to_u32, write_chunks, BIN_CHUNK,
};
use super::Format;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::polygon_mesh::fan;

/// Parses PLY `data` (ASCII or binary, either byte order); `file` only labels errors.
/// See the module documentation for what is read and what is filled in.
///
/// Preconditions: none; any bytes give a mesh or an error. Errors in the header and in ASCII
/// bodies carry the line; errors in binary bodies carry line 0 and the byte offset.
///
/// Cost: O(`data.len()`) time; memory proportional to the mesh, never to header counts that
/// the data cannot back.
pub fn parse_ply(data: &[u8], file: &Path) -> Result<Mesh> {
    parse_ply_counting_polygons(data, file).map(|(mesh, _)| mesh)
}

/// [`parse_ply`], also returning how many faces had more than three corners (split into
/// triangles, fans from their first corner: the rule of every reader), for the repair report.
/// Cost: as [`parse_ply`].
pub fn parse_ply_counting_polygons(data: &[u8], file: &Path) -> Result<(Mesh, usize)> {
    let header = PlyHeader::parse(data, file)?;
    let mut polygons = 0;
    let body = &data[header.body_start..];
    match header.encoding {
        Encoding::Ascii => {
            let mut src = AsciiSource { text: body, pos: 0, line: header.body_line, file };
            read_ply_body(&header, &mut src, file, &mut polygons).map(|mesh| (mesh, polygons))
        }
        Encoding::BinaryLe | Encoding::BinaryBe => {
            let mut src = BinarySource {
                data,
                pos: header.body_start,
                big_endian: header.encoding == Encoding::BinaryBe,
                file,
            };
            read_ply_body(&header, &mut src, file, &mut polygons).map(|mesh| (mesh, polygons))
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

fn read_ply_body(
    header: &PlyHeader,
    src: &mut impl Source,
    file: &Path,
    polygons: &mut usize,
) -> Result<Mesh> {
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
                corner_params =
                    read_ply_faces(element, header.encoding, vertex_count, src, file, &mut mesh, polygons)?;
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
/// params when every face carried a full `patch_uv` list (or `texcoord`, the name tessera
/// wrote before, used only when there is no `patch_uv`: another tool's `texcoord` next to
/// tessera's `patch_uv` is texture data, not patch parameters).
fn read_ply_faces(
    element: &Element,
    encoding: Encoding,
    vertex_count: u64,
    src: &mut impl Source,
    file: &Path,
    mesh: &mut Mesh,
    polygons: &mut usize,
) -> Result<Option<Vec<[f32; 2]>>> {
    let mut roles = Vec::with_capacity(element.props.len());
    let mut has_indices = false;
    let mut has_texcoord = false;
    let params_name = if element.props.iter().any(|p| p.name == PATCH_UV) { PATCH_UV } else { OLD_PATCH_UV };
    for p in &element.props {
        let role = match (p.name.as_str(), p.kind) {
            ("vertex_indices" | "vertex_index", PropKind::List { .. }) => FaceRole::Indices,
            ("patch", PropKind::Scalar(_)) => FaceRole::Patch,
            (name, PropKind::List { .. }) if name == params_name => FaceRole::TexCoord,
            (name, PropKind::Scalar(_)) if name == params_name => {
                return Err(Error::parse(
                    file,
                    p.line,
                    format!("face property {} has the wrong shape (list or scalar)", p.name),
                ));
            }
            ("vertex_indices" | "vertex_index" | "patch", _) => {
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
                return Err(src
                    .error(format!("face {i} has {} {params_name} values for {n} corners", texcoord.len())));
            } else if !all_finite(&texcoord) {
                return Err(src.error(format!("face {i} has a non-finite {params_name}")));
            } else {
                let corner = |k: usize| [texcoord[2 * k], texcoord[2 * k + 1]];
                for t in fan(n) {
                    out.extend(t.map(corner));
                }
            }
        }
        *polygons += usize::from(n > 3);
        for t in fan(n) {
            mesh.indices.extend(t.map(|k| polygon[k]));
            mesh.triangle_patch.push(patch);
        }
    }
    Ok(params)
}

// =============================================================================================
// Writing

/// The face property of the per-corner patch parameters.
const PATCH_UV: &str = "patch_uv";
/// Its name in files tessera wrote before; still read.
const OLD_PATCH_UV: &str = "texcoord";

/// Writes `mesh` as binary little-endian PLY to `w`. Vertex properties: `float x y z`,
/// `float nx ny nz`, `float u v`, `uint patch`; face properties:
/// `list uchar uint vertex_indices`, `uint patch` and, when [`Mesh::corner_params`] is set,
/// `list uchar float patch_uv` with the six values u0 v0 u1 v1 u2 v2 (the corners' parameters
/// in the triangle's own patch; not called `texcoord`, which standard clients read as texture
/// coordinates and split vertices for, see the module documentation).
///
/// Preconditions: as [`write_mesh`](super::write_mesh). I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time, the records filled in parallel chunks on the rayon
/// threads and written in order (the bytes do not depend on the thread count); memory: a few
/// MiB of chunk buffers.
pub fn write_ply<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    super::write_to(mesh, Format::Ply, w)
}

// PLY

pub(super) fn emit_ply<W: Write>(mesh: &Mesh, w: &mut W) -> io::Result<()> {
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
        writeln!(w, "property list uchar float {PATCH_UV}")?;
    }
    if mesh.strips.is_some() {
        // The Stanford `tristrips` convention: one list, strips separated by -1.
        writeln!(w, "element tristrips 1\nproperty list uint int vertex_indices")?;
    }
    writeln!(w, "end_header")?;
    // Fixed-size records, filled in parallel chunks and written in order (binary::write_chunks).
    const VERTEX: usize = 36;
    write_chunks(w, mesh.vertex_count(), BIN_CHUNK, |range, out| {
        out.resize(range.len() * VERTEX, 0);
        for (rec, i) in out.chunks_exact_mut(VERTEX).zip(range) {
            le_floats(&mut rec[0..12], mesh.positions[i]);
            le_floats(&mut rec[12..24], mesh.normals[i]);
            le_floats(&mut rec[24..32], mesh.uvs[i]);
            le_words(&mut rec[32..36], [mesh.vertex_patch[i]]);
        }
    })?;
    // `3 a b c patch`, then `6 u0 v0 u1 v1 u2 v2` with corner params.
    let face = if mesh.corner_params.is_some() { 17 + 25 } else { 17 };
    write_chunks(w, mesh.triangle_count(), BIN_CHUNK, |range, out| {
        out.resize(range.len() * face, 0);
        for (rec, t) in out.chunks_exact_mut(face).zip(range) {
            rec[0] = 3;
            le_words(&mut rec[1..13], mesh.triangle(t));
            le_words(&mut rec[13..17], [mesh.triangle_patch[t]]);
            if let Some(params) = &mesh.corner_params {
                rec[17] = 6;
                let [a, b, c] = [params[3 * t], params[3 * t + 1], params[3 * t + 2]];
                le_floats(&mut rec[18..42], [a[0], a[1], b[0], b[1], c[0], c[1]]);
            }
        }
    })?;
    if let Some(strips) = &mesh.strips {
        put_u32(w, strips.len() as u32)?;
        write_chunks(w, strips.len(), BIN_CHUNK, |range, out| {
            out.extend(strips[range].iter().flat_map(|&i| {
                let v = if i == crate::mesh::strips::RESTART { -1 } else { i as i32 };
                v.to_le_bytes()
            }));
        })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::binary::test_meshes::*;

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
    fn corner_params_under_the_old_name_are_still_read() {
        let mesh = grid(3, true);
        let new = bytes(|w| write_ply(&mesh, w));
        // Same length, so the binary body stays where the header says.
        let end = new.windows(10).position(|w| w == b"end_header").unwrap();
        let header = std::str::from_utf8(&new[..end]).unwrap().replace("float patch_uv", "float texcoord");
        let old = [header.as_bytes(), &new[end..]].concat();
        assert_eq!(parse_ply(&old, label()).unwrap(), mesh);
    }

    #[test]
    fn patch_uv_wins_over_another_tools_texcoord() {
        let text = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                    property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                    property list uchar float texcoord\nproperty list uchar float patch_uv\n\
                    end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 6 9 9 9 9 9 9 6 0 0 1 0 0 1\n";
        let mesh = parse_ply(text.as_bytes(), label()).unwrap();
        assert_eq!(mesh.corner_params, Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]));
        let old_only =
            text.replace("property list uchar float patch_uv\n", "").replace(" 6 0 0 1 0 0 1\n", "\n");
        let mesh = parse_ply(old_only.as_bytes(), label()).unwrap();
        assert_eq!(mesh.corner_params, Some(vec![[9.0, 9.0]; 3]));
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
        assert!(reason.contains("5 patch_uv values for 3 corners"), "{reason}");
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

    #[test]
    fn ply_header_and_size() {
        for with_params in [false, true] {
            let mesh = grid(3, with_params);
            let bytes = bytes(|w| write_ply(&mesh, w));
            let end = bytes.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
            let header = std::str::from_utf8(&bytes[..end]).unwrap();
            assert!(header.starts_with("ply\nformat binary_little_endian 1.0\ncomment tessera\n"));
            assert!(header.contains("element vertex 16\n"));
            assert!(header.contains("element face 18\n"));
            assert!(header.contains("property list uchar uint vertex_indices\nproperty uint patch\n"));
            assert_eq!(header.contains("property list uchar float patch_uv\n"), with_params);
            assert!(!header.contains("texcoord"));
            let face = 1 + 12 + 4 + if with_params { 1 + 24 } else { 0 };
            assert_eq!(bytes.len() - end, 16 * 36 + 18 * face);
        }
    }
}
