//! Wavefront OBJ loader (own parser; positions and faces only).
//!
//! Read: `v x y z [w | r g b]` (extra values ignored), `f` with `v`, `v/vt`, `v//vn` or
//! `v/vt/vn` references, 1-based or negative (relative to the vertices defined so far)
//! indices, `o`/`g` names, `#` comments (at line start or after whitespace), `\r\n` line ends,
//! trailing whitespace and `\` line continuations.
//!
//! - **Faces** with more than 3 vertices are fan-triangulated: `(v0, v[i], v[i+1])`.
//! - **Triangle order** is file order: faces as they appear, each face's fan in order.
//! - **Vertices** are kept as listed (no merging); every `v` becomes one position.
//! - **Objects**: every `o` or `g` statement starts a new object named by the rest of its line
//!   (so a name used twice gives two objects). Faces before any `o`/`g` go to a leading
//!   unnamed object. Objects without faces are dropped; unnamed ones are called `object<i>`
//!   (`i` = index in the final object list).
//! - Known but irrelevant statements (`vn`, `vt`, `s`, `usemtl`, `mtllib`, curves, …) are
//!   ignored; materials are never opened. Point and line elements (`p`, `l`) are skipped with
//!   one warning. Any other line (e.g. the vertex/face count line `6540 2180` some tools
//!   write) is skipped with a warning `line N: skipped unrecognised line '…'`.
//! - Names and comments may hold any bytes (decoded lossily); a number that is not valid UTF-8
//!   is an error `line N: not UTF-8 at byte B`.

use std::borrow::Cow;
use std::path::Path;

use glam::DVec3;

use super::{clip, drop_empty_objects, non_finite};
use crate::error::{Error, Result};
use crate::scene::mesh::{Loaded, Mesh, Object};

/// The most vertices one face (polygon) may have: a larger one is refused with its line number
/// before its indices are collected, so one huge `f` line cannot take the machine's memory.
pub const MAX_FACE_VERTICES: usize = 1 << 16;

/// The most triangles an OBJ file may make (faces fan-triangulated), counted while parsing;
/// the same bound as a glTF scene's ([`crate::load::MAX_TRIANGLES`]).
const MAX_TRIANGLES: usize = super::MAX_TRIANGLES;

/// How many unrecognised lines are reported individually before summarising.
const MAX_LINE_WARNINGS: usize = 10;

/// Statements that are valid OBJ but carry nothing a clash needs.
const IGNORED: &[&[u8]] = &[
    b"vn",
    b"vt",
    b"vp",
    b"s",
    b"usemtl",
    b"mtllib",
    b"usemap",
    b"maplib",
    b"cstype",
    b"deg",
    b"bmat",
    b"step",
    b"curv",
    b"curv2",
    b"surf",
    b"parm",
    b"trim",
    b"hole",
    b"scrv",
    b"sp",
    b"end",
    b"con",
    b"mg",
    b"bevel",
    b"c_interp",
    b"d_interp",
    b"lod",
    b"shadow_obj",
    b"trace_obj",
    b"ctech",
    b"stech",
    b"call",
    b"csh",
    b"res",
];

/// Parses OBJ `bytes`; see the module doc. Validation of the result is done by the caller too.
pub(crate) fn load(path: &Path, bytes: &[u8]) -> Result<Loaded> {
    Parser::new(path, MAX_TRIANGLES).run(bytes)
}

struct Parser<'p> {
    path: &'p Path,
    mesh: Mesh,
    /// Index of the object faces currently go to.
    current: u32,
    warnings: Vec<String>,
    unrecognised: usize,
    skipped_elements: usize,
    /// Positive indices beyond the vertices defined so far: (line, 1-based index).
    forward_refs: Vec<(usize, i64)>,
    face: Vec<u32>,
    /// [`MAX_TRIANGLES`] (smaller in tests).
    max_triangles: usize,
}

impl<'p> Parser<'p> {
    fn new(path: &'p Path, max_triangles: usize) -> Self {
        Parser {
            path,
            mesh: Mesh { objects: vec![Object::default()], ..Default::default() },
            current: 0,
            warnings: Vec::new(),
            unrecognised: 0,
            skipped_elements: 0,
            forward_refs: Vec::new(),
            face: Vec::new(),
            max_triangles,
        }
    }

    fn err(&self, line: usize, msg: impl std::fmt::Display) -> Error {
        Error::input(self.path, format!("line {line}: {msg}"))
    }

    fn run(mut self, bytes: &[u8]) -> Result<Loaded> {
        let mut lines = Lines { bytes, pos: 0, line: 0 };
        while let Some((line_no, start, text)) = lines.next_logical() {
            self.statement(line_no, start, &text)?;
        }
        let n = self.mesh.positions.len() as i64;
        if let Some(&(line, idx)) = self.forward_refs.iter().find(|(_, i)| *i > n) {
            return Err(self.err(line, format!("face refers to vertex {idx} but there are {n} vertices")));
        }
        if self.unrecognised > MAX_LINE_WARNINGS {
            self.warnings
                .push(format!("{} more unrecognised lines skipped", self.unrecognised - MAX_LINE_WARNINGS));
        }
        if self.skipped_elements > 0 {
            self.warnings
                .push(format!("skipped {} point/line elements ('p'/'l' statements)", self.skipped_elements));
        }
        drop_empty_objects(&mut self.mesh);
        for (i, o) in self.mesh.objects.iter_mut().enumerate() {
            if o.name.is_empty() {
                o.name = format!("object{i}");
            }
        }
        Ok(Loaded { mesh: self.mesh, warnings: self.warnings })
    }

    /// Handles one logical line; `start` is its byte offset in the file.
    fn statement(&mut self, line: usize, start: usize, text: &[u8]) -> Result<()> {
        let mut tokens = Tokens { text, pos: 0 };
        let Some((_, keyword)) = tokens.next() else {
            return Ok(());
        };
        match keyword {
            b"v" => match std::str::from_utf8(text) {
                // One UTF-8 check per line, not per coordinate (it was a fifth of the parse).
                Ok(valid) => self.vertex(line, start, &mut tokens, Some(valid)),
                Err(_) => self.vertex(line, start, &mut tokens, None),
            },
            b"f" | b"fo" => self.face(line, start, &mut tokens),
            b"o" | b"g" => {
                let name = String::from_utf8_lossy(tokens.rest()).trim().to_string();
                self.mesh.objects.push(Object { name, ..Default::default() });
                self.current = (self.mesh.objects.len() - 1) as u32;
                Ok(())
            }
            b"p" | b"l" => {
                self.skipped_elements += 1;
                Ok(())
            }
            k if IGNORED.contains(&k) => Ok(()),
            _ => {
                self.unrecognised += 1;
                if self.unrecognised <= MAX_LINE_WARNINGS {
                    let shown = String::from_utf8_lossy(trim(text));
                    self.warnings
                        .push(format!("line {line}: skipped unrecognised line '{}'", clip(&shown, 60)));
                }
                Ok(())
            }
        }
    }

    /// `valid`: the whole line, when it is known to be UTF-8.
    fn vertex(&mut self, line: usize, start: usize, tokens: &mut Tokens, valid: Option<&str>) -> Result<()> {
        let mut c = [0.0f64; 3];
        for (k, slot) in c.iter_mut().enumerate() {
            let Some((off, tok)) = tokens.next() else {
                return Err(self.err(line, format!("vertex has {k} coordinates (needs 3)")));
            };
            // Tokens end at ASCII whitespace, so they are char boundaries of a valid line.
            let s = match valid {
                Some(text) => &text[off..off + tok.len()],
                None => self.utf8(line, start + off, tok)?,
            };
            *slot = s.parse::<f64>().map_err(|_| {
                self.err(line, format!("cannot parse '{}' as a vertex coordinate", clip(s, 40)))
            })?;
        }
        let index = self.mesh.positions.len();
        if let Some(bad) = non_finite(c) {
            return Err(self.err(line, format!("vertex {} has a non-finite coordinate ({bad})", index + 1)));
        }
        if index > u32::MAX as usize {
            return Err(self.err(line, "more than 4294967296 vertices"));
        }
        self.mesh.positions.push(DVec3::from_array(c));
        Ok(())
    }

    fn face(&mut self, line: usize, start: usize, tokens: &mut Tokens) -> Result<()> {
        let mut face = std::mem::take(&mut self.face);
        face.clear();
        let defined = self.mesh.positions.len() as i64;
        while let Some((off, tok)) = tokens.next() {
            if face.len() == MAX_FACE_VERTICES {
                return Err(self.err(
                    line,
                    format!("face has more than {MAX_FACE_VERTICES} vertices, the most meshclash reads in one polygon"),
                ));
            }
            let v = tok.split(|&b| b == b'/').next().unwrap_or(tok);
            let idx = match plain_index(v) {
                Some(i) => i,
                None => {
                    let s = self.utf8(line, start + off, v)?;
                    s.parse().map_err(|_| {
                        self.err(line, format!("cannot parse '{}' as a face vertex index", clip(s, 40)))
                    })?
                }
            };
            let zero_based = match idx {
                0 => return Err(self.err(line, "face refers to vertex 0 (OBJ indices start at 1)")),
                i if i < 0 => {
                    let r = defined + i;
                    if r < 0 {
                        return Err(self.err(
                            line,
                            format!(
                                "face refers to vertex {i} but only {defined} vertices are \
                                 defined before it"
                            ),
                        ));
                    }
                    r
                }
                i => {
                    if i > defined {
                        self.forward_refs.push((line, i));
                    }
                    i - 1
                }
            };
            let Ok(z) = u32::try_from(zero_based) else {
                return Err(self.err(line, format!("face refers to vertex {idx}, beyond any file")));
            };
            face.push(z);
        }
        if face.len() < 3 {
            return Err(self.err(line, format!("face has {} vertices (needs at least 3)", face.len())));
        }
        let total = self.mesh.triangles.len() + face.len() - 2;
        if total > self.max_triangles {
            return Err(self.err(
                line,
                format!(
                    "the faces so far make {total} triangles, more than the {} supported",
                    self.max_triangles
                ),
            ));
        }
        self.mesh.triangles.reserve(face.len() - 2);
        for i in 1..face.len() - 1 {
            self.mesh.triangles.push([face[0], face[i], face[i + 1]]);
            self.mesh.tri_object.push(self.current);
        }
        self.face = face;
        Ok(())
    }

    fn utf8<'a>(&self, line: usize, offset: usize, tok: &'a [u8]) -> Result<&'a str> {
        std::str::from_utf8(tok)
            .map_err(|e| self.err(line, format!("not UTF-8 at byte {}", offset + e.valid_up_to())))
    }
}

/// Splits the file into logical lines: `\n`-terminated, `\r` stripped, `\`-continued lines
/// joined.
struct Lines<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    /// One physical line without its terminator: (1-based line number, start offset, text).
    fn physical(&mut self) -> Option<(usize, usize, &'a [u8])> {
        if self.pos >= self.bytes.len() {
            return None;
        }
        let start = self.pos;
        let rest = &self.bytes[start..];
        let len = memchr::memchr(b'\n', rest).unwrap_or(rest.len());
        self.pos = start + len + 1;
        self.line += 1;
        let mut text = &rest[..len];
        if let [head @ .., b'\r'] = text {
            text = head;
        }
        Some((self.line, start, text))
    }

    /// One logical line. Offsets inside continued lines are approximate (relative to the
    /// first physical line), which only affects the byte number in UTF-8 errors.
    fn next_logical(&mut self) -> Option<(usize, usize, Cow<'a, [u8]>)> {
        let (line, start, text) = self.physical()?;
        if !continues(text) {
            return Some((line, start, Cow::Borrowed(text)));
        }
        let mut joined = trim_end(text).to_vec();
        while continues(&joined) {
            joined.pop();
            joined.push(b' ');
            match self.physical() {
                Some((_, _, next)) => joined.extend_from_slice(trim_end(next)),
                None => break,
            }
        }
        Some((line, start, Cow::Owned(joined)))
    }
}

/// The common face index spelling, `[-]digits` with at most 18 digits (cannot overflow), read
/// without a UTF-8 check; anything else (a `+`, more digits, garbage) goes through `str::parse`,
/// which gives the same value or the error.
fn plain_index(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t {
        [b'-', rest @ ..] => (true, rest),
        _ => (false, t),
    };
    if digits.is_empty() || digits.len() > 18 || !digits.iter().all(u8::is_ascii_digit) {
        return None;
    }
    let v = digits.iter().fold(0i64, |v, &d| v * 10 + (d - b'0') as i64);
    Some(if neg { -v } else { v })
}

fn continues(text: &[u8]) -> bool {
    trim_end(text).last() == Some(&b'\\')
}

fn trim_end(t: &[u8]) -> &[u8] {
    let end = t.iter().rposition(|b| !b.is_ascii_whitespace()).map_or(0, |i| i + 1);
    &t[..end]
}

fn trim(t: &[u8]) -> &[u8] {
    let t = trim_end(t);
    let start = t.iter().position(|b| !b.is_ascii_whitespace()).unwrap_or(t.len());
    &t[start..]
}

/// Whitespace-separated tokens of a line, stopping at a `#` that starts a token.
struct Tokens<'a> {
    text: &'a [u8],
    pos: usize,
}

impl<'a> Tokens<'a> {
    /// The next token and its offset in the line.
    fn next(&mut self) -> Option<(usize, &'a [u8])> {
        let t = self.text;
        while self.pos < t.len() && t[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        if self.pos >= t.len() || t[self.pos] == b'#' {
            self.pos = t.len();
            return None;
        }
        let start = self.pos;
        while self.pos < t.len() && !t[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        Some((start, &t[start..self.pos]))
    }
    /// The rest of the line (up to a `#` that starts a token), untrimmed.
    fn rest(&mut self) -> &'a [u8] {
        let t = &self.text[self.pos.min(self.text.len())..];
        let mut end = t.len();
        for i in 0..t.len() {
            if t[i] == b'#' && (i == 0 || t[i - 1].is_ascii_whitespace()) {
                end = i;
                break;
            }
        }
        self.pos = self.text.len();
        &t[..end]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{load_bytes, load_path, shared, Format};
    use std::path::PathBuf;

    fn path() -> PathBuf {
        PathBuf::from("test.obj")
    }

    fn ok(src: &[u8]) -> Loaded {
        load_bytes(&path(), src, Format::Obj).unwrap()
    }

    fn err(src: &[u8]) -> String {
        let e = load_bytes(&path(), src, Format::Obj).unwrap_err().to_string();
        assert!(e.starts_with("test.obj: "), "{e}");
        assert!(!e.contains('\n'), "{e}");
        e
    }

    #[test]
    fn regression_huge_face_is_refused_naming_line_and_limit() {
        // Issue 11 item 10: one `f` line with tens of millions of indices reached 3.5 GB.
        let mut src = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n# big\nf".to_vec();
        for _ in 0..MAX_FACE_VERTICES {
            src.extend_from_slice(b" 1");
        }
        let at_cap = ok(&[src.clone(), b"\n".to_vec()].concat());
        assert_eq!(at_cap.mesh.triangles.len(), MAX_FACE_VERTICES - 2);
        src.extend_from_slice(b" 2 3\n");
        let e = err(&src);
        assert!(e.contains("line 5: face has more than 65536 vertices"), "{e}");
    }

    #[test]
    fn fan_triangles_count_against_the_triangle_cap_while_parsing() {
        let src = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 1 2 3 4 1 2\nf 1 2 3\n";
        let p = path();
        let l = Parser::new(&p, 6).run(src).unwrap();
        assert_eq!(l.mesh.triangles.len(), 6);
        let e = Parser::new(&p, 4).run(src).unwrap_err().to_string();
        assert!(e.contains("line 6: the faces so far make 5 triangles, more than the 4 supported"), "{e}");
        let e = Parser::new(&p, 6).run(&[&src[..], b"f 1 2 3\n"].concat()).unwrap_err().to_string();
        assert!(e.contains("line 8:"), "{e}");
    }

    #[test]
    fn quad_fan_and_negative_indices() {
        let src = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\nv 2 2 2\nf 1/1/1 2//3 -1\n";
        let l = ok(src);
        assert_eq!(l.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
        assert_eq!(l.mesh.positions[4], DVec3::new(2.0, 2.0, 2.0));
        assert_eq!(l.mesh.objects.len(), 1);
        assert_eq!(l.mesh.objects[0].name, "object0");
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    }

    #[test]
    fn plain_index_agrees_with_str_parse() {
        for t in ["1", "-1", "0", "-0", "007", "123456789012345678", "-123456789012345678"] {
            assert_eq!(plain_index(t.as_bytes()), Some(t.parse::<i64>().unwrap()), "{t}");
        }
        for t in ["", "-", "+1", "1e3", "1.0", "1234567890123456789", "--1", "1-", "x"] {
            assert_eq!(plain_index(t.as_bytes()), None, "{t}");
        }
    }

    #[test]
    fn pentagon_fan() {
        let l = ok(b"v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n");
        assert_eq!(l.mesh.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }

    #[test]
    fn objects_groups_comments_crlf_continuation() {
        let src = b"# header\r\nmtllib missing.mtl\r\nv 0 0 0 \r\nv 1 0 0\t\r\nv 0 1 0 # c\r\n\
                    o first # named\r\ng\r\nf 1 2 3\r\ng second part\r\nusemtl x\r\ns off\r\n\
                    f 1 \\\r\n 2 3\r\no first\r\nf 3 2 1\r\no empty\r\n";
        let l = ok(src);
        let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["object0", "second part", "first"]);
        assert_eq!(l.mesh.tri_object, vec![0, 1, 2]);
        assert_eq!(l.mesh.triangles[1], [0, 1, 2]);
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    }

    #[test]
    fn unrecognised_lines_warn() {
        let l = ok(b"6540 2180\nv 0 0 0\nv 1 0 0\nv 0 1 0\nfoo bar\nf 1 2 3\n");
        assert_eq!(
            l.warnings,
            vec![
                "line 1: skipped unrecognised line '6540 2180'".to_string(),
                "line 5: skipped unrecognised line 'foo bar'".to_string()
            ]
        );
        let mut many = Vec::new();
        for _ in 0..25 {
            many.extend_from_slice(b"junk\n");
        }
        many.extend_from_slice(b"v 0 0 0\nf 1 1 1\nl 1 1\n");
        let l = ok(&many);
        assert_eq!(l.warnings.len(), MAX_LINE_WARNINGS + 2, "{:?}", l.warnings);
        assert!(l.warnings.contains(&"15 more unrecognised lines skipped".to_string()));
        assert!(l.warnings.last().unwrap().contains("1 point/line"));
        // a degenerate (repeated index) triangle is kept
        assert_eq!(l.mesh.triangles, vec![[0, 0, 0]]);
    }

    #[test]
    fn index_errors() {
        let e = err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
        assert!(e.contains("line 4: face refers to vertex 0 (OBJ indices start at 1)"), "{e}");
        let e = err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
        assert!(e.contains("line 4: face refers to vertex 4 but there are 3 vertices"), "{e}");
        let e = err(b"v 0 0 0\nv 1 0 0\nf 1 2 -3\nv 0 1 0\n");
        assert!(e.contains("line 3: face refers to vertex -3 but only 2 vertices"), "{e}");
        let e = err(b"v 0 0 0\nv 1 0 0\nf 1 2\n");
        assert!(e.contains("line 3: face has 2 vertices"), "{e}");
        let e = err(b"v 0 0 0\nf 1 x 1\n");
        assert!(e.contains("line 2: cannot parse 'x' as a face vertex index"), "{e}");
        let e = err(b"v 0 0 0\nf 1 1 99999999999999999999\n");
        assert!(e.contains("line 2: cannot parse"), "{e}");
        let e = err(b"v 0 0 0\nf 1 1 9999999999999\n");
        assert!(e.contains("line 2: face refers to vertex 9999999999999"), "{e}");
    }

    #[test]
    fn forward_reference_is_allowed() {
        let l = ok(b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
        assert_eq!(l.mesh.triangles, vec![[0, 1, 2]]);
    }

    #[test]
    fn vertex_errors() {
        let e = err(b"v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
        assert!(e.contains("line 2: vertex 2 has a non-finite coordinate (NaN)"), "{e}");
        let e = err(b"v 0 0 -inf\n");
        assert!(e.contains("line 1: vertex 1 has a non-finite coordinate (-inf)"), "{e}");
        let e = err(b"v 0 0 1e999\n");
        assert!(e.contains("non-finite coordinate (inf)"), "{e}");
        let e = err(b"v 0 0\n");
        assert!(e.contains("line 1: vertex has 2 coordinates (needs 3)"), "{e}");
        let e = err(b"v 0 0 1,5\n");
        assert!(e.contains("line 1: cannot parse '1,5' as a vertex coordinate"), "{e}");
    }

    #[test]
    fn non_utf8() {
        // inside a number: error with the byte offset
        let e = err(b"v 0 0 0\nv 1 \xff2 0\n");
        assert!(e.contains("line 2: not UTF-8 at byte 12"), "{e}");
        let e = err(b"v 0 0 0\nf 1 1 \xc3\n");
        assert!(e.contains("line 2: not UTF-8 at byte 14"), "{e}");
        // in names and comments: lenient
        let l = ok(b"# caf\xe9\no caf\xe9\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n\xfe\xff\n");
        assert_eq!(l.mesh.objects[0].name, "caf\u{fffd}");
        assert_eq!(l.warnings.len(), 1);
    }

    #[test]
    fn no_triangles() {
        let e = err(b"v 0 0 0\nv 1 0 0\n# nothing\n");
        assert!(e.contains("no triangles"), "{e}");
        let e = err(b"\n\n\n");
        assert!(e.contains("no triangles"), "{e}");
    }

    #[test]
    fn shared_joined_tetrahedra() {
        let Some(p) = shared("joined_tetrahedra.obj") else {
            return;
        };
        let (l, f) = load_path(&p).unwrap();
        assert_eq!(f, Format::Obj);
        assert_eq!(l.mesh.triangles.len(), 8);
        assert_eq!(l.mesh.tri_object.len(), 8);
        assert_eq!(l.mesh.positions.len(), 5);
        let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["object0", "bottom"]);
        assert_eq!(l.mesh.tri_object, [0, 0, 0, 0, 1, 1, 1, 1]);
        // `f 5//2 2//2 1//2` (the first face after `o bottom`), 0-based
        assert_eq!(l.mesh.triangles[4], [4, 1, 0]);
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    }

    #[test]
    fn shared_fcl() {
        for (name, tris, header) in [("fcl_env.obj", 2180, "6540 2180"), ("fcl_rob.obj", 216, "648 216")] {
            let Some(p) = shared(name) else { return };
            let (l, _) = load_path(&p).unwrap();
            assert_eq!(l.mesh.triangles.len(), tris);
            assert_eq!(l.mesh.positions.len(), 3 * tris);
            assert_eq!(l.warnings, vec![format!("line 1: skipped unrecognised line '{header}'")]);
        }
    }

    #[test]
    fn shared_bunny() {
        let Some(p) = shared("stanford-bunny.obj") else {
            return;
        };
        let (l, _) = load_path(&p).unwrap();
        assert_eq!(l.mesh.triangles.len(), 69451);
        let (lo, hi) =
            l.mesh.positions.iter().fold((DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)), |(lo, hi), p| {
                (lo.min(*p), hi.max(*p))
            });
        let ext = hi - lo;
        assert!(ext.max_element() > 0.14 && ext.max_element() < 0.17, "{ext}");
    }
}
