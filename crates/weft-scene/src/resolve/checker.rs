//! The [`Checker`]: collects every error while values are checked, each with its key and line;
//! the shared checks (ranges, vectors, rotations, meshes read from files, motions).

use std::collections::BTreeMap;

use weft_solver::Motion;
use weft_solver::glam::{DQuat, DVec3, EulerRot};

use crate::error::SceneError;
use crate::ranges::{self, Range};
use crate::scene::Files;
use crate::schema::MotionSpec;
use crate::source::Source;

/// Collects errors while checking values.
pub(crate) struct Checker<'a> {
    src: &'a Source,
    files: &'a dyn Files,
    /// Files read so far, by the path written in the scene.
    pub read: BTreeMap<String, Vec<u8>>,
    /// Every error found.
    pub errors: Vec<SceneError>,
}

/// A number for a message: plain when short, else in exponent form (1.797e308 is not written
/// out as 309 digits).
pub(crate) fn show(v: f64) -> String {
    if v.is_nan() {
        "NaN".into()
    } else if v != 0.0 && v.is_finite() && !(1e-4..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

impl<'a> Checker<'a> {
    pub fn new(src: &'a Source, files: &'a dyn Files) -> Self {
        Self {
            src,
            files,
            read: BTreeMap::new(),
            errors: Vec::new(),
        }
    }

    pub(super) fn bad(&mut self, key: &str, message: impl Into<String>) {
        self.errors.push(self.src.error(key, message));
    }

    pub(super) fn check(&mut self, key: &str, v: f64, ok: bool, expected: &str) -> bool {
        let good = v.is_finite() && ok;
        if !good {
            self.bad(key, format!("must be {expected}, got {}", show(v)));
        }
        good
    }

    /// Checks `v` by `rule` (a library's range check, which says what it expects).
    pub(super) fn rule(
        &mut self,
        key: &str,
        v: f64,
        rule: fn(f64) -> Result<(), &'static str>,
    ) -> bool {
        let result = rule(v);
        if let Err(expected) = result {
            self.bad(key, format!("must be {expected}, got {}", show(v)));
        }
        result.is_ok()
    }

    /// Checks `v` against a physical range, naming the range and its reason.
    pub(super) fn within(&mut self, key: &str, v: f64, range: &Range) -> bool {
        if v.is_nan() || v.is_infinite() {
            return self.check(key, v, false, &format!("finite and {}", range.expected()));
        }
        let good = range.holds(v);
        if !good {
            self.bad(
                key,
                format!(
                    "out of range: must be {}, got {}",
                    range.expected(),
                    show(v)
                ),
            );
        }
        good
    }

    pub(super) fn non_negative(&mut self, key: &str, v: f64) -> bool {
        self.check(key, v, v >= 0.0, "finite and >= 0")
    }

    /// Coulomb friction of `table` (`<table>.static_friction`, `.dynamic_friction`): both
    /// finite and >= 0, dynamic no more than static.
    pub(super) fn friction(&mut self, table: &str, static_friction: f64, dynamic_friction: f64) {
        self.non_negative(&format!("{table}.static_friction"), static_friction);
        self.non_negative(&format!("{table}.dynamic_friction"), dynamic_friction);
        if dynamic_friction > static_friction {
            self.bad(
                &format!("{table}.dynamic_friction"),
                "must not exceed static_friction",
            );
        }
    }

    pub(super) fn positive(&mut self, key: &str, v: f64) -> bool {
        self.check(key, v, v > 0.0, "finite and > 0")
    }

    pub(super) fn vector(&mut self, key: &str, v: [f64; 3]) -> DVec3 {
        if let Some(c) = v.iter().find(|c| !c.is_finite()) {
            self.bad(
                key,
                format!("every component must be finite, got {}", show(*c)),
            );
        } else if let Some(c) = v.iter().find(|c| !ranges::COORDINATE.holds(**c)) {
            self.bad(
                key,
                format!(
                    "out of range: every component must be {}, got {}",
                    ranges::COORDINATE.expected(),
                    show(*c)
                ),
            );
        }
        DVec3::from_array(v)
    }

    pub(super) fn rotation(&mut self, key: &str, deg: [f64; 3]) -> DQuat {
        let d = self.vector(key, deg);
        DQuat::from_euler(
            EulerRot::XYZ,
            d.x.to_radians(),
            d.y.to_radians(),
            d.z.to_radians(),
        )
    }

    pub(super) fn unused<T>(&mut self, key: &str, value: &Option<T>, what: &str) {
        if value.is_some() {
            self.bad(key, format!("not used {what}"));
        }
    }

    /// Reads `path` as bytes (a glTF model or buffer); names `what` in errors.
    pub(super) fn read_bytes(&mut self, key: &str, path: &str, what: &str) -> Option<Vec<u8>> {
        match self.files.read(path) {
            Ok(bytes) => {
                self.read.insert(path.to_owned(), bytes.clone());
                Some(bytes)
            }
            Err(e) => {
                self.bad(key, format!("cannot read {what} file `{path}`: {e}"));
                None
            }
        }
    }

    /// Reads `path` as text (a garment, BVH or body-table file); names `what` in errors.
    pub(super) fn read_text(&mut self, key: &str, path: &str, what: &str) -> Option<String> {
        match self.files.read(path) {
            Ok(bytes) => {
                let text = String::from_utf8_lossy(&bytes).into_owned();
                self.read.insert(path.to_owned(), bytes);
                Some(text)
            }
            Err(e) => {
                self.bad(key, format!("cannot read {what} file `{path}`: {e}"));
                None
            }
        }
    }

    pub(super) fn read_mesh(
        &mut self,
        key: &str,
        path: &str,
        scale: f64,
    ) -> Option<(Vec<DVec3>, Vec<[u32; 3]>)> {
        let bytes = match self.files.read(path) {
            Ok(b) => b,
            Err(e) => {
                self.bad(key, format!("cannot read mesh file `{path}`: {e}"));
                return None;
            }
        };
        let text = String::from_utf8_lossy(&bytes).into_owned();
        self.read.insert(path.to_owned(), bytes);
        // One OBJ reader serves colliders and cloths; its errors name the file and line.
        match weft_collide::parse_obj(&text, path) {
            Ok(m) => {
                let positions: Vec<DVec3> = m.vertices.iter().map(|p| *p * scale).collect();
                let far = positions
                    .iter()
                    .position(|p| !p.is_finite() || p.abs().max_element() > ranges::COORDINATE.hi);
                if let Some(v) = far {
                    self.bad(
                        key,
                        format!(
                            "`{path}` vertex {} (counting from 1) scaled by {} lies at {}: out of \
                             range, every coordinate must be {}",
                            v + 1,
                            show(scale),
                            positions[v],
                            ranges::COORDINATE.expected()
                        ),
                    );
                    return None;
                }
                Some((positions, m.triangles))
            }
            Err(e) => {
                self.bad(key, format!("bad mesh: {e}"));
                None
            }
        }
    }

    pub(super) fn motion(&mut self, key: &str, m: &Option<MotionSpec>) -> Motion {
        match m {
            None | Some(MotionSpec::Static) => Motion::Static,
            Some(MotionSpec::Linear { velocity }) => Motion::Linear {
                velocity: self.vector(&format!("{key}.velocity"), *velocity),
            },
            Some(MotionSpec::Oscillate {
                amplitude,
                frequency,
            }) => {
                self.non_negative(&format!("{key}.frequency"), *frequency);
                Motion::Oscillate {
                    amplitude: self.vector(&format!("{key}.amplitude"), *amplitude),
                    frequency: *frequency,
                }
            }
            Some(MotionSpec::Rotate {
                pivot,
                axis,
                angular_velocity,
            }) => {
                let axis_v = self.vector(&format!("{key}.axis"), *axis);
                if axis_v.length_squared() == 0.0 {
                    self.bad(&format!("{key}.axis"), "must not be zero");
                }
                self.check(
                    &format!("{key}.angular_velocity"),
                    *angular_velocity,
                    true,
                    "finite",
                );
                Motion::Rotate {
                    pivot: self.vector(&format!("{key}.pivot"), *pivot),
                    axis: axis_v,
                    angular_velocity: *angular_velocity,
                }
            }
        }
    }
}
