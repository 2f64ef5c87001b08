//! Physical ranges of scene values, each with its reason. Outside them a value is not merely
//! unusual: it overflows or underflows the solver's arithmetic (1/m per particle, α/h² in XPBD,
//! edge lengths against the divergence bound) or makes one frame take hours.

/// A closed range and why it is the range.
pub(crate) struct Range {
    /// Smallest value allowed.
    pub lo: f64,
    /// Largest value allowed.
    pub hi: f64,
    /// Unit, for messages.
    pub unit: &'static str,
    /// Why values outside make no sense.
    pub why: &'static str,
}

/// `sim.dt` (s).
pub(crate) const DT: Range = Range {
    lo: 1e-6,
    hi: 1.0,
    unit: "s",
    why: "below 1 µs a simulated second takes a million frames; above 1 s one frame skips the motion",
};

/// Constraint sweeps per frame, `substeps × iterations`.
pub(crate) const SWEEPS_PER_FRAME: u64 = 1_000_000;

/// A cloth's total `mass` (kg).
pub(crate) const MASS: Range = Range {
    lo: 1e-6,
    hi: 1e6,
    unit: "kg",
    why: "from a milligram to a thousand tonnes; beyond, 1/m per particle under- or overflows",
};

/// A cloth's `density` (kg/m²).
pub(crate) const DENSITY: Range = Range {
    lo: 1e-6,
    hi: 1e6,
    unit: "kg/m²",
    why: "beyond, 1/m per particle under- or overflows",
};

/// A grid cloth's `size` sides (m).
pub(crate) const SIZE: Range = Range {
    lo: 1e-4,
    hi: 1e4,
    unit: "m",
    why: "from 0.1 mm to 10 km: smaller edges vanish in float32 logs, larger cloths start beyond \
          the default divergence bound",
};

/// XPBD compliances (m/N).
pub(crate) const COMPLIANCE: Range = Range {
    lo: 0.0,
    hi: 1e6,
    unit: "m/N",
    why: "softer than 1e6 m/N is no constraint at all, and larger values overflow α/h²",
};

/// XPBD constraint damping and mass-spring damping.
pub(crate) const DAMPING: Range = Range {
    lo: 0.0,
    hi: 1e6,
    unit: "",
    why: "larger damping freezes the cloth and overflows the damping term",
};

/// Mass-spring stiffness (N/m).
pub(crate) const SPRING_STIFFNESS: Range = Range {
    lo: 0.0,
    hi: 1e12,
    unit: "N/m",
    why: "stiffer than steel wire by orders of magnitude; k·h²/m overflows",
};

/// Any position, velocity, acceleration component.
pub(crate) const COORDINATE: Range = Range {
    lo: -1e6,
    hi: 1e6,
    unit: "",
    why: "1000 km and beyond is no cloth scene, and squares of such values overflow",
};

/// A mesh's `scale`.
pub(crate) const SCALE: Range = Range {
    lo: 1e-6,
    hi: 1e6,
    unit: "",
    why: "beyond, vertex positions under- or overflow",
};

/// `sim.cg_tolerance`: the implicit method's relative residual.
pub(crate) const CG_TOLERANCE: Range = Range {
    lo: 1e-14,
    hi: 0.5,
    unit: "",
    why: "below 1e-14 rounding keeps the residual from getting there; above 0.5 the solve \
          stops before it starts",
};

/// `sim.divergence_bound` (m).
pub(crate) const DIVERGENCE_BOUND: Range = Range {
    lo: 1e-3,
    hi: 1e9,
    unit: "m",
    why: "positions beyond 1e9 m have lost all centimetre precision",
};

/// `thickness` (m).
pub(crate) const THICKNESS: Range = Range {
    lo: 0.0,
    hi: 10.0,
    unit: "m",
    why: "a collision layer thicker than 10 m is no cloth",
};

/// `sim.damping` and `wind.drag` (1/s).
pub(crate) const RATE: Range = Range {
    lo: 0.0,
    hi: 1e6,
    unit: "1/s",
    why: "larger rates freeze the cloth within a microsecond",
};

impl Range {
    /// Whether `v` lies inside.
    pub fn holds(&self, v: f64) -> bool {
        v.is_finite() && self.lo <= v && v <= self.hi
    }

    /// "in [lo, hi] unit (why)".
    pub fn expected(&self) -> String {
        let unit = if self.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", self.unit)
        };
        format!("in [{:e}, {:e}]{unit} ({})", self.lo, self.hi, self.why)
    }
}
