//! The stable id of a pair of triangles (a finding), a pure function of their world
//! coordinates and part names: regions and the baseline comparison share it. The definition is
//! in [`crate::report::baseline`]'s module docs.

use crate::scene::mesh::Mesh;

const FNV_OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
const FNV_PRIME: u64 = 0x0000_0100_0000_01b3;

struct Fnv(u64);

impl Fnv {
    fn bytes(&mut self, b: &[u8]) {
        for &x in b {
            self.0 = (self.0 ^ x as u64).wrapping_mul(FNV_PRIME);
        }
    }

    fn triangle(&mut self, mesh: &Mesh, t: u32) {
        let mut v: [[u64; 3]; 3] = mesh.triangles[t as usize].map(|i| {
            let p = mesh.positions[i as usize];
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
pub fn finding_id(a: &Mesh, ta: u32, b: &Mesh, tb: u32) -> String {
    format_id(finding_hash(a, ta, b, tb))
}

/// The 64-bit hash behind [`finding_id`] (the id is its 16 hex digits, so ids order as their
/// hashes do).
pub fn finding_hash(a: &Mesh, ta: u32, b: &Mesh, tb: u32) -> u64 {
    fn name(m: &Mesh, t: u32) -> &str {
        m.objects.get(m.tri_object[t as usize] as usize).map_or("", |o| &o.name)
    }
    let mut h = Fnv(FNV_OFFSET);
    h.triangle(a, ta);
    h.name(name(a, ta));
    h.triangle(b, tb);
    h.name(name(b, tb));
    h.finish()
}

/// A finding id as written: 16 lowercase hex digits.
pub fn format_id(hash: u64) -> String {
    format!("{hash:016x}")
}
