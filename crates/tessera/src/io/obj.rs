//! Wavefront OBJ: the reader for polygon meshes (positions, normals and faces), the input of
//! PN triangles and of `tessera check`, and the writer of tessera's OBJ output.
//!
//! The reader is written by hand rather than with `tobj` because `tobj` does not report line
//! numbers, and every input error here must name the file and the line.
//!
//! Supported: `v x y z [w]` (a 4th value `w` or vertex colours after `x y z` are ignored),
//! `vn x y z`, `vt` (ignored, but counted so texture indices can be checked), and `f` with
//! corners `a`, `a/b`, `a//c` or `a/b/c`, including negative (relative) indices. Lines ending
//! in a backslash continue on the next line; `#` starts a comment. OpenSubdiv's tag lines
//! (`t crease …`, `t corner …`, `t hole …`, …) of subdivision cages are read into
//! [`PolygonMesh::tags`] ([`crate::subdivision::tags`]). `o`, `g`, `s`, `usemtl`, `mtllib`, `l`,
//! `p` and unknown statements are ignored.
//!
//! Indices follow the standard rule: a positive index `i` refers to the `i`-th element of
//! its kind defined *so far* (1-based), a negative index `-k` to the `k`-th most recent one.
//! An index that is 0 or refers to an element not yet defined is an error.

use std::io::{self, Write};
use std::path::Path;

use glam::DVec3;

use super::binary::write_chunks;
use super::patches::{quote, read_text};
use super::Format;
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::surface::{PolygonFace, PolygonMesh};

/// Reads and parses the OBJ file at `path`.
///
/// Bytes that are not UTF-8 are replaced, not rejected, so names or comments in another
/// encoding are harmless; inside a number they are reported as a non-number on their line.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read; otherwise as [`parse_obj`].
///
/// Cost: one read of the file plus the parse (O(file size)).
pub fn read_obj(path: &Path) -> Result<PolygonMesh> {
    parse_obj(&read_text(path)?, path)
}

/// Parses OBJ text. `file` is used only in error messages (pass a label such as `<memory>`
/// for text that does not come from a file).
///
/// # Errors
///
/// [`Error::Parse`] with `file` and the 1-based line for a `v`/`vn` with fewer than 3
/// numbers, a non-number, a NaN or infinite coordinate, a `v` coordinate beyond the f32 range
/// of the output mesh, a face with fewer than 3 corners, a malformed corner, or an index that
/// is 0 or refers to an element not defined before that line; [`Error::Unsupported`] (line 0)
/// when the file has no faces.
///
/// Cost: O(text length) time; memory O(mesh size).
pub fn parse_obj(text: &str, file: &Path) -> Result<PolygonMesh> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut mesh = PolygonMesh::default();
    let mut texcoord_count = 0usize;
    let mut physical = text.lines().enumerate();
    let mut joined = String::new();

    while let Some((index, first)) = physical.next() {
        let line = index + 1;
        // A comment never continues onto the next line, even if it ends in a backslash.
        if first.trim_start().starts_with('#') {
            continue;
        }
        let statement: &str = match continued(first) {
            None => first,
            Some(head) => {
                joined.clear();
                joined.push_str(head);
                for (_, next) in physical.by_ref() {
                    joined.push(' ');
                    match continued(next) {
                        Some(part) => joined.push_str(part),
                        None => {
                            joined.push_str(next);
                            break;
                        }
                    }
                }
                &joined
            }
        };
        let statement = statement.split('#').next().unwrap_or("");
        let mut tokens = statement.split_ascii_whitespace();
        let Some(keyword) = tokens.next() else {
            continue;
        };
        let at = At { file, line };
        match keyword {
            "v" => mesh.positions.push(at.vector(&mut tokens, "v")?),
            "vn" => mesh.normals.push(at.vector(&mut tokens, "vn")?),
            "vt" => texcoord_count += 1,
            "t" => mesh.tags.read_line(tokens, file, line)?,
            "f" => {
                let face = at.face(tokens, mesh.positions.len(), texcoord_count, mesh.normals.len())?;
                mesh.faces.push(face);
            }
            // o, g, s, usemtl, mtllib, l, p and anything unknown: not needed here.
            _ => {}
        }
    }

    if mesh.faces.is_empty() {
        return Err(Error::unsupported(file, 0, "no faces"));
    }
    if !mesh.tags.is_empty() {
        let faces: Vec<&[u32]> = mesh.faces.iter().map(|f| f.positions.as_slice()).collect();
        mesh.tags.check(mesh.positions.len(), &faces, file)?;
    }
    Ok(mesh)
}

/// When `line` ends in a backslash (trailing whitespace allowed), the line without it.
fn continued(line: &str) -> Option<&str> {
    line.trim_end().strip_suffix('\\')
}

/// The location of the statement being parsed, and the parsers that report errors there.
#[derive(Clone, Copy)]
struct At<'a> {
    file: &'a Path,
    line: usize,
}

impl At<'_> {
    fn err(self, reason: String) -> Error {
        Error::parse(self.file, self.line, reason)
    }

    /// `x y z` of a `v` or `vn` statement; anything after `z` is ignored.
    fn vector<'t>(self, tokens: &mut impl Iterator<Item = &'t str>, kw: &str) -> Result<DVec3> {
        const NAMES: [&str; 3] = ["x", "y", "z"];
        let mut xyz = [0.0f64; 3];
        for (k, (slot, name)) in xyz.iter_mut().zip(NAMES).enumerate() {
            let Some(token) = tokens.next() else {
                return Err(self.err(format!("`{kw}` needs 3 coordinates `x y z`, found {k}")));
            };
            let value = token.parse::<f64>().map_err(|_| {
                self.err(format!("`{kw}` coordinate {name} is {}, not a number", quote(token)))
            })?;
            if !value.is_finite() {
                let kind = if value.is_nan() { "NaN" } else { "infinite" };
                return Err(self.err(format!("`{kw}` coordinate {name} is {kind} ({})", quote(token))));
            }
            // Output meshes store f32, so a position past its range would come out infinite
            // (normals are only directions and are normalised in f64).
            if kw == "v" && value.abs() > f64::from(f32::MAX) {
                return Err(self.err(format!(
                    "`v` coordinate {name} is {}, beyond the f32 range (±3.4e38) of the output mesh",
                    quote(token)
                )));
            }
            *slot = value;
        }
        Ok(DVec3::from_array(xyz))
    }

    /// The corners of an `f` statement, checked against the element counts so far.
    fn face<'t>(
        self,
        corners: impl Iterator<Item = &'t str>,
        n_positions: usize,
        n_texcoords: usize,
        n_normals: usize,
    ) -> Result<PolygonFace> {
        let mut positions = Vec::with_capacity(4);
        let mut normals = Vec::new();
        let mut all_normals = true;
        for (c, corner) in corners.enumerate() {
            let what = |kind: &str| format!("face corner {} ({}): {kind}", c + 1, quote(corner));
            let mut parts = corner.split('/');
            let p = parts.next().unwrap_or("");
            let t = parts.next().unwrap_or("");
            let n = parts.next().unwrap_or("");
            if parts.next().is_some() {
                return Err(self.err(what("malformed corner: expected `v`, `v/vt`, `v//vn` or `v/vt/vn`")));
            }
            if p.is_empty() {
                return Err(self.err(what("the position index is missing")));
            }
            positions.push(self.index(p, n_positions, "position", "v", &what)?);
            if !t.is_empty() {
                self.index(t, n_texcoords, "texture coordinate", "vt", &what)?;
            }
            if n.is_empty() {
                all_normals = false;
            } else {
                normals.push(self.index(n, n_normals, "normal", "vn", &what)?);
            }
        }
        if positions.len() < 3 {
            return Err(self.err(format!(
                "face has {} corner{}; a face needs at least 3",
                positions.len(),
                if positions.len() == 1 { "" } else { "s" }
            )));
        }
        Ok(PolygonFace { positions, normals: all_normals.then_some(normals), line: self.line })
    }

    /// Resolves one 1-based or negative (relative) index against `count` elements defined so
    /// far, giving a 0-based index.
    fn index(
        self,
        token: &str,
        count: usize,
        name: &str,
        kw: &str,
        what: &dyn Fn(&str) -> String,
    ) -> Result<u32> {
        let i = match token.parse::<i64>() {
            Ok(i) => i,
            // An integer too long for i64 is out of range, not malformed.
            Err(e)
                if matches!(
                    e.kind(),
                    std::num::IntErrorKind::PosOverflow | std::num::IntErrorKind::NegOverflow
                ) =>
            {
                let (s, are) = if count == 1 { ("", "is") } else { ("s", "are") };
                return Err(self.err(what(&format!(
                    "{name} index {token} is out of range: only {count} {name}{s} (`{kw}`) {are} \
                     defined before this line"
                ))));
            }
            Err(_) => {
                return Err(self.err(what(&format!("{name} index {} is not an integer", quote(token)))));
            }
        };
        if i == 0 {
            return Err(self.err(what(&format!(
                "{name} index is 0, but OBJ indices start at 1 (negative ones count back)"
            ))));
        }
        let magnitude = i.unsigned_abs();
        let resolved = match usize::try_from(magnitude) {
            Ok(m) if m <= count => Some(if i > 0 { m - 1 } else { count - m }),
            _ => None,
        };
        match resolved.map(u32::try_from) {
            Some(Ok(r)) => Ok(r),
            Some(Err(_)) => {
                Err(self
                    .err(what(&format!("{name} index {i} exceeds the supported maximum of {}", u32::MAX))))
            }
            None => {
                let (s, are) = if count == 1 { ("", "is") } else { ("s", "are") };
                Err(self.err(what(&format!(
                    "{name} index {i} is out of range: only {count} {name}{s} (`{kw}`) {are} \
                     defined before this line"
                ))))
            }
        }
    }
}

// =============================================================================================
// Writing

/// Writes `mesh` as Wavefront OBJ text to `w`: a `# tessera` header, `v`, `vn` and `vt` lines
/// (the vertex's own uv), then `f a/a/a b/b/b c/c/c` faces (1-based), with a `g patch_<id>` line
/// before each run of triangles of the same patch. Floats are printed in the shortest form that
/// reads back to the same `f32`, in plain decimal notation (as Rust's `{}` prints them).
///
/// Preconditions: as [`write_mesh`](super::write_mesh). I/O errors are [`Error::Write`] labelled `<writer>`.
///
/// Cost: O(vertices + triangles) time, the text formatted in parallel on the rayon threads in
/// chunks of 16,384 lines and written in order (the bytes do not depend on the thread count);
/// memory: a 64 KiB buffer and a few MiB of chunk buffers.
pub fn write_obj<W: Write>(mesh: &Mesh, w: W) -> Result<()> {
    super::write_to(mesh, Format::Obj, w)
}

// OBJ

/// Lines per parallel chunk: about 0.5 MiB of text (30–50 bytes a line).
const OBJ_CHUNK: usize = 1 << 14;

pub(super) fn emit_obj<W: Write>(mesh: &Mesh, w: &mut W) -> io::Result<()> {
    writeln!(w, "# tessera")?;
    writeln!(w, "# {} vertices, {} triangles", mesh.vertex_count(), mesh.triangle_count())?;
    write_chunks(w, mesh.positions.len(), OBJ_CHUNK, |range, out| {
        for p in &mesh.positions[range] {
            floats_line(out, b"v", p);
        }
    })?;
    write_chunks(w, mesh.normals.len(), OBJ_CHUNK, |range, out| {
        for n in &mesh.normals[range] {
            floats_line(out, b"vn", n);
        }
    })?;
    write_chunks(w, mesh.uvs.len(), OBJ_CHUNK, |range, out| {
        for uv in &mesh.uvs[range] {
            floats_line(out, b"vt", uv);
        }
    })?;
    write_chunks(w, mesh.triangle_count(), OBJ_CHUNK, |range, out| {
        // The group of the triangle before the chunk, so that a chunk starts a `g` line
        // exactly where a sequential writer would.
        let mut group = range.start.checked_sub(1).map(|t| mesh.triangle_patch[t]);
        let mut ints = itoa::Buffer::new();
        for t in range {
            let patch = mesh.triangle_patch[t];
            if group != Some(patch) {
                out.extend_from_slice(b"g patch_");
                out.extend_from_slice(ints.format(patch).as_bytes());
                out.push(b'\n');
                group = Some(patch);
            }
            out.push(b'f');
            for &i in &mesh.indices[3 * t..3 * t + 3] {
                // u64 because index u32::MAX would overflow when made 1-based.
                let i = ints.format(u64::from(i) + 1).as_bytes();
                out.push(b' ');
                out.extend_from_slice(i);
                out.push(b'/');
                out.extend_from_slice(i);
                out.push(b'/');
                out.extend_from_slice(i);
            }
            out.push(b'\n');
        }
    })
}

/// Appends `keyword x y ...` and a newline.
fn floats_line<const N: usize>(out: &mut Vec<u8>, keyword: &[u8], values: &[f32; N]) {
    out.extend_from_slice(keyword);
    for &x in values {
        out.push(b' ');
        push_f32(out, x);
    }
    out.push(b'\n');
}

/// Appends `x` exactly as `format!("{x}")` prints a finite `f32`: the shortest decimal that
/// reads back to the same `f32`, never in exponent notation, without a trailing `.0`
/// (`1`, `-0`, `0.5`, `0.0000001`, `10000000000000000000000000000000`).
///
/// Why not `write!`: the standard formatter is several times slower than `ryu`, and OBJ
/// output is almost all numbers. `ryu` finds the same shortest digits (both give the
/// shortest representation nearest to the value), but prints `1.0` and `1e-7`; those two
/// forms are rewritten here, so the text stays what tessera always wrote.
///
/// Preconditions: `x` is finite (the writers check the mesh first). Cost: O(1), no allocation
/// beyond the growth of `out`.
pub(super) fn push_f32(out: &mut Vec<u8>, x: f32) {
    let mut buf = ryu::Buffer::new();
    let s = buf.format_finite(x).as_bytes();
    if is_tie(x, s) {
        // Rare (16 of the 3.1 million numbers of the factor-16 torus): the standard formatter
        // decides, so the text is the same.
        write!(out, "{x}").expect("writing to a Vec cannot fail");
        return;
    }
    let Some(e) = s.iter().position(|&b| b == b'e') else {
        out.extend_from_slice(s.strip_suffix(b".0").unwrap_or(s));
        return;
    };
    // `[-]d[.ddd]e[-]x`: the digits d.ddd times 10^x.
    let (mantissa, exponent) = (&s[..e], &s[e + 1..]);
    let (sign, mantissa) = match mantissa.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, mantissa),
    };
    let exponent: i32 =
        std::str::from_utf8(exponent).ok().and_then(|x| x.parse().ok()).expect("ryu exponent");
    let digits: Vec<u8> = mantissa.iter().copied().filter(|&b| b != b'.').collect();
    if sign {
        out.push(b'-');
    }
    // The decimal point goes after `point` digits (ryu writes one digit before its point).
    let point = exponent + 1;
    if point <= 0 {
        out.extend_from_slice(b"0.");
        out.extend(std::iter::repeat_n(b'0', point.unsigned_abs() as usize));
        out.extend_from_slice(&digits);
    } else if point as usize >= digits.len() {
        out.extend_from_slice(&digits);
        out.extend(std::iter::repeat_n(b'0', point as usize - digits.len()));
    } else {
        let (int, frac) = digits.split_at(point as usize);
        out.extend_from_slice(int);
        out.push(b'.');
        out.extend_from_slice(frac);
    }
}

/// Whether `x` lies exactly halfway between two shortest decimals, `ryu` having printed one of
/// them as `printed`. There the two formatters differ: `ryu` takes the even last digit (the
/// f32 1.06640625 prints as `1.0664062`), the standard library rounds up (`1.0664063`).
///
/// A tie needs the exact decimal expansion of `x` to have one digit more than the shortest
/// form, ending in 5. With `x = m·2^e`, `m` odd: for `e < 0` the exact digits are those of
/// `m·5^-e`; for `e ≥ 0` they are `m / 5^e` followed by zeros when that division is exact,
/// and otherwise end in an even digit. The shortest form of an f32 has at most 9 digits, so
/// only expansions of at most 10 digits matter, which bounds `-e` by 14. Cost: a few integer
/// operations.
fn is_tie(x: f32, printed: &[u8]) -> bool {
    let bits = x.to_bits();
    let (biased, fraction) = ((bits >> 23) & 0xff, bits & 0x7f_ffff);
    let (mut m, mut e) =
        if biased == 0 { (fraction, -149) } else { (fraction | 1 << 23, biased as i32 - 150) };
    if m == 0 {
        return false;
    }
    e += m.trailing_zeros() as i32;
    m >>= m.trailing_zeros();
    let exact = if e < 0 {
        if e < -14 {
            return false;
        }
        u64::from(m) * 5u64.pow(e.unsigned_abs())
    } else {
        let five = match 5u64.checked_pow(e as u32) {
            Some(f) if u64::from(m) % f == 0 => f,
            _ => return false,
        };
        u64::from(m) / five
    };
    if exact % 10 != 5 || exact >= 10_000_000_000 {
        return false;
    }
    // Significant digits of the printed form: no sign, point or exponent, no leading or
    // trailing zeros (`ryu` writes `0.00125` and `1000.0`).
    let mantissa = printed.split(|&b| b == b'e').next().unwrap_or(printed);
    let digits = || mantissa.iter().copied().filter(u8::is_ascii_digit);
    let leading = digits().take_while(|&d| d == b'0').count();
    let trailing = digits().rev().take_while(|&d| d == b'0').count();
    let shortest = digits().count().saturating_sub(leading + trailing);
    exact.ilog10() as usize + 1 == shortest + 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::binary::test_meshes::{bytes, grid};
    use crate::test_support::{assert_parse_error, data, Lcg};

    #[test]
    fn obj_lines_match_the_mesh() {
        let mesh = grid(4, false);
        let text = String::from_utf8(bytes(|w| write_obj(&mesh, w))).unwrap();
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

    fn parse(text: &str) -> Result<PolygonMesh> {
        parse_obj(text, Path::new("test.obj"))
    }

    #[track_caller]
    fn assert_parse_err(text: &str, line: usize, needle: &str) {
        assert_parse_error(parse(text), "test.obj", line, needle);
    }

    /// Histogram of face sizes: (triangles, quads, pentagons, larger).
    fn sizes(m: &PolygonMesh) -> [usize; 4] {
        let mut h = [0; 4];
        for f in &m.faces {
            h[f.positions.len().min(6) - 3] += 1;
        }
        h
    }

    fn load(rel: &str) -> PolygonMesh {
        let m = read_obj(&data(rel)).unwrap_or_else(|e| panic!("{e}"));
        for f in &m.faces {
            assert!(f.positions.len() >= 3);
            assert!(f.positions.iter().all(|&i| (i as usize) < m.positions.len()));
            if let Some(n) = &f.normals {
                assert_eq!(n.len(), f.positions.len());
                assert!(n.iter().all(|&i| (i as usize) < m.normals.len()));
            }
        }
        m
    }

    #[test]
    fn reads_every_data_file_with_readme_counts() {
        // (file, triangles, quads, pentagons, vertices), from /work/shared/data/README.md.
        let table: &[(&str, usize, usize, usize, usize)] = &[
            ("meshes/blob.obj", 276, 0, 0, 140),
            ("meshes/dragknob.obj", 318, 0, 0, 161),
            ("meshes/bunny_res4.obj", 948, 0, 0, 453),
            ("meshes/helmet.obj", 1000, 0, 0, 496),
            ("meshes/spool.obj", 1294, 0, 0, 649),
            ("meshes/bunny_closed.obj", 3674, 0, 0, 1839),
            ("meshes/bunny_res3.obj", 3851, 0, 0, 1889),
            ("meshes/knot.obj", 4160, 0, 0, 2080),
            ("meshes/elephant.obj", 5558, 0, 0, 2775),
            ("meshes/cow.obj", 5804, 0, 0, 2904),
            ("meshes/spot.obj", 5856, 0, 0, 2930),
            ("meshes/killeroo_cage.obj", 8316, 0, 0, 4290),
            ("meshes/dragon_res4.obj", 11102, 0, 0, 5205),
            ("meshes/bunny_res2.obj", 16301, 0, 0, 8171),
            ("meshes/armadillo.obj", 52000, 0, 0, 26002),
            ("meshes/bunny.obj", 69451, 0, 0, 35947),
            ("meshes/elephant_refined.obj", 88928, 0, 0, 44460),
            ("cages/catmark_cube.obj", 0, 6, 0, 8),
            ("cages/catmark_torus.obj", 0, 32, 0, 32),
            ("cages/catmark_toroidal_tet.obj", 0, 24, 0, 20),
            ("cages/catmark_helmet.obj", 0, 58, 0, 72),
            ("cages/catmark_righthanded.obj", 0, 434, 0, 436),
            ("cages/catmark_pawn.obj", 0, 588, 0, 601),
            ("cages/catmark_rook.obj", 44, 733, 0, 768),
            ("cages/catmark_bishop.obj", 132, 836, 0, 917),
            ("cages/catmark_nonman_edges.obj", 1, 84, 0, 142),
            ("cages/spot_control_mesh.obj", 4, 160, 16, 188),
            ("awkward/elephant_with_holes.obj", 4463, 0, 0, 2798),
            ("awkward/teapot_tri_nonmanifold.obj", 1024, 0, 0, 530),
            ("awkward/teapot_unwelded.obj", 992, 0, 0, 792),
            ("bench/torus_64x32.obj", 0, 2048, 0, 2048),
        ];
        for &(rel, tri, quad, pent, verts) in table {
            let m = load(rel);
            assert_eq!(sizes(&m), [tri, quad, pent, 0], "{rel}");
            assert_eq!(m.positions.len(), verts, "{rel}");
            let tris = m.triangles(&data(rel));
            if quad + pent == 0 {
                assert_eq!(tris.unwrap().len(), tri, "{rel}");
            } else {
                assert!(matches!(tris, Err(Error::Unsupported { .. })), "{rel}");
            }
            if rel != "meshes/spot.obj" {
                assert!(m.normals.is_empty(), "{rel}");
                assert!(m.faces.iter().all(|f| f.normals.is_none()), "{rel}");
            }
        }
        // Every OBJ file in the data folders is covered by the table.
        for dir in ["meshes", "cages", "awkward", "bench"] {
            for entry in std::fs::read_dir(data(dir)).unwrap() {
                let path = entry.unwrap().path();
                if path.extension().is_some_and(|e| e == "obj") {
                    let rel = format!("{dir}/{}", path.file_name().unwrap().to_string_lossy());
                    assert!(table.iter().any(|t| t.0 == rel), "{rel} not in the table");
                }
            }
        }
    }

    #[test]
    fn spot_has_a_normal_at_every_corner() {
        let m = load("meshes/spot.obj");
        assert_eq!(m.normals.len(), 2930);
        for f in &m.faces {
            // Written `a//a`: the normal index equals the position index.
            assert_eq!(f.normals.as_ref(), Some(&f.positions));
        }
        let first = &m.faces[0];
        assert_eq!(first.positions, vec![0, 1, 2]);
        assert_eq!(m.normals[0], DVec3::new(0.5743, -0.8166, -0.0586));
        assert!(m.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3));
    }

    #[test]
    fn cube_triangles_names_first_polygon() {
        let path = data("cages/catmark_cube.obj");
        let m = load("cages/catmark_cube.obj");
        let text = std::fs::read_to_string(&path).unwrap();
        let first_f = text.lines().position(|l| l.starts_with("f ")).unwrap() + 1;
        assert_eq!(m.faces[0].line, first_f);
        assert_eq!(m.faces[0].positions, vec![0, 1, 3, 2]);
        let err = m.triangles(&path).unwrap_err();
        match &err {
            Error::Unsupported { at, reason } => {
                assert_eq!(at.line, first_f);
                assert_eq!(
                    reason,
                    "face has 4 vertices; PN triangles need triangles (triangulate the mesh first)"
                );
            }
            other => panic!("{other:?}"),
        }
        assert!(err.to_string().contains("catmark_cube.obj"));
    }

    #[test]
    fn non_utf8_in_a_comment_is_harmless() {
        let path = std::env::temp_dir().join(format!("tessera-obj-{}.obj", std::process::id()));
        std::fs::write(&path, b"# caf\xe9 \xff\nv 0 0 0\nf 1 1 1\nv \xe9 0 0\n").unwrap();
        let result = read_obj(&path);
        std::fs::remove_file(&path).unwrap();
        let err = result.unwrap_err();
        assert!(matches!(&err, Error::Parse { at, .. } if at.line == 4), "{err}");
        assert!(err.to_string().contains("not a number"), "{err}");
    }

    #[test]
    fn missing_file_is_io_error() {
        let err = read_obj(Path::new("/nonexistent/dir/x.obj")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
        assert!(err.to_string().contains("x.obj"));
    }

    #[test]
    fn syntax_features() {
        let text = "\u{feff}# header \\\n\
            mtllib a.mtl\r\n\
            o thing\n\
            g group one\n\
            v 0 0 0 1.0\n\
            v 1 0 0 0.5 0.25 0.125\n\
            v\t0 1 0  # comment\n\
            v 1e0 1E0 -0.0\n\
            vt 0 0\n\
            vt 1 0\n\
            vn 0 0 1\n\
            vn 0 0 -1\n\
            usemtl red\n\
            s off\n\
            s 1\n\
            f 1 2 3\n\
            f 1/1 2/2 3/1\n\
            f 1//1 2//2 3//1 4//2\n\
            f 1/1/1 2/2/2 3/1/1\n\
            f -4 -3 -2\n\
            f -4/-2/-1 -3//-2 -1/-1\n\
            f 1 2 \\\n   3 4 \\\n 1\n\
            l 1 2\n\
            p 3\n\
            curv 0 1 1 2\n\
            vp 0.5\n\
            unknownthing 99 foo\n\
            f 1//1 2//1 3\n";
        let m = parse(text).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[1], DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(m.positions[3], DVec3::new(1.0, 1.0, 0.0));
        assert_eq!(m.normals, vec![DVec3::Z, DVec3::NEG_Z]);
        let f = &m.faces;
        assert_eq!(f.len(), 8);
        assert_eq!(f[0].positions, vec![0, 1, 2]);
        assert_eq!(f[0].normals, None);
        assert_eq!(f[0].line, 16);
        assert_eq!(f[1].normals, None);
        assert_eq!(f[2].positions, vec![0, 1, 2, 3]);
        assert_eq!(f[2].normals, Some(vec![0, 1, 0, 1]));
        assert_eq!(f[3].normals, Some(vec![0, 1, 0]));
        assert_eq!(f[4].positions, vec![0, 1, 2]);
        assert_eq!(f[5].positions, vec![0, 1, 3]);
        assert_eq!(f[5].normals, None); // last corner has no normal
        assert_eq!(f[6].positions, vec![0, 1, 2, 3, 0]);
        assert_eq!(f[6].line, 22);
        assert_eq!(f[7].line, 30);
        assert_eq!(f[7].normals, None);
        // The lines after the continued face keep their own numbers.
        assert_parse_err("v 0 0 0\nf 1 \\\n 1 \\\n 1\nf 1 1 2\n", 5, "position index 2");
        // An error inside a continued face is reported at its first line.
        assert_parse_err("v 0 0 0\n\nf 1 \\\n 1 \\\n 9\n", 3, "position index 9");
        // A comment ending in a backslash does not swallow the next line.
        assert_eq!(parse("# c:\\dir\\\nv 0 0 0\nf 1 1 1\n").unwrap().positions.len(), 1);
        // A continuation at the end of the file just ends the statement.
        assert_eq!(parse("v 0 0 0\nf 1 1 1 \\").unwrap().faces[0].positions.len(), 3);
    }

    #[test]
    fn errors_name_line_and_reason() {
        let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\n";
        let e = |tail: &str| format!("{head}{tail}");
        // Too few corners.
        assert_parse_err(&e("f 1 2\n"), 5, "face has 2 corners; a face needs at least 3");
        assert_parse_err(&e("f\n"), 5, "face has 0 corners");
        // Index 0 and out of range, positive and negative, for every element kind.
        assert_parse_err(&e("f 1 0 2\n"), 5, "face corner 2 (`0`): position index is 0");
        assert_parse_err(&e("f 1 2 4\n"), 5, "position index 4 is out of range: only 3");
        assert_parse_err(&e("f 1 2 -4\n"), 5, "position index -4 is out of range");
        assert_parse_err(&e("f 1//1 2//2 3//1\n"), 5, "normal index 2 is out of range");
        assert_parse_err(&e("f 1//1 2//-0 3//1\n"), 5, "normal index is 0");
        assert_parse_err(&e("f 1/1 2/1 3/1\n"), 5, "texture coordinate index 1");
        assert_parse_err(&e("f 1 2 -9223372036854775808\n"), 5, "out of range");
        assert_parse_err(
            &e("f 1 2 99999999999999999999\n"),
            5,
            "index 99999999999999999999 is out of range: only 3",
        );
        assert_parse_err(&e("f 1 2 -99999999999999999999\n"), 5, "out of range");
        // Indices refer to what is defined so far, not to later lines.
        assert_parse_err("v 0 0 0\nv 0 0 0\nf 1 2 3\nv 0 0 0\n", 3, "only 2 positions");
        // Malformed corners and non-numbers.
        assert_parse_err(&e("f 1 2 3/1/1/1\n"), 5, "malformed corner");
        assert_parse_err(&e("f 1 2 /1\n"), 5, "position index is missing");
        assert_parse_err(&e("f 1 2 x\n"), 5, "position index `x` is not an integer");
        assert_parse_err(&e("f 1 2 3.0\n"), 5, "not an integer");
        assert_parse_err(&e("v 1 two 3\n"), 5, "`v` coordinate y is `two`, not a number");
        assert_parse_err(&e("v 1 2\n"), 5, "`v` needs 3 coordinates `x y z`, found 2");
        assert_parse_err(&e("vn 1\n"), 5, "`vn` needs 3 coordinates `x y z`, found 1");
        // NaN and infinite coordinates.
        assert_parse_err(&e("v 1 2 nan\n"), 5, "`v` coordinate z is NaN");
        assert_parse_err(&e("v inf 2 3\n"), 5, "`v` coordinate x is infinite");
        assert_parse_err(&e("v 1 -1e999 3\n"), 5, "coordinate y is infinite");
        assert_parse_err(&e("vn 0 NaN 1\n"), 5, "`vn` coordinate y is NaN");
        // Positions the f32 output cannot hold (found by fuzzing: they came out infinite).
        assert_parse_err(&e("v 1e39 2 3\n"), 5, "`v` coordinate x is `1e39`, beyond the f32 range");
        // CRLF line numbers.
        assert_parse_err(&e("\n\nf 1 2 7\n").replace('\n', "\r\n"), 7, "index 7");
    }

    #[test]
    fn no_faces_is_unsupported() {
        for text in ["", "\n\n", "# only a comment\n", "v 0 0 0\nv 1 1 1\nl 1 2\n"] {
            let err = parse(text).unwrap_err();
            match &err {
                Error::Unsupported { at, reason } => {
                    assert_eq!(at.line, 0);
                    assert_eq!(reason, "no faces");
                }
                other => panic!("{other:?}"),
            }
            assert!(err.to_string().contains("test.obj"));
        }
    }

    #[test]
    fn truncated_real_files_never_panic() {
        for rel in ["meshes/blob.obj", "meshes/spot.obj", "cages/spot_control_mesh.obj"] {
            let path = data(rel);
            let text = std::fs::read_to_string(&path).unwrap();
            let n_lines = text.lines().count();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            // About 1500 cuts per file, plus every byte of the first and last 300.
            let step = (text.len() / 1500).max(1);
            let cuts =
                (0..text.len()).step_by(step).chain(0..300).chain(text.len().saturating_sub(300)..text.len());
            for cut in cuts {
                match parse_obj(&text[..cut], &path) {
                    Ok(m) => assert!(!m.faces.is_empty()),
                    Err(e) => {
                        let msg = e.to_string();
                        assert!(msg.contains(&name), "{msg}");
                        match e {
                            Error::Parse { at, .. } => assert!((1..=n_lines).contains(&at.line)),
                            Error::Unsupported { at, .. } => assert_eq!(at.line, 0),
                            other => panic!("{other:?}"),
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn garbage_never_panics() {
        let mut rng = Lcg(0x0b1);
        let path = Path::new("garbage.obj");
        // Never panics; a success is a valid mesh; an error names the file. True on success.
        let check = |text: &str| match parse_obj(text, path) {
            Ok(m) => {
                for f in &m.faces {
                    assert!(f.positions.len() >= 3);
                    let n_pos = m.positions.len();
                    assert!(f.positions.iter().all(|&i| (i as usize) < n_pos));
                    if let Some(n) = &f.normals {
                        assert_eq!(n.len(), f.positions.len());
                        assert!(n.iter().all(|&i| (i as usize) < m.normals.len()));
                    }
                }
                true
            }
            Err(e) => {
                assert!(e.to_string().contains("garbage.obj"));
                false
            }
        };
        // Raw bytes.
        for _ in 0..2000 {
            let len = rng.below(200);
            let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
            check(&String::from_utf8_lossy(&bytes));
        }
        // Files of plausible shape: random statements with valid arguments, indices in range
        // (positive or negative, with or without vt/vn). One in four is perturbed: junk
        // tokens, indices past the end or 0, too few arguments.
        const JUNK: [&str; 9] = ["nan", "inf", "x", "0", "\\", "1/2/3/4", "/1", "1e999", "7"];
        let mut ok = 0;
        for _ in 0..20000 {
            let bad = rng.below(4) == 0;
            let (mut nv, mut nt, mut nn, mut nf) = (0usize, 0usize, 0usize, 0usize);
            let mut s = String::new();
            for _ in 0..rng.below(16) {
                let mut args: Vec<String> = Vec::new();
                let keyword = match rng.below(8) {
                    0..=2 => {
                        nv += 1;
                        args.extend((0..3 + rng.below(2)).map(|k| format!("{k}.5")));
                        "v"
                    }
                    3 => {
                        nn += 1;
                        args.extend((0..3).map(|k| format!("-{k}e-1")));
                        "vn"
                    }
                    4 => {
                        nt += 1;
                        args.extend(["0.5".to_string(), "1".to_string()]);
                        "vt"
                    }
                    5 => "g part",
                    _ if nv == 0 => "# no vertex yet",
                    _ => {
                        // A valid index into `n` elements (n > 0), positive or negative.
                        let index = |rng: &mut Lcg, n: usize| {
                            let k = 1 + rng.below(n) as i64;
                            if rng.below(2) == 0 {
                                k
                            } else {
                                -k
                            }
                        };
                        let form = rng.below(4);
                        for _ in 0..3 + rng.below(3) {
                            let v = index(&mut rng, nv);
                            let t = if nt > 0 { index(&mut rng, nt) } else { 0 };
                            let n = if nn > 0 { index(&mut rng, nn) } else { 0 };
                            args.push(match form {
                                1 if nt > 0 => format!("{v}/{t}"),
                                2 if nn > 0 => format!("{v}//{n}"),
                                3 if nt > 0 && nn > 0 => format!("{v}/{t}/{n}"),
                                _ => v.to_string(),
                            });
                        }
                        nf += 1;
                        "f"
                    }
                };
                if bad && rng.below(6) == 0 {
                    if rng.below(2) == 0 {
                        args.pop();
                    }
                    let at = rng.below(args.len() + 1);
                    args.insert(at, JUNK[rng.below(JUNK.len())].to_string());
                }
                s.push_str(keyword);
                for a in &args {
                    s.push(' ');
                    s.push_str(a);
                    if rng.below(10) == 0 {
                        s.push_str(" \\\n");
                    }
                }
                s.push_str(["\n", "\r\n", " # note\n"][rng.below(3)]);
            }
            if check(&s) {
                ok += 1;
            } else {
                assert!(bad || nf == 0, "valid file rejected:\n{s}");
            }
        }
        assert!(ok > 10000, "only {ok} random files parsed");
    }
}
