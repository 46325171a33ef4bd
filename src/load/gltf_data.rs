//! glTF binary plumbing for [`super::gltf`]: GLB framing, JSON parsing and validation, the
//! extension member the `gltf` crate does not expose (`EXT_mesh_gpu_instancing` on nodes,
//! read by a second, typed serde pass over the same JSON that skips everything else),
//! buffer resolution (GLB chunk, base64 `data:` URIs, external files) and bounds-checked
//! accessor reading (strided, sparse, quantized).
//!
//! Accessors are read here rather than with `gltf::mesh::Reader`, whose iterators silently
//! stop (or, for malformed sparse data, panic) on out-of-range views: every byte range is
//! checked first and reported as a one-line error. Nothing is allocated from a declared size
//! before the bytes backing it are known to exist.

use std::borrow::Cow;
use std::io::Read;
use std::path::Path;

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::{Accessor, Document};
use base64::Engine as _;

use super::io_message;
use crate::error::{Error, Result};

/// Required extensions a file may list and still load: those decoded here
/// (`KHR_mesh_quantization`, `EXT_mesh_gpu_instancing`) and those that only add appearance
/// or metadata, never geometry (`KHR_materials_*` is accepted by prefix as well).
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_mesh_quantization",
    "EXT_mesh_gpu_instancing",
    "KHR_texture_transform",
    "KHR_texture_basisu",
    "EXT_texture_webp",
    "EXT_texture_avif",
    "MSFT_texture_dds",
    "KHR_lights_punctual",
    "EXT_lights_image_based",
    "KHR_xmp_json_ld",
    "EXT_mesh_features",
    "EXT_instance_features",
    "EXT_structural_metadata",
    "CESIUM_primitive_outline",
];

/// Splits a GLB file into its JSON chunk and optional BIN chunk, checking every declared
/// length against the file first. Unknown chunks after those are ignored (as the spec says).
pub(crate) fn split_glb<'a>(path: &Path, bytes: &'a [u8]) -> Result<(&'a [u8], Option<&'a [u8]>)> {
    let err = |m: String| Error::input(path, m);
    let have = bytes.len();
    if have < 12 {
        return Err(err(format!("truncated GLB: {have} bytes, the header alone needs 12")));
    }
    if &bytes[..4] != b"glTF" {
        return Err(err("not a GLB file: missing 'glTF' magic".into()));
    }
    let version = le_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(err(format!("GLB version {version} is not supported (expected 2)")));
    }
    let declared = le_u32(bytes, 8).unwrap_or(0);
    if declared > have {
        return Err(err(format!(
            "truncated GLB: header declares {declared} bytes but the file has {have} bytes"
        )));
    }
    let data = &bytes[..declared];
    let mut pos = 12;
    let mut json = None;
    let mut bin = None;
    let mut index = 0;
    while pos < data.len() {
        let (Some(len), Some(kind)) = (le_u32(data, pos), data.get(pos + 4..pos + 8)) else {
            return Err(err(format!("truncated GLB: chunk {index} header at byte {pos} is cut off")));
        };
        let start = pos + 8;
        if len > data.len() - start {
            let what = super::clip(String::from_utf8_lossy(kind).trim_end_matches('\0'), 4);
            return Err(err(format!(
                "truncated GLB: chunk {index} ('{what}') declares {len} bytes but only {} remain",
                data.len() - start
            )));
        }
        let chunk = &data[start..start + len];
        match (index, kind) {
            (0, b"JSON") => json = Some(chunk),
            (0, _) => return Err(err("GLB first chunk is not JSON".into())),
            (1, b"BIN\0") => bin = Some(chunk),
            _ => {}
        }
        index += 1;
        pos = start + len;
    }
    let json = json.ok_or_else(|| err("GLB has no JSON chunk".into()))?;
    Ok((json, bin))
}

fn le_u32(b: &[u8], o: usize) -> Option<usize> {
    let b = b.get(o..o.checked_add(4)?)?;
    Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
}

/// Parses and validates the glTF JSON. Required extensions are checked here (named in the
/// error when they cannot be decoded). Application-specific vertex attributes (`_BATCHID`,
/// `_FEATURE_ID_0`, …), which this build of `gltf-json` would reject as invalid semantics,
/// are dropped before validation: only POSITION and the indices are read.
pub(crate) fn parse_document(path: &Path, json: &[u8]) -> Result<Document> {
    let json = strip_bom(json);
    let mut root = ::gltf::json::Root::from_slice(json)
        .map_err(|e| Error::input(path, format!("invalid glTF JSON: {e}")))?;
    for ext in &root.extensions_required {
        if !ext.starts_with("KHR_materials_") && !SUPPORTED_REQUIRED.contains(&ext.as_str()) {
            let hint = match ext.as_str() {
                "KHR_draco_mesh_compression" => " (Draco-compressed geometry cannot be decoded)",
                "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
                    " (meshopt-compressed buffers cannot be decoded)"
                }
                _ => "",
            };
            return Err(Error::input(
                path,
                format!("glTF requires extension '{ext}', which is not supported{hint}"),
            ));
        }
    }
    // Checked above; the gltf crate would reject any it does not itself implement.
    root.extensions_required.clear();
    for mesh in &mut root.meshes {
        for prim in &mut mesh.primitives {
            prim.attributes.retain(|k, _| matches!(k, ::gltf::json::validation::Checked::Valid(_)));
        }
    }
    // An accessor with neither bufferView nor sparse values has its data supplied by an
    // extension (core spec, § 3.6.2.4): a compressed file whose extension we cannot decode.
    if let Some(a) = root.accessors.iter().position(|a| a.buffer_view.is_none() && a.sparse.is_none()) {
        let by: Vec<&str> = root
            .extensions_used
            .iter()
            .map(String::as_str)
            .filter(|e| !e.starts_with("KHR_materials_") && !SUPPORTED_REQUIRED.contains(e))
            .collect();
        let by = if by.is_empty() { "none".to_string() } else { by.join(", ") };
        return Err(Error::input(
            path,
            format!(
                "glTF accessor {a} has no data (neither bufferView nor sparse values): it would \
                 come from an extension that is not supported (extensions used: {by})"
            ),
        ));
    }
    // gltf-json's validation indexes `accessors` with the POSITION index unchecked (a panic on a
    // dangling index), so check those references before validating.
    let positions = ::gltf::json::validation::Checked::Valid(::gltf::json::mesh::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim.attributes.get(&positions) {
                if a.value() >= root.accessors.len() {
                    return Err(Error::input(
                        path,
                        format!(
                            "invalid glTF: mesh {m} primitive {p} uses POSITION accessor {} but \
                             there are {} accessors",
                            a.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    // The spec requires min/max on POSITION accessors, and gltf-json refuses a file without
    // them; the loader never reads them (it reads and checks every position itself), so a
    // missing pair is filled with a placeholder: a file whose POSITION holds ±inf is then
    // refused for the non-finite coordinate (naming mesh and position), not for the bounds.
    for mesh in &root.meshes {
        for prim in &mesh.primitives {
            if let Some(a) = prim.attributes.get(&positions) {
                let acc = &mut root.accessors[a.value()];
                if acc.min.is_none() || acc.max.is_none() {
                    acc.min = Some(serde_json::json!([0.0, 0.0, 0.0]));
                    acc.max = Some(serde_json::json!([0.0, 0.0, 0.0]));
                }
            }
        }
    }
    Document::from_json(root).map_err(|e| {
        let msg = match &e {
            ::gltf::Error::Validation(list) => {
                let more = match list.len() {
                    0 | 1 => String::new(),
                    n => format!(" (and {} more problems)", n - 1),
                };
                match list.first() {
                    Some((p, v)) => format!("invalid glTF: {p}: {v}{more}"),
                    None => "invalid glTF".to_string(),
                }
            }
            other => format!("invalid glTF: {other}"),
        };
        Error::input(path, msg)
    })
}

fn strip_bom(json: &[u8]) -> &[u8] {
    json.strip_prefix(&[0xEF, 0xBB, 0xBF]).unwrap_or(json)
}

/// The `EXT_mesh_gpu_instancing` attributes of one node: accessor indices, checked to exist.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct GpuInstancing {
    /// `TRANSLATION` accessor.
    pub translation: Option<usize>,
    /// `ROTATION` accessor.
    pub rotation: Option<usize>,
    /// `SCALE` accessor.
    pub scale: Option<usize>,
    /// Every attribute (the three above and application-specific ones such as `_ID`), by
    /// name: all must have the same count, which is the number of instances.
    pub all: Vec<(String, usize)>,
}

/// What the second JSON pass finds: per node its `EXT_mesh_gpu_instancing`.
#[derive(Debug, Default)]
pub(crate) struct Extensions {
    /// By node index; `None` for nodes without `EXT_mesh_gpu_instancing`.
    pub instancing: Vec<Option<GpuInstancing>>,
    /// By node index: the local transform read as f64 from the JSON.
    pub transforms: Vec<Option<NodeTransform>>,
}

/// Serde view of the parts of the glTF JSON the `gltf` crate (without its `extensions`
/// feature) drops or rounds (node transforms, which it stores as f32); every other member is
/// skipped unparsed.
#[derive(serde::Deserialize, Default)]
#[serde(default)]
struct ExtRoot {
    nodes: Vec<ExtNode>,
}

#[derive(serde::Deserialize, Default)]
#[serde(default)]
struct ExtNode {
    extensions: Option<ExtNodeExtensions>,
    /// The node transform as the JSON writes it, in f64 (the `gltf` crate keeps f32).
    matrix: Option<Vec<f64>>,
    translation: Option<Vec<f64>>,
    rotation: Option<Vec<f64>>,
    scale: Option<Vec<f64>>,
}

/// A node's local transform as written in the JSON, every number read as f64 (serde_json
/// parses JSON numbers correctly rounded to f64; the `gltf` crate rounds them again to f32,
/// which moves a part by up to half an f32 ulp of its translation).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum NodeTransform {
    /// `matrix`: 16 numbers, column-major (it wins over translation/rotation/scale, as in the
    /// `gltf` crate).
    Matrix([f64; 16]),
    /// `translation`, `rotation` (x, y, z, w), `scale`; missing members are the identity.
    Trs {
        /// Translation.
        t: [f64; 3],
        /// Rotation quaternion (x, y, z, w), as written (not normalised).
        r: [f64; 4],
        /// Scale.
        s: [f64; 3],
    },
}

impl ExtNode {
    /// The f64 transform; None if a member has the wrong length (the `gltf` crate's
    /// validation has already refused such files).
    fn transform(&self) -> Option<NodeTransform> {
        fn arr<const N: usize>(v: &Option<Vec<f64>>, default: [f64; N]) -> Option<[f64; N]> {
            match v {
                None => Some(default),
                Some(v) => v.as_slice().try_into().ok(),
            }
        }
        if let Some(m) = &self.matrix {
            return m.as_slice().try_into().ok().map(NodeTransform::Matrix);
        }
        Some(NodeTransform::Trs {
            t: arr(&self.translation, [0.0; 3])?,
            r: arr(&self.rotation, [0.0, 0.0, 0.0, 1.0])?,
            s: arr(&self.scale, [1.0; 3])?,
        })
    }
}

#[derive(serde::Deserialize, Default)]
#[serde(default)]
struct ExtNodeExtensions {
    #[serde(rename = "EXT_mesh_gpu_instancing")]
    gpu_instancing: Option<serde_json::Value>,
}

/// Reads the extension members of nodes and primitives from the glTF `json` (already
/// validated by [`parse_document`]); `accessors` is the number of accessors, for range checks.
///
/// `EXT_mesh_gpu_instancing` is honoured wherever a node carries it, whether or not the file
/// lists it in `extensionsUsed` (instances left out would be clashes missed).
pub(crate) fn parse_extensions(path: &Path, json: &[u8], accessors: usize) -> Result<Extensions> {
    let root: ExtRoot = serde_json::from_slice(strip_bom(json))
        .map_err(|e| Error::input(path, format!("invalid glTF JSON: {e}")))?;
    let mut out = Extensions::default();
    for (i, node) in root.nodes.into_iter().enumerate() {
        out.transforms.push(node.transform());
        let gpu = match node.extensions.and_then(|e| e.gpu_instancing) {
            Some(v) => Some(gpu_instancing(path, i, &v, accessors)?),
            None => None,
        };
        out.instancing.push(gpu);
    }
    Ok(out)
}

fn gpu_instancing(
    path: &Path,
    node: usize,
    v: &serde_json::Value,
    accessors: usize,
) -> Result<GpuInstancing> {
    let err = |m: String| Error::input(path, format!("glTF node {node}: EXT_mesh_gpu_instancing {m}"));
    let Some(attrs) = v.get("attributes").and_then(|a| a.as_object()) else {
        return Err(err("has no 'attributes' object".into()));
    };
    if attrs.is_empty() {
        return Err(err("has no attributes, so no instance count".into()));
    }
    let mut out = GpuInstancing::default();
    for (name, index) in attrs {
        let shown = super::clip(name, 40);
        let Some(a) = index.as_u64() else {
            return Err(err(format!("attribute {shown} is not an accessor index")));
        };
        if a >= accessors as u64 {
            return Err(err(format!(
                "attribute {shown} uses accessor {a} but there are {accessors} accessors"
            )));
        }
        let a = a as usize;
        match name.as_str() {
            "TRANSLATION" => out.translation = Some(a),
            "ROTATION" => out.rotation = Some(a),
            "SCALE" => out.scale = Some(a),
            _ => {}
        }
        out.all.push((name.clone(), a));
    }
    Ok(out)
}

/// Resolves every buffer: the GLB binary chunk, a base64 `data:` URI, or a relative file
/// (percent-decoded) next to `path`. Each must hold at least its declared `byteLength`.
pub(crate) fn load_buffers<'a>(
    path: &Path,
    doc: &Document,
    bin: Option<&'a [u8]>,
) -> Result<Vec<Cow<'a, [u8]>>> {
    let mut out = Vec::with_capacity(doc.buffers().len());
    for buffer in doc.buffers() {
        let i = buffer.index();
        let declared = buffer.length();
        let short = |what: &str, have: usize| {
            Error::input(
                path,
                format!("glTF buffer {i} declares {declared} bytes but {what} has {have} bytes"),
            )
        };
        let data: Cow<'a, [u8]> = match buffer.source() {
            ::gltf::buffer::Source::Bin => {
                let Some(b) = bin else {
                    return Err(Error::input(
                        path,
                        format!("glTF buffer {i} refers to the GLB binary chunk but there is none"),
                    ));
                };
                if b.len() < declared {
                    return Err(short("the GLB binary chunk", b.len()));
                }
                Cow::Borrowed(b)
            }
            ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let data = decode_data_uri(uri)
                    .map_err(|m| Error::input(path, format!("glTF buffer {i} data URI is invalid: {m}")))?;
                if data.len() < declared {
                    return Err(short("its data URI", data.len()));
                }
                Cow::Owned(data)
            }
            ::gltf::buffer::Source::Uri(uri) => Cow::Owned(read_external(path, i, uri, declared)?),
        };
        out.push(data);
    }
    Ok(out)
}

fn decode_data_uri(uri: &str) -> std::result::Result<Vec<u8>, String> {
    let Some((header, payload)) = uri.split_once(',') else {
        return Err("no ',' after the media type".into());
    };
    if !header.ends_with(";base64") {
        return Err(format!("'{}' is not base64-encoded", super::clip(header, 60)));
    }
    let engine = base64::engine::GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        base64::engine::GeneralPurposeConfig::new()
            .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
    );
    engine.decode(payload.trim()).map_err(|e| format!("bad base64: {e}"))
}

/// Why a buffer URI may not be read, or `None` when it is a relative reference that stays
/// inside the glTF's directory. `name` is the percent-decoded URI; `/` and `\\` both count
/// as separators, so the check is the same on every platform.
fn unsafe_relative_path(name: &str) -> Option<&'static str> {
    if name.starts_with(['/', '\\']) {
        return Some("an absolute path");
    }
    let mut depth = 0usize;
    for segment in name.split(['/', '\\']) {
        match segment {
            _ if segment.contains(':') => return Some("a scheme or drive letter"),
            ".." if depth == 0 => return Some("'..' leaving the glTF's directory"),
            ".." => depth -= 1,
            "" | "." => {}
            _ => depth += 1,
        }
    }
    if name.contains('\0') {
        return Some("a NUL byte");
    }
    None
}

/// Reads an external buffer. Policy: only relative references that stay inside the directory
/// of the glTF file (after percent-decoding: no scheme such as `file:` or `https:`, no
/// absolute path, no drive letter or UNC prefix, no `..` climbing above that directory); a
/// file inside it that is a symbolic link is followed.
fn read_external(path: &Path, i: usize, uri: &str, declared: usize) -> Result<Vec<u8>> {
    let shown = super::clip(uri, 80);
    let refuse = |why: &str| {
        Error::input(
            path,
            format!(
                "glTF buffer {i} URI '{shown}' is refused: {why} (only data: URIs and relative \
                 paths inside the glTF's directory are read)"
            ),
        )
    };
    if let Some(why) = unsafe_relative_path(uri) {
        return Err(refuse(why));
    }
    let name = percent_decode(uri).map_err(|()| {
        Error::input(path, format!("glTF buffer {i} URI '{shown}' is not valid UTF-8 when percent-decoded"))
    })?;
    if let Some(why) = unsafe_relative_path(&name) {
        return Err(refuse(why));
    }
    let file = path.parent().unwrap_or(Path::new("")).join(&name);
    let cannot = |e: std::io::Error| {
        Error::input(path, format!("glTF external buffer '{shown}' cannot be read: {}", io_message(&e)))
    };
    // The text checks above cannot see symlinks: resolve both ends and compare (issue 11 item 6).
    let real = file.canonicalize().map_err(cannot)?;
    let base = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let base = base.canonicalize().map_err(cannot)?;
    if !real.starts_with(&base) {
        return Err(refuse("it resolves (through a symlink) outside the glTF's directory"));
    }
    if !real.metadata().map_err(cannot)?.is_file() {
        return Err(refuse("it is not a regular file"));
    }
    let f = std::fs::File::open(&real).map_err(cannot)?;
    let have = f.metadata().map_err(cannot)?.len();
    if have < declared as u64 {
        return Err(Error::input(
            path,
            format!(
                "glTF external buffer '{shown}' has {have} bytes but buffer {i} declares \
                 {declared}"
            ),
        ));
    }
    let mut data = Vec::with_capacity(declared);
    f.take(declared as u64).read_to_end(&mut data).map_err(cannot)?;
    if data.len() < declared {
        return Err(Error::input(
            path,
            format!(
                "glTF external buffer '{shown}' shrank while reading: {} of {declared} bytes",
                data.len()
            ),
        ));
    }
    Ok(data)
}

fn percent_decode(s: &str) -> std::result::Result<String, ()> {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%' && i + 2 < b.len() {
            if let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2])) {
                out.push((h * 16 + l) as u8);
                i += 3;
                continue;
            }
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8(out).map_err(|_| ())
}

/// glTF's name for a component type, for messages.
pub(crate) fn type_name(t: DataType) -> &'static str {
    match t {
        DataType::I8 => "BYTE",
        DataType::U8 => "UNSIGNED_BYTE",
        DataType::I16 => "SHORT",
        DataType::U16 => "UNSIGNED_SHORT",
        DataType::U32 => "UNSIGNED_INT",
        DataType::F32 => "FLOAT",
    }
}

fn dims_name(d: Dimensions) -> &'static str {
    match d {
        Dimensions::Scalar => "SCALAR",
        Dimensions::Vec2 => "VEC2",
        Dimensions::Vec3 => "VEC3",
        Dimensions::Vec4 => "VEC4",
        Dimensions::Mat2 => "MAT2",
        Dimensions::Mat3 => "MAT3",
        Dimensions::Mat4 => "MAT4",
    }
}

/// Reads accessors from resolved buffers with every range checked.
pub(crate) struct Reader<'a, 'b> {
    /// The file, for messages.
    pub path: &'a Path,
    /// Resolved buffer data, by buffer index.
    pub buffers: &'a [Cow<'b, [u8]>],
    /// Total input bytes (file plus buffers): bounds accessors with no backing bufferView.
    pub input_bytes: usize,
}

impl Reader<'_, '_> {
    fn err(&self, msg: String) -> Error {
        Error::input(self.path, msg)
    }

    /// A POSITION accessor as f64 triples (`what` names the mesh/primitive for messages).
    ///
    /// `FLOAT` components are widened exactly. The integer component types of
    /// `KHR_mesh_quantization` are decoded as [`component`] says (exact for unnormalized
    /// integers; one correctly rounded f64 division for normalized ones). Sparse substitution
    /// works for every type, the sparse values having the accessor's component type.
    pub(crate) fn positions(&self, acc: &Accessor, what: &str) -> Result<Vec<[f64; 3]>> {
        if acc.dimensions() != Dimensions::Vec3 {
            return Err(self.err(format!(
                "positions accessor of {what} has type {} (expected VEC3)",
                dims_name(acc.dimensions())
            )));
        }
        if acc.data_type() == DataType::U32 {
            return Err(self.err(format!(
                "positions accessor of {what} uses component type UNSIGNED_INT (expected FLOAT, or \
                 BYTE, UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT with KHR_mesh_quantization)"
            )));
        }
        let out = self.vectors::<3>(acc, what)?;
        for (i, p) in out.iter().enumerate() {
            if let Some(bad) = super::non_finite(*p) {
                return Err(self.err(format!("position {i} of {what} has a non-finite coordinate ({bad})")));
            }
        }
        Ok(out)
    }

    /// Reads `acc` (any component type except `UNSIGNED_INT`) as `N`-vectors of f64, decoded
    /// by [`component`]. The caller checks the accessor type and component type it allows.
    pub(crate) fn vectors<const N: usize>(&self, acc: &Accessor, what: &str) -> Result<Vec<[f64; N]>> {
        let t = acc.data_type();
        let size = t.size();
        let norm = acc.normalized();
        self.read(acc, what, N * size, |b| std::array::from_fn(|k| component(t, norm, &b[k * size..])))
    }

    /// An `EXT_mesh_gpu_instancing` attribute of `node`: `TRANSLATION` and `SCALE` are FLOAT
    /// VEC3, `ROTATION` is VEC4 of FLOAT or normalized BYTE or SHORT (the extension's table).
    /// Other (application-specific) attributes are not read.
    pub(crate) fn check_instance_attribute(&self, acc: &Accessor, name: &str, node: usize) -> Result<()> {
        let (dims, ok) = match name {
            "TRANSLATION" | "SCALE" => (Dimensions::Vec3, acc.data_type() == DataType::F32),
            "ROTATION" => (
                Dimensions::Vec4,
                acc.data_type() == DataType::F32
                    || (matches!(acc.data_type(), DataType::I8 | DataType::I16) && acc.normalized()),
            ),
            _ => return Ok(()),
        };
        if acc.dimensions() != dims || !ok {
            let expected = match name {
                "ROTATION" => "VEC4 of FLOAT, or of normalized BYTE or SHORT",
                _ => "VEC3 of FLOAT",
            };
            return Err(self.err(format!(
                "glTF node {node}: EXT_mesh_gpu_instancing {name} accessor {} is {} of {}{} \
                 (expected {expected})",
                acc.index(),
                dims_name(acc.dimensions()),
                if acc.normalized() { "normalized " } else { "" },
                type_name(acc.data_type()),
            )));
        }
        Ok(())
    }

    /// An index accessor (u8, u16 or u32 scalars) as u32.
    pub(crate) fn indices(&self, acc: &Accessor, what: &str) -> Result<Vec<u32>> {
        if acc.dimensions() != Dimensions::Scalar {
            return Err(self.err(format!(
                "indices accessor of {what} has type {} (expected SCALAR)",
                dims_name(acc.dimensions())
            )));
        }
        match acc.data_type() {
            DataType::U8 => self.read(acc, what, 1, |b| b[0] as u32),
            DataType::U16 => self.read(acc, what, 2, |b| u16::from_le_bytes([b[0], b[1]]) as u32),
            DataType::U32 => self.read(acc, what, 4, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            t => Err(self.err(format!(
                "indices accessor of {what} uses component type {} (expected UNSIGNED_BYTE, \
                 UNSIGNED_SHORT or UNSIGNED_INT)",
                type_name(t)
            ))),
        }
    }

    /// The bytes of buffer view `view`, checked against its buffer.
    fn view_bytes(&self, view: &::gltf::buffer::View) -> Result<&[u8]> {
        let b = view.buffer().index();
        let data = self.buffers.get(b).map(|c| &c[..]).unwrap_or(&[]);
        let limit = data.len().min(view.buffer().length());
        let start = view.offset();
        match start.checked_add(view.length()) {
            Some(end) if end <= limit => Ok(&data[start..end]),
            _ => Err(self.err(format!(
                "glTF bufferView {} (offset {start}, length {}) does not fit in buffer {b} \
                 ({limit} bytes)",
                view.index(),
                view.length()
            ))),
        }
    }

    /// Checks that `count` elements of `elem` bytes at `offset` with `stride` fit in `len`.
    fn fits(
        &self,
        count: usize,
        elem: usize,
        stride: usize,
        offset: usize,
        len: usize,
        what: String,
    ) -> Result<()> {
        if count == 0 {
            return Ok(());
        }
        let end = (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(elem))
            .and_then(|x| x.checked_add(offset));
        match end {
            Some(end) if end <= len => Ok(()),
            _ => Err(self.err(format!(
                "{what}: {count} elements of {elem} bytes (stride {stride}) from offset {offset} \
                 do not fit in its bufferView of {len} bytes"
            ))),
        }
    }

    /// Reads `acc` as elements of `elem` bytes decoded by `decode`, applying sparse values.
    /// Without a bufferView the base values are all-zero bytes, decoded.
    fn read<T: Copy>(
        &self,
        acc: &Accessor,
        what: &str,
        elem: usize,
        decode: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>> {
        let count = acc.count();
        let label = || format!("accessor {} of {what}", acc.index());
        let mut out = match acc.view() {
            Some(view) => {
                let data = self.view_bytes(&view)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(self.err(format!(
                        "{}: byteStride {stride} is smaller than its {elem}-byte elements",
                        label()
                    )));
                }
                self.fits(count, elem, stride, acc.offset(), data.len(), label())?;
                let data = &data[acc.offset().min(data.len())..];
                let mut out = Vec::with_capacity(count);
                for i in 0..count {
                    let o = i * stride;
                    out.push(decode(&data[o..o + elem]));
                }
                out
            }
            None => {
                if count > self.input_bytes {
                    return Err(self.err(format!(
                        "{} declares {count} elements without a bufferView, more than the {} \
                         bytes of input",
                        label(),
                        self.input_bytes
                    )));
                }
                vec![decode(&vec![0u8; elem]); count]
            }
        };
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            if n > count {
                return Err(
                    self.err(format!("{}: sparse count {n} exceeds the accessor count {count}", label()))
                );
            }
            let ind = sparse.indices();
            let isize = ind.index_type().size();
            let ibytes = self.view_bytes(&ind.view())?;
            self.fits(n, isize, isize, ind.offset(), ibytes.len(), format!("{} sparse indices", label()))?;
            let ibytes = &ibytes[ind.offset().min(ibytes.len())..];
            let vals = sparse.values();
            let vbytes = self.view_bytes(&vals.view())?;
            self.fits(n, elem, elem, vals.offset(), vbytes.len(), format!("{} sparse values", label()))?;
            let vbytes = &vbytes[vals.offset().min(vbytes.len())..];
            for k in 0..n {
                let b = &ibytes[k * isize..(k + 1) * isize];
                let idx = match isize {
                    1 => b[0] as usize,
                    2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                };
                let Some(slot) = out.get_mut(idx) else {
                    return Err(self
                        .err(format!("{}: sparse index {idx} is out of range ({count} elements)", label())));
                };
                *slot = decode(&vbytes[k * elem..(k + 1) * elem]);
            }
        }
        Ok(out)
    }
}

/// One accessor component at the start of `b` as f64.
///
/// - `FLOAT`: the f32 value, widened exactly.
/// - Integer types, not normalized: the integer itself (exact).
/// - Normalized (glTF 2.0 § 3.11, as KHR_mesh_quantization restates): `c / 255`,
///   `c / 65535` for unsigned bytes and shorts, `max(c / 127, -1)`, `max(c / 32767, -1)` for
///   signed ones, each quotient one IEEE-754 f64 division (correctly rounded, so the same on
///   every platform); the clamp only maps -128 and -32768 to exactly -1.
/// - `UNSIGNED_INT` (never allowed for the attributes read here): the integer, normalized by
///   `2^32 - 1` if flagged.
///
/// `b` must hold at least the component's size (the caller's ranges guarantee it).
pub(crate) fn component(t: DataType, normalized: bool, b: &[u8]) -> f64 {
    let (v, max) = match t {
        DataType::F32 => return f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]])),
        DataType::I8 => (f64::from(b[0] as i8), 127.0),
        DataType::U8 => (f64::from(b[0]), 255.0),
        DataType::I16 => (f64::from(i16::from_le_bytes([b[0], b[1]])), 32767.0),
        DataType::U16 => (f64::from(u16::from_le_bytes([b[0], b[1]])), 65535.0),
        DataType::U32 => (f64::from(u32::from_le_bytes([b[0], b[1], b[2], b[3]])), 4294967295.0),
    };
    if normalized {
        (v / max).max(-1.0)
    } else {
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("a%20b%2Fc.bin").unwrap(), "a b/c.bin");
        assert_eq!(percent_decode("100%").unwrap(), "100%");
        assert_eq!(percent_decode("x%4").unwrap(), "x%4");
        assert_eq!(percent_decode("%zz").unwrap(), "%zz");
        assert!(percent_decode("%ff").is_err());
    }

    #[test]
    fn data_uris() {
        assert_eq!(decode_data_uri("data:application/octet-stream;base64,AAEC").unwrap(), [0, 1, 2]);
        assert_eq!(decode_data_uri("data:application/gltf-buffer;base64,AAE=").unwrap(), [0, 1]);
        assert_eq!(decode_data_uri("data:application/gltf-buffer;base64,AAE").unwrap(), [0, 1]);
        assert!(decode_data_uri("data:text/plain,hello").is_err());
        assert!(decode_data_uri("data:;base64,!!!!").is_err());
        assert!(decode_data_uri("data:nocomma").is_err());
    }

    #[test]
    fn glb_framing_hostile() {
        let p = Path::new("h.glb");
        let e = split_glb(p, b"glTF\x02\0\0").unwrap_err().to_string();
        assert!(e.contains("truncated GLB: 7 bytes"), "{e}");
        let mut b = b"glTF".to_vec();
        b.extend_from_slice(&2u32.to_le_bytes());
        b.extend_from_slice(&u32::MAX.to_le_bytes());
        b.extend_from_slice(&[0; 20]);
        let e = split_glb(p, &b).unwrap_err().to_string();
        assert!(e.contains("header declares 4294967295 bytes but the file has 32 bytes"), "{e}");
        b[8..12].copy_from_slice(&32u32.to_le_bytes());
        b[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
        b[16..20].copy_from_slice(b"JSON");
        let e = split_glb(p, &b).unwrap_err().to_string();
        assert!(e.contains("chunk 0 ('JSON') declares 4294967295 bytes but only 12 remain"), "{e}");
        b[12..16].copy_from_slice(&4u32.to_le_bytes());
        b[16..20].copy_from_slice(b"BIN\0");
        let e = split_glb(p, &b).unwrap_err().to_string();
        assert!(e.contains("first chunk is not JSON"), "{e}");
        b[4..8].copy_from_slice(&1u32.to_le_bytes());
        let e = split_glb(p, &b).unwrap_err().to_string();
        assert!(e.contains("GLB version 1 is not supported"), "{e}");
        // a chunk header cut off by the declared length
        b[4..8].copy_from_slice(&2u32.to_le_bytes());
        b[16..20].copy_from_slice(b"JSON");
        b[8..12].copy_from_slice(&28u32.to_le_bytes());
        let e = split_glb(p, &b).unwrap_err().to_string();
        assert!(e.contains("chunk 1 header at byte 24 is cut off"), "{e}");
    }
}
