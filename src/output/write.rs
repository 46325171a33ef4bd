//! The one place outputs reach the file system (issue 11, items 1-2).
//!
//! Rules, for every output (`-o`, `--junit`, `--export-glb`, and any added later):
//! - an existing path that is not a regular file (a device such as `/dev/null`, a FIFO, a
//!   socket) is written directly, never renamed over;
//! - a symlink is followed and its *target* is replaced atomically; the link stays a link;
//! - otherwise the bytes go to a temporary with an unpredictable name created with `O_EXCL`
//!   (the `tempfile` crate) in the target's directory, synced, then renamed over the target, so
//!   a planted symlink at a guessable temporary name is never followed.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` completely or not at all (regular files), or directly (devices,
/// FIFOs, sockets). Errors name `path`.
pub fn write_file(path: &Path, bytes: &[u8]) -> Result<()> {
    let err = |e: std::io::Error| Error::Output { path: path.to_path_buf(), msg: e.to_string() };
    let target = resolve(path).map_err(err)?;
    match std::fs::metadata(&target) {
        Ok(m) if !m.is_file() && !m.is_dir() => {
            let mut f = std::fs::OpenOptions::new().write(true).open(&target).map_err(err)?;
            return f.write_all(bytes).and_then(|_| f.flush()).map_err(err);
        }
        _ => {}
    }
    let dir = target.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir).map_err(err)?;
    tmp.write_all(bytes).and_then(|_| tmp.as_file().sync_all()).map_err(err)?;
    tmp.persist(&target).map_err(|e| err(e.error))?;
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
}
