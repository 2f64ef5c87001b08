//! A `[cloth.<name>]` table: a grid or an OBJ mesh, its pins, mass, material and per-family
//! settings, checked and built into a [`ClothSpec`].

use weft_solver::{
    ClothMesh, ClothParams, GridDesc, Mass, MeshError, Method, Orientation, Settings,
};

use super::garment::{DEFAULT_SEAM_TIME, Rig, garment};
use super::pins::{grid_pins, mesh_pins};
use super::{Checker, valid_name};
use crate::family::{self, Field, Setting};
use crate::ranges;
use crate::scene::ClothSpec;
use crate::schema::{
    ClothSection, DEFAULT_RESOLUTION, DEFAULT_SIZE, DEFAULT_THICKNESS, OrientationName,
    RESOLUTION_RANGE,
};

pub(super) fn cloth(
    c: &mut Checker<'_>,
    name: &str,
    s: &ClothSection,
    settings: &Settings,
    rig: Rig<'_>,
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
    let held_specs = s.held.clone().unwrap_or_default();
    let mut held = Vec::new();
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
    let thickness = s.thickness.unwrap_or(DEFAULT_THICKNESS);
    let thickness_ok = c.check(
        &k("thickness"),
        thickness,
        thickness > 0.0,
        "finite and > 0 m (contact keeps cloth this far from colliders and other cloth)",
    ) && c.within(&k("thickness"), thickness, &ranges::THICKNESS);
    let motion = c.motion(&k("motion"), &s.motion);
    let seam_time = s.seam_time.unwrap_or(DEFAULT_SEAM_TIME);
    let mut seams = Vec::new();
    let mut attachments = Vec::new();
    if s.garment.is_none() {
        c.unused(&k("seam_time"), &s.seam_time, "without a garment");
        c.unused(&k("attach"), &s.attach, "without a garment");
    }
    let mesh = if s.garment.is_some() {
        c.unused(
            &k("mesh"),
            &s.mesh,
            "with a garment (give one or the other)",
        );
        c.unused(&k("resolution"), &s.resolution, "by a garment cloth");
        c.unused(&k("size"), &s.size, "by a garment cloth");
        c.unused(&k("orientation"), &s.orientation, "by a garment cloth");
        c.unused(&k("scale"), &s.scale, "by a garment cloth");
        c.unused(&k("disc_radius"), &s.disc_radius, "by a garment cloth");
        c.unused(&k("clamp_radius"), &s.clamp_radius, "by a garment cloth");
        c.unused(
            &k("pins"),
            &s.pins,
            "by a garment cloth (attach it to a bone)",
        );
        c.unused(
            &k("held"),
            &s.held,
            "by a garment cloth (attach it to a bone)",
        );
        c.non_negative(&k("seam_time"), seam_time);
        let explicit = s.mass.is_some() || s.density.is_some() || material.is_some();
        let g = garment(c, name, s, explicit.then_some(mass), center, rig)?;
        if c.errors.len() > before {
            return None;
        }
        seams = g.seams;
        attachments = g.attachments;
        g.mesh
    } else if let Some(path) = &s.mesh {
        c.unused(&k("resolution"), &s.resolution, "by a mesh cloth");
        c.unused(&k("size"), &s.size, "by a mesh cloth");
        c.unused(&k("orientation"), &s.orientation, "by a mesh cloth");
        c.unused(&k("disc_radius"), &s.disc_radius, "by a mesh cloth");
        c.unused(&k("clamp_radius"), &s.clamp_radius, "by a mesh cloth");
        let scale = s.scale.unwrap_or(1.0);
        c.within(&k("scale"), scale, &ranges::SCALE);
        let mut indices = mesh_pins(c, &k("pins"), &pins);
        held = mesh_pins(c, &k("held"), &held_specs);
        indices.extend(&held);
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
        let [nx, ny] = s.resolution.unwrap_or(DEFAULT_RESOLUTION);
        if !RESOLUTION_RANGE.contains(&nx) || !RESOLUTION_RANGE.contains(&ny) {
            let (lo, hi) = (RESOLUTION_RANGE.start(), RESOLUTION_RANGE.end());
            c.bad(
                &k("resolution"),
                format!("each count must be in {lo}..={hi}, got [{nx}, {ny}]"),
            );
        }
        let [w, h] = s.size.unwrap_or(DEFAULT_SIZE);
        c.within(&k("size"), w, &ranges::SIZE);
        c.within(&k("size"), h, &ranges::SIZE);
        let mut pinned = grid_pins(c, &k("pins"), &pins, nx, ny);
        let still = grid_pins(c, &k("held"), &held_specs, nx, ny);
        if c.errors.len() > before {
            return None;
        }
        pinned.extend(&still);
        let desc = GridDesc {
            resolution: (nx as usize, ny as usize),
            size: (w, h),
            center,
            orientation: match s.orientation.unwrap_or_default() {
                OrientationName::Vertical => Orientation::Vertical,
                OrientationName::Horizontal => Orientation::Horizontal,
            },
            mass,
            pins: pinned,
        };
        held = desc
            .pin_indices(&still)
            .map_err(|e| mesh_error(c, name, &e, false))
            .ok()?;
        let grid = desc
            .build()
            .map_err(|e| mesh_error(c, name, &e, false))
            .ok()?;
        match disc(c, name, s, w.min(h)) {
            Some((radius, clamp)) => {
                let (mesh, map) = grid
                    .cut_disc(center, radius, clamp, mass)
                    .map_err(|e| mesh_error(c, name, &e, false))
                    .ok()?;
                held = held
                    .iter()
                    .filter_map(|&i| map.get(i as usize).copied().flatten())
                    .collect();
                mesh
            }
            None => grid,
        }
    };
    held.sort_unstable();
    held.dedup();
    if thickness_ok {
        thinner_than_the_cloth(c, &k("thickness"), thickness, &mesh);
    }
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
    let topology = std::sync::Arc::new(weft_solver::Topology::new(&mesh.triangles));
    if c.errors.len() == before && material.is_none() {
        match weft_solver::stable_spring_defaults(&mesh, &topology, &params, &unset) {
            Ok(p) => params = p,
            Err(e) => c.bad(&format!("cloth.{name}"), e.to_string()),
        }
    }
    (c.errors.len() == before).then(|| ClothSpec {
        name: name.to_owned(),
        method,
        mesh,
        topology,
        params,
        thickness,
        motion,
        held,
        seams,
        seam_time,
        attachments,
    })
}

/// A grid cloth's `disc_radius` and `clamp_radius` (0 without one), checked against the
/// grid's shorter side `side`; `None` without a disc or where either is bad (reported).
fn disc(c: &mut Checker<'_>, name: &str, s: &ClothSection, side: f64) -> Option<(f64, f64)> {
    let k = |field: &str| format!("cloth.{name}.{field}");
    let Some(radius) = s.disc_radius else {
        c.unused(
            &k("clamp_radius"),
            &s.clamp_radius,
            "without a `disc_radius`",
        );
        return None;
    };
    let radius_ok = c.check(
        &k("disc_radius"),
        radius,
        radius > 0.0 && radius <= 0.5 * side,
        &format!(
            "finite, > 0 and at most half the grid's shorter side, {} m",
            0.5 * side
        ),
    );
    let clamp = s.clamp_radius.unwrap_or(0.0);
    let clamp_ok = c.check(
        &k("clamp_radius"),
        clamp,
        clamp >= 0.0 && clamp < radius,
        &format!("finite, >= 0 and less than disc_radius ({radius} m)"),
    );
    (radius_ok && clamp_ok).then_some((radius, clamp))
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

/// A thickness larger than the cloth itself is no layer: the cloth's smallest dimension is the
/// middle side of its bounding box at rest (a flat sheet's shorter side, however it lies; a
/// garment's panels as placed around the body).
fn thinner_than_the_cloth(c: &mut Checker<'_>, key: &str, thickness: f64, mesh: &ClothMesh) {
    let (lo, hi) = mesh.positions.iter().fold(
        (
            weft_solver::glam::DVec3::INFINITY,
            weft_solver::glam::DVec3::NEG_INFINITY,
        ),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let mut sides = (hi - lo).to_array();
    sides.sort_by(f64::total_cmp);
    let smallest = sides[1];
    if smallest.is_finite() && thickness > smallest {
        c.bad(
            key,
            format!(
                "must not exceed the cloth's smallest dimension ({} m, the middle side of its \
                 bounding box at rest), got {}",
                super::checker::show(smallest),
                super::checker::show(thickness)
            ),
        );
    }
}
