//! Bad meshes and bad shapes give error values that say what and where — never a panic.

use std::path::PathBuf;

use weft_collide::{
    ColliderDesc, CollisionWorld, CompoundPart, Friction, MeshError, ShapeDesc, ShapeError,
    TriangleMesh, load_obj, parse_obj,
};
use weft_solver::glam::DVec3;

const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-collide-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write temp file");
    path
}

#[test]
fn valid_tetrahedron_and_shipped_blob_load() {
    let m = parse_obj(TETRA, "tetra.obj").expect("valid");
    assert_eq!((m.vertices.len(), m.triangles.len()), (4, 4));
    let blob = load_obj(weft_collide::scenarios::blob_path()).expect("shipped blob loads");
    assert_eq!(blob.triangles.len(), 1280);
}

#[test]
fn missing_file_names_the_file() {
    let err = load_obj("assets/meshes/no-such-mesh.obj").expect_err("must be rejected");
    assert!(matches!(err, MeshError::Io { .. }), "{err:?}");
    assert!(err.to_string().contains("no-such-mesh.obj"), "{err}");
}

#[test]
fn malformed_lines_name_file_and_line() {
    let cases = [
        ("v 0 0\n", 1, "3 coordinates"),
        ("v 0 0 0\nv 1 0 zero\n", 2, "`zero` is not a number"),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n",
            4,
            "at least 3 vertices",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n",
            4,
            "`x` is not a vertex reference",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", 4, "1-based"),
    ];
    for (text, line, reason) in cases {
        let err = parse_obj(text, "bad.obj").expect_err("must be rejected");
        match &err {
            MeshError::Malformed { line: l, .. } => assert_eq!(*l, line, "{err}"),
            other => panic!("expected Malformed for {text:?}, got {other:?}"),
        }
        let msg = err.to_string();
        assert!(msg.starts_with(&format!("bad.obj:{line}:")), "{msg}");
        assert!(msg.contains(reason), "{msg}");
    }
}

#[test]
fn nan_vertex_names_file_and_line() {
    let path = temp_file("nan.obj", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n");
    let err = load_obj(&path).expect_err("must be rejected");
    assert!(
        matches!(
            err,
            MeshError::NonFiniteVertex {
                line: 2,
                vertex: 1,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("nan.obj:2"), "{err}");
}

#[test]
fn out_of_range_index_is_reported_with_its_line() {
    let err =
        parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n", "far.obj").expect_err("must be rejected");
    assert!(
        matches!(
            err,
            MeshError::IndexOutOfRange {
                line: 4,
                index: 6,
                vertices: 3,
                ..
            }
        ),
        "{err:?}"
    );
    let err = parse_obj("v 0 0 0\nf -2 -1 1\n", "neg.obj").expect_err("must be rejected");
    assert!(
        matches!(err, MeshError::IndexOutOfRange { line: 2, .. }),
        "{err:?}"
    );
}

#[test]
fn degenerate_triangle_names_its_face_line() {
    // Face on line 5 repeats a vertex; face on line 6 is collinear.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nf 1 2 3\nf 1 2 4\n";
    let err = parse_obj(text, "flat.obj").expect_err("must be rejected");
    assert!(
        matches!(
            err,
            MeshError::DegenerateTriangle {
                line: 6,
                triangle: 1,
                ..
            }
        ),
        "{err:?}"
    );
    let err =
        parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 1 3\n", "rep.obj").expect_err("must be rejected");
    assert!(
        matches!(err, MeshError::DegenerateTriangle { line: 4, .. }),
        "{err:?}"
    );
}

#[test]
fn non_manifold_edge_names_the_third_face() {
    // Three triangles share edge 1-2 (0-based 0-1): a fin.
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n";
    let err = parse_obj(text, "fin.obj").expect_err("must be rejected");
    assert!(
        matches!(
            err,
            MeshError::NonManifoldEdge {
                line: 8,
                a: 0,
                b: 1,
                ..
            }
        ),
        "{err:?}"
    );
    assert!(err.to_string().contains("fin.obj:8"), "{err}");
}

#[test]
fn empty_mesh_is_an_error() {
    let err = parse_obj("# nothing\nv 0 0 0\n", "empty.obj").expect_err("must be rejected");
    assert!(matches!(err, MeshError::Empty { .. }), "{err:?}");
    let err = TriangleMesh::new(vec![DVec3::ZERO], vec![]).expect_err("must be rejected");
    assert!(matches!(err, MeshError::Empty { .. }), "{err:?}");
}

#[test]
fn bad_shapes_are_rejected_with_the_reason() {
    let build = |shape: ShapeDesc| {
        ShapeDesc::build(&shape)
            .map(|_| ())
            .expect_err("must be rejected")
    };
    assert!(matches!(
        build(ShapeDesc::Sphere { radius: -1.0 }),
        ShapeError::InvalidParameter {
            name: "sphere.radius",
            ..
        }
    ));
    assert!(matches!(
        build(ShapeDesc::Cuboid {
            half_extents: DVec3::new(1.0, f64::NAN, 1.0)
        }),
        ShapeError::InvalidParameter {
            name: "cuboid.half_extents",
            ..
        }
    ));
    assert!(matches!(
        build(ShapeDesc::HalfSpace {
            normal: DVec3::ZERO
        }),
        ShapeError::InvalidParameter {
            name: "half_space.normal",
            ..
        }
    ));
    // Coplanar points have no volume: an error, not a panic inside the hull algorithm.
    let flat = (0..6)
        .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    assert!(matches!(
        build(ShapeDesc::ConvexHull { points: flat }),
        ShapeError::DegenerateHull { points: 6 }
    ));
    assert!(matches!(
        build(ShapeDesc::Compound(vec![])),
        ShapeError::EmptyCompound
    ));
    let mesh = parse_obj(TETRA, "tetra.obj").expect("valid");
    let err = build(ShapeDesc::Compound(vec![
        CompoundPart::at(DVec3::ZERO, ShapeDesc::Sphere { radius: 1.0 }),
        CompoundPart::at(DVec3::X, ShapeDesc::TriMesh(mesh)),
    ]));
    assert!(
        matches!(
            err,
            ShapeError::UnsupportedInCompound {
                part: 1,
                kind: "triangle mesh"
            }
        ),
        "{err:?}"
    );
    // A mesh edited after loading is re-validated when built.
    let mut edited = parse_obj(TETRA, "tetra.obj").expect("valid");
    edited.vertices[2] = DVec3::splat(f64::INFINITY);
    assert!(matches!(
        build(ShapeDesc::TriMesh(edited)),
        ShapeError::Mesh(MeshError::NonFiniteVertex { vertex: 2, .. })
    ));
    // Friction must be finite and non-negative.
    let solver = weft_collide::scenarios::sphere_drop(weft_solver::Method::Xpbd, 4)
        .expect("scenario")
        .0;
    let err = CollisionWorld::new(&solver)
        .add_collider(
            &ColliderDesc::new(ShapeDesc::Sphere { radius: 1.0 })
                .with_friction(Friction::new(-0.1, 0.0)),
        )
        .expect_err("must be rejected");
    assert!(matches!(
        err,
        ShapeError::InvalidParameter {
            name: "friction.static_coefficient",
            ..
        }
    ));
    // The OBJ loader's errors come through `ShapeDesc::from_obj` unchanged.
    let err = ShapeDesc::from_obj("assets/meshes/missing.obj", 1.0).expect_err("must be rejected");
    assert!(
        matches!(err, ShapeError::Mesh(MeshError::Io { .. })),
        "{err:?}"
    );
}
