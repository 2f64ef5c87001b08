//! `weft check --explain`: the scene as it will run, as TOML, every default filled in: the
//! file's tables with their defaults, and in each cloth table its method, its grid's shape and
//! placement, its mass and thickness, and the 36 `<family>_<field>` keys its material and
//! keys resolved to.

use toml_edit::{DocumentMut, Item, Table, value};
use weft_scene::Scene;
use weft_scene::schema::{DEFAULT_RESOLUTION, DEFAULT_SIZE};
use weft_solver::{Family, FamilyParams};

/// The resolved scene as TOML text, each cloth table completed from what it resolved to.
pub fn resolved(scene: &Scene) -> String {
    let text = scene.resolved_toml();
    let Ok(mut doc) = text.parse::<DocumentMut>() else {
        return text;
    };
    for c in &scene.cloths {
        let Some(t) = doc
            .get_mut("cloth")
            .and_then(Item::as_table_like_mut)
            .and_then(|cloths| cloths.get_mut(&c.name))
            .and_then(Item::as_table_mut)
        else {
            continue;
        };
        let set = |t: &mut Table, key: &str, item: Item| {
            if !t.contains_key(key) {
                t.insert(key, item);
            }
        };
        set(t, "method", value(c.method.name()));
        let grid = !t.contains_key("mesh") && !t.contains_key("garment");
        if grid {
            set(
                t,
                "resolution",
                value(array(&DEFAULT_RESOLUTION.map(|v| v as f64))),
            );
            set(t, "size", value(array(&DEFAULT_SIZE)));
            set(t, "orientation", value("vertical"));
            set(t, "center", value(array(&[0.0; 3])));
        }
        if !t.contains_key("density") {
            set(t, "mass", value(c.mesh.masses.iter().sum::<f64>()));
        }
        set(t, "thickness", value(c.thickness));
        for f in Family::ALL {
            let p: &FamilyParams = c.params.get(f);
            let n = f.name();
            set(t, &format!("{n}_enabled"), value(p.enabled));
            for (field, v) in [
                ("compliance", p.compliance),
                ("damping", p.damping),
                ("pbd_stiffness", p.pbd_stiffness),
                ("spring_stiffness", p.spring_stiffness),
                ("spring_damping", p.spring_damping),
            ] {
                t.insert(&format!("{n}_{field}"), value(v));
            }
        }
    }
    one_line_arrays(doc.as_table_mut());
    doc.to_string()
}

/// Writes every array under `t` on one line (`[0.0, 1.5, 0.0]`, not one number a line).
fn one_line_arrays(t: &mut dyn toml_edit::TableLike) {
    for (_, item) in t.iter_mut() {
        match item {
            Item::Value(toml_edit::Value::Array(a)) => a.fmt(),
            Item::Value(toml_edit::Value::InlineTable(i)) => one_line_arrays(i),
            Item::Table(inner) => one_line_arrays(inner),
            Item::ArrayOfTables(ts) => ts.iter_mut().for_each(|t| one_line_arrays(t)),
            _ => {}
        }
    }
}

/// A TOML array of numbers (whole ones written as integers).
fn array(v: &[f64]) -> toml_edit::Array {
    v.iter()
        .map(|&x| {
            if x.fract() == 0.0 && x.abs() < 1e15 {
                toml_edit::Value::from(x as i64)
            } else {
                toml_edit::Value::from(x)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scene of two keys resolves to a complete one: defaults in every table, a cloth's
    /// 36 family keys, and text that loads back to the same simulation.
    #[test]
    fn explain_fills_every_default_and_reads_back_the_same() {
        let text = "[cloth.sheet]\npins = [\"top\"]\n";
        let files = weft_scene::MapFiles(Default::default());
        let scene = weft_scene::from_text("mini.toml", text, &[], &files).expect("loads");
        let out = resolved(&scene);
        for key in [
            "method = \"xpbd\"",
            "substeps = 10",
            "resolution = [20, 20]",
            "size = [1, 1]",
            "gravity = [0.0, -9.81, 0.0]",
            "orientation = \"vertical\"",
            "thickness = 0.005",
            "stretch_compliance = 0",
            "bend_dihedral_enabled = false",
            "tether_spring_damping",
        ] {
            assert!(out.contains(key), "{key} missing from:\n{out}");
        }
        let again = weft_scene::from_text("explained.toml", &out, &[], &files).expect("reads back");
        assert_eq!(again.cloths[0].params, scene.cloths[0].params);
        assert_eq!(
            again.cloths[0].mesh.positions,
            scene.cloths[0].mesh.positions
        );
        assert_eq!(again.settings, scene.settings);
    }
}
