//! `--bcf FILE.bcfzip`: the clashes as BCF 2.1 topics (or 3.0 with `--bcf-version 3.0`), for
//! BIM tools (Navisworks, Solibri, BIMcollab, Revit, IfcOpenShell's BCF, ...).
//!
//! BCF 3.0 differs in layout only: `bcf.version` is `<Version VersionId="3.0"/>`, an
//! `extensions.xml` at the root lists the values used (topic type `Clash`, status `Open`, label
//! and user `meshclash`), the topic holds its `<Labels><Label>` and `<Viewpoints><ViewPoint>`,
//! and the camera has an `AspectRatio`. No `documents.xml` (no documents) and no
//! `snapshot.png` in either version (rendering one needs a rasteriser meshclash does not have).
//!
//! The archive holds `bcf.version` and one folder per topic named by its GUID, with
//! `markup.bcf` (the topic: `TopicType="Clash"`, title, description) and `viewpoint.bcfv` (a
//! perspective camera framing the clash, both parts selected and coloured A orange / B blue, the
//! witness segment and up to [`MAX_LINES`] contact segments as `Lines`). Topics are the clash
//! rows of the HTML report ([`crate::output::html::clashes`]): one per clash region
//! (`--bcf-topics regions`) or one per part pair (`part-pairs`), worst first.
//!
//! * **GUIDs** are derived from the stable finding ids (a region's id; for a part pair its two
//!   part names), so exporting again after a fix updates the same topics instead of adding new
//!   ones.
//! * **Components**: a part whose name (or last `/` segment of its node path) is a 22-character
//!   IFC GUID is referenced by `IfcGuid` (IfcConvert writes glTF node names that way); any other
//!   part by `AuthoringToolId` = its name and `OriginatingSystem` = its file name (no directory).
//!   At most [`MAX_COMPONENTS`] per viewpoint.
//! * **Coordinates** are metres: the report units converted (`--units`; glTF is metres; model
//!   units of OBJ/STL are taken as metres), and glTF's Y-up turned into BCF's Z-up
//!   (`(x, y, z)` → `(x, -z, y)`, as IfcConvert does).
//! * Dates: the time of the run, or 1970-01-01 with `--no-timings` so archives are
//!   byte-identical.

use crate::check::query::ClashResult;
use crate::output::html::{self, Row};
use crate::report::Report;
use crate::scene::mesh::Mesh;
use glam::DVec3;
use quick_xml::events::{BytesDecl, BytesEnd, BytesStart, BytesText, Event};
use quick_xml::Writer;
use std::io::Write;

/// Components listed per viewpoint at most.
pub const MAX_COMPONENTS: usize = 100;
/// Contact segments written as viewpoint lines at most (besides the witness).
pub const MAX_LINES: usize = 64;
/// Colour of A's part (ARGB hex).
pub const COLOR_A: &str = "FFFF800D";
/// Colour of B's part.
pub const COLOR_B: &str = "FF1F78CC";

/// `--bcf-topics`: what one topic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Topics {
    /// One topic per clash region (a part pair with several separate interferences gets one
    /// topic per interference).
    #[default]
    Regions,
    /// One topic per clashing part pair.
    PartPairs,
}

/// `--bcf-version`: the BCF schema version written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Version {
    /// BCF 2.1 (every BIM tool reads it).
    #[default]
    V21,
    /// BCF 3.0: `extensions.xml` at the root, viewpoints and labels inside the topic, cameras
    /// with an aspect ratio.
    V30,
}

impl Version {
    /// `2.1` or `3.0`.
    pub fn name(self) -> &'static str {
        match self {
            Version::V21 => "2.1",
            Version::V30 => "3.0",
        }
    }
}

/// One topic before writing.
struct Topic {
    guid: String,
    title: String,
    description: String,
    /// (name, file name, colour) of the components.
    components: Vec<(String, String, &'static str)>,
    centre: DVec3,
    radius: f64,
    lines: Vec<[DVec3; 2]>,
}

/// The archive as bytes. `result` and the meshes are those the report was built from.
pub fn export(
    rep: &Report,
    result: &ClashResult,
    a: &Mesh,
    b: &Mesh,
    topics: Topics,
    version: Version,
) -> Vec<u8> {
    let cl = html::clashes(rep, result, a, b);
    let to_m = metres(rep);
    let gltf = |f: &str| f == "gltf" || f == "glb";
    let y_up = gltf(&rep.inputs.a.format) && gltf(&rep.inputs.b.format);
    let world = |p: &[f32]| {
        let v = DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) + cl.centre;
        let v = v * to_m;
        if y_up {
            DVec3::new(v.x, -v.z, v.y)
        } else {
            v
        }
    };
    let file = |slot: usize| {
        let p = if slot == 0 { &rep.inputs.a.path } else { &rep.inputs.b.path };
        std::path::Path::new(p).file_name().map_or_else(|| p.clone(), |f| f.to_string_lossy().into_owned())
    };
    // Group rows into topics.
    let mut groups: Vec<(String, Vec<&Row>, usize)> = Vec::new();
    for (i, row) in cl.rows.iter().enumerate() {
        let key = match topics {
            Topics::Regions => format!("meshclash region {}", row.id),
            Topics::PartPairs => format!("meshclash part pair {}\u{0}{}", row.a_name, row.b_name),
        };
        match groups.iter_mut().find(|g| g.0 == key) {
            Some(g) => g.1.push(row),
            None => groups.push((key, vec![row], i)),
        }
    }
    let units =
        if rep.settings.units == "model" { "model units".to_string() } else { rep.settings.units.clone() };
    let mut out = Vec::new();
    for (n, (key, rows, first)) in groups.iter().enumerate() {
        let r0 = rows[0];
        let (ka, kb) = cl.keys[*first];
        let pairs: u64 = rows.iter().map(|r| r.pairs).sum();
        let crossing: u64 = rows.iter().map(|r| r.crossing).sum();
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        let mut lines = Vec::new();
        for r in rows {
            let (p, q) = (world(&r.bounds[0]), world(&r.bounds[1]));
            lo = lo.min(p.min(q));
            hi = hi.max(p.max(q));
            if r.witness.len() == 6 {
                lines.push([world(&r.witness[0..3]), world(&r.witness[3..6])]);
            }
        }
        for r in rows {
            for s in r.segments.chunks_exact(6).take(MAX_LINES.saturating_sub(lines.len())) {
                lines.push([world(&s[0..3]), world(&s[3..6])]);
            }
        }
        let centre = (lo + hi) * 0.5;
        let size = rep.settings.model_size * to_m;
        let radius = ((hi - lo).length() * 0.75).max(size * 0.01).max(1e-6);
        let measure = match (r0.penetration, r0.distance) {
            (Some(p), _) if r0.penetration_exact => {
                format!(", penetration {} {units} (exact, convex)", crate::output::text::num(p))
            }
            (Some(p), _) => format!(", penetration at least {} {units}", crate::output::text::num(p)),
            (None, Some(d)) if d > 0.0 => format!(", distance {} {units}", crate::output::text::num(d)),
            _ => String::new(),
        };
        let measure = match &r0.overlap {
            Some(e) => format!("{measure}, {} {units}", crate::output::text::overlap_text(e)),
            None => measure,
        };
        let title = format!(
            "#{} {} {} \u{d7} {}{}",
            n + 1,
            r0.kind,
            r0.a_name,
            r0.b_name,
            if pairs > 0 { format!(", {pairs} pairs") } else { String::new() }
        );
        let mut description = format!(
            "meshclash: {} between {} (A, {}) and {} (B, {}): {} triangle pairs, {} crossing{}. Region(s): {}.",
            r0.kind,
            r0.a_name,
            file(ka.0),
            r0.b_name,
            file(kb.0),
            pairs,
            crossing,
            measure,
            rows.iter().map(|r| r.id.as_str()).collect::<Vec<_>>().join(", ")
        );
        if let Some(st) = rows.iter().find_map(|r| r.status.as_deref()) {
            description.push_str(&format!(" Baseline: {st}."));
        }
        let mut components =
            vec![(r0.a_name.clone(), file(ka.0), COLOR_A), (r0.b_name.clone(), file(kb.0), COLOR_B)];
        components.truncate(MAX_COMPONENTS);
        out.push(Topic { guid: guid(key), title, description, components, centre, radius, lines });
    }
    let date = if rep.timings_ms.is_some() { now_iso() } else { "1970-01-01T00:00:00Z".to_string() };
    archive(&out, &date, version)
}

/// Factor from the report units to metres (model units: taken as metres).
fn metres(rep: &Report) -> f64 {
    match rep.settings.units.as_str() {
        "um" => 1e-6,
        "mm" => 1e-3,
        "cm" => 1e-2,
        "in" => 0.0254,
        "ft" => 0.3048,
        "yd" => 0.9144,
        _ => 1.0,
    }
}

/// A deterministic GUID (RFC 4122 layout, version 8 "custom") from `key`: two FNV-1a 64 hashes.
pub fn guid(key: &str) -> String {
    let fnv = |seed: u64| key.bytes().fold(seed, |h, b| (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3));
    let (h1, h2) = (fnv(0xcbf2_9ce4_8422_2325), fnv(0x6c62_272e_07bb_0142 ^ key.len() as u64));
    let mut b = [0u8; 16];
    b[..8].copy_from_slice(&h1.to_be_bytes());
    b[8..].copy_from_slice(&h2.to_be_bytes());
    b[6] = (b[6] & 0x0f) | 0x80;
    b[8] = (b[8] & 0x3f) | 0x80;
    let hex: String = b.iter().map(|x| format!("{x:02x}")).collect();
    format!("{}-{}-{}-{}-{}", &hex[0..8], &hex[8..12], &hex[12..16], &hex[16..20], &hex[20..32])
}

/// The IFC GUID a part name stands for: the name, or the last segment of its node path, when
/// it is 22 characters of IFC's base-64 alphabet (first character 0-3).
pub fn ifc_guid(name: &str) -> Option<&str> {
    let last = name.rsplit('/').next().unwrap_or(name);
    let ok = last.len() == 22
        && last.bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_' || c == b'$')
        && matches!(last.as_bytes()[0], b'0'..=b'3');
    ok.then_some(last)
}

fn now_iso() -> String {
    let secs =
        std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // Civil date from days since 1970-01-01 (proleptic Gregorian).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + (m <= 2) as i64;
    format!("{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z", rem / 3600, rem % 3600 / 60, rem % 60)
}

/// A small layer over quick-xml's writer: elements, attributes and text escaped by it.
struct Xml(Writer<Vec<u8>>);

impl Xml {
    fn new() -> Xml {
        let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
        w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None))).expect("in memory");
        Xml(w)
    }
    fn open(&mut self, name: &str, attrs: &[(&str, &str)]) -> &mut Self {
        let mut e = BytesStart::new(name);
        for &(k, v) in attrs {
            e.push_attribute((k, xml_chars(v).as_ref()));
        }
        self.0.write_event(Event::Start(e)).expect("in memory");
        self
    }
    fn empty(&mut self, name: &str, attrs: &[(&str, &str)]) -> &mut Self {
        let mut e = BytesStart::new(name);
        for &(k, v) in attrs {
            e.push_attribute((k, xml_chars(v).as_ref()));
        }
        self.0.write_event(Event::Empty(e)).expect("in memory");
        self
    }
    fn close(&mut self, name: &str) -> &mut Self {
        self.0.write_event(Event::End(BytesEnd::new(name))).expect("in memory");
        self
    }
    fn leaf(&mut self, name: &str, text: &str) -> &mut Self {
        self.open(name, &[]);
        self.0.write_event(Event::Text(BytesText::new(&xml_chars(text)))).expect("in memory");
        self.close(name)
    }
    fn point(&mut self, name: &str, p: DVec3) -> &mut Self {
        self.open(name, &[]);
        self.leaf("X", &num(p.x)).leaf("Y", &num(p.y)).leaf("Z", &num(p.z));
        self.close(name)
    }
    fn bytes(self) -> Vec<u8> {
        let mut v = self.0.into_inner();
        v.push(b'\n');
        v
    }
}

/// `s` with every character XML 1.0 forbids (controls other than tab, newline and carriage
/// return, U+FFFE, U+FFFF; not even a character reference may name them) written as its Rust
/// escape (`\u{1b}`), so any part name makes a well-formed document; quick-xml then escapes
/// markup characters.
pub fn xml_chars(s: &str) -> std::borrow::Cow<'_, str> {
    let bad = |c: char| (c < ' ' && !matches!(c, '\t' | '\n' | '\r')) || matches!(c, '\u{FFFE}' | '\u{FFFF}');
    if !s.chars().any(bad) {
        return s.into();
    }
    s.chars()
        .map(|c| if bad(c) { c.escape_unicode().to_string() } else { c.to_string() })
        .collect::<String>()
        .into()
}

fn num(x: f64) -> String {
    format!("{x}")
}

fn version_file(v: Version) -> Vec<u8> {
    let mut x = Xml::new();
    match v {
        Version::V21 => {
            x.open("Version", &[("VersionId", "2.1")]).leaf("DetailedVersion", "2.1").close("Version");
        }
        Version::V30 => {
            x.empty("Version", &[("VersionId", "3.0")]);
        }
    }
    x.bytes()
}

/// BCF 3.0 `extensions.xml`: the values the topics use (every list is required, some empty).
fn extensions() -> Vec<u8> {
    let mut x = Xml::new();
    x.open("Extensions", &[]);
    x.open("TopicTypes", &[]).leaf("TopicType", "Clash").close("TopicTypes");
    x.open("TopicStatuses", &[]).leaf("TopicStatus", "Open").close("TopicStatuses");
    x.empty("Priorities", &[]);
    x.open("TopicLabels", &[]).leaf("TopicLabel", "meshclash").close("TopicLabels");
    x.open("Users", &[]).leaf("User", "meshclash").close("Users");
    x.empty("SnippetTypes", &[]).empty("Stages", &[]);
    x.close("Extensions");
    x.bytes()
}

fn markup(t: &Topic, date: &str, v: Version) -> Vec<u8> {
    let vp = guid(&format!("{} viewpoint", t.guid));
    let mut x = Xml::new();
    x.open("Markup", &[]);
    x.open("Topic", &[("Guid", &t.guid), ("TopicType", "Clash"), ("TopicStatus", "Open")]);
    x.leaf("Title", &t.title);
    match v {
        Version::V21 => x.leaf("Labels", "meshclash"),
        Version::V30 => x.open("Labels", &[]).leaf("Label", "meshclash").close("Labels"),
    };
    x.leaf("CreationDate", date).leaf("CreationAuthor", "meshclash").leaf("Description", &t.description);
    if v == Version::V30 {
        // 3.0: the viewpoints are part of the topic.
        x.open("Viewpoints", &[]);
        x.open("ViewPoint", &[("Guid", &vp)]).leaf("Viewpoint", "viewpoint.bcfv").close("ViewPoint");
        x.close("Viewpoints");
    }
    x.close("Topic");
    if v == Version::V21 {
        x.open("Viewpoints", &[("Guid", &vp)]).leaf("Viewpoint", "viewpoint.bcfv").close("Viewpoints");
    }
    x.close("Markup");
    x.bytes()
}

fn component(x: &mut Xml, name: &str, file: &str) {
    match ifc_guid(name) {
        Some(g) => {
            x.open("Component", &[("IfcGuid", g)]).leaf("OriginatingSystem", file).close("Component");
        }
        None => {
            x.open("Component", &[])
                .leaf("OriginatingSystem", file)
                .leaf("AuthoringToolId", name)
                .close("Component");
        }
    }
}

fn viewpoint(t: &Topic, v: Version) -> Vec<u8> {
    let vp = guid(&format!("{} viewpoint", t.guid));
    // From front-left above (Z up), at a distance that fits a sphere of `radius` in 60°.
    let dir = DVec3::new(0.55, 0.65, -0.52).normalize();
    let dist = t.radius / (30f64.to_radians()).sin() * 1.1;
    let eye = t.centre - dir * dist;
    let up = (DVec3::Z - dir * DVec3::Z.dot(dir)).normalize();
    let mut x = Xml::new();
    x.open("VisualizationInfo", &[("Guid", &vp)]);
    x.open("Components", &[]);
    x.open("Selection", &[]);
    for (name, file, _) in &t.components {
        component(&mut x, name, file);
    }
    x.close("Selection");
    x.empty("Visibility", &[("DefaultVisibility", "true")]);
    x.open("Coloring", &[]);
    for (name, file, color) in &t.components {
        x.open("Color", &[("Color", color)]);
        // 3.0 wraps a colour's components in `<Components>`; 2.1 lists them directly.
        if v == Version::V30 {
            x.open("Components", &[]);
        }
        component(&mut x, name, file);
        if v == Version::V30 {
            x.close("Components");
        }
        x.close("Color");
    }
    x.close("Coloring");
    x.close("Components");
    x.open("PerspectiveCamera", &[]);
    x.point("CameraViewPoint", eye).point("CameraDirection", dir).point("CameraUpVector", up);
    x.leaf("FieldOfView", "60");
    if v == Version::V30 {
        x.leaf("AspectRatio", "1.5");
    }
    x.close("PerspectiveCamera");
    if !t.lines.is_empty() {
        x.open("Lines", &[]);
        for [p, q] in &t.lines {
            x.open("Line", &[]).point("StartPoint", *p).point("EndPoint", *q).close("Line");
        }
        x.close("Lines");
    }
    x.close("VisualizationInfo");
    x.bytes()
}

fn archive(topics: &[Topic], date: &str, v: Version) -> Vec<u8> {
    let mut z = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let mut put = |name: &str, bytes: &[u8]| {
        z.start_file(name, opts).expect("in memory");
        z.write_all(bytes).expect("in memory");
    };
    put("bcf.version", &version_file(v));
    if v == Version::V30 {
        put("extensions.xml", &extensions());
    }
    for t in topics {
        put(&format!("{}/markup.bcf", t.guid), &markup(t, date, v));
        put(&format!("{}/viewpoint.bcfv", t.guid), &viewpoint(t, v));
    }
    z.finish().expect("in memory").into_inner()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guids_are_stable_distinct_and_well_formed() {
        let (g1, g2) = (guid("meshclash region 0123456789abcdef"), guid("meshclash region 0123456789abcdee"));
        assert_eq!(g1, guid("meshclash region 0123456789abcdef"));
        assert_ne!(g1, g2);
        assert_eq!(g1.len(), 36);
        assert_eq!(&g1[14..15], "8");
        assert!(matches!(&g1[19..20], "8" | "9" | "a" | "b"));
    }

    #[test]
    fn ifc_guids_are_recognised_only_when_they_are_one() {
        assert_eq!(ifc_guid("2O2Fr$t4X7Zf8NOew3FLOH"), Some("2O2Fr$t4X7Zf8NOew3FLOH"));
        assert_eq!(ifc_guid("node0/3vB2YO$MX4xv5uCqZZG05x"), Some("3vB2YO$MX4xv5uCqZZG05x"));
        assert_eq!(ifc_guid("node0/node13/node72"), None);
        assert_eq!(ifc_guid("9O2Fr$t4X7Zf8NOew3FLOH"), None);
        assert_eq!(ifc_guid("2O2Fr-t4X7Zf8NOew3FLOH"), None);
    }

    #[test]
    fn forbidden_characters_are_escaped_and_every_document_is_well_formed() {
        assert_eq!(xml_chars("plain <&> name\ttab"), "plain <&> name\ttab");
        assert_eq!(xml_chars("a\u{1b}[2Kb\u{0}\u{FFFF}"), "a\\u{1b}[2Kb\\u{0}\\u{ffff}");
        // Every character 0..=0x10FFFF (but surrogates) in an element and an attribute.
        let all: String = (0u32..0x11_0000).filter_map(char::from_u32).collect();
        let mut x = Xml::new();
        x.open("R", &[("Name", &all)]).leaf("T", &all).close("R");
        let doc = String::from_utf8(x.bytes()).unwrap();
        let parsed = roxmltree::Document::parse(&doc).unwrap();
        let t = parsed.descendants().find(|n| n.has_tag_name("T")).unwrap().text().unwrap();
        assert!(
            t.contains("\\u{1}") && t.contains('\u{10FFFF}') && t.contains("<=>") && t.contains("%&'("),
            "not escaped as expected"
        );
    }

    #[test]
    fn dates_are_iso() {
        let d = now_iso();
        assert_eq!(d.len(), 20);
        assert!(d.starts_with("20") && d.ends_with('Z'), "{d}");
    }
}
