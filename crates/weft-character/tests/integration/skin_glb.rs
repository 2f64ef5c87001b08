//! The shipped skinned character (assets/characters/bcn_epileptic.glb, three meshes on one
//! skin) read by `read_skinned_gltf`, against the glTF skinning worked out apart from the
//! loader: the document parsed by the `gltf` crate, every joint's world matrix composed by
//! walking up its parents (not in the loader's parents-first order), each channel sampled at
//! its bracketing keys, and each vertex blended from its own four joints and weights.

use std::path::PathBuf;

use glam::{DMat4, DQuat, DVec3};
use weft_character::files::read_skinned_gltf;

fn path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../assets/characters/bcn_epileptic.glb")
}

/// A node's local (translation, rotation, scale) at time `t`.
type Trs = (DVec3, DQuat, DVec3);

/// Linear interpolation of key values `v` at times `times`, held before the first and after
/// the last key (glTF 2.0 §3.11, LINEAR; rotations by slerp).
fn sample<T: Copy>(times: &[f64], v: &[T], t: f64, mix: impl Fn(T, T, f64) -> T) -> T {
    if t <= times[0] {
        return v[0];
    }
    for k in 1..times.len() {
        if t <= times[k] {
            let f = (t - times[k - 1]) / (times[k] - times[k - 1]);
            return mix(v[k - 1], v[k], f);
        }
    }
    v[times.len() - 1]
}

/// Every vertex of every mesh node skinned by skin 0, at time `t`, in node order.
fn by_hand(t: f64) -> Vec<DVec3> {
    let bytes = std::fs::read(path()).expect("the glb");
    let glb = gltf::Gltf::from_slice(&bytes).expect("valid glTF");
    let blob = glb.blob.clone().expect("a binary chunk");
    let doc = glb.document;
    let get = |_: gltf::Buffer| Some(blob.as_slice());
    let d3 = |v: [f32; 3]| DVec3::new(v[0].into(), v[1].into(), v[2].into());
    let dq = |v: [f32; 4]| DQuat::from_xyzw(v[0].into(), v[1].into(), v[2].into(), v[3].into());
    let mut local: Vec<Trs> = doc
        .nodes()
        .map(|n| {
            let (tr, r, s) = n.transform().decomposed();
            (d3(tr), dq(r), d3(s))
        })
        .collect();
    let anim = doc.animations().next().expect("an animation");
    for ch in anim.channels() {
        let r = ch.reader(get);
        let times: Vec<f64> = r.read_inputs().expect("times").map(f64::from).collect();
        let node = &mut local[ch.target().node().index()];
        match r.read_outputs().expect("values") {
            gltf::animation::util::ReadOutputs::Translations(v) => {
                let v: Vec<DVec3> = v.map(d3).collect();
                node.0 = sample(&times, &v, t, |a, b, f| a + (b - a) * f);
            }
            gltf::animation::util::ReadOutputs::Rotations(v) => {
                let v: Vec<DQuat> = v.into_f32().map(dq).collect();
                node.1 = sample(&times, &v, t, |a, b, f| a.slerp(b, f));
            }
            gltf::animation::util::ReadOutputs::Scales(v) => {
                let v: Vec<DVec3> = v.map(d3).collect();
                node.2 = sample(&times, &v, t, |a, b, f| a + (b - a) * f);
            }
            _ => {}
        }
    }
    let mut parent = vec![None; local.len()];
    for n in doc.nodes() {
        for c in n.children() {
            parent[c.index()] = Some(n.index());
        }
    }
    // World matrix: the node's own, then its parent's, … up to the root.
    let world = |mut i: usize| {
        let mut m = DMat4::IDENTITY;
        loop {
            let (tr, r, s) = local[i];
            m = DMat4::from_translation(tr)
                * DMat4::from_quat(r.normalize())
                * DMat4::from_scale(s)
                * m;
            match parent[i] {
                Some(p) => i = p,
                None => return m,
            }
        }
    };
    let skin = doc.skins().next().expect("a skin");
    let ibm: Vec<DMat4> = skin
        .reader(get)
        .read_inverse_bind_matrices()
        .expect("inverse bind matrices")
        .map(|c| DMat4::from_cols_array_2d(&c.map(|col| col.map(f64::from))))
        .collect();
    let joint: Vec<DMat4> = skin
        .joints()
        .zip(&ibm)
        .map(|(j, b)| world(j.index()) * *b)
        .collect();
    let mut out = Vec::new();
    for node in doc.nodes().filter(|n| n.skin().is_some()) {
        for prim in node.mesh().expect("a mesh").primitives() {
            let r = prim.reader(get);
            let p = r.read_positions().expect("positions");
            let j = r.read_joints(0).expect("joints").into_u16();
            let w = r.read_weights(0).expect("weights").into_f32();
            for ((p, j), w) in p.zip(j).zip(w) {
                let v = d3(p);
                let total: f64 = w.iter().map(|&x| f64::from(x)).sum();
                let mut x = DVec3::ZERO;
                for k in 0..4 {
                    let m = joint[j[k] as usize];
                    x += m.transform_point3(v) * (f64::from(w[k]) / total);
                }
                out.push(x);
            }
        }
    }
    out
}

#[test]
fn the_shipped_glb_reads_all_three_meshes_on_one_skin() {
    let m = read_skinned_gltf(&path()).expect("bcn_epileptic.glb");
    assert_eq!(m.joints.len(), 54);
    assert_eq!(m.positions.len(), 3014);
    assert_eq!(m.triangles.len(), 5126);
    assert_eq!(m.channels.len(), 171);
    assert!((m.duration() - 3.3).abs() < 1e-6);
    let neck = m.names.iter().position(|n| n == "B_Neck").expect("B_Neck");
    assert!(m.joints.contains(&neck));
}

#[test]
fn the_shipped_glb_skins_as_worked_out_apart_at_and_between_keys() {
    let m = read_skinned_gltf(&path()).expect("bcn_epileptic.glb");
    // t = 0 (the first keys), 1.0 and 1.5 s (mid-jump, between keys of the 100-key channels
    // and of the 80-key one), and 3.3 s (the last keys).
    for t in [0.0, 1.0, 1.5, 1.2345, 3.3] {
        let want = by_hand(t);
        let got = m.skin(t);
        assert_eq!(got.len(), want.len());
        let worst = got
            .iter()
            .zip(&want)
            .map(|(g, w)| (*g - *w).length())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-9,
            "t = {t}: a vertex {worst} m from the hand skinning"
        );
    }
    // Mid-jump the body has moved: the check compares moving vertices.
    let rest = m.skin(0.0);
    let moved = m
        .skin(1.5)
        .iter()
        .zip(&rest)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, f64::max);
    assert!(moved > 0.2, "{moved}");
}
