//! The mannequin body: a [`BodyTable`] resolved against a skeleton into shapes in their bones'
//! frames, and evaluated at a pose into world shapes that carry their bones' velocities.

use glam::DVec3;
use weft_collide::body::RoundCone;

use crate::animation::BoneState;
use crate::body_table::{BodyTable, ShapeKind, ShapeSpec};
use crate::error::BodyError;
use crate::shape::{Geometry, WorldShape};
use crate::skeleton::Skeleton;

/// One shape in its bone's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyShape {
    /// Display name.
    pub name: String,
    /// The carrying bone (joint index).
    pub bone: usize,
    /// Geometry in the bone's frame (m).
    pub local: Geometry,
}

/// Collision shapes fixed to the bones of one skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    shapes: Vec<BodyShape>,
    joints: usize,
}

impl Body {
    /// Resolves a table against a skeleton: bones by name, radii checked, shape ends at the
    /// named (or only) child joint or at an explicit `end`.
    pub fn new(skeleton: &Skeleton, table: &BodyTable) -> Result<Self, BodyError> {
        let shapes = table
            .shapes
            .iter()
            .enumerate()
            .map(|(i, spec)| resolve(skeleton, table, i, spec))
            .collect::<Result<_, _>>()?;
        Ok(Self {
            shapes,
            joints: skeleton.len(),
        })
    }

    /// The shapes, in table order.
    pub fn shapes(&self) -> &[BodyShape] {
        &self.shapes
    }

    /// Number of joints of the skeleton the body was built for.
    pub fn joints(&self) -> usize {
        self.joints
    }

    /// World shapes for the bones' states at one instant (`bones` indexed like the skeleton).
    pub fn evaluate(&self, bones: &[BoneState]) -> Vec<WorldShape> {
        let mut out = Vec::with_capacity(self.shapes.len());
        self.evaluate_into(bones, &mut out);
        out
    }

    /// [`Body::evaluate`] into a reused buffer.
    pub fn evaluate_into(&self, bones: &[BoneState], out: &mut Vec<WorldShape>) {
        assert_eq!(bones.len(), self.joints, "bone states and skeleton differ");
        out.clear();
        out.extend(self.shapes.iter().enumerate().map(|(i, s)| {
            let motion = bones[s.bone];
            WorldShape {
                shape: i,
                bone: s.bone,
                geometry: s.local.transformed(&motion.transform),
                motion,
            }
        }));
    }
}

fn resolve(
    skeleton: &Skeleton,
    table: &BodyTable,
    i: usize,
    spec: &ShapeSpec,
) -> Result<BodyShape, BodyError> {
    let err = |key: &'static str, message: String| BodyError::Shape {
        line: table.line_of(i, key),
        index: i + 1,
        bone: spec.bone.clone(),
        key,
        message,
    };
    let bone = skeleton
        .find(&spec.bone)
        .ok_or_else(|| err("bone", format!("no joint `{}` in the skeleton", spec.bone)))?;
    let radius = |key: &'static str, v: Option<f64>| -> Result<f64, BodyError> {
        match v {
            None => Err(err(
                key,
                format!("a {} needs `{key}`", kind_name(spec.kind)),
            )),
            Some(r) if r.is_finite() && r > 0.0 => Ok(r),
            Some(r) => Err(err(
                key,
                format!("must be a positive length in metres, got {r}"),
            )),
        }
    };
    let forbid = |key: &'static str, given: bool| -> Result<(), BodyError> {
        if given {
            Err(err(
                key,
                format!("a {} takes no `{key}`", kind_name(spec.kind)),
            ))
        } else {
            Ok(())
        }
    };
    let point = |key: &'static str, v: Option<[f64; 3]>| -> Result<Option<DVec3>, BodyError> {
        match v.map(DVec3::from_array) {
            Some(p) if !p.is_finite() => Err(err(key, "must be finite".into())),
            p => Ok(p),
        }
    };
    let start = point("start", spec.start)?.unwrap_or(DVec3::ZERO);
    let end = point("end", spec.end)?;
    let local = match spec.kind {
        ShapeKind::Sphere => {
            forbid("r0", spec.r0.is_some())?;
            forbid("r1", spec.r1.is_some())?;
            forbid("to", spec.to.is_some())?;
            forbid("end", spec.end.is_some())?;
            Geometry::Sphere {
                center: start,
                radius: radius("radius", spec.radius)?,
            }
        }
        ShapeKind::Capsule | ShapeKind::RoundCone => {
            let (ra, rb) = if spec.kind == ShapeKind::Capsule {
                forbid("r0", spec.r0.is_some())?;
                forbid("r1", spec.r1.is_some())?;
                let r = radius("radius", spec.radius)?;
                (r, r)
            } else {
                forbid("radius", spec.radius.is_some())?;
                (radius("r0", spec.r0)?, radius("r1", spec.r1)?)
            };
            let b = match (end, &spec.to) {
                (Some(_), Some(_)) => {
                    return Err(err("end", "give either `to` or `end`, not both".into()));
                }
                (Some(p), None) => p,
                (None, Some(to)) => {
                    let child = skeleton
                        .find(to)
                        .filter(|&c| skeleton.joints()[c].parent == Some(bone))
                        .ok_or_else(|| {
                            err(
                                "to",
                                format!("`{to}` is not a child joint of `{}`", spec.bone),
                            )
                        })?;
                    skeleton.joints()[child].offset
                }
                (None, None) => {
                    let children: Vec<usize> = skeleton.children(bone).collect();
                    match children[..] {
                        [only] => skeleton.joints()[only].offset,
                        _ => {
                            let names: Vec<&str> = children
                                .iter()
                                .map(|&c| skeleton.joints()[c].name.as_str())
                                .collect();
                            return Err(err(
                                "to",
                                format!(
                                    "`{}` has {} children ({}): name the end with `to` or `end`",
                                    spec.bone,
                                    children.len(),
                                    names.join(", ")
                                ),
                            ));
                        }
                    }
                }
            };
            Geometry::RoundCone(RoundCone::new(start, b, ra, rb))
        }
    };
    Ok(BodyShape {
        name: spec.name.clone().unwrap_or_else(|| spec.bone.clone()),
        bone,
        local,
    })
}

fn kind_name(kind: ShapeKind) -> &'static str {
    match kind {
        ShapeKind::RoundCone => "round-cone",
        ShapeKind::Capsule => "capsule",
        ShapeKind::Sphere => "sphere",
    }
}
