//! A skinned glTF character as the body (`[character] model = …`): the shipped
//! assets/scenes/glb_character.toml resolves into a deforming mesh collider that follows the
//! skinning, the cape attached to a joint of the jumping character never ends a substep inside
//! it by more than its thickness and its top edge follows the joint, runs give the same bytes
//! on 1 and 2 threads, and bad model keys are errors naming the file, line and key.

use std::collections::HashMap;

use crate::common;

use common::triangle::closest;
use common::{errors, load, run_watched, scenes_dir};
use weft_scene::{Origin, Scene};
use weft_solver::glam::DVec3;

fn scene(overrides: &[&str]) -> Scene {
    let ov: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    load(&scenes_dir().join("glb_character.toml"), &ov)
}

#[test]
fn the_glb_scene_resolves_to_a_deforming_mesh_that_follows_the_skinning() {
    let scene = scene(&[]);
    assert!(scene.character.is_none(), "a model, not a skeleton");
    let model = scene.model.clone().expect("a glTF model");
    let mesh = model.skin.mesh();
    // The three meshes of BCN_Epileptic (torso, head, legs) on one 54-joint skin.
    assert_eq!(mesh.joints.len(), 54);
    assert_eq!(mesh.positions.len(), 3014);
    assert!((mesh.duration() - 3.3).abs() < 1e-6, "{}", mesh.duration());
    // Placed with its feet on the floor: the lowest vertex at rest is within 1 mm of y = 0.
    let rest = model.skin.vertices(0.0);
    let lowest = rest.iter().map(|v| v.y).fold(f64::INFINITY, f64::min);
    assert!(lowest.abs() < 1e-3, "lowest vertex at y = {lowest}");
    let mut groups = scene.build().expect("builds");
    let g = &mut groups[0];
    for _ in 0..3 {
        g.step().expect("a frame");
    }
    let t = g.solver.time();
    let world = g.world.as_ref().expect("a collision world");
    let body: Vec<_> = world
        .colliders()
        .iter()
        .filter(|c| c.is_deforming())
        .collect();
    assert_eq!(body.len(), 1, "one deforming collider, the body");
    let got = body[0].mesh_vertices().expect("mesh vertices");
    // The collider's vertices at the last substep's end are the skinning at that time, lifted
    // by the scene's `position` (skinned apart, without the placement).
    let lift = DVec3::new(0.0, 1.025, 0.0);
    let want = mesh.skin(t);
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        assert!(
            (*g - (*w + lift)).length() < 1e-12,
            "vertex {k}: {g} vs {w}"
        );
    }
    // And it moved: the jump has begun.
    let moved = got
        .iter()
        .zip(&rest)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    assert!(moved > 1e-3, "the body moved {moved} m in {t} s");
}

const CELL: f64 = 0.1;

fn cell(p: DVec3) -> (i64, i64, i64) {
    let c = (p / CELL).floor();
    (c.x as i64, c.y as i64, c.z as i64)
}

/// For each point, its distance to the nearest triangle within `reach` (brute force over the
/// triangles of a uniform grid) and whether it lies behind that triangle's face (inside the
/// body, the closest point inside the face and the point on the side opposite its normal);
/// `None` when no triangle is within reach.
fn nearest_sides(
    points: &[DVec3],
    v: &[DVec3],
    tris: &[[u32; 3]],
    reach: f64,
) -> Vec<Option<(f64, bool)>> {
    let mut grid: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (i, t) in tris.iter().enumerate() {
        let [a, b, c] = t.map(|k| v[k as usize]);
        let (lo, hi) = (
            cell(a.min(b).min(c) - DVec3::splat(reach)),
            cell(a.max(b).max(c) + DVec3::splat(reach)),
        );
        for x in lo.0..=hi.0 {
            for y in lo.1..=hi.1 {
                for z in lo.2..=hi.2 {
                    grid.entry((x, y, z)).or_default().push(i);
                }
            }
        }
    }
    points
        .iter()
        .map(|&p| {
            let mut best: Option<(f64, bool)> = None;
            for &i in grid.get(&cell(p)).map(Vec::as_slice).unwrap_or_default() {
                let [a, b, c] = tris[i].map(|k| v[k as usize]);
                let (q, face) = closest(p, a, b, c);
                let d = (p - q).length();
                if d <= reach && best.is_none_or(|(bd, _)| d < bd) {
                    let n = (b - a).cross(c - a);
                    best = Some((d, face && (p - q).dot(n) < 0.0));
                }
            }
            best
        })
        .collect()
}

/// The cape rides the jump until the kicked-back legs have swept into it (1.83 s): at the end of every substep no particle lies
/// behind the body's surface (the closest point inside a face, on the side opposite its
/// outward normal) by more than the cloth's thickness, the cape does touch the body
/// (particles within two thicknesses of it), and its attached top edge sits where the
/// B_Spine4 joint carries it, to 1e-9 m.
#[test]
fn a_cape_on_the_jumping_glb_character_never_ends_a_substep_inside_it() {
    let scene = scene(&[]);
    let model = scene.model.clone().expect("a model");
    let cloth = &scene.cloths[0];
    let thickness = cloth.thickness;
    let tris = model.skin.mesh().triangles.clone();
    let [attach] = cloth.attachments.as_slice() else {
        panic!("one attachment");
    };
    assert_eq!(attach.bone_name, "B_Spine4");
    let node = attach.bone;
    assert_eq!(model.skin.mesh().names[node], "B_Spine4");
    // Each attached vertex in the joint's frame at t = 0, worked out here.
    let bind = model.skin.node_world(0.0)[node].inverse();
    let local: Vec<(usize, DVec3)> = attach
        .vertices
        .iter()
        .map(|&v| {
            (
                v as usize,
                bind.transform_point3(cloth.mesh.positions[v as usize]),
            )
        })
        .collect();
    let mut groups = scene.build().expect("builds");
    let g = &mut groups[0];
    let (mut deepest, mut touching, mut substeps, mut attach_error) = (0.0f64, 0usize, 0, 0.0f64);
    let mut where_deepest = (0.0, 0);
    run_watched(g, 110, |ctx, p| {
        let v = model.skin.vertices(ctx.time);
        let sides = nearest_sides(&p.positions, &v, &tris, 0.05);
        for (i, s) in sides.iter().enumerate() {
            if let Some((d, behind)) = *s {
                if d < 2.0 * thickness {
                    touching += 1;
                }
                if behind && d > deepest {
                    deepest = d;
                    where_deepest = (ctx.time, i);
                }
            }
        }
        let joint = model.skin.node_world(ctx.time)[node];
        for &(i, l) in &local {
            attach_error = attach_error.max((p.positions[i] - joint.transform_point3(l)).length());
        }
        substeps += 1;
    });
    println!(
        "{substeps} substeps; deepest behind the surface {deepest} m (t = {}, particle {}); \
         {touching} particle-substeps within 2 thicknesses; attached vertices off by {attach_error} m",
        where_deepest.0, where_deepest.1
    );
    assert_eq!(substeps, 1100);
    assert!(
        touching > 1000,
        "the cape barely touched the body: {touching}"
    );
    assert!(
        deepest <= thickness,
        "a particle ended a substep {deepest} m inside the body (thickness {thickness}) at t = {}",
        where_deepest.0
    );
    assert!(
        attach_error < 1e-9,
        "attached vertices {attach_error} m off their joint"
    );
    // The joint moved (the jump began), so the attachment was tested in motion.
    let moved = (model.skin.node_world(1.0)[node].w_axis - model.skin.node_world(0.0)[node].w_axis)
        .length();
    assert!(moved > 0.05, "B_Spine4 moved {moved} m");
}

/// Every method runs the scene's first 20 frames (the cloth landing on the head) and keeps
/// the cloth within reach of the character.
#[test]
fn every_method_runs_the_glb_scene() {
    for method in weft_solver::Method::ALL {
        let mut groups = common::with_method(&scenes_dir().join("glb_character.toml"), method, &[]);
        for frame in 0..20 {
            if let Err(e) = groups[0].step() {
                panic!("{method}: frame {frame}: {e}");
            }
        }
        let far = groups[0]
            .solver
            .particles()
            .positions
            .iter()
            .map(|p| (*p - DVec3::new(0.0, 1.5, 0.0)).length())
            .fold(0.0, f64::max);
        assert!(far < 1.5, "{method}: a particle {far} m from the character");
    }
}

/// The same scene gives the same bytes on 1 and 2 threads.
#[test]
fn the_glb_scene_gives_the_same_bytes_on_one_and_two_threads() {
    let run = |threads: usize| -> Vec<u64> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .expect("pool");
        pool.install(|| {
            let mut groups = scene(&[]).build().expect("builds");
            for _ in 0..12 {
                groups[0].step().expect("a frame");
            }
            groups[0]
                .solver
                .particles()
                .positions
                .iter()
                .flat_map(|p| p.to_array().map(f64::to_bits))
                .collect()
        })
    };
    assert_eq!(run(1), run(2));
}

const GOOD: &str = r#"[character]
model = "../characters/bcn_epileptic.glb"
position = [0.0, 1.025, 0.0]

[cloth.sheet]
resolution = [4, 4]
center = [0.0, 2.0, 0.0]
"#;

#[test]
fn bad_model_keys_are_errors_with_file_line_and_key() {
    let files = weft_scene::DirFiles(scenes_dir());
    let ok = weft_scene::from_text("good.toml", GOOD, &[], &files).expect("GOOD loads");
    assert!(ok.model.is_some());
    let with = |from: &str, to: &str| {
        assert!(GOOD.contains(from), "{from}");
        GOOD.replacen(from, to, 1)
    };
    let model_line = "model = \"../characters/bcn_epileptic.glb\"";
    let cases: Vec<(String, usize, &str, &str)> = vec![
        (
            with("bcn_epileptic.glb", "nobody.glb"),
            2,
            "character.model",
            "cannot read glTF model file `../characters/nobody.glb`",
        ),
        (
            with("bcn_epileptic.glb", "cmu_01_01_4s.bvh"),
            2,
            "character.model",
            "`../characters/cmu_01_01_4s.bvh` is not a usable skinned glTF: not valid glTF",
        ),
        (
            with(
                "bcn_epileptic.glb",
                "../scenes/../characters/LICENSE-assimp-testmodels.txt",
            ),
            2,
            "character.model",
            "not a usable skinned glTF",
        ),
        (
            with(model_line, &format!("{model_line}\nanimation = \"Dance\"")),
            3,
            "character.animation",
            "`../characters/bcn_epileptic.glb` has no animation named `Dance` (the file's \
             animations: 0 `Epileptisch`)",
        ),
        (
            with(model_line, &format!("{model_line}\nscale = nan")),
            3,
            "character.scale",
            "must be finite and > 0, got NaN",
        ),
        (
            with(model_line, &format!("{model_line}\nscale = 1e6")),
            2,
            "character.model",
            "out of range",
        ),
        (
            with(
                model_line,
                &format!("{model_line}\nrotation_deg = [0.0, inf, 0.0]"),
            ),
            3,
            "character.rotation_deg",
            "must be finite",
        ),
        (
            with(model_line, &format!("{model_line}\nmodle = 1")),
            3,
            "character.modle",
            "did you mean `model`",
        ),
        (
            with(
                model_line,
                &format!("{model_line}\nskeleton = \"walker.bvh\""),
            ),
            3,
            "character.skeleton",
            "not used with `model`",
        ),
        (
            with("model = \"../characters/bcn_epileptic.glb\"\n", ""),
            2,
            "character.position",
            "not used without `model`",
        ),
    ];
    common::assert_errors(&cases);
}

/// A skinned glTF without a skin, and an animation the file does not have, name the file.
#[test]
fn a_gltf_without_a_skin_or_the_named_animation_is_an_error_naming_the_file() {
    let text = std::fs::read_to_string(scenes_dir().join("../characters/simple_skin.gltf"))
        .expect("fixture");
    let mut map = std::collections::BTreeMap::new();
    map.insert("skin.gltf".to_owned(), text.clone().into_bytes());
    map.insert(
        "noskin.gltf".to_owned(),
        text.replacen("\"skin\" : 0,", "", 1).into_bytes(),
    );
    let files = weft_scene::MapFiles(map);
    let scene = |model: &str, extra: &str| {
        format!("[character]\nmodel = \"{model}\"\n{extra}\n[cloth.c]\nresolution = [4, 4]\n")
    };
    let ok = weft_scene::from_text("s.toml", &scene("skin.gltf", ""), &[], &files)
        .expect("the fixture loads");
    assert_eq!(ok.model.expect("a model").skin.mesh().positions.len(), 10);
    let first = |text: &str| match weft_scene::from_text("s.toml", text, &[], &files) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.0[0].clone(),
    };
    let e = first(&scene("noskin.gltf", ""));
    assert_eq!(e.key, "character.model");
    assert!(
        e.message.contains(
            "`noskin.gltf` is not a usable skinned glTF: no node has both a mesh and a skin"
        ),
        "{}",
        e.message
    );
    assert!(matches!(e.origin, Origin::File { line: Some(2), .. }));
    let e = first(&scene("skin.gltf", "animation = 3"));
    assert_eq!(e.key, "character.animation");
    assert!(matches!(e.origin, Origin::File { line: Some(3), .. }));
    assert!(
        e.message
            .contains("no animation 3 (the file's animations: 0 ``)"),
        "{}",
        e.message
    );
    let e = first(&scene("skin.gltf", "animation = -1"));
    assert_eq!(e.key, "character.animation");
    assert!(matches!(e.origin, Origin::File { line: Some(3), .. }));
}

/// A garment attached to a joint the model's skin does not have is an error naming the key.
#[test]
fn an_unknown_joint_of_a_model_is_an_error_with_the_key() {
    let text = "[character]\nmodel = \"../characters/bcn_epileptic.glb\"\n\n[cloth.cape]\n\
                garment = \"../garments/cape.toml\"\n\
                attach = [{ bone = \"Chest\", panel = \"cape\", edges = [2, 2] }]\n";
    let errs = errors(text);
    assert!(
        errs.iter().any(|(l, k, m)| *l == Some(6)
            && k == "cloth.cape.attach[0].bone"
            && m.contains(
                "no joint named `Chest` in the skin of `../characters/bcn_epileptic.glb`"
            )),
        "{errs:?}"
    );
}
