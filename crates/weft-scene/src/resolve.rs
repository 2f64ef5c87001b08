//! Validation: turns a deserialised [`SceneFile`] into a checked [`Scene`] with solver types,
//! reporting every bad value with its key and line.

use std::collections::BTreeMap;

use weft_collide::SelfCollisionParams;
use weft_solver::glam::{DQuat, DVec3, EulerRot};
use weft_solver::{
    Aero, ClothMesh, ClothParams, Corner, Edge, Forces, GridDesc, Mass, MeshError, Method, Motion,
    Orientation, Pin, Settings, Wind,
};

use crate::error::SceneError;
use crate::family::{self, Field, Setting};
use crate::ranges::{self, Range};
use crate::scene::{ClothSpec, ColliderSpec, Files, SelfCollisionSpec, ShapeSpec};
use crate::schema::{
    ClothSection, ColliderSection, MotionSpec, OrientationName, PartSection, PinSpec, SceneFile,
    ShapeKind,
};
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

    fn bad(&mut self, key: &str, message: impl Into<String>) {
        self.errors.push(self.src.error(key, message));
    }

    fn check(&mut self, key: &str, v: f64, ok: bool, expected: &str) -> bool {
        let good = v.is_finite() && ok;
        if !good {
            self.bad(key, format!("must be {expected}, got {}", show(v)));
        }
        good
    }

    /// Checks `v` by `rule` (a library's range check, which says what it expects).
    fn rule(&mut self, key: &str, v: f64, rule: fn(f64) -> Result<(), &'static str>) -> bool {
        let result = rule(v);
        if let Err(expected) = result {
            self.bad(key, format!("must be {expected}, got {}", show(v)));
        }
        result.is_ok()
    }

    /// Checks `v` against a physical range, naming the range and its reason.
    fn within(&mut self, key: &str, v: f64, range: &Range) -> bool {
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

    fn non_negative(&mut self, key: &str, v: f64) -> bool {
        self.check(key, v, v >= 0.0, "finite and >= 0")
    }

    fn positive(&mut self, key: &str, v: f64) -> bool {
        self.check(key, v, v > 0.0, "finite and > 0")
    }

    fn vector(&mut self, key: &str, v: [f64; 3]) -> DVec3 {
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

    fn rotation(&mut self, key: &str, deg: [f64; 3]) -> DQuat {
        let d = self.vector(key, deg);
        DQuat::from_euler(
            EulerRot::XYZ,
            d.x.to_radians(),
            d.y.to_radians(),
            d.z.to_radians(),
        )
    }

    fn unused<T>(&mut self, key: &str, value: &Option<T>, what: &str) {
        if value.is_some() {
            self.bad(key, format!("not used {what}"));
        }
    }

    fn read_mesh(
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
                let positions: Vec<DVec3> =
                    m.vertices.iter().map(|p| p.as_dvec3() * scale).collect();
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

    fn motion(&mut self, key: &str, m: &Option<MotionSpec>) -> Motion {
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

/// Checks every value of `file` and resolves it into solver types.
pub(crate) fn resolve(file: &SceneFile, c: &mut Checker<'_>) -> Option<ResolvedParts> {
    let sim = &file.sim;
    let dt = sim.dt.0;
    c.within("sim.dt", dt, &ranges::DT);
    let count = |c: &mut Checker<'_>, key: &str, v: i64| -> u32 {
        if !(1..=100_000).contains(&v) {
            c.bad(key, format!("must be an integer in 1..=100000, got {v}"));
            1
        } else {
            v as u32
        }
    };
    let substeps = count(c, "sim.substeps", sim.substeps);
    let iterations = count(c, "sim.iterations", sim.iterations);
    let sweeps = u64::from(substeps) * u64::from(iterations);
    if sweeps > ranges::SWEEPS_PER_FRAME {
        c.bad(
            "sim.iterations",
            format!(
                "substeps x iterations = {sweeps} constraint sweeps per frame, more than {}: \
                 one frame would take minutes (no scene needs that many)",
                ranges::SWEEPS_PER_FRAME
            ),
        );
    }
    let gravity = c.vector("sim.gravity", sim.gravity);
    c.within("sim.damping", sim.damping, &ranges::RATE);
    c.within(
        "sim.divergence_bound",
        sim.divergence_bound,
        &ranges::DIVERGENCE_BOUND,
    );
    let settings = Settings {
        method: sim.method.into(),
        dt,
        substeps,
        iterations,
        divergence_bound: sim.divergence_bound,
        ..Settings::default()
    };
    let mut wind = Wind::default();
    if let Some(w) = &file.wind {
        wind.velocity = c.vector("wind.velocity", w.velocity);
        c.within("wind.drag", w.drag, &ranges::RATE);
        wind.drag = w.drag;
        if let Some(a) = &w.aero {
            c.non_negative("wind.aero.air_density", a.air_density);
            c.non_negative("wind.aero.drag_coefficient", a.drag_coefficient);
            c.non_negative("wind.aero.lift_coefficient", a.lift_coefficient);
            wind.aero = Some(Aero {
                air_density: a.air_density,
                drag_coefficient: a.drag_coefficient,
                lift_coefficient: a.lift_coefficient,
            });
        }
    }
    let forces = Forces {
        gravity,
        wind,
        damping: sim.damping,
    };
    if file.cloth.is_empty() {
        c.bad("cloth", "a scene needs at least one [cloth.<name>] table");
    }
    let cloths: Vec<ClothSpec> = file
        .cloth
        .iter()
        .filter_map(|(name, section)| cloth(c, name, section, &settings))
        .collect();
    let colliders: Vec<ColliderSpec> = file
        .collider
        .iter()
        .enumerate()
        .filter_map(|(i, s)| collider(c, i, s))
        .collect();
    let self_collision = file.self_collision.as_ref().and_then(|s| {
        let names: Vec<String> = s
            .cloths
            .clone()
            .unwrap_or_else(|| file.cloth.keys().cloned().collect());
        for (i, n) in names.iter().enumerate() {
            if !file.cloth.contains_key(n) {
                c.bad(
                    &format!("self_collision.cloths[{i}]"),
                    format!("no cloth named `{n}`"),
                );
            }
        }
        c.non_negative("self_collision.static_friction", s.static_friction);
        c.non_negative("self_collision.dynamic_friction", s.dynamic_friction);
        if s.dynamic_friction > s.static_friction {
            c.bad(
                "self_collision.dynamic_friction",
                "must not exceed static_friction",
            );
        }
        // The ranges are weft-collide's, the one authority on them.
        c.rule(
            "self_collision.max_displacement",
            s.max_displacement,
            SelfCollisionParams::check_max_displacement,
        );
        c.rule(
            "self_collision.search_margin",
            s.search_margin,
            SelfCollisionParams::check_search_margin,
        );
        s.enabled.then_some(SelfCollisionSpec {
            cloths: names,
            static_friction: s.static_friction,
            dynamic_friction: s.dynamic_friction,
            max_displacement: s.max_displacement,
            search_margin: s.search_margin,
            adaptive_search_margin: s.adaptive_search_margin,
        })
    });
    c.errors.is_empty().then_some(ResolvedParts {
        settings,
        forces,
        cloths,
        colliders,
        self_collision,
    })
}

/// What [`resolve`] yields.
pub(crate) struct ResolvedParts {
    pub settings: Settings,
    pub forces: Forces,
    pub cloths: Vec<ClothSpec>,
    pub colliders: Vec<ColliderSpec>,
    pub self_collision: Option<SelfCollisionSpec>,
}

fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '_' || ch == '-')
}

fn named_pin(name: &str) -> Option<Pin> {
    Some(match name {
        "top-left" => Pin::Corner(Corner::TopLeft),
        "top-right" => Pin::Corner(Corner::TopRight),
        "bottom-left" => Pin::Corner(Corner::BottomLeft),
        "bottom-right" => Pin::Corner(Corner::BottomRight),
        "top" => Pin::Edge(Edge::Top),
        "bottom" => Pin::Edge(Edge::Bottom),
        "left" => Pin::Edge(Edge::Left),
        "right" => Pin::Edge(Edge::Right),
        _ => return None,
    })
}

fn cloth(
    c: &mut Checker<'_>,
    name: &str,
    s: &ClothSection,
    settings: &Settings,
) -> Option<ClothSpec> {
    let k = |field: &str| format!("cloth.{name}.{field}");
    let before = c.errors.len();
    if !valid_name(name) {
        c.bad(
            &format!("cloth.{name}"),
            "a cloth name may hold only letters, digits, `_` and `-`",
        );
    }
    let method = s.method.map(Method::from).unwrap_or(settings.method);
    let material = s
        .material
        .as_ref()
        .and_then(|m| match crate::material::resolve(m) {
            Ok(m) => Some(m),
            Err((field, message)) => {
                c.bad(&k(&field), message);
                None
            }
        });
    let mass = match (s.mass, s.density) {
        (Some(_), Some(_)) => {
            c.bad(&k("density"), "give `mass` or `density`, not both");
            Mass::Total(1.0)
        }
        (Some(m), None) => {
            c.within(&k("mass"), m, &ranges::MASS);
            Mass::Total(m)
        }
        (None, Some(d)) => {
            c.within(&k("density"), d, &ranges::DENSITY);
            Mass::Density(d)
        }
        (None, None) => material.map_or(Mass::Total(1.0), |m| Mass::Density(m.density)),
    };
    let center = c.vector(&k("center"), s.center.unwrap_or_default());
    let pins = s.pins.clone().unwrap_or_default();
    let mut params = ClothParams::default();
    let entries = s.family_settings();
    for &(fam, setting) in &entries {
        if let Some(v) = setting.number() {
            c.rule(
                &k(&family::key(fam, setting.field())),
                v,
                setting.field().rule(),
            );
        }
    }
    for &(fam, setting) in &entries {
        let field = setting.field();
        let range = match field {
            Field::Compliance => &ranges::COMPLIANCE,
            Field::Damping | Field::SpringDamping => &ranges::DAMPING,
            Field::SpringStiffness => &ranges::SPRING_STIFFNESS,
            Field::Enabled | Field::PbdStiffness => continue,
        };
        if let Some(v) = setting.number()
            && (field.rule())(v).is_ok()
        {
            c.within(&k(&family::key(fam, field)), v, range);
        }
    }
    let thickness = s.thickness.unwrap_or(0.005);
    c.within(&k("thickness"), thickness, &ranges::THICKNESS);
    let motion = c.motion(&k("motion"), &s.motion);
    let mesh = if let Some(path) = &s.mesh {
        c.unused(&k("resolution"), &s.resolution, "by a mesh cloth");
        c.unused(&k("size"), &s.size, "by a mesh cloth");
        c.unused(&k("orientation"), &s.orientation, "by a mesh cloth");
        let scale = s.scale.unwrap_or(1.0);
        c.within(&k("scale"), scale, &ranges::SCALE);
        let mut indices = Vec::new();
        for (i, p) in pins.iter().enumerate() {
            match p {
                PinSpec::Index(v) if *v >= 0 && *v <= u32::MAX as i64 => indices.push(*v as u32),
                PinSpec::Index(v) => {
                    c.bad(&format!("{}[{i}]", k("pins")), format!("bad index {v}"))
                }
                PinSpec::Named(n) => c.bad(
                    &format!("{}[{i}]", k("pins")),
                    format!("`{n}`: a mesh cloth is pinned by vertex index only"),
                ),
            }
        }
        let (positions, triangles) = c.read_mesh(&k("mesh"), path, scale)?;
        let positions = positions.into_iter().map(|p| p + center).collect();
        if c.errors.len() > before {
            return None;
        }
        ClothMesh::from_triangles(positions, triangles, mass, indices)
            .map_err(|e| mesh_error(c, name, &e, true))
            .ok()?
    } else {
        c.unused(&k("scale"), &s.scale, "by a grid cloth");
        let [nx, ny] = s.resolution.unwrap_or([20, 20]);
        if !(2..=4096).contains(&nx) || !(2..=4096).contains(&ny) {
            c.bad(
                &k("resolution"),
                format!("each count must be in 2..=4096, got [{nx}, {ny}]"),
            );
        }
        let [w, h] = s.size.unwrap_or([1.0, 1.0]);
        c.within(&k("size"), w, &ranges::SIZE);
        c.within(&k("size"), h, &ranges::SIZE);
        let mut grid_pins = Vec::new();
        for (i, p) in pins.iter().enumerate() {
            let key = format!("{}[{i}]", k("pins"));
            match p {
                PinSpec::Named(n) => match named_pin(n) {
                    Some(pin) => grid_pins.push(pin),
                    None => c.bad(
                        &key,
                        format!(
                            "unknown pin `{n}`: expected top-left, top-right, bottom-left, \
                             bottom-right, top, bottom, left, right or a vertex index"
                        ),
                    ),
                },
                PinSpec::Index(v) if *v >= 0 && *v < nx.saturating_mul(ny) => {
                    grid_pins.push(Pin::Index(*v as u32))
                }
                PinSpec::Index(v) => c.bad(
                    &key,
                    format!(
                        "vertex {v} does not exist (the grid has {})",
                        nx.max(0).saturating_mul(ny.max(0))
                    ),
                ),
            }
        }
        if c.errors.len() > before {
            return None;
        }
        GridDesc {
            resolution: (nx as usize, ny as usize),
            size: (w, h),
            center,
            orientation: match s.orientation.unwrap_or_default() {
                OrientationName::Vertical => Orientation::Vertical,
                OrientationName::Horizontal => Orientation::Horizontal,
            },
            mass,
            pins: grid_pins,
        }
        .build()
        .map_err(|e| mesh_error(c, name, &e, false))
        .ok()?
    };
    if let Some(m) = material {
        params = m.params(&mesh, settings, &params);
    }
    family::apply(&entries, &mut params);
    // Spring constants not given in the file scale with the cloth's particle masses, so the
    // explicit mass-spring method is stable at the default substeps (weft_solver::spring_defaults).
    let unset: Vec<weft_solver::Family> = weft_solver::Family::ALL
        .into_iter()
        .filter(|&f| {
            !entries
                .iter()
                .any(|&(g, setting)| g == f && matches!(setting, Setting::SpringStiffness(_)))
        })
        .collect();
    if c.errors.len() == before && material.is_none() {
        match weft_solver::stable_spring_defaults(&mesh, &params, &unset) {
            Ok(p) => params = p,
            Err(e) => c.bad(&format!("cloth.{name}"), e.to_string()),
        }
    }
    (c.errors.len() == before).then(|| ClothSpec {
        name: name.to_owned(),
        method,
        mesh,
        params,
        thickness,
        motion,
    })
}

fn mesh_error(c: &mut Checker<'_>, name: &str, e: &MeshError, is_mesh: bool) {
    let field = match e {
        MeshError::GridTooSmall { .. } => "resolution",
        MeshError::InvalidSize { .. } => "size",
        MeshError::InvalidMass { .. } => "mass",
        MeshError::PinOutOfRange { .. } => "pins",
        MeshError::NonFiniteVertex { .. } if !is_mesh => "center",
        _ => "mesh",
    };
    c.bad(&format!("cloth.{name}.{field}"), e.to_string());
}

struct Geometry<'s> {
    shape: ShapeKind,
    radius: Option<f64>,
    half_extents: Option<[f64; 3]>,
    half_height: Option<f64>,
    normal: Option<[f64; 3]>,
    points: &'s Option<Vec<[f64; 3]>>,
}

fn shape(c: &mut Checker<'_>, key: &str, g: &Geometry<'_>) -> Option<ShapeSpec> {
    let k = |f: &str| format!("{key}.{f}");
    let what = format!("by a {:?} shape", g.shape).to_lowercase();
    let need = |c: &mut Checker<'_>, f: &str, v: Option<f64>| -> f64 {
        match v {
            Some(v) => {
                c.positive(&k(f), v);
                v
            }
            None => {
                c.bad(&k(f), "missing");
                0.0
            }
        }
    };
    use ShapeKind as S;
    if !matches!(g.shape, S::Sphere | S::Capsule) {
        c.unused(&k("radius"), &g.radius, &what);
    }
    if g.shape != S::Cuboid {
        c.unused(&k("half_extents"), &g.half_extents, &what);
    }
    if g.shape != S::Capsule {
        c.unused(&k("half_height"), &g.half_height, &what);
    }
    if g.shape != S::Plane {
        c.unused(&k("normal"), &g.normal, &what);
    }
    if g.shape != S::ConvexHull {
        c.unused(&k("points"), g.points, &what);
    }
    Some(match g.shape {
        S::Sphere => ShapeSpec::Sphere {
            radius: need(c, "radius", g.radius),
        },
        S::Cuboid => {
            let Some(h) = g.half_extents else {
                c.bad(&k("half_extents"), "missing");
                return None;
            };
            let v = c.vector(&k("half_extents"), h);
            if v.min_element() <= 0.0 {
                c.bad(&k("half_extents"), "every component must be > 0");
            }
            ShapeSpec::Cuboid { half_extents: v }
        }
        S::Capsule => {
            let half_height = g.half_height.unwrap_or(0.0);
            c.non_negative(&k("half_height"), half_height);
            ShapeSpec::Capsule {
                half_height,
                radius: need(c, "radius", g.radius),
            }
        }
        S::Plane => {
            let n = c.vector(&k("normal"), g.normal.unwrap_or([0.0, 1.0, 0.0]));
            if n.length_squared() == 0.0 {
                c.bad(&k("normal"), "must not be zero");
            }
            ShapeSpec::Plane { normal: n }
        }
        S::ConvexHull => {
            let points: Vec<DVec3> = g
                .points
                .as_deref()
                .unwrap_or_default()
                .iter()
                .enumerate()
                .map(|(i, p)| c.vector(&format!("{}[{i}]", k("points")), *p))
                .collect();
            if points.len() < 4 {
                c.bad(
                    &k("points"),
                    format!("a hull needs at least 4 points, got {}", points.len()),
                );
            }
            ShapeSpec::ConvexHull { points }
        }
        S::Mesh | S::Compound => return None,
    })
}

fn collider(c: &mut Checker<'_>, i: usize, s: &ColliderSection) -> Option<ColliderSpec> {
    let key = format!("collider[{i}]");
    let k = |f: &str| format!("{key}.{f}");
    let before = c.errors.len();
    let name = s.name.clone().unwrap_or_else(|| format!("collider{i}"));
    if !valid_name(&name) {
        c.bad(&k("name"), "may hold only letters, digits, `_` and `-`");
    }
    let geometry = Geometry {
        shape: s.shape,
        radius: s.radius,
        half_extents: s.half_extents,
        half_height: s.half_height,
        normal: s.normal,
        points: &s.points,
    };
    if s.shape != ShapeKind::Mesh {
        c.unused(&k("mesh"), &s.mesh, "by this shape");
        c.unused(&k("scale"), &s.scale, "by this shape");
    }
    if s.shape != ShapeKind::Compound {
        c.unused(&k("parts"), &s.parts, "by this shape");
    }
    let spec = match s.shape {
        ShapeKind::Mesh => {
            let scale = s.scale.unwrap_or(1.0);
            c.within(&k("scale"), scale, &ranges::SCALE);
            match &s.mesh {
                Some(path) => c
                    .read_mesh(&k("mesh"), path, scale)
                    .map(|(positions, triangles)| ShapeSpec::Mesh {
                        positions,
                        triangles,
                    }),
                None => {
                    c.bad(&k("mesh"), "missing: an OBJ file");
                    None
                }
            }
        }
        ShapeKind::Compound => {
            let parts = s.parts.as_deref().unwrap_or_default();
            if parts.is_empty() {
                c.bad(&k("parts"), "a compound needs at least one part");
            }
            let mut out = Vec::new();
            for (j, p) in parts.iter().enumerate() {
                let pk = format!("{}[{j}]", k("parts"));
                if matches!(
                    p.shape,
                    ShapeKind::Mesh | ShapeKind::Compound | ShapeKind::Plane
                ) {
                    c.bad(
                        &format!("{pk}.shape"),
                        "a compound part must be convex: sphere, cuboid, capsule or convex-hull",
                    );
                    continue;
                }
                if let Some(sh) = part(c, &pk, p) {
                    out.push(sh);
                }
            }
            Some(ShapeSpec::Compound(out))
        }
        _ => shape(c, &key, &geometry),
    };
    let position = c.vector(&k("position"), s.position);
    let rotation = c.rotation(&k("rotation_deg"), s.rotation_deg);
    c.non_negative(&k("static_friction"), s.static_friction);
    c.non_negative(&k("dynamic_friction"), s.dynamic_friction);
    if s.dynamic_friction > s.static_friction {
        c.bad(&k("dynamic_friction"), "must not exceed static_friction");
    }
    let motion = c.motion(&k("motion"), &s.motion);
    let shape = spec?;
    (c.errors.len() == before).then_some(ColliderSpec {
        name,
        shape,
        position,
        rotation,
        motion,
        static_friction: s.static_friction,
        dynamic_friction: s.dynamic_friction,
    })
}

fn part(c: &mut Checker<'_>, key: &str, p: &PartSection) -> Option<(DVec3, DQuat, ShapeSpec)> {
    let g = Geometry {
        shape: p.shape,
        radius: p.radius,
        half_extents: p.half_extents,
        half_height: p.half_height,
        normal: p.normal,
        points: &p.points,
    };
    let sh = shape(c, key, &g)?;
    let pos = c.vector(&format!("{key}.position"), p.position);
    let rot = c.rotation(&format!("{key}.rotation_deg"), p.rotation_deg);
    Some((pos, rot, sh))
}
