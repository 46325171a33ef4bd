//! The result cache: re-check only what changed.
//!
//! A part pair's result is stored under a [`PairKey`], and a later run that meets the same key
//! reuses it instead of walking the trees again. What the store guarantees:
//!
//! - **Content-addressed, exact.** A [`PartKey`] is a SHA-256 of the part's name and the bit
//!   patterns of its world-space f64 triangles (after placement and units), in triangle order:
//!   a part moved, re-tessellated or renamed is a new key; nothing is matched "nearly". A
//!   [`PairKey`] adds the A-side and B-side part keys in that order, the [`Fingerprint`] of every
//!   setting that changes the answer, the tool version ([`TOOL_VERSION`]) and the entry layout
//!   ([`FORMAT`]): a cache written by another version, or under other settings, is never found.
//! - **Nothing is trusted without verification.** An entry is read back only if its header has
//!   the magic, this layout, this version and exactly the requested key, its declared length
//!   is what the file holds, and the payload's SHA-256 matches; then the payload must decode
//!   whole. Anything else (corrupt, truncated, foreign, not a regular file) is ignored with one
//!   warning, counted as a miss and removed; the caller recomputes and stores it again. The
//!   per-pair results travel in a binary layout ([`pack`]) that holds every f64 as its bits; a
//!   JSON value ([`Store::put`]) is stored only when its encoding decodes back to the same
//!   bytes, so every f64 returns bit for bit.
//! - **Atomic, shareable.** Entries are written to a new temporary (unpredictable name,
//!   `O_EXCL`) beside the entry and renamed over it: readers see no entry or a whole one, and
//!   two processes storing the same key at once both succeed. Concurrent runs and shards may
//!   share one directory.
//! - **Bounded.** After a put, when the directory holds more than its bound, the least
//!   recently used entries (file modification time, refreshed on every hit) are removed until
//!   it holds at most 7/8 of the bound. Each process counts what it wrote since its last scan,
//!   so concurrent writers can overshoot by what they wrote meanwhile; an eviction racing
//!   another process costs at most a recomputation. No entry is read into memory beyond
//!   [`MAX_ENTRY_BYTES`] or the bound, whatever a file declares.
//! - **A cache never fails a run.** [`Store::open`] refuses, with one line naming the
//!   directory, a path that is not a directory (or a symbolic link to one), a directory that
//!   cannot be created or written, and a non-empty directory that is not a meshclash cache (so
//!   a mistyped `--cache` never fills or evicts from someone's files). After that, a failing
//!   put is a warning and storing stops for the run; lookups keep working.
//!
//! The library never prints: warnings are collected ([`Store::take_warnings`]) with the counts
//! ([`Store::stats`], [`Store::summary`] for the report's `cache` block).
//!
//! Layout on disk: `DIR/CACHEDIR.TAG`, and each entry at `DIR/ab/cdef…` (the key's first two
//! hex digits name the directory, the other 62 the file); the entry's bytes are described in
//! [`entry`].

pub mod entry;
pub mod hook;
pub mod key;
pub mod pack;
pub mod pairs;
pub mod store;

pub use hook::{CacheConfig, WholeCheck};
pub use key::{Fingerprint, PairKey, PartHasher, PartKey, Setting, FORMAT, TOOL_VERSION};
pub use pairs::{CheckCache, PairReuse};
pub use store::{CacheSummary, Stats, Store, DEFAULT_MAX_BYTES, MAX_ENTRY_BYTES};

#[cfg(test)]
mod tests;
