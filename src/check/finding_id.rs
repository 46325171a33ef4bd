//! The stable id of a pair of triangles (a finding), a pure function of their world
//! coordinates and part names: regions and the baseline comparison share it. The definition is
//! in [`crate::report::baseline`]'s module docs.

use crate::check::query::PairFinding;
use crate::scene::mesh::WorldTriangles;

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

#[derive(Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(FNV_PRIME);
        }
    }

    fn triangle<M: WorldTriangles + ?Sized>(&mut self, mesh: &M, t: u32) {
        let mut v: [[u64; 3]; 3] = mesh.corners(t).map(|p| {
            [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits()) // -0.0 + 0.0 = +0.0
        });
        v.sort_unstable();
        for c in v.iter().flatten() {
            self.bytes(&c.to_le_bytes());
        }
    }

    fn name(&mut self, s: &str) {
        self.bytes(&(s.len() as u64).to_le_bytes());
        self.bytes(s.as_bytes());
    }

    /// splitmix64's finaliser, so that nearby inputs differ in every digit.
    fn finish(self) -> u64 {
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
}

/// The stable id of the pair (triangle `ta` of `a`, triangle `tb` of `b`), see the module docs.
pub fn finding_id<A, B>(a: &A, ta: u32, b: &B, tb: u32) -> String
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    format_id(finding_hash(a, ta, b, tb))
}

fn object_name<M: WorldTriangles + ?Sized>(m: &M, t: u32) -> &str {
    m.object_name(m.object_of(t))
}

/// The hash state after A's triangle `ta` and its object name: the first half of every id
/// whose A triangle is `ta`.
fn a_half<A: WorldTriangles + ?Sized>(a: &A, ta: u32) -> Fnv {
    let mut h = Fnv(FNV_OFFSET);
    h.triangle(a, ta);
    h.name(object_name(a, ta));
    h
}

/// Complete an id begun by [`a_half`] with B's triangle `tb`.
fn b_half<B: WorldTriangles + ?Sized>(mut h: Fnv, b: &B, tb: u32) -> u64 {
    h.triangle(b, tb);
    h.name(object_name(b, tb));
    h.finish()
}

/// The 64-bit hash behind [`finding_id`] (the id is its 16 hex digits, so ids order as their
/// hashes do).
pub fn finding_hash<A, B>(a: &A, ta: u32, b: &B, tb: u32) -> u64
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    b_half(a_half(a, ta), b, tb)
}

/// [`finding_hash`] of every pair, in the order of `pairs`, computed in parallel. Consecutive
/// pairs with the same A triangle (a list sorted by (a, b)) share the first half of the hash,
/// which is computed once for them. `a` and `b` are where the triangles come from: the world
/// meshes, or an instanced scene that places only the triangles read.
pub fn finding_hashes<A, B>(pairs: &[PairFinding], a: &A, b: &B) -> Vec<u64>
where
    A: WorldTriangles + ?Sized,
    B: WorldTriangles + ?Sized,
{
    use rayon::prelude::*;
    const CHUNK: usize = 2048;
    let mut out = vec![0u64; pairs.len()];
    out.par_chunks_mut(CHUNK).zip(pairs.par_chunks(CHUNK)).for_each(|(out, pairs)| {
        let mut last: Option<(u32, Fnv)> = None;
        for (h, p) in out.iter_mut().zip(pairs) {
            let first = match last {
                Some((ta, s)) if ta == p.a => s,
                _ => {
                    let s = a_half(a, p.a);
                    last = Some((p.a, s));
                    s
                }
            };
            *h = b_half(first, b, p.b);
        }
    });
    out
}

/// A finding id as written: 16 lowercase hex digits.
pub fn format_id(hash: u64) -> String {
    let mut s = String::with_capacity(16);
    push_id(&mut s, hash);
    s
}

/// Append `hash` as a finding id (16 lowercase hex digits) to `s`.
fn push_id(s: &mut String, hash: u64) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    for k in (0..16).rev() {
        s.push(HEX[((hash >> (4 * k)) & 0xf) as usize] as char);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn format_id_writes_what_the_format_macro_writes() {
        for h in [0u64, 1, 0xa, 0xdead_beef, u64::MAX, 0x0123_4567_89ab_cdef, 1 << 63] {
            assert_eq!(format_id(h), format!("{h:016x}"));
        }
    }
}
