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

mod decimal;

use std::borrow::Cow;
use std::path::Path;

use glam::DVec3;

use super::{clip, drop_empty_objects};
use crate::error::{Error, InputProblem, Location, NonFinite, ObjFaceProblem as Face, Result};
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
    // The common file (vertices, plain faces, names, comments, ignored statements) is parsed in
    // chunks on every core; anything else (an error, a warning, a continued line) is handed to
    // the sequential parser, which gives the one answer both would give on the files the fast
    // path accepts (tested: `chunked_parse_equals_the_sequential_parser`).
    if let Some(loaded) = chunked::parse(bytes, MAX_TRIANGLES, chunked::CHUNK_BYTES) {
        return Ok(loaded);
    }
    Parser::new(path, MAX_TRIANGLES).run(bytes)
}

/// Parses the OBJ file `file` of `size` bytes on the parallel fast path, reading it a chunk at a
/// time (never whole); `None` when the fast path declines (the caller then reads the file whole
/// and calls [`load`], which reports the problem) or the file cannot be read as it was.
pub(crate) fn load_file(file: &std::fs::File, size: u64) -> Option<Loaded> {
    chunked::parse_file(file, size, MAX_TRIANGLES, chunked::CHUNK_BYTES)
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

    fn err(&self, line: usize, problem: impl Into<InputProblem>) -> Error {
        Error::at(self.path, Location::Line(line as u64), problem)
    }

    fn run(mut self, bytes: &[u8]) -> Result<Loaded> {
        let mut lines = Lines { bytes, pos: 0, line: 0 };
        while let Some((line_no, start, text)) = lines.next_logical() {
            self.statement(line_no, start, &text)?;
        }
        let n = self.mesh.positions.len() as i64;
        if let Some(&(line, idx)) = self.forward_refs.iter().find(|(_, i)| *i > n) {
            return Err(self.err(line, Face::BeyondLastVertex { index: idx, vertices: n }));
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
            b"v" => self.vertex(line, start, &mut tokens),
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

    fn vertex(&mut self, line: usize, start: usize, tokens: &mut Tokens) -> Result<()> {
        let mut c = [0.0f64; 3];
        for (k, slot) in c.iter_mut().enumerate() {
            let Some((off, tok)) = tokens.next() else {
                return Err(self.err(line, InputProblem::TooFewCoordinates { found: k }));
            };
            *slot = match decimal::parse(tok) {
                Some(x) => x,
                None => {
                    let s = self.utf8(line, start + off, tok)?;
                    s.parse::<f64>().map_err(|_| self.err(line, InputProblem::BadNumber(clip(s, 40))))?
                }
            };
        }
        let index = self.mesh.positions.len();
        if let Some(value) = NonFinite::first(c) {
            return Err(self.err(line, InputProblem::ObjNonFiniteVertex { vertex: index + 1, value }));
        }
        if index > u32::MAX as usize {
            let quantity = crate::error::Quantity::Vertices;
            return Err(
                self.err(line, InputProblem::TooLarge { quantity, count: index as u64 + 1, limit: 1 << 32 })
            );
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
                return Err(self.err(line, Face::TooManyVertices { limit: MAX_FACE_VERTICES }));
            }
            let v = tok.split(|&b| b == b'/').next().unwrap_or(tok);
            let idx = match plain_index(v) {
                Some(i) => i,
                None => {
                    let s = self.utf8(line, start + off, v)?;
                    s.parse().map_err(|_| self.err(line, Face::BadIndex(clip(s, 40))))?
                }
            };
            let zero_based = match idx {
                0 => return Err(self.err(line, Face::ZeroIndex)),
                i if i < 0 => {
                    let r = defined + i;
                    if r < 0 {
                        return Err(self.err(line, Face::BeforeFirstVertex { index: i, defined }));
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
                return Err(self.err(line, Face::BeyondAnyFile { index: idx }));
            };
            face.push(z);
        }
        if face.len() < 3 {
            return Err(self.err(line, Face::TooFewVertices { found: face.len() }));
        }
        let total = self.mesh.triangles.len() + face.len() - 2;
        if total > self.max_triangles {
            return Err(self.err(line, Face::TooManyTriangles { total, limit: self.max_triangles }));
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
        std::str::from_utf8(tok).map_err(|e| {
            self.err(line, InputProblem::NotUtf8 { byte: Some((offset + e.valid_up_to()) as u64) })
        })
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

/// The parallel fast path of [`load`]: the file cut into chunks at line ends, each chunk parsed
/// on its own (rayon), the chunks joined in file order. It accepts only files on which the
/// sequential [`Parser`] would succeed with no warning, and gives exactly its result there;
/// on anything else it returns `None` and the sequential parser runs (and reports the problem
/// with its line number).
mod chunked {
    use super::{decimal, plain_index, trim_end, Tokens, IGNORED, MAX_FACE_VERTICES};
    use crate::scene::mesh::{Loaded, Mesh, Object};
    use glam::DVec3;

    /// Nominal chunk size (a chunk ends at the first line end after it). A cost knob only.
    pub(super) const CHUNK_BYTES: usize = 1 << 18;

    /// What one chunk holds; indices are resolved when the chunks are joined.
    #[derive(Default)]
    struct Chunk {
        positions: Vec<DVec3>,
        /// Triangles; an index that was negative (relative) holds a placeholder, see `relative`.
        triangles: Vec<[u32; 3]>,
        /// Per triangle: the `o`/`g` statements of this chunk before it.
        names_before: Vec<u32>,
        /// Names of this chunk's `o`/`g` statements, in order.
        names: Vec<String>,
        /// Relative indices: (slot in the flattened `triangles`, vertices of this chunk
        /// before the face + the negative index); the chunk's vertex offset is added on join.
        relative: Vec<(usize, i64)>,
        /// The largest positive (1-based) index used (forward references are allowed up to the
        /// file's vertex count).
        max_index: u64,
    }

    /// Byte ranges of the chunks: each ends just after a `\n` (or at the end of the file).
    fn cut(bytes: &[u8], size: usize) -> Vec<std::ops::Range<usize>> {
        let mut out = Vec::new();
        let mut start = 0;
        while start < bytes.len() {
            let nominal = (start + size).min(bytes.len());
            let end = match memchr::memchr(b'\n', &bytes[nominal..]) {
                Some(i) => nominal + i + 1,
                None => bytes.len(),
            };
            out.push(start..end);
            start = end;
        }
        out
    }

    /// Parses `bytes` if the fast path can (see the module doc); `None` otherwise.
    pub(super) fn parse(bytes: &[u8], max_triangles: usize, chunk_bytes: usize) -> Option<Loaded> {
        run(&InMemory { bytes, ranges: cut(bytes, chunk_bytes) }, max_triangles)
    }

    /// Parses the regular file `file` of `size` bytes if the fast path can, reading it a chunk
    /// at a time into each worker's own buffer (the whole file is never held in memory, and
    /// the bytes are parsed while they are still in the cache they were read into); `None`
    /// otherwise, or when the file cannot be read as it was when `size` was taken (it failed,
    /// shrank or grew): the caller then reads it whole.
    pub(super) fn parse_file(
        file: &std::fs::File,
        size: u64,
        max_triangles: usize,
        chunk_bytes: usize,
    ) -> Option<Loaded> {
        let loaded = run(&InFile { file, size, chunk: chunk_bytes.max(1) as u64 }, max_triangles)?;
        (file.metadata().ok()?.len() == size).then_some(loaded)
    }

    /// Where the chunks' bytes come from: a slice in memory or a file read chunk by chunk.
    trait Source: Sync {
        /// How many chunks.
        fn count(&self) -> usize;
        /// The bytes of chunk `k` (whole lines), read into `buf` when they are not in memory;
        /// `None` when they cannot be read.
        fn bytes<'s>(&'s self, k: usize, buf: &'s mut Vec<u8>) -> Option<&'s [u8]>;
    }

    /// A file in memory, cut at line ends ([`cut`]).
    struct InMemory<'a> {
        bytes: &'a [u8],
        ranges: Vec<std::ops::Range<usize>>,
    }

    impl Source for InMemory<'_> {
        fn count(&self) -> usize {
            self.ranges.len()
        }
        fn bytes<'s>(&'s self, k: usize, _: &'s mut Vec<u8>) -> Option<&'s [u8]> {
            Some(&self.bytes[self.ranges[k].clone()])
        }
    }

    /// A file on disk in chunks of `chunk` bytes: chunk `k` holds the lines that start in
    /// `[k·chunk, (k+1)·chunk)` (a line starts at 0 or after a `\n`), so the chunks are found
    /// each on its own, reading around their nominal range only, and they cover the file once.
    struct InFile<'f> {
        file: &'f std::fs::File,
        size: u64,
        chunk: u64,
    }

    /// Bytes read past a chunk's nominal end at first, for its last line.
    const MARGIN: u64 = 4096;

    /// The bytes of the file from `base` on read so far into `buf[..filled]`.
    struct Window<'f, 'b> {
        file: &'f std::fs::File,
        size: u64,
        base: u64,
        filled: usize,
        buf: &'b mut Vec<u8>,
    }

    impl Window<'_, '_> {
        /// Reads on up to file position `upto` (at most the file's size); false when the read
        /// fails or comes short.
        fn fill(&mut self, upto: u64) -> bool {
            use std::os::unix::fs::FileExt;
            let upto = upto.min(self.size);
            let have = self.base + self.filled as u64;
            if upto <= have {
                return true;
            }
            let need = (upto - self.base) as usize;
            if self.buf.len() < need {
                // The buffer only grows, and is reused from chunk to chunk: zeroed once.
                self.buf.resize(need, 0);
            }
            if self.file.read_exact_at(&mut self.buf[self.filled..need], have).is_err() {
                return false;
            }
            self.filled = need;
            true
        }

        /// The start of the first line that starts after position `from` and at most at
        /// `limit` (the position after the first `\n` at or after `from`), reading on as far as
        /// needed; `Some(None)` when there is none up to `limit`, `None` when a read fails.
        fn line_start_after(&mut self, from: u64, limit: u64) -> Option<Option<u64>> {
            let mut at = from;
            loop {
                let end = self.base + self.filled as u64;
                let window = &self.buf[(at - self.base) as usize..self.filled];
                if let Some(i) = memchr::memchr(b'\n', window) {
                    let start = at + i as u64 + 1;
                    return Some((start <= limit).then_some(start));
                }
                if end >= limit.min(self.size) {
                    return Some(None);
                }
                at = end;
                let more = (self.filled as u64).max(1 << 16);
                if !self.fill(end.saturating_add(more)) {
                    return None;
                }
            }
        }
    }

    impl Source for InFile<'_> {
        fn count(&self) -> usize {
            self.size.div_ceil(self.chunk) as usize
        }
        fn bytes<'s>(&'s self, k: usize, buf: &'s mut Vec<u8>) -> Option<&'s [u8]> {
            let (size, lo) = (self.size, k as u64 * self.chunk);
            let hi = lo.saturating_add(self.chunk).min(size);
            let base = lo.saturating_sub(1);
            let mut w = Window { file: self.file, size, base, filled: 0, buf };
            if !w.fill(hi.saturating_add(MARGIN)) {
                return None;
            }
            // The chunk's first line: the file's first, or the first starting in [lo, hi)
            // (none: a line that started before spans the chunk, which is then empty).
            let start = if k == 0 {
                0
            } else {
                match w.line_start_after(lo - 1, hi - 1)? {
                    Some(s) => s,
                    None => return Some(&[]),
                }
            };
            // Its end: where the next chunk's first line starts (the first line start at or
            // after `hi`), or the file's end.
            let end = if hi == size { size } else { w.line_start_after(hi - 1, size)?.unwrap_or(size) };
            if !w.fill(end) {
                return None;
            }
            let Window { base, buf, .. } = w;
            let buf: &'s Vec<u8> = buf;
            Some(&buf[(start - base) as usize..(end - base) as usize])
        }
    }

    /// What has been joined so far, in file order.
    struct Joined {
        /// The next chunk to join.
        turn: usize,
        /// A chunk declined (or a worker stopped): the fast path gives up.
        failed: bool,
        mesh: Mesh,
        max_index: u64,
    }

    /// Marks the join failed when a worker unwinds, so that no other waits for its chunk.
    struct FailOnUnwind<'a>(&'a std::sync::Mutex<Joined>, &'a std::sync::Condvar);

    impl Drop for FailOnUnwind<'_> {
        fn drop(&mut self) {
            if std::thread::panicking() {
                self.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner).failed = true;
                self.1.notify_all();
            }
        }
    }

    /// Parses the chunks of `source` on every core: each worker takes the next chunk, parses it
    /// into its own vectors (reused from chunk to chunk) and, when the chunks before it are
    /// joined, appends it to the mesh; so the mesh is built in file order once, without a
    /// vector per chunk nor a second copy.
    fn run(source: &impl Source, max_triangles: usize) -> Option<Loaded> {
        use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
        use std::sync::{Condvar, Mutex, PoisonError};
        let n = source.count();
        let next = AtomicUsize::new(0);
        let stop = AtomicBool::new(false);
        let joined = Mutex::new(Joined {
            turn: 0,
            failed: false,
            mesh: Mesh { objects: vec![Object::default()], ..Default::default() },
            max_index: 0,
        });
        let cv = Condvar::new();
        let work = || {
            let _guard = FailOnUnwind(&joined, &cv);
            let mut buf = Vec::new();
            let mut c = Chunk::default();
            loop {
                let k = next.fetch_add(1, Ordering::Relaxed);
                if k >= n || stop.load(Ordering::Relaxed) {
                    return;
                }
                let parsed = source.bytes(k, &mut buf).is_some_and(|b| chunk_into(b, &mut c).is_some());
                let mut j = joined.lock().unwrap_or_else(PoisonError::into_inner);
                while j.turn != k && !j.failed {
                    j = cv.wait(j).unwrap_or_else(PoisonError::into_inner);
                }
                if j.failed {
                    return;
                }
                if parsed && append(&mut j, &mut c, max_triangles) {
                    j.turn += 1;
                } else {
                    j.failed = true;
                    stop.store(true, Ordering::Relaxed);
                }
                drop(j);
                cv.notify_all();
            }
        };
        let workers = rayon::current_num_threads().min(n).max(1);
        rayon::scope(|s| {
            let work = &work;
            for _ in 1..workers {
                s.spawn(move |_| work());
            }
            work();
        });
        let Joined { turn, failed, mut mesh, max_index } =
            joined.into_inner().unwrap_or_else(PoisonError::into_inner);
        if failed || turn != n || max_index > mesh.positions.len() as u64 {
            return None; // a chunk declined, or a face refers beyond the file's vertices
        }
        super::drop_empty_objects(&mut mesh);
        for (i, o) in mesh.objects.iter_mut().enumerate() {
            if o.name.is_empty() {
                o.name = format!("object{i}");
            }
        }
        Some(Loaded { mesh, warnings: Vec::new() })
    }

    /// Appends the next chunk `c` to `j`, resolving its relative indices and its objects;
    /// false when the file would exceed the triangle or vertex bound.
    fn append(j: &mut Joined, c: &mut Chunk, max_triangles: usize) -> bool {
        let mesh = &mut j.mesh;
        let (v0, t0, o0) = (mesh.positions.len(), mesh.triangles.len(), mesh.objects.len() as u32 - 1);
        if t0 + c.triangles.len() > max_triangles || v0 + c.positions.len() > u32::MAX as usize + 1 {
            return false;
        }
        mesh.positions.extend_from_slice(&c.positions);
        mesh.triangles.extend_from_slice(&c.triangles);
        for &(slot, r) in &c.relative {
            let Ok(v) = u32::try_from(v0 as i64 + r) else { return false };
            mesh.triangles[t0 + slot / 3][slot % 3] = v;
        }
        mesh.tri_object.extend(c.names_before.iter().map(|&k| o0 + k));
        mesh.objects.extend(c.names.drain(..).map(|name| Object { name, ..Default::default() }));
        j.max_index = j.max_index.max(c.max_index);
        true
    }

    /// Parses one chunk into `c` (emptied first; its vectors keep their capacity).
    fn chunk_into(bytes: &[u8], c: &mut Chunk) -> Option<()> {
        // Capacity for the most vertices and plain triangles the chunk can hold (a statement
        // takes at least 8 bytes), so the vectors never move while growing: reserved but
        // untouched pages cost nothing.
        let most = bytes.len() / 8 + 1;
        c.positions.clear();
        c.triangles.clear();
        c.names_before.clear();
        c.names.clear();
        c.relative.clear();
        c.max_index = 0;
        c.positions.reserve(most);
        c.triangles.reserve(most);
        c.names_before.reserve(most);
        let mut face: Vec<i64> = Vec::new();
        let mut start = 0;
        let ends = memchr::memchr_iter(b'\n', bytes).chain(std::iter::once(bytes.len()));
        for end in ends {
            let mut text = &bytes[start.min(end)..end];
            start = end + 1;
            if let [head @ .., b'\r'] = text {
                text = head;
            }
            if trim_end(text).last() == Some(&b'\\') {
                return None; // continued lines: the sequential parser joins them
            }
            // The two statements that make up nearly every file, in their plain spellings, in
            // one pass over their bytes; any other spelling takes the general path below.
            match text {
                [b'v', rest @ ..] => {
                    if let Some(p) = plain_vertex(rest) {
                        c.positions.push(p);
                        continue;
                    }
                }
                [b'f', rest @ ..] => {
                    if let Some(v) = plain_triangle(rest) {
                        let most = v.iter().max().map_or(0, |&i| i as u64 + 1);
                        c.max_index = c.max_index.max(most);
                        c.triangles.push(v);
                        c.names_before.push(c.names.len() as u32);
                        continue;
                    }
                }
                _ => {}
            }
            let mut tokens = Tokens { text, pos: 0 };
            let Some((_, keyword)) = tokens.next() else {
                continue;
            };
            match keyword {
                b"v" => {
                    let mut p = [0.0f64; 3];
                    for slot in &mut p {
                        let (_, tok) = tokens.next()?;
                        *slot = match super::decimal::parse(tok) {
                            Some(x) => x,
                            None => std::str::from_utf8(tok).ok()?.parse::<f64>().ok()?,
                        };
                        if !slot.is_finite() {
                            return None;
                        }
                    }
                    c.positions.push(DVec3::from_array(p));
                }
                b"f" | b"fo" => {
                    face.clear();
                    while let Some((_, tok)) = tokens.next() {
                        if face.len() == MAX_FACE_VERTICES {
                            return None;
                        }
                        let v = tok.split(|&b| b == b'/').next().unwrap_or(tok);
                        face.push(plain_index(v)?);
                    }
                    if face.len() < 3 {
                        return None;
                    }
                    let defined = c.positions.len() as i64;
                    let slot0 = c.triangles.len() * 3;
                    let mut resolved = [0u32; 3];
                    let at = |k: usize, corner: usize, c: &mut Chunk| -> Option<u32> {
                        let i = face[k];
                        if i > 0 {
                            c.max_index = c.max_index.max(i as u64);
                            u32::try_from(i - 1).ok()
                        } else if i < 0 {
                            c.relative.push((corner, defined + i));
                            Some(0)
                        } else {
                            None
                        }
                    };
                    let names = c.names.len() as u32;
                    for i in 1..face.len() - 1 {
                        let base = slot0 + (i - 1) * 3;
                        for (corner, k) in [0, i, i + 1].into_iter().enumerate() {
                            resolved[corner] = at(k, base + corner, c)?;
                        }
                        c.triangles.push(resolved);
                        c.names_before.push(names);
                    }
                }
                b"o" | b"g" => {
                    c.names.push(String::from_utf8_lossy(tokens.rest()).trim().to_string());
                }
                k if IGNORED.contains(&k) => {}
                _ => return None, // `p`/`l` and unrecognised lines warn: the sequential parser
            }
        }
        Some(())
    }

    /// A blank between the fields of a plain statement (the general path splits at any ASCII
    /// whitespace; a line with other whitespace takes it).
    #[inline(always)]
    fn blank(b: Option<&u8>) -> bool {
        matches!(b, Some(b' ' | b'\t'))
    }

    /// Moves `*i` past the blanks there, of which a field separator has at least one (false
    /// when there is none).
    #[inline(always)]
    fn skip_blanks(rest: &[u8], i: &mut usize) -> bool {
        let start = *i;
        while blank(rest.get(*i)) {
            *i += 1;
        }
        *i > start
    }

    /// After a line's leading `v`: blanks, three coordinates the decimal fast path reads, each
    /// after blanks, and nothing but blanks after the third. On such a line the general path
    /// reads the same three tokens with the same reader ([`decimal::parse`] of a token is
    /// [`decimal::prefix`] when the prefix ends at the token's end), so it gives the same
    /// position. `None`: the line takes the general path.
    #[inline]
    fn plain_vertex(rest: &[u8]) -> Option<DVec3> {
        let mut p = [0.0f64; 3];
        let mut i = 0;
        for slot in &mut p {
            if !skip_blanks(rest, &mut i) {
                return None;
            }
            let (x, used) = decimal::prefix(&rest[i..])?;
            if !x.is_finite() {
                return None;
            }
            *slot = x;
            i += used;
        }
        rest[i..].iter().all(|b| blank(Some(b))).then(|| DVec3::from_array(p))
    }

    /// After a line's leading `f`: three vertex references `i`, `i/…` (the rest of the token
    /// is not read, as on the general path), each after blanks, with positive indices of at
    /// most ten digits in `1..=2^32`, and nothing but blanks after; their 0-based indices.
    /// `None`: the line takes the general path (relative indices, polygons, anything else).
    #[inline]
    fn plain_triangle(rest: &[u8]) -> Option<[u32; 3]> {
        let mut v = [0u32; 3];
        let mut i = 0;
        for slot in &mut v {
            if !skip_blanks(rest, &mut i) {
                return None;
            }
            let start = i;
            let mut x: u64 = 0;
            while let Some(&b) = rest.get(i) {
                let d = b.wrapping_sub(b'0');
                if d > 9 {
                    break;
                }
                x = x * 10 + d as u64;
                i += 1;
                if i - start > 10 {
                    return None;
                }
            }
            if i == start || x == 0 || x > 1 << 32 {
                return None;
            }
            if rest.get(i) == Some(&b'/') {
                while rest.get(i).is_some_and(|b| !b.is_ascii_whitespace()) {
                    i += 1;
                }
            }
            *slot = (x - 1) as u32;
        }
        rest[i..].iter().all(|b| blank(Some(b))).then_some(v)
    }

    #[cfg(test)]
    mod tests {
        use super::super::Parser;
        use std::path::Path;

        /// Both parsers on `src`: the fast path either declines or gives the sequential answer,
        /// for every chunk size (1 byte: a chunk per line).
        fn agree(src: &[u8]) -> bool {
            let want = Parser::new(Path::new("t.obj"), 1 << 20).run(src);
            let file = in_file(src);
            let mut took = false;
            for size in [1, 7, 64, 1 << 20] {
                let got = super::parse(src, 1 << 20, size);
                let read = super::parse_file(file.as_file(), src.len() as u64, 1 << 20, size);
                assert_eq!(
                    format!("{:?}", read.as_ref().map(|l| &l.mesh)),
                    format!("{:?}", got.as_ref().map(|l| &l.mesh)),
                    "read from a file in chunks of {size} bytes"
                );
                if let Some(got) = got {
                    let want = want.as_ref().expect("the fast path accepted a file the parser refuses");
                    assert!(want.warnings.is_empty());
                    assert_eq!(format!("{:?}", got.mesh), format!("{:?}", want.mesh), "chunk size {size}");
                    took = true;
                }
            }
            took
        }

        /// `src` in a temporary file.
        fn in_file(src: &[u8]) -> tempfile::NamedTempFile {
            use std::io::Write;
            let mut f = tempfile::NamedTempFile::new().unwrap();
            f.write_all(src).unwrap();
            f
        }

        /// Lines longer than a chunk and than what is read past a chunk's end at first, a file
        /// without a final line end, blank and `\r\n` lines: read from the file in chunks of
        /// every size, the mesh is the one parsed in memory.
        #[test]
        fn file_read_in_chunks_equals_the_file_in_memory() {
            let long = |n: usize| [b"# ".as_slice(), &vec![b'x'; n], b"\n"].concat();
            let mut src = b"v 0 0 0\nv 1 0 0\r\n\n".to_vec();
            src.extend(long(10_000));
            src.extend(b"v 0 1 0\no ");
            src.extend(vec![b'n'; 9000]);
            src.extend(b"\nf 1 2 3\n");
            src.extend(long(3));
            src.extend(long(70_000));
            src.extend(b"f 3 2 1");
            let want = Parser::new(Path::new("t.obj"), 1 << 20).run(&src).unwrap();
            let file = in_file(&src);
            for size in [1, 2, 3, 7, 64, 4095, 4096, 4097, 10_000, 1 << 16, 1 << 20] {
                let got = super::parse_file(file.as_file(), src.len() as u64, 1 << 20, size)
                    .unwrap_or_else(|| panic!("declined with chunks of {size} bytes"));
                assert_eq!(format!("{:?}", got.mesh), format!("{:?}", want.mesh), "chunks of {size} bytes");
            }
            assert_eq!(want.mesh.triangles.len(), 2);
            assert_eq!(want.mesh.objects[0].name.len(), 9000);
            // A file that is not the size it was taken to be (it changed): declined.
            let n = src.len() as u64;
            assert!(super::parse_file(file.as_file(), n - 1, 1 << 20, 64).is_none());
            assert!(super::parse_file(file.as_file(), n + 1, 1 << 20, 64).is_none());
        }

        /// One line of a megabyte in chunks of 64 bytes: only the chunk where it starts reads
        /// it (the others find no line of their own), so reading stays linear.
        #[test]
        fn a_line_spanning_many_chunks_is_read_once() {
            let mut src = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n#".to_vec();
            src.extend(vec![b'c'; 1 << 20]);
            src.extend(b"\nf 1 2 3\n");
            let file = in_file(&src);
            let source = super::InFile { file: file.as_file(), size: src.len() as u64, chunk: 64 };
            let mut buf = Vec::new();
            let mut lines = Vec::new();
            for k in 0..super::Source::count(&source) {
                let bytes = super::Source::bytes(&source, k, &mut buf).unwrap().to_vec();
                assert!(buf.len() < 70_000 || bytes.len() > 1 << 20, "chunk {k} read {} bytes", buf.len());
                if !bytes.is_empty() {
                    lines.push(bytes);
                }
                buf = Vec::new();
            }
            assert_eq!(lines.concat(), src);
        }

        #[test]
        fn chunked_parse_equals_the_sequential_parser() {
            let taken: &[&[u8]] = &[
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n",
                b"# c\r\nv 0 0 0 1\r\nv 1 0 0\r\nv 0 1 0\r\nvn 0 0 1\r\no a # x\r\nf -3/1/1 -2//1 -1\r\ng\r\nf 1 2 3 1\r\n",
                b"f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n",
                b"o first\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 4 3\no empty\no last\nf -1 -2 -3\ns off\nusemtl m\n",
                b"v 1e3 -2.5E-3 +4\nv .5 5. 0\nv 0 0 1\nf 1 2 3",
            ];
            for src in taken {
                assert!(agree(src), "{}", String::from_utf8_lossy(src));
            }
            let declined: &[&[u8]] = &[
                b"v 0 0 0\nv 1 0 0\nf 1 2\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 1 2\n",
                b"v 0 0 nan\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 \\\n 3\n",
                b"6540 2180\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2\nf 1 2 3\n",
                b"v 0 0\nf 1 2 3\n",
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf +1 2 3\n",
            ];
            for src in declined {
                assert!(!agree(src), "{}", String::from_utf8_lossy(src));
            }
        }

        /// Lines in and near the plain spellings the one-pass readers take (blanks, signs,
        /// exponents, `/` references, large and zero indices, trailing values, comments, other
        /// whitespace): the chunked parse equals the sequential parser or declines, line by line
        /// and in files mixing them.
        #[test]
        fn plain_statement_readers_equal_the_general_path() {
            let mut seed = 0x9e37_79b9_7f4a_7c15u64;
            let mut next = move |n: u64| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                seed % n
            };
            let seps: [&[u8]; 6] = [b" ", b"  ", b"\t", b" \t", b"\x0c", b""];
            let numbers: [&[u8]; 16] = [
                b"0",
                b"-0",
                b"1",
                b"-2.5",
                b"+4",
                b".5",
                b"5.",
                b"1e3",
                b"-2.5E-3",
                b"0.8506507873535156",
                b"12345678901234567890",
                b"1e400",
                b"nan",
                b"inf",
                b"1.5x",
                b"1e",
            ];
            let indices: [&[u8]; 14] = [
                b"1",
                b"2",
                b"3",
                b"4",
                b"01",
                b"3/1",
                b"2//7",
                b"1/2/3",
                b"-1",
                b"0",
                b"+1",
                b"4294967296",
                b"4294967297",
                b"12345678901",
            ];
            let tails: [&[u8]; 6] = [b"", b" ", b" 1", b" # c", b"#c", b"\t"];
            let mut lines = 0;
            for case in 0..3000 {
                let mut src = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n".to_vec();
                for _ in 0..1 + next(6) {
                    let sep = |k: u64| if k < 5 { seps[0] } else { seps[(k % 6) as usize] };
                    if next(2) == 0 {
                        src.push(b'v');
                        for _ in 0..3 {
                            src.extend_from_slice(sep(next(8)));
                            src.extend_from_slice(numbers[(next(20) % 16) as usize]);
                        }
                    } else {
                        src.push(b'f');
                        for _ in 0..3 + (next(8) == 0) as u64 {
                            src.extend_from_slice(sep(next(8)));
                            src.extend_from_slice(indices[(next(18) % 14) as usize]);
                        }
                    }
                    src.extend_from_slice(tails[(next(12) % 6) as usize]);
                    src.extend_from_slice(if next(4) == 0 { b"\r\n" } else { b"\n" });
                    lines += 1;
                }
                if case % 2 == 0 {
                    src.extend_from_slice(b"f 1 2 3\n");
                }
                agree(&src);
            }
            assert!(lines > 5000);
            // Plain files are taken, and read as the general path reads them.
            assert!(agree(
                b"v 0.5 -1e-3 +2\nv\t1 0 0\t\nv  0 1 0 \nf 1 2 3\nf 3/3 2//2 1/1/1\nf\t1  2\t3 \n"
            ));
        }

        #[test]
        fn chunked_parse_of_the_shared_meshes_equals_the_sequential_parser() {
            for name in ["joined_tetrahedra.obj", "stanford-bunny.obj", "fcl_env.obj"] {
                let Some(path) = crate::load::shared(name) else { continue };
                let bytes = std::fs::read(&path).unwrap();
                let want = Parser::new(&path, 1 << 28).run(&bytes).unwrap();
                let got = super::parse(&bytes, 1 << 28, 4096);
                if want.warnings.is_empty() {
                    let got = got.unwrap_or_else(|| panic!("{name}: declined a file with no warnings"));
                    assert_eq!(format!("{:?}", got.mesh), format!("{:?}", want.mesh), "{name}");
                } else {
                    assert!(got.is_none(), "{name}: took a file the parser warns about");
                }
            }
        }
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
        // one `f` line with tens of millions of indices reached 3.5 GB.
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
    fn errors_carry_their_line_and_problem_as_data() {
        use crate::error::{InputProblem as P, Location, NonFinite, ObjFaceProblem as F};
        let typed = |src: &[u8]| load_bytes(&path(), src, Format::Obj).unwrap_err();
        let cases: [(&[u8], u64, P); 5] = [
            (b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, P::ObjFace(F::ZeroIndex)),
            (
                b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                4,
                P::ObjFace(F::BeyondLastVertex { index: 4, vertices: 3 }),
            ),
            (b"v 0 0 0\nv 1 0 0\nf 1 2 -3\n", 3, P::ObjFace(F::BeforeFirstVertex { index: -3, defined: 2 })),
            (b"v 0 0\n", 1, P::TooFewCoordinates { found: 2 }),
            (b"v 0 0 0\nv 0 inf 0\n", 2, P::ObjNonFiniteVertex { vertex: 2, value: NonFinite::Inf }),
        ];
        for (src, line, problem) in cases {
            let e = typed(src);
            assert_eq!(e.path(), Some(path().as_path()));
            assert_eq!(e.location(), Some(&Location::Line(line)), "{e}");
            assert_eq!(format!("{:?}", e.input_problem()), format!("{:?}", Some(&problem)), "{e}");
        }
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
