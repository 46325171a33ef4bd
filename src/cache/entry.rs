//! The bytes of one cache entry: a header that says what the entry is and proves the payload
//! whole, then the payload.
//!
//! | bytes | content |
//! |---|---|
//! | 8 | magic `MCLCACHE` |
//! | 4 | [`FORMAT`], u32 little-endian |
//! | 1 | the tool version's length `n` in bytes (at most 255) |
//! | n | the tool version, UTF-8 |
//! | 32 | the [`PairKey`] the entry answers |
//! | 8 | the payload's length, u64 little-endian |
//! | 32 | the payload's SHA-256 |
//! | … | the payload (JSON) |
//!
//! [`decode`] accepts an entry only when every field matches what the reader asked for and the
//! file holds exactly the declared payload.

use std::fmt;

use super::key::{digest, PairKey, FORMAT};

/// The first bytes of every entry.
pub const MAGIC: &[u8; 8] = b"MCLCACHE";

/// The header's length for a tool version of `version_len` bytes.
pub fn header_len(version_len: usize) -> usize {
    8 + 4 + 1 + version_len + 32 + 8 + 32
}

/// The longest header any entry can have (a 255-byte version).
pub const MAX_HEADER: usize = 8 + 4 + 1 + 255 + 32 + 8 + 32;

/// Why an entry was not used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Rejected {
    /// Not a regular file (a directory, a FIFO, a device, a symbolic link).
    NotAFile,
    /// Shorter than its header.
    ShortHeader {
        /// The file's length.
        len: u64,
    },
    /// Does not start with [`MAGIC`].
    Magic,
    /// Written with another entry layout.
    Format {
        /// The entry's layout number.
        found: u32,
    },
    /// Written by another version of the tool.
    Version {
        /// The entry's version (lossy UTF-8).
        found: String,
    },
    /// The header names another key.
    Key,
    /// The declared payload length is not what the file holds.
    Length {
        /// The declared length.
        declared: u64,
        /// What the file holds after the header.
        actual: u64,
    },
    /// The entry is larger than the reader accepts.
    TooLarge {
        /// The file's length.
        len: u64,
        /// The limit.
        limit: u64,
    },
    /// The payload's SHA-256 is not the header's.
    Checksum,
    /// The payload is whole but does not decode as the requested type.
    Payload(String),
    /// Reading it failed.
    Io(String),
}

impl fmt::Display for Rejected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Rejected::NotAFile => f.write_str("not a regular file"),
            Rejected::ShortHeader { len } => write!(f, "truncated ({len} bytes, shorter than its header)"),
            Rejected::Magic => f.write_str("not a meshclash cache entry (bad magic)"),
            Rejected::Format { found } => {
                write!(f, "written with entry layout {found}, this build reads layout {FORMAT}")
            }
            Rejected::Version { found } => write!(f, "written by meshclash {found}"),
            Rejected::Key => f.write_str("its header names another key"),
            Rejected::Length { declared, actual } => {
                write!(f, "truncated or padded (declares {declared} payload bytes, holds {actual})")
            }
            Rejected::TooLarge { len, limit } => write!(f, "{len} bytes, over the {limit}-byte limit"),
            Rejected::Checksum => f.write_str("payload checksum mismatch"),
            Rejected::Payload(e) => write!(f, "payload does not decode: {e}"),
            Rejected::Io(e) => write!(f, "cannot read: {e}"),
        }
    }
}

/// The entry for `key` holding `payload`, as written by `version`.
pub fn encode(key: &PairKey, version: &str, payload: &[u8]) -> Vec<u8> {
    let v = version.as_bytes();
    assert!(v.len() <= 255, "a tool version is a short string");
    let mut out = Vec::with_capacity(header_len(v.len()) + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend(FORMAT.to_le_bytes());
    out.push(v.len() as u8);
    out.extend_from_slice(v);
    out.extend_from_slice(key.as_bytes());
    out.extend((payload.len() as u64).to_le_bytes());
    out.extend_from_slice(&digest(payload));
    out.extend_from_slice(payload);
    out
}

/// Check the header in `head` (the file's first bytes, up to [`MAX_HEADER`]) of a file of
/// `file_len` bytes against `key` and `version`; the payload's length and checksum on success.
pub fn check_header(
    head: &[u8],
    file_len: u64,
    key: &PairKey,
    version: &str,
) -> Result<(usize, [u8; 32]), Rejected> {
    let short = Rejected::ShortHeader { len: file_len };
    if head.len() < 13 {
        return Err(if head.len() >= 8 && &head[..8] != MAGIC { Rejected::Magic } else { short });
    }
    if &head[..8] != MAGIC {
        return Err(Rejected::Magic);
    }
    let format = u32::from_le_bytes(head[8..12].try_into().expect("4 bytes"));
    if format != FORMAT {
        return Err(Rejected::Format { found: format });
    }
    let vlen = head[12] as usize;
    let hlen = header_len(vlen);
    if head.len() < hlen {
        return Err(short);
    }
    let found = &head[13..13 + vlen];
    if found != version.as_bytes() {
        return Err(Rejected::Version { found: String::from_utf8_lossy(found).into_owned() });
    }
    let mut at = 13 + vlen;
    if &head[at..at + 32] != key.as_bytes() {
        return Err(Rejected::Key);
    }
    at += 32;
    let declared = u64::from_le_bytes(head[at..at + 8].try_into().expect("8 bytes"));
    at += 8;
    let actual = file_len - hlen as u64;
    if declared != actual {
        return Err(Rejected::Length { declared, actual });
    }
    let sum: [u8; 32] = head[at..at + 32].try_into().expect("32 bytes");
    Ok((hlen, sum))
}

/// Decode a whole entry held in memory (`bytes`) written for `key` by `version`: its payload.
pub fn decode<'a>(bytes: &'a [u8], key: &PairKey, version: &str) -> Result<&'a [u8], Rejected> {
    let head = &bytes[..bytes.len().min(MAX_HEADER)];
    let (hlen, sum) = check_header(head, bytes.len() as u64, key, version)?;
    let payload = &bytes[hlen..];
    if digest(payload) != sum {
        return Err(Rejected::Checksum);
    }
    Ok(payload)
}
