//! A joint hierarchy: names, parents and rest offsets, and forward kinematics over a pose.

use glam::DVec3;

use crate::error::SkeletonError;
use crate::pose::Pose;
use crate::transform::Transform;

/// One joint: its name, its parent and its rest offset from the parent (m, parent frame).
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name, unique in its skeleton (BVH end sites are named `<parent>_End`).
    pub name: String,
    /// Index of the parent joint; `None` for the root.
    pub parent: Option<usize>,
    /// Rest offset from the parent joint, in the parent's frame (m).
    pub offset: DVec3,
    /// Whether this is a BVH "End Site": a leaf that only marks where its parent bone ends.
    pub end_site: bool,
}

/// Joints in an order where every parent comes before its children; joint 0 is the root.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    joints: Vec<Joint>,
}

impl Skeleton {
    /// Builds a skeleton, checking: at least one joint, exactly one root (joint 0), parents
    /// listed before children, unique names, finite offsets.
    pub fn new(joints: Vec<Joint>) -> Result<Self, SkeletonError> {
        if joints.is_empty() {
            return Err(SkeletonError::Empty);
        }
        for (i, j) in joints.iter().enumerate() {
            match (i, j.parent) {
                (0, None) => {}
                (0, Some(_)) => return Err(SkeletonError::RootHasParent(j.name.clone())),
                (_, None) => return Err(SkeletonError::SecondRoot(j.name.clone())),
                (_, Some(p)) if p >= i => {
                    return Err(SkeletonError::ParentAfterChild {
                        joint: j.name.clone(),
                        parent: p,
                    });
                }
                _ => {}
            }
            if !j.offset.is_finite() {
                return Err(SkeletonError::NonFiniteOffset(j.name.clone()));
            }
            if joints[..i].iter().any(|k| k.name == j.name) {
                return Err(SkeletonError::DuplicateName(j.name.clone()));
            }
        }
        Ok(Self { joints })
    }

    /// The joints, parents first.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Number of joints (end sites included).
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Always false: a skeleton has at least its root.
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// Index of the joint called `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Indices of the direct children of joint `i`.
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, j)| j.parent == Some(i))
            .map(|(k, _)| k)
    }

    /// The rest pose: no rotation, no channel translation.
    pub fn rest_pose(&self) -> Pose {
        Pose::identity(self.len())
    }

    /// Each joint's local transform in `pose`: rotation R_i, translation offset_i + d_i.
    pub fn local_transform(&self, pose: &Pose, i: usize) -> Transform {
        Transform::new(
            pose.rotations[i],
            self.joints[i].offset + pose.translations[i],
        )
    }

    /// World transforms of every joint in `pose` (forward kinematics: W_i = W_parent · L_i).
    pub fn world_transforms(&self, pose: &Pose) -> Vec<Transform> {
        let mut out = Vec::with_capacity(self.len());
        self.world_transforms_into(pose, &mut out);
        out
    }

    /// [`Skeleton::world_transforms`] into a reused buffer.
    pub fn world_transforms_into(&self, pose: &Pose, out: &mut Vec<Transform>) {
        assert_eq!(
            pose.len(),
            self.len(),
            "pose and skeleton joint counts differ"
        );
        out.clear();
        for (i, j) in self.joints.iter().enumerate() {
            let local = self.local_transform(pose, i);
            let world = match j.parent {
                None => local,
                Some(p) => out[p] * local,
            };
            out.push(world);
        }
    }

    /// World positions of every joint in `pose`.
    pub fn world_positions(&self, pose: &Pose) -> Vec<DVec3> {
        self.world_transforms(pose)
            .iter()
            .map(|t| t.translation)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint(name: &str, parent: Option<usize>) -> Joint {
        Joint {
            name: name.into(),
            parent,
            offset: DVec3::Y,
            end_site: false,
        }
    }

    #[test]
    fn rejects_malformed_hierarchies() {
        assert!(matches!(Skeleton::new(vec![]), Err(SkeletonError::Empty)));
        let two_roots = vec![joint("a", None), joint("b", None)];
        assert!(matches!(
            Skeleton::new(two_roots),
            Err(SkeletonError::SecondRoot(_))
        ));
        let forward = vec![joint("a", None), joint("b", Some(2)), joint("c", Some(0))];
        assert!(matches!(
            Skeleton::new(forward),
            Err(SkeletonError::ParentAfterChild { .. })
        ));
        let dup = vec![joint("a", None), joint("a", Some(0))];
        assert!(matches!(
            Skeleton::new(dup),
            Err(SkeletonError::DuplicateName(_))
        ));
        let ok = Skeleton::new(vec![
            joint("a", None),
            joint("b", Some(0)),
            joint("c", Some(0)),
        ]);
        let ok = ok.expect("valid skeleton");
        assert_eq!(ok.children(0).collect::<Vec<_>>(), vec![1, 2]);
        assert_eq!(ok.find("c"), Some(2));
    }
}
