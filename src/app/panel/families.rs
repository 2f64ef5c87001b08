//! The panel's constraint families of one cloth: the stiffness of each family for the method
//! the cloth runs, in its physical unit with three significant digits, and a tooltip on each
//! name and value saying what it is.
//!
//! XPBD keeps a compliance α, the inverse of a stiffness: the panel shows and edits the
//! stiffness 1/α (the bending stiffness B for isometric bending), so "B 1.2e-5 N·m" rather
//! than "α 83333.3". PBD's k is a unitless fraction per projection; the mass-spring methods
//! keep their spring stiffness as it is.

use egui::{DragValue, Grid, Ui};
use weft_solver::{ClothParams, Family, Method};

/// What family `f`'s constraints do, for its tooltip.
fn family_help(f: Family) -> &'static str {
    match f {
        Family::Stretch => "stretch: keeps each mesh edge at its rest length",
        Family::Shear => "shear: keeps each grid quad's diagonals at their rest length",
        Family::BendDistance => {
            "bend_distance: bending as the distance between the two far vertices across each \
             interior edge (cheap, weak near flat)"
        }
        Family::BendDihedral => {
            "bend_dihedral: bending as the angle between the two triangles at each interior edge"
        }
        Family::BendIsometric => {
            "bend_isometric: bending by the quadratic isometric energy (Bergou et al. 2006), \
             flat at rest"
        }
        Family::Tether => "tether: stops particles moving farther from their pins than at rest",
    }
}

/// The symbol and unit of family `f`'s stiffness (XPBD's 1/α, or a spring's k).
fn stiffness_unit(f: Family) -> (&'static str, &'static str) {
    match f {
        Family::BendDihedral => ("k", "N·m/rad"),
        Family::BendIsometric => ("B", "N·m"),
        _ => ("k", "N/m"),
    }
}

/// `v` with three significant digits: plain between 0.001 and 10 000, else as `1.23e-5`;
/// "rigid" for an infinite stiffness.
pub fn sig(v: f64) -> String {
    if v.is_infinite() && v > 0.0 {
        return "rigid".into();
    }
    let a = v.abs();
    if v == 0.0 || (1e-3..1e4).contains(&a) {
        let decimals = if v == 0.0 {
            0
        } else {
            (2 - a.log10().floor() as i32).max(0) as usize
        };
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_owned()
        } else {
            s
        }
    } else {
        let s = format!("{v:.2e}");
        // "1.20e-5" → "1.2e-5"
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

/// Parses what a user typed into a stiffness: a number, or "rigid" / "inf" for no give.
fn parse(s: &str) -> Option<f64> {
    let t = s.trim().to_lowercase();
    match t.as_str() {
        "rigid" | "inf" | "∞" => Some(f64::INFINITY),
        _ => t.parse::<f64>().ok().filter(|v| !v.is_nan()),
    }
}

/// A stiffness field: drags by 1% of the value, types as a number or "rigid".
fn stiffness_field(ui: &mut Ui, k: &mut f64, unit: &str, tip: String) -> bool {
    let speed = if k.is_finite() {
        (k.abs() * 0.01).max(1e-12)
    } else {
        0.0
    };
    ui.add(
        DragValue::new(k)
            .speed(speed)
            .range(0.0..=f64::INFINITY)
            .custom_formatter(|v, _| sig(v))
            .custom_parser(parse)
            .suffix(format!(" {unit}")),
    )
    .on_hover_text(tip)
    .changed()
}

/// Draws the families of a cloth run by `method` and edits `params`; returns whether a
/// value changed.
pub fn grid(ui: &mut Ui, method: Method, params: &mut ClothParams) -> bool {
    let mut changed = false;
    let header = match method {
        Method::Xpbd => "stiffness (1/α)",
        Method::Pbd => "PBD k (0 to 1)",
        _ => "spring stiffness",
    };
    Grid::new("families")
        .num_columns(2)
        .striped(true)
        .show(ui, |ui| {
            ui.label("family");
            ui.label(header).on_hover_text(format!(
                "the values {} uses; the other methods' values are kept in the scene",
                method.name()
            ));
            ui.end_row();
            for f in Family::ALL {
                let p = params.get_mut(f);
                if !p.enabled {
                    continue;
                }
                ui.label(f.name()).on_hover_text(family_help(f));
                let (symbol, unit) = stiffness_unit(f);
                changed |= match method {
                    Method::Xpbd => {
                        let mut k = if p.compliance == 0.0 {
                            f64::INFINITY
                        } else {
                            1.0 / p.compliance
                        };
                        let tip = format!(
                            "{symbol} = 1/α, the stiffness XPBD's compliance α = {} {} stands \
                             for; larger is stiffer, \"rigid\" is α = 0",
                            sig(p.compliance),
                            inverse(unit)
                        );
                        let edited = stiffness_field(ui, &mut k, unit, tip);
                        if edited {
                            p.compliance = if k.is_infinite() { 0.0 } else { 1.0 / k };
                        }
                        edited
                    }
                    Method::Pbd => ui
                        .add(
                            DragValue::new(&mut p.pbd_stiffness)
                                .speed(0.005)
                                .range(0.0..=1.0)
                                .custom_formatter(|v, _| sig(v)),
                        )
                        .on_hover_text(
                            "PBD stiffness k: the fraction of each constraint's error corrected \
                             per projection (Müller et al. 2007), unitless, 0 to 1",
                        )
                        .changed(),
                    _ => {
                        let tip = format!(
                            "{symbol}, the spring stiffness of the mass-spring methods ({unit})"
                        );
                        stiffness_field(ui, &mut p.spring_stiffness, unit, tip)
                    }
                };
                ui.end_row();
            }
        });
    changed
}

/// The unit of a compliance, the inverse of the stiffness unit `unit`.
fn inverse(unit: &str) -> &'static str {
    match unit {
        "N·m/rad" => "rad/(N·m)",
        "N·m" => "1/(N·m)",
        _ => "m/N",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_have_three_significant_digits_and_no_trailing_zeros() {
        assert_eq!(sig(1.2e-5), "1.2e-5");
        assert_eq!(sig(1.0 / 204081.632653), "4.9e-6");
        assert_eq!(sig(5000.0), "5000");
        assert_eq!(sig(12345.0), "1.23e4");
        assert_eq!(sig(0.05), "0.05");
        assert_eq!(sig(0.123456), "0.123");
        assert_eq!(sig(1.0), "1");
        assert_eq!(sig(0.0), "0");
        assert_eq!(sig(f64::INFINITY), "rigid");
        assert_eq!(parse("rigid"), Some(f64::INFINITY));
        assert_eq!(parse(" 2.5e3 "), Some(2500.0));
        assert_eq!(parse("soft"), None);
    }
}
