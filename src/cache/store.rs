//! The cache directory: entries by [`PairKey`], written atomically, verified on read, bounded in
//! size with least-recently-used eviction. See the [module documentation](super) for the
//! guarantees.

use std::fs::{self, File};
use std::io::{self, Read, Write};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, SystemTime};

use rustix::fs::{FileType, Mode, OFlags};
use serde::de::DeserializeOwned;
use serde::Serialize;

use super::entry::{self, Rejected, MAX_HEADER};
use super::key::{PairKey, TOOL_VERSION};
use crate::error::UsageProblem;
use crate::{Error, Result};

/// The largest entry the store writes or reads: a bound on the memory one entry can take,
/// whatever a hostile file declares.
pub const MAX_ENTRY_BYTES: u64 = 256 << 20;

/// The size bound when the caller has no other: 1 GiB.
pub const DEFAULT_MAX_BYTES: u64 = 1 << 30;

/// The name of the tag file marking a directory as a cache (the Cache Directory Tagging
/// Specification: backup and archiving tools skip such directories).
pub const TAG_FILE: &str = "CACHEDIR.TAG";

/// The tag file's content; the second line marks the directory as meshclash's.
const TAG: &str = "Signature: 8a477f597d28d172789f06886806bc55\n\
                   # This directory is a meshclash result cache: every entry is re-created on demand.\n";
const TAG_MARK: &str = "meshclash result cache";

/// The most of a tag file that is read (ours is under 200 bytes).
const MAX_TAG_BYTES: u64 = 4096;

/// The name prefix of temporary files (an entry being written, the tag being written).
const TEMP_PREFIX: &str = ".tmp-";

/// A temporary file this old was left by a process that died while writing; eviction removes
/// it. Writing one entry takes milliseconds.
const STALE_TEMP: Duration = Duration::from_secs(24 * 60 * 60);

/// Eviction brings the directory down to this fraction of the bound (numerator / 16), so that
/// the puts after it do not each scan the directory again.
const LOW_WATER_SIXTEENTHS: u64 = 14;

/// What the store did, for the report (`part_pairs_reused` is [`Stats::hits`],
/// `part_pairs_checked` is [`Stats::misses`] when every candidate pair is looked up once).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Lookups that returned a stored value.
    pub hits: u64,
    /// Lookups that returned nothing (absent or ignored).
    pub misses: u64,
    /// Entries written.
    pub stored: u64,
    /// Entries removed to keep the directory under its bound.
    pub evicted: u64,
    /// Entries found but not used (corrupt, truncated, foreign); each is also a miss.
    pub ignored: u64,
}

/// The report's `cache` block.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CacheSummary {
    /// Candidate part pairs whose stored result was reused.
    pub part_pairs_reused: u64,
    /// Candidate part pairs checked (not in the cache, or their entry was ignored).
    pub part_pairs_checked: u64,
    /// The cache directory, as given.
    pub dir: String,
}

#[derive(Default)]
struct Counters {
    hits: AtomicU64,
    misses: AtomicU64,
    stored: AtomicU64,
    evicted: AtomicU64,
    ignored: AtomicU64,
}

fn bump(c: &AtomicU64) {
    c.fetch_add(1, Ordering::Relaxed);
}

/// A result cache directory. Shareable between threads (`&self` everywhere) and between
/// processes (see the module documentation).
pub struct Store {
    dir: PathBuf,
    max_bytes: u64,
    counters: Counters,
    warnings: Mutex<Vec<String>>,
    /// Bytes of entries the directory holds as far as this process knows: `None` until the
    /// first put scans it, then the last scan plus what this process wrote since.
    size: Mutex<Option<u64>>,
    /// Set after a put failed: this run stores nothing more (one warning, not one per pair).
    writes_off: AtomicBool,
    /// Set once an entry was too large for the bound (warned once).
    too_large_warned: AtomicBool,
}

impl std::fmt::Debug for Store {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Store").field("dir", &self.dir).field("max_bytes", &self.max_bytes).finish()
    }
}

fn open_error(dir: &Path, what: impl std::fmt::Display) -> Error {
    Error::bad_flag("cache", UsageProblem::Invalid(format!("{}: {what}", dir.display())))
}

/// Whether `name` is a fan-out directory's name: two lowercase hex digits.
fn is_fanout_name(name: &str) -> bool {
    name.len() == 2 && name.bytes().all(|c| matches!(c, b'0'..=b'9' | b'a'..=b'f'))
}

/// Whether `name` is an entry's file name: the last 62 lowercase hex digits of a key.
fn is_entry_name(name: &str) -> bool {
    name.len() == 62 && name.bytes().all(|c| matches!(c, b'0'..=b'9' | b'a'..=b'f'))
}

impl Store {
    /// Open (creating it and its parents if needed) the cache directory `dir`, holding at most
    /// about `max_bytes` bytes of entries.
    ///
    /// Errors (one line naming `dir`): it exists but is not a directory (or is a symbolic link
    /// to a missing target or to something other than a directory); it cannot be created; it
    /// is not empty and not a meshclash cache (no `CACHEDIR.TAG` of ours: a directory of other
    /// files is never filled, nor evicted from); no file can be created in it.
    pub fn open(dir: impl AsRef<Path>, max_bytes: u64) -> Result<Store> {
        let dir = dir.as_ref().to_path_buf();
        match fs::symlink_metadata(&dir) {
            Ok(m) if m.is_dir() => {}
            Ok(m) if m.file_type().is_symlink() => match fs::metadata(&dir) {
                Ok(t) if t.is_dir() => {}
                Ok(_) => {
                    return Err(open_error(&dir, "is a symbolic link to something other than a directory"))
                }
                Err(e) => {
                    return Err(open_error(&dir, format!("is a symbolic link that cannot be followed: {e}")))
                }
            },
            Ok(_) => return Err(open_error(&dir, "is not a directory")),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {
                fs::create_dir_all(&dir).map_err(|e| open_error(&dir, format!("cannot create: {e}")))?
            }
            Err(e) => return Err(open_error(&dir, format!("cannot inspect: {e}"))),
        }
        let tag = dir.join(TAG_FILE);
        match read_tag(&tag) {
            Ok(Some(t)) if String::from_utf8_lossy(&t).contains(TAG_MARK) => {}
            Ok(Some(_)) => {
                return Err(open_error(
                    &dir,
                    "holds another program's CACHEDIR.TAG; give meshclash a directory of its own",
                ))
            }
            Ok(None) => {
                let listing =
                    fs::read_dir(&dir).map_err(|e| open_error(&dir, format!("cannot list: {e}")))?;
                for item in listing {
                    let item = item.map_err(|e| open_error(&dir, format!("cannot list: {e}")))?;
                    let name = item.file_name();
                    let name = name.to_string_lossy();
                    if !(is_fanout_name(&name) || name.starts_with(TEMP_PREFIX) || name == TAG_FILE) {
                        return Err(open_error(
                            &dir,
                            format!(
                                "is not empty and not a meshclash cache (it holds '{name}'); \
                                 give an empty or new directory"
                            ),
                        ));
                    }
                }
                write_atomically(&dir, &tag, TAG.as_bytes())
                    .map_err(|e| open_error(&dir, format!("is not writable: {e}")))?;
            }
            Err(why) => return Err(open_error(&dir, format!("{TAG_FILE}: {why}"))),
        }
        // The tag may predate a permission change: prove a file can be created.
        tempfile::Builder::new()
            .prefix(TEMP_PREFIX)
            .tempfile_in(&dir)
            .map_err(|e| open_error(&dir, format!("is not writable: {e}")))?;
        Ok(Store {
            dir,
            max_bytes,
            counters: Counters::default(),
            warnings: Mutex::new(Vec::new()),
            size: Mutex::new(None),
            writes_off: AtomicBool::new(false),
            too_large_warned: AtomicBool::new(false),
        })
    }

    /// The directory, as given to [`Store::open`].
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The size bound given to [`Store::open`].
    pub fn max_bytes(&self) -> u64 {
        self.max_bytes
    }

    /// Where the entry of `key` lives: `dir/ab/cdef…` (the key's first two hex digits, then
    /// the other 62).
    pub fn entry_path(&self, key: &PairKey) -> PathBuf {
        let hex = key.hex();
        self.dir.join(&hex[..2]).join(&hex[2..])
    }

    /// The value stored for `key`, if there is a whole entry for exactly this key, this tool
    /// version and this entry layout that decodes as `T`. Anything else is a miss; an entry
    /// that is there but not usable adds one warning and is removed (the caller recomputes and
    /// puts it again). A hit marks the entry recently used.
    pub fn get<T: DeserializeOwned>(&self, key: &PairKey) -> Option<T> {
        self.get_with(key, |p| serde_json::from_slice::<T>(p).map_err(|e| e.to_string()))
    }

    /// As [`Store::get`], with the payload decoded by `decode` (an error is a payload that
    /// does not decode: the entry is ignored with one warning and removed).
    pub fn get_with<T>(
        &self,
        key: &PairKey,
        decode: impl FnOnce(&[u8]) -> std::result::Result<T, String>,
    ) -> Option<T> {
        let path = self.entry_path(key);
        let found = match read_entry(&path, key, self.max_bytes.min(MAX_ENTRY_BYTES)) {
            Ok(None) => None,
            Ok(Some((file, bytes))) => {
                match entry::decode(&bytes, key, TOOL_VERSION)
                    .and_then(|p| decode(p).map_err(Rejected::Payload))
                {
                    Ok(v) => {
                        // Recently used: eviction goes by modification time. Failing to touch
                        // (another user's entry) only makes eviction less exact.
                        let _ = file.set_modified(SystemTime::now());
                        Some(v)
                    }
                    Err(why) => {
                        self.ignore(&path, &why);
                        None
                    }
                }
            }
            Err(why) => {
                self.ignore(&path, &why);
                None
            }
        };
        bump(if found.is_some() { &self.counters.hits } else { &self.counters.misses });
        found
    }

    fn ignore(&self, path: &Path, why: &Rejected) {
        bump(&self.counters.ignored);
        // Remove it so it does not warn again; if another process replaced it meanwhile, that
        // costs one recomputation, never a wrong answer.
        let _ = fs::remove_file(path);
        self.warn(format!("cache: ignored entry {}: {why}", path.display()));
    }

    /// Add a warning (the caller's, about an entry it could not use).
    pub(crate) fn warn(&self, w: String) {
        self.warnings.lock().unwrap_or_else(|p| p.into_inner()).push(w);
    }

    /// Store `value` for `key`. Never fails the run: a value that cannot be stored adds a
    /// warning and is not stored (after an I/O failure this store writes nothing more).
    ///
    /// The value is stored only if its encoding decodes back to a value that encodes to the
    /// same bytes (so every f64 comes back bit for bit; a non-finite float, which JSON cannot
    /// hold, is refused here rather than failing every later read); hence `DeserializeOwned`.
    /// Values must serialize deterministically: a `HashMap` inside (iteration order varies) is
    /// refused the same way; use `BTreeMap` or a `Vec`.
    pub fn put<T: Serialize + DeserializeOwned>(&self, key: &PairKey, value: &T) {
        if self.writes_off.load(Ordering::Relaxed) {
            return;
        }
        let payload = match encode_exact(value) {
            Ok(p) => p,
            Err(why) => {
                self.warn(format!("cache: result not stored: {why}"));
                return;
            }
        };
        self.put_bytes(key, &payload);
    }

    /// Store `payload` (already encoded, in a layout its reader decodes with
    /// [`Store::get_with`]) for `key`. Never fails the run, as [`Store::put`].
    pub fn put_bytes(&self, key: &PairKey, payload: &[u8]) {
        if self.writes_off.load(Ordering::Relaxed) {
            return;
        }
        let bytes = entry::encode(key, TOOL_VERSION, payload);
        let len = bytes.len() as u64;
        let limit = self.max_bytes.min(MAX_ENTRY_BYTES);
        if len > limit {
            if !self.too_large_warned.swap(true, Ordering::Relaxed) {
                self.warn(format!(
                    "cache: a result of {len} bytes is over the {limit}-byte entry limit; \
                     such results are not stored"
                ));
            }
            return;
        }
        let path = self.entry_path(key);
        if let Err(e) = self.write_entry(&path, &bytes) {
            if !self.writes_off.swap(true, Ordering::Relaxed) {
                self.warn(format!(
                    "cache: cannot store in {}: {e}; storing turned off for this run",
                    self.dir.display()
                ));
            }
            return;
        }
        bump(&self.counters.stored);
        self.account(len);
    }

    fn write_entry(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        let fanout = path.parent().expect("an entry path has a fan-out directory");
        match fs::symlink_metadata(fanout) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => {
                return Err(io::Error::other(format!(
                    "{} is not a directory (a symbolic link or a file)",
                    fanout.display()
                )))
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => match fs::create_dir(fanout) {
                Ok(()) => {}
                Err(e) if e.kind() == io::ErrorKind::AlreadyExists => {
                    if !fs::symlink_metadata(fanout)?.is_dir() {
                        return Err(io::Error::other(format!("{} is not a directory", fanout.display())));
                    }
                }
                Err(e) => return Err(e),
            },
            Err(e) => return Err(e),
        }
        write_atomically(fanout, path, bytes)
    }

    /// Count `added` bytes just written; evict when over the bound.
    fn account(&self, added: u64) {
        let mut size = self.size.lock().unwrap_or_else(|p| p.into_inner());
        let known = match *size {
            Some(s) => s.saturating_add(added),
            None => self.scan().iter().map(|e| e.len).sum(),
        };
        *size = Some(if known > self.max_bytes { self.evict() } else { known });
    }

    /// Remove least recently used entries until the directory holds at most the low-water
    /// mark; the bytes left. Entries another process removes or replaces meanwhile are simply
    /// gone or new: removal of a missing file is not an error, and a replaced entry is at
    /// worst one recomputation.
    fn evict(&self) -> u64 {
        let mut entries = self.scan();
        let mut total: u64 = entries.iter().map(|e| e.len).sum();
        if total <= self.max_bytes {
            return total;
        }
        let low = self.max_bytes / 16 * LOW_WATER_SIXTEENTHS;
        entries.sort_by(|x, y| x.mtime.cmp(&y.mtime).then_with(|| x.path.cmp(&y.path)));
        for e in entries {
            if total <= low {
                break;
            }
            match fs::remove_file(&e.path) {
                Ok(()) => {
                    bump(&self.counters.evicted);
                    total -= e.len;
                }
                Err(err) if err.kind() == io::ErrorKind::NotFound => total -= e.len,
                Err(_) => {}
            }
        }
        total
    }

    /// Every entry file in the directory (fan-out directories that are real directories, file
    /// names that are entry names); stale temporaries are removed on the way.
    fn scan(&self) -> Vec<Scanned> {
        let mut out = Vec::new();
        let Ok(top) = fs::read_dir(&self.dir) else { return out };
        let now = SystemTime::now();
        for d in top.flatten() {
            let name = d.file_name();
            if !is_fanout_name(&name.to_string_lossy()) || !d.file_type().is_ok_and(|t| t.is_dir()) {
                continue;
            }
            let Ok(files) = fs::read_dir(d.path()) else { continue };
            for f in files.flatten() {
                let name = f.file_name();
                let name = name.to_string_lossy();
                let Ok(m) = f.metadata() else { continue };
                let mtime = m.modified().unwrap_or(SystemTime::UNIX_EPOCH);
                if name.starts_with(TEMP_PREFIX) {
                    if m.is_file() && now.duration_since(mtime).is_ok_and(|age| age > STALE_TEMP) {
                        let _ = fs::remove_file(f.path());
                    }
                    continue;
                }
                if is_entry_name(&name) && !m.is_dir() {
                    out.push(Scanned { path: f.path(), len: m.len(), mtime });
                }
            }
        }
        out
    }

    /// The warnings collected since the last call (ignored entries, results not stored), in
    /// the order they happened; the library never prints them.
    pub fn take_warnings(&self) -> Vec<String> {
        std::mem::take(&mut *self.warnings.lock().unwrap_or_else(|p| p.into_inner()))
    }

    /// The counts so far.
    pub fn stats(&self) -> Stats {
        let c = &self.counters;
        let get = |a: &AtomicU64| a.load(Ordering::Relaxed);
        Stats {
            hits: get(&c.hits),
            misses: get(&c.misses),
            stored: get(&c.stored),
            evicted: get(&c.evicted),
            ignored: get(&c.ignored),
        }
    }

    /// The report's `cache` block.
    pub fn summary(&self) -> CacheSummary {
        let s = self.stats();
        CacheSummary {
            part_pairs_reused: s.hits,
            part_pairs_checked: s.misses,
            dir: self.dir.to_string_lossy().into_owned(),
        }
    }
}

struct Scanned {
    path: PathBuf,
    len: u64,
    mtime: SystemTime,
}

/// `value` as JSON, if that JSON decodes to a value that encodes to the same bytes.
fn encode_exact<T: Serialize + DeserializeOwned>(value: &T) -> std::result::Result<Vec<u8>, String> {
    let payload = serde_json::to_vec(value).map_err(|e| format!("cannot encode: {e}"))?;
    let back: T = serde_json::from_slice(&payload)
        .map_err(|e| format!("its encoding does not decode (a non-finite number?): {e}"))?;
    let again = serde_json::to_vec(&back).map_err(|e| format!("cannot encode: {e}"))?;
    if again != payload {
        return Err("its encoding does not come back exactly".into());
    }
    Ok(payload)
}

/// Write `bytes` to `path` through a new temporary in `dir` (same file system): created with
/// an unpredictable name and `O_EXCL`, mode 0666 less the umask, then renamed over `path`, so a
/// reader sees the old file, no file or the whole new one.
fn write_atomically(dir: &Path, path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut tmp = tempfile::Builder::new()
        .prefix(TEMP_PREFIX)
        .permissions(fs::Permissions::from_mode(0o666))
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

/// Open `path` without following a symbolic link and without blocking (a FIFO planted there
/// cannot hang the run): `None` if there is none; the file and its length if it is a regular
/// file of at most `limit` bytes; else why not.
fn open_regular(path: &Path, limit: u64) -> std::result::Result<Option<(File, u64)>, Rejected> {
    let flags = OFlags::RDONLY | OFlags::NOFOLLOW | OFlags::NONBLOCK | OFlags::CLOEXEC;
    let fd = match rustix::fs::open(path, flags, Mode::empty()) {
        Ok(fd) => fd,
        Err(rustix::io::Errno::NOENT) => return Ok(None),
        Err(rustix::io::Errno::LOOP) => return Err(Rejected::NotAFile),
        Err(e) => return Err(Rejected::Io(io::Error::from(e).to_string())),
    };
    let st = rustix::fs::fstat(&fd).map_err(|e| Rejected::Io(io::Error::from(e).to_string()))?;
    if FileType::from_raw_mode(st.st_mode) != FileType::RegularFile {
        return Err(Rejected::NotAFile);
    }
    let len = st.st_size as u64;
    if len > limit {
        return Err(Rejected::TooLarge { len, limit });
    }
    Ok(Some((File::from(fd), len)))
}

/// The tag file's bytes, `None` when there is none.
fn read_tag(path: &Path) -> std::result::Result<Option<Vec<u8>>, Rejected> {
    let Some((mut file, len)) = open_regular(path, MAX_TAG_BYTES)? else { return Ok(None) };
    let mut bytes = vec![0u8; len as usize];
    file.read_exact(&mut bytes).map_err(|e| Rejected::Io(e.to_string()))?;
    Ok(Some(bytes))
}

/// Read the entry at `path`: `None` if there is none; the open file (to touch) and its bytes
/// when the header matches `key` and this build; else why not. Nothing is allocated beyond
/// `limit` bytes or what the file holds.
fn read_entry(
    path: &Path,
    key: &PairKey,
    limit: u64,
) -> std::result::Result<Option<(File, Vec<u8>)>, Rejected> {
    let Some((mut file, len)) = open_regular(path, limit)? else { return Ok(None) };
    let mut head = vec![0u8; (len as usize).min(MAX_HEADER)];
    file.read_exact(&mut head).map_err(|e| Rejected::Io(e.to_string()))?;
    entry::check_header(&head, len, key, TOOL_VERSION)?;
    let from = head.len();
    let mut bytes = head;
    bytes.resize(len as usize, 0);
    file.read_exact(&mut bytes[from..]).map_err(|e| Rejected::Io(e.to_string()))?;
    Ok(Some((file, bytes)))
}
