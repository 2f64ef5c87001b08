//! Each cloth's explicit-spring stability limit, in words, for `weft check` and the viewer.

use weft_solver::Solver;

/// One cloth's stability verdict.
pub struct Verdict {
    /// The line to show.
    pub text: String,
    /// False when the run will or may explode: an explicit method with its substep past (or
    /// within 10 % of) the highest mode's limit.
    pub ok: bool,
}

/// The verdict for cloth `cloth` of `solver` at its current method and substep.
pub fn verdict(solver: &Solver, cloth: usize) -> Option<Verdict> {
    let bound = solver.stability(cloth)?;
    let name = &solver.cloths().get(cloth)?.name;
    let s = solver.settings();
    let (h, limit, sure) = (s.h(), bound.mode_max_substep(), bound.max_substep());
    if !s.method.is_explicit() {
        return Some(Verdict {
            text: format!(
                "cloth `{name}` ({}): no substep limit (explicit springs would need h < {})",
                s.method.name(),
                millis(limit),
            ),
            ok: true,
        });
    }
    // The estimate is a Rayleigh quotient (ω from below), and tension adds stiffness: keep 10 %.
    let ok = h < 0.9 * limit;
    let text = format!(
        "cloth `{name}` ({}): largest stable substep h < {} (highest mode ω = {:.0} rad/s, \
         γ = {:.0} 1/s; guaranteed below {} by Gershgorin's ω ≤ {:.0} rad/s); substep {} is \
         {:.2} of it{}",
        s.method.name(),
        millis(limit),
        bound.mode_omega,
        bound.mode_gamma,
        millis(sure),
        bound.omega,
        millis(h),
        h / limit,
        if ok {
            String::new()
        } else {
            format!(
                " — {}: use sim.substeps >= {} or softer springs",
                if h >= limit {
                    "will explode"
                } else {
                    "may explode"
                },
                (s.dt / (0.9 * limit)).floor() as u64 + 1
            )
        }
    );
    Some(Verdict { text, ok })
}

fn millis(s: f64) -> String {
    if s.is_finite() {
        format!("{:.3} ms", s * 1e3)
    } else {
        "∞".to_owned()
    }
}
