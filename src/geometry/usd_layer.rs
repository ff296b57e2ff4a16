//! Opening one USD layer safely: its bytes from a `.usda`/`.usd` file or from the first layer
//! of a `.usdz` package (told apart by their first bytes), bounded in size, then parsed by the
//! `openusd` crate's text reader, guarded where it recurses on what the file says: it recurses
//! once per nesting level of prims, dictionaries and lists, so a scan counts the nesting first
//! (strings and comments skipped) and refuses a file deeper than [`MAX_TEXT_NESTING`], and the
//! parse runs on a thread of its own with a stack of 64 MiB, so the limit holds
//! whatever thread loads the scene.
//!
//! Binary ("crate") layers are refused with a message that says how to convert them. The
//! crate's binary reader (0.6; later ones need a newer Rust) allocates whatever sizes a file
//! declares and follows its offsets without a bound: fuzzing found a 3 KB file that makes
//! it ask for 5.8 × 10¹⁷ bytes, which aborts the program — no error can report that.

use std::io::{Cursor, Read};
use std::path::Path;

use openusd::sdf;

/// The deepest nesting of brackets a text layer may have.
pub const MAX_TEXT_NESTING: usize = 1000;

/// The stack of the thread that parses a text layer: room for [`MAX_TEXT_NESTING`] levels of
/// the parser's recursion (about 4 KB each, measured) many times over.
const PARSER_STACK: usize = 64 << 20;

/// The largest layer read: 256 MiB, as for scene files.
const MAX_LAYER_BYTES: u64 = crate::input_file::MAX_TEXT_BYTES;

/// A parsed layer, with its text.
pub struct Layer {
    /// The layer's specs and fields.
    pub data: sdf::Data,
    /// The text it was parsed from (for the lines of errors).
    pub text: String,
}

impl Layer {
    /// The value of `name` on the spec at `path`, unless unauthored.
    pub fn field(&self, path: &sdf::Path, name: &str) -> Option<std::borrow::Cow<'_, sdf::Value>> {
        sdf::AbstractData::try_field(&self.data, path, name)
            .ok()
            .flatten()
    }

    /// Whether the spec at `path` has the field `name`.
    pub fn has(&self, path: &sdf::Path, name: &str) -> bool {
        sdf::AbstractData::has_field(&self.data, path, name)
    }
}

/// Reads the layer at `path` ([`layer_from_bytes`]).
pub fn open_layer(path: &Path) -> Result<Layer, String> {
    let bytes =
        crate::input_file::read_bytes(path, MAX_LAYER_BYTES).map_err(|why| format!("the file {why}"))?;
    layer_from_bytes(bytes)
}

/// A layer from a file's bytes, by their start: a USDZ package (a zip archive: its first USD
/// layer, the package's default one), a binary layer (`PXR-USDC`, refused), else text.
pub fn layer_from_bytes(bytes: Vec<u8>) -> Result<Layer, String> {
    let bytes = if bytes.starts_with(b"PK\x03\x04") {
        first_packaged_layer(bytes)?
    } else {
        bytes
    };
    if bytes.starts_with(b"PXR-USDC") {
        return Err(
            "binary USD (crate) layers are not read (the openusd crate's binary reader can abort the \
             program on a malformed file); convert it to text with OpenUSD's `usdcat FILE -o FILE.usda`"
                .to_owned(),
        );
    }
    text_layer(bytes)
}

/// The bytes of a USDZ package's first USD layer.
fn first_packaged_layer(package: Vec<u8>) -> Result<Vec<u8>, String> {
    let mut zip = zip::ZipArchive::new(Cursor::new(package))
        .map_err(|e| format!("not a readable USDZ package: {e}"))?;
    let index = (0..zip.len())
        .find(|&i| {
            zip.name_for_index(i).is_some_and(|n| {
                let n = n.to_ascii_lowercase();
                n.ends_with(".usda") || n.ends_with(".usdc") || n.ends_with(".usd")
            })
        })
        .ok_or("the USDZ package holds no USD layer")?;
    let entry = zip
        .by_index(index)
        .map_err(|e| format!("not a readable USDZ package: {e}"))?;
    let name = entry.name().to_owned();
    let mut bytes = Vec::new();
    entry
        .take(MAX_LAYER_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("the package's layer '{name}' cannot be read: {e}"))?;
    if bytes.len() as u64 > MAX_LAYER_BYTES {
        return Err(format!(
            "the package's layer '{name}' is larger than {MAX_LAYER_BYTES} bytes"
        ));
    }
    if bytes.starts_with(b"PK\x03\x04") {
        return Err(format!("the package's layer '{name}' is itself a package"));
    }
    Ok(bytes)
}

/// A text layer, its nesting checked, parsed on a thread with a stack of its own.
fn text_layer(bytes: Vec<u8>) -> Result<Layer, String> {
    let text = String::from_utf8(bytes).map_err(|_| "neither a USD binary file nor UTF-8 text".to_owned())?;
    let depth = nesting(&text);
    if depth > MAX_TEXT_NESTING {
        return Err(format!(
            "its brackets nest {depth} deep; at most {MAX_TEXT_NESTING} levels are read"
        ));
    }
    let parse = std::thread::Builder::new()
        .name("caustic-usda".into())
        .stack_size(PARSER_STACK)
        .spawn(move || {
            let mut parser = openusd::usda::parser::Parser::new(&text);
            let specs = parser.parse().map_err(|e| match parser.last_error_highlight() {
                Some(h) => format!("line {}, column {}: {e:#}", h.line, h.column),
                None => format!("{e:#}"),
            });
            specs.map(|specs| (sdf::Data::from_specs(specs), text))
        })
        .map_err(|e| format!("cannot start the USD parser: {e}"))?;
    let (data, text) = parse
        .join()
        .map_err(|_| "the USD text parser failed on this file".to_owned())?
        .map_err(|e| format!("not a readable USD text file: {e}"))?;
    Ok(Layer { data, text })
}

/// The line (1-based) of `prim`'s definition in `text`, or of its attribute `attr` when given
/// and found after it: for errors, found by the names alone (the parsed layer keeps no lines).
pub fn line_of(text: &str, prim: &str, attr: Option<&str>) -> Option<usize> {
    let mut pos = 0;
    for name in prim.split('/').filter(|n| !n.is_empty()) {
        let quoted = format!("\"{name}\"");
        pos += text[pos..].find(&quoted)?;
        pos += quoted.len();
    }
    if let Some(attr) = attr {
        let bytes = text.as_bytes();
        let mut from = pos;
        while let Some(k) = text[from..].find(attr) {
            let (start, end) = (from + k, from + k + attr.len());
            let before = start.checked_sub(1).map(|i| bytes[i]);
            let after = bytes.get(end).copied();
            if before.is_some_and(|b| b.is_ascii_whitespace())
                && after.is_some_and(|b| b.is_ascii_whitespace() || b == b'=')
            {
                pos = start;
                break;
            }
            from = end;
        }
    }
    Some(text[..pos].matches('\n').count() + 1)
}

/// The deepest nesting of `{`, `[` and `(` in USD text, outside strings, asset paths and
/// comments.
pub fn nesting(text: &str) -> usize {
    let bytes = text.as_bytes();
    let (mut depth, mut deepest, mut i) = (0usize, 0usize, 0usize);
    while i < bytes.len() {
        match bytes[i] {
            b'#' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
            }
            quote @ (b'"' | b'\'' | b'@') => {
                let triple = bytes[i..].starts_with(&[quote; 3]);
                let close: &[u8] = if triple {
                    &bytes[i..i + 3]
                } else {
                    &bytes[i..i + 1]
                };
                i += close.len();
                while i < bytes.len() && !bytes[i..].starts_with(close) {
                    i += if bytes[i] == b'\\' && quote != b'@' { 2 } else { 1 };
                }
                i += close.len() - 1;
            }
            b'{' | b'[' | b'(' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            b'}' | b']' | b')' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nesting_skips_strings_and_comments() {
        assert_eq!(nesting("def \"a\" { def \"b\" { x = [(1, 2)] } }"), 4);
        assert_eq!(
            nesting("# {{{{\n\"((((\" '[[' @{{@ \"\"\"{\n{\"\"\" \"\\\"{\" {}"),
            1
        );
        assert_eq!(nesting(&"[".repeat(5000)), 5000);
    }

    #[test]
    fn deep_text_is_refused_not_overflowed() {
        let n = 50_000;
        let deep = format!("#usda 1.0\n{}{}", "def \"a\" {\n".repeat(n), "}\n".repeat(n));
        let err = text_layer(deep.into_bytes()).err().expect("refused");
        assert!(err.contains("nest 50000 deep"), "{err}");
        // At the limit, the parser's own thread has room.
        let n = MAX_TEXT_NESTING;
        let deep = format!(
            "#usda 1.0\n(\n customLayerData = {}{{}}{}\n)\n",
            "{ dictionary a = ".repeat(n - 2),
            " }".repeat(n - 2)
        );
        assert!(text_layer(deep.into_bytes()).is_ok());
    }
}
