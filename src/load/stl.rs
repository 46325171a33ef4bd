//! STL loader, binary and ASCII.
//!
//! - **Binary vs ASCII** is decided by size, never by a leading `solid`: a file is binary iff
//!   it is at least 84 bytes and exactly `84 + 50·n` bytes long, with `n` the little-endian
//!   u32 at offset 80. Otherwise it must look like ASCII STL (`solid` after optional
//!   whitespace, and a `facet` or `endsolid` keyword somewhere); anything else is reported as
//!   a truncated (or oversized) binary STL, without allocating from `n`.
//! - **Binary**: one object, named from the 80-byte header when it is printable text (a leading
//!   `solid` is stripped), else `solid0`. Positions are f32, converted exactly to f64. Each
//!   facet contributes 3 new vertices (no merging); the normal and attribute bytes are ignored.
//! - **ASCII**: any number of `solid NAME … endsolid` blocks; one object per solid, named by
//!   the text after `solid` (or `solid<i>` for the `i`-th solid of the file when empty).
//!   Keywords are case-insensitive; extra whitespace, CRLF and a missing final `endsolid` are
//!   tolerated; `outer loop`/`endloop` are optional. A facet with more than 3 vertices is
//!   fan-triangulated. Numbers are parsed as f64. Errors name the line.
//! - **Triangle order** is file order (facet order; for ASCII, solids in file order).

use std::path::Path;

use glam::DVec3;

use super::{clip, drop_empty_objects, non_finite};
use crate::error::{Error, InputProblem, Location, Misplaced, Part, Quantity, Result};
use crate::scene::mesh::{Loaded, Mesh, Object};

const HEADER: usize = 84;
const FACET: u64 = 50;

/// The size a binary STL with the triangle count in its header must have, if it has a header.
fn binary_expected_len(bytes: &[u8]) -> Option<(u32, u64)> {
    let n = u32::from_le_bytes(bytes.get(80..84)?.try_into().ok()?);
    Some((n, HEADER as u64 + FACET * n as u64))
}

fn is_binary(bytes: &[u8]) -> bool {
    matches!(binary_expected_len(bytes), Some((_, need)) if need == bytes.len() as u64)
}

/// Starts with `solid` after optional whitespace (and BOM) and has `facet` in its first 4 KiB
/// or `endsolid` in its last 1 KiB.
fn looks_ascii(bytes: &[u8]) -> bool {
    let mut b = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(bytes);
    let start = b.iter().position(|c| !c.is_ascii_whitespace()).unwrap_or(b.len());
    b = &b[start..];
    if b.len() < 5 || !b[..5].eq_ignore_ascii_case(b"solid") {
        return false;
    }
    // Bounded scans: a facet near the start, or `endsolid` near the end (an empty solid).
    let head = &b[..b.len().min(4096)];
    let tail = &b[b.len().saturating_sub(1024)..];
    contains_ignore_case(head, b"facet") || contains_ignore_case(tail, b"endsolid")
}

fn contains_ignore_case(hay: &[u8], needle: &[u8]) -> bool {
    hay.windows(needle.len()).any(|w| w.eq_ignore_ascii_case(needle))
}

/// What a file that is not STL looks like, from its first bytes: a known binary magic number,
/// or text that reads as OBJ or glTF JSON.
fn looks_like(bytes: &[u8]) -> Option<&'static str> {
    const MAGIC: [(&[u8], &str); 7] = [
        (b"\x89PNG\r\n\x1a\n", "PNG"),
        (b"glTF", "GLB (binary glTF)"),
        (b"\xff\xd8\xff", "JPEG"),
        (b"PK\x03\x04", "ZIP"),
        (b"\x1f\x8b", "gzip"),
        (b"%PDF", "PDF"),
        (b"ply", "PLY"),
    ];
    if let Some((_, kind)) = MAGIC.iter().find(|(m, _)| bytes.starts_with(m)) {
        return Some(kind);
    }
    let head = &bytes[..bytes.len().min(4096)];
    let text = std::str::from_utf8(head).ok().or_else(|| {
        // a multi-byte character cut at the end of the window
        std::str::from_utf8(&head[..head.len().saturating_sub(3)]).ok()
    })?;
    let t = text.trim_start();
    if t.starts_with('{') {
        return Some("glTF JSON");
    }
    let obj = t.lines().map(str::trim_start).any(|l| {
        ["v ", "vn ", "vt ", "f ", "o ", "g ", "mtllib ", "usemtl "].iter().any(|k| l.starts_with(k))
    });
    obj.then_some("OBJ")
}

/// Errors unless `bytes` is an exactly-sized binary STL or looks like ASCII STL.
pub(crate) fn check_viable(path: &Path, bytes: &[u8]) -> Result<()> {
    if bytes.is_empty() {
        return Err(Error::in_file(path, InputProblem::Empty));
    }
    if is_binary(bytes) || looks_ascii(bytes) {
        return Ok(());
    }
    if let Some(looks_like) = looks_like(bytes) {
        return Err(Error::in_file(path, InputProblem::NotStl { looks_like }));
    }
    let have = bytes.len() as u64;
    Err(Error::in_file(
        path,
        match binary_expected_len(bytes) {
            None => InputProblem::TooShortForStl { have },
            Some((triangles, need)) if need > have => {
                InputProblem::Truncated { part: Part::StlFacets { triangles }, declared: need, have }
            }
            Some((triangles, need)) => InputProblem::SizeMismatch { triangles, need, have },
        },
    ))
}

/// Loads binary or ASCII STL `bytes`; see the module doc.
pub(crate) fn load(path: &Path, bytes: &[u8]) -> Result<Loaded> {
    check_viable(path, bytes)?;
    if is_binary(bytes) {
        load_binary(path, bytes)
    } else {
        load_ascii(path, bytes)
    }
}

fn load_binary(path: &Path, bytes: &[u8]) -> Result<Loaded> {
    let n = binary_expected_len(bytes).map_or(0, |(n, _)| n as usize);
    if n > u32::MAX as usize / 3 {
        let problem = InputProblem::TooLarge {
            quantity: Quantity::StlTriangles,
            count: n as u64,
            limit: (u32::MAX / 3) as u64,
        };
        return Err(Error::in_file(path, problem));
    }
    // Size was checked against the file: `bytes` holds all n facets.
    let mut positions = Vec::with_capacity(3 * n);
    let mut triangles = Vec::with_capacity(n);
    for (t, facet) in bytes[HEADER..].chunks_exact(FACET as usize).enumerate() {
        let f = |i: usize| {
            let o = 12 + 4 * i;
            f32::from_le_bytes([facet[o], facet[o + 1], facet[o + 2], facet[o + 3]]) as f64
        };
        for k in 0..3 {
            let c = [f(3 * k), f(3 * k + 1), f(3 * k + 2)];
            if let Some(value) = non_finite(c) {
                let at = Location::Corner { triangle: t, corner: k };
                return Err(Error::at(path, at, InputProblem::NonFinite { value }));
            }
            positions.push(DVec3::from_array(c));
        }
        let b = 3 * t as u32;
        triangles.push([b, b + 1, b + 2]);
    }
    let name = header_name(&bytes[..80]).unwrap_or_else(|| "solid0".to_string());
    Ok(Loaded {
        mesh: Mesh {
            positions,
            tri_object: vec![0; triangles.len()],
            triangles,
            objects: vec![Object { name, ..Default::default() }],
        },
        warnings: Vec::new(),
    })
}

/// The binary header as a name, if it is printable ASCII (up to the first NUL) and non-empty
/// after stripping a leading `solid`.
fn header_name(header: &[u8]) -> Option<String> {
    let end = header.iter().position(|&b| b == 0).unwrap_or(header.len());
    let text = &header[..end];
    if !text.iter().all(|b| (0x20..0x7f).contains(b)) {
        return None;
    }
    let s = std::str::from_utf8(text).ok()?.trim();
    let s = match s.get(..5) {
        Some(p) if p.eq_ignore_ascii_case("solid") => s[5..].trim(),
        _ => s,
    };
    (!s.is_empty()).then(|| s.to_string())
}

#[derive(PartialEq)]
enum State {
    Outside,
    InSolid,
    InFacet,
}

fn load_ascii(path: &Path, bytes: &[u8]) -> Result<Loaded> {
    let err = |line: usize, problem: InputProblem| Error::at(path, Location::Line(line as u64), problem);
    let misplaced = |line: usize, keyword: &str, how: Misplaced| {
        err(line, InputProblem::Misplaced { keyword: keyword.to_string(), how })
    };
    let mut mesh = Mesh::default();
    let mut warnings = Vec::new();
    let mut state = State::Outside;
    let mut solids = 0usize;
    let mut verts: Vec<DVec3> = Vec::with_capacity(3);
    let mut facet_line = 0;
    let mut line_no = 0;
    let mut offset = 0usize;
    for raw in bytes.split(|&b| b == b'\n') {
        line_no += 1;
        let line_start = offset;
        offset += raw.len() + 1;
        let mut tokens = raw
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty())
            .map(|t| (t.as_ptr() as usize - raw.as_ptr() as usize, t));
        let Some((_, kw)) = tokens.next() else {
            continue;
        };
        let is = |k: &[u8]| kw.eq_ignore_ascii_case(k);
        if is(b"solid") {
            if state == State::InFacet {
                return Err(misplaced(line_no, "solid", Misplaced::InsideFacet));
            }
            if state == State::InSolid {
                warnings.push(format!("line {line_no}: new solid before 'endsolid'"));
            }
            let rest = raw.get(kw.as_ptr() as usize - raw.as_ptr() as usize + 5..).unwrap_or(&[]);
            let name = String::from_utf8_lossy(rest).trim().to_string();
            let name = if name.is_empty() { format!("solid{solids}") } else { name };
            mesh.objects.push(Object { name, ..Default::default() });
            solids += 1;
            state = State::InSolid;
        } else if is(b"facet") {
            match state {
                State::InSolid => {}
                State::Outside => return Err(misplaced(line_no, "facet", Misplaced::OutsideSolid)),
                State::InFacet => return Err(misplaced(line_no, "facet", Misplaced::InsideFacet)),
            }
            verts.clear();
            facet_line = line_no;
            state = State::InFacet;
        } else if is(b"outer") || is(b"endloop") {
            if state != State::InFacet {
                let kw = String::from_utf8_lossy(kw);
                return Err(misplaced(line_no, &kw, Misplaced::OutsideFacet));
            }
        } else if is(b"vertex") {
            if state != State::InFacet {
                return Err(misplaced(line_no, "vertex", Misplaced::OutsideFacet));
            }
            let mut c = [0.0f64; 3];
            for (k, slot) in c.iter_mut().enumerate() {
                let Some((off, tok)) = tokens.next() else {
                    return Err(err(line_no, InputProblem::TooFewCoordinates { found: k }));
                };
                let s = std::str::from_utf8(tok).map_err(|e| {
                    let byte = (line_start + off + e.valid_up_to()) as u64;
                    err(line_no, InputProblem::NotUtf8 { byte: Some(byte) })
                })?;
                *slot = s.parse().map_err(|_| err(line_no, InputProblem::BadNumber(clip(s, 40))))?;
            }
            if let Some(value) = non_finite(c) {
                return Err(err(line_no, InputProblem::NonFinite { value }));
            }
            verts.push(DVec3::from_array(c));
        } else if is(b"endfacet") {
            if state != State::InFacet {
                return Err(misplaced(line_no, "endfacet", Misplaced::OutsideFacet));
            }
            if verts.len() < 3 {
                let problem =
                    InputProblem::ShortFacet { start_line: facet_line as u64, vertices: verts.len() };
                return Err(err(line_no, problem));
            }
            let base = mesh.positions.len();
            if base + verts.len() > u32::MAX as usize {
                let (count, limit) = ((base + verts.len()) as u64, u32::MAX as u64);
                return Err(err(
                    line_no,
                    InputProblem::TooLarge { quantity: Quantity::Vertices, count, limit },
                ));
            }
            let b = base as u32;
            mesh.positions.extend_from_slice(&verts);
            for i in 1..verts.len() as u32 - 1 {
                mesh.triangles.push([b, b + i, b + i + 1]);
                mesh.tri_object.push((mesh.objects.len() - 1) as u32);
            }
            state = State::InSolid;
        } else if is(b"endsolid") {
            match state {
                State::InSolid => state = State::Outside,
                State::Outside => return Err(misplaced(line_no, "endsolid", Misplaced::WithoutSolid)),
                State::InFacet => return Err(misplaced(line_no, "endsolid", Misplaced::InsideFacet)),
            }
        } else {
            let shown = String::from_utf8_lossy(kw);
            return Err(err(line_no, InputProblem::UnknownKeyword(clip(&shown, 40))));
        }
    }
    match state {
        State::InFacet => {
            return Err(Error::in_file(path, InputProblem::UnfinishedFacet { start_line: facet_line as u64 }))
        }
        State::InSolid => warnings.push("last solid has no 'endsolid'".to_string()),
        State::Outside => {}
    }
    drop_empty_objects(&mut mesh);
    Ok(Loaded { mesh, warnings })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::{load_bytes, load_path, shared, Format};
    use std::path::PathBuf;

    fn path() -> PathBuf {
        PathBuf::from("t.stl")
    }

    fn err(bytes: &[u8]) -> String {
        let p = path();
        let e = match crate::load::detect_format(&p, bytes) {
            Err(e) => e,
            Ok(f) => load_bytes(&p, bytes, f).unwrap_err(),
        }
        .to_string();
        assert!(e.starts_with("t.stl: ") && !e.contains('\n'), "{e}");
        e
    }

    fn binary(header: &[u8], tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b[..header.len()].copy_from_slice(header);
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for v in t {
                for c in v {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.1]];

    #[test]
    fn binary_basic_with_solid_header() {
        let b = binary(b"solid  my part ", &[TRI, [[0.0; 3]; 3]]);
        let l = load_bytes(&path(), &b, Format::Stl).unwrap();
        assert_eq!(l.mesh.triangles, vec![[0, 1, 2], [3, 4, 5]]);
        assert_eq!(l.mesh.positions[2], DVec3::new(0.0, 1.0, 0.1f32 as f64));
        assert_eq!(l.mesh.objects[0].name, "my part");
        assert_eq!(l.mesh.tri_object, vec![0, 0]);
        let b = binary(b"\x01\x02bin", &[TRI]);
        let l = load_bytes(&path(), &b, Format::Stl).unwrap();
        assert_eq!(l.mesh.objects[0].name, "solid0");
    }

    #[test]
    fn binary_hostile() {
        let mut b = binary(b"", &[TRI; 2]);
        b.truncate(b.len() - 1);
        let e = err(&b);
        assert!(
            e.contains("truncated binary STL: header declares 2 triangles (needs 184 bytes) but the file has 183 bytes"),
            "{e}"
        );
        let mut b = binary(b"solid x", &[TRI; 13]);
        b[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
        let e = err(&b);
        assert!(
            e.contains(
                "header declares 4294967295 triangles (needs 214748364834 bytes) but the file has 734 bytes"
            ),
            "{e}"
        );
        let mut b = binary(b"", &[TRI]);
        b.push(0);
        let e = err(&b);
        assert!(e.contains("binary STL size mismatch") && e.contains("(1 extra)"), "{e}");
        let e = err(b"abc");
        assert!(e.contains("too short for binary STL"), "{e}");
        let e = err(&binary(b"", &[]));
        assert!(e.contains("no triangles"), "{e}");
        let e = load_bytes(&path(), b"", Format::Stl).unwrap_err().to_string();
        assert!(e.contains("file is empty"), "{e}");
    }

    #[test]
    fn binary_non_finite() {
        let mut t = [TRI, TRI];
        t[1][2][1] = f32::NAN;
        let e = err(&binary(b"", &t));
        assert!(e.contains("triangle 1 vertex 2 has a non-finite coordinate (NaN)"), "{e}");
        t[1][2][1] = f32::NEG_INFINITY;
        let e = err(&binary(b"", &t));
        assert!(e.contains("non-finite coordinate (-inf)"), "{e}");
    }

    const ASCII: &str = "solid one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   \
        vertex 1 0 0\n   vertex 0 1 0\n  endloop\n endfacet\nendsolid one\n";

    #[test]
    fn ascii_multi_solid_case_crlf() {
        let src = format!(
            "{ASCII}\r\n  SOLID\r\nFACET NORMAL 0 0 0\r\nOUTER LOOP\r\nVERTEX 1e0 2 3\r\n\
             VERTEX 4 5 6\r\nvertex 7 8 9.5\r\nvertex 0 0 0\r\nENDLOOP\r\nENDFACET\r\nENDSOLID\r\n"
        );
        let l = load_bytes(&path(), src.as_bytes(), Format::Stl).unwrap();
        let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, ["one", "solid1"]);
        // quad facet fan-triangulated
        assert_eq!(l.mesh.triangles, vec![[0, 1, 2], [3, 4, 5], [3, 5, 6]]);
        assert_eq!(l.mesh.tri_object, vec![0, 1, 1]);
        assert_eq!(l.mesh.positions[5], DVec3::new(7.0, 8.0, 9.5));
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    }

    #[test]
    fn ascii_missing_endsolid_warns() {
        let src = ASCII.replace("endsolid one\n", "");
        let l = load_bytes(&path(), src.as_bytes(), Format::Stl).unwrap();
        assert_eq!(l.mesh.triangles.len(), 1);
        assert_eq!(l.warnings.len(), 1);
    }

    #[test]
    fn ascii_errors_name_line() {
        let e = err(ASCII.replace("vertex 1 0 0", "vertex 1 x 0").as_bytes());
        assert!(e.contains("line 5: cannot parse 'x' as a vertex coordinate"), "{e}");
        let e = err(ASCII.replace("vertex 1 0 0", "vertex 1 NaN 0").as_bytes());
        assert!(e.contains("line 5: vertex has a non-finite coordinate (NaN)"), "{e}");
        let e = err(ASCII.replace("vertex 1 0 0", "vertex 1 0").as_bytes());
        assert!(e.contains("line 5: vertex has 2 coordinates (needs 3)"), "{e}");
        let e = err(ASCII.replace("   vertex 0 1 0\n", "").as_bytes());
        assert!(e.contains("line 7: facet starting at line 2 has 2 vertices"), "{e}");
        let e = err(ASCII.replace("endloop", "wobble").as_bytes());
        assert!(e.contains("line 7: unexpected 'wobble' in ASCII STL"), "{e}");
        let e = err(ASCII.replace(" endfacet\nendsolid one\n", "").as_bytes());
        assert!(e.contains("end of file inside the facet starting at line 2"), "{e}");
        let e = err(ASCII.replace("vertex 1 0 0", "vertex 1 \u{e9} 0").as_bytes());
        assert!(e.contains("line 5: cannot parse"), "{e}");
        let mut bad = ASCII.as_bytes().to_vec();
        let at = ASCII.find("vertex 1 0 0").unwrap() + 7;
        bad[at] = 0xff;
        let e = err(&bad);
        assert!(e.contains(&format!("line 5: not UTF-8 at byte {at}")), "{e}");
        let e = err(b"solid empty\nendsolid empty\n");
        assert!(e.contains("no triangles"), "{e}");
    }

    #[test]
    fn ascii_looking_binary_is_binary() {
        // a binary STL whose header says "solid ... facet": sized exactly, so binary
        let b = binary(b"solid facet endsolid", &[TRI]);
        let l = load_bytes(&path(), &b, Format::Stl).unwrap();
        assert_eq!(l.mesh.triangles.len(), 1);
        assert_eq!(l.mesh.objects[0].name, "facet endsolid");
    }

    fn shared_case(name: &str, tris: usize, objects: &[&str]) -> Option<Loaded> {
        let p = shared(name)?;
        let (l, f) = load_path(&p).unwrap();
        assert_eq!(f, Format::Stl);
        assert_eq!(l.mesh.triangles.len(), tris, "{name}");
        assert_eq!(l.mesh.positions.len(), 3 * tris, "{name}");
        let names: Vec<_> = l.mesh.objects.iter().map(|o| o.name.as_str()).collect();
        assert_eq!(names, objects, "{name}");
        Some(l)
    }

    #[test]
    fn shared_files() {
        shared_case("angle_block.STL", 704, &["angle_block"]);
        shared_case("shared.STL", 24, &["solid0"]);
        shared_case("soup.stl", 100, &["solid0"]);
        shared_case("featuretype.STL", 3476, &["ddlid featuretype"]);
        shared_case("1002_tray_bottom.STL", 4520, &["1002_tray_bottom"]);
        if let Some(l) = shared_case("multibody.stl", 32, &["bodyB", "bodyA"]) {
            assert_eq!(l.mesh.tri_object.iter().filter(|&&o| o == 1).count(), 20);
        }
        if let Some(l) = shared_case("counter.unitsmm.STL", 83750, &["solid0"]) {
            let zmin = l.mesh.positions.iter().map(|p| p.z).fold(f64::MAX, f64::min);
            let zmax = l.mesh.positions.iter().map(|p| p.z).fold(f64::MIN, f64::max);
            assert!((255.0..257.0).contains(&zmin) && (281.0..282.5).contains(&zmax), "{zmin} {zmax}");
        }
    }

    /// A PNG, GLB or OBJ renamed `.stl` got "truncated binary STL: header declares 479199460
    /// triangles"; it now says what the file looks like.
    #[test]
    fn not_an_stl_file_says_what_it_looks_like() {
        let p = std::path::Path::new("x.stl");
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.resize(300, 7);
        let e = check_viable(p, &png).unwrap_err().to_string();
        assert_eq!(e, "x.stl: not an STL file (looks like PNG)");
        let mut glb = b"glTF\x02\0\0\0".to_vec();
        glb.resize(200, 0);
        assert!(check_viable(p, &glb).unwrap_err().to_string().ends_with("(looks like GLB (binary glTF))"));
        let mut obj = b"# exported\nmtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n".to_vec();
        obj.resize(200, b' ');
        assert!(check_viable(p, &obj).unwrap_err().to_string().ends_with("(looks like OBJ)"));
    }
}
