use std::fs;
use std::path::Path;
use std::time::{Duration, SystemTime};

use glam::DVec3;
use serde::{Deserialize, Serialize};

use super::entry::{self, Rejected, MAGIC};
use super::*;
use crate::scene::mesh::Mesh;

fn tri(c: [f64; 9]) -> [DVec3; 3] {
    [DVec3::new(c[0], c[1], c[2]), DVec3::new(c[3], c[4], c[5]), DVec3::new(c[6], c[7], c[8])]
}

const UNIT: [f64; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];

fn settings() -> Vec<(&'static str, Setting)> {
    vec![
        ("tolerance", 0.01.into()),
        ("mode", "clash".into()),
        ("max_pairs", 1000_u64.into()),
        ("penetration", true.into()),
        ("detail", None::<&str>.into()),
    ]
}

// The digests below were computed independently (Python's hashlib over the byte layouts the
// doc comments give); they pin the layouts: changing one must bump `FORMAT`.
#[test]
fn part_key_test_vector() {
    let p = PartKey::of("p", [tri(UNIT)]);
    assert_eq!(p.hex(), "685219fed0199e13eb837b5e3ab6cc4992a6c3be002d1bfb9ee7127654f1acac");
    let mut q = UNIT;
    q[8] = -0.0;
    assert_eq!(
        PartKey::of("q", [tri(q)]).hex(),
        "1874258ed4d297c1e4cabc25b4f721007cf829a54c43ded800fa11ecd1cb4967"
    );
}

#[test]
fn settings_fingerprint_test_vector_in_any_order() {
    let want = "3dda65bb875dfc0d0eef30838d8d1172c5db146c94ac7d080529b5267f6f74c6";
    let mut s = settings();
    assert_eq!(Fingerprint::of(s.clone()).hex(), want);
    s.reverse();
    assert_eq!(Fingerprint::of(s.clone()).hex(), want);
    s.rotate_left(2);
    assert_eq!(Fingerprint::of(s).hex(), want);
}

#[test]
fn pair_key_test_vector() {
    let p = PartKey::of("p", [tri(UNIT)]);
    let mut q = UNIT;
    q[8] = -0.0;
    let q = PartKey::of("q", [tri(q)]);
    let s = Fingerprint::of(settings());
    let k = PairKey::for_version(&p, &q, &s, "0.1.0", 1);
    assert_eq!(k.hex(), "141b1bc5afd6bf93834455276c1948c2c5b06ed6218ec61a0e8fea18b0a73bed");
    assert_eq!(PairKey::new(&p, &q, &s), PairKey::for_version(&p, &q, &s, TOOL_VERSION, FORMAT));
}

#[test]
fn part_key_follows_every_bit_name_and_order() {
    let a = tri(UNIT);
    let mut moved = UNIT;
    moved[3] = f64::from_bits(1.0_f64.to_bits() + 1);
    let b = tri(moved);
    let base = PartKey::of("part", [a, b]);
    assert_eq!(base, PartKey::of("part", [a, b]));
    assert_ne!(base, PartKey::of("part", [b, a]), "triangle order");
    assert_ne!(base, PartKey::of("Part", [a, b]), "name");
    assert_ne!(base, PartKey::of("part", [a, a]), "one ulp of one coordinate");
    assert_ne!(base, PartKey::of("part", [a]), "triangle count");
    // The name's length is hashed: a name cannot borrow bytes from the triangles.
    assert_ne!(PartKey::of("", []), PartKey::of("\0\0\0\0\0\0\0\0", []));
    // Translated by an exact amount: still a new key (placement is part of the key).
    let shifted = a.map(|v| v + DVec3::new(1.0, 0.0, 0.0));
    assert_ne!(PartKey::of("part", [a]), PartKey::of("part", [shifted]));
}

#[test]
fn part_key_of_a_mesh_part_and_incrementally_agree() {
    let mesh = Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
        triangles: vec![[0, 1, 2], [0, 2, 3], [1, 2, 3]],
        ..Mesh::default()
    };
    let direct = PartKey::of("n", [[DVec3::ZERO, DVec3::Y, DVec3::Z], [DVec3::X, DVec3::Y, DVec3::Z]]);
    assert_eq!(PartKey::of_mesh_part("n", &mesh, &[1, 2]), direct);
    let objects = ["x", "y"].map(|n| crate::scene::mesh::Object { name: n.into(), ..Default::default() });
    let mesh = Mesh { tri_object: vec![1, 0, 1], objects: objects.to_vec(), ..mesh };
    let parts = crate::check::assembly::parts_of(&mesh, 0);
    let keys: Vec<PartKey> =
        parts.iter().map(|p| PartKey::of_mesh_part(&p.name, &mesh, &p.triangles)).collect();
    assert_eq!(keys.len(), 2);
    assert_ne!(keys[0], keys[1]);
    assert_eq!(PartKey::of_parts(&mesh, &parts), keys);
    let mut h = PartHasher::new("n");
    h.triangle([DVec3::ZERO, DVec3::Y, DVec3::Z]);
    h.triangle([DVec3::X, DVec3::Y, DVec3::Z]);
    assert_eq!(h.finish(), direct);
}

#[test]
fn fingerprint_separates_kinds_values_and_absence() {
    let f = |s: Vec<(&str, Setting)>| Fingerprint::of(s);
    assert_ne!(f(vec![("n", 3_u64.into())]), f(vec![("n", 3.0.into())]));
    assert_ne!(f(vec![("n", 3_u64.into())]), f(vec![("n", 3_i64.into())]));
    assert_ne!(f(vec![("t", 0.0.into())]), f(vec![("t", (-0.0).into())]));
    assert_ne!(f(vec![("t", None::<f64>.into())]), f(vec![]));
    assert_eq!(f(vec![("t", Some(2.5).into())]), f(vec![("t", 2.5.into())]));
    assert_ne!(f(vec![("a", "bc".into())]), f(vec![("ab", "c".into())]));
    assert_ne!(f(vec![("mode", "clash".into())]), f(vec![("mode", "clearance".into())]));
    let base = f(settings());
    let mut s = settings();
    s[0].1 = 0.010000000000000002.into();
    assert_ne!(base, f(s));
}

#[test]
fn pair_key_follows_sides_settings_version_and_layout() {
    let p = PartKey::of("p", [tri(UNIT)]);
    let q = PartKey::of("q", [tri(UNIT)]);
    let s = Fingerprint::of(settings());
    let k = PairKey::new(&p, &q, &s);
    assert_ne!(k, PairKey::new(&q, &p, &s), "sides are ordered");
    assert_ne!(k, PairKey::new(&p, &q, &Fingerprint::of(vec![])));
    assert_ne!(k, PairKey::for_version(&p, &q, &s, "0.0.0-other", FORMAT));
    assert_ne!(k, PairKey::for_version(&p, &q, &s, TOOL_VERSION, FORMAT + 1));
}

// ---------------------------------------------------------------------------------------------
// The store.

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Outcome {
    verdict: String,
    pairs: Vec<(u32, u32)>,
    closest: Option<f64>,
    points: Vec<[f64; 3]>,
}

fn outcome(n: u32) -> Outcome {
    Outcome {
        verdict: format!("clash {n}"),
        pairs: (0..n).map(|i| (i, 2 * i + 1)).collect(),
        closest: Some(0.1 + 0.2 * f64::from(n)),
        points: vec![[1.0 / 3.0, -0.0, 5e-324], [f64::MAX, f64::MIN_POSITIVE, -1e300]],
    }
}

fn key(n: u32) -> PairKey {
    let a = PartKey::of(&format!("a{n}"), [tri(UNIT)]);
    let b = PartKey::of("b", [tri(UNIT)]);
    PairKey::new(&a, &b, &Fingerprint::of(settings()))
}

fn store(dir: &Path) -> Store {
    Store::open(dir, DEFAULT_MAX_BYTES).unwrap()
}

fn one_warning(s: &Store, needle: &str) {
    let w = s.take_warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    assert!(w[0].contains(needle), "{w:?} lacks {needle:?}");
    assert!(!w[0].contains('\n'));
    assert!(w[0].starts_with("cache: "), "{w:?}");
}

#[test]
fn put_then_get_returns_the_value_and_counts() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    assert_eq!(s.get::<Outcome>(&key(1)), None);
    s.put(&key(1), &outcome(3));
    assert_eq!(s.get::<Outcome>(&key(1)), Some(outcome(3)));
    assert_eq!(s.get::<Outcome>(&key(2)), None);
    assert_eq!(s.stats(), Stats { hits: 1, misses: 2, stored: 1, evicted: 0, ignored: 0 });
    assert!(s.take_warnings().is_empty());
    let hex = key(1).hex();
    assert_eq!(s.entry_path(&key(1)), d.path().join(&hex[..2]).join(&hex[2..]));
    assert!(s.entry_path(&key(1)).is_file());
    assert!(d.path().join("CACHEDIR.TAG").is_file());
    // Another store on the same directory (a later run) finds it.
    let again = store(d.path());
    assert_eq!(again.get::<Outcome>(&key(1)), Some(outcome(3)));
    let sum = serde_json::to_string(&again.summary()).unwrap();
    let dir = serde_json::to_string(&d.path().to_string_lossy()).unwrap();
    assert_eq!(sum, format!(r#"{{"part_pairs_reused":1,"part_pairs_checked":0,"dir":{dir}}}"#));
}

#[test]
fn floats_come_back_bit_for_bit() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    // Finite f64s from all over the bit space (xorshift), plus the awkward ones.
    let mut x = 0x9e37_79b9_7f4a_7c15_u64;
    let mut xs: Vec<f64> = vec![0.0, -0.0, 5e-324, -5e-324, f64::MIN_POSITIVE, f64::MAX, f64::MIN, 0.1 + 0.2];
    xs.push(f64::from_bits(0x000f_ffff_ffff_ffff)); // largest subnormal
    xs.push(f64::EPSILON);
    while xs.len() < 20_000 {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        let f = f64::from_bits(x);
        if f.is_finite() {
            xs.push(f);
        }
    }
    s.put(&key(7), &xs);
    let back: Vec<f64> = s.get(&key(7)).expect("stored");
    assert_eq!(back.len(), xs.len());
    for (a, b) in xs.iter().zip(&back) {
        assert_eq!(a.to_bits(), b.to_bits(), "{a:e} came back as {b:e}");
    }
}

#[test]
fn non_finite_values_are_not_stored() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        s.put(&key(1), &vec![1.0, v]);
        one_warning(&s, "result not stored");
    }
    assert_eq!(s.stats().stored, 0);
    assert!(!s.entry_path(&key(1)).exists());
    assert_eq!(s.get::<Vec<f64>>(&key(1)), None);
}

/// Store `outcome(1)` under `key(1)`, let `spoil` change the file, and check that a lookup is a
/// miss with one warning containing `needle`, and that the slot works again afterwards.
fn spoiled(spoil: impl FnOnce(&Path, Vec<u8>), needle: &str) {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    s.put(&key(1), &outcome(1));
    let path = s.entry_path(&key(1));
    let bytes = fs::read(&path).unwrap();
    spoil(&path, bytes);
    assert_eq!(s.get::<Outcome>(&key(1)), None, "{needle}");
    one_warning(&s, needle);
    assert_eq!(s.stats().ignored, 1);
    assert_eq!(s.stats().misses, 1);
    assert!(fs::symlink_metadata(&path).is_err() || fs::symlink_metadata(&path).unwrap().is_dir());
    // Recomputed and stored again: a hit.
    if !path.is_dir() {
        s.put(&key(1), &outcome(1));
        assert_eq!(s.get::<Outcome>(&key(1)), Some(outcome(1)));
        assert!(s.take_warnings().is_empty());
    }
}

fn header_len() -> usize {
    entry::header_len(TOOL_VERSION.len())
}

#[test]
fn a_corrupt_payload_is_ignored() {
    spoiled(
        |p, mut b| {
            let i = b.len() - 3;
            b[i] ^= 0x01;
            fs::write(p, b).unwrap()
        },
        "checksum mismatch",
    );
}

#[test]
fn a_corrupt_checksum_is_ignored() {
    spoiled(
        |p, mut b| {
            let i = header_len() - 1;
            b[i] ^= 0x80;
            fs::write(p, b).unwrap()
        },
        "checksum mismatch",
    );
}

#[test]
fn truncated_entries_are_ignored() {
    spoiled(|p, b| fs::write(p, &b[..b.len() - 1]).unwrap(), "truncated");
    spoiled(|p, b| fs::write(p, &b[..header_len()]).unwrap(), "truncated");
    spoiled(|p, b| fs::write(p, &b[..header_len() - 1]).unwrap(), "truncated");
    spoiled(|p, b| fs::write(p, &b[..5]).unwrap(), "truncated");
    spoiled(|p, _| fs::write(p, b"").unwrap(), "truncated");
}

#[test]
fn padded_entries_are_ignored() {
    spoiled(
        |p, mut b| {
            b.push(b' ');
            fs::write(p, b).unwrap()
        },
        "padded",
    );
}

#[test]
fn foreign_entries_are_ignored() {
    spoiled(
        |p, mut b| {
            b[0] = b'X';
            fs::write(p, b).unwrap()
        },
        "bad magic",
    );
    spoiled(|p, _| fs::write(p, b"{\"verdict\": \"clash\"}").unwrap(), "bad magic");
    spoiled(
        |p, mut b| {
            b[8..12].copy_from_slice(&(FORMAT + 1).to_le_bytes());
            fs::write(p, b).unwrap()
        },
        "entry layout",
    );
    // Another version's entry (whole and with a valid checksum) at this key's path.
    spoiled(
        |p, _| fs::write(p, entry::encode(&key(1), "9.9.9-other", br#"{"x":1}"#)).unwrap(),
        "written by meshclash 9.9.9-other",
    );
    // A whole, valid entry of another key.
    spoiled(
        |p, _| {
            let other = serde_json::to_vec(&outcome(1)).unwrap();
            fs::write(p, entry::encode(&key(2), TOOL_VERSION, &other)).unwrap()
        },
        "another key",
    );
}

#[test]
fn a_hostile_declared_length_allocates_nothing() {
    spoiled(
        |p, mut b| {
            let at = header_len() - 40;
            b[at..at + 8].copy_from_slice(&u64::MAX.to_le_bytes());
            fs::write(p, b).unwrap()
        },
        &format!("declares {} payload bytes", u64::MAX),
    );
}

#[test]
fn an_entry_of_another_type_is_ignored() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    s.put(&key(1), &outcome(1));
    assert_eq!(s.get::<Vec<u64>>(&key(1)), None);
    one_warning(&s, "payload does not decode");
}

#[test]
fn entries_over_the_limit_are_not_read() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    s.put(&key(1), &outcome(1));
    let small = Store::open(d.path(), 64).unwrap();
    assert_eq!(small.get::<Outcome>(&key(1)), None);
    one_warning(&small, "over the 64-byte limit");
    // And not written: one warning for the run, however many results.
    small.put(&key(2), &outcome(2));
    small.put(&key(3), &outcome(3));
    one_warning(&small, "not stored");
    assert_eq!(small.stats().stored, 0);
}

#[test]
fn symlinks_fifos_and_directories_at_an_entry_path_are_not_read() {
    let d = tempfile::tempdir().unwrap();
    let target = d.path().join("elsewhere");
    spoiled(
        |p, b| {
            fs::write(&target, b).unwrap();
            fs::remove_file(p).unwrap();
            std::os::unix::fs::symlink(&target, p).unwrap();
        },
        "not a regular file",
    );
    assert!(target.exists(), "only the link is removed");
    spoiled(
        |p, _| {
            fs::remove_file(p).unwrap();
            rustix::fs::mknodat(
                rustix::fs::CWD,
                p,
                rustix::fs::FileType::Fifo,
                rustix::fs::Mode::from_raw_mode(0o600),
                0,
            )
            .unwrap();
        },
        "not a regular file",
    );
    spoiled(
        |p, _| {
            fs::remove_file(p).unwrap();
            fs::create_dir(p).unwrap();
        },
        "not a regular file",
    );
}

#[test]
fn a_directory_at_the_entry_path_turns_storing_off_with_one_warning() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    fs::create_dir_all(s.entry_path(&key(1))).unwrap();
    s.put(&key(1), &outcome(1));
    one_warning(&s, "storing turned off");
    s.put(&key(2), &outcome(2));
    assert!(s.take_warnings().is_empty());
    assert_eq!(s.stats().stored, 0);
    assert_eq!(s.get::<Outcome>(&key(2)), None);
}

#[test]
fn a_symlinked_fanout_directory_is_not_written_through() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    let elsewhere = tempfile::tempdir().unwrap();
    let fanout = s.entry_path(&key(1)).parent().unwrap().to_path_buf();
    std::os::unix::fs::symlink(elsewhere.path(), &fanout).unwrap();
    s.put(&key(1), &outcome(1));
    one_warning(&s, "not a directory");
    assert_eq!(fs::read_dir(elsewhere.path()).unwrap().count(), 0);
}

fn open_err(dir: &Path) -> String {
    let e = Store::open(dir, DEFAULT_MAX_BYTES).unwrap_err();
    assert_eq!(e.exit_code(), crate::error::ExitCode::Error);
    let m = e.to_string();
    assert!(!m.contains('\n'), "{m}");
    assert!(m.contains("--cache"), "{m}");
    assert!(m.contains(&dir.display().to_string()), "{m}");
    m
}

#[test]
fn open_refuses_what_is_not_a_cache_directory() {
    let d = tempfile::tempdir().unwrap();
    let file = d.path().join("file");
    fs::write(&file, "x").unwrap();
    assert!(open_err(&file).contains("is not a directory"));
    let to_file = d.path().join("to-file");
    std::os::unix::fs::symlink(&file, &to_file).unwrap();
    assert!(open_err(&to_file).contains("symbolic link to something other than a directory"));
    let dangling = d.path().join("dangling");
    std::os::unix::fs::symlink(d.path().join("missing"), &dangling).unwrap();
    assert!(open_err(&dangling).contains("cannot be followed"));
    let under_file = file.join("sub");
    assert!(open_err(&under_file).contains("cannot"));
    // A directory of someone's files: never filled, never evicted from.
    let project = d.path().join("project");
    fs::create_dir(&project).unwrap();
    fs::write(project.join("notes.txt"), "mine").unwrap();
    assert!(open_err(&project).contains("not empty and not a meshclash cache"));
    assert!(!project.join("CACHEDIR.TAG").exists());
    // Another program's cache.
    let other = d.path().join("other");
    fs::create_dir(&other).unwrap();
    fs::write(other.join("CACHEDIR.TAG"), "Signature: 8a477f597d28d172789f06886806bc55\n# cargo\n").unwrap();
    assert!(open_err(&other).contains("another program's CACHEDIR.TAG"));
    // A tag that is a FIFO or a link is not read (no hang, no following).
    let fifo = d.path().join("fifo");
    fs::create_dir(&fifo).unwrap();
    let mode = rustix::fs::Mode::from_raw_mode(0o600);
    rustix::fs::mknodat(rustix::fs::CWD, fifo.join("CACHEDIR.TAG"), rustix::fs::FileType::Fifo, mode, 0)
        .unwrap();
    assert!(open_err(&fifo).contains("CACHEDIR.TAG: not a regular file"));
    let linked = d.path().join("linked");
    fs::create_dir(&linked).unwrap();
    std::os::unix::fs::symlink(other.join("CACHEDIR.TAG"), linked.join("CACHEDIR.TAG")).unwrap();
    assert!(open_err(&linked).contains("CACHEDIR.TAG: not a regular file"));
}

#[test]
fn open_refuses_an_unwritable_directory() {
    let d = tempfile::tempdir().unwrap();
    let ro = d.path().join("ro");
    Store::open(&ro, DEFAULT_MAX_BYTES).unwrap();
    use std::os::unix::fs::PermissionsExt;
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o555)).unwrap();
    if fs::write(ro.join("probe"), "").is_ok() {
        println!("skipped: running with privileges that ignore directory permissions");
        return;
    }
    assert!(open_err(&ro).contains("is not writable"));
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o755)).unwrap();
}

#[test]
fn open_creates_nested_directories_and_follows_a_link_to_a_directory() {
    let d = tempfile::tempdir().unwrap();
    let nested = d.path().join("a/b/c");
    let s = store(&nested);
    s.put(&key(1), &outcome(1));
    let link = d.path().join("link");
    std::os::unix::fs::symlink(&nested, &link).unwrap();
    assert_eq!(store(&link).get::<Outcome>(&key(1)), Some(outcome(1)));
}

/// Put `n` entries of equal size, then age them: entry `i` last used `n - i` hours ago.
fn aged(s: &Store, n: u32) {
    for i in 0..n {
        s.put(&key(i), &outcome(1));
    }
    for i in 0..n {
        let t = SystemTime::now() - Duration::from_secs(3600 * u64::from(n - i));
        fs::File::options().write(true).open(s.entry_path(&key(i))).unwrap().set_modified(t).unwrap();
    }
}

#[test]
fn eviction_removes_the_least_recently_used_down_to_the_low_water_mark() {
    let d = tempfile::tempdir().unwrap();
    let probe = store(d.path());
    probe.put(&key(99), &outcome(1));
    let one = fs::metadata(probe.entry_path(&key(99))).unwrap().len();
    fs::remove_file(probe.entry_path(&key(99))).unwrap();
    // Room for exactly 5 entries; the low-water mark (7/8) leaves 4.
    let s = Store::open(d.path(), 5 * one).unwrap();
    aged(&s, 5);
    assert_eq!(s.stats().evicted, 0);
    // Entry 0 is the oldest, but a hit makes it the most recently used.
    assert!(s.get::<Outcome>(&key(0)).is_some());
    s.put(&key(5), &outcome(1));
    let present: Vec<u32> = (0..6).filter(|&i| s.entry_path(&key(i)).exists()).collect();
    assert_eq!(present, vec![0, 3, 4, 5]);
    assert_eq!(s.stats().evicted, 2);
    // Files that are not entries are never evicted.
    let fan = s.entry_path(&key(3)).parent().unwrap().join("README");
    fs::write(&fan, vec![b'x'; 10 * one as usize]).unwrap();
    s.put(&key(6), &outcome(1));
    assert!(fan.exists());
    assert!(d.path().join("CACHEDIR.TAG").exists());
    assert!(s.take_warnings().is_empty());
}

#[test]
fn eviction_removes_stale_temporaries_only() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    let fan = d.path().join("ab");
    fs::create_dir(&fan).unwrap();
    let stale = fan.join(".tmp-stale");
    let fresh = fan.join(".tmp-fresh");
    fs::write(&stale, "x").unwrap();
    fs::write(&fresh, "x").unwrap();
    let old = SystemTime::now() - Duration::from_secs(3 * 24 * 3600);
    fs::File::options().write(true).open(&stale).unwrap().set_modified(old).unwrap();
    // The first put scans the directory.
    s.put(&key(1), &outcome(1));
    assert!(!stale.exists());
    assert!(fresh.exists());
}

#[test]
fn threads_sharing_a_store_see_whole_entries() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    let values = [outcome(1), outcome(40), outcome(200)];
    std::thread::scope(|scope| {
        for t in 0..6 {
            let (s, values) = (&s, &values);
            scope.spawn(move || {
                for round in 0..50 {
                    s.put(&key(round % 5), &values[(t + round as usize) % 3]);
                    if let Some(v) = s.get::<Outcome>(&key((round + 1) % 5)) {
                        assert!(values.contains(&v));
                    }
                }
            });
        }
    });
    assert!(s.take_warnings().is_empty());
    assert_eq!(s.stats().ignored, 0);
    assert_eq!(s.stats().stored, 300);
    for i in 0..5 {
        assert!(values.contains(&s.get::<Outcome>(&key(i)).unwrap()));
    }
}

const CHILD_DIR: &str = "MESHCLASH_CACHE_TEST_CHILD_DIR";

/// Run by `processes_sharing_a_directory` in child processes; does nothing otherwise.
#[test]
#[ignore = "a child of processes_sharing_a_directory"]
fn child_writer() {
    let Some(dir) = std::env::var_os(CHILD_DIR) else { return };
    let s = store(Path::new(&dir));
    for round in 0..200 {
        s.put(&key(round % 4), &outcome(round % 4 * 50));
        if let Some(v) = s.get::<Outcome>(&key((round + 1) % 4)) {
            assert_eq!(v, outcome((round + 1) % 4 * 50));
        }
    }
    assert!(s.take_warnings().is_empty());
}

#[test]
fn processes_sharing_a_directory_see_whole_entries() {
    let d = tempfile::tempdir().unwrap();
    let _ = store(d.path());
    let exe = std::env::current_exe().unwrap();
    let children: Vec<_> = (0..2)
        .map(|_| {
            std::process::Command::new(&exe)
                .args(["cache::tests::child_writer", "--exact", "--ignored", "--test-threads=1"])
                .env(CHILD_DIR, d.path())
                .stdout(std::process::Stdio::piped())
                .stderr(std::process::Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let s = store(d.path());
    let mut children = children;
    // Read while the children write: every hit is a whole entry of the right value.
    while children.iter_mut().any(|c| c.try_wait().unwrap().is_none()) {
        for i in 0..4 {
            if let Some(v) = s.get::<Outcome>(&key(i)) {
                assert_eq!(v, outcome(i * 50));
            }
        }
    }
    for c in children {
        let out = c.wait_with_output().unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(out.status.success(), "{text}{}", String::from_utf8_lossy(&out.stderr));
        assert!(text.contains("1 passed"), "the child ran: {text}");
    }
    assert!(s.take_warnings().is_empty());
    for i in 0..4 {
        assert_eq!(s.get::<Outcome>(&key(i)), Some(outcome(i * 50)));
    }
}

#[test]
fn take_warnings_empties() {
    let d = tempfile::tempdir().unwrap();
    let s = store(d.path());
    s.put(&key(1), &f64::NAN);
    assert_eq!(s.take_warnings().len(), 1);
    assert!(s.take_warnings().is_empty());
}

#[test]
fn decode_checks_what_check_header_checks_and_the_sum() {
    let payload = br#"{"a":1}"#;
    let bytes = entry::encode(&key(1), "1.2.3", payload);
    assert_eq!(&bytes[..8], MAGIC);
    assert_eq!(bytes.len(), entry::header_len(5) + payload.len());
    assert_eq!(entry::decode(&bytes, &key(1), "1.2.3"), Ok(&payload[..]));
    assert_eq!(entry::decode(&bytes, &key(2), "1.2.3"), Err(Rejected::Key));
    assert!(matches!(entry::decode(&bytes, &key(1), "1.2.4"), Err(Rejected::Version { .. })));
    // Every strict prefix is refused.
    for n in 0..bytes.len() {
        assert!(entry::decode(&bytes[..n], &key(1), "1.2.3").is_err(), "prefix {n}");
    }
    // Every single-bit flip is refused.
    for i in 0..bytes.len() {
        for bit in 0..8 {
            let mut b = bytes.clone();
            b[i] ^= 1 << bit;
            assert!(entry::decode(&b, &key(1), "1.2.3").is_err(), "byte {i} bit {bit}");
        }
    }
}

fn one_triangle(name: &str) -> Mesh {
    Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
        triangles: vec![[0, 1, 2]],
        tri_object: vec![0],
        objects: vec![crate::scene::mesh::Object { name: name.into(), ..Default::default() }],
    }
}

// Computed independently with Python's hashlib over the layout of `PartKey::of_mesh`.
#[test]
fn mesh_key_test_vector() {
    assert_eq!(
        PartKey::of_mesh(&one_triangle("p")).hex(),
        "10f294393e6a77142d2a7a46d7f005fd8722d5c1c380ef61f19b70a7cccbbf10"
    );
}

#[test]
fn mesh_key_sees_numbering_sharing_and_objects() {
    let base = one_triangle("p");
    let k = PartKey::of_mesh(&base);
    // The same triangle, its corners numbered from another vertex.
    let rotated = Mesh { triangles: vec![[1, 2, 0]], ..base.clone() };
    assert_ne!(PartKey::of_mesh(&rotated), k);
    // The same coordinates, one vertex duplicated instead of shared.
    let unshared = Mesh {
        positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::ZERO],
        triangles: vec![[3, 1, 2]],
        ..base.clone()
    };
    assert_ne!(PartKey::of_mesh(&unshared), k);
    assert_ne!(PartKey::of_mesh(&one_triangle("q")), k);
    let mut instanced = base.clone();
    instanced.objects[0].gltf_mesh = Some(0);
    assert_ne!(PartKey::of_mesh(&instanced), k);
    let mut placed = base.clone();
    placed.objects[0].world = Some(glam::DMat4::IDENTITY);
    assert_ne!(PartKey::of_mesh(&placed), k);
    assert_eq!(PartKey::of_mesh(&base.clone()), k);
}

#[test]
fn check_fingerprint_changes_with_every_setting() {
    use crate::check::assembly::Selection;
    use crate::check::query::{Detail, Mode, Settings};
    let s = Settings::default();
    let sel = Selection::default();
    let fp =
        |s: &Settings, sel: &Selection, split: bool, pen: bool| hook::check_fingerprint(s, sel, split, pen);
    let base = fp(&s, &sel, false, false);
    assert_eq!(fp(&s, &sel, false, false), base);
    let mut variants = Vec::new();
    let mut t = s;
    t.tolerances.touch = 1e-9;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.tolerances.clearance = 1.0;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.tolerances.touch = -0.0;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.mode = Mode::Fast;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.first_hit = true;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.detail = Detail::Parts;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.bvh.leaf_size += 1;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.bvh.strategy = crate::bvh::Strategy::Median;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.distance_error.rel = 0.1;
    variants.push(fp(&t, &sel, false, false));
    let mut t = s;
    t.distance_error.abs = 0.1;
    variants.push(fp(&t, &sel, false, false));
    variants.push(fp(&s, &sel, true, false));
    variants.push(fp(&s, &sel, false, true));
    let with = |f: fn(&mut Selection)| {
        let mut x = Selection::default();
        f(&mut x);
        fp(&s, &x, false, false)
    };
    variants.push(with(|x| x.scene = true));
    variants.push(with(|x| x.select_a = vec!["a*".into()]));
    variants.push(with(|x| x.select_b = vec!["a*".into()]));
    variants.push(with(|x| x.exclude = vec!["a*".into()]));
    // Globs are length-prefixed: ["a,b"] and ["a", "b"] differ.
    variants.push(with(|x| x.exclude = vec!["a,b".into()]));
    variants.push(with(|x| x.exclude = vec!["a".into(), "b".into()]));
    let mut all = variants.clone();
    all.push(base);
    let distinct: std::collections::HashSet<_> = all.iter().map(|f| f.hex()).collect();
    assert_eq!(distinct.len(), all.len());
}

/// Closed cubes (OBJ, one `o` group each) of edge 1 at `mins`.
fn cubes_obj(mins: &[[f64; 3]]) -> String {
    let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut out = String::new();
    for (k, m) in mins.iter().enumerate() {
        out += &format!("o c{k}\n");
        for i in 0..8 {
            let [x, y, z] = [i & 1, (i >> 1) & 1, (i >> 2) & 1].map(f64::from);
            out += &format!("v {} {} {}\n", m[0] + x, m[1] + y, m[2] + z);
        }
        for f in faces {
            let v = f.map(|i| i + 8 * k + 1);
            out += &format!("f {} {} {}\nf {} {} {}\n", v[0], v[1], v[2], v[0], v[2], v[3]);
        }
    }
    out
}

/// Every pack in the cache at `dir`: (its key, its payload decoded).
fn packs_in(dir: &Path) -> Vec<(PairKey, pack::Pack)> {
    let mut out = Vec::new();
    for fan in fs::read_dir(dir).unwrap().flatten().filter(|e| e.path().is_dir()) {
        for e in fs::read_dir(fan.path()).unwrap().flatten() {
            let hex = format!("{}{}", fan.file_name().to_string_lossy(), e.file_name().to_string_lossy());
            if hex.len() != 64 {
                continue;
            }
            let mut d = [0u8; 32];
            for (i, b) in d.iter_mut().enumerate() {
                *b = u8::from_str_radix(&hex[2 * i..2 * i + 2], 16).unwrap();
            }
            let key = PairKey::from_digest(d);
            let bytes = fs::read(e.path()).unwrap();
            let payload = entry::decode(&bytes, &key, TOOL_VERSION).unwrap();
            if let Ok(p) = pack::decode_pack(payload) {
                out.push((key, p));
            }
        }
    }
    out
}

/// A scene request for a chain of overlapping cubes written into `dir`: each pair of neighbours
/// crosses in several triangle pairs and has an overlap box; one more cube lies apart.
fn chain_of_cubes(dir: &Path) -> crate::pipeline::Request {
    let path = dir.join("cubes.obj");
    let mins = [[0.0, 0.0, 0.0], [0.5, 0.25, 0.0], [1.25, 0.5, 0.125], [1.75, 0.75, 0.5], [9.0, 0.0, 0.0]];
    fs::write(&path, cubes_obj(&mins)).unwrap();
    let mut req = crate::pipeline::Request::scene(&path);
    req.deterministic = true;
    req
}

#[test]
fn overlap_boxes_are_reused_and_a_wrong_stored_box_is_recomputed() {
    use crate::pipeline::run;
    let d = tempfile::tempdir().unwrap();
    let mut req = chain_of_cubes(d.path());
    let bits = |o: &crate::pipeline::Outcome| format!("{:?}", o.overlaps);
    let cold = run(&req, &|_| {}).unwrap();
    let boxes = cold.overlaps.iter().flatten().count();
    assert_eq!(boxes, 3, "each neighbour pair has a box: {:?}", cold.overlaps);
    let n = cold.assembly.info.candidate_part_pairs as u64;
    let cache = d.path().join("c");
    req.cache = Some(CacheConfig { dir: cache.clone(), max_bytes: DEFAULT_MAX_BYTES });
    let counts = |o: &crate::pipeline::Outcome| {
        let c = o.cache.as_ref().unwrap();
        (c.part_pairs_reused, c.part_pairs_checked)
    };
    let first = run(&req, &|_| {}).unwrap();
    assert_eq!((bits(&first), counts(&first)), (bits(&cold), (0, n)));
    // Every clashing pair is stored with its box.
    let stored: Vec<Option<Option<crate::check::overlap::Overlap>>> =
        packs_in(&cache).into_iter().flat_map(|(_, p)| p.pairs).map(|(_, s)| s.overlap).collect();
    assert_eq!(stored.iter().filter(|o| matches!(o, Some(Some(_)))).count(), boxes, "{stored:?}");
    let warm = run(&req, &|_| {}).unwrap();
    assert_eq!((bits(&warm), counts(&warm)), (bits(&cold), (n, 0)));
    assert!(warm.cache_warnings.is_empty(), "{:?}", warm.cache_warnings);
    // A stored box moved off its parts (the entry resealed, so its checksum holds): the pair is
    // not reused, it is checked again and its box recomputed.
    let s = store(&cache);
    for (key, mut p) in packs_in(&cache) {
        for (_, st) in &mut p.pairs {
            if let Some(Some(o)) = &mut st.overlap {
                o.min.x += 100.0;
                o.max.x += 100.0;
            }
        }
        s.put_bytes(&key, &pack::encode_pack(&p.pairs, &p.trees));
    }
    let spoiled = run(&req, &|_| {}).unwrap();
    assert_eq!((bits(&spoiled), counts(&spoiled)), (bits(&cold), (n - boxes as u64, boxes as u64)));
    assert_eq!(spoiled.cache_warnings.len(), boxes, "{:?}", spoiled.cache_warnings);
    assert!(spoiled.cache_warnings.iter().all(|w| w.contains("overlap box")), "{:?}", spoiled.cache_warnings);
    // The recomputed boxes were stored again: the next run reuses everything.
    let again = run(&req, &|_| {}).unwrap();
    assert_eq!((bits(&again), counts(&again)), (bits(&cold), (n, 0)));
    assert!(again.cache_warnings.is_empty(), "{:?}", again.cache_warnings);
}

#[test]
fn finding_ids_are_stored_reused_and_a_wrong_list_is_recomputed() {
    use crate::check::finding_id::finding_hash;
    use crate::pipeline::{report, run, Request};
    let d = tempfile::tempdir().unwrap();
    let mut req = chain_of_cubes(d.path());
    // A short list, so the report records the other ids under `unlisted`.
    req.max_pairs = 5;
    let json = |o: &crate::pipeline::Outcome| {
        let mut r = report::build(o);
        r.cache = None;
        crate::report::to_json(&r)
    };
    let in_pool = |threads: usize, req: &Request| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| run(req, &|_| {}).unwrap())
    };
    let plain = in_pool(2, &req);
    assert!(plain.assembly.result.pairs.len() > 10 && plain.unlisted.is_some());
    let want = json(&plain);
    let cache = d.path().join("c");
    req.cache = Some(CacheConfig { dir: cache.clone(), max_bytes: DEFAULT_MAX_BYTES });
    let cold = in_pool(2, &req);
    assert_eq!(json(&cold), want);
    // Every stored triangle pair carries its id: the hash of its two triangles in the mesh.
    let mesh = &cold.inputs[0].input.mesh;
    let parts = &cold.assembly.parts;
    let mut stored = 0;
    for (_, p) in packs_in(&cache) {
        for (_, s) in &p.pairs {
            let ids = s.ids.as_ref().expect("ids stored");
            assert_eq!(ids.len(), s.result.pairs.len());
            stored += ids.len();
            // The pair's two parts: the ones whose numbering maps every pair to a finding.
            let found = cold.assembly.part_pairs.iter().any(|pp| {
                let (pa, pb) = (&parts[pp.a], &parts[pp.b]);
                s.result.pairs.iter().zip(ids).all(|(q, &id)| {
                    let (ta, tb) = (pa.triangles[q.a as usize], pb.triangles[q.b as usize]);
                    finding_hash(mesh, ta, mesh, tb) == id
                })
            });
            assert!(found || ids.is_empty(), "stored ids are no part pair's hashes");
        }
    }
    assert_eq!(stored, cold.assembly.result.pairs.len());
    // Warm, with one thread and two: the stored ids give the same report.
    for threads in [1, 2] {
        let warm = in_pool(threads, &req);
        assert_eq!(warm.cache.as_ref().unwrap().part_pairs_checked, 0);
        assert!(warm.cache_warnings.is_empty(), "{:?}", warm.cache_warnings);
        assert_eq!(json(&warm), want, "{threads} threads");
    }
    // Stored ids that are not the pairs' (resealed, so the checksum holds) are refused with a
    // warning per list and computed again.
    let s = store(&cache);
    let mut lists = 0;
    for (key, mut p) in packs_in(&cache) {
        for (_, st) in &mut p.pairs {
            if let Some(ids) = st.ids.as_mut().filter(|i| !i.is_empty()) {
                ids.iter_mut().for_each(|x| *x ^= 1);
                lists += 1;
            }
        }
        s.put_bytes(&key, &pack::encode_pack(&p.pairs, &p.trees));
    }
    assert!(lists >= 3);
    let spoiled = in_pool(2, &req);
    assert_eq!(json(&spoiled), want);
    assert_eq!(spoiled.cache_warnings.len(), lists, "{:?}", spoiled.cache_warnings);
    assert!(spoiled.cache_warnings.iter().all(|w| w.contains("finding ids")), "{:?}", spoiled.cache_warnings);
    // A pack whose ids flag is neither 0 nor 1 does not decode: refused whole, its pairs checked.
    let (key, p) =
        packs_in(&cache).into_iter().find(|(_, p)| p.pairs.iter().any(|(_, s)| s.ids.is_some())).unwrap();
    let mut bytes = pack::encode_pack(&p.pairs, &p.trees);
    let mut none = p.clone();
    none.pairs.iter_mut().for_each(|(_, s)| s.ids = None);
    // The first byte where the layouts with and without ids part is the first ids flag.
    let other = pack::encode_pack(&none.pairs, &none.trees);
    let at = bytes.iter().zip(&other).position(|(x, y)| x != y).unwrap();
    assert_eq!((bytes[at], other[at]), (1, 0));
    bytes[at] = 7;
    assert!(pack::decode_pack(&bytes).unwrap_err().contains("ids flag"));
    s.put_bytes(&key, &bytes);
    let refused = in_pool(2, &req);
    assert_eq!(json(&refused), want);
    assert!(refused.cache.as_ref().unwrap().part_pairs_checked > 0);
}

// Computed independently with Python's hashlib over the layout of `PartKey::of_part_layout`:
// a part whose vertices sit after another vertex of the file, numbered from 0 by first use.
#[test]
fn part_layout_key_test_vector() {
    let mesh = Mesh {
        positions: vec![DVec3::splat(9.0), DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
        triangles: vec![[1, 2, 3], [2, 4, 3]],
        tri_object: vec![0, 0],
        objects: vec![crate::scene::mesh::Object { name: "p".into(), ..Default::default() }],
    };
    assert_eq!(
        PartKey::of_part_layout("p", &mesh, &[0, 1]).hex(),
        "8961bfddf00d3a01a1b09f771cb6c01509d77f2ec646b2fe9aa273e9ba214529"
    );
}

/// Four instances of one glTF mesh (two triangles over four vertices each, one after another
/// in the file): the third with one vertex nudged, the fourth with its triangles' corners in
/// another order (it does not read like the others), the fifth a part of its own.
fn instances() -> Mesh {
    use crate::scene::mesh::Object;
    let quad = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let mut tri_object = Vec::new();
    let mut objects = Vec::new();
    for k in 0..5u32 {
        let base = positions.len() as u32;
        let offset = DVec3::new(f64::from(k) * 2.0, 0.0, 0.0);
        positions.extend(quad.iter().map(|&p| p + offset));
        if k == 2 {
            positions[base as usize + 3].z = 1e-300;
        }
        let t = if k == 3 { [[1, 3, 2], [0, 1, 2]] } else { [[0, 1, 2], [1, 3, 2]] };
        triangles.extend(t.map(|c| c.map(|i| i + base)));
        tri_object.extend([k, k]);
        let gltf_mesh = (k < 4).then_some(0);
        objects.push(Object { name: format!("i{k}"), gltf_mesh, ..Default::default() });
    }
    Mesh { positions, triangles, tri_object, objects }
}

#[test]
fn part_layout_keys_of_instances_are_each_parts_own() {
    let mesh = instances();
    let parts = crate::check::assembly::parts_of(&mesh, 0);
    let refs: Vec<&crate::check::assembly::Part> = parts.iter().collect();
    let keys = PartKey::of_part_layouts([&mesh, &mesh], &refs);
    let one_by_one: Vec<PartKey> =
        parts.iter().map(|p| PartKey::of_part_layout(&p.name, &mesh, &p.triangles)).collect();
    assert_eq!(keys, one_by_one);
    // Any order of the parts: the same key for each.
    let reversed: Vec<&crate::check::assembly::Part> = parts.iter().rev().collect();
    let mut back = PartKey::of_part_layouts([&mesh, &mesh], &reversed);
    back.reverse();
    assert_eq!(back, keys);
    let distinct: std::collections::HashSet<PartKey> = keys.iter().copied().collect();
    assert_eq!(distinct.len(), keys.len());
    // The same part under another name, moved, or with its corners in another order: a new key.
    let p = &parts[0];
    let k = PartKey::of_part_layout(&p.name, &mesh, &p.triangles);
    assert_ne!(PartKey::of_part_layout("other", &mesh, &p.triangles), k);
    let mut moved = mesh.clone();
    moved.positions[0].x = -0.0;
    assert_ne!(PartKey::of_part_layout(&p.name, &moved, &p.triangles), k);
    // An instance at the other end of the file, the same coordinates and sharing: the same key.
    let mut copy = mesh.clone();
    let base = copy.positions.len() as u32;
    copy.positions.extend(mesh.positions[..4].iter().copied());
    copy.triangles.extend([[0, 1, 2], [1, 3, 2]].map(|c| c.map(|i| i + base)));
    let at = copy.triangles.len() as u32;
    assert_eq!(PartKey::of_part_layout(&p.name, &copy, &[at - 2, at - 1]), k);
}

/// The part keys of an instanced scene's parts, placed one by one, against the keys of the
/// same parts of the scene's expanded mesh.
fn placed_keys_match_expanded(path: &Path) {
    let bytes = fs::read(path).expect("read the scene");
    let scene = crate::load::load_gltf_instanced(path, &bytes).expect("load instanced");
    let expanded = scene.expand().expect("expand").mesh;
    let parts = crate::check::assembly::parts_of(&expanded, 0);
    assert_eq!(parts.len(), scene.parts.len(), "{}", path.display());
    let refs: Vec<&crate::check::assembly::Part> = parts.iter().collect();
    let placed = PartKey::of_placed_parts(&scene, &refs);
    let want = PartKey::of_part_layouts([&expanded, &expanded], &refs);
    assert_eq!(placed, want, "{}", path.display());
    let one_by_one: Vec<PartKey> =
        parts.iter().map(|p| PartKey::of_part_layout(&p.name, &expanded, &p.triangles)).collect();
    assert_eq!(placed, one_by_one, "{}", path.display());
    // Any subset, in any order: each part's own key.
    let some: Vec<&crate::check::assembly::Part> = parts.iter().rev().step_by(2).collect();
    let want_some: Vec<PartKey> = some.iter().map(|p| one_by_one[p.object as usize]).collect();
    assert_eq!(PartKey::of_placed_parts(&scene, &some), want_some, "{}", path.display());
}

#[test]
fn placed_part_keys_are_the_expanded_parts_keys() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    for name in ["Box.glb", "SimpleMeshes.gltf", "pins.glb", "simple_pole.glb"] {
        placed_keys_match_expanded(&dir.join("meshes").join(name));
    }
    // A scene of many instances of shared meshes, when the corpus is at hand.
    let engine = dir.join("../shared/meshes/2CylinderEngine.glb");
    if engine.is_file() {
        placed_keys_match_expanded(&engine);
    }
}

#[test]
fn placed_part_keys_change_with_the_placement() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes/SimpleMeshes.gltf");
    let bytes = fs::read(&path).expect("read the scene");
    let scene = crate::load::load_gltf_instanced(&path, &bytes).expect("load instanced");
    let expanded = scene.expand().expect("expand").mesh;
    let parts = crate::check::assembly::parts_of(&expanded, 0);
    let refs: Vec<&crate::check::assembly::Part> = parts.iter().collect();
    let keys = PartKey::of_placed_parts(&scene, &refs);
    // Two instances of one mesh at two places: two keys.
    let distinct: std::collections::HashSet<PartKey> = keys.iter().copied().collect();
    assert_eq!(distinct.len(), keys.len());
    let mut moved = scene.clone();
    moved.parts[0].world.w_axis.x += 0.5;
    let moved_keys = PartKey::of_placed_parts(&moved, &refs);
    assert_ne!(moved_keys[0], keys[0]);
    assert_eq!(moved_keys[1..], keys[1..]);
}
