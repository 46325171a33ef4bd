//! The binary payloads of the per-pair cache: a *pack* (stored part-pair results and tree
//! sizes) and an *index* (the packs of a lineage). They travel inside an [`entry`](super::entry),
//! whose header proves them whole (length and SHA-256 of the payload, the key, the layout and
//! the tool version); these layouts are what the payload itself holds. Every integer is
//! little-endian, every f64 travels as its IEEE bits (u64), so every number comes back bit for
//! bit and nothing is parsed as text.
//!
//! Pack payload:
//!
//! | bytes | content |
//! |---|---|
//! | 8 | tag `MCLPACK` and the payload layout ([`PACK_LAYOUT`], one byte) |
//! | 8 | the number of pairs `n` (u64) |
//! | n × … | each pair: its 32-byte [`PairKey`](super::PairKey), then its result (below) |
//! | 8 | the number of tree sizes `m` (u64) |
//! | m × 40 | each: a 32-byte [`PartKey`](super::PartKey) and the tree's bytes (u64) |
//!
//! A result (its triangles numbered in their parts):
//!
//! | bytes | content |
//! |---|---|
//! | 1 | verdict: 0 clear, 1 clearance, 2 touching, 3 clash |
//! | 32 | counts: crossing, touching, within tolerance, clearance (u64 each) |
//! | 1 | containment: 0 none, 1 a in b, 2 b in a, 3 a partly in b, 4 b partly in a, 5 volumes overlap, 6 undecided |
//! | 4 + k | only when undecided: the reason's length `k` (u32) and its UTF-8 |
//! | 1 | 1 when a closest pair follows, else 0 |
//! | 8 + 2 × 28 | the closest pair: distance bits, then for A and B the triangle (u32) and the witness point (3 × f64 bits) |
//! | 1 | 1 when a bound follows, else 0 (see [`Stored::beyond`]) |
//! | 48 | the bound: the 32-byte numbering digest, the triangles in A and B (u32 each), the distance bits |
//! | 1 | the overlap box (see [`Stored::overlap`]): 0 not known, 1 known to be none, 2 a box follows |
//! | 48 | the box: its lower, then its upper corner (3 × f64 bits each; finite, lower ≤ upper) |
//! | 8 | the number of triangle pairs `t` (u64) |
//! | t × … | each: triangle in A and in B (u32 each), kind (1 byte: 0 crossing, 1 touching, 2 clearance), contact (1 byte: 0 none, 1 point, 2 segment, 3 coplanar area, 4 coplanar boundary), distance bits (u64), 1 when a segment follows (1 byte), the segment (6 × f64 bits) |
//! | 1 | 1 when the finding ids follow (see [`Stored::ids`]), else 0 |
//! | t × 8 | the finding id of each triangle pair, in their order (u64) |
//!
//! Index payload: tag `MCLINDX` and the layout byte, the number of packs (u64), each pack's
//! 32-byte key.
//!
//! Decoding checks every bound before it reads or allocates (a count larger than the bytes
//! left could hold is refused before any reservation), every tag and enum byte, and that the
//! payload ends exactly where the last record does: a payload that passed the entry's checksum
//! but does not decode (a foreign or damaged writer) is an error naming the first bad field.

use crate::check::containment::Containment;
use crate::check::overlap::Overlap;
use crate::check::query::{ClashResult, Closest, Counts, PairFinding, PairKind, Timings, Verdict};
use crate::geom::DVec3;
use crate::narrow::tri_tri::Contact;

use super::key::Digest;

/// The payload layout byte of packs and indexes; bump it (with [`super::FORMAT`]) when a
/// layout below changes.
pub const PACK_LAYOUT: u8 = 3;

const PACK_TAG: &[u8; 7] = b"MCLPACK";
const INDEX_TAG: &[u8; 7] = b"MCLINDX";

/// The fewest bytes one stored result takes (no reason, no closest pair, no triangle pairs).
const MIN_RESULT: usize = 1 + 32 + 1 + 1 + 1 + 1 + 8 + 1;
/// The fewest bytes one triangle pair takes.
const MIN_FINDING: usize = 4 + 4 + 1 + 1 + 8 + 1;

/// One part pair's stored answer.
#[derive(Debug, Clone, PartialEq)]
pub struct Stored {
    /// The result, triangles numbered in their parts (no tree stats, zero timings, closedness
    /// unknown).
    pub result: ClashResult,
    /// For a clear pair: a proven bound on its closest pair. Either `result.closest` is the
    /// pair's closest pair, or every triangle pair of the two parts comes after this candidate
    /// in the order the scene's closest pair is chosen by (distance, then triangle in A, then
    /// in B, in the input meshes' numbering). `None`: nothing is known.
    pub beyond: Option<Beyond>,
    /// The exact box of the two parts' common volume, as the report carries it for a clashing
    /// pair ([`crate::check::overlap::overlap_box`] over the two parts): `Some(None)` known to
    /// be none (a part is open, or nothing is common), `Some(Some(box))` that box, `None` not
    /// known (a pair that is not a clash, or whose box was not computed).
    pub overlap: Option<Option<Overlap>>,
    /// The finding id ([`crate::check::finding_id::finding_hash`]) of each of `result.pairs`,
    /// in their order: a function of the two parts' names and exact world triangles, so of the
    /// pair's key. `None`: not stored (computed when reused).
    pub ids: Option<Vec<u64>>,
}

/// The least closest-pair candidate a check found over the part pairs it searched together
/// (see [`Stored::beyond`]): a triangle pair of some part pair, in the input meshes'
/// numbering, with the digest of that numbering.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beyond {
    /// The digest of the parts' triangle numbering the candidate's triangles are in (see
    /// [`super::pairs`]): the order against it holds only in that numbering.
    pub numbering: Digest,
    /// The triangle in input A.
    pub a: u32,
    /// The triangle in input B.
    pub b: u32,
    /// Its distance.
    pub distance: f64,
}

/// A decoded pack: results by pair key, tree sizes by part key, in stored order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pack {
    /// (pair key, stored answer).
    pub pairs: Vec<(Digest, Stored)>,
    /// (part key, tree bytes).
    pub trees: Vec<(Digest, u64)>,
}

fn verdict_byte(v: Verdict) -> u8 {
    match v {
        Verdict::Clear => 0,
        Verdict::Clearance => 1,
        Verdict::Touching => 2,
        Verdict::Clash => 3,
    }
}

fn kind_byte(k: PairKind) -> u8 {
    match k {
        PairKind::Crossing => 0,
        PairKind::Touching => 1,
        PairKind::Clearance => 2,
    }
}

fn contact_byte(c: Option<Contact>) -> u8 {
    match c {
        None => 0,
        Some(Contact::Point) => 1,
        Some(Contact::Segment) => 2,
        Some(Contact::CoplanarArea) => 3,
        Some(Contact::CoplanarBoundary) => 4,
    }
}

struct Writer(Vec<u8>);

impl Writer {
    fn u8(&mut self, x: u8) {
        self.0.push(x);
    }
    fn u32(&mut self, x: u32) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn u64(&mut self, x: u64) {
        self.0.extend_from_slice(&x.to_le_bytes());
    }
    fn f64(&mut self, x: f64) {
        self.u64(x.to_bits());
    }
    fn point(&mut self, p: DVec3) {
        for c in p.to_array() {
            self.f64(c);
        }
    }
    fn bytes(&mut self, b: &[u8]) {
        self.0.extend_from_slice(b);
    }

    fn result(&mut self, s: &Stored) {
        let r = &s.result;
        self.u8(verdict_byte(r.verdict));
        let Counts { crossing, touching, within_tolerance, clearance } = r.counts;
        for c in [crossing, touching, within_tolerance, clearance] {
            self.u64(c);
        }
        let c = match &r.containment {
            Containment::None => 0,
            Containment::AInB => 1,
            Containment::BInA => 2,
            Containment::APartlyInB => 3,
            Containment::BPartlyInA => 4,
            Containment::VolumesOverlap => 5,
            Containment::Undecided(_) => 6,
        };
        self.u8(c);
        if let Containment::Undecided(why) = &r.containment {
            self.u32(why.len() as u32);
            self.bytes(why.as_bytes());
        }
        match &r.closest {
            None => self.u8(0),
            Some(c) => {
                self.u8(1);
                self.f64(c.distance);
                self.u32(c.a.0);
                self.point(c.a.1);
                self.u32(c.b.0);
                self.point(c.b.1);
            }
        }
        match &s.beyond {
            None => self.u8(0),
            Some(x) => {
                self.u8(1);
                self.bytes(&x.numbering);
                self.u32(x.a);
                self.u32(x.b);
                self.f64(x.distance);
            }
        }
        match &s.overlap {
            None => self.u8(0),
            Some(None) => self.u8(1),
            Some(Some(o)) => {
                self.u8(2);
                self.point(o.min);
                self.point(o.max);
            }
        }
        self.u64(r.pairs.len() as u64);
        for p in &r.pairs {
            self.u32(p.a);
            self.u32(p.b);
            self.u8(kind_byte(p.kind));
            self.u8(contact_byte(p.contact));
            self.f64(p.distance);
            match p.segment {
                None => self.u8(0),
                Some([x, y]) => {
                    self.u8(1);
                    self.point(x);
                    self.point(y);
                }
            }
        }
        // Ids that do not match the pairs one for one are not written (never produced).
        match s.ids.as_ref().filter(|i| i.len() == r.pairs.len()) {
            None => self.u8(0),
            Some(ids) => {
                self.u8(1);
                for &id in ids {
                    self.u64(id);
                }
            }
        }
    }
}

/// How many bytes [`encode_pack`] writes for these results (no reason is longer than u32).
fn pack_len(pairs: &[(Digest, Stored)], trees: usize) -> usize {
    let results: usize = pairs
        .iter()
        .map(|(_, s)| {
            let r = &s.result;
            let why = match &r.containment {
                Containment::Undecided(w) => 4 + w.len(),
                _ => 0,
            };
            let segs = r.pairs.iter().filter(|p| p.segment.is_some()).count();
            32 + MIN_RESULT
                + why
                + if r.closest.is_some() { 8 + 56 } else { 0 }
                + if s.beyond.is_some() { 48 } else { 0 }
                + if matches!(s.overlap, Some(Some(_))) { 48 } else { 0 }
                + r.pairs.len() * MIN_FINDING
                + segs * 48
                + s.ids.as_ref().filter(|i| i.len() == r.pairs.len()).map_or(0, |i| 8 * i.len())
        })
        .sum();
    8 + 8 + results + 8 + trees * 40
}

/// The payload of a pack of `pairs` and `trees`. A reason longer than 4 GiB is cut (never
/// produced by the check).
pub fn encode_pack(pairs: &[(Digest, Stored)], trees: &[(Digest, u64)]) -> Vec<u8> {
    let mut w = Writer(Vec::with_capacity(pack_len(pairs, trees.len())));
    w.bytes(PACK_TAG);
    w.u8(PACK_LAYOUT);
    w.u64(pairs.len() as u64);
    for (k, s) in pairs {
        w.bytes(k);
        w.result(s);
    }
    w.u64(trees.len() as u64);
    for (k, b) in trees {
        w.bytes(k);
        w.u64(*b);
    }
    w.0
}

/// The payload of an index listing `packs`.
pub fn encode_index(packs: &[Digest]) -> Vec<u8> {
    let mut w = Writer(Vec::with_capacity(16 + 32 * packs.len()));
    w.bytes(INDEX_TAG);
    w.u8(PACK_LAYOUT);
    w.u64(packs.len() as u64);
    for k in packs {
        w.bytes(k);
    }
    w.0
}

/// A bounds-checked cursor over a payload.
struct Reader<'a> {
    bytes: &'a [u8],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(format!("truncated at byte {} ({what})", self.at));
        };
        let s = &self.bytes[self.at..end];
        self.at = end;
        Ok(s)
    }
    fn u8(&mut self, what: &str) -> Result<u8, String> {
        Ok(self.take(1, what)?[0])
    }
    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.take(4, what)?.try_into().expect("4 bytes")))
    }
    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.take(8, what)?.try_into().expect("8 bytes")))
    }
    fn f64(&mut self, what: &str) -> Result<f64, String> {
        self.u64(what).map(f64::from_bits)
    }
    fn point(&mut self, what: &str) -> Result<DVec3, String> {
        Ok(DVec3::new(self.f64(what)?, self.f64(what)?, self.f64(what)?))
    }
    fn digest(&mut self, what: &str) -> Result<Digest, String> {
        Ok(self.take(32, what)?.try_into().expect("32 bytes"))
    }
    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }
    /// A count of records of at least `min` bytes each, refused when the bytes left cannot
    /// hold that many.
    fn count(&mut self, min: usize, what: &str) -> Result<usize, String> {
        let at = self.at;
        let n = self.u64(what)?;
        match usize::try_from(n) {
            Ok(n) if n.checked_mul(min).is_some_and(|b| b <= self.left()) => Ok(n),
            _ => Err(format!("{what} {n} at byte {at}: more than the {} bytes left hold", self.left())),
        }
    }
    fn tag(&mut self, tag: &[u8; 7]) -> Result<(), String> {
        let t = self.take(8, "tag")?;
        if &t[..7] != tag {
            return Err(format!("not a {} payload", String::from_utf8_lossy(tag)));
        }
        if t[7] != PACK_LAYOUT {
            return Err(format!("payload layout {}, this build reads {PACK_LAYOUT}", t[7]));
        }
        Ok(())
    }
    fn end(&self) -> Result<(), String> {
        if self.left() == 0 {
            Ok(())
        } else {
            Err(format!("{} bytes after the last record", self.left()))
        }
    }

    fn result(&mut self) -> Result<Stored, String> {
        let verdict = match self.u8("verdict")? {
            0 => Verdict::Clear,
            1 => Verdict::Clearance,
            2 => Verdict::Touching,
            3 => Verdict::Clash,
            v => return Err(format!("bad verdict {v}")),
        };
        let counts = Counts {
            crossing: self.u64("counts")?,
            touching: self.u64("counts")?,
            within_tolerance: self.u64("counts")?,
            clearance: self.u64("counts")?,
        };
        let containment = match self.u8("containment")? {
            0 => Containment::None,
            1 => Containment::AInB,
            2 => Containment::BInA,
            3 => Containment::APartlyInB,
            4 => Containment::BPartlyInA,
            5 => Containment::VolumesOverlap,
            6 => {
                let n = self.u32("reason length")? as usize;
                let b = self.take(n, "reason")?;
                let why = std::str::from_utf8(b).map_err(|_| "reason is not UTF-8".to_string())?;
                Containment::Undecided(why.to_string())
            }
            c => return Err(format!("bad containment {c}")),
        };
        let closest = match self.u8("closest flag")? {
            0 => None,
            1 => Some(Closest {
                distance: self.f64("closest")?,
                a: (self.u32("closest")?, self.point("closest")?),
                b: (self.u32("closest")?, self.point("closest")?),
            }),
            f => return Err(format!("bad closest flag {f}")),
        };
        let beyond = match self.u8("bound flag")? {
            0 => None,
            1 => Some(Beyond {
                numbering: self.digest("bound")?,
                a: self.u32("bound")?,
                b: self.u32("bound")?,
                distance: self.f64("bound")?,
            }),
            f => return Err(format!("bad bound flag {f}")),
        };
        let overlap = match self.u8("overlap flag")? {
            0 => None,
            1 => Some(None),
            2 => {
                let (min, max) = (self.point("overlap")?, self.point("overlap")?);
                if !(min.is_finite() && max.is_finite() && min.cmple(max).all()) {
                    return Err(format!("overlap box {min} to {max} is not a box"));
                }
                Some(Some(Overlap { min, max }))
            }
            f => return Err(format!("bad overlap flag {f}")),
        };
        let n = self.count(MIN_FINDING, "triangle pairs")?;
        let mut pairs = Vec::with_capacity(n);
        for _ in 0..n {
            let a = self.u32("pair")?;
            let b = self.u32("pair")?;
            let kind = match self.u8("kind")? {
                0 => PairKind::Crossing,
                1 => PairKind::Touching,
                2 => PairKind::Clearance,
                k => return Err(format!("bad kind {k}")),
            };
            let contact = match self.u8("contact")? {
                0 => None,
                1 => Some(Contact::Point),
                2 => Some(Contact::Segment),
                3 => Some(Contact::CoplanarArea),
                4 => Some(Contact::CoplanarBoundary),
                c => return Err(format!("bad contact {c}")),
            };
            let distance = self.f64("distance")?;
            let segment = match self.u8("segment flag")? {
                0 => None,
                1 => Some([self.point("segment")?, self.point("segment")?]),
                f => return Err(format!("bad segment flag {f}")),
            };
            pairs.push(PairFinding { a, b, kind, contact, distance, segment });
        }
        let ids = match self.u8("ids flag")? {
            0 => None,
            1 => {
                let b = self.take(8 * n, "ids")?;
                Some(b.chunks_exact(8).map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes"))).collect())
            }
            f => return Err(format!("bad ids flag {f}")),
        };
        let result = ClashResult {
            pairs,
            counts,
            closest,
            verdict,
            containment,
            closed: [None, None],
            trees: Default::default(),
            timings: Timings::default(),
        };
        Ok(Stored { result, beyond, overlap, ids })
    }
}

/// A pack's payload back; the error names the first bad field.
pub fn decode_pack(bytes: &[u8]) -> Result<Pack, String> {
    let mut r = Reader { bytes, at: 0 };
    r.tag(PACK_TAG)?;
    let n = r.count(32 + MIN_RESULT, "pairs")?;
    let mut pairs = Vec::with_capacity(n);
    for _ in 0..n {
        let k = r.digest("pair key")?;
        pairs.push((k, r.result()?));
    }
    let m = r.count(40, "tree sizes")?;
    let mut trees = Vec::with_capacity(m);
    for _ in 0..m {
        trees.push((r.digest("part key")?, r.u64("tree bytes")?));
    }
    r.end()?;
    Ok(Pack { pairs, trees })
}

/// An index's payload back: the pack keys.
pub fn decode_index(bytes: &[u8]) -> Result<Vec<Digest>, String> {
    let mut r = Reader { bytes, at: 0 };
    r.tag(INDEX_TAG)?;
    let n = r.count(32, "packs")?;
    let packs = (0..n).map(|_| r.digest("pack key")).collect::<Result<Vec<_>, _>>()?;
    r.end()?;
    Ok(packs)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn result(n: u32, containment: Containment) -> ClashResult {
        let odd = [-0.0, f64::MIN_POSITIVE / 4.0, 1.0 + f64::EPSILON, -1e300, 0.1];
        let pairs = (0..n)
            .map(|i| PairFinding {
                a: i,
                b: u32::MAX - i,
                kind: [PairKind::Crossing, PairKind::Touching, PairKind::Clearance][i as usize % 3],
                contact: [
                    None,
                    Some(Contact::Point),
                    Some(Contact::Segment),
                    Some(Contact::CoplanarArea),
                    Some(Contact::CoplanarBoundary),
                ][i as usize % 5],
                distance: odd[i as usize % 5],
                segment: (i % 2 == 0)
                    .then(|| [DVec3::new(odd[0], odd[1], odd[2]), DVec3::new(odd[3], odd[4], -0.5)]),
            })
            .collect();
        ClashResult {
            pairs,
            counts: Counts { crossing: 1, touching: u64::MAX, within_tolerance: 3, clearance: 4 },
            closest: (n % 2 == 1).then(|| Closest {
                distance: 0.25,
                a: (7, DVec3::new(-0.0, 1e-310, 3.0)),
                b: (9, DVec3::new(4.0, 5.0, 6.0)),
            }),
            verdict: [Verdict::Clear, Verdict::Clearance, Verdict::Touching, Verdict::Clash][n as usize % 4],
            containment,
            closed: [None, None],
            trees: Default::default(),
            timings: Timings::default(),
        }
    }

    fn sample() -> Pack {
        let kinds = [
            Containment::None,
            Containment::AInB,
            Containment::BInA,
            Containment::APartlyInB,
            Containment::BPartlyInA,
            Containment::VolumesOverlap,
            Containment::Undecided("open part é".into()),
        ];
        let pairs = kinds
            .into_iter()
            .enumerate()
            .map(|(i, c)| {
                let beyond =
                    (i % 2 == 0).then_some(Beyond { numbering: [i as u8; 32], a: 1, b: 2, distance: 0.5 });
                let overlap = [
                    None,
                    Some(None),
                    Some(Some(Overlap {
                        min: DVec3::new(-0.0, 1e-310, -2.0),
                        max: DVec3::new(0.0, 1.0, 0.1),
                    })),
                ][i % 3];
                let result = result(i as u32, c);
                let ids = (i % 3 != 1).then(|| {
                    (0..result.pairs.len() as u64)
                        .map(|k| k.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ i as u64)
                        .collect()
                });
                ([i as u8 + 1; 32], Stored { result, beyond, overlap, ids })
            })
            .collect();
        Pack { pairs, trees: vec![([9; 32], 123), ([10; 32], u64::MAX)] }
    }

    /// Equal bit for bit: `Debug` writes each f64 as the shortest text that reads back to its
    /// bits, -0 as `-0.0` (`PartialEq` takes -0 for 0).
    fn bits(p: &Pack) -> String {
        format!("{p:?}")
    }

    #[test]
    fn packs_and_indexes_come_back_bit_for_bit() {
        let want = sample();
        let bytes = encode_pack(&want.pairs, &want.trees);
        assert_eq!(bytes.len(), pack_len(&want.pairs, want.trees.len()), "the length is reserved exactly");
        let back = decode_pack(&bytes).unwrap();
        assert_eq!(back, want);
        assert_eq!(bits(&back), bits(&want));
        let keys = vec![[1; 32], [2; 32], [3; 32]];
        assert_eq!(decode_index(&encode_index(&keys)).unwrap(), keys);
        assert_eq!(decode_pack(&encode_pack(&[], &[])).unwrap(), Pack::default());
    }

    #[test]
    fn every_truncation_and_padding_is_refused() {
        let want = sample();
        let bytes = encode_pack(&want.pairs, &want.trees);
        for n in 0..bytes.len() {
            assert!(decode_pack(&bytes[..n]).is_err(), "cut at {n}");
        }
        let mut padded = bytes.clone();
        padded.push(0);
        assert!(decode_pack(&padded).unwrap_err().contains("after the last record"));
        let index = encode_index(&[[1; 32]]);
        for n in 0..index.len() {
            assert!(decode_index(&index[..n]).is_err(), "cut at {n}");
        }
        // One kind's payload is not the other's.
        assert!(decode_index(&bytes).is_err() && decode_pack(&index).is_err());
    }

    #[test]
    fn bad_fields_and_huge_counts_are_refused_before_any_allocation() {
        let want = sample();
        let bytes = encode_pack(&want.pairs, &want.trees);
        // The count of pairs, then the first result's verdict byte.
        let mut huge = bytes.clone();
        huge[8..16].copy_from_slice(&u64::MAX.to_le_bytes());
        assert!(decode_pack(&huge).unwrap_err().contains("more than"));
        let mut verdict = bytes.clone();
        verdict[16 + 32] = 4;
        assert!(decode_pack(&verdict).unwrap_err().contains("verdict"));
        let mut layout = bytes.clone();
        layout[7] = PACK_LAYOUT + 1;
        assert!(decode_pack(&layout).unwrap_err().contains("layout"));
        // Every single-byte change either is refused or decodes to a different pack (the
        // entry's checksum catches the rest): never a panic.
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x5a;
            if let Ok(p) = decode_pack(&b) {
                assert_ne!(bits(&p), bits(&want), "byte {i}");
            }
        }
    }
}
