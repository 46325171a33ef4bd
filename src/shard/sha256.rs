//! SHA-256 (FIPS 180-4), for the content hashes of a plan's inputs, the plan's own hash, the
//! stable part-pair ids and the result cache's keys: one type over the `sha2` crate, so every
//! user hashes at the processor's speed.

/// An incremental SHA-256 (the `sha2` crate: SHA-NI or the ARMv8 SHA extensions when the
/// processor has them, detected at run time; a portable implementation otherwise).
#[derive(Debug, Clone, Default)]
pub struct Sha256(sha2::Sha256);

impl Sha256 {
    /// Feed bytes.
    pub fn update(&mut self, data: &[u8]) {
        sha2::Digest::update(&mut self.0, data);
    }

    /// The digest's 32 bytes.
    pub fn digest(self) -> [u8; 32] {
        sha2::Digest::finalize(self.0).into()
    }

    /// The digest as 64 lowercase hex digits.
    pub fn hex(self) -> String {
        self.digest().iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// SHA-256 of `data`, as hex.
pub fn hex(data: &[u8]) -> String {
    let mut s = Sha256::default();
    s.update(data);
    s.hex()
}

/// SHA-256 of a file's bytes, read in chunks (a plan's inputs can be gigabytes).
pub fn file_hex(path: &std::path::Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut f = std::fs::File::open(path)?;
    let mut s = Sha256::default();
    let mut buf = vec![0u8; 1 << 20];
    loop {
        let n = f.read(&mut buf)?;
        if n == 0 {
            return Ok(s.hex());
        }
        s.update(&buf[..n]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_digests() {
        assert_eq!(hex(b""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
        assert_eq!(hex(b"abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
        assert_eq!(
            hex(b"abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1"
        );
        // A million 'a' fed in uneven pieces (block boundaries inside updates).
        let mut s = Sha256::default();
        let a = vec![b'a'; 1000];
        for i in 0..1000 {
            s.update(&a[..(i % 7) * 100 + 1]);
            s.update(&a[..999 - (i % 7) * 100]);
        }
        assert_eq!(s.hex(), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
    }
}
