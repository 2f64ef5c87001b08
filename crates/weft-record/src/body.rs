//! The character's body on `/colliders`: each part an entity `collider/<part name>` drawn, in
//! its own frame, as Foxglove primitives that make its surface exactly: its two end spheres and
//! the cone tangent to both (a cylinder with scaled ends; a sphere alone for a sphere); a
//! skinned glTF character's body as the triangle list `collider/body/model`.

use foxglove::messages::{CylinderPrimitive, SceneEntity, SpherePrimitive};
use weft_solver::glam::{DQuat, DVec3};

use crate::messages::{FRAME_ID, GREY, pose, timestamp, triangle_list, vec3};
use weft_sim::body::PartPose;
use weft_sim::body::mesh::tangent_angle;

/// The entities of the body parts `parts` at time `time` (s).
pub fn entities(time: f64, parts: &[(String, PartPose)]) -> Vec<SceneEntity> {
    parts
        .iter()
        .map(|(name, p)| {
            let mut e = SceneEntity {
                timestamp: Some(timestamp(time)),
                frame_id: FRAME_ID.into(),
                id: format!("collider/{name}"),
                ..SceneEntity::default()
            };
            for (centre, r) in [(p.a, p.r0), (p.b, p.r1)] {
                e.spheres.push(SpherePrimitive {
                    pose: Some(pose(centre, p.rotation)),
                    size: Some(vec3(DVec3::splat(2.0 * r))),
                    color: Some(GREY),
                });
                if p.is_sphere() {
                    break;
                }
            }
            let h = p.half_height();
            if let Some(alpha) = tangent_angle(p.r0, p.r1, h) {
                // The rings where the cone touches the spheres (local y, radius).
                let (y0, rho0) = (-h + p.r0 * alpha.sin(), p.r0 * alpha.cos());
                let (y1, rho1) = (h + p.r1 * alpha.sin(), p.r1 * alpha.cos());
                let widest = rho0.max(rho1);
                // Foxglove cylinders run along z, from its bottom face at −z to its top.
                let z_to_y = p.rotation * DQuat::from_rotation_x(-std::f64::consts::FRAC_PI_2);
                e.cylinders.push(CylinderPrimitive {
                    pose: Some(pose(
                        p.position + p.rotation * DVec3::new(0.0, 0.5 * (y0 + y1), 0.0),
                        z_to_y,
                    )),
                    size: Some(vec3(DVec3::new(2.0 * widest, 2.0 * widest, y1 - y0))),
                    bottom_scale: rho0 / widest,
                    top_scale: rho1 / widest,
                    color: Some(GREY),
                });
            }
            e
        })
        .collect()
}

/// The skinned glTF character's body at time `time` (s) as the entity
/// `collider/body/model`: its triangles at `vertices` (world, m), in grey.
pub fn model_entity(time: f64, vertices: &[DVec3], triangles: &[[u32; 3]]) -> SceneEntity {
    SceneEntity {
        timestamp: Some(timestamp(time)),
        frame_id: FRAME_ID.into(),
        id: format!("collider/{}", weft_sim::body::MODEL_NAME),
        triangles: vec![triangle_list(
            pose(DVec3::ZERO, DQuat::IDENTITY),
            vertices,
            triangles,
            Some(GREY),
        )],
        ..SceneEntity::default()
    }
}

#[cfg(test)]
mod tests {
    use weft_character::{Character, Geometry};
    use weft_solver::glam::DVec3;

    use crate::{RecordOptions, Recorder, Status};
    use weft_sim::Simulation;

    /// The walker and a small cloth far from it (the file `weft export`'s test runs too).
    const SCENE: &str = include_str!("../../../tests/fixtures/walker.toml");

    fn walking() -> Simulation {
        let scene =
            weft_scene::from_text("walker.toml", SCENE, &[], &weft_scene::DirFiles(".".into()))
                .expect("the scene loads");
        Simulation::new(scene).expect("the scene builds")
    }

    fn numbers(v: &serde_json::Value) -> DVec3 {
        let n = |i: usize| v[i].as_f64().expect("a number");
        DVec3::new(n(0), n(1), n(2))
    }

    /// The log read back: at every frame, each body part on `/colliders/state` is the walker's
    /// shape at that frame's time, worked out by weft-character's forward kinematics, and it
    /// has an entity on `/colliders`.
    #[test]
    fn logged_body_parts_are_the_characters_shapes_at_each_frame() {
        let mut sim = walking();
        // The same walker, made apart from the scene: the analytic reference.
        let character = Character::walker();
        let path = std::env::temp_dir().join(format!("weft-body-{}.mcap", std::process::id()));
        let file = std::fs::File::create(&path).expect("a temporary file");
        let options = RecordOptions {
            mesh_every: 0,
            ..RecordOptions::default()
        };
        let frames = 40;
        let mut rec = Recorder::new(file, &sim, frames, options).expect("a recorder");
        rec.frame(&sim, &sim.stats(0.0, 0)).expect("frame 0");
        for _ in 0..frames {
            let stats = sim.step().expect("a step");
            rec.frame(&sim, &stats).expect("a frame");
        }
        rec.finish(&Status::Complete, frames).expect("finished");
        let bytes = std::fs::read(&path).expect("the log");
        let _ = std::fs::remove_file(&path);
        let shapes = character.body().shapes().len();
        let (mut states, mut updates) = (0, 0);
        for m in mcap::MessageStream::new(&bytes).expect("readable") {
            let m = m.expect("a message");
            let t = m.log_time as f64 * 1e-9;
            if m.channel.topic == "/colliders" {
                use foxglove::Decode;
                let u = foxglove::messages::SceneUpdate::decode(&m.data[..]).expect("decodes");
                let ids: Vec<&str> = u.entities.iter().map(|e| e.id.as_str()).collect();
                assert_eq!(ids.len(), shapes);
                assert_eq!(ids[0], "collider/body/0");
                updates += 1;
                continue;
            }
            if m.channel.topic != crate::collider_state::TOPIC {
                continue;
            }
            states += 1;
            let v: serde_json::Value = serde_json::from_slice(&m.data).expect("JSON");
            let time = v["time"].as_f64().expect("time");
            assert!((time - t).abs() < 1e-9);
            let cs = v["colliders"].as_array().expect("colliders");
            assert_eq!(cs.len(), shapes, "every part");
            let want = character.state(time);
            for (i, s) in want.shapes.iter().enumerate() {
                let c = &cs[i];
                assert_eq!(c["name"], format!("body/{i}"));
                let position = numbers(&c["position"]);
                let r = &c["rotation"];
                let rotation = weft_solver::glam::DQuat::from_xyzw(
                    r[0].as_f64().expect("x"),
                    r[1].as_f64().expect("y"),
                    r[2].as_f64().expect("z"),
                    r[3].as_f64().expect("w"),
                );
                match s.geometry {
                    Geometry::Sphere { center, radius } => {
                        assert_eq!(c["shape"], "sphere");
                        assert_eq!(c["radius"].as_f64(), Some(radius));
                        assert!((position - center).length() < 1e-12, "part {i} at {time}");
                    }
                    Geometry::RoundCone(cone) => {
                        let (a, b, h) = if cone.ra == cone.rb {
                            assert_eq!(c["shape"], "capsule");
                            assert_eq!(c["radius"].as_f64(), Some(cone.ra));
                            let h = c["half_height"].as_f64().expect("half height");
                            let (m, y) = (position, rotation * DVec3::Y);
                            (m - h * y, m + h * y, h)
                        } else {
                            assert_eq!(c["shape"], "round-cone");
                            assert_eq!(c["r0"].as_f64(), Some(cone.ra));
                            assert_eq!(c["r1"].as_f64(), Some(cone.rb));
                            let h = c["half_height"].as_f64().expect("half height");
                            (numbers(&c["a"]), numbers(&c["b"]), h)
                        };
                        assert!((a - cone.a).length() < 1e-12, "part {i} at {time}: a");
                        assert!((b - cone.b).length() < 1e-12, "part {i} at {time}: b");
                        assert!((2.0 * h - (cone.b - cone.a).length()).abs() < 1e-12);
                        // The pose carries the part's frame: local y from a to b.
                        let y = rotation * DVec3::new(0.0, h, 0.0);
                        assert!((position + y - cone.b).length() < 1e-12);
                        assert!((position - y - cone.a).length() < 1e-12);
                    }
                }
            }
        }
        assert_eq!(states, frames as usize + 1);
        assert_eq!(updates, frames as usize + 1, "the body moves every frame");
    }
}
