//! Foxglove well-known messages for cloth particles, cloth surfaces and colliders.

use foxglove::bytes::Bytes;
use foxglove::messages::packed_element_field::NumericType;
use foxglove::messages::{
    Color, CubePrimitive, CylinderPrimitive, PackedElementField, Point3, PointCloud, Pose,
    Quaternion, SceneEntity, SceneUpdate, SpherePrimitive, Timestamp, TriangleListPrimitive,
    Vector3,
};
use weft_collide::ShapeDesc;

use crate::options::Precision;
use half::slice::HalfFloatSliceExt;
use weft_scene::ColliderSpec;
use weft_solver::glam::{DQuat, DVec3};

/// The frame every message is expressed in.
pub const FRAME_ID: &str = "world";

/// Simulated time in nanoseconds (the MCAP log time).
pub fn nanos(time: f64) -> u64 {
    (time * 1e9).round().max(0.0) as u64
}

/// Simulated time as a Foxglove timestamp.
pub fn timestamp(time: f64) -> Timestamp {
    let ns = nanos(time);
    Timestamp::new((ns / 1_000_000_000) as u32, (ns % 1_000_000_000) as u32)
}

pub(super) fn vec3(v: DVec3) -> Vector3 {
    Vector3 {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

pub(super) fn pose(position: DVec3, rotation: DQuat) -> Pose {
    Pose {
        position: Some(vec3(position)),
        orientation: Some(Quaternion {
            x: rotation.x,
            y: rotation.y,
            z: rotation.z,
            w: rotation.w,
        }),
    }
}

/// Every particle's position as float32 x, y, z in particle order.
pub fn point_cloud(time: f64, positions: &[DVec3]) -> PointCloud {
    point_cloud_as(time, positions, Precision::F32)
}

/// Every particle's position in particle order at `precision`: float32 `x`, `y`, `z`, or
/// IEEE binary16 `x_f16`, `y_f16`, `z_f16` (declared UINT16: Foxglove has no 16-bit float),
/// rounded through float32 (within 2⁻¹¹ + 2⁻²⁴ of each coordinate).
pub fn point_cloud_as(time: f64, positions: &[DVec3], precision: Precision) -> PointCloud {
    let (size, names, kind) = match precision {
        Precision::F32 => (4, ["x", "y", "z"], NumericType::Float32),
        Precision::F16 => (2, ["x_f16", "y_f16", "z_f16"], NumericType::Uint16),
    };
    let mut data = Vec::with_capacity(3 * size * positions.len());
    match precision {
        Precision::F32 => {
            for p in positions {
                for c in [p.x, p.y, p.z] {
                    data.extend_from_slice(&(c as f32).to_le_bytes());
                }
            }
        }
        Precision::F16 => {
            // Through float32, whose slice conversion uses the CPU's F16C instructions where it
            // has them: 4× as fast as `f16::from_f64` one value at a time.
            let wide: Vec<f32> = positions
                .iter()
                .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
                .collect();
            let mut narrow = vec![half::f16::ZERO; wide.len()];
            narrow.convert_from_f32_slice(&wide);
            for h in narrow {
                data.extend_from_slice(&h.to_le_bytes());
            }
        }
    }
    let fields = names
        .iter()
        .zip(0..)
        .map(|(name, i)| PackedElementField {
            name: (*name).into(),
            offset: i * size as u32,
            r#type: kind as i32,
        })
        .collect();
    PointCloud {
        timestamp: Some(timestamp(time)),
        frame_id: FRAME_ID.into(),
        pose: Some(pose(DVec3::ZERO, DQuat::IDENTITY)),
        point_stride: 3 * size as u32,
        fields,
        data: Bytes::from(data),
    }
}

/// `triangles` (indices into `vertices`, m) as a Foxglove indexed triangle list at `pose`.
pub fn triangle_list(
    pose: Pose,
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    color: Option<Color>,
) -> TriangleListPrimitive {
    TriangleListPrimitive {
        pose: Some(pose),
        points: vertices
            .iter()
            .map(|p| Point3 {
                x: p.x,
                y: p.y,
                z: p.z,
            })
            .collect(),
        color,
        colors: vec![],
        indices: triangles.iter().flatten().copied().collect(),
    }
}

/// The cloth surface as an indexed triangle list.
pub fn cloth_mesh(
    time: f64,
    name: &str,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    color: Color,
) -> SceneUpdate {
    let tri = triangle_list(
        pose(DVec3::ZERO, DQuat::IDENTITY),
        positions,
        triangles,
        Some(color),
    );
    SceneUpdate {
        deletions: vec![],
        entities: vec![SceneEntity {
            timestamp: Some(timestamp(time)),
            frame_id: FRAME_ID.into(),
            id: format!("cloth/{name}"),
            triangles: vec![tri],
            ..SceneEntity::default()
        }],
    }
}

/// A colour per method, so side-by-side cloths are told apart.
pub fn method_color(method: weft_solver::Method) -> Color {
    let (r, g, b) = match method {
        weft_solver::Method::Xpbd => (0.25, 0.55, 0.95),
        weft_solver::Method::Pbd => (0.95, 0.55, 0.2),
        weft_solver::Method::MassSpring => (0.4, 0.8, 0.35),
        weft_solver::Method::ImplicitMassSpring => (0.75, 0.4, 0.85),
    };
    Color { r, g, b, a: 1.0 }
}

pub(super) const GREY: Color = Color {
    r: 0.6,
    g: 0.6,
    b: 0.62,
    a: 0.8,
};

fn add_shape(e: &mut SceneEntity, shape: &ShapeDesc, position: DVec3, rotation: DQuat) {
    let p = pose(position, rotation);
    let color = Some(GREY);
    match shape {
        ShapeDesc::Sphere { radius } => e.spheres.push(SpherePrimitive {
            pose: Some(p),
            size: Some(vec3(DVec3::splat(2.0 * radius))),
            color,
        }),
        ShapeDesc::Cuboid { half_extents } => e.cubes.push(CubePrimitive {
            pose: Some(p),
            size: Some(vec3(2.0 * *half_extents)),
            color,
        }),
        ShapeDesc::Capsule {
            half_height,
            radius,
        } => {
            // Foxglove cylinders run along z; capsules along local y.
            let to_y = rotation * DQuat::from_rotation_x(std::f64::consts::FRAC_PI_2);
            e.cylinders.push(CylinderPrimitive {
                pose: Some(pose(position, to_y)),
                size: Some(vec3(DVec3::new(
                    2.0 * radius,
                    2.0 * radius,
                    2.0 * half_height,
                ))),
                bottom_scale: 1.0,
                top_scale: 1.0,
                color,
            });
            for s in [-1.0, 1.0] {
                let c = position + rotation * DVec3::new(0.0, s * half_height, 0.0);
                add_shape(e, &ShapeDesc::Sphere { radius: *radius }, c, rotation);
            }
        }
        ShapeDesc::HalfSpace { normal } => {
            let n = normal.normalize_or(DVec3::Y);
            let r = rotation * DQuat::from_rotation_arc(DVec3::Y, n);
            let centre = position - r * DVec3::new(0.0, 0.0005, 0.0);
            e.cubes.push(CubePrimitive {
                pose: Some(pose(centre, r)),
                size: Some(vec3(DVec3::new(10.0, 0.001, 10.0))),
                color,
            });
        }
        ShapeDesc::ConvexHull { points } => {
            // Drawn as the points' bounding box.
            let lo = points.iter().copied().fold(DVec3::INFINITY, DVec3::min);
            let hi = points.iter().copied().fold(DVec3::NEG_INFINITY, DVec3::max);
            e.cubes.push(CubePrimitive {
                pose: Some(pose(position + rotation * (0.5 * (lo + hi)), rotation)),
                size: Some(vec3(hi - lo)),
                color,
            });
        }
        ShapeDesc::TriMesh(mesh) => {
            e.triangles
                .push(triangle_list(p, &mesh.vertices, &mesh.triangles, color))
        }
        ShapeDesc::Compound(parts) => {
            for part in parts {
                add_shape(
                    e,
                    &part.shape,
                    position + rotation * part.position,
                    rotation * part.rotation,
                );
            }
        }
    }
}

/// Every collider at time `time`, moved by its motion.
pub fn colliders(time: f64, colliders: &[ColliderSpec]) -> SceneUpdate {
    let entities = colliders
        .iter()
        .map(|c| {
            let (position, rotation) = c.motion.transform(time).carry(c.position, c.rotation);
            let mut e = SceneEntity {
                timestamp: Some(timestamp(time)),
                frame_id: FRAME_ID.into(),
                id: format!("collider/{}", c.name),
                ..SceneEntity::default()
            };
            add_shape(&mut e, &c.shape, position, rotation);
            e
        })
        .collect();
    SceneUpdate {
        deletions: vec![],
        entities,
    }
}

/// The positions of a point cloud written by [`point_cloud_as`] (float32 `x`, `y`, `z` or
/// binary16 `x_f16`, `y_f16`, `z_f16`), as float32; `None` for any other layout.
pub fn positions_of(cloud: &PointCloud) -> Option<Vec<[f32; 3]>> {
    let names: Vec<(&str, u32)> = cloud
        .fields
        .iter()
        .map(|f| (f.name.as_str(), f.offset))
        .collect();
    let data = &cloud.data[..];
    match (cloud.point_stride, names.as_slice()) {
        (12, [("x", 0), ("y", 4), ("z", 8)]) if data.len() % 12 == 0 => {
            let f = |c: &[u8], o: usize| f32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
            Some(
                data.chunks_exact(12)
                    .map(|c| [f(c, 0), f(c, 4), f(c, 8)])
                    .collect(),
            )
        }
        (6, [("x_f16", 0), ("y_f16", 2), ("z_f16", 4)]) if data.len() % 6 == 0 => {
            let f = |c: &[u8], o: usize| half::f16::from_le_bytes([c[o], c[o + 1]]).to_f32();
            Some(
                data.chunks_exact(6)
                    .map(|c| [f(c, 0), f(c, 2), f(c, 4)])
                    .collect(),
            )
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Positions read back at each precision are within its stated bound of the originals.
    #[test]
    fn positions_read_back_within_their_precision() {
        let x: Vec<DVec3> = (0..200)
            .map(|i| {
                let t = i as f64 * 0.037;
                DVec3::new(t.sin() * 1.9, -t * 0.01, 0.3 + t.cos())
            })
            .collect();
        for (precision, bound) in [
            (Precision::F32, 2f64.powi(-24)),
            (Precision::F16, 2f64.powi(-11) + 2f64.powi(-24)),
        ] {
            let cloud = point_cloud_as(1.0, &x, precision);
            let back = positions_of(&cloud).expect("a layout it wrote");
            assert_eq!(back.len(), x.len());
            for (p, q) in x.iter().zip(&back) {
                for (a, b) in [(p.x, q[0]), (p.y, q[1]), (p.z, q[2])] {
                    let err = (a - f64::from(b)).abs();
                    assert!(
                        err <= bound * a.abs().max(6.1e-5),
                        "{precision:?}: {a} read as {b}"
                    );
                }
            }
        }
        let mut odd = point_cloud(0.0, &x);
        odd.point_stride = 16;
        assert!(positions_of(&odd).is_none());
    }
}
