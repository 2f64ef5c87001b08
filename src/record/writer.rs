//! The MCAP recorder: channels per cloth, per-frame messages, the scene as metadata and
//! attachments, and a status record written on every way out.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;

use anyhow::Context;
use foxglove::Encode;
use foxglove::messages::{PointCloud, SceneUpdate};
use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, WriteOptions, Writer};

use crate::record::{body, collider_state, messages};
use crate::sim::{FrameStats, Simulation};

/// What a run logs besides particles.
#[derive(Clone, Copy, Debug)]
pub struct RecordOptions {
    /// Log the cloth surface every this many frames (0: never).
    pub mesh_every: u64,
    /// Add wall-clock step time to `/stats` (makes files differ between runs).
    pub timing: bool,
}

/// How a run ended, written as the `weft.status` metadata record.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Status {
    /// Every requested frame was simulated.
    Complete,
    /// SIGINT or SIGTERM stopped the run.
    Interrupted,
    /// The simulation diverged; the message says where.
    Diverged(String),
}

impl Status {
    fn name(&self) -> &'static str {
        match self {
            Status::Complete => "complete",
            Status::Interrupted => "interrupted",
            Status::Diverged(_) => "diverged",
        }
    }
}

/// The JSON schema of `/stats` messages.
const STATS_SCHEMA: &str = r#"{"title":"weft.FrameStats","type":"object","properties":{"frame":{"type":"integer"},"time":{"type":"number","description":"simulated time (s)"},"kinetic_energy":{"type":"number","description":"J"},"residual_max":{"type":"number","description":"largest |C| of distance-like constraints (m)"},"residual_rms":{"type":"number","description":"largest per-solver RMS |C| (m)"},"contacts":{"type":"integer"},"step_ms":{"type":"number","description":"wall-clock step time (ms); only with --timing"}},"required":["frame","time","kinetic_energy","residual_max","residual_rms","contacts"]}"#;

/// Writes one run to an MCAP file.
pub struct Recorder {
    w: Writer<BufWriter<File>>,
    particles: Vec<u16>,
    meshes: Vec<u16>,
    colliders: Option<u16>,
    collider_state: Option<u16>,
    moving_colliders: bool,
    stats: u16,
    sequence: u32,
    options: RecordOptions,
    buf: Vec<u8>,
}

fn schema_of<T: Encode>(w: &mut Writer<BufWriter<File>>) -> anyhow::Result<u16> {
    let s = T::get_schema().context("foxglove schema missing")?;
    Ok(w.add_schema(&s.name, &s.encoding, &s.data)?)
}

impl Recorder {
    /// Starts the log in `file` (already created): schemas, channels, the scene and settings.
    pub fn new(
        file: File,
        sim: &Simulation,
        frames: u64,
        options: RecordOptions,
    ) -> anyhow::Result<Self> {
        let mut w = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            .compression_threads(0)
            .profile("")
            .create(BufWriter::new(file))?;
        let pc = schema_of::<PointCloud>(&mut w)?;
        let su = schema_of::<SceneUpdate>(&mut w)?;
        let st = w.add_schema("weft.FrameStats", "jsonschema", STATS_SCHEMA.as_bytes())?;
        let none = BTreeMap::new();
        let scene = &sim.scene;
        // A character's body is logged with the colliders, and moves every frame.
        let has_body = !crate::body::parts(sim).is_empty() || scene.model.is_some();
        let no_colliders = scene.colliders.is_empty() && !has_body;
        let mut particles = Vec::new();
        let mut meshes = Vec::new();
        for c in &scene.cloths {
            let topic = format!("/cloth/{}/particles", c.name);
            particles.push(w.add_channel(pc, &topic, "protobuf", &none)?);
            if options.mesh_every > 0 {
                let topic = format!("/cloth/{}/mesh", c.name);
                meshes.push(w.add_channel(su, &topic, "protobuf", &none)?);
            }
        }
        let colliders = if no_colliders {
            None
        } else {
            Some(w.add_channel(su, "/colliders", "protobuf", &none)?)
        };
        let stats = w.add_channel(st, "/stats", "json", &none)?;
        // Added after every older schema and channel, so theirs keep their ids.
        let collider_state = if no_colliders {
            None
        } else {
            let cs = w.add_schema(
                collider_state::SCHEMA_NAME,
                "jsonschema",
                collider_state::schema().as_bytes(),
            )?;
            Some(w.add_channel(cs, collider_state::TOPIC, "json", &none)?)
        };
        let overrides: Vec<String> = scene.overrides.iter().map(|o| o.to_string()).collect();
        let run: BTreeMap<String, String> = [
            ("scene", scene.name.clone()),
            ("frames", frames.to_string()),
            ("overrides", serde_json::to_string(&overrides)?),
            ("mesh_every", options.mesh_every.to_string()),
            ("timing", options.timing.to_string()),
            ("weft_version", env!("CARGO_PKG_VERSION").to_owned()),
            (
                "methods",
                scene
                    .methods()
                    .iter()
                    .map(|m| m.name())
                    .collect::<Vec<_>>()
                    .join(","),
            ),
        ]
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect();
        w.write_metadata(&Metadata {
            name: "weft.run".into(),
            metadata: run,
        })?;
        w.write_metadata(&Metadata {
            name: "weft.resolved".into(),
            metadata: BTreeMap::from([("toml".to_owned(), scene.resolved_toml())]),
        })?;
        let mut attach = |name: String, media_type: &str, data: &[u8]| {
            w.attach(&Attachment {
                log_time: 0,
                create_time: 0,
                name,
                media_type: media_type.into(),
                data: std::borrow::Cow::Borrowed(data),
            })
        };
        attach(
            "scene/source.toml".into(),
            "application/toml",
            scene.source.as_bytes(),
        )?;
        attach(
            "scene/effective.toml".into(),
            "application/toml",
            scene.effective.as_bytes(),
        )?;
        attach(
            "scene/resolved.toml".into(),
            "application/toml",
            scene.resolved_toml().as_bytes(),
        )?;
        for (path, bytes) in &scene.files {
            attach(format!("files/{path}"), "model/obj", bytes)?;
        }
        let moving_colliders = has_body
            || scene
                .colliders
                .iter()
                .any(|c| c.motion != weft_solver::Motion::Static);
        Ok(Self {
            w,
            particles,
            meshes,
            colliders,
            collider_state,
            moving_colliders,
            stats,
            sequence: 0,
            options,
            buf: Vec::new(),
        })
    }

    fn put<T: Encode>(&mut self, channel: u16, time: f64, msg: &T) -> anyhow::Result<()>
    where
        T::Error: Send + Sync + 'static,
    {
        self.buf.clear();
        msg.encode(&mut self.buf)?;
        self.raw(channel, time)
    }

    fn raw(&mut self, channel: u16, time: f64) -> anyhow::Result<()> {
        let t = messages::nanos(time);
        self.sequence += 1;
        self.w.write_to_known_channel(
            &MessageHeader {
                channel_id: channel,
                sequence: self.sequence,
                log_time: t,
                publish_time: t,
            },
            &self.buf,
        )?;
        Ok(())
    }

    /// Logs the current state of every cloth, the colliders and the frame's statistics.
    pub fn frame(&mut self, sim: &Simulation, stats: &FrameStats) -> anyhow::Result<()> {
        let time = stats.time;
        let parts = crate::body::parts(sim);
        for (i, c) in sim.scene.cloths.iter().enumerate() {
            let x = sim.cloth_positions(i);
            let ch = self.particles[i];
            self.put(ch, time, &messages::point_cloud(time, x))?;
            let every = self.options.mesh_every;
            if every > 0 && stats.frame % every == 0 {
                let color = messages::method_color(c.method);
                let m = messages::cloth_mesh(time, &c.name, x, &c.mesh.triangles, color);
                let ch = self.meshes[i];
                self.put(ch, time, &m)?;
            }
        }
        if let Some(ch) = self.colliders
            && (stats.frame == 0 || self.moving_colliders)
        {
            let mut m = messages::colliders(time, &sim.scene.colliders);
            m.entities.extend(body::entities(time, &parts));
            // A skinned body is as large as a cloth mesh: logged when the cloth meshes are.
            let every = self.options.mesh_every;
            if (stats.frame == 0 || (every > 0 && stats.frame % every == 0))
                && let Some((vertices, triangles)) = crate::body::model_mesh(sim)
            {
                m.entities
                    .push(body::model_entity(time, vertices, triangles));
            }
            self.put(ch, time, &m)?;
        }
        if let Some(ch) = self.collider_state {
            let states = collider_state::states(time, &sim.scene.colliders, &parts);
            let m = collider_state::message(stats.frame, time, &states);
            self.buf = serde_json::to_vec(&m)?;
            self.raw(ch, time)?;
        }
        let mut json = serde_json::json!({
            "frame": stats.frame,
            "time": stats.time,
            "kinetic_energy": stats.kinetic_energy,
            "residual_max": stats.residual_max,
            "residual_rms": stats.residual_rms,
            "contacts": stats.contacts,
        });
        if self.options.timing {
            json["step_ms"] = stats.step_ms.into();
        }
        self.buf = serde_json::to_vec(&json)?;
        self.raw(self.stats, time)
    }

    /// Adds a JSON channel (described by a JSON schema) for messages written with
    /// [`Recorder::json`], e.g. the viewer's `/interaction`.
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema: &str,
    ) -> anyhow::Result<u16> {
        let id = self
            .w
            .add_schema(schema_name, "jsonschema", schema.as_bytes())?;
        Ok(self.w.add_channel(id, topic, "json", &BTreeMap::new())?)
    }

    /// Writes one JSON message at simulated time `time` (s) on a channel from
    /// [`Recorder::add_json_channel`].
    pub fn json(
        &mut self,
        channel: u16,
        time: f64,
        value: &serde_json::Value,
    ) -> anyhow::Result<()> {
        self.buf = serde_json::to_vec(value)?;
        self.raw(channel, time)
    }

    /// Writes the status record, the summary section and the footer, and syncs the file.
    pub fn finish(mut self, status: &Status, frames_simulated: u64) -> anyhow::Result<()> {
        let message = match status {
            Status::Diverged(m) => m.clone(),
            _ => String::new(),
        };
        self.w.write_metadata(&Metadata {
            name: "weft.status".into(),
            metadata: BTreeMap::from([
                ("status".to_owned(), status.name().to_owned()),
                ("frames".to_owned(), frames_simulated.to_string()),
                ("message".to_owned(), message),
            ]),
        })?;
        self.w.finish()?;
        let file = self
            .w
            .into_inner()
            .into_inner()
            .map_err(|e| e.into_error())?;
        file.sync_all()?;
        Ok(())
    }
}
