//! Shared body of the fuzz targets: load the bytes with one loader and, when that succeeds,
//! check every guarantee `meshclash::load` documents. An `Err` must be one line naming the file.

use std::path::Path;

use meshclash::load::{detect_format, load_bytes, Format};

/// Runs the loader for `format` on `data` (as a file called `name`) and checks the result.
pub fn check(name: &str, data: &[u8], format: Format) {
    let path = Path::new(name);
    // Format detection sees the same bytes first, as in `load_path`; it must not panic either.
    let _ = detect_format(path, data);
    match load_bytes(path, data, format) {
        Ok(loaded) => {
            let m = &loaded.mesh;
            assert!(!m.triangles.is_empty(), "Ok with no triangles");
            assert_eq!(m.tri_object.len(), m.triangles.len(), "tri_object length");
            let n = m.positions.len();
            for t in &m.triangles {
                for &v in t {
                    assert!((v as usize) < n, "index {v} out of range ({n} vertices)");
                }
            }
            for p in &m.positions {
                assert!(p.is_finite(), "non-finite position {p:?}");
            }
            for &o in &m.tri_object {
                assert!((o as usize) < m.objects.len(), "object {o} out of range");
            }
            for o in &m.objects {
                assert!(!o.name.is_empty(), "object without a name");
            }
        }
        Err(e) => {
            let s = e.to_string();
            assert!(s.starts_with(&format!("{name}: ")), "error does not name the file: {s}");
            assert!(!s.contains('\n'), "error spans lines: {s}");
        }
    }
}
