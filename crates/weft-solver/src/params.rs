//! Constraint families and their per-method parameters.

use thiserror::Error;

/// A family of constraints; each cloth sets each family's parameters on its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// Mesh edges (grid lines on grids).
    Stretch,
    /// Quad diagonals on grids.
    Shear,
    /// Distance between the two wing vertices across each interior edge (cheap, but weak near
    /// flat: the distance changes as cos(θ/2), so its gradient vanishes at θ = 0).
    BendDistance,
    /// Dihedral angle across each interior edge.
    BendDihedral,
    /// Isometric bending across each interior edge: the quadratic energy of Bergou et al. 2006,
    /// flat at rest (constant weights, no angle: cheaper than the dihedral).
    BendIsometric,
    /// Long-range attachments to pinned particles (unilateral: only resists stretching).
    Tether,
}

impl Family {
    /// Every family, in a fixed order.
    pub const ALL: [Family; 6] = [
        Family::Stretch,
        Family::Shear,
        Family::BendDistance,
        Family::BendDihedral,
        Family::BendIsometric,
        Family::Tether,
    ];

    /// Number of families.
    pub const COUNT: usize = Self::ALL.len();

    /// Position of the family in [`Family::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// Lower-case name as used in scene files (`stretch`, `shear`, `bend_distance`, …).
    pub fn name(self) -> &'static str {
        match self {
            Family::Stretch => "stretch",
            Family::Shear => "shear",
            Family::BendDistance => "bend_distance",
            Family::BendDihedral => "bend_dihedral",
            Family::BendIsometric => "bend_isometric",
            Family::Tether => "tether",
        }
    }
}

/// The parameters of one constraint family, for each method.
///
/// Units: distance families (stretch, shear, bend-distance, tether) use m/N for compliance and
/// N/m for spring stiffness; the dihedral family uses rad/(N·m) and N·m/rad; the isometric
/// family's C is dimensionless (|e| θ/√A_e for a small fold θ) and its stiffness is the
/// bending stiffness B itself: 1/(N·m) and N·m.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FamilyParams {
    /// Whether the family's constraints are created at all.
    pub enabled: bool,
    /// XPBD compliance α (inverse stiffness); 0 is infinitely stiff.
    pub compliance: f64,
    /// XPBD constraint damping β: the Rayleigh damping coefficient of Macklin et al. 2016,
    /// eq. (26), a force −β Ċ ∇C (N·s/m for distance families, N·m·s/rad for the dihedral).
    pub damping: f64,
    /// PBD stiffness k in [0, 1], applied to each projection (Müller et al. 2007, §3.3).
    pub pbd_stiffness: f64,
    /// Mass-spring stiffness.
    pub spring_stiffness: f64,
    /// Mass-spring damping along the spring (N·s/m).
    pub spring_damping: f64,
}

impl FamilyParams {
    /// Defaults for a family: stiff in-plane, soft bend-distance bending, tethers off.
    ///
    /// The dihedral family is off by default: in contact-heavy drapes (a cloth on a sphere)
    /// XPBD with dihedral bending was measured to gain energy, while it conserves energy in
    /// free motion; see the README's known issues.
    pub fn default_for(family: Family) -> Self {
        let (enabled, compliance, pbd_stiffness, spring_stiffness) = match family {
            Family::Stretch => (true, 0.0, 1.0, 5.0e3),
            Family::Shear => (true, 1e-6, 1.0, 2.0e3),
            Family::BendDistance => (true, 1e-3, 0.1, 50.0),
            Family::BendDihedral => (false, 1.0, 0.05, 0.05),
            Family::BendIsometric => (false, 1e4, 0.05, 1e-4),
            Family::Tether => (false, 0.0, 1.0, 5.0e3),
        };
        Self {
            enabled,
            compliance,
            damping: 0.0,
            pbd_stiffness,
            spring_stiffness,
            spring_damping: 0.0,
        }
    }

    /// Checks a compliance, damping, spring stiffness or spring damping: finite and ≥ 0.
    /// Says what is expected otherwise.
    pub fn check_non_negative(v: f64) -> Result<(), &'static str> {
        if v.is_finite() && v >= 0.0 {
            Ok(())
        } else {
            Err("finite and >= 0")
        }
    }

    /// Checks a PBD stiffness: finite and in [0, 1]. Says what is expected otherwise.
    pub fn check_pbd_stiffness(v: f64) -> Result<(), &'static str> {
        if v.is_finite() && (0.0..=1.0).contains(&v) {
            Ok(())
        } else {
            Err("finite and in [0, 1]")
        }
    }

    /// Checks every value is finite and in range; `family` names the parameter in the error.
    pub fn validate(&self, family: Family) -> Result<(), ParamError> {
        self.validate_as(family.name())
    }

    /// Defaults for seams: held closed almost rigidly (XPBD compliance 10⁻⁹ m/N, PBD
    /// stiffness 1) and, for the spring methods, the stretch family's default stiffness.
    pub fn seam_default() -> Self {
        Self {
            enabled: true,
            compliance: 1e-9,
            ..Self::default_for(Family::Stretch)
        }
    }

    /// As [`FamilyParams::validate`], naming the parameters `<name>.<field>`.
    pub fn validate_as(&self, name: &str) -> Result<(), ParamError> {
        let non_negative = Self::check_non_negative as fn(f64) -> Result<(), &'static str>;
        [
            ("compliance", self.compliance, non_negative),
            ("damping", self.damping, non_negative),
            (
                "pbd_stiffness",
                self.pbd_stiffness,
                Self::check_pbd_stiffness,
            ),
            ("spring_stiffness", self.spring_stiffness, non_negative),
            ("spring_damping", self.spring_damping, non_negative),
        ]
        .into_iter()
        .try_for_each(|(field, value, check)| {
            check(value).map_err(|expected| ParamError {
                name: format!("{name}.{field}"),
                value,
                expected,
            })
        })
    }
}

/// The material directions a constraint acts along, on a grid cloth: the warp is the grid's
/// rows (its first index), the weft its columns, the bias the diagonals between them.
///
/// A stretch constraint acts along its edge. A bending hinge bends the cloth across its edge:
/// a hinge on an edge along the weft bends a strip that runs along the warp, so it takes the
/// warp's bending. Constraints of a cloth without a grid take the bias.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Along the grid's rows (the first index).
    Warp,
    /// Along the grid's columns.
    Weft,
    /// Diagonal to both, or a cloth without a grid.
    Bias,
}

impl Direction {
    /// Every direction, in the order of the solver's parameter groups.
    pub const ALL: [Direction; 3] = [Direction::Warp, Direction::Weft, Direction::Bias];

    /// Position in [`Direction::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }
}

/// How much stiffer one family is along the weft and the bias than along the warp (the
/// family's own parameters); 1 and 1 for an isotropic cloth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Anisotropy {
    /// Weft stiffness over warp stiffness.
    pub weft: f64,
    /// Bias stiffness over warp stiffness.
    pub bias: f64,
}

impl Default for Anisotropy {
    fn default() -> Self {
        Self::ISOTROPIC
    }
}

impl Anisotropy {
    /// The same stiffness in every direction.
    pub const ISOTROPIC: Anisotropy = Anisotropy {
        weft: 1.0,
        bias: 1.0,
    };

    /// The ratio for `direction`.
    pub fn ratio(&self, direction: Direction) -> f64 {
        match direction {
            Direction::Warp => 1.0,
            Direction::Weft => self.weft,
            Direction::Bias => self.bias,
        }
    }
}

impl FamilyParams {
    /// These parameters made `ratio` times stiffer, for a solver running `iterations`
    /// iterations: XPBD compliance ÷ ratio, spring stiffness × ratio, damping unchanged; PBD
    /// stiffness k such that n iterations remove what a spring `ratio` times stiffer would in
    /// XPBD's first iteration: with f = 1 − (1 − k)ⁿ the fraction removed and
    /// q = f/(1 − f) = s α̃⁻¹ (Macklin et al. 2016, eq. 18), q' = ratio · q.
    pub fn scaled(&self, ratio: f64, iterations: u32) -> FamilyParams {
        if ratio == 1.0 {
            return *self;
        }
        let n = f64::from(iterations.max(1));
        let f = 1.0 - (1.0 - self.pbd_stiffness).powf(n);
        let pbd_stiffness = if f >= 1.0 {
            self.pbd_stiffness
        } else {
            let q = ratio * f / (1.0 - f);
            let f = q / (1.0 + q);
            (1.0 - (1.0 - f).powf(1.0 / n)).clamp(0.0, 1.0)
        };
        FamilyParams {
            compliance: self.compliance / ratio,
            spring_stiffness: self.spring_stiffness * ratio,
            pbd_stiffness,
            ..*self
        }
    }
}

/// Parameters of every family of one cloth, indexed by [`Family::index`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClothParams {
    /// One entry per family: its values along the warp (every direction when isotropic).
    pub families: [FamilyParams; Family::COUNT],
    /// Per family, how much stiffer it is along the weft and the bias.
    pub anisotropy: [Anisotropy; Family::COUNT],
}

impl Default for ClothParams {
    fn default() -> Self {
        Self {
            families: Family::ALL.map(FamilyParams::default_for),
            anisotropy: [Anisotropy::ISOTROPIC; Family::COUNT],
        }
    }
}

impl ClothParams {
    /// The parameters of `family`.
    pub fn get(&self, family: Family) -> &FamilyParams {
        &self.families[family.index()]
    }

    /// Mutable parameters of `family`.
    pub fn get_mut(&mut self, family: Family) -> &mut FamilyParams {
        &mut self.families[family.index()]
    }

    /// Builder-style: sets `family`'s parameters.
    pub fn with(mut self, family: Family, params: FamilyParams) -> Self {
        self.families[family.index()] = params;
        self
    }

    /// Builder-style: edits `family`'s parameters in place.
    pub fn edit(mut self, family: Family, f: impl FnOnce(&mut FamilyParams)) -> Self {
        f(self.get_mut(family));
        self
    }

    /// Validates every family and its anisotropy (ratios finite and > 0).
    pub fn validate(&self) -> Result<(), ParamError> {
        Family::ALL.iter().try_for_each(|&f| {
            self.get(f).validate(f)?;
            let a = self.anisotropy[f.index()];
            for (field, value) in [("weft", a.weft), ("bias", a.bias)] {
                if !(value.is_finite() && value > 0.0) {
                    return Err(ParamError {
                        name: format!("{}.anisotropy.{field}", f.name()),
                        value,
                        expected: "finite and > 0",
                    });
                }
            }
            Ok(())
        })
    }

    /// The parameter groups of this cloth, as the solver's constraints index them
    /// ([`ClothParams::group`]): every family along each [`Direction`], for a solver running
    /// `iterations` iterations.
    pub fn groups(&self, iterations: u32) -> [FamilyParams; GROUPS_PER_CLOTH] {
        std::array::from_fn(|g| {
            let (direction, family) = (Direction::ALL[g / Family::COUNT], g % Family::COUNT);
            let ratio = self.anisotropy[family].ratio(direction);
            self.families[family].scaled(ratio, iterations)
        })
    }

    /// The group index of `family` along `direction` on cloth `cloth`.
    pub fn group(cloth: usize, family: Family, direction: Direction) -> u32 {
        (cloth * GROUPS_PER_CLOTH + direction.index() * Family::COUNT + family.index()) as u32
    }
}

/// Every cloth's parameter groups, in cloth order (see [`ClothParams::groups`]).
pub(crate) fn expand(cloths: &[ClothParams], iterations: u32) -> Vec<FamilyParams> {
    cloths.iter().flat_map(|c| c.groups(iterations)).collect()
}

/// Parameter groups per cloth: one per family and [`Direction`].
pub const GROUPS_PER_CLOTH: usize = Family::COUNT * Direction::ALL.len();

/// A parameter outside the range where it makes sense.
#[derive(Clone, Debug, Error, PartialEq)]
#[error("parameter `{name}` = {value} is invalid: {expected}")]
pub struct ParamError {
    /// Dotted name of the parameter, e.g. `stretch.compliance`.
    pub name: String,
    /// The value given.
    pub value: f64,
    /// What was expected.
    pub expected: &'static str,
}

/// Checks a cloth thickness (m) is finite and non-negative.
pub(crate) fn check_thickness(thickness: f64) -> Result<(), ParamError> {
    if thickness.is_finite() && thickness >= 0.0 {
        Ok(())
    } else {
        Err(ParamError {
            name: "thickness".into(),
            value: thickness,
            expected: "finite and >= 0",
        })
    }
}
