//! `weft view --record`: the session logged in the layout of `weft run --out`, plus an
//! `/interaction` channel with the grabbed particle and drag target of every frame.

use anyhow::Context;

use crate::app::grab::Grab;
use crate::output::Output;
use weft_record::{RecordOptions, Recorder, Status};
use weft_sim::{FrameStats, Simulation};

/// The JSON schema of `/interaction` messages.
const INTERACTION_SCHEMA: &str = r#"{"title":"weft.Interaction","type":"object","properties":{"frame":{"type":"integer","description":"frame of the session (continues across resets)"},"time":{"type":"number","description":"simulated time of the session (s)"},"grabbed":{"type":"boolean"},"cloth":{"type":["string","null"],"description":"name of the grabbed cloth"},"cloth_index":{"type":["integer","null"]},"particle":{"type":["integer","null"],"description":"index within the cloth, as in /cloth/<name>/particles"},"target":{"type":["array","null"],"items":{"type":"number"},"description":"drag target (m)"}},"required":["frame","time","grabbed"]}"#;

/// An open session log, written to its partial file and renamed into place when finished.
pub struct SessionLog {
    rec: Recorder,
    out: Output,
    interaction: u16,
    frames: u64,
    time: f64,
}

impl SessionLog {
    /// Starts the log in `out` (already claimed) with the scene of `sim` as frame 0.
    pub fn new(
        out: Output,
        sim: &Simulation,
        options: RecordOptions,
        planned: u64,
    ) -> anyhow::Result<Self> {
        let target = out.target().display().to_string();
        let mut rec = Recorder::new(out.handle()?, sim, planned, options)
            .with_context(|| format!("writing {target}"))?;
        let interaction = rec
            .add_json_channel("/interaction", "weft.Interaction", INTERACTION_SCHEMA)
            .with_context(|| format!("writing {target}"))?;
        let mut log = Self {
            rec,
            out,
            interaction,
            frames: 0,
            time: 0.0,
        };
        let stats = sim.stats(0.0, 0);
        log.write(sim, stats, None)?;
        Ok(log)
    }

    /// Logs the frame just stepped (`dt` long), numbered and timed by the session so that
    /// log time keeps increasing across resets.
    pub fn frame(
        &mut self,
        sim: &Simulation,
        stats: FrameStats,
        dt: f64,
        grab: Option<&Grab>,
    ) -> anyhow::Result<()> {
        self.frames += 1;
        self.time += dt;
        self.write(sim, stats, grab)
            .with_context(|| format!("writing {}", self.out.target().display()))
    }

    fn write(
        &mut self,
        sim: &Simulation,
        mut stats: FrameStats,
        grab: Option<&Grab>,
    ) -> anyhow::Result<()> {
        stats.frame = self.frames;
        stats.time = self.time;
        self.rec.frame(sim, &stats)?;
        let json = match grab {
            Some(g) => serde_json::json!({
                "frame": self.frames,
                "time": self.time,
                "grabbed": true,
                "cloth": sim.scene.cloths.get(g.cloth).map(|c| c.name.clone()),
                "cloth_index": g.cloth,
                "particle": g.particle,
                "target": g.target.to_array(),
            }),
            None => serde_json::json!({
                "frame": self.frames,
                "time": self.time,
                "grabbed": false,
                "cloth": null,
                "cloth_index": null,
                "particle": null,
                "target": null,
            }),
        };
        Ok(self.rec.json(self.interaction, self.time, &json)?)
    }

    /// Writes the status and the summary, closes the file and renames it into place.
    pub fn finish(self, status: &Status) -> anyhow::Result<()> {
        let target = self.out.target().display().to_string();
        self.rec
            .finish(status, self.frames)
            .with_context(|| format!("finishing {target}"))?;
        self.out.commit()
    }
}
