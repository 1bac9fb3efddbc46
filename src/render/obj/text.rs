//! The OBJ text of a mesh and its MTL material library.
//!
//! Owns: the OBJ line syntax (`v`, `vn`, `f v//vn`, `usemtl`, `o`, `mtllib`,
//! comments), buffered writing with the first IO error kept, and the MTL file.
//! Must not build geometry.

use super::MeshTarget;
use crate::number::{write_significant, write_uint};
use glam::DVec3;
use std::io::{self, Write};

/// Output is assembled in a buffer of this size before it is written.
const BUFFER: usize = 1 << 16;

/// Materials are called this followed by the colour index: `lsyc_color3`.
pub const MATERIAL_PREFIX: &str = "lsyc_color";

/// The material name of colour `color` (the same in OBJ, MTL and glTF).
pub fn material_name(color: u32) -> String {
    format!("{MATERIAL_PREFIX}{color}")
}

/// OBJ text, buffered. Call [`ObjText::finish`] to flush.
pub struct ObjText<W: Write> {
    out: W,
    /// Text not yet written to `out`.
    buf: Vec<u8>,
    /// The first write error; nothing is written after it.
    error: Option<io::Error>,
    palette: crate::render::Palette,
}

impl<W: Write> ObjText<W> {
    pub fn new(out: W) -> Self {
        ObjText {
            out,
            buf: Vec::with_capacity(BUFFER + 256),
            error: None,
            palette: crate::render::Palette::default(),
        }
    }

    /// A `mtllib` line: the material library the faces' `usemtl` refer to.
    pub fn mtllib(&mut self, file: &str) {
        self.text(&format!("mtllib {file}\n"));
    }

    /// Writes what is left and flushes; reports the first IO error of any
    /// earlier write.
    pub fn finish(mut self) -> io::Result<W> {
        self.drain();
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        self.out.flush()?;
        Ok(self.out)
    }

    /// Writes the buffer out (or drops it after an error).
    fn drain(&mut self) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(&self.buf)
        {
            self.error = Some(e);
        }
        self.buf.clear();
    }

    /// Ends a line; writes the buffer out when it is full.
    fn end_line(&mut self) {
        self.buf.push(b'\n');
        if self.buf.len() >= BUFFER {
            self.drain();
        }
    }

    fn text(&mut self, t: &str) {
        self.buf.extend_from_slice(t.as_bytes());
        if self.buf.len() >= BUFFER {
            self.drain();
        }
    }

    fn triple(&mut self, tag: &[u8], p: DVec3) {
        self.buf.extend_from_slice(tag);
        for x in [p.x, p.y, p.z] {
            self.buf.push(b' ');
            write_significant(&mut self.buf, x);
        }
        self.end_line();
    }
}

impl<W: Write> MeshTarget for ObjText<W> {
    fn vertex(&mut self, p: DVec3) {
        self.triple(b"v", p);
    }

    fn normal(&mut self, n: DVec3) {
        self.triple(b"vn", n);
    }

    fn face(&mut self, corners: &[(u64, u64)]) {
        self.buf.push(b'f');
        for &(v, n) in corners {
            self.buf.push(b' ');
            write_uint(&mut self.buf, v);
            self.buf.extend_from_slice(b"//");
            write_uint(&mut self.buf, n);
        }
        self.end_line();
    }

    fn material(&mut self, color: u32) {
        self.text(&format!("usemtl {}\n", self.palette.material(color)));
    }

    fn object(&mut self, name: &str) {
        // An OBJ name is one word: spaces and line breaks become `_`.
        let name: String = name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        self.text(&format!("o {name}\n"));
    }

    fn palette(&mut self, palette: &crate::render::Palette) {
        self.palette = palette.clone();
    }

    fn comment(&mut self, text: &str) {
        for line in text.lines() {
            self.text(&format!("# {line}\n"));
        }
    }
}

/// The MTL material library of `colors`: one diffuse material per colour,
/// named as `usemtl` names it, its `Kd` the palette colour in linear RGB (as
/// glTF's base colour).
pub fn write_mtl(out: &mut dyn Write, colors: &[u32]) -> io::Result<()> {
    write_mtl_with(out, colors, &crate::render::Palette::default())
}

/// [`write_mtl`] with a program's palette: its colours and material names.
pub fn write_mtl_with(
    out: &mut dyn Write,
    colors: &[u32],
    palette: &crate::render::Palette,
) -> io::Result<()> {
    let mut buf = Vec::new();
    buf.extend_from_slice(crate::render::mark::MTL_COMMENT.as_bytes());
    buf.extend_from_slice(b": one material per palette colour\n");
    for &c in colors {
        let [r, g, b] = palette.linear(c);
        buf.extend_from_slice(format!("\nnewmtl {}\n", palette.material(c)).as_bytes());
        buf.extend_from_slice(b"Kd");
        for x in [r, g, b] {
            buf.push(b' ');
            write_significant(&mut buf, x);
        }
        buf.extend_from_slice(b"\nKa 0 0 0\nKs 0 0 0\nd 1\nillum 1\n");
        buf.extend_from_slice(format!("# {}\n", palette.hex(c)).as_bytes());
    }
    out.write_all(&buf)?;
    out.flush()
}
