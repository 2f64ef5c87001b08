//! A node of the binary bounding-volume hierarchy, as the hierarchy ([`super::bvh`]) builds it
//! and its four-wide copy ([`super::wide_bvh`]) reads it.

use glam::DVec3;

/// A node: its box and either two children (`count == 0`: nodes `first` and `first + 1`) or
/// a leaf's primitives `first .. first + count`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Node {
    /// Minimum corner.
    pub lo: DVec3,
    /// Maximum corner.
    pub hi: DVec3,
    /// First child, or first primitive of a leaf.
    pub first: u32,
    /// Primitives of a leaf; 0 for an inner node.
    pub count: u32,
}
