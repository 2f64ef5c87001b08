//! Live controls: what the viewer's side panel changes between frames, and Python's
//! `Simulation.set`, named by the scene file's own keys (`sim.substeps`,
//! `cloth.<name>.stretch_compliance`, …). A change takes effect from the next frame; a
//! refused value changes nothing.

use weft_scene::family::{Field, key as family_key};
use weft_solver::glam::DVec3;
use weft_solver::{ClothParams, Family, Forces, Method, ParamError, Settings};

use crate::{SimError, Simulation};

/// The keys [`Control::parse`] takes, `<name>` standing for a cloth's name and `<family>` for
/// a constraint family (`stretch`, `shear`, `bend_distance`, `bend_dihedral`,
/// `bend_isometric`, `tether`).
pub const LIVE_KEYS: [&str; 13] = [
    "sim.method",
    "sim.dt",
    "sim.substeps",
    "sim.iterations",
    "sim.gravity",
    "sim.damping",
    "wind.velocity",
    "wind.drag",
    "cloth.<name>.thickness",
    "cloth.<name>.<family>_compliance",
    "cloth.<name>.<family>_damping",
    "cloth.<name>.<family>_pbd_stiffness",
    "cloth.<name>.<family>_spring_stiffness (and <family>_spring_damping)",
];

/// A value given to a live control.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number.
    Number(f64),
    /// A word (a method's name, a time step as `"1/60"`).
    Text(String),
    /// Three numbers (a vector, m/s or m/s²).
    Vector([f64; 3]),
}

impl Value {
    fn describe(&self) -> String {
        match self {
            Value::Number(v) => format!("{v}"),
            Value::Text(t) => format!("{t:?}"),
            Value::Vector(v) => format!("{v:?}"),
        }
    }
}

/// One live change, parsed from its key and value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Control {
    /// `sim.method`: every solver switches to the method (each cloth keeps the parameters of
    /// every method, so nothing else changes).
    Method(Method),
    /// `sim.dt`: the frame time step (s).
    Dt(f64),
    /// `sim.substeps`.
    Substeps(u32),
    /// `sim.iterations`.
    Iterations(u32),
    /// `sim.gravity` (m/s²).
    Gravity(DVec3),
    /// `sim.damping`: the global velocity damping rate (1/s).
    Damping(f64),
    /// `wind.velocity` (m/s).
    WindVelocity(DVec3),
    /// `wind.drag`: the uniform drag rate (1/s).
    WindDrag(f64),
    /// `cloth.<name>.thickness`: a cloth's collision thickness (m).
    Thickness {
        /// Scene cloth index.
        cloth: usize,
        /// Thickness (m).
        value: f64,
    },
    /// `cloth.<name>.<family>_<field>`: one number of a constraint family of a cloth.
    Family {
        /// Scene cloth index.
        cloth: usize,
        /// The family.
        family: Family,
        /// The field (never [`Field::Enabled`]: constraints are made when the scene is built).
        field: Field,
        /// The value.
        value: f64,
    },
}

fn bad(key: &str, expected: &str, got: &Value) -> SimError {
    SimError::BadValue {
        key: key.to_owned(),
        expected: expected.to_owned(),
        got: got.describe(),
    }
}

fn number(key: &str, v: &Value) -> Result<f64, SimError> {
    match v {
        Value::Number(x) if x.is_finite() => Ok(*x),
        _ => Err(bad(key, "a finite number", v)),
    }
}

fn count(key: &str, v: &Value) -> Result<u32, SimError> {
    match v {
        Value::Number(x) if x.fract() == 0.0 && (1.0..=f64::from(u32::MAX)).contains(x) => {
            Ok(*x as u32)
        }
        _ => Err(bad(key, "a whole number >= 1", v)),
    }
}

fn vector(key: &str, v: &Value) -> Result<DVec3, SimError> {
    match v {
        Value::Vector(a) if a.iter().all(|x| x.is_finite()) => Ok(DVec3::from_array(*a)),
        _ => Err(bad(key, "three finite numbers", v)),
    }
}

/// A time step: a number or a fraction such as `"1/60"` (s).
fn seconds(key: &str, v: &Value) -> Result<f64, SimError> {
    let parsed = match v {
        Value::Number(x) => Some(*x),
        Value::Text(t) => {
            let p = |s: &str| s.trim().parse::<f64>().ok();
            match t.split_once('/') {
                Some((a, b)) => p(a).zip(p(b)).map(|(a, b)| a / b),
                None => p(t),
            }
        }
        Value::Vector(_) => None,
    };
    parsed.filter(|x| x.is_finite() && *x > 0.0).ok_or_else(|| {
        bad(
            key,
            "a time step > 0 (s), a number or a fraction such as \"1/60\"",
            v,
        )
    })
}

impl Control {
    /// Parses `key` = `value` against `sim`'s cloths (see [`LIVE_KEYS`]).
    pub fn parse(sim: &Simulation, key: &str, value: &Value) -> Result<Control, SimError> {
        let unknown = || SimError::UnknownKey {
            key: key.to_owned(),
            hint: format!("the live settings are {}", LIVE_KEYS.join(", ")),
        };
        Ok(match key {
            "sim.method" => match value {
                Value::Text(t) => Control::Method(t.parse().map_err(|e| SimError::BadValue {
                    key: key.into(),
                    expected: format!("a method ({e})"),
                    got: value.describe(),
                })?),
                _ => return Err(bad(key, "a method's name", value)),
            },
            "sim.dt" => Control::Dt(seconds(key, value)?),
            "sim.substeps" => Control::Substeps(count(key, value)?),
            "sim.iterations" => Control::Iterations(count(key, value)?),
            "sim.gravity" => Control::Gravity(vector(key, value)?),
            "sim.damping" => Control::Damping(number(key, value)?),
            "wind.velocity" => Control::WindVelocity(vector(key, value)?),
            "wind.drag" => Control::WindDrag(number(key, value)?),
            _ => {
                let Some(rest) = key.strip_prefix("cloth.") else {
                    return Err(unknown());
                };
                // Cloth names may hold dots: the setting is what follows the last one.
                let Some((name, setting)) = rest.rsplit_once('.') else {
                    return Err(unknown());
                };
                let cloth = sim.cloth_index(name)?;
                if setting == "thickness" {
                    return Ok(Control::Thickness {
                        cloth,
                        value: number(key, value)?,
                    });
                }
                let found = Family::ALL.iter().find_map(|&f| {
                    Field::ALL
                        .iter()
                        .find(|&&d| family_key(f, d) == setting)
                        .map(|&d| (f, d))
                });
                match found {
                    Some((_, Field::Enabled)) => {
                        return Err(SimError::UnknownKey {
                            key: key.to_owned(),
                            hint: "a family's constraints are made when the scene is built: \
                                   give it as an override when the scene is loaded"
                                .into(),
                        });
                    }
                    Some((family, field)) => Control::Family {
                        cloth,
                        family,
                        field,
                        value: number(key, value)?,
                    },
                    None => return Err(unknown()),
                }
            }
        })
    }
}

impl Simulation {
    /// The scene index of the cloth called `name`.
    pub fn cloth_index(&self, name: &str) -> Result<usize, SimError> {
        let cloths = &self.scene.cloths;
        cloths
            .iter()
            .position(|c| c.name == name)
            .ok_or_else(|| SimError::NoSuchCloth {
                name: name.to_owned(),
                known: cloths
                    .iter()
                    .map(|c| format!("`{}`", c.name))
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// Parses and applies one live change (see [`LIVE_KEYS`]).
    pub fn set(&mut self, key: &str, value: &Value) -> Result<(), SimError> {
        let control = Control::parse(self, key, value)?;
        self.apply(control)
    }

    /// Applies one live change from the next frame on; a refused value changes nothing.
    pub fn apply(&mut self, control: Control) -> Result<(), SimError> {
        let settings = self.settings();
        let forces = self.forces();
        match control {
            Control::Method(m) => self.set_method(m)?,
            Control::Dt(dt) => self.set_settings(Settings { dt, ..settings })?,
            Control::Substeps(substeps) => self.set_settings(Settings {
                substeps,
                ..settings
            })?,
            Control::Iterations(iterations) => self.set_settings(Settings {
                iterations,
                ..settings
            })?,
            Control::Gravity(gravity) => self.set_forces(Forces { gravity, ..forces })?,
            Control::Damping(damping) => self.set_forces(Forces { damping, ..forces })?,
            Control::WindVelocity(velocity) => {
                let mut f = forces;
                f.wind.velocity = velocity;
                self.set_forces(f)?;
            }
            Control::WindDrag(drag) => {
                let mut f = forces;
                f.wind.drag = drag;
                self.set_forces(f)?;
            }
            Control::Thickness { cloth, value } => self.set_thickness(cloth, value)?,
            Control::Family {
                cloth,
                family,
                field,
                value,
            } => {
                let Some(mut params) = self.cloth_params(cloth) else {
                    return Ok(());
                };
                let p = params.get_mut(family);
                match field {
                    Field::Enabled => {}
                    Field::Compliance => p.compliance = value,
                    Field::Damping => p.damping = value,
                    Field::PbdStiffness => p.pbd_stiffness = value,
                    Field::SpringStiffness => p.spring_stiffness = value,
                    Field::SpringDamping => p.spring_damping = value,
                }
                self.set_cloth_params(cloth, params)?;
            }
        }
        Ok(())
    }

    /// The settings of the first solver (every solver has the same, but for its method).
    pub fn settings(&self) -> Settings {
        self.groups
            .first()
            .map_or(self.scene.settings, |g| *g.solver.settings())
    }

    /// The forces of the first solver (every solver has the same).
    pub fn forces(&self) -> Forces {
        self.groups
            .first()
            .map_or(self.scene.forces, |g| *g.solver.forces())
    }

    /// Switches every solver to `method`.
    pub fn set_method(&mut self, method: Method) -> Result<(), ParamError> {
        for g in &self.groups {
            Settings {
                method,
                ..*g.solver.settings()
            }
            .validate()?;
        }
        for g in &mut self.groups {
            let s = Settings {
                method,
                ..*g.solver.settings()
            };
            g.solver.set_settings(s)?;
            g.method = method;
        }
        Ok(())
    }

    /// Gives every solver `settings`, each keeping its own method. A new time step starts
    /// a new epoch of [`Simulation::time`], so simulated time stays the sum of the steps.
    pub fn set_settings(&mut self, settings: Settings) -> Result<(), ParamError> {
        settings.validate()?;
        let dt = self.dt();
        for g in &mut self.groups {
            let s = Settings {
                method: g.solver.settings().method,
                ..settings
            };
            g.solver.set_settings(s)?;
        }
        if settings.dt != dt {
            self.new_epoch(settings.dt);
        }
        Ok(())
    }

    /// Gives every solver `forces`.
    pub fn set_forces(&mut self, forces: Forces) -> Result<(), ParamError> {
        forces.validate()?;
        for g in &mut self.groups {
            g.solver.set_forces(forces)?;
        }
        Ok(())
    }

    /// The solver group of scene cloth `cloth` and the cloth's index in that solver.
    fn place(&self, cloth: usize) -> Option<(usize, usize)> {
        self.groups
            .iter()
            .enumerate()
            .find_map(|(g, group)| Some((g, group.cloths.iter().position(|&c| c == cloth)?)))
    }

    /// The family parameters of scene cloth `cloth`, if it exists.
    pub fn cloth_params(&self, cloth: usize) -> Option<ClothParams> {
        let (g, local) = self.place(cloth)?;
        self.groups[g].solver.cloth_params(local)
    }

    /// Changes the family parameters of scene cloth `cloth`.
    pub fn set_cloth_params(
        &mut self,
        cloth: usize,
        params: ClothParams,
    ) -> Result<(), ParamError> {
        let (g, local) = self.place(cloth).ok_or_else(|| no_cloth(cloth))?;
        self.groups[g].solver.set_cloth_params(local, params)
    }

    /// The collision thickness of scene cloth `cloth` (m), if it exists.
    pub fn thickness(&self, cloth: usize) -> Option<f64> {
        let (g, local) = self.place(cloth)?;
        Some(self.groups[g].solver.cloths()[local].thickness)
    }

    /// Changes the collision thickness of scene cloth `cloth` (m), in its solver and its
    /// collision world.
    pub fn set_thickness(&mut self, cloth: usize, thickness: f64) -> Result<(), ParamError> {
        let (g, local) = self.place(cloth).ok_or_else(|| no_cloth(cloth))?;
        let group = &mut self.groups[g];
        group.solver.set_thickness(local, thickness)?;
        if let Some(w) = group.world.as_mut() {
            w.sync_thickness(&group.solver);
        }
        Ok(())
    }
}

fn no_cloth(cloth: usize) -> ParamError {
    ParamError {
        name: "cloth".into(),
        value: cloth as f64,
        expected: "an existing cloth index",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tests::sim;

    fn set(s: &mut Simulation, key: &str, v: Value) -> Result<(), SimError> {
        s.set(key, &v)
    }

    #[test]
    fn every_live_key_reaches_every_solver() {
        let mut s = sim("xpbd", "[0.0, -9.81, 0.0]");
        set(&mut s, "sim.substeps", Value::Number(7.0)).expect("substeps");
        set(&mut s, "sim.iterations", Value::Number(3.0)).expect("iterations");
        set(&mut s, "sim.method", Value::Text("pbd".into())).expect("method");
        set(&mut s, "sim.gravity", Value::Vector([0.0, -1.0, 0.0])).expect("gravity");
        set(&mut s, "sim.damping", Value::Number(0.5)).expect("damping");
        set(&mut s, "wind.velocity", Value::Vector([1.0, 0.0, 0.0])).expect("wind");
        set(&mut s, "wind.drag", Value::Number(0.25)).expect("drag");
        set(&mut s, "cloth.a.thickness", Value::Number(0.01)).expect("thickness");
        set(&mut s, "cloth.a.stretch_compliance", Value::Number(1e-4)).expect("compliance");
        set(&mut s, "cloth.a.shear_pbd_stiffness", Value::Number(0.5)).expect("pbd");
        set(
            &mut s,
            "cloth.a.bend_distance_spring_stiffness",
            Value::Number(9.0),
        )
        .expect("springs");
        let st = s.settings();
        assert_eq!((st.substeps, st.iterations, st.method), (7, 3, Method::Pbd));
        assert_eq!(s.groups[0].method, Method::Pbd);
        let f = s.forces();
        assert_eq!(f.gravity, DVec3::new(0.0, -1.0, 0.0));
        assert_eq!((f.damping, f.wind.drag), (0.5, 0.25));
        assert_eq!(f.wind.velocity, DVec3::X);
        assert_eq!(s.thickness(0), Some(0.01));
        let p = s.cloth_params(0).expect("cloth a");
        assert_eq!(p.get(Family::Stretch).compliance, 1e-4);
        assert_eq!(p.get(Family::Shear).pbd_stiffness, 0.5);
        assert_eq!(p.get(Family::BendDistance).spring_stiffness, 9.0);
        s.step().expect("steps with every change");
    }

    #[test]
    fn bad_keys_and_values_are_refused_and_change_nothing() {
        let mut s = sim("xpbd", "[0.0, -9.81, 0.0]");
        let before = (s.settings(), s.forces(), s.cloth_params(0));
        let cases = [
            ("sim.substep", Value::Number(5.0), "not a live setting"),
            ("sim.substeps", Value::Number(0.0), "whole number >= 1"),
            ("sim.substeps", Value::Number(2.5), "whole number >= 1"),
            (
                "sim.iterations",
                Value::Text("3".into()),
                "whole number >= 1",
            ),
            ("sim.method", Value::Text("rk4".into()), "unknown method"),
            ("sim.damping", Value::Number(f64::NAN), "finite number"),
            ("sim.damping", Value::Number(-1.0), "invalid"),
            ("sim.gravity", Value::Number(1.0), "three finite numbers"),
            ("sim.dt", Value::Number(0.0), "time step > 0"),
            (
                "cloth.b.thickness",
                Value::Number(0.1),
                "no cloth named `b`",
            ),
            (
                "cloth.a.stretch_enabled",
                Value::Number(0.0),
                "when the scene is built",
            ),
            ("cloth.a.shear_pbd_stiffness", Value::Number(2.0), "[0, 1]"),
            (
                "cloth.a.stretch_stiffness",
                Value::Number(1.0),
                "not a live setting",
            ),
            ("cloth.a.thickness", Value::Number(-0.1), "invalid"),
        ];
        for (key, v, says) in cases {
            let e = set(&mut s, key, v).expect_err(key);
            assert!(e.to_string().contains(says), "{key}: {e}");
        }
        assert_eq!((s.settings(), s.forces(), s.cloth_params(0)), before);
    }

    #[test]
    fn a_new_time_step_keeps_time_the_sum_of_the_steps() {
        let mut s = sim("xpbd", "[0.0, -9.81, 0.0]");
        let dt = s.settings().dt;
        for _ in 0..3 {
            s.step().expect("steps");
        }
        assert_eq!(s.time(), 3.0 * dt, "the scene's step alone: frame × dt");
        set(&mut s, "sim.dt", Value::Text("1/120".into())).expect("fraction");
        s.step().expect("steps");
        s.step().expect("steps");
        assert!(
            (s.time() - (3.0 * dt + 2.0 / 120.0)).abs() < 1e-12,
            "{}",
            s.time()
        );
    }
}
