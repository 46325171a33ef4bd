//! The one place outputs reach the file system.
//!
//! Rules, for every output (`-o`, `--junit`, `--export-glb`, and any added later):
//! - **checked before any work** ([`check_outputs`]): an output that is one of the inputs (the
//!   same file after following symlinks, or a hard link to it: same device and inode) or
//!   another output of the same run is refused; an output that is a directory, or whose
//!   directory is missing or not writable, is refused;
//! - **all or nothing** ([`Staged`]): every output of a run goes to its own temporary first, and
//!   the temporaries are renamed over their targets only once all of them were written; a run
//!   that fails leaves no output behind (its temporaries are deleted);
//! - an existing path that is not a regular file (a device such as `/dev/null`, a FIFO, a
//!   socket) is written directly, never renamed over (it cannot be staged: it is written when
//!   its content is ready, before the other outputs are committed);
//! - a path naming a file this process already holds open for writing (`/dev/stdout`,
//!   `/dev/stderr` or `/proc/self/fd/N` while that descriptor is redirected to a file) is
//!   written through that descriptor, at its offset and in its mode (appending under `>>`),
//!   never truncated and never renamed over: what the shell wrote there before stays;
//! - two outputs naming one file, existing or new, are refused;
//! - every file an input reads counts as an input ([`crate::load::files_read`]: a glTF's
//!   external buffers and images too);
//! - a symlink is followed and its *target* is replaced atomically; the link stays a link;
//! - temporaries get unpredictable names, created with `O_EXCL` (the `tempfile` crate) in the
//!   target's directory, are synced, then renamed, so a planted symlink at a guessable temporary
//!   name is never followed.
//!
//! Content is streamed into the temporary through a buffer ([`Staged::stage_with`]): a report
//! is never held whole in memory as text.

use crate::error::{Error, OutputProblem, Result};
use std::io::{BufWriter, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` completely or not at all (regular files), or directly (devices,
/// FIFOs, sockets). Errors name `path`. One output on its own: a run with several outputs
/// stages them all in one [`Staged`].
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let mut s = Staged::new();
    s.stage(path, bytes)?;
    s.commit()
}

/// An I/O error as an output problem.
fn io_problem(e: &std::io::Error) -> OutputProblem {
    OutputProblem::Io { kind: e.kind(), reason: e.to_string() }
}

fn out_err(path: &Path) -> impl Fn(std::io::Error) -> Error + '_ {
    move |e| Error::output(path, io_problem(&e))
}

/// Outputs written to temporaries, renamed over their targets by [`Staged::commit`]. Dropping
/// a `Staged` without committing deletes the temporaries: nothing is left behind.
#[derive(Debug, Default)]
pub struct Staged {
    pending: Vec<(PathBuf, tempfile::NamedTempFile)>,
}

/// The buffer an output is written through: large reports (hundreds of MB of pretty JSON)
/// are written in few system calls.
const OUT_BUFFER: usize = 1 << 20;

impl Staged {
    /// Nothing staged yet.
    pub fn new() -> Self {
        Staged::default()
    }

    /// Stage `bytes` for `path`.
    pub fn stage(&mut self, path: &Path, bytes: &[u8]) -> Result<()> {
        self.stage_with(path, |w| w.write_all(bytes))
    }

    /// Stage the bytes `fill` writes (through a buffer) for `path`. A path that is an existing
    /// device, FIFO or socket is written directly, now.
    pub fn stage_with(
        &mut self,
        path: &Path,
        fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
    ) -> Result<()> {
        let err = out_err(path);
        let target = match target(path).map_err(&err)? {
            Target::Directory => return Err(Error::output(path, OutputProblem::IsADirectory)),
            Target::Direct => {
                let f = std::fs::OpenOptions::new().write(true).truncate(true).open(path).map_err(&err)?;
                let mut w = BufWriter::with_capacity(OUT_BUFFER, f);
                return fill(&mut w).and_then(|_| w.flush()).map_err(&err);
            }
            Target::Descriptor(f) => {
                let mut w = BufWriter::with_capacity(OUT_BUFFER, f);
                return fill(&mut w).and_then(|_| w.flush()).map_err(&err);
            }
            Target::Replace(t) => t,
        };
        // Mode 0666 less the umask, as for any new file (tempfile's default is 0600).
        let mode = std::os::unix::fs::PermissionsExt::from_mode(0o666);
        let mut tmp =
            tempfile::Builder::new().permissions(mode).tempfile_in(dir_of(&target)).map_err(&err)?;
        {
            let mut w = BufWriter::with_capacity(OUT_BUFFER, tmp.as_file_mut());
            fill(&mut w).and_then(|_| w.flush()).map_err(&err)?;
        }
        tmp.as_file().sync_all().map_err(&err)?;
        self.pending.push((target, tmp));
        Ok(())
    }

    /// Rename every temporary over its target, in the order staged.
    pub fn commit(self) -> Result<()> {
        for (target, tmp) in self.pending {
            tmp.persist(&target).map_err(|e| out_err(&target)(e.error))?;
        }
        Ok(())
    }
}

/// How an output path is written.
enum Target {
    /// An existing directory: refused.
    Directory,
    /// Opened and written in place: an existing device, FIFO or socket (also through a
    /// symlink, e.g. `/dev/stdout` on a pipe), or a file reached through `/proc` or `/dev`
    /// (`/dev/stdout` redirected to a file: renaming over it would leave the shell's descriptor
    /// on the old file).
    Direct,
    /// A regular file this process holds open for writing: written through (a duplicate of)
    /// that descriptor, at its offset, without truncating.
    Descriptor(std::fs::File),
    /// Staged in a temporary and renamed over this path (the final target of any symlinks).
    Replace(PathBuf),
}

fn target(path: &Path) -> std::io::Result<Target> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => return Ok(Target::Directory),
        Ok(m) if !m.is_file() => return Ok(Target::Direct),
        Ok(m) => {
            if let Some(f) = open_for_writing(&m) {
                return Ok(Target::Descriptor(f));
            }
        }
        _ => {}
    }
    let t = resolve(path)?;
    if t.starts_with("/proc") || t.starts_with("/dev") {
        return Ok(Target::Direct);
    }
    Ok(Target::Replace(t))
}

/// A handle on the regular file `m` (same device and inode) that this process already holds
/// open for writing, written without truncating: a duplicate of standard output or standard
/// error (sharing its offset and mode), else a reopening, in append mode, of another such
/// descriptor (through `/proc/self/fd`). `None` when there is none, or when the descriptors
/// cannot be listed (then only the path rules apply).
fn open_for_writing(m: &std::fs::Metadata) -> Option<std::fs::File> {
    use rustix::fs::OFlags;
    use std::os::fd::AsFd;
    let writable = |flags: OFlags| flags.intersects(OFlags::WRONLY | OFlags::RDWR);
    let same = |dev: u64, ino: u64| dev == m.dev() && ino == m.ino();
    let (out, err) = (std::io::stdout(), std::io::stderr());
    for fd in [out.as_fd(), err.as_fd()] {
        let (Ok(st), Ok(flags)) = (rustix::fs::fstat(fd), rustix::fs::fcntl_getfl(fd)) else {
            continue;
        };
        if same(st.st_dev, st.st_ino) && writable(flags) {
            return fd.try_clone_to_owned().ok().map(std::fs::File::from);
        }
    }
    let mut fds: Vec<u32> = std::fs::read_dir("/proc/self/fd")
        .ok()?
        .filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|&n| n > 2)
        .collect();
    fds.sort_unstable();
    for n in fds {
        let link = PathBuf::from(format!("/proc/self/fd/{n}"));
        let Ok(st) = std::fs::metadata(&link) else { continue };
        // `flags:` in fdinfo is octal; the access mode is its two low bits (0 read-only).
        let flags = std::fs::read_to_string(format!("/proc/self/fdinfo/{n}")).ok().and_then(|t| {
            let v = t.lines().find_map(|l| l.strip_prefix("flags:"))?.trim().to_string();
            u32::from_str_radix(&v, 8).ok()
        });
        if same(st.dev(), st.ino()) && flags.is_some_and(|f| f & 3 != 0) {
            if let Ok(f) = std::fs::OpenOptions::new().append(true).open(&link) {
                return Some(f);
            }
        }
    }
    None
}

/// The directory a temporary for `target` goes in.
fn dir_of(target: &Path) -> &Path {
    target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// One output to check: the flag that names it (`-o`, `--junit`, …) and its path.
pub type Named<'a> = (&'a str, &'a Path);

/// Checks every output of a run before the run starts (the rules in the module doc). `inputs`
/// are the files the run reads (a missing one is skipped: loading it will report it).
pub fn check_outputs(outputs: &[Named], inputs: &[&Path]) -> Result<()> {
    let id = |m: &std::fs::Metadata| (m.dev(), m.ino());
    let read: Vec<PathBuf> = inputs.iter().flat_map(|p| crate::load::files_read(p)).collect();
    let inputs: Vec<((u64, u64), &Path)> =
        read.iter().filter_map(|p| std::fs::metadata(p).ok().map(|m| (id(&m), p.as_path()))).collect();
    let mut seen: Vec<((u64, u64), &str)> = Vec::new();
    // Outputs that do not exist yet, by their directory (resolved) and file name.
    let mut new: Vec<(PathBuf, &str)> = Vec::new();
    for &(flag, path) in outputs {
        let fail = |problem: OutputProblem| Error::output(path, problem);
        let flag_ = || flag.to_string();
        let (target, in_place) = match target(path).map_err(|e| fail(io_problem(&e)))? {
            Target::Directory => return Err(fail(OutputProblem::FlagNamesDirectory { flag: flag_() })),
            Target::Direct => (path.to_path_buf(), false),
            Target::Descriptor(_) => (path.to_path_buf(), true),
            Target::Replace(t) => (t, false),
        };
        match std::fs::metadata(&target) {
            Ok(m) => {
                if let Some((_, input)) = inputs.iter().find(|(i, _)| *i == id(&m)) {
                    return Err(fail(OutputProblem::NamesAnInput {
                        flag: flag_(),
                        input: input.to_path_buf(),
                    }));
                }
                if let Some((_, other)) = seen.iter().find(|(i, _)| *i == id(&m)) {
                    return Err(fail(OutputProblem::SameFile { flag: flag_(), other: other.to_string() }));
                }
                if !m.is_file() {
                    continue; // a device, FIFO or socket: written directly (and may repeat)
                }
                seen.push((id(&m), flag));
                if in_place || target.starts_with("/proc") || target.starts_with("/dev") {
                    continue; // written in place
                }
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                // Two names of one new file: the same file name in the same directory.
                let key = std::fs::canonicalize(dir_of(&target))
                    .map(|d| d.join(target.file_name().unwrap_or_default()));
                if let Ok(key) = key {
                    if let Some((_, other)) = new.iter().find(|(k, _)| *k == key) {
                        return Err(fail(OutputProblem::SameFile {
                            flag: flag_(),
                            other: other.to_string(),
                        }));
                    }
                    new.push((key, flag));
                }
            }
            Err(e) => return Err(fail(io_problem(&e))),
        }
        let dir = dir_of(&target);
        match std::fs::metadata(dir) {
            Ok(m) if m.is_dir() => {}
            Ok(_) => return Err(fail(OutputProblem::ParentNotADirectory { dir: dir.to_path_buf() })),
            Err(e) => {
                let problem = OutputProblem::Directory {
                    dir: dir.to_path_buf(),
                    kind: e.kind(),
                    reason: e.to_string(),
                };
                return Err(fail(problem));
            }
        }
        // Writable: the only honest test is to create (and at once delete) a temporary there.
        tempfile::NamedTempFile::new_in(dir).map_err(|e| {
            fail(OutputProblem::NotWritable { dir: dir.to_path_buf(), kind: e.kind(), reason: e.to_string() })
        })?;
    }
    Ok(())
}

/// The path to replace: `path` itself, or, when it is a symlink (possibly a chain), the final
/// target, which need not exist yet.
fn resolve(path: &Path) -> std::io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(d) if link.is_relative() => d.join(link),
                    _ => link,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(std::io::Error::other("too many levels of symbolic links"))
}

/// Writes what `fill` writes to the process's standard output (for the binary: the library
/// itself never prints), through a buffer, and reports how it went: `Ok(true)` written,
/// `Ok(false)` the reader went away (a broken pipe: quiet, as `head` expects), `Err` any other
/// failure (a full disk or `/dev/full`, a closed stdout).
///
/// A closed standard output (`>&-`) is detected: the Rust runtime reopens a closed descriptor 1
/// on `/dev/null` (read-write) at start-up, so every write would "succeed" and the report would
/// be lost with exit code 0. A shell's `>/dev/null` opens it write-only and stays allowed.
pub fn to_stdout(fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>) -> std::io::Result<bool> {
    use std::os::fd::AsFd;
    let stdout = std::io::stdout();
    let mut lock = stdout.lock();
    lock.flush()?;
    if stdout_was_closed(&lock) {
        return Err(std::io::Error::other("standard output is closed"));
    }
    let file = std::fs::File::from(lock.as_fd().try_clone_to_owned()?);
    let mut w = BufWriter::with_capacity(1 << 16, file);
    match fill(&mut w).and_then(|_| w.flush()) {
        Ok(()) => Ok(true),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(false),
        Err(e) => Err(e),
    }
}

/// Whether descriptor 1 is the `/dev/null` the runtime opened read-write for a closed stdout.
fn stdout_was_closed(fd: &impl std::os::fd::AsFd) -> bool {
    let Ok(flags) = rustix::fs::fcntl_getfl(fd) else {
        return true; // not even a descriptor
    };
    if !flags.contains(rustix::fs::OFlags::RDWR) {
        return false;
    }
    let (Ok(ours), Ok(null)) = (rustix::fs::fstat(fd), std::fs::metadata("/dev/null")) else {
        return false;
    };
    (rustix::fs::FileType::from_raw_mode(ours.st_mode) == rustix::fs::FileType::CharacterDevice)
        && ours.st_rdev == null.rdev()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::FileTypeExt;

    #[test]
    fn dev_null_stays_a_character_device() {
        // Before the fix, a temp file was renamed over /dev/null (as root).
        write_file(Path::new("/dev/null"), b"{}\n").unwrap();
        let m = std::fs::symlink_metadata("/dev/null").unwrap();
        assert!(m.file_type().is_char_device());
    }

    #[test]
    fn symlink_target_is_replaced_and_link_kept() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("real.json");
        std::fs::write(&target, b"old").unwrap();
        let link = d.path().join("link.json");
        std::os::unix::fs::symlink("real.json", &link).unwrap();
        write_file(&link, b"new").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
    }

    #[test]
    fn planted_symlink_at_old_temp_name_is_not_followed() {
        let d = tempfile::tempdir().unwrap();
        let victim = d.path().join("victim.txt");
        std::fs::write(&victim, b"keep").unwrap();
        let planted = d.path().join(format!(".r.json.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_file(&d.path().join("r.json"), b"report").unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"keep");
        assert_eq!(std::fs::read(d.path().join("r.json")).unwrap(), b"report");
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into()).collect();
        v.sort();
        v
    }

    #[test]
    fn staged_outputs_appear_only_on_commit_and_vanish_on_drop() {
        let d = tempfile::tempdir().unwrap();
        let (j, r) = (d.path().join("j.xml"), d.path().join("r.json"));
        let mut s = Staged::new();
        s.stage(&j, b"<x/>").unwrap();
        s.stage_with(&r, |w| w.write_all(b"{}")).unwrap();
        assert!(!j.exists() && !r.exists());
        s.commit().unwrap();
        assert_eq!(names(d.path()), ["j.xml", "r.json"]);
        let mut s = Staged::new();
        s.stage(&d.path().join("other.xml"), b"<x/>").unwrap();
        drop(s); // a run that failed after staging
        assert_eq!(names(d.path()), ["j.xml", "r.json"]);
    }

    #[test]
    fn a_failing_fill_leaves_nothing() {
        let d = tempfile::tempdir().unwrap();
        let r = d.path().join("r.json");
        let e = Staged::new().stage_with(&r, |_| Err(std::io::Error::other("boom"))).unwrap_err();
        assert!(e.to_string().contains("boom"), "{e}");
        assert!(names(d.path()).is_empty());
    }

    #[test]
    fn output_that_is_an_input_is_refused_through_symlink_and_hard_link() {
        let d = tempfile::tempdir().unwrap();
        let input = d.path().join("a.obj");
        std::fs::write(&input, b"v 0 0 0\n").unwrap();
        let link = d.path().join("link.json");
        std::os::unix::fs::symlink(&input, &link).unwrap();
        let hard = d.path().join("hard.json");
        std::fs::hard_link(&input, &hard).unwrap();
        let dotted = d.path().join(".").join("a.obj");
        for out in [&input, &link, &hard, &dotted] {
            let e = check_outputs(&[("-o", out)], &[&input]).unwrap_err().to_string();
            assert!(e.contains("names the input") && e.contains("a.obj"), "{}: {e}", out.display());
        }
        check_outputs(&[("-o", &d.path().join("r.json"))], &[&input]).unwrap();
    }

    #[test]
    fn two_outputs_naming_one_file_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let r = d.path().join("r.json");
        std::fs::write(&r, b"old").unwrap();
        let e = check_outputs(&[("-o", &r), ("--junit", &r)], &[]).unwrap_err().to_string();
        assert!(e.contains("--junit names the same file as -o"), "{e}");
    }

    #[test]
    fn two_outputs_naming_one_new_file_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let r = d.path().join("r.json");
        let dotted = d.path().join(".").join("r.json");
        let e = check_outputs(&[("-o", &r), ("--junit", &dotted)], &[]).unwrap_err().to_string();
        assert!(e.contains("--junit names the same file as -o"), "{e}");
        let link = d.path().join("link.json");
        std::os::unix::fs::symlink("r.json", &link).unwrap();
        let e = check_outputs(&[("--junit", &r), ("--bcf", &link)], &[]).unwrap_err().to_string();
        assert!(e.contains("--bcf names the same file as --junit"), "{e}");
        check_outputs(&[("-o", &r), ("--junit", &d.path().join("j.xml"))], &[]).unwrap();
    }

    #[test]
    fn output_naming_a_gltf_external_buffer_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let gltf = d.path().join("m.gltf");
        std::fs::write(&gltf, r#"{"buffers":[{"uri":"geo.bin","byteLength":4}],"images":[{"uri":"t.png"}]}"#)
            .unwrap();
        std::fs::write(d.path().join("geo.bin"), b"1234").unwrap();
        std::fs::write(d.path().join("t.png"), b"png").unwrap();
        for name in ["geo.bin", "t.png"] {
            let out = d.path().join(name);
            let e = check_outputs(&[("-o", &out)], &[&gltf]).unwrap_err().to_string();
            assert!(e.contains("names the input") && e.contains(name), "{e}");
        }
    }

    #[test]
    fn a_file_held_open_for_appending_is_appended_to_not_replaced() {
        // Standard error redirected to a file (the child's), written through `/dev/stderr`:
        // tested in the binary's tests; here a descriptor other than 0-2.
        let d = tempfile::tempdir().unwrap();
        let log = d.path().join("log");
        std::fs::write(&log, b"HEADER\n").unwrap();
        let held = std::fs::OpenOptions::new().append(true).open(&log).unwrap();
        let via = PathBuf::from(format!("/proc/self/fd/{}", std::os::fd::AsRawFd::as_raw_fd(&held)));
        check_outputs(&[("-o", &via)], &[]).unwrap();
        write_file(&via, b"report\n").unwrap();
        assert_eq!(std::fs::read(&log).unwrap(), b"HEADER\nreport\n");
        let ino = |p: &Path| std::fs::metadata(p).unwrap().ino();
        assert_eq!(ino(&log), held.metadata().unwrap().ino(), "the file was replaced");
    }

    #[test]
    fn dev_stdout_on_a_pipe_is_written_in_place() {
        // A symlink chain to a pipe (`/dev/stdout` -> `/proc/self/fd/1` -> `pipe:[N]`) must not
        // be resolved to a path to rename over.
        let d = tempfile::tempdir().unwrap();
        let fifo = d.path().join("f");
        assert!(std::process::Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let link = d.path().join("out.json");
        std::os::unix::fs::symlink(&fifo, &link).unwrap();
        check_outputs(&[("-o", &link)], &[]).unwrap();
        let reader = std::thread::spawn({
            let fifo = fifo.clone();
            move || std::fs::read(fifo).unwrap()
        });
        write_file(&link, b"through").unwrap();
        assert_eq!(reader.join().unwrap(), b"through");
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
    }

    #[test]
    fn missing_directory_and_directory_targets_are_refused() {
        let d = tempfile::tempdir().unwrap();
        let e = check_outputs(&[("-o", &d.path().join("missing/r.json"))], &[]).unwrap_err().to_string();
        assert!(e.contains("missing"), "{e}");
        let e = check_outputs(&[("--junit", d.path())], &[]).unwrap_err().to_string();
        assert!(e.contains("directory"), "{e}");
        check_outputs(&[("-o", Path::new("/dev/null"))], &[]).unwrap();
    }
}
