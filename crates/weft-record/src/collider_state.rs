//! The `/colliders/state` channel: every collider at one frame's pose, as JSON described by a
//! JSON Schema, so that any reader can check contact without Weft's code.
//!
//! A collider is first turned into a [`ColliderState`] (name, pose and a [`StateShape`]); the
//! JSON and the schema are both written from that one list of shape kinds, so a new kind (the
//! character's round cones: `"round-cone"` with `"r0"`, `"r1"` and two end points) is added
//! here in one place: a variant, its [`StateShape::kind`], its parameters and its schema rule.

use serde_json::{Map, Value, json};
use weft_collide::ShapeDesc;
use weft_scene::ColliderSpec;

use weft_sim::body::PartPose;
use weft_solver::glam::{DQuat, DVec3};

/// The channel's topic.
pub const TOPIC: &str = "/colliders/state";

/// The schema's name.
pub const SCHEMA_NAME: &str = "weft.ColliderStates";

/// A collider's shape with the parameters a reader needs to place it.
#[derive(Clone, Debug, PartialEq)]
pub enum StateShape {
    /// A ball.
    Sphere {
        /// Radius (m).
        radius: f64,
    },
    /// A capsule: a segment along the local y axis from −`half_height` to `half_height`,
    /// swept by a ball of `radius`.
    Capsule {
        /// Radius (m).
        radius: f64,
        /// Half the length of the core segment (m).
        half_height: f64,
    },
    /// A round cone (a body part): the spheres of radii `r0` at `a` and `r1` at `b` joined by
    /// the cone tangent to both; in its local frame `a` is at y = −`half_height` and `b` at
    /// +`half_height`.
    RoundCone {
        /// Radius at `a` (m).
        r0: f64,
        /// Radius at `b` (m).
        r1: f64,
        /// Half the distance between the end points (m).
        half_height: f64,
        /// First end point (world, m).
        a: DVec3,
        /// Second end point (world, m).
        b: DVec3,
    },
    /// A box centred on the pose.
    Cuboid {
        /// Half extents along the local axes (m).
        half_extents: DVec3,
    },
    /// The half-space `normal · x ≤ offset` (world frame), bounded by the plane through the
    /// collider's position.
    Plane {
        /// Outward unit normal in the world frame.
        normal: DVec3,
        /// `normal · p` for any point `p` of the plane (m).
        offset: f64,
    },
    /// A convex hull (pose only: its points are in the scene).
    ConvexHull,
    /// A triangle mesh (pose only: its triangles are in the scene).
    Mesh,
    /// Parts, each with its own world pose and shape.
    Compound(Vec<ColliderState>),
}

/// One collider at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct ColliderState {
    /// The collider's name (a compound's parts: `<name>/<index>`).
    pub name: String,
    /// World position of its origin (m).
    pub position: DVec3,
    /// World orientation.
    pub rotation: DQuat,
    /// Its shape.
    pub shape: StateShape,
}

impl StateShape {
    /// Every kind, as written in `"shape"`.
    pub const KINDS: [&'static str; 8] = [
        "sphere",
        "capsule",
        "round-cone",
        "cuboid",
        "plane",
        "convex-hull",
        "mesh",
        "compound",
    ];

    /// The kind, as written in `"shape"`.
    pub fn kind(&self) -> &'static str {
        match self {
            StateShape::Sphere { .. } => "sphere",
            StateShape::Capsule { .. } => "capsule",
            StateShape::RoundCone { .. } => "round-cone",
            StateShape::Cuboid { .. } => "cuboid",
            StateShape::Plane { .. } => "plane",
            StateShape::ConvexHull => "convex-hull",
            StateShape::Mesh => "mesh",
            StateShape::Compound(_) => "compound",
        }
    }

    /// The keys each kind must carry besides name, shape and pose (for the schema).
    fn required(kind: &str) -> &'static [&'static str] {
        match kind {
            "sphere" => &["radius"],
            "capsule" => &["radius", "half_height"],
            "round-cone" => &["r0", "r1", "half_height", "a", "b"],
            "cuboid" => &["half_extents"],
            "plane" => &["normal", "offset"],
            "compound" => &["parts"],
            _ => &[],
        }
    }

    /// Writes the shape's parameters into `o`.
    fn put(&self, o: &mut Map<String, Value>) {
        match self {
            StateShape::Sphere { radius } => {
                o.insert("radius".into(), json!(radius));
            }
            StateShape::Capsule {
                radius,
                half_height,
            } => {
                o.insert("radius".into(), json!(radius));
                o.insert("half_height".into(), json!(half_height));
            }
            StateShape::RoundCone {
                r0,
                r1,
                half_height,
                a,
                b,
            } => {
                o.insert("r0".into(), json!(r0));
                o.insert("r1".into(), json!(r1));
                o.insert("half_height".into(), json!(half_height));
                o.insert("a".into(), vec3(*a));
                o.insert("b".into(), vec3(*b));
            }
            StateShape::Cuboid { half_extents } => {
                o.insert("half_extents".into(), vec3(*half_extents));
            }
            StateShape::Plane { normal, offset } => {
                o.insert("normal".into(), vec3(*normal));
                o.insert("offset".into(), json!(offset));
            }
            StateShape::ConvexHull | StateShape::Mesh => {}
            StateShape::Compound(parts) => {
                o.insert(
                    "parts".into(),
                    Value::Array(parts.iter().map(ColliderState::to_json).collect()),
                );
            }
        }
    }
}

fn vec3(v: DVec3) -> Value {
    json!([v.x, v.y, v.z])
}

impl ColliderState {
    /// The state of a shape placed at `position`, `rotation` (world).
    pub fn of_shape(name: String, shape: &ShapeDesc, position: DVec3, rotation: DQuat) -> Self {
        let shape = match shape {
            ShapeDesc::Sphere { radius } => StateShape::Sphere { radius: *radius },
            ShapeDesc::Capsule {
                half_height,
                radius,
            } => StateShape::Capsule {
                radius: *radius,
                half_height: *half_height,
            },
            ShapeDesc::Cuboid { half_extents } => StateShape::Cuboid {
                half_extents: *half_extents,
            },
            ShapeDesc::HalfSpace { normal } => {
                let n = (rotation * normal.normalize_or(DVec3::Y)).normalize_or(DVec3::Y);
                StateShape::Plane {
                    normal: n,
                    offset: n.dot(position),
                }
            }
            ShapeDesc::ConvexHull { .. } => StateShape::ConvexHull,
            ShapeDesc::TriMesh(_) => StateShape::Mesh,
            ShapeDesc::Compound(parts) => StateShape::Compound(
                parts
                    .iter()
                    .enumerate()
                    .map(|(i, part)| {
                        Self::of_shape(
                            format!("{name}/{i}"),
                            &part.shape,
                            position + rotation * part.position,
                            rotation * part.rotation,
                        )
                    })
                    .collect(),
            ),
        };
        Self {
            name,
            position,
            rotation,
            shape,
        }
    }

    /// The state of a body part at its pose: a sphere when its ends coincide, a capsule when
    /// its radii are equal, else a round cone.
    pub fn of_part(name: String, part: &PartPose) -> Self {
        let shape = if part.is_sphere() {
            StateShape::Sphere { radius: part.r0 }
        } else if part.is_capsule() {
            StateShape::Capsule {
                radius: part.r0,
                half_height: part.half_height(),
            }
        } else {
            StateShape::RoundCone {
                r0: part.r0,
                r1: part.r1,
                half_height: part.half_height(),
                a: part.a,
                b: part.b,
            }
        };
        Self {
            name,
            position: part.position,
            rotation: part.rotation,
            shape,
        }
    }

    /// The state of a scene collider at time `time` (s), moved by its motion.
    pub fn at(collider: &ColliderSpec, time: f64) -> Self {
        let (position, rotation) = collider
            .motion
            .transform(time)
            .carry(collider.position, collider.rotation);
        Self::of_shape(collider.name.clone(), &collider.shape, position, rotation)
    }

    /// This state as a JSON object.
    pub fn to_json(&self) -> Value {
        let mut o = Map::new();
        o.insert("name".into(), json!(self.name));
        o.insert("shape".into(), json!(self.shape.kind()));
        o.insert("position".into(), vec3(self.position));
        let q = self.rotation;
        o.insert("rotation".into(), json!([q.x, q.y, q.z, q.w]));
        self.shape.put(&mut o);
        Value::Object(o)
    }
}

/// Every collider of `colliders` at time `time` (s), then every body part of `body` (named,
/// at that time's pose).
pub fn states(
    time: f64,
    colliders: &[ColliderSpec],
    body: &[(String, PartPose)],
) -> Vec<ColliderState> {
    colliders
        .iter()
        .map(|c| ColliderState::at(c, time))
        .chain(
            body.iter()
                .map(|(name, p)| ColliderState::of_part(name.clone(), p)),
        )
        .collect()
}

/// One `/colliders/state` message.
pub fn message(frame: u64, time: f64, states: &[ColliderState]) -> Value {
    json!({
        "frame": frame,
        "time": time,
        "colliders": states.iter().map(ColliderState::to_json).collect::<Vec<_>>(),
    })
}

/// The channel's JSON Schema (draft-07): a collider's keys, and per shape kind the parameters
/// it must carry (`if`/`then` on `"shape"`), with compound parts described by the same rules.
pub fn schema() -> String {
    let number_array = |n: usize, what: &str| {
        json!({"type": "array", "items": {"type": "number"}, "minItems": n, "maxItems": n,
               "description": what})
    };
    let rules: Vec<Value> = StateShape::KINDS
        .iter()
        .map(|k| {
            json!({"if": {"properties": {"shape": {"const": k}}},
                   "then": {"required": StateShape::required(k)}})
        })
        .collect();
    let collider = |parts: Option<Value>| {
        let mut properties = json!({
            "name": {"type": "string"},
            "shape": {"enum": StateShape::KINDS},
            "position": number_array(3, "world position of the origin (m)"),
            "rotation": number_array(4, "world orientation as a unit quaternion x, y, z, w"),
            "radius": {"type": "number", "exclusiveMinimum": 0,
                       "description": "sphere or capsule radius (m)"},
            "half_height": {"type": "number", "minimum": 0,
                            "description": "capsule, round cone: half the core segment, along \
                                            local y (m)"},
            "r0": {"type": "number", "exclusiveMinimum": 0,
                   "description": "round cone: radius at a, local y = -half_height (m)"},
            "r1": {"type": "number", "exclusiveMinimum": 0,
                   "description": "round cone: radius at b, local y = +half_height (m)"},
            "a": number_array(3, "round cone: the end point of radius r0 (world, m)"),
            "b": number_array(3, "round cone: the end point of radius r1 (world, m)"),
            "half_extents": number_array(3, "cuboid half extents along the local axes (m)"),
            "normal": number_array(3, "plane: outward unit normal, world frame"),
            "offset": {"type": "number",
                       "description": "plane: normal · p for points p of the plane (m)"},
        });
        if let (Some(parts), Some(o)) = (parts, properties.as_object_mut()) {
            o.insert("parts".into(), parts);
        }
        json!({
            "type": "object",
            "properties": properties,
            "required": ["name", "shape", "position", "rotation"],
            "allOf": rules,
        })
    };
    let part = collider(None);
    let parts = json!({"type": "array", "items": part,
                       "description": "compound: its parts at their world poses"});
    json!({
        "$schema": "http://json-schema.org/draft-07/schema#",
        "title": SCHEMA_NAME,
        "description": "Every collider at one frame's pose.",
        "type": "object",
        "properties": {
            "frame": {"type": "integer", "minimum": 0},
            "time": {"type": "number", "description": "simulated time (s)"},
            "colliders": {"type": "array", "items": collider(Some(parts))},
        },
        "required": ["frame", "time", "colliders"],
    })
    .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_solver::Motion;

    fn spec(shape: ShapeDesc, motion: Motion) -> ColliderSpec {
        ColliderSpec {
            name: "c".into(),
            shape,
            position: DVec3::new(0.0, 1.0, 0.0),
            rotation: DQuat::from_rotation_z(0.5),
            motion,
            static_friction: 0.0,
            dynamic_friction: 0.0,
        }
    }

    #[test]
    fn a_moving_sphere_is_at_its_analytic_position() {
        let c = spec(
            ShapeDesc::Sphere { radius: 0.25 },
            Motion::Linear {
                velocity: DVec3::new(2.0, 0.0, -1.0),
            },
        );
        let v = ColliderState::at(&c, 0.5).to_json();
        assert_eq!(v["shape"], "sphere");
        assert_eq!(v["radius"], 0.25);
        assert_eq!(v["position"], json!([1.0, 1.0, -0.5]));
        let q = DQuat::from_rotation_z(0.5);
        assert_eq!(v["rotation"], json!([q.x, q.y, q.z, q.w]));
    }

    #[test]
    fn a_plane_carries_its_world_normal_and_offset() {
        let c = spec(
            ShapeDesc::HalfSpace {
                normal: DVec3::new(0.0, 2.0, 0.0),
            },
            Motion::Static,
        );
        let StateShape::Plane { normal, offset } = ColliderState::at(&c, 0.0).shape else {
            panic!("a plane")
        };
        let want = DQuat::from_rotation_z(0.5) * DVec3::Y;
        assert!((normal - want).length() < 1e-15, "{normal}");
        assert!((offset - want.dot(DVec3::new(0.0, 1.0, 0.0))).abs() < 1e-15);
    }

    #[test]
    fn compound_parts_are_placed_in_the_world() {
        let c = spec(
            ShapeDesc::Compound(vec![weft_collide::CompoundPart::at(
                DVec3::new(1.0, 0.0, 0.0),
                ShapeDesc::Capsule {
                    half_height: 0.3,
                    radius: 0.1,
                },
            )]),
            Motion::Static,
        );
        let v = ColliderState::at(&c, 0.0).to_json();
        let part = &v["parts"][0];
        assert_eq!(part["name"], "c/0");
        assert_eq!(part["shape"], "capsule");
        assert_eq!(part["half_height"], 0.3);
        let p = DVec3::new(0.0, 1.0, 0.0) + DQuat::from_rotation_z(0.5) * DVec3::X;
        assert_eq!(part["position"], json!([p.x, p.y, p.z]));
    }

    #[test]
    fn the_schema_names_every_kind_and_its_parameters() {
        let s: Value = serde_json::from_str(&schema()).expect("the schema is JSON");
        let collider = &s["properties"]["colliders"]["items"];
        assert_eq!(
            collider["properties"]["shape"]["enum"],
            json!(StateShape::KINDS)
        );
        let rules = collider["allOf"].as_array().expect("rules");
        assert_eq!(rules.len(), StateShape::KINDS.len());
        let capsule = rules
            .iter()
            .find(|r| r["if"]["properties"]["shape"]["const"] == "capsule")
            .expect("a capsule rule");
        assert_eq!(
            capsule["then"]["required"],
            json!(["radius", "half_height"])
        );
    }
}
