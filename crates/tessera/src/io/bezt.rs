//! Reader for tessera's cubic Bézier triangle text format (`.bezt`), shaped like the Newell
//! patch format of [`super::patches`]:
//!
//! ```text
//! T                  line 1: number of triangles
//! i0,i1,...,i9       T lines: 10 comma-separated 1-based control-point indices
//! V                  number of control points
//! x,y,z              V lines: one control point
//! ```
//!
//! The 10 indices of a triangle are its control points `b_ijk` (`i + j + k = 3`) in the order
//! of [`BezierTriangle::index`](crate::surface::BezierTriangle::index):
//! `b300, b210, b201, b120, b111, b102, b030, b021, b012, b003`. The triangle is
//! `S(u, v) = Σ 3!/(i! j! k!) λ0^i λ1^j λ2^k b_ijk` with `λ = (1 - u - v, u, v)`, so its corners
//! are `i0` (`b300`, at `u = v = 0`), `i6` (`b030`, at `u = 1`) and `i9` (`b003`, at `v = 1`),
//! and its boundary curves are `i0 i1 i3 i6`, `i6 i7 i8 i9` and `i9 i5 i2 i0`. The front side
//! is the one `dS/du × dS/dv` points to, so corners in counter-clockwise order seen from the
//! front.
//!
//! Neighbouring triangles share a boundary curve by using the same 4 control points (by index,
//! or by equal positions: [`SurfaceSet::from_bezier_triangle_file`](crate::surface::SurfaceSet::from_bezier_triangle_file)
//! welds them), which is what makes the tessellation crack-free. Bézier triangles are
//! polynomial, so point lines have no weight column.
//!
//! Tolerated, as in the patch format: spaces or tabs around values and commas, CRLF line
//! endings, a UTF-8 byte-order mark, blank lines, a missing final newline and exponent
//! notation. Rejected, with the file, the 1-based line and the reason: an empty file, a bad
//! count, a triangle line without exactly 10 indices, an index that is 0 or greater than the
//! point count, a point line without exactly 3 numbers, a non-number, a NaN or infinite
//! coordinate, a coordinate beyond the f32 range, fewer data lines than the counts promise,
//! and non-blank lines after the last point. A file declaring 0 triangles is
//! [`Error::Unsupported`](crate::Error::Unsupported).
//!
//! A flat triangle with corners (0,0,0), (3,0,0) and (0,3,0):
//!
//! ```text
//! 1
//! 1,2,3,4,5,6,7,8,9,10
//! 10
//! 0,0,0
//! 1,0,0
//! 0,1,0
//! 2,0,0
//! 1,1,0
//! 0,2,0
//! 3,0,0
//! 2,1,0
//! 1,2,0
//! 0,3,0
//! ```

use std::path::Path;

use glam::DVec3;

use super::patches::{parse_indexed, read_text};
use crate::error::Result;
use crate::surface::{BezierTriangle, BuildOptions, Patch, SurfaceSet};

/// Number of control points of a cubic Bézier triangle.
const TRIANGLE_POINTS: usize = 10;

/// A parsed `.bezt` file: indexed cubic Bézier triangles and their control points.
#[derive(Debug, Clone, PartialEq)]
pub struct BezierTriangleFile {
    /// Per triangle, its 10 control-point indices, 0-based into `points`, in the order of
    /// [`BezierTriangle::index`](crate::surface::BezierTriangle::index). Every index is
    /// `< points.len()`.
    pub triangles: Vec<[u32; 10]>,
    /// Control-point positions, all finite and within the f32 range.
    pub points: Vec<DVec3>,
    /// Per triangle (same length as `triangles`), the 1-based source line it was read from.
    pub lines: Vec<usize>,
}

/// Reads and parses the `.bezt` file at `path`. Bytes that are not UTF-8 are replaced, and
/// then reported as non-numbers on their line.
///
/// # Errors
///
/// [`Error::Io`](crate::Error::Io) when the file cannot be read; otherwise as
/// [`parse_bezt`].
///
/// Cost: one read of the file plus the parse (O(file size)).
pub fn read_bezt(path: &Path) -> Result<BezierTriangleFile> {
    parse_bezt(&read_text(path)?, path)
}

/// Parses the text of a `.bezt` file. `file` is used only in error messages (pass a label
/// such as `<memory>` for text that does not come from a file).
///
/// # Errors
///
/// [`Error::Parse`](crate::Error::Parse) with `file`, the 1-based line and the reason for
/// every malformed input listed in the module documentation;
/// [`Error::Unsupported`](crate::Error::Unsupported) at the count line when the file declares
/// 0 triangles.
///
/// Cost: O(text length) time; memory O(triangles + points) plus one slice per line;
/// reservations are capped by the lines present, so an absurd count fails without a large
/// allocation.
pub fn parse_bezt(text: &str, file: &Path) -> Result<BezierTriangleFile> {
    let (triangles, points, _weights, lines) =
        parse_indexed::<TRIANGLE_POINTS>(text, file, "triangle", false)?;
    Ok(BezierTriangleFile { triangles, points, lines })
}

/// Writes `file` in the `.bezt` text format (the inverse of [`parse_bezt`]): 1-based indices,
/// and numbers in the shortest form that reads back to the same `f64` (`{:?}`).
///
/// Preconditions: every index `< points.len()` and finite points, as [`parse_bezt`] returns;
/// otherwise the text does not parse back.
///
/// Cost: O(triangles + points) time and output size.
pub fn to_bezt_text(file: &BezierTriangleFile) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = writeln!(out, "{}", file.triangles.len());
    for t in &file.triangles {
        let idx: Vec<String> = t.iter().map(|i| (u64::from(*i) + 1).to_string()).collect();
        let _ = writeln!(out, "{}", idx.join(","));
    }
    let _ = writeln!(out, "{}", file.points.len());
    for p in &file.points {
        let _ = writeln!(out, "{:?},{:?},{:?}", p.x, p.y, p.z);
    }
    out
}

impl SurfaceSet {
    /// Builds cubic Bézier triangles from a parsed `.bezt` file
    /// ([`crate::io::bezt`]). Triangles that use the same control points (by index, or by
    /// position up to `options.weld`) share boundary curves in the topology, so their
    /// tessellation is crack-free; all-collapsed triangles are dropped and counted in
    /// [`Repairs`](crate::surface::Repairs).
    ///
    /// Preconditions: indices in range and finite points, as the parser guarantees.
    /// Cost: O(triangles) hashing, as [`SurfaceSet::from_patches`].
    pub fn from_bezier_triangle_file(file: &BezierTriangleFile, options: BuildOptions) -> SurfaceSet {
        let patches = file
            .triangles
            .iter()
            .map(|idx| Patch::BezierTriangle(BezierTriangle { points: idx.map(|i| file.points[i as usize]) }))
            .collect();
        Self::from_patches(patches, options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use crate::test_support::assert_parse_error;

    fn parse(text: &str) -> Result<BezierTriangleFile> {
        parse_bezt(text, Path::new("<test>"))
    }

    /// The flat triangle of the module documentation.
    fn flat() -> String {
        let mut s = String::from("1\n1,2,3,4,5,6,7,8,9,10\n10\n");
        // b_ijk at (j, k, 0), in storage order: corners (0,0,0), (3,0,0) and (0,3,0).
        for (j, k) in [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2), (3, 0), (2, 1), (1, 2), (0, 3)] {
            s += &format!("{j},{k},0\n");
        }
        s
    }

    #[test]
    fn documented_example_parses() {
        let f = parse(&flat()).unwrap();
        assert_eq!(f.triangles, [[0, 1, 2, 3, 4, 5, 6, 7, 8, 9]]);
        assert_eq!(f.points[6], DVec3::new(3.0, 0.0, 0.0));
        assert_eq!(f.points[9], DVec3::new(0.0, 3.0, 0.0));
        assert_eq!(f.lines, [2]);
        let doc = include_str!("bezt.rs");
        let example: String = doc
            .lines()
            .skip_while(|l| *l != "//! A flat triangle with corners (0,0,0), (3,0,0) and (0,3,0):")
            .skip(3)
            .take_while(|l| *l != "//! ```")
            .map(|l| format!("{}\n", l.trim_start_matches("//! ")))
            .collect();
        assert_eq!(parse(&example).unwrap(), f, "the module example is the test's triangle");
    }

    #[test]
    fn text_round_trip() {
        let f = parse(&flat()).unwrap();
        assert_eq!(parse(&to_bezt_text(&f)).unwrap().triangles, f.triangles);
        assert_eq!(parse(&to_bezt_text(&f)).unwrap().points, f.points);
    }

    #[test]
    fn errors_name_file_line_and_reason() {
        let good = flat();
        assert_parse_error(parse(""), "<test>", 1, "expected the triangle count");
        assert_parse_error(parse("x\n"), "<test>", 1, "bad triangle count");
        let t = good.replacen(",10\n", "\n", 1);
        assert_parse_error(parse(&t), "<test>", 2, "expected 10 comma-separated indices, found 9");
        let t = good.replacen(",10\n", ",11\n", 1);
        assert_parse_error(parse(&t), "<test>", 2, "index 10 of 10 is 11");
        let t = good.replacen("3,0,0\n", "3,0,0,1\n", 1);
        assert_parse_error(parse(&t), "<test>", 10, "expected 3 comma-separated coordinates");
        let t = good.replacen("3,0,0\n", "3,nan,0\n", 1);
        assert_parse_error(parse(&t), "<test>", 10, "y is NaN");
        let t = good.trim_end().rsplit_once('\n').unwrap().0.to_string();
        assert_parse_error(parse(&t), "<test>", 12, "truncated file");
        assert_parse_error(parse(&format!("{good}1,2,3\n")), "<test>", 14, "unexpected content");
        assert!(matches!(parse("0\n0\n"), Err(Error::Unsupported { at, .. }) if at.line == 1));
    }
}
