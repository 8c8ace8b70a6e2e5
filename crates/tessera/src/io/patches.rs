//! Reader for the Newell bicubic Bézier patch text format (the `teaset.tgz` format).
//!
//! ```text
//! P                  line 1: number of patches
//! i0,i1,...,i15      P lines: 16 comma-separated 1-based control-point indices
//! V                  number of control points
//! x,y,z[,w]          V lines: one control point; the optional 4th value is its weight
//! ```
//!
//! Index `k` on a patch line is control point `P[k / 4][k % 4]`. The weight column is this
//! project's extension for rational patches (`w` finite and `> 0`; `1.0` when absent).
//!
//! Tolerated because it is harmless: spaces or tabs around values and commas, CRLF line
//! endings, a UTF-8 byte-order mark, blank lines (anywhere; the counts drive the parse), a
//! missing final newline and exponent notation. Rejected, with the file and the 1-based line:
//! an empty file, a bad count, a patch line without exactly 16 indices, an index that is 0 or
//! greater than the point count, a non-number, a NaN or infinite coordinate, a coordinate
//! beyond the f32 range of the output meshes, a weight that is not finite and positive, a
//! file with fewer data lines than its counts promise, and non-blank lines after the last
//! point.

use std::path::Path;

use glam::DVec3;

use crate::error::{Error, Result};
use crate::surface::{BuildOptions, Patch, RationalBicubic, SurfaceSet};

/// Number of control points of a bicubic patch.
const PATCH_POINTS: usize = 16;

/// A parsed patch file: indexed bicubic Bézier patches and their control points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PatchFile {
    /// Per patch, its 16 control-point indices, 0-based into `points`; index `k` is control
    /// point `P[k / 4][k % 4]`. Every index is `< points.len()`.
    pub patches: Vec<[u32; 16]>,
    /// Control-point positions.
    pub points: Vec<DVec3>,
    /// One weight per point (same length as `points`): the 4th value of the point line when
    /// given, else `1.0`. Always finite and `> 0`.
    pub weights: Vec<f64>,
    /// Per patch (same length as `patches`), the 1-based source line it was read from, for
    /// error messages about individual patches.
    pub lines: Vec<usize>,
}

impl PatchFile {
    /// `true` when every weight is exactly `1.0`, i.e. every patch is polynomial.
    ///
    /// Cost: O(points).
    pub fn is_polynomial(&self) -> bool {
        self.weights.iter().all(|&w| w == 1.0)
    }
}

/// Reads and parses the patch file at `path`.
///
/// Bytes that are not UTF-8 are replaced, not rejected; in this format they can only stand
/// where a number should, so they are reported as non-numbers on their line.
///
/// # Errors
///
/// [`Error::Io`] when the file cannot be read; otherwise as [`parse_patches`].
///
/// Cost: one read of the file plus the parse (O(file size)).
pub fn read_patches(path: &Path) -> Result<PatchFile> {
    parse_patches(&read_text(path)?, path)
}

/// Parses the text of a patch file. `file` is used only in error messages (pass a label such
/// as `<memory>` for text that does not come from a file).
///
/// # Errors
///
/// [`Error::Parse`] with `file`, the 1-based line and the reason for every malformed input
/// listed in the module documentation; [`Error::Unsupported`] at the count line when the file
/// declares 0 patches.
///
/// Cost: O(text length) time; memory O(patches + points) plus one slice per line. Reservations
/// are capped by the number of lines left, so an absurd count in a tiny file fails (as
/// truncated) without a large allocation.
pub fn parse_patches(text: &str, file: &Path) -> Result<PatchFile> {
    let (patches, points, weights, lines) = parse_indexed::<PATCH_POINTS>(text, file, "patch", true)?;
    Ok(PatchFile { patches, points, weights, lines })
}

/// What [`parse_indexed`] returns: per element its `N` 0-based indices, the points, their
/// weights and each element's source line.
pub(super) type Indexed<const N: usize> = (Vec<[u32; N]>, Vec<DVec3>, Vec<f64>, Vec<usize>);

/// The parser shared by the indexed control-point formats (this one and [`super::bezt`]): an
/// element count, that many lines of `N` comma-separated 1-based indices, a point count and
/// that many `x,y,z` lines (with an optional weight `w` when `weights` is set). `what` names
/// an element in messages ("patch", "triangle").
///
/// # Errors
///
/// As [`parse_patches`], with `N` in place of 16; a 4th value on a point line when `weights`
/// is not set is [`Error::Parse`].
///
/// Cost: as [`parse_patches`].
pub(super) fn parse_indexed<const N: usize>(
    text: &str,
    file: &Path,
    what_one: &str,
    weights_allowed: bool,
) -> Result<Indexed<N>> {
    let mut src = DataLines::new(text, file);
    let Some((count_line, count_text)) = src.next() else {
        return Err(Error::parse(file, 1, format!("empty file: expected the {what_one} count on line 1")));
    };
    let patch_count = parse_count(count_text, what_one, count_line, file)?;
    if patch_count == 0 {
        return Err(Error::unsupported(
            file,
            count_line,
            format!("the file declares 0 {}", plural(what_one)),
        ));
    }

    // Patch lines: syntax only here; the indices are checked once the point count is known.
    let mut raw: Vec<[u64; N]> = Vec::with_capacity(patch_count.min(src.remaining()));
    let mut lines = Vec::with_capacity(raw.capacity());
    for p in 0..patch_count {
        let what = || format!("{what_one} {} of {patch_count}", p + 1);
        let (line, body) = src.expect(|| format!("{} ({N} comma-separated indices)", what()))?;
        raw.push(parse_patch_line::<N>(body, line, file, &what)?);
        lines.push(line);
    }

    let (count_line, count_text) = src.expect(|| "the point count".to_string())?;
    let point_count = parse_count(count_text, "point", count_line, file)?;
    if u32::try_from(point_count).is_err() {
        return Err(Error::parse(
            file,
            count_line,
            format!("point count {point_count} exceeds the supported maximum of {}", u32::MAX),
        ));
    }

    let mut patches = Vec::with_capacity(raw.len());
    for (p, (indices, &line)) in raw.iter().zip(&lines).enumerate() {
        let mut out = [0u32; N];
        for (k, (&i, slot)) in indices.iter().zip(out.iter_mut()).enumerate() {
            // `point_count <= u32::MAX`, so `i - 1` fits in u32 whenever `1 <= i <= point_count`.
            match u32::try_from(i) {
                Ok(i) if i >= 1 && (i as usize) <= point_count => *slot = i - 1,
                _ => {
                    return Err(Error::parse(
                        file,
                        line,
                        format!(
                            "{what_one} {} of {patch_count}: index {} of {N} is {i}, but indices \
                             must be in 1..={point_count} (the file has {point_count} points)",
                            p + 1,
                            k + 1,
                        ),
                    ));
                }
            }
        }
        patches.push(out);
    }

    let cap = point_count.min(src.remaining());
    let mut points = Vec::with_capacity(cap);
    let mut weights = Vec::with_capacity(cap);
    for v in 0..point_count {
        let what = || format!("point {} of {point_count}", v + 1);
        let (line, body) = src.expect(|| format!("{} (`x,y,z` or `x,y,z,w`)", what()))?;
        let (p, w) = parse_point_line(body, line, file, &what, weights_allowed)?;
        points.push(p);
        weights.push(w);
    }

    if let Some((line, extra)) = src.next() {
        return Err(Error::parse(
            file,
            line,
            format!(
                "unexpected content after the last point (the counts say {patch_count} {} \
                 and {point_count} points, all already read): {}",
                plural(what_one),
                quote(extra)
            ),
        ));
    }

    Ok((patches, points, weights, lines))
}

/// `patch` → `patches`, `triangle` → `triangles`.
fn plural(what: &str) -> String {
    if what.ends_with('h') {
        format!("{what}es")
    } else {
        format!("{what}s")
    }
}

/// Writes `file` in the patch format (the inverse of [`parse_patches`]): 1-based indices, and
/// numbers in the shortest form that reads back to the same `f64` (`{:?}`, which keeps
/// exponents short). The weight column is written only for points whose weight is not 1, so
/// a polynomial file stays in Newell's original format.
///
/// Preconditions: every index `< points.len()`, one weight per point, finite numbers, as
/// [`parse_patches`] returns; otherwise the text does not parse back.
///
/// Cost: O(patches + points) time and output size.
pub fn to_patches_text(file: &PatchFile) -> String {
    use std::fmt::Write as _;
    let mut text = String::new();
    // Writing to a String cannot fail.
    let _ = writeln!(text, "{}", file.patches.len());
    for patch in &file.patches {
        let indices: Vec<String> = patch.iter().map(|&i| (u64::from(i) + 1).to_string()).collect();
        let _ = writeln!(text, "{}", indices.join(","));
    }
    let _ = writeln!(text, "{}", file.points.len());
    for (k, p) in file.points.iter().enumerate() {
        let _ = write!(text, "{:?},{:?},{:?}", p.x, p.y, p.z);
        match file.weights.get(k) {
            Some(&w) if w != 1.0 => {
                let _ = writeln!(text, ",{w:?}");
            }
            _ => text.push('\n'),
        }
    }
    text
}

/// The non-blank lines of a text, trimmed, with their 1-based line numbers.
struct DataLines<'a> {
    file: &'a Path,
    /// Every physical line (CR and surrounding whitespace removed).
    lines: Vec<&'a str>,
    /// Index of the next physical line to look at.
    pos: usize,
    /// 1-based number of the last non-blank line returned (0 before the first).
    last: usize,
}

impl<'a> DataLines<'a> {
    fn new(text: &'a str, file: &'a Path) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let lines = text.lines().map(str::trim).collect();
        DataLines { file, lines, pos: 0, last: 0 }
    }

    /// Upper bound on the number of data lines left (used to cap reservations).
    fn remaining(&self) -> usize {
        self.lines.len() - self.pos
    }

    /// The next non-blank line and its 1-based number.
    fn next(&mut self) -> Option<(usize, &'a str)> {
        while let Some(&line) = self.lines.get(self.pos) {
            self.pos += 1;
            if !line.is_empty() {
                self.last = self.pos;
                return Some((self.pos, line));
            }
        }
        None
    }

    /// The next non-blank line, or a "truncated file" error naming the last line with data
    /// and what was expected next.
    fn expect(&mut self, expected: impl FnOnce() -> String) -> Result<(usize, &'a str)> {
        match self.next() {
            Some(found) => Ok(found),
            None => Err(Error::parse(
                self.file,
                self.last.max(1),
                format!(
                    "truncated file: the data ends at line {}, but {} was expected next",
                    self.last,
                    expected()
                ),
            )),
        }
    }
}

/// Parses a patch or point count: a non-negative decimal integer.
fn parse_count(text: &str, what: &str, line: usize, file: &Path) -> Result<usize> {
    text.parse::<u64>().ok().and_then(|n| usize::try_from(n).ok()).ok_or_else(|| {
        Error::parse(
            file,
            line,
            format!("bad {what} count {}: expected a non-negative decimal integer", quote(text)),
        )
    })
}

/// Parses the `N` comma-separated 1-based indices of an element line (range checked later).
fn parse_patch_line<const N: usize>(
    body: &str,
    line: usize,
    file: &Path,
    what: &dyn Fn() -> String,
) -> Result<[u64; N]> {
    let found = body.split(',').count();
    if found != N {
        let hint = if found == 1 && body.contains(char::is_whitespace) {
            " (indices must be separated by commas)"
        } else {
            ""
        };
        return Err(Error::parse(
            file,
            line,
            format!("{}: expected {N} comma-separated indices, found {found}{hint}", what()),
        ));
    }
    let mut out = [0u64; N];
    for (k, (field, slot)) in body.split(',').zip(out.iter_mut()).enumerate() {
        let field = field.trim();
        *slot = field.parse::<u64>().map_err(|_| {
            Error::parse(
                file,
                line,
                format!("{}: index {} is {}, which is not a positive integer", what(), k + 1, quote(field)),
            )
        })?;
    }
    Ok(out)
}

/// Parses `x,y,z` or `x,y,z,w`.
fn parse_point_line(
    body: &str,
    line: usize,
    file: &Path,
    what: &dyn Fn() -> String,
    weights_allowed: bool,
) -> Result<(DVec3, f64)> {
    const NAMES: [&str; 4] = ["x", "y", "z", "weight w"];
    let found = body.split(',').count();
    if !weights_allowed && found != 3 {
        return Err(Error::parse(
            file,
            line,
            format!("{}: expected 3 comma-separated coordinates `x,y,z`, found {found} values", what()),
        ));
    }
    if !(3..=4).contains(&found) {
        return Err(Error::parse(
            file,
            line,
            format!(
                "{}: expected 3 comma-separated coordinates `x,y,z` (or 4 with a weight, \
                 `x,y,z,w`), found {found} values",
                what()
            ),
        ));
    }
    let mut values = [1.0f64; 4];
    let fields = body.split(',').map(str::trim);
    for (k, (field, (slot, name))) in fields.zip(values.iter_mut().zip(NAMES)).enumerate() {
        let value = field.parse::<f64>().map_err(|_| {
            Error::parse(file, line, format!("{}: {name} is {}, not a number", what(), quote(field)))
        })?;
        if k < 3 && !value.is_finite() {
            let kind = if value.is_nan() { "NaN" } else { "infinite" };
            return Err(Error::parse(file, line, format!("{}: {name} is {kind} ({})", what(), quote(field))));
        }
        // Output meshes store f32, so a coordinate past its range would come out infinite.
        if k < 3 && value.abs() > f64::from(f32::MAX) {
            return Err(Error::parse(
                file,
                line,
                format!(
                    "{}: {name} is {}, beyond the f32 range (±3.4e38) of the output mesh",
                    what(),
                    quote(field)
                ),
            ));
        }
        if k == 3 && !(value.is_finite() && value > 0.0) {
            return Err(Error::parse(
                file,
                line,
                format!("{}: weight w is {}, but weights must be finite and > 0", what(), quote(field)),
            ));
        }
        *slot = value;
    }
    Ok((DVec3::new(values[0], values[1], values[2]), values[3]))
}

/// Reads a text file for the parsers of this folder. Invalid UTF-8 is replaced (U+FFFD)
/// rather than rejected: in names or comments it is harmless, and in numbers the parser then
/// reports it with its line. No copy is made when the file is valid UTF-8.
///
/// # Errors
///
/// As [`read_input`](super::read_input).
///
/// Cost: one read of the file.
pub(super) fn read_text(path: &Path) -> Result<String> {
    let bytes = super::read_input(path)?;
    Ok(String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned()))
}

/// Quotes a piece of input for an error message: in backticks, escaped, and cut after 40
/// characters. Cost: O(min(len, 40)).
pub(super) fn quote(s: &str) -> String {
    const MAX: usize = 40;
    match s.char_indices().nth(MAX) {
        Some((cut, _)) => format!("`{}...`", s[..cut].escape_debug()),
        None => format!("`{}`", s.escape_debug()),
    }
}

/// Helpers shared by the tests of the parsers in this folder.
impl SurfaceSet {
    /// Builds bicubic rational patches from a parsed patch file.
    pub fn from_patch_file(file: &PatchFile, options: BuildOptions) -> SurfaceSet {
        let patches = file
            .patches
            .iter()
            .map(|idx| {
                Patch::Bicubic(RationalBicubic {
                    points: idx.map(|i| file.points[i as usize]),
                    weights: idx.map(|i| file.weights[i as usize]),
                })
            })
            .collect();
        Self::from_patches(patches, options)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_support::{assert_parse_error, data, Lcg};

    fn parse(text: &str) -> Result<PatchFile> {
        parse_patches(text, Path::new("test.patches"))
    }

    #[track_caller]
    fn assert_parse_err(text: &str, line: usize, needle: &str) {
        assert_parse_error(parse(text), "test.patches", line, needle);
    }

    /// A valid one-patch file with 16 points (indices 1..=16), one point per line.
    fn one_patch() -> String {
        let idx: Vec<String> = (1..=16).map(|i| i.to_string()).collect();
        let mut s = format!("1\n{}\n16\n", idx.join(","));
        for i in 0..16 {
            s.push_str(&format!("{}.5,{},-{}\n", i, i % 4, i / 4));
        }
        s
    }

    fn check_file(rel: &str, patches: usize, points: usize) -> PatchFile {
        let pf = read_patches(&data(rel)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(pf.patches.len(), patches, "{rel}");
        assert_eq!(pf.lines.len(), patches, "{rel}");
        assert_eq!(pf.points.len(), points, "{rel}");
        assert_eq!(pf.weights.len(), points, "{rel}");
        assert!(pf.is_polynomial(), "{rel}");
        for (p, patch) in pf.patches.iter().enumerate() {
            assert_eq!(pf.lines[p], p + 2, "{rel}");
            assert!(patch.iter().all(|&i| (i as usize) < points), "{rel}");
        }
        assert!(pf.points.iter().all(|p| p.is_finite()), "{rel}");
        pf
    }

    #[test]
    fn reads_every_data_file() {
        let teapot = check_file("patches/teapot.patches", 32, 306);
        assert_eq!(teapot.patches[0][0], 0);
        assert_eq!(teapot.patches[0][15], 15);
        assert_eq!(teapot.patches[1][0], 3);
        assert_eq!(teapot.points[0], DVec3::new(1.4, 0.0, 2.4));
        assert_eq!(teapot.points[1], DVec3::new(1.4, -0.784, 2.4));
        assert_eq!(*teapot.points.last().unwrap(), DVec3::new(1.425, -0.798, 0.0));
        check_file("patches/teacup.patches", 26, 251);
        check_file("patches/teapot_teasetorig.patches", 28, 269);
        check_file("bench/torus_64x32.patches", 2048, 18432);
        // And every other patch file in the folders, whatever it is.
        for dir in ["patches", "bench"] {
            for entry in std::fs::read_dir(data(dir)).unwrap() {
                let path = entry.unwrap().path();
                if path.extension().is_some_and(|e| e == "patches") {
                    read_patches(&path).unwrap_or_else(|e| panic!("{e}"));
                }
            }
        }
    }

    #[test]
    fn missing_file_is_io_error() {
        let err = read_patches(Path::new("/nonexistent/dir/x.patches")).unwrap_err();
        assert!(matches!(err, Error::Io { .. }), "{err:?}");
        assert!(err.to_string().contains("x.patches"));
    }

    #[test]
    fn tolerant_formatting() {
        let base = parse(&one_patch()).unwrap();
        // CRLF, spaces around commas, blank lines, no final newline, BOM, exponents.
        let crlf = one_patch().replace('\n', "\r\n");
        assert_eq!(parse(&crlf).unwrap(), base);
        let spaced = one_patch().replace(',', " , ").replace('\n', " \n\t");
        assert_eq!(parse(&spaced).unwrap(), base);
        let blank = format!("\n{}\n\n  \n", one_patch().replace("\n16\n", "\n\n16\n\n"));
        let pf = parse(&blank).unwrap();
        assert_eq!(pf.points, base.points);
        assert_eq!(pf.lines, vec![3]);
        let no_nl = one_patch().trim_end().to_string();
        assert_eq!(parse(&no_nl).unwrap(), base);
        assert_eq!(parse(&format!("\u{feff}{}", one_patch())).unwrap(), base);
        let exp = one_patch().replace("0.5,0,-0\n", "5e-1,0E0,-0.0e+3\n");
        assert_ne!(exp, one_patch());
        assert_eq!(parse(&exp).unwrap().points, base.points);
    }

    #[test]
    fn weights() {
        let pf = parse(&one_patch()).unwrap();
        assert!(pf.weights.iter().all(|&w| w == 1.0));
        let text = one_patch().replace("1.5,1,-0\n", "1.5,1,-0,2.5\n");
        let pf = parse(&text).unwrap();
        assert_eq!(pf.weights[1], 2.5);
        assert_eq!(pf.points[1], DVec3::new(1.5, 1.0, 0.0));
        assert!(!pf.is_polynomial());
        assert_eq!(pf.weights.iter().filter(|&&w| w == 1.0).count(), 15);
        for bad in ["0", "-1", "inf", "nan", "-0.0"] {
            let text = one_patch().replace("1.5,1,-0\n", &format!("1.5,1,-0,{bad}\n"));
            assert_parse_err(&text, 5, "weight");
        }
        let text = one_patch().replace("1.5,1,-0\n", "1.5,1,-0,abc\n");
        assert_parse_err(&text, 5, "not a number");
    }

    #[test]
    fn errors_name_line_and_reason() {
        let good = one_patch();
        assert_parse_err("", 1, "empty");
        assert_parse_err("\n \r\n\n", 1, "empty");
        assert_parse_err("abc\n", 1, "bad patch count");
        assert_parse_err("-3\n", 1, "bad patch count");
        assert_parse_err("1.5\n", 1, "bad patch count");
        // Wrong index count: says how many were found.
        let t = good.replacen(",16\n", "\n", 1);
        assert_parse_err(&t, 2, "found 15");
        let t = good.replacen(",16\n", ",16,17\n", 1);
        assert_parse_err(&t, 2, "found 17");
        assert_parse_err("1\n1 2 3 4\n", 2, "separated by commas");
        // Index 0 and index > V: names the index and V.
        let t = good.replacen("1,2,3", "1,0,3", 1);
        assert_parse_err(&t, 2, "index 2 of 16 is 0");
        let t = good.replacen(",16\n", ",17\n", 1);
        assert_parse_err(&t, 2, "is 17, but indices must be in 1..=16");
        let t = good.replacen(",16\n", ",99999999999999\n", 1);
        assert_parse_err(&t, 2, "is 99999999999999");
        // Non-numbers.
        let t = good.replacen("1,2,3", "1,x,3", 1);
        assert_parse_err(&t, 2, "`x`, which is not a positive integer");
        let t = good.replacen("1,2,3", "1,-2,3", 1);
        assert_parse_err(&t, 2, "not a positive integer");
        let t = good.replacen("\n16\n", "\nsixteen\n", 1);
        assert_parse_err(&t, 3, "bad point count");
        let t = good.replace("2.5,2,-0\n", "2.5,two,-0\n");
        assert_parse_err(&t, 6, "point 3 of 16: y is `two`, not a number");
        let t = good.replace("2.5,2,-0\n", "2.5,2\n");
        assert_parse_err(&t, 6, "found 2 values");
        let t = good.replace("2.5,2,-0\n", "2.5,2,0,1,1\n");
        assert_parse_err(&t, 6, "found 5 values");
        let t = good.replace("2.5,2,-0\n", "2.5,,0\n");
        assert_parse_err(&t, 6, "not a number");
        // NaN and infinities.
        for (bad, kind) in [("NaN", "NaN"), ("inf", "infinite"), ("-1e999", "infinite")] {
            let t = good.replace("2.5,2,-0\n", &format!("2.5,2,{bad}\n"));
            assert_parse_err(&t, 6, &format!("point 3 of 16: z is {kind}"));
        }
        // Coordinates the f32 output cannot hold (found by fuzzing: they came out infinite).
        let t = good.replace("2.5,2,-0\n", "2.5,2,-1e39\n");
        assert_parse_err(&t, 6, "point 3 of 16: z is `-1e39`, beyond the f32 range");
        // Extra content after the data.
        let t = format!("{good}\n0,0,0\n");
        assert_parse_err(&t, 21, "unexpected content after the last point");
        // Zero patches is unsupported, not a parse error.
        let err = parse("0\n0\n").unwrap_err();
        assert!(matches!(err, Error::Unsupported { .. }), "{err:?}");
    }

    #[test]
    fn truncation_names_where_data_ran_out() {
        let good = one_patch();
        assert_parse_err("1\n", 1, "patch 1 of 1 (16 comma-separated indices) was expected");
        let head: String = good.lines().take(2).map(|l| format!("{l}\n")).collect();
        assert_parse_err(&head, 2, "the point count was expected");
        let head: String = good.lines().take(10).map(|l| format!("{l}\n")).collect();
        assert_parse_err(&head, 10, "data ends at line 10, but point 8 of 16");
        // Trailing blank lines do not move the reported line.
        assert_parse_err(&format!("{head}\n\n\n"), 10, "point 8 of 16");
    }

    #[test]
    fn absurd_counts_do_not_allocate() {
        // Would need terabytes if the counts were trusted for reservations.
        assert_parse_err("1000000000000\n1,2\n", 2, "found 2");
        assert_parse_err("1000000000000\n", 1, "patch 1 of 1000000000000");
        let idx = (1..=16).map(|i| i.to_string()).collect::<Vec<_>>().join(",");
        assert_parse_err(&format!("1\n{idx}\n999999999\n"), 3, "point 1 of 999999999");
        assert_parse_err(&format!("1\n{idx}\n4294967295\n1,2,3\n"), 4, "point 2 of 4294967295");
        assert_parse_err(&format!("1\n{idx}\n4294967296\n"), 3, "supported maximum");
        assert_parse_err("99999999999999999999999\n", 1, "bad patch count");
    }

    #[test]
    fn truncated_real_file_never_panics() {
        let path = data("patches/teapot.patches");
        let text = std::fs::read_to_string(&path).unwrap();
        let last_line_start = text.trim_end().rfind('\n').unwrap() + 1;
        let n_lines = text.lines().count();
        for cut in 0..text.len() {
            match parse_patches(&text[..cut], &path) {
                Ok(pf) => {
                    // Only a cut inside the last point line can still be a complete file.
                    assert!(cut > last_line_start, "cut {cut} parsed");
                    assert_eq!(pf.points.len(), 306);
                }
                Err(e) => {
                    let msg = e.to_string();
                    assert!(msg.contains("teapot.patches"), "{msg}");
                    match e {
                        Error::Parse { at, .. } => assert!((1..=n_lines).contains(&at.line)),
                        other => panic!("{other:?}"),
                    }
                }
            }
        }
    }

    #[test]
    fn garbage_never_panics() {
        let mut rng = Lcg(0x5eed);
        let path = Path::new("garbage.patches");
        // Raw bytes.
        for _ in 0..2000 {
            let len = rng.below(200);
            let bytes: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
            let _ = parse_patches(&String::from_utf8_lossy(&bytes), path);
        }
        // Files of plausible shape (small counts, random valid values). One in four is
        // perturbed: junk values, off-by-one counts and field counts, an index past the end.
        const JUNK: [&str; 8] = ["nan", "inf", "x", "", "-1", "0", "1e999", "99999999999"];
        let mut ok = 0;
        for _ in 0..20000 {
            let bad = rng.below(4) == 0;
            // Small perturbation of `n`, in bad files only.
            let off = |rng: &mut Lcg, n: usize| {
                if bad && rng.below(8) == 0 {
                    (n + rng.below(3)).saturating_sub(1)
                } else {
                    n
                }
            };
            // A junk value now and then in a bad file, else `valid`.
            let field = |rng: &mut Lcg, valid: String| {
                if bad && rng.below(40) == 0 {
                    JUNK[rng.below(JUNK.len())].to_string()
                } else {
                    valid
                }
            };
            let n_patches = rng.below(3) + usize::from(!bad);
            let n_points = 1 + rng.below(20);
            let mut lines = vec![field(&mut rng, n_patches.to_string())];
            for _ in 0..off(&mut rng, n_patches) {
                let idx: Vec<String> = (0..off(&mut rng, 16))
                    .map(|_| {
                        let n = off(&mut rng, n_points);
                        let i = 1 + rng.below(n.max(1));
                        field(&mut rng, i.to_string())
                    })
                    .collect();
                lines.push(idx.join(","));
            }
            lines.push(field(&mut rng, n_points.to_string()));
            for _ in 0..off(&mut rng, n_points) {
                let n = 3 + rng.below(2);
                let xyz: Vec<String> = (0..off(&mut rng, n))
                    .map(|_| {
                        let x = rng.below(10);
                        field(&mut rng, format!("{x}.5"))
                    })
                    .collect();
                lines.push(xyz.join(","));
            }
            let s = lines.join(["\n", "\r\n", "\n\n"][rng.below(3)]);
            match parse_patches(&s, path) {
                Ok(pf) => {
                    ok += 1;
                    let n = pf.points.len();
                    assert!(pf.patches.iter().flatten().all(|&i| (i as usize) < n));
                    assert_eq!(pf.weights.len(), n);
                    assert_eq!(pf.lines.len(), pf.patches.len());
                }
                Err(e) => {
                    assert!(bad, "valid file rejected: {e}\n{s}");
                    assert!(e.to_string().contains("garbage.patches"));
                }
            }
        }
        assert!(ok > 15000, "only {ok} random files parsed");
        // Mutations of a valid file: replace one byte.
        let good = one_patch().into_bytes();
        for _ in 0..5000 {
            let mut b = good.clone();
            let at = rng.below(b.len());
            b[at] = b",\n0123456789.-eE x"[rng.below(18)];
            let _ = parse_patches(&String::from_utf8_lossy(&b), path);
        }
    }
}
