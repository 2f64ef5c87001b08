//! Errors of the crate, each naming where the problem is (line, joint, frame, shape and key).

use thiserror::Error;

/// A skeleton that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SkeletonError {
    /// No joint at all.
    #[error("the skeleton has no joint")]
    Empty,
    /// Joint 0 names a parent.
    #[error("root joint `{0}` has a parent")]
    RootHasParent(String),
    /// A second joint without parent.
    #[error("joint `{0}` is a second root")]
    SecondRoot(String),
    /// A parent listed after its child.
    #[error("joint `{joint}` has parent index {parent}, which is not listed before it")]
    ParentAfterChild {
        /// The child.
        joint: String,
        /// The parent's index.
        parent: usize,
    },
    /// Two joints with one name.
    #[error("two joints are called `{0}`")]
    DuplicateName(String),
    /// An offset with NaN or infinity.
    #[error("joint `{0}` has a non-finite offset")]
    NonFiniteOffset(String),
}

/// A clip that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ClipError {
    /// Frame time not finite and positive.
    #[error("frame time must be finite and positive, got {0}")]
    FrameTime(f64),
    /// No frame.
    #[error("a clip needs at least one frame")]
    NoFrames,
    /// A frame whose joint count differs from the skeleton's.
    #[error("frame {frame} has {found} joints, the skeleton has {expected}")]
    JointCount {
        /// Frame index.
        frame: usize,
        /// Joints in the frame.
        found: usize,
        /// Joints in the skeleton.
        expected: usize,
    },
    /// A frame with a non-finite value or a rotation that is not a unit quaternion.
    #[error("frame {frame} has a non-finite value or a non-unit rotation")]
    NotFinite {
        /// Frame index.
        frame: usize,
    },
}

/// A BVH text that cannot be read; every variant names its line (1-based).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BvhError {
    /// The text ends where more was expected.
    #[error("line {line}: the file ends where {expected} was expected")]
    Truncated {
        /// Last line of the text.
        line: usize,
        /// What was expected.
        expected: &'static str,
    },
    /// A token other than the one expected.
    #[error("line {line}: expected {expected}, found `{found}`")]
    Expected {
        /// Line of the token.
        line: usize,
        /// What was expected.
        expected: &'static str,
        /// What was found.
        found: String,
    },
    /// A channel name other than X/Y/Z position/rotation.
    #[error(
        "line {line}: unknown channel `{name}` (expected Xposition, Yposition, Zposition, \
         Xrotation, Yrotation or Zrotation)"
    )]
    UnknownChannel {
        /// Line of the CHANNELS statement.
        line: usize,
        /// The unknown name.
        name: String,
    },
    /// A channel listed twice for one joint.
    #[error("line {line}: channel `{name}` is listed twice")]
    RepeatedChannel {
        /// Line of the CHANNELS statement.
        line: usize,
        /// The repeated name.
        name: String,
    },
    /// A number that does not parse or is not finite.
    #[error("line {line}: `{token}` is not a finite number")]
    NotANumber {
        /// Line of the token.
        line: usize,
        /// The token.
        token: String,
    },
    /// A count (channels, frames) that is not a non-negative integer.
    #[error("line {line}: `{token}` is not a non-negative whole number")]
    NotACount {
        /// Line of the token.
        line: usize,
        /// The token.
        token: String,
    },
    /// A joint block that is never closed.
    #[error("line {line}: `{joint}` opened here has no closing `}}`")]
    MissingBrace {
        /// Line where the joint's block was opened.
        line: usize,
        /// The joint.
        joint: String,
    },
    /// Two joints with one name.
    #[error("line {line}: a second joint is called `{name}`")]
    DuplicateJoint {
        /// Line of the second declaration.
        line: usize,
        /// The name.
        name: String,
    },
    /// `Frames: 0`.
    #[error("line {line}: the clip has no frame (Frames: 0)")]
    ZeroFrames {
        /// Line of `Frames:`.
        line: usize,
    },
    /// A frame time that is zero, negative or not finite.
    #[error("line {line}: Frame Time must be positive, got {value}")]
    FrameTime {
        /// Line of `Frame Time:`.
        line: usize,
        /// The value.
        value: f64,
    },
    /// A frame line with the wrong number of values.
    #[error(
        "line {line}: frame {frame} has {found} values, the hierarchy declares {expected} channels"
    )]
    FrameValues {
        /// Line of the frame.
        line: usize,
        /// Frame index (0-based).
        frame: usize,
        /// Values on the line.
        found: usize,
        /// Channels declared.
        expected: usize,
    },
    /// Fewer frame lines than `Frames:` announces.
    #[error("line {line}: the file ends after {found} frames, `Frames:` announces {expected}")]
    MissingFrames {
        /// Last line of the text.
        line: usize,
        /// Frames read.
        found: usize,
        /// Frames announced.
        expected: usize,
    },
    /// Joints nested deeper than [`MAX_JOINT_DEPTH`](crate::bvh::MAX_JOINT_DEPTH).
    #[error("line {line}: joints are nested more than {limit} levels deep below the root")]
    TooDeep {
        /// Line of the joint past the limit.
        line: usize,
        /// The limit.
        limit: usize,
    },
    /// Text after the last announced frame.
    #[error("line {line}: text after the {frames} frames that `Frames:` announces")]
    ExtraData {
        /// Line of the extra text.
        line: usize,
        /// Frames announced.
        frames: usize,
    },
    /// A scale option that is not finite and positive.
    #[error("the BVH scale must be finite and positive, got {0}")]
    Scale(f64),
    /// The hierarchy does not make a skeleton.
    #[error(transparent)]
    Skeleton(#[from] SkeletonError),
    /// The frames do not make a clip.
    #[error(transparent)]
    Clip(#[from] ClipError),
}

/// A body table that cannot be read or does not fit its skeleton.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BodyError {
    /// The text is not valid TOML or not a body table.
    #[error("{}{message}", at(.line))]
    Toml {
        /// 1-based line, when known.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// A shape entry that cannot be built.
    #[error("{}shape {index} (bone `{bone}`), key `{key}`: {message}", at(.line))]
    Shape {
        /// 1-based line of the key (or of the shape), when known.
        line: Option<usize>,
        /// 1-based index of the shape in the table.
        index: usize,
        /// The shape's bone.
        bone: String,
        /// The key at fault.
        key: &'static str,
        /// What is wrong.
        message: String,
    },
}

fn at(line: &Option<usize>) -> String {
    line.map(|l| format!("line {l}: ")).unwrap_or_default()
}

/// Cloth vertices that cannot be attached to a bone.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum AttachError {
    /// A vertex index past the end of the positions.
    #[error("vertex {vertex} is out of range ({len} vertices)")]
    VertexOutOfRange {
        /// The vertex.
        vertex: u32,
        /// Number of positions.
        len: usize,
    },
    /// A vertex with a non-finite position.
    #[error("vertex {vertex} has a non-finite position")]
    NonFinite {
        /// The vertex.
        vertex: u32,
    },
    /// A bone index past the end of the skeleton.
    #[error("bone {bone} is out of range ({len} bones)")]
    BoneOutOfRange {
        /// The bone.
        bone: usize,
        /// Number of bones.
        len: usize,
    },
}
