//! Collider shapes as plain descriptions in f64 (the one form a scene, a test and the
//! collision world share), and their parry `SharedShape`s in f32.

use std::path::Path;

use glam::{DQuat, DVec3, Vec3};
use parry3d::math::Pose;
use parry3d::shape::{SharedShape, TriMesh, TriMeshFlags};

use crate::convert::pose;
use crate::error::{MeshError, ShapeError};
use crate::mesh::TriangleMesh;
use crate::obj::load_obj;

/// A collider's geometry in its own frame (metres), in f64. [`ShapeDesc::build`] rounds it to
/// the f32 that parry holds; the closed-form and triangle-mesh queries use those same rounded
/// values, widened, so that every query and the drawing see one shape.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeDesc {
    /// A ball centred on the origin.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A box centred on the origin.
    Cuboid {
        /// Half the box's size along each axis (m).
        half_extents: DVec3,
    },
    /// A capsule along the local y axis, centred on the origin.
    Capsule {
        /// Half the length of its core segment (m).
        half_height: f64,
        /// Radius (m).
        radius: f64,
    },
    /// The half-space below a plane through the origin (a ground).
    HalfSpace {
        /// Outward normal (normalised on build).
        normal: DVec3,
    },
    /// The convex hull of points.
    ConvexHull {
        /// The points (at least 4, not coplanar).
        points: Vec<DVec3>,
    },
    /// A triangle mesh, pushed out along its (pseudo-)normals; winding gives the outside.
    TriMesh(TriangleMesh),
    /// Several convex shapes rigidly joined.
    Compound(Vec<CompoundPart>),
}

/// One part of a compound shape: a shape placed in the compound's frame.
#[derive(Clone, Debug, PartialEq)]
pub struct CompoundPart {
    /// Position of the part in the compound's frame (m).
    pub position: DVec3,
    /// Orientation of the part in the compound's frame.
    pub rotation: DQuat,
    /// The part's shape (no triangle mesh, no half-space).
    pub shape: ShapeDesc,
}

impl CompoundPart {
    /// A part placed at `position` without rotation.
    pub fn at(position: DVec3, shape: ShapeDesc) -> Self {
        Self {
            position,
            rotation: DQuat::IDENTITY,
            shape,
        }
    }
}

fn positive(name: &'static str, value: f32) -> Result<(), ShapeError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ShapeError::InvalidParameter {
            name,
            value: value.into(),
            expected: "finite and > 0",
        })
    }
}

impl ShapeDesc {
    /// A triangle-mesh shape read from an OBJ file, scaled about the file's origin.
    pub fn from_obj(path: impl AsRef<Path>, scale: f64) -> Result<Self, ShapeError> {
        positive("scale", scale as f32)?;
        Ok(Self::TriMesh(
            load_obj(path)?.transformed(scale, DVec3::ZERO),
        ))
    }

    /// A short name of the kind of shape.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Sphere { .. } => "sphere",
            Self::Cuboid { .. } => "cuboid",
            Self::Capsule { .. } => "capsule",
            Self::HalfSpace { .. } => "half-space",
            Self::ConvexHull { .. } => "convex hull",
            Self::TriMesh(_) => "triangle mesh",
            Self::Compound(_) => "compound",
        }
    }

    /// Validates the description, rounded to f32 as parry holds it, and builds parry's shape.
    pub fn build(&self) -> Result<SharedShape, ShapeError> {
        match self {
            Self::Sphere { radius } => {
                let radius = *radius as f32;
                positive("sphere.radius", radius)?;
                Ok(SharedShape::ball(radius))
            }
            Self::Cuboid { half_extents } => {
                let h = half_extents.as_vec3();
                for c in h.to_array() {
                    positive("cuboid.half_extents", c)?;
                }
                Ok(SharedShape::cuboid(h.x, h.y, h.z))
            }
            Self::Capsule {
                half_height,
                radius,
            } => {
                let (half_height, radius) = (*half_height as f32, *radius as f32);
                positive("capsule.radius", radius)?;
                if !(half_height.is_finite() && half_height >= 0.0) {
                    return Err(ShapeError::InvalidParameter {
                        name: "capsule.half_height",
                        value: half_height.into(),
                        expected: "finite and >= 0",
                    });
                }
                Ok(SharedShape::capsule_y(half_height, radius))
            }
            Self::HalfSpace { normal } => {
                let normal = normal.as_vec3();
                let n = normal.normalize_or_zero();
                if n == Vec3::ZERO || !n.is_finite() {
                    return Err(ShapeError::InvalidParameter {
                        name: "half_space.normal",
                        value: normal.length().into(),
                        expected: "a finite non-zero vector",
                    });
                }
                Ok(SharedShape::halfspace(n))
            }
            Self::ConvexHull { points } => {
                let points: Vec<Vec3> = points.iter().map(|p| p.as_vec3()).collect();
                if points.len() < 4 || points.iter().any(|p| !p.is_finite()) {
                    return Err(ShapeError::DegenerateHull {
                        points: points.len(),
                    });
                }
                // parry's quickhull can panic on fully degenerate input; refuse coplanar sets first.
                let p0 = points[0];
                let far = points
                    .iter()
                    .copied()
                    .max_by(|a, b| {
                        (*a - p0)
                            .length_squared()
                            .total_cmp(&(*b - p0).length_squared())
                    })
                    .unwrap_or(p0);
                let line = far - p0;
                let off_line = points
                    .iter()
                    .copied()
                    .max_by(|a, b| {
                        line.cross(*a - p0)
                            .length_squared()
                            .total_cmp(&line.cross(*b - p0).length_squared())
                    })
                    .unwrap_or(p0);
                let normal = line.cross(off_line - p0);
                let spread = points
                    .iter()
                    .map(|p| normal.dot(*p - p0).abs())
                    .fold(0.0f32, f32::max);
                // spread / |normal| is the largest distance to the plane of the first three.
                if normal.length_squared() <= 1e-12 * line.length_squared().powi(2)
                    || spread <= 1e-6 * line.length() * normal.length()
                {
                    return Err(ShapeError::DegenerateHull {
                        points: points.len(),
                    });
                }
                SharedShape::convex_hull(&points).ok_or(ShapeError::DegenerateHull {
                    points: points.len(),
                })
            }
            Self::TriMesh(mesh) => {
                // Re-validate: the fields are public and may have been edited after loading.
                let vertices = mesh.vertices_f32();
                crate::mesh::validate(Path::new("<memory>"), &vertices, &mesh.triangles, &[], &[])?;
                // ORIENTED computes pseudo-normals, so that "inside" (behind the surface) is
                // decided correctly at edges and vertices too.
                let trimesh =
                    TriMesh::with_flags(vertices, mesh.triangles.clone(), TriMeshFlags::ORIENTED)
                        .map_err(|e| MeshError::Parry {
                        path: "<memory>".into(),
                        reason: e.to_string(),
                    })?;
                Ok(SharedShape::new(trimesh))
            }
            Self::Compound(parts) => {
                let mut flat = Vec::new();
                flatten(parts, &Pose::IDENTITY, &mut flat)?;
                if flat.is_empty() {
                    return Err(ShapeError::EmptyCompound);
                }
                Ok(SharedShape::compound(flat))
            }
        }
    }
}

/// Builds the parts of a compound, composing nested compounds' poses into one flat list.
fn flatten(
    parts: &[CompoundPart],
    parent: &Pose,
    out: &mut Vec<(Pose, SharedShape)>,
) -> Result<(), ShapeError> {
    for part in parts {
        let (position, rotation) = (part.position.as_vec3(), part.rotation.as_quat());
        if !(position.is_finite() && rotation.is_finite()) {
            return Err(ShapeError::InvalidParameter {
                name: "compound.part.position",
                value: f64::NAN,
                expected: "finite position and rotation",
            });
        }
        let local = *parent * pose(position, rotation.normalize());
        match &part.shape {
            ShapeDesc::Compound(inner) => flatten(inner, &local, out)?,
            ShapeDesc::TriMesh(_) | ShapeDesc::HalfSpace { .. } => {
                return Err(ShapeError::UnsupportedInCompound {
                    part: out.len(),
                    kind: part.shape.kind(),
                });
            }
            shape => out.push((local, shape.build()?)),
        }
    }
    Ok(())
}
