//! Each cloth's explicit-spring stability limit, in words, for `weft check`, the viewer's
//! panel, and the warning `run`, `view`, `render` and `experiments` print before they start;
//! for the implicit method, the substeps that keep its swing from being damped away.

use weft_scene::SolverGroup;
use weft_solver::{Method, Solver};

use crate::framing::Bounds;

/// The share of its amplitude a swing should keep over a second under backward Euler.
const KEEP: f64 = 0.9;

/// Share of an undamped mode's amplitude that backward Euler keeps over one second at substep
/// `h`: each substep multiplies it by (1 + ω²h²)^(−1/2) (the implicit step's amplification
/// factor on ẍ = −ω²x; measured in weft-solver's `oscillator_decays_as_backward_euler_predicts`).
fn backward_euler_keep(omega: f64, h: f64) -> f64 {
    (1.0 + (omega * h).powi(2)).powf(-0.5 / h)
}

/// The fewest substeps of a frame `dt` at which backward Euler keeps [`KEEP`] of a mode of
/// `omega` over a second (at most a million).
fn substeps_to_keep(omega: f64, dt: f64) -> u64 {
    // keep(h) rises as h falls: search the power of two above, then bisect.
    let ok = |n: u64| backward_euler_keep(omega, dt / n as f64) >= KEEP;
    let mut hi = 1u64;
    while !ok(hi) && hi < 1 << 20 {
        hi *= 2;
    }
    let mut lo = hi / 2;
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if ok(mid) { hi = mid } else { lo = mid }
    }
    hi.max(1)
}

/// The implicit method's line: stable at any substep, and how many substeps keep the cloth's
/// slowest swing, a hanging chain's fundamental ω = (j₀,₁ / 2) √(g / L) with j₀,₁ = 2.4048
/// the first zero of J₀ and L the cloth's largest extent (Bernoulli's hanging chain).
fn implicit_advice(solver: &Solver, cloth: usize, explicit_limit: f64) -> String {
    let s = solver.settings();
    let c = &solver.cloths()[cloth];
    let head = format!(
        "cloth `{}` ({}): stable at any substep (explicit springs would need h < {})",
        c.name,
        s.method.name(),
        millis(explicit_limit)
    );
    let mut bounds = Bounds::default();
    for p in &solver.particles().positions[c.particles.clone()] {
        bounds.add(p.as_vec3());
    }
    let length = f64::from((bounds.hi - bounds.lo).max_element());
    let g = solver.forces().gravity.length();
    if bounds.is_empty() || !(length > 0.0 && g > 0.0) {
        return head;
    }
    let omega = 0.5 * 2.4048 * (g / length).sqrt();
    let kept = backward_euler_keep(omega, s.h());
    format!(
        "{head}; its numerical damping keeps {:.0} % of the slowest swing's amplitude a second \
         (ω = {omega:.1} rad/s, a {length:.2} m hanging chain's); sim.substeps >= {} keeps \
         {:.0} %, one a frame holds a rest shape",
        kept * 100.0,
        substeps_to_keep(omega, s.dt),
        KEEP * 100.0
    )
}

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
    if s.method == Method::ImplicitMassSpring {
        return Some(Verdict {
            text: implicit_advice(solver, cloth, limit),
            ok: true,
        });
    }
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
                " — {}: use sim.substeps >= {} (inside the guaranteed bound) or softer springs",
                if h >= limit {
                    "will explode"
                } else {
                    "may explode"
                },
                // Not the estimate's count: the walker's T-shirt, advised 462 by it (0.9 of
                // the mode's limit), exploded at 462 and 480 and held at 500.
                bound.min_substeps(s.dt)
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

    /// The substep count a verdict line advises (`sim.substeps >= N`).
    fn suggested(text: &str) -> u64 {
        let tail = text.split("sim.substeps >= ").nth(1).expect("a suggestion");
        tail.split(' ')
            .next()
            .and_then(|n| n.parse().ok())
            .expect("a count")
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
        // The advice is the fewest substeps inside the guaranteed bound, not the estimate's.
        let g = groups("mass-spring");
        let (dt, bound) = (
            g[0].solver.settings().dt,
            g[0].solver.stability(0).expect("bound"),
        );
        let n = suggested(&lines[0]) as f64;
        assert!(dt / n < bound.max_substep(), "{}", lines[0]);
        assert!(dt / (n - 1.0) >= bound.max_substep(), "{}", lines[0]);
        assert!(
            bound.max_substep() < 0.9 * bound.mode_max_substep(),
            "{bound:?}"
        );
    }

    #[test]
    fn the_fewest_substeps_that_keep_the_swing_are_found() {
        let (omega, dt) = (4.0, 1.0 / 60.0);
        let n = substeps_to_keep(omega, dt);
        assert!(backward_euler_keep(omega, dt / n as f64) >= KEEP);
        assert!(
            backward_euler_keep(omega, dt / (n - 1) as f64) < KEEP,
            "{n}"
        );
        // Small ωh: keep ≈ e^(−ω²h/2), so h ≈ 2 ln(1/0.9) / ω² = 13.2 ms: 2 substeps of 16.7 ms.
        assert_eq!(n, 2);
        assert_eq!(substeps_to_keep(0.5, dt), 1);
        // The damping grows as ω²: 10× the frequency needs about 100× the substeps.
        let stiff = substeps_to_keep(40.0, dt);
        assert!((120..=130).contains(&stiff), "{stiff}");
    }

    #[test]
    fn check_tells_implicit_users_the_substeps_that_keep_the_swing() {
        let set = |key: &str, value: &str| weft_scene::Override {
            key: key.into(),
            value: value.into(),
        };
        let scene = |substeps: &str| {
            weft_scene::load(
                std::path::Path::new("assets/scenes/hanging.toml"),
                &[
                    set("sim.method", "\"implicit-mass-spring\""),
                    set("sim.substeps", substeps),
                ],
            )
            .expect("scene loads")
            .build()
            .expect("solvers")
        };
        let one = verdict(&scene("1")[0].solver, 0).expect("a line");
        assert!(one.ok, "{}", one.text);
        assert!(one.text.contains("stable at any substep"), "{}", one.text);
        let n = suggested(&one.text);
        // A 1 m cloth: ω = 1.2024 √9.81 = 3.77 rad/s; one substep of 1/60 s keeps
        // e^(−ω²h/2) ≈ 89 % a second, two keep 94 %.
        assert!(one.text.contains("keeps 89 %"), "{}", one.text);
        assert_eq!(n, 2, "{}", one.text);
        // At the suggested count the line's own figure is at least 90 %.
        let at_n = verdict(&scene(&n.to_string())[0].solver, 0).expect("a line");
        let kept: f64 = at_n
            .text
            .split("keeps ")
            .nth(1)
            .and_then(|t| t.split(' ').next())
            .and_then(|k| k.parse().ok())
            .expect("a share");
        assert!(kept >= 90.0, "{}", at_n.text);
        assert_eq!(
            suggested(&at_n.text),
            n,
            "the advice does not depend on the substep"
        );
    }
}
