//! `/stats`: one JSON message per logged frame ([`json`]) and its JSON Schema
//! ([`STATS_SCHEMA`]).

use serde_json::Value;
use weft_sim::FrameStats;

/// The JSON schema of `/stats` messages.
pub const STATS_SCHEMA: &str = r#"{"title":"weft.FrameStats","type":"object","properties":{"frame":{"type":"integer"},"time":{"type":"number","description":"simulated time (s)"},"kinetic_energy":{"type":"number","description":"J"},"residual_max":{"type":"number","description":"largest |C| of distance-like constraints (m)"},"residual_rms":{"type":"number","description":"largest per-solver RMS |C| (m)"},"contacts":{"type":"integer"},"cg_iterations":{"type":"integer","description":"conjugate-gradient iterations of the frame's solves: implicit mass-spring's, and XPBD's of stiff bending (with the stretch on cloths up to 20,000 rows)"},"bending_residual":{"type":"number","description":"largest relative residual XPBD's last substep left in the bending hinges' equation (0 converged, 1 a hinge about twice as soft as its compliance); only under XPBD with bending"},"crossings":{"type":"integer","description":"edge-triangle crossings between cloth elements that share no vertex, every cloth of a solver together; only where crossings are measured (cloth can meet cloth, or asked for)"},"closest_approach":{"type":["number","null"],"description":"closest approach between cloth elements that share no vertex (m), null when none comes within crossing_reach; only with crossings"},"crossing_reach":{"type":"number","description":"how far the closest approach is looked for (m): 3 times the largest cloth thickness; only with crossings"},"step_ms":{"type":"number","description":"wall-clock step time (ms); only with --timing"},"log_wait_ms":{"type":"number","description":"wall-clock time the run has waited for the log's queue before this frame (ms); only with --timing"}},"required":["frame","time","kinetic_energy","residual_max","residual_rms","contacts"]}"#;

/// The `/stats` message of a frame; `waited_ms` (the wait for the log's queue) adds the
/// wall-clock fields (`--timing`).
pub(crate) fn json(s: &FrameStats, waited_ms: Option<f64>) -> Value {
    let mut json = serde_json::json!({
        "frame": s.frame,
        "time": s.time,
        "kinetic_energy": s.kinetic_energy,
        "residual_max": s.residual_max,
        "residual_rms": s.residual_rms,
        "contacts": s.contacts,
        "cg_iterations": s.cg_iterations,
    });
    if let Some(b) = s.bending_residual {
        json["bending_residual"] = b.into();
    }
    if let Some(c) = &s.crossings {
        json["crossings"] = c.crossings.into();
        json["closest_approach"] = c.closest.into();
        json["crossing_reach"] = c.reach.into();
    }
    if let Some(w) = waited_ms {
        json["step_ms"] = s.step_ms.into();
        json["log_wait_ms"] = w.into();
    }
    json
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_sim::CrossingStats;

    /// The schema's property names, its required names, and the type(s) of each property.
    fn schema() -> (Value, Vec<String>) {
        let v: Value = serde_json::from_str(STATS_SCHEMA).expect("the schema is JSON");
        let required = v["required"]
            .as_array()
            .expect("required")
            .iter()
            .map(|r| r.as_str().expect("a name").to_owned())
            .collect();
        (v["properties"].clone(), required)
    }

    /// Whether `value` is of the JSON Schema `ty` (a name or a list of names).
    fn of_type(value: &Value, ty: &Value) -> bool {
        match ty {
            Value::Array(tys) => tys.iter().any(|t| of_type(value, t)),
            Value::String(t) => match t.as_str() {
                "integer" => value.is_u64() || value.is_i64(),
                "number" => value.is_number(),
                "null" => value.is_null(),
                _ => false,
            },
            _ => false,
        }
    }

    /// Every message a frame may write holds only the schema's properties, each of its type,
    /// and every required one: without crossings or timing, with both, with no closest
    /// approach within reach.
    #[test]
    fn every_stats_message_fits_its_schema() {
        let (properties, required) = schema();
        let plain = FrameStats {
            frame: 3,
            time: 0.05,
            kinetic_energy: 1.5,
            residual_max: 1e-4,
            residual_rms: 1e-5,
            contacts: 7,
            cg_iterations: 12,
            bending_residual: None,
            step_ms: 2.5,
            crossings: None,
        };
        let measured = |closest| FrameStats {
            crossings: Some(CrossingStats {
                crossings: 12,
                closest,
                reach: 0.006,
            }),
            ..plain
        };
        let cases = [
            (plain, None, 7),
            (plain, Some(0.25), 9),
            (measured(Some(0.0012)), None, 10),
            (measured(None), Some(0.25), 12),
            (
                FrameStats {
                    bending_residual: Some(2e-3),
                    ..plain
                },
                None,
                8,
            ),
        ];
        for (stats, waited, keys) in cases {
            let m = json(&stats, waited);
            let obj = m.as_object().expect("an object");
            assert_eq!(obj.len(), keys, "{m}");
            for (k, v) in obj {
                let ty = &properties[k]["type"];
                assert!(of_type(v, ty), "{k} = {v} is not of type {ty}");
            }
            for r in &required {
                assert!(obj.contains_key(r), "{r} missing from {m}");
            }
        }
        let bent = FrameStats {
            bending_residual: Some(2e-3),
            ..plain
        };
        assert_eq!(json(&bent, None)["bending_residual"], 2e-3);
        assert!(json(&plain, None).get("bending_residual").is_none());
        let m = json(&measured(None), None);
        assert_eq!(m["crossings"], 12);
        assert!(m["closest_approach"].is_null());
        assert_eq!(m["crossing_reach"], 0.006);
        assert_eq!(
            json(&measured(Some(0.0012)), None)["closest_approach"],
            0.0012
        );
    }
}
