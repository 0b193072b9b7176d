//! `fmuResourceLocation` → a local directory.
//!
//! Importers spell the same directory in several ways (docs/fmu.md, "What the importers do"): fmpy and fmuCheck pass
//! `file:///tmp/x%20y` (percent-encoded), OMSimulator (fmi4c) passes `file:////tmp/x y` (four
//! slashes, not encoded), others `file:/tmp/x` or `file://localhost/tmp/x`. All of them are
//! accepted here; so is a bare absolute path, which some tools pass although it is not a URI.

use std::path::PathBuf;

/// Parses a resource-location URI into a local path.
///
/// Accepted: `file:///abs`, `file:/abs`, `file://localhost/abs`, `file:////abs` (leading slashes
/// collapse to one), scheme case-insensitive, percent-escapes decoded (bytes, so UTF-8 and other
/// encodings survive), and a plain absolute path. Rejected with a reason: another scheme, a
/// remote host (`file://server/share`), a malformed escape, an empty or relative path.
pub fn resource_path(uri: &str) -> Result<PathBuf, String> {
    let path_part = if let Some(rest) = strip_prefix_ignore_case(uri, "file:") {
        if let Some(after) = rest.strip_prefix("//") {
            // `file://<authority>/<path>`; an empty authority gives `file:///path`, and OMS's
            // `file:////path` has an empty authority followed by `//path`.
            if after.starts_with('/') {
                after.to_string()
            } else {
                let (host, path) = match after.find('/') {
                    Some(i) => (&after[..i], &after[i..]),
                    None => (after, ""),
                };
                if !host.eq_ignore_ascii_case("localhost") {
                    return Err(format!(
                        "resource location '{uri}' names the remote host '{host}'; only local files are supported"
                    ));
                }
                path.to_string()
            }
        } else {
            rest.to_string()
        }
    } else if uri.contains("://") || looks_like_scheme(uri) {
        return Err(format!(
            "resource location '{uri}' is not a file URI; only file:// is supported"
        ));
    } else {
        uri.to_string()
    };
    let bytes =
        percent_decode(&path_part).map_err(|e| format!("resource location '{uri}': {e}"))?;
    let mut path = bytes_to_path(bytes);
    path = collapse_leading_slashes(path);
    if path.as_os_str().is_empty() {
        return Err(format!("resource location '{uri}' has an empty path"));
    }
    if !path.is_absolute() {
        return Err(format!("resource location '{uri}' is not an absolute path"));
    }
    Ok(path)
}

fn strip_prefix_ignore_case<'a>(s: &'a str, prefix: &str) -> Option<&'a str> {
    if s.len() >= prefix.len()
        && s.is_char_boundary(prefix.len())
        && s[..prefix.len()].eq_ignore_ascii_case(prefix)
    {
        Some(&s[prefix.len()..])
    } else {
        None
    }
}

/// `scheme:` with a scheme of at least two characters (so `C:\dir` on Windows is not a scheme).
fn looks_like_scheme(s: &str) -> bool {
    match s.find(':') {
        Some(i) if i >= 2 => {
            let scheme = &s[..i];
            scheme
                .chars()
                .next()
                .is_some_and(|c| c.is_ascii_alphabetic())
                && scheme
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'))
        }
        _ => false,
    }
}

/// Decodes `%XX` escapes into bytes; other characters are kept as their UTF-8 bytes.
fn percent_decode(s: &str) -> Result<Vec<u8>, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("malformed percent escape at byte {i}"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Ok(out)
}

#[cfg(unix)]
fn bytes_to_path(bytes: Vec<u8>) -> PathBuf {
    use std::os::unix::ffi::OsStringExt;
    PathBuf::from(std::ffi::OsString::from_vec(bytes))
}

#[cfg(not(unix))]
fn bytes_to_path(bytes: Vec<u8>) -> PathBuf {
    let s = String::from_utf8_lossy(&bytes).into_owned();
    // `file:///C:/dir` gives `/C:/dir`: drop the slash before the drive letter.
    let b = s.as_bytes();
    if b.len() >= 3 && b[0] == b'/' && b[1].is_ascii_alphabetic() && b[2] == b':' {
        return PathBuf::from(&s[1..]);
    }
    PathBuf::from(s)
}

/// `//tmp/x` (OMS's four-slash URI) → `/tmp/x`. On Unix a path with leading `//` names the same
/// file as with one slash (POSIX leaves exactly two slashes implementation-defined; Linux treats
/// them as one). Elsewhere the path is returned unchanged.
fn collapse_leading_slashes(path: PathBuf) -> PathBuf {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::{OsStrExt, OsStringExt};
        let b = path.as_os_str().as_bytes();
        let n = b.iter().take_while(|&&c| c == b'/').count();
        if n > 1 {
            return PathBuf::from(std::ffi::OsString::from_vec(b[n - 1..].to_vec()));
        }
    }
    path
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;

    fn ok(uri: &str) -> String {
        resource_path(uri)
            .unwrap_or_else(|e| panic!("{uri}: {e}"))
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn every_importer_spelling_gives_the_same_directory() {
        assert_eq!(ok("file:///tmp/fmu/resources"), "/tmp/fmu/resources");
        assert_eq!(ok("file:/tmp/fmu/resources"), "/tmp/fmu/resources");
        assert_eq!(
            ok("file://localhost/tmp/fmu/resources"),
            "/tmp/fmu/resources"
        );
        assert_eq!(ok("file:////tmp/fmu/resources"), "/tmp/fmu/resources");
        assert_eq!(ok("FILE:///tmp/fmu/resources/"), "/tmp/fmu/resources/");
        assert_eq!(ok("/tmp/fmu/resources"), "/tmp/fmu/resources");
    }

    #[test]
    fn percent_escapes_are_decoded_as_bytes() {
        assert_eq!(ok("file:///tmp/a%20b/%25x"), "/tmp/a b/%x");
        // "ü" is C3 BC in UTF-8.
        assert_eq!(ok("file:///tmp/%C3%BC"), "/tmp/\u{fc}");
        // OMS does not encode: spaces arrive literally.
        assert_eq!(ok("file:////tmp/a b"), "/tmp/a b");
    }

    #[test]
    fn unsupported_locations_are_rejected_with_a_reason() {
        for uri in [
            "http://example.com/r",
            "file://server/share/r",
            "file:///tmp/%zz",
            "file:///tmp/%2",
            "relative/dir",
            "",
            "file:",
        ] {
            let e = resource_path(uri).expect_err(uri);
            assert!(e.contains("resource location"), "{uri}: {e}");
        }
    }
}
