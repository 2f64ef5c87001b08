//! Error values of the collision crate.

use std::path::PathBuf;

use thiserror::Error;

/// A triangle mesh (from an OBJ file or from memory) that cannot be used as a collider.
#[derive(Debug, Error)]
pub enum MeshError {
    /// The file could not be read.
    #[error("cannot read mesh file `{path}`: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying I/O error.
        source: std::io::Error,
    },
    /// A line of the OBJ file could not be parsed.
    #[error("{path}:{line}: malformed OBJ line: {reason}")]
    Malformed {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        reason: String,
    },
    /// A vertex coordinate is NaN or infinite.
    #[error(
        "{path}:{line}: vertex {} (OBJ counts from 1) has a non-finite coordinate",
        .vertex + 1
    )]
    NonFiniteVertex {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// 1-based line number (0 for meshes built in memory).
        line: usize,
        /// 0-based vertex index.
        vertex: usize,
    },
    /// A face refers to a vertex that does not exist.
    #[error(
        "{path}:{line}: face uses vertex {} (OBJ counts from 1), but only {vertices} vertices \
         are defined",
        .index + 1
    )]
    IndexOutOfRange {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// 1-based line number (0 for meshes built in memory).
        line: usize,
        /// The 0-based index given.
        index: i64,
        /// Vertices defined so far.
        vertices: usize,
    },
    /// A triangle has (nearly) zero area or repeats a vertex.
    #[error("{path}:{line}: triangle {triangle} is degenerate (zero area or repeated vertex)")]
    DegenerateTriangle {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// 1-based line number of its face (0 for meshes built in memory).
        line: usize,
        /// 0-based triangle index.
        triangle: usize,
    },
    /// More than two triangles share one edge.
    #[error(
        "{path}:{line}: edge {}-{} (vertices counted from 1) is shared by more than two \
         triangles (non-manifold mesh)",
        u64::from(*.a) + 1,
        u64::from(*.b) + 1
    )]
    NonManifoldEdge {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// 1-based line number of the third face on the edge (0 for meshes built in memory).
        line: usize,
        /// One end of the edge (0-based vertex index).
        a: u32,
        /// The other end.
        b: u32,
    },
    /// The mesh has no face.
    #[error("{path}: mesh has no faces")]
    Empty {
        /// The file (or `<memory>`).
        path: PathBuf,
    },
    /// parry rejected the mesh.
    #[error("{path}: parry rejected the triangle mesh: {reason}")]
    Parry {
        /// The file (or `<memory>`).
        path: PathBuf,
        /// parry's message.
        reason: String,
    },
}

/// A collider shape or collider description that cannot be built.
#[derive(Debug, Error)]
pub enum ShapeError {
    /// A size, radius or coefficient is not finite or out of range.
    #[error("collider parameter `{name}` = {value} is invalid: {expected}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// Fewer than four affinely independent points for a convex hull.
    #[error("convex hull of {points} points is degenerate (need 4 non-coplanar finite points)")]
    DegenerateHull {
        /// Number of points given.
        points: usize,
    },
    /// A compound with no parts.
    #[error("a compound collider needs at least one part")]
    EmptyCompound,
    /// A triangle mesh or half-space inside a compound (parry nests no composite shapes, and a
    /// half-space has no finite bounds for the compound's BVH).
    #[error("part {part} of a compound is a {kind}; add it as its own collider")]
    UnsupportedInCompound {
        /// Index of the offending part (after flattening nested compounds).
        part: usize,
        /// What it is.
        kind: &'static str,
    },
    /// The triangle mesh is bad.
    #[error(transparent)]
    Mesh(#[from] MeshError),
}

/// Anything that can go wrong while setting up collisions.
#[derive(Debug, Error)]
pub enum CollideError {
    /// A collider cannot be built.
    #[error(transparent)]
    Shape(#[from] ShapeError),
    /// A mesh cannot be loaded.
    #[error(transparent)]
    Mesh(#[from] MeshError),
    /// A self-collision or world parameter is out of range.
    #[error("parameter `{name}` = {value} is invalid: {expected}")]
    InvalidParameter {
        /// Name of the parameter.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        expected: &'static str,
    },
    /// A cloth index that does not exist.
    #[error("cloth {index} does not exist (the solver has {count})")]
    NoSuchCloth {
        /// The index given.
        index: usize,
        /// Number of cloths.
        count: usize,
    },
    /// The solver could not be built or stepped (scenarios).
    #[error("solver: {0}")]
    Solver(String),
}
