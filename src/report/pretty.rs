//! The report's pretty JSON, written field by field: the same bytes as
//! `serde_json::to_writer_pretty` (two-space indent, `": "` after keys, `[]` and `{}` for empty
//! containers, strings escaped as serde_json escapes them, numbers as serde_json prints them),
//! without going through serde's derive for the long lists. A report of a large scene holds
//! millions of triangle pairs (`part_pairs[].pairs`) and finding ids (`unlisted`): they are
//! formatted here into one buffer written in large pieces. The small blocks go through
//! serde_json and are re-indented to their depth (a pretty value's only raw newlines are its
//! line breaks: a newline inside a string is written `\n`).
//!
//! The writer takes the [`Report`] apart field by field, so a new field does not compile
//! until it is written here, in its place.

use super::{PairReport, PartPairReport, Report, UnlistedFindings};
use serde::Serialize;
use std::io::{self, Write};

/// Bytes gathered before they are handed to the writer.
const CHUNK: usize = 1 << 18;

/// A buffered pretty-JSON writer over `w`.
struct Out<'a> {
    buf: Vec<u8>,
    w: &'a mut dyn Write,
    /// Scratch for the values that go through serde_json.
    scratch: Vec<u8>,
}

impl Out<'_> {
    fn flush_if_full(&mut self) -> io::Result<()> {
        if self.buf.len() >= CHUNK {
            self.w.write_all(&self.buf)?;
            self.buf.clear();
        }
        Ok(())
    }

    fn finish(mut self) -> io::Result<()> {
        self.w.write_all(&self.buf)?;
        self.buf.clear();
        Ok(())
    }

    fn raw(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    fn indent(&mut self, level: usize) {
        for _ in 0..level {
            self.buf.extend_from_slice(b"  ");
        }
    }

    /// The separator before a member or element of a container at `level` (its contents'
    /// depth), then its indentation.
    fn sep(&mut self, first: bool, level: usize) {
        self.raw(if first { b"\n" } else { b",\n" });
        self.indent(level);
    }

    /// `"key": ` of a member at `level`.
    fn key(&mut self, first: bool, level: usize, key: &str) {
        self.sep(first, level);
        self.string(key);
        self.raw(b": ");
    }

    /// The end of a non-empty container whose contents are at `level`.
    fn close(&mut self, level: usize, bracket: &[u8]) {
        self.raw(b"\n");
        self.indent(level - 1);
        self.raw(bracket);
    }

    // Strings and integers are formatted by serde_json itself (the same bytes as its
    // serializer writes); appending to a `Vec` cannot fail.
    fn string(&mut self, s: &str) {
        let _appended = serde_json::to_writer(&mut self.buf, s).is_ok();
    }

    fn u64(&mut self, x: u64) {
        use serde_json::ser::Formatter;
        let _appended = serde_json::ser::CompactFormatter.write_u64(&mut self.buf, x).is_ok();
    }

    fn bool(&mut self, b: bool) {
        self.raw(if b { b"true" } else { b"false" });
    }

    /// A value through serde_json, pretty, re-indented to `level` (the depth of the member or
    /// element it is the value of).
    fn serde<T: Serialize + ?Sized>(&mut self, level: usize, v: &T) -> io::Result<()> {
        self.scratch.clear();
        serde_json::to_writer_pretty(&mut self.scratch, v).map_err(io::Error::from)?;
        let mut rest = &self.scratch[..];
        while let Some(i) = rest.iter().position(|&c| c == b'\n') {
            self.buf.extend_from_slice(&rest[..=i]);
            for _ in 0..level {
                self.buf.extend_from_slice(b"  ");
            }
            rest = &rest[i + 1..];
        }
        self.buf.extend_from_slice(rest);
        Ok(())
    }

    /// A member whose value goes through serde_json.
    fn member<T: Serialize + ?Sized>(
        &mut self,
        first: bool,
        level: usize,
        key: &str,
        v: &T,
    ) -> io::Result<()> {
        self.key(first, level, key);
        self.serde(level, v)
    }
}

/// `rep` as serde_json's pretty JSON (no trailing newline), written to `w`.
pub fn write_pretty(w: &mut dyn Write, rep: &Report) -> io::Result<()> {
    let mut o = Out { buf: Vec::with_capacity(CHUNK + (1 << 12)), w, scratch: Vec::new() };
    let Report {
        complete,
        missing_shards,
        schema,
        tool,
        inputs,
        settings,
        verdict,
        failed,
        summary,
        closest,
        pairs,
        pairs_truncated,
        unlisted,
        bvh,
        cross_check,
        assembly,
        parts,
        part_pairs,
        regions,
        warnings,
        timings_ms,
        baseline,
        self_check,
        cache,
    } = rep;
    const L: usize = 1;
    o.raw(b"{");
    let mut first = true;
    if let Some(c) = complete {
        o.member(first, L, "complete", c)?;
        first = false;
    }
    if !missing_shards.is_empty() {
        o.member(first, L, "missing_shards", missing_shards)?;
        first = false;
    }
    o.key(first, L, "schema");
    o.string(schema);
    o.member(false, L, "tool", tool)?;
    o.member(false, L, "inputs", inputs)?;
    o.member(false, L, "settings", settings)?;
    o.member(false, L, "verdict", verdict)?;
    o.key(false, L, "failed");
    o.bool(*failed);
    o.member(false, L, "summary", summary)?;
    o.member(false, L, "closest", closest)?;
    o.key(false, L, "pairs");
    seq(&mut o, L + 1, pairs, pair_report)?;
    o.key(false, L, "pairs_truncated");
    o.bool(*pairs_truncated);
    if let Some(u) = unlisted {
        o.key(false, L, "unlisted");
        unlisted_findings(&mut o, L + 1, u)?;
    }
    o.member(false, L, "bvh", bvh)?;
    o.member(false, L, "cross_check", cross_check)?;
    o.member(false, L, "assembly", assembly)?;
    o.member(false, L, "parts", parts)?;
    o.key(false, L, "part_pairs");
    seq(&mut o, L + 1, part_pairs, part_pair_report)?;
    o.member(false, L, "regions", regions)?;
    o.member(false, L, "warnings", warnings)?;
    o.member(false, L, "timings_ms", timings_ms)?;
    if let Some(b) = baseline {
        o.member(false, L, "baseline", b)?;
    }
    if let Some(s) = self_check {
        o.member(false, L, "self", s)?;
    }
    if let Some(c) = cache {
        o.member(false, L, "cache", c)?;
    }
    o.close(L, b"}");
    o.finish()
}

/// An array whose elements (at `level`) are written by `item`.
fn seq<T>(
    o: &mut Out<'_>,
    level: usize,
    items: &[T],
    item: impl Fn(&mut Out<'_>, usize, &T) -> io::Result<()>,
) -> io::Result<()> {
    o.raw(b"[");
    for (k, x) in items.iter().enumerate() {
        o.sep(k == 0, level);
        item(o, level, x)?;
        o.flush_if_full()?;
    }
    if items.is_empty() {
        o.raw(b"]");
    } else {
        o.close(level, b"]");
    }
    Ok(())
}

fn unlisted_findings(o: &mut Out<'_>, level: usize, u: &UnlistedFindings) -> io::Result<()> {
    let UnlistedFindings { crossing_ids, other_ids } = u;
    o.raw(b"{");
    o.key(true, level, "crossing_ids");
    seq(o, level + 1, crossing_ids, |o, _, s| {
        o.string(s);
        Ok(())
    })?;
    o.key(false, level, "other_ids");
    seq(o, level + 1, other_ids, |o, _, s| {
        o.string(s);
        Ok(())
    })?;
    o.close(level, b"}");
    Ok(())
}

/// An object member at `level` inside an element whose members are at `level`.
fn pair_report(o: &mut Out<'_>, level: usize, p: &PairReport) -> io::Result<()> {
    let PairReport { a, b, a_object, b_object, kind, contact, distance, segment, id, status } = p;
    let m = level + 1;
    o.raw(b"{");
    o.key(true, m, "a");
    o.u64(u64::from(*a));
    o.key(false, m, "b");
    o.u64(u64::from(*b));
    o.key(false, m, "a_object");
    o.u64(u64::from(*a_object));
    o.key(false, m, "b_object");
    o.u64(u64::from(*b_object));
    o.key(false, m, "kind");
    o.string(kind.name());
    o.key(false, m, "contact");
    match contact {
        Some(c) => o.string(c.name()),
        None => o.raw(b"null"),
    }
    o.member(false, m, "distance", distance)?;
    o.member(false, m, "segment", segment)?;
    if let Some(id) = id {
        o.key(false, m, "id");
        o.string(id);
    }
    if let Some(s) = status {
        o.key(false, m, "status");
        o.string(s);
    }
    o.close(m, b"}");
    Ok(())
}

fn part_pair_report(o: &mut Out<'_>, level: usize, p: &PartPairReport) -> io::Result<()> {
    let PartPairReport {
        a,
        b,
        a_name,
        b_name,
        verdict,
        crossing_pairs,
        touching_pairs,
        clearance_pairs,
        min_distance,
        contained,
        closest,
        pairs,
        pairs_truncated,
        overlap,
    } = p;
    let m = level + 1;
    o.raw(b"{");
    o.key(true, m, "a");
    o.u64(*a as u64);
    o.key(false, m, "b");
    o.u64(*b as u64);
    o.key(false, m, "a_name");
    o.string(a_name);
    o.key(false, m, "b_name");
    o.string(b_name);
    o.key(false, m, "verdict");
    o.string(verdict.name());
    o.key(false, m, "crossing_pairs");
    o.u64(*crossing_pairs);
    o.key(false, m, "touching_pairs");
    o.u64(*touching_pairs);
    o.key(false, m, "clearance_pairs");
    o.u64(*clearance_pairs);
    o.member(false, m, "min_distance", min_distance)?;
    o.key(false, m, "contained");
    match contained {
        Some(c) => o.string(c.name()),
        None => o.raw(b"null"),
    }
    o.member(false, m, "closest", closest)?;
    o.key(false, m, "pairs");
    seq(o, m + 1, pairs, |o, l, &[x, y]| {
        o.raw(b"[");
        o.sep(true, l + 1);
        o.u64(u64::from(x));
        o.sep(false, l + 1);
        o.u64(u64::from(y));
        o.close(l + 1, b"]");
        Ok(())
    })?;
    o.key(false, m, "pairs_truncated");
    o.bool(*pairs_truncated);
    if let Some(ov) = overlap {
        o.member(false, m, "overlap", ov)?;
    }
    o.close(m, b"}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::{ClosestReport, OverlapReport, ReportContact, ReportContainment, ReportPairKind};
    use crate::report::{ReportVerdict, Witness};

    /// A small deterministic generator (64-bit LCG, high bits).
    struct Rng(u64);

    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            self.0 >> 11
        }
        fn below(&mut self, n: u64) -> u64 {
            self.next() % n
        }
        fn coin(&mut self) -> bool {
            self.below(2) == 0
        }
        /// Every kind of f64 a report can hold: integers, fractions, tiny and huge, negative
        /// zero, arbitrary bit patterns (infinities and NaN print as null).
        fn f64(&mut self) -> f64 {
            match self.below(6) {
                0 => self.below(1000) as f64,
                1 => -0.0,
                2 => (self.next() as f64) * 1e-300,
                3 => f64::from_bits(self.next() << 11 | self.below(2048)),
                4 => (self.below(1 << 20) as f64) / 1024.0 - 512.0,
                _ => [f64::INFINITY, f64::NAN, f64::MAX, f64::MIN_POSITIVE][self.below(4) as usize],
            }
        }
        /// Strings with quotes, backslashes, every control character, DEL and non-ASCII.
        fn string(&mut self) -> String {
            let n = self.below(12);
            (0..n)
                .map(|_| match self.below(5) {
                    0 => char::from(self.below(0x20) as u8),
                    1 => ['"', '\\', '/', '\u{7f}', 'é', '\u{2028}', '😀'][self.below(7) as usize],
                    _ => char::from(b'a' + self.below(26) as u8),
                })
                .collect()
        }
        fn point(&mut self) -> [f64; 3] {
            [self.f64(), self.f64(), self.f64()]
        }
    }

    const KINDS: [ReportPairKind; 3] =
        [ReportPairKind::Crossing, ReportPairKind::Touching, ReportPairKind::Clearance];
    const CONTACTS: [ReportContact; 5] = [
        ReportContact::Point,
        ReportContact::Segment,
        ReportContact::CoplanarArea,
        ReportContact::CoplanarBoundary,
        ReportContact::WithinTolerance,
    ];
    const VERDICTS: [ReportVerdict; 4] =
        [ReportVerdict::Clear, ReportVerdict::Clearance, ReportVerdict::Touching, ReportVerdict::Clash];
    const CONTAINMENTS: [ReportContainment; 6] = [
        ReportContainment::AInB,
        ReportContainment::BInA,
        ReportContainment::APartlyInB,
        ReportContainment::BPartlyInA,
        ReportContainment::VolumesOverlap,
        ReportContainment::Undecided,
    ];

    fn pair(r: &mut Rng) -> PairReport {
        PairReport {
            a: r.next() as u32,
            b: r.below(1000) as u32,
            a_object: r.below(u32::MAX as u64 + 1) as u32,
            b_object: r.below(3) as u32,
            kind: KINDS[r.below(3) as usize],
            contact: r.coin().then(|| CONTACTS[r.below(5) as usize]),
            distance: r.f64(),
            segment: r.coin().then(|| [r.point(), r.point()]),
            id: r.coin().then(|| r.string()),
            status: r.coin().then(|| r.string()),
        }
    }

    fn part_pair(r: &mut Rng) -> PartPairReport {
        let n = [0, 1, 2, 40][r.below(4) as usize];
        PartPairReport {
            a: r.next() as usize,
            b: r.below(10) as usize,
            a_name: r.string(),
            b_name: r.string(),
            verdict: VERDICTS[r.below(4) as usize],
            crossing_pairs: r.next(),
            touching_pairs: [0, u64::MAX, r.next()][r.below(3) as usize],
            clearance_pairs: r.below(10),
            min_distance: r.coin().then(|| r.f64()),
            contained: r.coin().then(|| CONTAINMENTS[r.below(6) as usize]),
            closest: r.coin().then(|| ClosestReport {
                distance: r.f64(),
                a: Witness { triangle: r.next() as u32, object: 1, point: r.point() },
                b: Witness { triangle: 0, object: r.below(5) as u32, point: r.point() },
            }),
            pairs: (0..n).map(|_| [r.next() as u32, r.below(100) as u32]).collect(),
            pairs_truncated: r.coin(),
            overlap: r.coin().then(|| OverlapReport { min: r.point(), max: r.point(), extent: r.point() }),
        }
    }

    /// A real report (two small meshes of the repository, in scene mode and as two files).
    fn base_report(scene: bool) -> Report {
        let m = |f: &str| format!("{}/meshes/{f}", env!("CARGO_MANIFEST_DIR"));
        let mut req = if scene {
            crate::pipeline::Request::scene(m("multibody.stl"))
        } else {
            crate::pipeline::Request::files(m("fcl_env.obj"), m("fcl_rob.obj"))
        };
        req.deterministic = true;
        crate::pipeline::report::build(&crate::pipeline::run(&req, &|_| {}).unwrap())
    }

    fn same_as_serde(rep: &Report) {
        let want = serde_json::to_vec_pretty(rep).unwrap();
        let mut got = Vec::new();
        write_pretty(&mut got, rep).unwrap();
        if got != want {
            let at = got.iter().zip(&want).position(|(x, y)| x != y).unwrap_or(got.len().min(want.len()));
            let show = |b: &[u8]| {
                String::from_utf8_lossy(&b[at.saturating_sub(200)..(at + 200).min(b.len())]).into_owned()
            };
            panic!("differs at byte {at}:\n--- ours\n{}\n--- serde_json\n{}", show(&got), show(&want));
        }
    }

    #[test]
    fn pretty_report_is_serde_json_byte_for_byte() {
        let mut r = Rng(7);
        for scene in [false, true] {
            let base = base_report(scene);
            same_as_serde(&base);
            for round in 0..40 {
                let mut rep = base.clone();
                let n = [0, 1, 3, 30][round % 4];
                rep.pairs = (0..n).map(|_| pair(&mut r)).collect();
                rep.part_pairs = (0..[0, 1, 7][round % 3]).map(|_| part_pair(&mut r)).collect();
                rep.pairs_truncated = r.coin();
                rep.failed = r.coin();
                rep.schema = r.string();
                rep.complete = r.coin().then(|| r.coin());
                rep.missing_shards = (0..r.below(3)).map(|_| r.string()).collect();
                rep.warnings = (0..r.below(3)).map(|_| r.string()).collect();
                rep.unlisted = r.coin().then(|| UnlistedFindings {
                    crossing_ids: (0..r.below(4)).map(|_| r.string()).collect(),
                    other_ids: (0..r.below(2) * 5).map(|_| format!("{:016x}", r.next())).collect(),
                });
                rep.cache = r.coin().then(|| crate::cache::CacheSummary {
                    part_pairs_reused: r.next(),
                    part_pairs_checked: 0,
                    dir: r.string(),
                });
                same_as_serde(&rep);
            }
        }
    }

    #[test]
    fn escaped_strings_are_serde_json_strings() {
        let mut r = Rng(11);
        let mut all: String = (0u8..0x80).map(char::from).collect();
        all.push_str("é\u{2028}😀");
        for s in std::iter::once(all).chain((0..500).map(|_| r.string())) {
            let mut sink = Vec::new();
            let mut out = Out { buf: Vec::new(), w: &mut sink, scratch: Vec::new() };
            out.string(&s);
            assert_eq!(out.buf, serde_json::to_vec(&s).unwrap(), "{s:?}");
        }
    }
}
