//! The marks lsyc's outputs carry, and telling a file lsyc wrote from one it
//! did not (a hand-written `.mtl`, a picture someone drew), so that the
//! command line replaces only what it made itself beside an output.
//!
//! Owns: the marks (the SVG head, the PNG `Software` text, the OBJ and MTL
//! header comments, the glTF generator) and `made_by_lsyc`. The writers use
//! the constants here; a change of a mark is a change here. Must not read
//! more than the head of a file.

use std::io::Read;
use std::path::Path;

/// The start of every SVG lsyc writes.
pub const SVG_HEAD: &str = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\" viewBox=\"";
/// The PNG text chunk (keyword, text) of every PNG lsyc writes.
pub const PNG_SOFTWARE: (&str, &str) = ("Software", "lsyc");
/// The comment at the head of every OBJ lsyc writes (after `mtllib`).
pub const OBJ_COMMENT: &str = "# lsyc OBJ";
/// The first line of every material library lsyc writes.
pub const MTL_COMMENT: &str = "# lsyc MTL";
/// The glTF `asset.generator` of every GLB lsyc writes.
pub const GLTF_GENERATOR: &str = "lsyc";

/// How much of a file is read to find its mark.
const HEAD_BYTES: usize = 64 * 1024;

/// Whether the file at `path` was written by lsyc, judged by its extension
/// and its head: an empty file counts as lsyc's too (nothing to lose), a
/// file that cannot be read or has an extension lsyc does not write does not.
pub fn made_by_lsyc(path: &Path) -> bool {
    let Some(head) = head(path) else {
        return false;
    };
    if head.is_empty() {
        return true;
    }
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("svg") => head.starts_with(SVG_HEAD.as_bytes()),
        Some("png" | "apng") => png_marked(&head),
        Some("obj") => contains(&head[..head.len().min(4096)], OBJ_COMMENT.as_bytes()),
        Some("mtl") => head.starts_with(MTL_COMMENT.as_bytes()),
        Some("glb") => glb_marked(&head),
        Some("txt") => module_string(&head),
        _ => false,
    }
}

/// The first `HEAD_BYTES` of a file.
fn head(path: &Path) -> Option<Vec<u8>> {
    let f = std::fs::File::open(path).ok()?;
    let mut buf = Vec::new();
    f.take(HEAD_BYTES as u64).read_to_end(&mut buf).ok()?;
    Some(buf)
}

fn contains(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w == needle)
}

/// A PNG whose text chunks (before the image data) include lsyc's `Software`.
fn png_marked(data: &[u8]) -> bool {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    if !data.starts_with(SIGNATURE) {
        return false;
    }
    let want = format!("{}\0{}", PNG_SOFTWARE.0, PNG_SOFTWARE.1);
    let mut at = SIGNATURE.len();
    while let Some(chunk) = data.get(at..at + 8) {
        let len = u32::from_be_bytes([chunk[0], chunk[1], chunk[2], chunk[3]]) as usize;
        let kind = &chunk[4..8];
        let body = at + 8;
        if kind == b"IDAT" || kind == b"IEND" {
            return false;
        }
        if kind == b"tEXt" && data.get(body..body + len) == Some(want.as_bytes()) {
            return true;
        }
        at = body.saturating_add(len).saturating_add(4);
    }
    false
}

/// A binary glTF whose JSON names lsyc as its generator.
fn glb_marked(data: &[u8]) -> bool {
    let want = format!("\"generator\":\"{GLTF_GENERATOR}\"");
    data.starts_with(b"glTF") && contains(data, want.as_bytes())
}

/// A derived string as `-o X.txt` writes it: one line, ending with a newline.
fn module_string(data: &[u8]) -> bool {
    match data.iter().position(|&b| b == b'\n') {
        Some(i) => i + 1 == data.len(),
        // Longer than the head read: one line so far.
        None => data.len() == HEAD_BYTES,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn marks_are_found_only_where_lsyc_put_them() {
        let dir = tempfile::tempdir().expect("tempdir");
        let file = |name: &str, bytes: &[u8]| {
            let p = dir.path().join(name);
            std::fs::write(&p, bytes).expect("writes");
            made_by_lsyc(&p)
        };
        assert!(file("a.mtl", b"# lsyc MTL: one material\nnewmtl x\n"));
        assert!(!file("b.mtl", b"newmtl bark\nKd 0.5 0.3 0.1\n"));
        assert!(file("c.obj", b"mtllib c.mtl\n# lsyc OBJ: tubes\nv 0 0 0\n"));
        assert!(!file("d.obj", b"v 0 0 0\nf 1 1 1\n"));
        assert!(file("e.txt", b"F+F-F\n"));
        assert!(!file("f.txt", b"notes\nmore notes\n"));
        assert!(file("g.svg", format!("{SVG_HEAD}0 0 1 1\"/>").as_bytes()));
        assert!(!file(
            "h.svg",
            b"<svg xmlns=\"http://www.w3.org/2000/svg\"/>"
        ));
        assert!(file("empty.svg", b""));
        assert!(!file("i.png", b"\x89PNG\r\n\x1a\n\0\0\0\0IDAT"));
        assert!(!file("j.lsy", b"lsystem A { axiom F; }"));
    }
}
