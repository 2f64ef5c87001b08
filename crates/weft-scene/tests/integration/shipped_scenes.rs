//! Every shipped scene runs 300 frames under every method at its own settings, and contact
//! never adds energy: a cloth resting on a sphere loses kinetic energy under every method.

use crate::common;

use std::path::PathBuf;

use common::{scenes_dir, with_method};
use weft_scene::SolverGroup;
use weft_solver::Method;

fn kinetic_energy(groups: &[SolverGroup]) -> f64 {
    groups
        .iter()
        .map(|g| g.solver.particles().kinetic_energy())
        .sum()
}

/// Scenes built to diverge under some method, by design.
const BUILT_TO_EXPLODE: &[&str] = &["explode.toml"];

/// The dressed walker's scenes, checked over their clip by tests/dressed.rs (the layered
/// outfit over a few frames there): 300 frames under four methods would take minutes, and
/// explicit mass-spring needs substeps below 0.05 ms for their fabrics (their `weft check`
/// says so).
const DRESSED: &[&str] = &[
    "cape.toml",
    "character.toml",
    "skirt.toml",
    "layered_outfit.toml",
];

/// The skinned glTF character's scene, checked by tests/glb_character.rs (contact every
/// substep over 0.5 s, every method over a few frames): 300 frames of a 5,126-triangle
/// deforming body under four methods would hold CI up for minutes.
const SKINNED: &[&str] = &["glb_character.toml"];
/// The cantilever test's strip, run by assets/experiments/cantilever.toml under the methods it
/// is for: cotton on 2.3 mm cells needs 3,682 explicit mass-spring substeps (`weft check` says
/// so), where every other method holds. The Cusick drape test's disc likewise (cotton on
/// 1.25 cm cells), run by assets/experiments/cusick.toml and tests/cusick.rs.
const CANTILEVER: &[&str] = &["cantilever.toml", "cusick.toml"];

/// Thin layers of thousands of particles under mesh contact, stepped under every method by
/// weft-sim's tests/crossings_hold.rs (2 s, the towel 5 s), which fails on a step's error as
/// on a crossing: running them here too would double the suite's slowest minutes.
const MESH_CONTACT: &[&str] = &["layers.toml", "towel_fold.toml", "twist.toml"];

#[test]
fn every_shipped_scene_runs_300_frames_under_every_method() {
    let mut paths: Vec<PathBuf> = std::fs::read_dir(scenes_dir())
        .expect("scenes folder")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter(|p| {
            let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
            !BUILT_TO_EXPLODE.contains(&name)
                && !DRESSED.contains(&name)
                && !SKINNED.contains(&name)
                && !CANTILEVER.contains(&name)
                && !MESH_CONTACT.contains(&name)
        })
        .collect();
    paths.sort();
    assert!(paths.len() >= 7, "{paths:?}");
    for path in &paths {
        for method in Method::ALL {
            let mut groups = with_method(path, method, &[]);
            for frame in 0..300 {
                for g in &mut groups {
                    if let Err(e) = g.step() {
                        panic!("{} under {method}: frame {frame}: {e}", path.display());
                    }
                }
            }
            // Nothing flew off: every particle is within 20 m of the origin.
            let far = groups
                .iter()
                .flat_map(|g| g.solver.particles().positions.iter())
                .map(|p| p.length())
                .fold(0.0, f64::max);
            assert!(
                far < 20.0,
                "{} under {method}: a particle at {far} m",
                path.display()
            );
            println!("{} under {method}: ok", path.display());
        }
    }
}

#[test]
fn a_cloth_resting_on_a_sphere_never_gains_kinetic_energy() {
    let path = scenes_dir().join("sphere_drop.toml");
    let small = vec!["cloth.sheet.resolution=[20, 20]".to_owned()];
    for method in Method::ALL {
        let mut groups = with_method(&path, method, &small);
        let mut energy = Vec::new();
        for _ in 0..360 {
            for g in &mut groups {
                g.step().expect("stays finite");
            }
            energy.push(kinetic_energy(&groups));
        }
        // Dropped 0.3 m onto the ball; after 3 s it rests on it. From then on (the last 3 s)
        // the kinetic energy may only fall: no window holds more than the one before it.
        let settled = &energy[180..];
        let at = |k: usize| {
            settled[k * 30..(k + 1) * 30]
                .iter()
                .copied()
                .fold(0.0, f64::max)
        };
        let windows: Vec<f64> = (0..6).map(at).collect();
        println!("{method}: kinetic energy per 0.5 s window after 3 s: {windows:?}");
        for k in 1..windows.len() {
            assert!(
                windows[k] <= windows[k - 1] * 1.05 + 1e-6,
                "{method}: kinetic energy grew at rest, {windows:?}"
            );
        }
        assert!(
            windows[5] < 1e-2,
            "{method}: a resting cloth still has {} J",
            windows[5]
        );
    }
}

#[test]
fn a_cloth_draped_with_material_bending_never_gains_kinetic_energy() {
    // Denim (the stiffest-bending woven preset) turns bending on with its physical stiffness:
    // isometric at 20², soft per substep; then the same through dihedral angles instead. Its springs are past explicit mass-spring's limit at these substeps (that
    // method is covered by the test above, with its default springs); every other method runs.
    let path = scenes_dir().join("sphere_drop.toml");
    let denim = vec![
        "cloth.sheet.resolution=[20, 20]".to_owned(),
        "cloth.sheet.material=\"denim\"".to_owned(),
    ];
    let mut angles = denim.clone();
    angles.extend([
        "cloth.sheet.bend_isometric_enabled=false".to_owned(),
        "cloth.sheet.bend_dihedral_enabled=true".to_owned(),
        // What the material gives a dihedral on square cells: k_θ = B, α = 1/B.
        "cloth.sheet.bend_dihedral_compliance=1.02e4".to_owned(),
        "cloth.sheet.bend_dihedral_spring_stiffness=9.8e-5".to_owned(),
        "cloth.sheet.bend_dihedral_pbd_stiffness=1e-3".to_owned(),
    ]);
    let runs = [(2, &denim), (1, &angles)];
    for ((family, ov), method) in runs
        .iter()
        .flat_map(|r| [Method::Xpbd, Method::Pbd, Method::ImplicitMassSpring].map(move |m| (*r, m)))
    {
        let mut groups = with_method(&path, method, ov);
        let bending: usize = groups
            .iter()
            .map(|g| g.solver.constraints().color_counts()[family])
            .sum();
        assert!(bending > 0, "{ov:?}: no bending constraints");
        let mut energy = Vec::new();
        for _ in 0..360 {
            for g in &mut groups {
                g.step().expect("stays finite");
            }
            energy.push(kinetic_energy(&groups));
        }
        let at = |k: usize| {
            energy[180 + k * 30..180 + (k + 1) * 30]
                .iter()
                .copied()
                .fold(0.0, f64::max)
        };
        let windows: Vec<f64> = (0..6).map(at).collect();
        println!("{method}, denim: kinetic energy per 0.5 s window after 3 s: {windows:?}");
        for k in 1..windows.len() {
            assert!(
                windows[k] <= windows[k - 1] * 1.05 + 1e-6,
                "{method}: kinetic energy grew at rest, {windows:?}"
            );
        }
        // Far below the 4.5 J of potential energy the drop starts with.
        assert!(windows[0] < 0.05, "{method}: {windows:?}");
    }
}
