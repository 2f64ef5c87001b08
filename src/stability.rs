//! Each cloth's explicit-spring stability limit, in words, for `weft check`, the viewer's
//! panel, and the warning `run`, `view`, `render` and `experiments` print before they start.

use weft_scene::SolverGroup;
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

/// The verdict lines of every cloth in `groups` that will or may explode.
pub fn warnings(groups: &[SolverGroup]) -> Vec<String> {
    groups
        .iter()
        .flat_map(|g| (0..g.solver.cloths().len()).filter_map(|i| verdict(&g.solver, i)))
        .filter(|v| !v.ok)
        .map(|v| v.text)
        .collect()
}

/// Prints each of `groups`' warnings to standard error as `weft check` words them, before a
/// command starts stepping; returns how many there were.
pub fn warn(groups: &[SolverGroup]) -> usize {
    let lines = warnings(groups);
    for line in &lines {
        eprintln!("weft: warning: {line}");
    }
    lines.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn groups(method: &str) -> Vec<SolverGroup> {
        let set = weft_scene::Override {
            key: "cloth.springs.method".into(),
            value: format!("\"{method}\""),
        };
        weft_scene::load(std::path::Path::new("assets/scenes/explode.toml"), &[set])
            .expect("scene loads")
            .build()
            .expect("solvers")
    }

    #[test]
    fn explicit_springs_past_their_limit_are_warned_about() {
        let lines = warnings(&groups("mass-spring"));
        assert_eq!(lines.len(), 1, "{lines:?}");
        assert!(lines[0].contains("cloth `springs`"), "{}", lines[0]);
        assert!(
            lines[0].contains("will explode: use sim.substeps >="),
            "{}",
            lines[0]
        );
        assert!(warnings(&groups("implicit-mass-spring")).is_empty());
    }
}
