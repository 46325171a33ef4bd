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

use super::unreadable;
use crate::error::{
    AccessorPart, AccessorRole, AccessorUser, Error, GltfProblem, InputProblem, InstancingProblem, Location,
    Part, Reading, Result,
};

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
    let err = |p: InputProblem| Error::in_file(path, p);
    let truncated = |part: Part, declared: usize, have: usize| InputProblem::Truncated {
        part,
        declared: declared as u64,
        have: have as u64,
    };
    let have = bytes.len();
    if have < 12 {
        return Err(err(truncated(Part::GlbHeader, 12, have)));
    }
    if &bytes[..4] != b"glTF" {
        return Err(err(GltfProblem::NotGlb.into()));
    }
    let version = le_u32(bytes, 4).unwrap_or(0);
    if version != 2 {
        return Err(err(GltfProblem::GlbVersion(version as u32).into()));
    }
    let declared = le_u32(bytes, 8).unwrap_or(0);
    if declared > have {
        return Err(err(truncated(Part::Glb, declared, have)));
    }
    let data = &bytes[..declared];
    let mut pos = 12;
    let mut json = None;
    let mut bin = None;
    let mut index = 0;
    while pos < data.len() {
        let at = Location::Byte(pos as u64);
        let (Some(len), Some(kind)) = (le_u32(data, pos), data.get(pos + 4..pos + 8)) else {
            let problem = truncated(Part::GlbChunkHeader { chunk: index }, 8, data.len() - pos);
            return Err(Error::at(path, at, problem));
        };
        let start = pos + 8;
        if len > data.len() - start {
            let kind = super::clip(String::from_utf8_lossy(kind).trim_end_matches('\0'), 4);
            let problem = truncated(Part::GlbChunk { chunk: index, kind }, len, data.len() - start);
            return Err(Error::at(path, at, problem));
        }
        let chunk = &data[start..start + len];
        match (index, kind) {
            (0, b"JSON") => json = Some(chunk),
            (0, _) => return Err(err(GltfProblem::FirstChunkNotJson.into())),
            (1, b"BIN\0") => bin = Some(chunk),
            _ => {}
        }
        index += 1;
        pos = start + len;
    }
    let json = json.ok_or_else(|| err(GltfProblem::NoJsonChunk.into()))?;
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
        .map_err(|e| Error::in_file(path, GltfProblem::Json(e.to_string())))?;
    for ext in &root.extensions_required {
        if !ext.starts_with("KHR_materials_") && !SUPPORTED_REQUIRED.contains(&ext.as_str()) {
            return Err(Error::in_file(path, InputProblem::UnsupportedExtension(ext.clone())));
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
        let extensions_used: Vec<String> = root
            .extensions_used
            .iter()
            .filter(|e| !e.starts_with("KHR_materials_") && !SUPPORTED_REQUIRED.contains(&e.as_str()))
            .cloned()
            .collect();
        let at = Location::Accessor { accessor: a, user: None };
        return Err(Error::at(path, at, GltfProblem::NoAccessorData { extensions_used }));
    }
    // gltf-json's validation indexes `accessors` with the POSITION index unchecked (a panic on a
    // dangling index), so check those references before validating.
    let positions = ::gltf::json::validation::Checked::Valid(::gltf::json::mesh::Semantic::Positions);
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            if let Some(a) = prim.attributes.get(&positions) {
                if a.value() >= root.accessors.len() {
                    let problem = GltfProblem::NoPositionAccessor {
                        accessor: a.value(),
                        accessors: root.accessors.len(),
                    };
                    return Err(Error::at(path, Location::Primitive { mesh: m, primitive: p }, problem));
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
                    Some((p, v)) => format!("{p}: {v}{more}"),
                    None => String::new(),
                }
            }
            other => other.to_string(),
        };
        Error::in_file(path, GltfProblem::Invalid(msg))
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
        .map_err(|e| Error::in_file(path, GltfProblem::Json(e.to_string())))?;
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
    let err = |p: InstancingProblem| Error::at(path, Location::Node(node), p);
    let Some(attrs) = v.get("attributes").and_then(|a| a.as_object()) else {
        return Err(err(InstancingProblem::NoAttributesObject));
    };
    if attrs.is_empty() {
        return Err(err(InstancingProblem::NoAttributes));
    }
    let mut out = GpuInstancing::default();
    for (name, index) in attrs {
        let attribute = super::clip(name, 40);
        let Some(a) = index.as_u64() else {
            return Err(err(InstancingProblem::NotAnIndex { attribute }));
        };
        if a >= accessors as u64 {
            return Err(err(InstancingProblem::AccessorOutOfRange { attribute, accessor: a, accessors }));
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
        let at = Location::Buffer(i);
        let short = |part: Part, have: usize| {
            Error::at(
                path,
                at.clone(),
                InputProblem::Truncated { part, declared: declared as u64, have: have as u64 },
            )
        };
        let data: Cow<'a, [u8]> = match buffer.source() {
            ::gltf::buffer::Source::Bin => {
                let Some(b) = bin else {
                    return Err(Error::at(path, at, GltfProblem::NoBinChunk));
                };
                if b.len() < declared {
                    return Err(short(Part::BinChunk, b.len()));
                }
                Cow::Borrowed(b)
            }
            ::gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let data = decode_data_uri(uri)
                    .map_err(|m| Error::at(path, at.clone(), GltfProblem::BadDataUri(m)))?;
                if data.len() < declared {
                    return Err(short(Part::DataUri, data.len()));
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
    let at = Location::Buffer(i);
    let refuse = |reason: &'static str| {
        Error::at(path, at.clone(), GltfProblem::UriRefused { uri: shown.clone(), reason })
    };
    if let Some(why) = unsafe_relative_path(uri) {
        return Err(refuse(why));
    }
    let name = percent_decode(uri)
        .map_err(|()| Error::at(path, at.clone(), GltfProblem::UriNotUtf8 { uri: shown.clone() }))?;
    if let Some(why) = unsafe_relative_path(&name) {
        return Err(refuse(why));
    }
    let file = path.parent().unwrap_or(Path::new("")).join(&name);
    let cannot = |e: std::io::Error| {
        Error::at(path, at.clone(), unreadable(Reading::ExternalBuffer(shown.clone()), &e))
    };
    // The text checks above cannot see symlinks: resolve both ends and compare.
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
    let short = |part: Part, have: u64| {
        Error::at(path, at.clone(), InputProblem::Truncated { part, declared: declared as u64, have })
    };
    if have < declared as u64 {
        return Err(short(Part::ExternalFile(shown.clone()), have));
    }
    let mut data = Vec::with_capacity(declared);
    f.take(declared as u64).read_to_end(&mut data).map_err(cannot)?;
    if data.len() < declared {
        return Err(short(Part::ExternalFileRead(shown.clone()), data.len() as u64));
    }
    Ok(data)
}

/// The files next to the glTF `path` that its JSON names as buffers or images (not `data:`
/// URIs, not references [`read_external`] refuses), in order; nothing when the JSON does not
/// parse. Only the `uri` members are kept while parsing.
pub(crate) fn external_files(path: &Path, json: &[u8]) -> Vec<std::path::PathBuf> {
    #[derive(serde::Deserialize)]
    struct Named {
        uri: Option<String>,
    }
    #[derive(serde::Deserialize)]
    struct Doc {
        #[serde(default)]
        buffers: Vec<Named>,
        #[serde(default)]
        images: Vec<Named>,
    }
    let Ok(doc) = serde_json::from_slice::<Doc>(strip_bom(json)) else { return Vec::new() };
    let dir = path.parent().unwrap_or(Path::new(""));
    doc.buffers
        .iter()
        .chain(&doc.images)
        .filter_map(|n| n.uri.as_deref())
        .filter(|uri| !uri.starts_with("data:") && unsafe_relative_path(uri).is_none())
        .filter_map(|uri| percent_decode(uri).ok())
        .filter(|name| unsafe_relative_path(name).is_none())
        .map(|name| dir.join(name))
        .collect()
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
    /// `problem` with accessor `acc` read for `user`.
    fn err(&self, acc: &Accessor, user: AccessorUser, problem: GltfProblem) -> Error {
        Error::at(self.path, Location::Accessor { accessor: acc.index(), user: Some(user) }, problem)
    }

    /// A POSITION accessor of primitive `user` as f64 triples.
    ///
    /// `FLOAT` components are widened exactly. The integer component types of
    /// `KHR_mesh_quantization` are decoded as [`component`] says (exact for unnormalized
    /// integers; one correctly rounded f64 division for normalized ones). Sparse substitution
    /// works for every type, the sparse values having the accessor's component type.
    pub(crate) fn positions(&self, acc: &Accessor, mesh: usize, primitive: usize) -> Result<Vec<[f64; 3]>> {
        let user = AccessorUser::Primitive { mesh, primitive };
        let role = AccessorRole::Positions;
        if acc.dimensions() != Dimensions::Vec3 {
            let found = dims_name(acc.dimensions());
            return Err(self.err(acc, user, GltfProblem::AccessorType { role, found }));
        }
        if acc.data_type() == DataType::U32 {
            let found = type_name(acc.data_type());
            return Err(self.err(acc, user, GltfProblem::ComponentType { role, found }));
        }
        let out = self.vectors::<3>(acc, user)?;
        for (position, p) in out.iter().enumerate() {
            if let Some(value) = super::non_finite(*p) {
                let at = Location::Position { mesh, primitive, position };
                return Err(Error::at(self.path, at, InputProblem::NonFinite { value }));
            }
        }
        Ok(out)
    }

    /// Reads `acc` (any component type except `UNSIGNED_INT`) as `N`-vectors of f64, decoded
    /// by [`component`]. The caller checks the accessor type and component type it allows.
    pub(crate) fn vectors<const N: usize>(
        &self,
        acc: &Accessor,
        user: AccessorUser,
    ) -> Result<Vec<[f64; N]>> {
        let t = acc.data_type();
        let size = t.size();
        let norm = acc.normalized();
        if t == DataType::F32 {
            // `component` of a FLOAT, without choosing the type per component.
            let f = |b: &[u8]| f64::from(f32::from_le_bytes([b[0], b[1], b[2], b[3]]));
            return self.read(acc, user, N * 4, |b| std::array::from_fn(|k| f(&b[k * 4..])));
        }
        self.read(acc, user, N * size, |b| std::array::from_fn(|k| component(t, norm, &b[k * size..])))
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
            let problem = InstancingProblem::AttributeType {
                attribute: name.to_string(),
                accessor: acc.index(),
                dims: dims_name(acc.dimensions()),
                normalized: acc.normalized(),
                component: type_name(acc.data_type()),
            };
            return Err(Error::at(self.path, Location::Node(node), problem));
        }
        Ok(())
    }

    /// An index accessor (u8, u16 or u32 scalars) of primitive `user` as u32.
    pub(crate) fn indices(&self, acc: &Accessor, mesh: usize, primitive: usize) -> Result<Vec<u32>> {
        let user = AccessorUser::Primitive { mesh, primitive };
        let role = AccessorRole::Indices;
        if acc.dimensions() != Dimensions::Scalar {
            let found = dims_name(acc.dimensions());
            return Err(self.err(acc, user, GltfProblem::AccessorType { role, found }));
        }
        match acc.data_type() {
            DataType::U8 => self.read(acc, user, 1, |b| b[0] as u32),
            DataType::U16 => self.read(acc, user, 2, |b| u16::from_le_bytes([b[0], b[1]]) as u32),
            DataType::U32 => self.read(acc, user, 4, |b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])),
            t => Err(self.err(acc, user, GltfProblem::ComponentType { role, found: type_name(t) })),
        }
    }

    /// The index accessor of a TRIANGLES primitive as its triangles (each three indices in
    /// order) and the trailing indices that make no triangle: what [`Self::indices`] gives,
    /// grouped, with its checks and errors. A tightly packed accessor without sparse values is
    /// decoded straight into triangles (no flat list).
    pub(crate) fn triangle_indices(
        &self,
        acc: &Accessor,
        mesh: usize,
        primitive: usize,
    ) -> Result<(Vec<[u32; 3]>, Vec<u32>)> {
        let t = acc.data_type();
        let elem = t.size();
        let packed = acc.dimensions() == Dimensions::Scalar
            && matches!(t, DataType::U8 | DataType::U16 | DataType::U32)
            && acc.sparse().is_none()
            && acc.view().is_some_and(|v| v.stride().is_none_or(|s| s == elem));
        let Some(view) = acc.view().filter(|_| packed) else {
            let flat = self.indices(acc, mesh, primitive)?;
            let whole = flat.len() / 3 * 3;
            let triangles = flat[..whole].chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            return Ok((triangles, flat[whole..].to_vec()));
        };
        let user = AccessorUser::Primitive { mesh, primitive };
        let data = self.view_bytes(&view)?;
        let count = acc.count();
        self.fits((acc, user, AccessorPart::Elements), count, elem, elem, acc.offset(), data.len())?;
        let data = &data[acc.offset().min(data.len())..];
        let data = &data[..count * elem];
        fn group<const E: usize>(data: &[u8], one: fn([u8; E]) -> u32) -> (Vec<[u32; 3]>, Vec<u32>) {
            let at = |c: &[u8], k: usize| one(c[k * E..(k + 1) * E].try_into().expect("E bytes"));
            let triples = data.chunks_exact(3 * E);
            let rest = triples.remainder().chunks_exact(E).map(|c| at(c, 0)).collect();
            (triples.map(|c| [at(c, 0), at(c, 1), at(c, 2)]).collect(), rest)
        }
        Ok(match elem {
            1 => group::<1>(data, |b| b[0] as u32),
            2 => group::<2>(data, |b| u16::from_le_bytes(b) as u32),
            _ => group::<4>(data, u32::from_le_bytes),
        })
    }

    /// The bytes of buffer view `view`, checked against its buffer.
    fn view_bytes(&self, view: &::gltf::buffer::View) -> Result<&[u8]> {
        let b = view.buffer().index();
        let data = self.buffers.get(b).map(|c| &c[..]).unwrap_or(&[]);
        let limit = data.len().min(view.buffer().length());
        let start = view.offset();
        match start.checked_add(view.length()) {
            Some(end) if end <= limit => Ok(&data[start..end]),
            _ => {
                let problem = GltfProblem::ViewOutOfBuffer {
                    offset: start,
                    length: view.length(),
                    buffer: b,
                    buffer_len: limit,
                };
                Err(Error::at(self.path, Location::BufferView(view.index()), problem))
            }
        }
    }

    /// Checks that `count` elements of `elem` bytes at `offset` with `stride` fit in `len`
    /// (`part` of accessor `acc` read for `user`).
    fn fits(
        &self,
        (acc, user, part): (&Accessor, AccessorUser, AccessorPart),
        count: usize,
        elem: usize,
        stride: usize,
        offset: usize,
        len: usize,
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
            _ => {
                let problem =
                    GltfProblem::ElementsOutOfView { part, count, elem, stride, offset, view_len: len };
                Err(self.err(acc, user, problem))
            }
        }
    }

    /// Reads `acc` as elements of `elem` bytes decoded by `decode`, applying sparse values.
    /// Without a bufferView the base values are all-zero bytes, decoded.
    fn read<T: Copy>(
        &self,
        acc: &Accessor,
        user: AccessorUser,
        elem: usize,
        decode: impl Fn(&[u8]) -> T,
    ) -> Result<Vec<T>> {
        let count = acc.count();
        let mut out = match acc.view() {
            Some(view) => {
                let data = self.view_bytes(&view)?;
                let stride = view.stride().unwrap_or(elem);
                if stride < elem {
                    return Err(self.err(acc, user, GltfProblem::StrideTooSmall { stride, elem }));
                }
                self.fits(
                    (acc, user, AccessorPart::Elements),
                    count,
                    elem,
                    stride,
                    acc.offset(),
                    data.len(),
                )?;
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
                    let problem = GltfProblem::TooManyElements { count, input_bytes: self.input_bytes };
                    return Err(self.err(acc, user, problem));
                }
                vec![decode(&vec![0u8; elem]); count]
            }
        };
        if let Some(sparse) = acc.sparse() {
            let n = sparse.count();
            if n > count {
                return Err(self.err(acc, user, GltfProblem::SparseCount { sparse: n, count }));
            }
            let ind = sparse.indices();
            let isize = ind.index_type().size();
            let ibytes = self.view_bytes(&ind.view())?;
            let part = (acc, user, AccessorPart::SparseIndices);
            self.fits(part, n, isize, isize, ind.offset(), ibytes.len())?;
            let ibytes = &ibytes[ind.offset().min(ibytes.len())..];
            let vals = sparse.values();
            let vbytes = self.view_bytes(&vals.view())?;
            self.fits((acc, user, AccessorPart::SparseValues), n, elem, elem, vals.offset(), vbytes.len())?;
            let vbytes = &vbytes[vals.offset().min(vbytes.len())..];
            for k in 0..n {
                let b = &ibytes[k * isize..(k + 1) * isize];
                let idx = match isize {
                    1 => b[0] as usize,
                    2 => u16::from_le_bytes([b[0], b[1]]) as usize,
                    _ => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize,
                };
                let Some(slot) = out.get_mut(idx) else {
                    return Err(self.err(acc, user, GltfProblem::SparseIndex { index: idx, count }));
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
