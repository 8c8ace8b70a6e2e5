//! The buffers an outside `.gltf` names by URI: `data:` URIs, and files under a
//! [`UriScope`], read no further than their declared length.

use std::io::{self, Read};
use std::path::Path;

use crate::error::{Error, Result};

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
pub(super) fn resolve_uri(
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
