//! Typed errors. Every error that reaches the user is one line naming the file (when there is one)
//! and the problem; the binary maps [`Error::exit_code`] to the process exit code.
//!
//! The context of an error is data, not text: an input error carries the file, where in it
//! ([`Location`]: a line, a byte, a triangle, a glTF node or accessor, a clash-set check) and
//! what is wrong ([`InputProblem`]); a usage error carries the flag and a [`UsageProblem`]; an
//! output error the path and an [`OutputProblem`]. `Display` renders them as the one-line
//! messages the command line prints (`meshclash: error: {error}`); the accessors
//! ([`Error::path`], [`Error::location`], [`Error::flag`], [`Error::input_problem`], …) give the
//! parts to library users.

use std::fmt::{self, Write as _};
use std::io;
use std::path::{Path, PathBuf};

/// Everything that can go wrong between the command line and the report.
#[derive(Debug)]
pub enum Error {
    /// A bad or unreadable input file: missing, wrong format, truncated, NaN coordinates, bad
    /// indices, no triangles, hostile sizes.
    Input {
        /// The file the problem is in.
        path: PathBuf,
        /// Where in the file, when the problem has a place.
        at: Option<Location>,
        /// What is wrong (boxed: the error stays small, as the `Err` of every `Result`).
        problem: Box<InputProblem>,
    },
    /// Writing the report failed (or would fail: outputs are checked before the run).
    Output {
        /// Where the report was going.
        path: PathBuf,
        /// What went wrong.
        problem: OutputProblem,
    },
    /// Bad arguments or settings.
    Usage {
        /// The flag at fault, without its leading `--` (`leaf-size`), when there is one.
        flag: Option<String>,
        /// What is wrong with it.
        problem: UsageProblem,
    },
}

/// Where in an input file a problem is.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Location {
    /// A line of a text file (1-based).
    Line(u64),
    /// A byte offset in the file (0-based).
    Byte(u64),
    /// A triangle, by its index in file order (0-based).
    Triangle(usize),
    /// A vertex, by its index in the mesh (0-based).
    Vertex(usize),
    /// Corner `corner` (0..3) of triangle `triangle` (binary STL).
    Corner {
        /// The triangle (0-based, file order).
        triangle: usize,
        /// Its corner, 0, 1 or 2.
        corner: usize,
    },
    /// A glTF mesh primitive.
    Primitive {
        /// The mesh index.
        mesh: usize,
        /// The primitive's index in the mesh.
        primitive: usize,
    },
    /// Entry `index` of the index list of a glTF mesh primitive.
    Index {
        /// The mesh index.
        mesh: usize,
        /// The primitive's index in the mesh.
        primitive: usize,
        /// The entry's position in the primitive's index list.
        index: usize,
    },
    /// Element `position` of the POSITION accessor of a glTF mesh primitive (local space).
    Position {
        /// The mesh index.
        mesh: usize,
        /// The primitive's index in the mesh.
        primitive: usize,
        /// The vertex's index in the accessor.
        position: usize,
    },
    /// Vertex `position` of a glTF mesh as placed in the world by a node (or one of its GPU
    /// instances).
    Placed {
        /// The mesh index.
        mesh: usize,
        /// The vertex's index in the mesh's (first) POSITION accessor.
        position: usize,
        /// The node drawing the mesh.
        node: usize,
        /// The `EXT_mesh_gpu_instancing` instance, when the node has them.
        instance: Option<usize>,
    },
    /// A glTF node.
    Node(usize),
    /// An `EXT_mesh_gpu_instancing` instance of a glTF node.
    Instance {
        /// The node.
        node: usize,
        /// The instance (0-based, accessor order).
        instance: usize,
    },
    /// A glTF accessor, and what reads it when that is known.
    Accessor {
        /// The accessor index.
        accessor: usize,
        /// The primitive or node that uses it.
        user: Option<AccessorUser>,
    },
    /// A glTF buffer.
    Buffer(usize),
    /// A glTF buffer view.
    BufferView(usize),
    /// A check of a clash-set file.
    Check(CheckRef),
    /// The `defaults` of a clash-set file.
    Defaults,
}

/// What reads a glTF accessor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum AccessorUser {
    /// A mesh primitive (its POSITION or indices).
    Primitive {
        /// The mesh index.
        mesh: usize,
        /// The primitive's index in the mesh.
        primitive: usize,
    },
    /// A node's `EXT_mesh_gpu_instancing` attributes.
    Instancing {
        /// The node.
        node: usize,
    },
}

/// A check of a clash-set file: by name, or by its 1-based number when it has no usable name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CheckRef {
    /// The check's `name`.
    Name(String),
    /// Its 1-based position in `checks`.
    Number(usize),
}

/// A non-finite coordinate value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NonFinite {
    /// Not a number.
    NaN,
    /// +infinity.
    Inf,
    /// -infinity.
    NegInf,
}

impl NonFinite {
    /// The first non-finite value of `v`, if any.
    pub fn first<const N: usize>(v: [f64; N]) -> Option<NonFinite> {
        v.iter().find(|x| !x.is_finite()).map(|&x| NonFinite::of(x))
    }

    /// What `x` is (finite values count as +infinity or -infinity by sign; call it on
    /// non-finite values).
    pub fn of(x: f64) -> NonFinite {
        if x.is_nan() {
            NonFinite::NaN
        } else if x > 0.0 {
            NonFinite::Inf
        } else {
            NonFinite::NegInf
        }
    }
}

impl fmt::Display for NonFinite {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            NonFinite::NaN => "NaN",
            NonFinite::Inf => "inf",
            NonFinite::NegInf => "-inf",
        })
    }
}

/// What was being read when reading failed.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Reading {
    /// An input mesh file.
    File,
    /// An input, to hash it (`meshclash run` checking it against its plan).
    Input,
    /// A clash-set file.
    ClashSet,
    /// A shard plan.
    Plan,
    /// A shard report.
    ShardReport,
    /// A baseline report.
    Baseline,
    /// A glTF external buffer, by its URI (as shown: shortened to 80 characters).
    ExternalBuffer(String),
}

/// The kind of a path that is not a regular file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum FileKind {
    /// A directory.
    Directory,
    /// A named pipe.
    Fifo,
    /// A character device (`/dev/zero`).
    CharDevice,
    /// A block device.
    BlockDevice,
    /// A Unix socket.
    Socket,
    /// Anything else.
    Other,
}

impl fmt::Display for FileKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FileKind::Directory => "a directory",
            FileKind::Fifo => "a FIFO",
            FileKind::CharDevice => "a character device",
            FileKind::BlockDevice => "a block device",
            FileKind::Socket => "a socket",
            FileKind::Other => "not a regular file",
        })
    }
}

/// The part of a file that is shorter than declared.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Part {
    /// The facets of a binary STL whose header declares `triangles`.
    StlFacets {
        /// The triangle count of the header.
        triangles: u32,
    },
    /// The 12-byte GLB header.
    GlbHeader,
    /// The GLB file (its header's total length).
    Glb,
    /// The 8-byte header of GLB chunk `chunk` (located by [`Location::Byte`]).
    GlbChunkHeader {
        /// The chunk's index.
        chunk: usize,
    },
    /// GLB chunk `chunk` of type `kind` (as shown: at most 4 characters).
    GlbChunk {
        /// The chunk's index.
        chunk: usize,
        /// Its type (`JSON`, `BIN`).
        kind: String,
    },
    /// The GLB binary chunk a buffer refers to (located by [`Location::Buffer`]).
    BinChunk,
    /// A buffer's `data:` URI (located by [`Location::Buffer`]).
    DataUri,
    /// A buffer's external file, by its URI as shown (located by [`Location::Buffer`]).
    ExternalFile(String),
    /// A buffer's external file that shrank while it was read (located by
    /// [`Location::Buffer`]).
    ExternalFileRead(String),
}

/// A count that is over its limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Quantity {
    /// Triangles of a binary STL.
    StlTriangles,
    /// Vertices of a text file.
    Vertices,
    /// Vertices of a glTF scene after instancing.
    SceneVertices,
    /// Triangles of a glTF scene after instancing.
    SceneTriangles,
    /// Parts of a glTF scene after instancing.
    SceneParts,
    /// Triangles `meshclash self` can number.
    SelfTriangles,
}

/// How an ASCII STL keyword is out of place.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Misplaced {
    /// Inside a facet (a missing `endfacet`).
    InsideFacet,
    /// Before any `solid`.
    OutsideSolid,
    /// Outside a facet.
    OutsideFacet,
    /// `endsolid` without `solid`.
    WithoutSolid,
}

/// What is wrong with an input file.
#[derive(Debug)]
#[non_exhaustive]
pub enum InputProblem {
    /// The file (or something it names) cannot be read: missing, no permission, an I/O error.
    Unreadable {
        /// What was being read.
        reading: Reading,
        /// The I/O error's kind (`NotFound`, `PermissionDenied`, …).
        kind: io::ErrorKind,
        /// The operating system's text.
        reason: String,
    },
    /// The path is a directory, FIFO, device or socket (refused before it is opened).
    NotARegularFile {
        /// What it is.
        kind: FileKind,
    },
    /// The path has no extension to tell its format.
    NoExtension,
    /// The extension is none of `.obj`, `.stl`, `.gltf`, `.glb` (lowercased, without the dot).
    UnknownExtension(String),
    /// The file is empty.
    Empty,
    /// Text that is not UTF-8 (at `byte` of the file, when known).
    NotUtf8 {
        /// The byte offset of the first invalid byte.
        byte: Option<u64>,
    },
    /// An `.obj` file holding binary data: a NUL byte (located by [`Location::Byte`]).
    NotText,
    /// A `.stl` file that looks like another format (`PNG`, `OBJ`, `glTF JSON`, …).
    NotStl {
        /// What it looks like.
        looks_like: &'static str,
    },
    /// A `.stl` file too short for binary STL that is not ASCII STL either.
    TooShortForStl {
        /// Its size in bytes.
        have: u64,
    },
    /// A `.gltf`/`.glb` file that is neither JSON nor GLB; `start` is its first bytes (up
    /// to 8).
    NotGltf {
        /// The first bytes of the file.
        start: Vec<u8>,
    },
    /// A part of the file is shorter than its header or its JSON declares.
    Truncated {
        /// Which part.
        part: Part,
        /// The bytes declared (needed).
        declared: u64,
        /// The bytes there are.
        have: u64,
    },
    /// A binary STL longer than its triangle count says.
    SizeMismatch {
        /// The triangle count of the header.
        triangles: u32,
        /// The size that count needs.
        need: u64,
        /// The file's size.
        have: u64,
    },
    /// Nothing to check: no triangles.
    NoTriangles,
    /// A coordinate is NaN or infinite.
    NonFinite {
        /// The first bad value.
        value: NonFinite,
    },
    /// A vertex is not finite once placed (the transform overflowed or was not finite).
    NonFiniteAfterTransform {
        /// The first bad value, when reported.
        value: Option<NonFinite>,
    },
    /// A placed vertex lies beyond ±2^250, where the exact predicates stop being exact.
    BeyondExactRange,
    /// A vertex index points past the vertices.
    IndexOutOfRange {
        /// The index as given (it may be negative in an array handed over by a caller).
        index: i128,
        /// The number of vertices.
        len: usize,
    },
    /// A count over what is supported.
    TooLarge {
        /// What is counted.
        quantity: Quantity,
        /// How many there are (or are declared).
        count: u64,
        /// The most supported.
        limit: u64,
    },
    /// A glTF scene whose check needs more memory than this process may use.
    NeedsMemory {
        /// Triangles after instancing.
        triangles: u64,
        /// Bytes the check needs (estimated).
        need: u64,
        /// Bytes available.
        available: u64,
        /// The estimate's bytes per triangle.
        per_triangle: u64,
    },
    /// An ASCII STL keyword out of place (located by [`Location::Line`]).
    Misplaced {
        /// The keyword as written (shortened).
        keyword: String,
        /// How it is out of place.
        how: Misplaced,
    },
    /// A word that is no ASCII STL keyword (shortened to 40 characters).
    UnknownKeyword(String),
    /// A vertex line with fewer than 3 coordinates.
    TooFewCoordinates {
        /// How many it has.
        found: usize,
    },
    /// A vertex coordinate that is not a number (shortened to 40 characters).
    BadNumber(String),
    /// An ASCII STL facet with fewer than 3 vertices.
    ShortFacet {
        /// The line of its `facet`.
        start_line: u64,
        /// How many vertices it has.
        vertices: usize,
    },
    /// The file ends inside the ASCII STL facet starting at `start_line`.
    UnfinishedFacet {
        /// The line of its `facet`.
        start_line: u64,
    },
    /// A glTF file requires an extension that cannot be read.
    UnsupportedExtension(String),
    /// A glTF-specific problem.
    Gltf(GltfProblem),
    /// An input changed since the shard plan was made.
    ChangedSincePlan {
        /// The input's SHA-256 now (hex).
        sha256: String,
        /// The SHA-256 the plan has (hex).
        planned: String,
    },
    /// A part selection (`--select-a`, `--exclude`, …) leaves nothing to check; the text is
    /// the selection's.
    Selection(String),
    /// A third-party parser's message (JSON, command line parsing of a clash-set check).
    Syntax(String),
    /// A rule of the file's format is broken (clash-set files, shard plans and reports,
    /// baselines); the text says which.
    Invalid(String),
    /// A problem in a check of a clash-set file (located by [`Location::Check`]): the check's
    /// own error.
    InCheck(Box<Error>),
    /// A loader broke its own guarantees (a bug).
    Internal(String),
    /// A coordinate beyond ±2^250 (located by [`Location::Vertex`]), where the exact predicates
    /// stop being exact.
    CoordinateBeyondExactRange {
        /// The coordinate.
        coordinate: f64,
    },
    /// An OBJ vertex that is not finite (located by [`Location::Line`]); `vertex` is its 1-based
    /// number in the file.
    ObjNonFiniteVertex {
        /// The vertex's 1-based number.
        vertex: usize,
        /// The first bad value.
        value: NonFinite,
    },
    /// An OBJ face (`f`) that cannot be read (located by [`Location::Line`]).
    ObjFace(ObjFaceProblem),
}

/// What is wrong with an OBJ face.
#[derive(Debug, Clone, PartialEq)]
pub enum ObjFaceProblem {
    /// More vertices than one polygon may have.
    TooManyVertices {
        /// The most read in one polygon.
        limit: usize,
    },
    /// A vertex reference that is not an integer (shortened to 40 characters).
    BadIndex(String),
    /// A reference to vertex 0 (OBJ indices start at 1).
    ZeroIndex,
    /// A negative (relative) reference before the first vertex.
    BeforeFirstVertex {
        /// The index as written.
        index: i64,
        /// The vertices defined before the face.
        defined: i64,
    },
    /// An index beyond what any file can hold (more than 2^32 vertices).
    BeyondAnyFile {
        /// The index as written.
        index: i64,
    },
    /// Fewer than 3 vertices.
    TooFewVertices {
        /// How many it has.
        found: usize,
    },
    /// The faces so far make more triangles than supported.
    TooManyTriangles {
        /// Triangles up to and including this face.
        total: usize,
        /// The most supported.
        limit: usize,
    },
    /// A positive (forward) reference beyond the vertices of the whole file.
    BeyondLastVertex {
        /// The index as written (1-based).
        index: i64,
        /// The file's vertices.
        vertices: i64,
    },
}

/// What a glTF accessor is read as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum AccessorRole {
    /// POSITION.
    Positions,
    /// Indices.
    Indices,
}

/// Which bytes of an accessor do not fit in their buffer view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum AccessorPart {
    /// Its elements.
    Elements,
    /// Its sparse indices.
    SparseIndices,
    /// Its sparse values.
    SparseValues,
}

/// A problem only glTF files have.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum GltfProblem {
    /// The JSON does not parse; the JSON parser's message.
    Json(String),
    /// The `gltf` crate's validation refuses the document; its message (may be empty).
    Invalid(String),
    /// A `.glb` without the `glTF` magic.
    NotGlb,
    /// A GLB container version other than 2.
    GlbVersion(u32),
    /// The first GLB chunk is not JSON.
    FirstChunkNotJson,
    /// A GLB without a JSON chunk.
    NoJsonChunk,
    /// An accessor with neither bufferView nor sparse values (located by
    /// [`Location::Accessor`]): its data would come from an extension.
    NoAccessorData {
        /// The `extensionsUsed` that could supply it.
        extensions_used: Vec<String>,
    },
    /// A primitive's POSITION names an accessor that does not exist (located by
    /// [`Location::Primitive`]).
    NoPositionAccessor {
        /// The accessor named.
        accessor: usize,
        /// How many there are.
        accessors: usize,
    },
    /// A problem with a node's `EXT_mesh_gpu_instancing` (located by [`Location::Node`]).
    Instancing(InstancingProblem),
    /// An `EXT_mesh_gpu_instancing` attribute value is not finite (located by
    /// [`Location::Instance`]).
    InstanceNotFinite {
        /// `TRANSLATION`, `ROTATION` or `SCALE`.
        attribute: &'static str,
        /// The first bad value.
        value: NonFinite,
    },
    /// A zero rotation quaternion (located by [`Location::Node`] or [`Location::Instance`]).
    ZeroQuaternion,
    /// A node's local transform is not finite (located by [`Location::Node`]).
    NonFiniteTransform {
        /// True for `matrix`, false for translation/rotation/scale.
        matrix: bool,
    },
    /// A world transform overflows (located by [`Location::Node`] or
    /// [`Location::Instance`]).
    WorldOverflow,
    /// A node lists the same child twice (located by [`Location::Node`], the parent).
    ChildTwice {
        /// The child.
        child: usize,
    },
    /// A node with two parents (located by [`Location::Node`], the child).
    TwoParents {
        /// The first parent.
        first: usize,
        /// The second.
        second: usize,
    },
    /// The node graph has a cycle (located by [`Location::Node`], a node on it).
    Cycle,
    /// A scene root that is also a child (located by [`Location::Node`]).
    RootIsChild {
        /// Its parent.
        parent: usize,
    },
    /// A scene lists a root twice (located by [`Location::Node`]).
    RootListedTwice,
    /// The hierarchy is deeper than `limit` (located by [`Location::Node`], where it got so).
    TooDeep {
        /// The most levels supported.
        limit: usize,
    },
    /// A buffer refers to a GLB binary chunk the file does not have (located by
    /// [`Location::Buffer`]).
    NoBinChunk,
    /// A buffer's `data:` URI does not decode (located by [`Location::Buffer`]).
    BadDataUri(String),
    /// A buffer URI that is not read by policy (located by [`Location::Buffer`]).
    UriRefused {
        /// The URI as shown (shortened to 80 characters).
        uri: String,
        /// Why.
        reason: &'static str,
    },
    /// A buffer URI that is not UTF-8 once percent-decoded (located by [`Location::Buffer`]).
    UriNotUtf8 {
        /// The URI as shown.
        uri: String,
    },
    /// An accessor of the wrong type (`VEC2` for positions, …; located by
    /// [`Location::Accessor`]).
    AccessorType {
        /// What it is read as.
        role: AccessorRole,
        /// Its type (`SCALAR`, `VEC2`, …).
        found: &'static str,
    },
    /// An accessor of a component type its role does not allow (located by
    /// [`Location::Accessor`]).
    ComponentType {
        /// What it is read as.
        role: AccessorRole,
        /// Its component type (`UNSIGNED_INT`, `FLOAT`, …).
        found: &'static str,
    },
    /// A buffer view that does not fit in its buffer (located by [`Location::BufferView`]).
    ViewOutOfBuffer {
        /// Its byte offset.
        offset: usize,
        /// Its length.
        length: usize,
        /// The buffer.
        buffer: usize,
        /// The buffer's usable length.
        buffer_len: usize,
    },
    /// An accessor's elements do not fit in their buffer view (located by
    /// [`Location::Accessor`]).
    ElementsOutOfView {
        /// Which elements.
        part: AccessorPart,
        /// How many.
        count: usize,
        /// Bytes per element.
        elem: usize,
        /// The stride.
        stride: usize,
        /// The byte offset in the view.
        offset: usize,
        /// The view's length.
        view_len: usize,
    },
    /// A byte stride smaller than the elements (located by [`Location::Accessor`]).
    StrideTooSmall {
        /// The stride.
        stride: usize,
        /// Bytes per element.
        elem: usize,
    },
    /// An accessor without a bufferView declaring more elements than the input has bytes
    /// (located by [`Location::Accessor`]).
    TooManyElements {
        /// Elements declared.
        count: usize,
        /// Bytes of input (file and buffers).
        input_bytes: usize,
    },
    /// More sparse values than elements (located by [`Location::Accessor`]).
    SparseCount {
        /// Sparse count.
        sparse: usize,
        /// The accessor's count.
        count: usize,
    },
    /// A sparse index past the elements (located by [`Location::Accessor`]).
    SparseIndex {
        /// The index.
        index: usize,
        /// The accessor's count.
        count: usize,
    },
}

/// A problem with a node's `EXT_mesh_gpu_instancing` member.
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum InstancingProblem {
    /// No `attributes` object.
    NoAttributesObject,
    /// An empty `attributes` object, so no instance count.
    NoAttributes,
    /// An attribute whose value is not an accessor index (name shortened to 40 characters).
    NotAnIndex {
        /// The attribute.
        attribute: String,
    },
    /// An attribute naming an accessor that does not exist.
    AccessorOutOfRange {
        /// The attribute (shortened to 40 characters).
        attribute: String,
        /// The accessor named.
        accessor: u64,
        /// How many there are.
        accessors: usize,
    },
    /// An accessor that does not exist.
    NoSuchAccessor {
        /// The accessor named.
        accessor: usize,
    },
    /// Attributes with different counts.
    CountMismatch {
        /// The first attribute.
        first: String,
        /// Its count.
        first_count: usize,
        /// The attribute that differs (shortened to 40 characters).
        attribute: String,
        /// Its count.
        count: usize,
    },
    /// An attribute accessor of a type the extension does not allow.
    AttributeType {
        /// `TRANSLATION`, `ROTATION` or `SCALE`.
        attribute: String,
        /// The accessor.
        accessor: usize,
        /// Its type (`VEC3`, …).
        dims: &'static str,
        /// Whether it is normalized.
        normalized: bool,
        /// Its component type (`FLOAT`, …).
        component: &'static str,
    },
}

/// What is wrong with an output.
#[derive(Debug)]
#[non_exhaustive]
pub enum OutputProblem {
    /// An I/O error creating, writing or renaming it.
    Io {
        /// The I/O error's kind.
        kind: io::ErrorKind,
        /// Its text.
        reason: String,
    },
    /// The output path is a directory.
    IsADirectory,
    /// The path given to `flag` is a directory (found before the run).
    FlagNamesDirectory {
        /// The flag (`-o`, `--junit`, …).
        flag: String,
    },
    /// The path given to `flag` is one of the run's inputs (the same file).
    NamesAnInput {
        /// The flag.
        flag: String,
        /// The input, as given.
        input: PathBuf,
    },
    /// Two outputs name the same file.
    SameFile {
        /// The flag.
        flag: String,
        /// The other output's flag.
        other: String,
    },
    /// The output's directory is not a directory.
    ParentNotADirectory {
        /// The directory.
        dir: PathBuf,
    },
    /// The output's directory cannot be inspected (missing, no permission).
    Directory {
        /// The directory.
        dir: PathBuf,
        /// The I/O error's kind.
        kind: io::ErrorKind,
        /// Its text.
        reason: String,
    },
    /// No file can be created in the output's directory.
    NotWritable {
        /// The directory.
        dir: PathBuf,
        /// The I/O error's kind.
        kind: io::ErrorKind,
        /// Its text.
        reason: String,
    },
}

/// What is wrong with a flag or a setting.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum UsageProblem {
    /// Not a finite number >= 0.
    NotNonNegative {
        /// The value given.
        value: f64,
    },
    /// Not a finite number > 0.
    NotPositive {
        /// The value given.
        value: f64,
    },
    /// An item of a number list that is not a finite number.
    NotANumber {
        /// The item as written.
        text: String,
    },
    /// A tolerance that is not `number` or `number` `rel`, finite and >= 0.
    BadTolerance {
        /// The value as written.
        text: String,
    },
    /// A matrix of other than 12 or 16 numbers.
    MatrixLength {
        /// How many numbers were given.
        got: usize,
    },
    /// A 4×4 matrix whose last row is not `0,0,0,1`.
    NotAffine,
    /// A translation of other than 3 numbers.
    NotATriple {
        /// How many numbers were given.
        got: usize,
    },
    /// A whole number outside `min..=max`.
    OutOfRange {
        /// The value given.
        value: u64,
        /// The least allowed.
        min: u64,
        /// The most allowed.
        max: u64,
    },
    /// A required argument is missing (`mesh A`, `clash-set FILE`).
    Missing(String),
    /// Flags or settings that do not go together; the sentence names them.
    Conflict(String),
    /// Relative tolerances overflow for the model's size.
    ToleranceOverflow,
    /// The `--cross-check parry` reference failed; parry's message.
    CrossCheck(String),
    /// A value the flag's own parser refuses (a thread pool that cannot be built, clap's
    /// message); the text is that parser's.
    Invalid(String),
    /// A problem described only by text.
    Other(String),
}

impl Error {
    /// `problem` with input file `path`, at no particular place.
    pub fn in_file(path: &Path, problem: impl Into<InputProblem>) -> Self {
        Error::located(path, None, problem)
    }

    /// `problem` at `at` in input file `path`.
    pub fn at(path: &Path, at: Location, problem: impl Into<InputProblem>) -> Self {
        Error::located(path, Some(at), problem)
    }

    /// `problem` in input file `path`, at `at` when it has a place.
    pub fn located(path: &Path, at: Option<Location>, problem: impl Into<InputProblem>) -> Self {
        Error::Input { path: path.to_path_buf(), at, problem: Box::new(problem.into()) }
    }

    /// A usage error not tied to one flag.
    pub fn usage(problem: UsageProblem) -> Self {
        Error::Usage { flag: None, problem }
    }

    /// A usage error of flag `flag` (without its leading `--`).
    pub fn bad_flag(flag: &str, problem: UsageProblem) -> Self {
        Error::Usage { flag: Some(flag.to_string()), problem }
    }

    /// `problem` writing output `path`.
    pub fn output(path: &Path, problem: OutputProblem) -> Self {
        Error::Output { path: path.to_path_buf(), problem }
    }

    /// The process exit code for this error (always [`ExitCode::Error`]: bad input, I/O or
    /// usage).
    pub fn exit_code(&self) -> ExitCode {
        ExitCode::Error
    }

    /// The file the error is about (the input or the output), if any.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Error::Input { path, .. } | Error::Output { path, .. } => Some(path),
            Error::Usage { .. } => None,
        }
    }

    /// Where in the input file the problem is, if it has a place.
    pub fn location(&self) -> Option<&Location> {
        match self {
            Error::Input { at, .. } => at.as_ref(),
            _ => None,
        }
    }

    /// The flag at fault (without `--`), for a usage error naming one.
    pub fn flag(&self) -> Option<&str> {
        match self {
            Error::Usage { flag, .. } => flag.as_deref(),
            _ => None,
        }
    }

    /// The problem of an input error.
    pub fn input_problem(&self) -> Option<&InputProblem> {
        match self {
            Error::Input { problem, .. } => Some(problem),
            _ => None,
        }
    }

    /// The problem of an output error.
    pub fn output_problem(&self) -> Option<&OutputProblem> {
        match self {
            Error::Output { problem, .. } => Some(problem),
            _ => None,
        }
    }

    /// The problem of a usage error.
    pub fn usage_problem(&self) -> Option<&UsageProblem> {
        match self {
            Error::Usage { problem, .. } => Some(problem),
            _ => None,
        }
    }

    /// True when an input could not be opened or read as a file at all (missing, no
    /// permission, a directory or device): an operating-system problem rather than bad
    /// content.
    pub fn is_unreadable_file(&self) -> bool {
        matches!(
            self.input_problem(),
            Some(
                InputProblem::Unreadable { reading: Reading::File, .. }
                    | InputProblem::NotARegularFile { .. }
            )
        )
    }

    /// The message without the `usage: ` prefix a usage error has on its own (as a clash-set
    /// check quotes it).
    fn bare(&self) -> String {
        match self {
            Error::Usage { flag, problem } => usage_text(flag.as_deref(), problem),
            other => other.to_string(),
        }
    }
}

impl From<ObjFaceProblem> for InputProblem {
    fn from(f: ObjFaceProblem) -> Self {
        InputProblem::ObjFace(f)
    }
}

impl From<GltfProblem> for InputProblem {
    fn from(p: GltfProblem) -> Self {
        InputProblem::Gltf(p)
    }
}

impl From<InstancingProblem> for InputProblem {
    fn from(p: InstancingProblem) -> Self {
        InputProblem::Gltf(GltfProblem::Instancing(p))
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Input { path, at, problem } => {
                write!(f, "{}: {}", path.display(), one_line(&input_text(at.as_ref(), problem)))
            }
            Error::Output { path, problem } => {
                write!(f, "{}: cannot write report: {}", path.display(), one_line(&problem.to_string()))
            }
            Error::Usage { flag, problem } => {
                write!(f, "usage: {}", one_line(&usage_text(flag.as_deref(), problem)))
            }
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Input { problem, .. } => match problem.as_ref() {
                InputProblem::InCheck(inner) => Some(inner.as_ref()),
                _ => None,
            },
            _ => None,
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Line(n) => write!(f, "line {n}"),
            Location::Byte(b) => write!(f, "byte {b}"),
            Location::Triangle(t) => write!(f, "triangle {t}"),
            Location::Vertex(v) => write!(f, "vertex {v}"),
            Location::Corner { triangle, corner } => write!(f, "triangle {triangle} vertex {corner}"),
            Location::Primitive { mesh, primitive } => write!(f, "mesh {mesh} primitive {primitive}"),
            Location::Index { mesh, primitive, index } => {
                write!(f, "index {index} of mesh {mesh} primitive {primitive}")
            }
            Location::Position { mesh, primitive, position } => {
                write!(f, "position {position} of mesh {mesh} primitive {primitive}")
            }
            Location::Placed { mesh, position, node, instance } => {
                write!(f, "position {position} of mesh {mesh} placed by glTF node {node}")?;
                match instance {
                    Some(k) => write!(f, " instance {k}"),
                    None => Ok(()),
                }
            }
            Location::Node(n) => write!(f, "glTF node {n}"),
            Location::Instance { node, instance } => write!(f, "glTF node {node} GPU instance {instance}"),
            Location::Accessor { accessor, user: None } => write!(f, "glTF accessor {accessor}"),
            Location::Accessor { accessor, user: Some(u) } => write!(f, "accessor {accessor} of {u}"),
            Location::Buffer(b) => write!(f, "glTF buffer {b}"),
            Location::BufferView(v) => write!(f, "glTF bufferView {v}"),
            Location::Check(CheckRef::Name(n)) => write!(f, "check '{n}'"),
            Location::Check(CheckRef::Number(i)) => write!(f, "check #{i}"),
            Location::Defaults => f.write_str("defaults"),
        }
    }
}

impl fmt::Display for AccessorUser {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AccessorUser::Primitive { mesh, primitive } => write!(f, "mesh {mesh} primitive {primitive}"),
            AccessorUser::Instancing { node } => write!(f, "node {node} EXT_mesh_gpu_instancing"),
        }
    }
}

/// `"{at}: "`, or nothing without a place.
fn prefix(at: Option<&Location>) -> String {
    at.map_or(String::new(), |a| format!("{a}: "))
}

/// The text of an OBJ face problem (after its `line N: `).
fn obj_face_text(f: &ObjFaceProblem) -> String {
    use ObjFaceProblem as F;
    match f {
        F::TooManyVertices { limit } => {
            format!("face has more than {limit} vertices, the most meshclash reads in one polygon")
        }
        F::BadIndex(t) => format!("cannot parse '{t}' as a face vertex index"),
        F::ZeroIndex => "face refers to vertex 0 (OBJ indices start at 1)".into(),
        F::BeforeFirstVertex { index, defined } => {
            format!("face refers to vertex {index} but only {defined} vertices are defined before it")
        }
        F::BeyondAnyFile { index } => format!("face refers to vertex {index}, beyond any file"),
        F::TooFewVertices { found } => format!("face has {found} vertices (needs at least 3)"),
        F::TooManyTriangles { total, limit } => {
            format!("the faces so far make {total} triangles, more than the {limit} supported")
        }
        F::BeyondLastVertex { index, vertices } => {
            format!("face refers to vertex {index} but there are {vertices} vertices")
        }
    }
}

/// The message of an input error after `path: ` (before [`one_line`]).
fn input_text(at: Option<&Location>, p: &InputProblem) -> String {
    use InputProblem as P;
    let pre = prefix(at);
    match p {
        P::Unreadable { reading, reason, .. } => match reading {
            Reading::File => format!("{pre}cannot read file: {reason}"),
            Reading::Input | Reading::ClashSet => format!("{pre}cannot read: {reason}"),
            Reading::Plan => format!("{pre}cannot read plan: {reason}"),
            Reading::ShardReport => format!("{pre}cannot read shard report: {reason}"),
            Reading::Baseline => format!("{pre}cannot read baseline: {reason}"),
            // The buffer's index is not in the message: the URI names it.
            Reading::ExternalBuffer(uri) => format!("glTF external buffer '{uri}' cannot be read: {reason}"),
        },
        P::NotARegularFile { kind } => {
            format!("not a regular file ({kind}); meshclash reads only regular files")
        }
        P::NoExtension => "no file extension (expected .obj, .stl, .gltf or .glb)".into(),
        P::UnknownExtension(ext) => {
            format!("unknown extension '.{ext}' (expected .obj, .stl, .gltf or .glb)")
        }
        P::Empty => "file is empty".into(),
        P::NotUtf8 { byte: Some(b) } => format!("{pre}not UTF-8 at byte {b}"),
        P::NotUtf8 { byte: None } => format!("{pre}not UTF-8 text"),
        P::NotText => match at {
            Some(Location::Byte(b)) => format!("not an OBJ text file: NUL byte at byte {b} (binary data)"),
            _ => format!("{pre}not an OBJ text file: NUL byte (binary data)"),
        },
        P::NotStl { looks_like } => format!("not an STL file (looks like {looks_like})"),
        P::TooShortForStl { have } => format!(
            "not an STL file: {have} bytes is too short for binary STL (needs at least 84) and it is \
             not ASCII STL"
        ),
        P::NotGltf { start } => format!(
            "not a glTF file: expected JSON starting with '{{' or the GLB magic 'glTF', found {}",
            describe_start(start)
        ),
        P::Truncated { part, declared, have } => truncated_text(at, part, *declared, *have),
        P::SizeMismatch { triangles, need, have } => format!(
            "binary STL size mismatch: header declares {triangles} triangles (needs {need} bytes) but the \
             file has {have} bytes ({} extra)",
            have.saturating_sub(*need)
        ),
        P::NoTriangles => format!("{pre}no triangles"),
        P::NonFinite { value } => match at {
            // An ASCII STL `vertex` line.
            Some(Location::Line(n)) => format!("line {n}: vertex has a non-finite coordinate ({value})"),
            Some(a) => format!("{a} has a non-finite coordinate ({value})"),
            None => format!("a coordinate is not finite ({value})"),
        },
        P::NonFiniteAfterTransform { value } => {
            let v = value.map_or(String::new(), |v| format!(" ({v})"));
            match at {
                Some(Location::Placed { mesh, position, node, instance }) => {
                    let which = instance.map_or(String::new(), |k| format!(" instance {k}"));
                    format!(
                        "position {position} of mesh {mesh} is not finite{v} after the transform of node \
                         {node}{which}"
                    )
                }
                Some(a) => format!("{a} is not finite{v} after the transform"),
                None => format!("a vertex is not finite{v} after the transform"),
            }
        }
        P::BeyondExactRange => format!(
            "{} has a coordinate beyond ±2^250 (about 1.8e75) after the transform, where verdicts stop \
             being exact",
            at.map_or("a vertex".to_string(), |a| a.to_string())
        ),
        P::IndexOutOfRange { index, len } => match at {
            Some(Location::Index { mesh, primitive, index: k }) => format!(
                "mesh {mesh} primitive {primitive}: index {k} refers to vertex {index} but there are {len} \
                 vertices"
            ),
            Some(a) => format!("{a} refers to vertex {index} but there are {len} vertices"),
            None => format!("vertex index {index} is out of range ({len} vertices)"),
        },
        P::TooLarge { quantity, count, limit } => {
            let scene = |what: &str| {
                format!("glTF scene has {count} {what} after instancing, more than the {limit} supported")
            };
            match quantity {
                Quantity::StlTriangles => format!("binary STL has {count} triangles, more than supported"),
                Quantity::Vertices => format!("{pre}more than {limit} vertices"),
                Quantity::SceneVertices => scene("vertices"),
                Quantity::SceneTriangles => scene("triangles"),
                Quantity::SceneParts => scene("parts"),
                Quantity::SelfTriangles => format!("{count} triangles: `self` handles at most {limit}"),
            }
        }
        P::NeedsMemory { triangles, need, available, per_triangle } => {
            const GIB: f64 = (1u64 << 30) as f64;
            format!(
                "glTF scene has {triangles} triangles after instancing; checking them needs about {:.1} GiB \
                 (~{per_triangle} bytes per triangle), more than the {:.1} GiB this process may use",
                *need as f64 / GIB,
                *available as f64 / GIB
            )
        }
        P::Misplaced { keyword, how } => match how {
            Misplaced::InsideFacet => format!("{pre}'{keyword}' inside a facet (missing endfacet)"),
            Misplaced::OutsideSolid => format!("{pre}'{keyword}' outside a solid"),
            Misplaced::OutsideFacet => format!("{pre}'{keyword}' outside a facet"),
            Misplaced::WithoutSolid => format!("{pre}'{keyword}' without 'solid'"),
        },
        P::UnknownKeyword(k) => format!("{pre}unexpected '{k}' in ASCII STL"),
        P::TooFewCoordinates { found } => format!("{pre}vertex has {found} coordinates (needs 3)"),
        P::BadNumber(t) => format!("{pre}cannot parse '{t}' as a vertex coordinate"),
        P::ShortFacet { start_line, vertices } => {
            format!("{pre}facet starting at line {start_line} has {vertices} vertices (needs 3)")
        }
        P::UnfinishedFacet { start_line } => {
            format!("{pre}unexpected end of file inside the facet starting at line {start_line}")
        }
        P::UnsupportedExtension(ext) => {
            let hint = match ext.as_str() {
                "KHR_draco_mesh_compression" => " (Draco-compressed geometry cannot be decoded)",
                "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
                    " (meshopt-compressed buffers cannot be decoded)"
                }
                _ => "",
            };
            format!("glTF requires extension '{ext}', which is not supported{hint}")
        }
        P::Gltf(g) => gltf_text(at, g),
        P::ChangedSincePlan { sha256, planned } => format!(
            "{pre}changed since the plan (sha256 {}…, the plan has {}…): plan again",
            head(sha256, 12),
            head(planned, 12)
        ),
        P::CoordinateBeyondExactRange { coordinate } => format!(
            "{} has coordinate {coordinate:e}, beyond ±2^250 (about 1.8e75), where verdicts stop being exact",
            at.map_or("a vertex".to_string(), |a| a.to_string())
        ),
        P::ObjNonFiniteVertex { vertex, value } => {
            format!("{pre}vertex {vertex} has a non-finite coordinate ({value})")
        }
        P::ObjFace(f) => format!("{pre}{}", obj_face_text(f)),
        P::Selection(m) | P::Syntax(m) | P::Invalid(m) => format!("{pre}{m}"),
        P::InCheck(e) => format!("{pre}{}", e.bare()),
        P::Internal(m) => format!("{pre}internal loader error: {m}"),
    }
}

/// The first `n` characters of `s`.
fn head(s: &str, n: usize) -> &str {
    s.char_indices().nth(n).map_or(s, |(i, _)| &s[..i])
}

/// The first bytes of a file for a message: as text when printable, else in hex.
fn describe_start(head: &[u8]) -> String {
    let head = &head[..head.len().min(8)];
    if head.iter().all(|b| b.is_ascii_graphic() || *b == b' ') {
        format!("'{}'", String::from_utf8_lossy(head))
    } else {
        let hex: Vec<String> = head.iter().map(|b| format!("{b:02x}")).collect();
        format!("bytes {}", hex.join(" "))
    }
}

fn truncated_text(at: Option<&Location>, part: &Part, declared: u64, have: u64) -> String {
    let buffer = match at {
        Some(Location::Buffer(i)) => i.to_string(),
        _ => "?".to_string(),
    };
    match part {
        Part::StlFacets { triangles } => format!(
            "truncated binary STL: header declares {triangles} triangles (needs {declared} bytes) but the \
             file has {have} bytes"
        ),
        Part::GlbHeader => format!("truncated GLB: {have} bytes, the header alone needs {declared}"),
        Part::Glb => {
            format!("truncated GLB: header declares {declared} bytes but the file has {have} bytes")
        }
        Part::GlbChunkHeader { chunk } => match at {
            Some(Location::Byte(b)) => format!("truncated GLB: chunk {chunk} header at byte {b} is cut off"),
            _ => format!("truncated GLB: chunk {chunk} header is cut off"),
        },
        Part::GlbChunk { chunk, kind } => format!(
            "truncated GLB: chunk {chunk} ('{kind}') declares {declared} bytes but only {have} remain"
        ),
        Part::BinChunk => format!(
            "glTF buffer {buffer} declares {declared} bytes but the GLB binary chunk has {have} bytes"
        ),
        Part::DataUri => {
            format!("glTF buffer {buffer} declares {declared} bytes but its data URI has {have} bytes")
        }
        Part::ExternalFile(uri) => {
            format!("glTF external buffer '{uri}' has {have} bytes but buffer {buffer} declares {declared}")
        }
        Part::ExternalFileRead(uri) => {
            format!("glTF external buffer '{uri}' shrank while reading: {have} of {declared} bytes")
        }
    }
}

fn gltf_text(at: Option<&Location>, g: &GltfProblem) -> String {
    use GltfProblem as G;
    let pre = prefix(at);
    // The glTF messages name their place in their own words; `pre` serves a place of an
    // unexpected kind.
    let node = |s: &str| match at {
        Some(Location::Node(n)) => format!("glTF node {n}{s}"),
        _ => format!("{pre}glTF node{s}"),
    };
    let buffer = |s: &str| match at {
        Some(Location::Buffer(i)) => format!("glTF buffer {i} {s}"),
        _ => format!("{pre}glTF buffer {s}"),
    };
    // "accessor A of USER" (`label`) and "ROLE accessor of USER" (`role`).
    let (label, user) = match at {
        Some(Location::Accessor { accessor, user: Some(u) }) => {
            (format!("accessor {accessor} of {u}"), u.to_string())
        }
        Some(a) => (a.to_string(), a.to_string()),
        None => ("accessor".to_string(), "?".to_string()),
    };
    match g {
        G::Json(m) => format!("{pre}invalid glTF JSON: {m}"),
        G::Invalid(m) if m.is_empty() => format!("{pre}invalid glTF"),
        G::Invalid(m) => format!("{pre}invalid glTF: {m}"),
        G::NotGlb => "not a GLB file: missing 'glTF' magic".into(),
        G::GlbVersion(v) => format!("GLB version {v} is not supported (expected 2)"),
        G::FirstChunkNotJson => "GLB first chunk is not JSON".into(),
        G::NoJsonChunk => "GLB has no JSON chunk".into(),
        G::NoAccessorData { extensions_used } => {
            let by = if extensions_used.is_empty() { "none".to_string() } else { extensions_used.join(", ") };
            let a = match at {
                Some(Location::Accessor { accessor, .. }) => format!("glTF accessor {accessor}"),
                _ => format!("{pre}glTF accessor"),
            };
            format!(
                "{a} has no data (neither bufferView nor sparse values): it would come from an extension \
                 that is not supported (extensions used: {by})"
            )
        }
        G::NoPositionAccessor { accessor, accessors } => format!(
            "invalid glTF: {} uses POSITION accessor {accessor} but there are {accessors} accessors",
            at.map_or("a primitive".to_string(), |a| a.to_string())
        ),
        G::Instancing(i) => node(&format!(": EXT_mesh_gpu_instancing {}", instancing_text(i))),
        G::InstanceNotFinite { attribute, value } => {
            format!("{pre}{attribute} is not finite ({value})")
        }
        G::ZeroQuaternion => match at {
            Some(Location::Instance { .. }) => format!("{pre}ROTATION is a zero quaternion"),
            _ => node(" has a zero rotation quaternion"),
        },
        G::NonFiniteTransform { matrix: true } => node(" has a non-finite matrix"),
        G::NonFiniteTransform { matrix: false } => node(" has a non-finite translation, rotation or scale"),
        G::WorldOverflow => match at {
            Some(Location::Instance { node, instance }) => format!(
                "glTF node {node}: world transform of GPU instance {instance} is not finite (overflow)"
            ),
            _ => node(": world transform is not finite (overflow)"),
        },
        G::ChildTwice { child } => node(&format!(" lists child {child} twice")),
        G::TwoParents { first, second } => node(&format!(" has two parents (nodes {first} and {second})")),
        G::Cycle => match at {
            Some(Location::Node(n)) => format!("glTF node graph has a cycle at node {n}"),
            _ => format!("{pre}glTF node graph has a cycle"),
        },
        G::RootIsChild { parent } => node(&format!(" is a scene root but also a child of node {parent}")),
        G::RootListedTwice => match at {
            Some(Location::Node(n)) => format!("glTF scene lists node {n} twice"),
            _ => format!("{pre}glTF scene lists a node twice"),
        },
        G::TooDeep { limit } => match at {
            Some(Location::Node(n)) => {
                format!("glTF node hierarchy deeper than {limit} levels (at node {n})")
            }
            _ => format!("{pre}glTF node hierarchy deeper than {limit} levels"),
        },
        G::NoBinChunk => buffer("refers to the GLB binary chunk but there is none"),
        G::BadDataUri(m) => buffer(&format!("data URI is invalid: {m}")),
        G::UriRefused { uri, reason } => buffer(&format!(
            "URI '{uri}' is refused: {reason} (only data: URIs and relative paths inside the glTF's \
             directory are read)"
        )),
        G::UriNotUtf8 { uri } => buffer(&format!("URI '{uri}' is not valid UTF-8 when percent-decoded")),
        G::AccessorType { role, found } => match role {
            AccessorRole::Positions => format!("positions accessor of {user} has type {found} (expected VEC3)"),
            AccessorRole::Indices => format!("indices accessor of {user} has type {found} (expected SCALAR)"),
        },
        G::ComponentType { role, found } => match role {
            AccessorRole::Positions => format!(
                "positions accessor of {user} uses component type {found} (expected FLOAT, or BYTE, \
                 UNSIGNED_BYTE, SHORT or UNSIGNED_SHORT with KHR_mesh_quantization)"
            ),
            AccessorRole::Indices => format!(
                "indices accessor of {user} uses component type {found} (expected UNSIGNED_BYTE, \
                 UNSIGNED_SHORT or UNSIGNED_INT)"
            ),
        },
        G::ViewOutOfBuffer { offset, length, buffer, buffer_len } => {
            let view = match at {
                Some(Location::BufferView(v)) => format!("glTF bufferView {v}"),
                _ => format!("{pre}glTF bufferView"),
            };
            format!(
                "{view} (offset {offset}, length {length}) does not fit in buffer {buffer} ({buffer_len} bytes)"
            )
        }
        G::ElementsOutOfView { part, count, elem, stride, offset, view_len } => {
            let which = match part {
                AccessorPart::Elements => "",
                AccessorPart::SparseIndices => " sparse indices",
                AccessorPart::SparseValues => " sparse values",
            };
            format!(
                "{label}{which}: {count} elements of {elem} bytes (stride {stride}) from offset {offset} do \
                 not fit in its bufferView of {view_len} bytes"
            )
        }
        G::StrideTooSmall { stride, elem } => {
            format!("{label}: byteStride {stride} is smaller than its {elem}-byte elements")
        }
        G::TooManyElements { count, input_bytes } => format!(
            "{label} declares {count} elements without a bufferView, more than the {input_bytes} bytes of input"
        ),
        G::SparseCount { sparse, count } => {
            format!("{label}: sparse count {sparse} exceeds the accessor count {count}")
        }
        G::SparseIndex { index, count } => {
            format!("{label}: sparse index {index} is out of range ({count} elements)")
        }
    }
}

fn instancing_text(i: &InstancingProblem) -> String {
    use InstancingProblem as I;
    match i {
        I::NoAttributesObject => "has no 'attributes' object".into(),
        I::NoAttributes => "has no attributes, so no instance count".into(),
        I::NotAnIndex { attribute } => format!("attribute {attribute} is not an accessor index"),
        I::AccessorOutOfRange { attribute, accessor, accessors } => {
            format!("attribute {attribute} uses accessor {accessor} but there are {accessors} accessors")
        }
        I::NoSuchAccessor { accessor } => format!("accessor {accessor} does not exist"),
        I::CountMismatch { first, first_count, attribute, count } => {
            format!("attributes have different counts ({first}: {first_count}, {attribute}: {count})")
        }
        I::AttributeType { attribute, accessor, dims, normalized, component } => {
            let expected = match attribute.as_str() {
                "ROTATION" => "VEC4 of FLOAT, or of normalized BYTE or SHORT",
                _ => "VEC3 of FLOAT",
            };
            let n = if *normalized { "normalized " } else { "" };
            format!("{attribute} accessor {accessor} is {dims} of {n}{component} (expected {expected})")
        }
    }
}

impl fmt::Display for OutputProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OutputProblem::Io { reason, .. } => f.write_str(reason),
            OutputProblem::IsADirectory => f.write_str("is a directory"),
            OutputProblem::FlagNamesDirectory { flag } => write!(f, "{flag} names a directory"),
            OutputProblem::NamesAnInput { flag, input } => write!(
                f,
                "{flag} names the input {} (the same file); refusing to overwrite an input",
                input.display()
            ),
            OutputProblem::SameFile { flag, other } => write!(f, "{flag} names the same file as {other}"),
            OutputProblem::ParentNotADirectory { dir } => write!(f, "{} is not a directory", dir.display()),
            OutputProblem::Directory { dir, reason, .. } => {
                write!(f, "directory {}: {reason}", dir.display())
            }
            OutputProblem::NotWritable { dir, reason, .. } => {
                write!(f, "directory {} is not writable: {reason}", dir.display())
            }
        }
    }
}

/// The message of a usage error after `usage: ` (before [`one_line`]).
fn usage_text(flag: Option<&str>, p: &UsageProblem) -> String {
    use UsageProblem as U;
    let name = flag.map_or("the value".to_string(), |f| format!("--{f}"));
    let mut s = String::new();
    let _ = match p {
        U::NotNonNegative { value } => write!(s, "{name} must be a finite number >= 0, got {value}"),
        U::NotPositive { value } => write!(s, "{name} must be a finite number > 0, got {value}"),
        U::NotANumber { text } => write!(s, "{name}: '{text}' is not a finite number"),
        U::BadTolerance { text } => write!(
            s,
            "{name} must be a finite number >= 0, optionally with a 'rel' suffix (e.g. 0.01 or 1e-6rel), got \
             '{text}'"
        ),
        U::MatrixLength { got } => write!(s, "{name} takes 12 or 16 numbers, got {got}"),
        U::NotAffine => write!(s, "{name}: the last row must be 0,0,0,1 (affine only)"),
        U::NotATriple { got } => write!(s, "{name} takes x,y,z, got {got} numbers"),
        U::OutOfRange { value, min, max } => write!(s, "{name} must be {min}..={max}, got {value}"),
        U::Missing(what) => write!(s, "missing {what}"),
        U::Conflict(m) | U::Other(m) => s.write_str(m),
        U::ToleranceOverflow => s.write_str("relative tolerance overflows for this model size"),
        U::CrossCheck(m) => write!(s, "--cross-check parry: {m}"),
        U::Invalid(m) => match flag {
            Some(f) => write!(s, "--{f}: {m}"),
            None => s.write_str(m),
        },
    };
    s
}

/// Messages from third-party parsers may span lines; the contract is one line.
fn one_line(s: &str) -> String {
    s.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The process exit codes, the contract with CI scripts.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitCode {
    /// 0: nothing at or above `--fail-on`.
    Ok = 0,
    /// 1: findings at or above `--fail-on`.
    Findings = 1,
    /// 2: bad input, I/O or usage error.
    Error = 2,
}

impl ExitCode {
    /// [`ExitCode::Findings`] if the run failed its `--fail-on`, else [`ExitCode::Ok`].
    pub fn from_failed(failed: bool) -> Self {
        if failed {
            ExitCode::Findings
        } else {
            ExitCode::Ok
        }
    }

    /// The number.
    pub fn code(self) -> u8 {
        self as u8
    }
}

impl From<ExitCode> for std::process::ExitCode {
    fn from(c: ExitCode) -> Self {
        std::process::ExitCode::from(c.code())
    }
}

/// Shorthand for results in this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Shortens `s` to at most `max` characters for a message, adding `…` when cut; control
/// characters (NUL, tabs, …) are shown as `?` so the message stays one printable line.
pub(crate) fn clip(s: &str, max: usize) -> String {
    let mut out: String = s.chars().take(max).map(|c| if c.is_control() { '?' } else { c }).collect();
    if s.chars().nth(max).is_some() {
        out.push('…');
    }
    out
}

#[cfg(test)]
mod tests {
    //! The errors as data: each case checks the structured fields (path, location, problem)
    //! and the one line `Display` makes of them, which is the command line's message.

    use super::*;
    use crate::load::{load_bytes, load_path, Format};
    use base64::Engine as _;

    fn load_err(name: &str, bytes: &[u8], format: Format) -> Error {
        let path = Path::new(name);
        match crate::load::detect_format(path, bytes) {
            Err(e) => e,
            Ok(f) => {
                assert_eq!(f, format);
                load_bytes(path, bytes, f).unwrap_err()
            }
        }
    }

    /// A binary STL of `tris`.
    fn binary_stl(tris: &[[[f32; 3]; 3]]) -> Vec<u8> {
        let mut b = vec![0u8; 80];
        b.extend_from_slice(&(tris.len() as u32).to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for c in t.iter().flatten() {
                b.extend_from_slice(&c.to_le_bytes());
            }
            b.extend_from_slice(&[0, 0]);
        }
        b
    }

    const TRI: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

    #[test]
    fn truncated_stl_carries_the_byte_counts_and_the_path() {
        let mut b = binary_stl(&[TRI, TRI]);
        b.pop();
        let e = load_err("dir/t.stl", &b, Format::Stl);
        assert_eq!(e.path(), Some(Path::new("dir/t.stl")));
        assert_eq!(e.location(), None);
        match e.input_problem() {
            Some(InputProblem::Truncated {
                part: Part::StlFacets { triangles: 2 },
                declared: 184,
                have: 183,
            }) => {}
            other => panic!("{other:?}"),
        }
        assert_eq!(
            e.to_string(),
            "dir/t.stl: truncated binary STL: header declares 2 triangles (needs 184 bytes) but the file has \
             183 bytes"
        );
        assert_eq!(e.exit_code(), ExitCode::Error);
    }

    #[test]
    fn stl_coordinates_and_lines_are_locations() {
        let mut t = [TRI, TRI];
        t[1][2][0] = f32::INFINITY;
        let e = load_err("t.stl", &binary_stl(&t), Format::Stl);
        assert_eq!(e.location(), Some(&Location::Corner { triangle: 1, corner: 2 }));
        assert!(matches!(e.input_problem(), Some(InputProblem::NonFinite { value: NonFinite::Inf })));
        assert_eq!(e.to_string(), "t.stl: triangle 1 vertex 2 has a non-finite coordinate (inf)");

        let ascii = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 zz 0\nvertex 0 1 0\n\
                     endloop\nendfacet\nendsolid\n";
        let e = load_err("a.stl", ascii.as_bytes(), Format::Stl);
        assert_eq!(e.location(), Some(&Location::Line(5)));
        assert!(matches!(e.input_problem(), Some(InputProblem::BadNumber(s)) if s == "zz"));
        assert_eq!(e.to_string(), "a.stl: line 5: cannot parse 'zz' as a vertex coordinate");

        let e = load_err("a.stl", ascii.replace("outer loop", "endfacet").as_bytes(), Format::Stl);
        assert_eq!(e.location(), Some(&Location::Line(3)));
        assert!(matches!(e.input_problem(), Some(InputProblem::ShortFacet { start_line: 2, vertices: 0 })));
        assert_eq!(e.to_string(), "a.stl: line 3: facet starting at line 2 has 0 vertices (needs 3)");
    }

    #[test]
    fn glb_framing_and_unreadable_files() {
        let e = load_err("x.glb", b"glTF\x02\0\0", Format::Glb);
        assert!(matches!(
            e.input_problem(),
            Some(InputProblem::Truncated { part: Part::GlbHeader, declared: 12, have: 7 })
        ));
        assert_eq!(e.to_string(), "x.glb: truncated GLB: 7 bytes, the header alone needs 12");

        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("gone.obj");
        let e = load_path(&missing).unwrap_err();
        assert!(e.is_unreadable_file());
        assert!(matches!(
            e.input_problem(),
            Some(InputProblem::Unreadable { reading: Reading::File, kind: io::ErrorKind::NotFound, .. })
        ));
        assert_eq!(
            e.to_string(),
            format!("{}: cannot read file: No such file or directory", missing.display())
        );
        let e = load_path(dir.path()).unwrap_err();
        assert!(e.is_unreadable_file());
        assert!(matches!(
            e.input_problem(),
            Some(InputProblem::NotARegularFile { kind: FileKind::Directory })
        ));
    }

    /// A one-triangle glTF (positions VEC3 `dims`, indices `idx`) with its buffer in a data URI.
    fn gltf(dims: &str, idx: [u16; 3]) -> Vec<u8> {
        let mut bin: Vec<u8> =
            [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0].iter().flat_map(|x| x.to_le_bytes()).collect();
        for i in idx {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        bin.extend_from_slice(&[0, 0]);
        let b64 = base64::engine::general_purpose::STANDARD.encode(&bin);
        format!(
            r#"{{"asset":{{"version":"2.0"}},
  "buffers":[{{"byteLength":44,"uri":"data:application/octet-stream;base64,{b64}"}}],
  "bufferViews":[{{"buffer":0,"byteLength":36}},{{"buffer":0,"byteOffset":36,"byteLength":6}}],
  "accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"{dims}","min":[0,0,0],"max":[1,1,0]}},
    {{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"}}],
  "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1}}]}}],
  "nodes":[{{"mesh":0}}], "scenes":[{{"nodes":[0]}}]}}"#
        )
        .into_bytes()
    }

    #[test]
    fn gltf_indices_and_accessors_are_locations() {
        let e = load_err("t.gltf", &gltf("VEC3", [0, 1, 7]), Format::Gltf);
        assert_eq!(e.location(), Some(&Location::Index { mesh: 0, primitive: 0, index: 2 }));
        assert!(matches!(e.input_problem(), Some(InputProblem::IndexOutOfRange { index: 7, len: 3 })));
        assert_eq!(
            e.to_string(),
            "t.gltf: mesh 0 primitive 0: index 2 refers to vertex 7 but there are 3 vertices"
        );

        let e = load_err("t.gltf", &gltf("VEC2", [0, 1, 2]), Format::Gltf);
        let user = Some(AccessorUser::Primitive { mesh: 0, primitive: 0 });
        assert_eq!(e.location(), Some(&Location::Accessor { accessor: 0, user }));
        assert!(matches!(
            e.input_problem(),
            Some(InputProblem::Gltf(GltfProblem::AccessorType {
                role: AccessorRole::Positions,
                found: "VEC2"
            }))
        ));
        assert_eq!(
            e.to_string(),
            "t.gltf: positions accessor of mesh 0 primitive 0 has type VEC2 (expected VEC3)"
        );
    }

    #[test]
    fn usage_errors_name_their_flag() {
        let e = crate::api::Tolerance::parse("touch-tolerance", "1e-3 rel!").unwrap_err();
        assert_eq!(e.flag(), Some("touch-tolerance"));
        assert_eq!(e.path(), None);
        assert!(
            matches!(e.usage_problem(), Some(UsageProblem::BadTolerance { text }) if text == "1e-3 rel!")
        );
        assert_eq!(
            e.to_string(),
            "usage: --touch-tolerance must be a finite number >= 0, optionally with a 'rel' suffix (e.g. 0.01 \
             or 1e-6rel), got '1e-3 rel!'"
        );
        let e = Error::bad_flag("leaf-size", UsageProblem::OutOfRange { value: 0, min: 1, max: 64 });
        assert_eq!(e.to_string(), "usage: --leaf-size must be 1..=64, got 0");
        assert_eq!(Error::usage(UsageProblem::Missing("mesh A".into())).to_string(), "usage: missing mesh A");
    }

    #[test]
    fn output_errors_carry_the_flag_and_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let e = crate::output::write::check_outputs(&[("--junit", dir.path())], &[]).unwrap_err();
        assert_eq!(e.path(), Some(dir.path()));
        assert!(
            matches!(e.output_problem(), Some(OutputProblem::FlagNamesDirectory { flag }) if flag == "--junit")
        );
        assert_eq!(
            e.to_string(),
            format!("{}: cannot write report: --junit names a directory", dir.path().display())
        );
    }

    #[test]
    fn a_check_of_a_clash_set_wraps_its_own_error() {
        let inner = Error::bad_flag("clearance", UsageProblem::NotNonNegative { value: -1.0 });
        let e = Error::at(
            Path::new("set.json"),
            Location::Check(CheckRef::Name("c".into())),
            InputProblem::InCheck(Box::new(inner)),
        );
        // The check quotes a usage error without its `usage: ` prefix, any other error whole.
        assert_eq!(e.to_string(), "set.json: check 'c': --clearance must be a finite number >= 0, got -1");
        let source = std::error::Error::source(&e).unwrap().downcast_ref::<Error>().unwrap();
        assert_eq!(source.flag(), Some("clearance"));
        let inner = Error::in_file(Path::new("m.stl"), InputProblem::NoTriangles);
        let e = Error::at(
            Path::new("set.json"),
            Location::Check(CheckRef::Number(2)),
            InputProblem::InCheck(Box::new(inner)),
        );
        assert_eq!(e.to_string(), "set.json: check #2: m.stl: no triangles");
    }

    #[test]
    fn the_error_stays_small() {
        // The `Err` of every `Result` in the crate: the input problem is boxed.
        assert!(std::mem::size_of::<Error>() <= 10 * std::mem::size_of::<usize>());
    }

    #[test]
    fn messages_stay_one_line() {
        // Third-party text may span lines; the message may not.
        let e = Error::in_file(Path::new("g.gltf"), GltfProblem::Json("expected value\n  at line 1".into()));
        assert_eq!(e.to_string(), "g.gltf: invalid glTF JSON: expected value at line 1");
        let e = Error::in_file(Path::new("p"), InputProblem::Syntax("third  party\ttext".into()));
        assert_eq!(e.to_string(), "p: third party text");
        let e = Error::output(
            Path::new("o"),
            OutputProblem::Io { kind: io::ErrorKind::Other, reason: "a\nb".into() },
        );
        assert_eq!(e.to_string(), "o: cannot write report: a b");
    }
}
