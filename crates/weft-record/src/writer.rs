//! The MCAP recorder: channels per cloth, per-frame messages, the scene as metadata and
//! attachments, and a status record written on every way out.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;

use foxglove::Encode;
use foxglove::messages::{PointCloud, SceneUpdate};
use mcap::records::{MessageHeader, Metadata};
use mcap::{Attachment, Compression, WriteOptions, Writer};
use serde_json::{Value, json};

use crate::error::{RecordError, Result};
use crate::{body, collider_state, messages};
use weft_sim::{FrameStats, Simulation};

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

/// The metadata record that describes a log's channels again, outside chunks: the recorder
/// adds every schema and channel to the log's first chunk, and when that chunk is damaged
/// `weft recover` rebuilds them from this. Keys are channel ids; each value is a JSON object
/// with the channel's `topic`, `message_encoding` and `schema` (`id`, `name`, `encoding`, and
/// for a JSON schema its `text`; a foxglove schema is named only, see [`foxglove_schema`]).
pub const CHANNELS: &str = "weft.channels";

/// The data of the foxglove schema called `name` (as the recorder writes it), if it is one.
pub fn foxglove_schema(name: &str) -> Option<Vec<u8>> {
    [PointCloud::get_schema(), SceneUpdate::get_schema()]
        .into_iter()
        .flatten()
        .find(|s| s.name == name)
        .map(|s| s.data.into_owned())
}

/// A schema added to a log: its id, and how the [`CHANNELS`] metadata describes it.
type Added = (u16, Value);

/// Adds the foxglove schema of `T`, described by its name.
fn schema_of<T: Encode>(w: &mut Writer<BufWriter<File>>) -> Result<Added> {
    let s = T::get_schema().ok_or(RecordError::SchemaMissing(std::any::type_name::<T>()))?;
    let id = w.add_schema(&s.name, &s.encoding, &s.data)?;
    Ok((
        id,
        json!({"id": id, "name": s.name, "encoding": s.encoding}),
    ))
}

/// Adds a JSON schema, described with its text.
fn json_schema(w: &mut Writer<BufWriter<File>>, name: &str, text: &str) -> Result<Added> {
    let id = w.add_schema(name, "jsonschema", text.as_bytes())?;
    Ok((
        id,
        json!({"id": id, "name": name, "encoding": "jsonschema", "text": text}),
    ))
}

/// Adds a channel, and its entry to `described` (the [`CHANNELS`] metadata).
fn channel(
    w: &mut Writer<BufWriter<File>>,
    described: &mut BTreeMap<String, String>,
    schema: &Added,
    topic: &str,
    encoding: &str,
) -> Result<u16> {
    let id = w.add_channel(schema.0, topic, encoding, &BTreeMap::new())?;
    let entry = json!({"topic": topic, "message_encoding": encoding, "schema": schema.1});
    described.insert(id.to_string(), entry.to_string());
    Ok(id)
}

impl Recorder {
    /// Starts the log in `file` (already created): schemas, channels, the scene and settings.
    pub fn new(file: File, sim: &Simulation, frames: u64, options: RecordOptions) -> Result<Self> {
        let mut w = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            .compression_threads(0)
            .profile("")
            .create(BufWriter::new(file))?;
        let pc = schema_of::<PointCloud>(&mut w)?;
        let su = schema_of::<SceneUpdate>(&mut w)?;
        let st = json_schema(&mut w, "weft.FrameStats", STATS_SCHEMA)?;
        let mut described = BTreeMap::new();
        let scene = &sim.scene;
        // A character's body is logged with the colliders, and moves every frame.
        let has_body = !weft_sim::body::parts(sim).is_empty() || scene.model.is_some();
        let no_colliders = scene.colliders.is_empty() && !has_body;
        let mut particles = Vec::new();
        let mut meshes = Vec::new();
        for c in &scene.cloths {
            let topic = format!("/cloth/{}/particles", c.name);
            particles.push(channel(&mut w, &mut described, &pc, &topic, "protobuf")?);
            if options.mesh_every > 0 {
                let topic = format!("/cloth/{}/mesh", c.name);
                meshes.push(channel(&mut w, &mut described, &su, &topic, "protobuf")?);
            }
        }
        let colliders = if no_colliders {
            None
        } else {
            Some(channel(
                &mut w,
                &mut described,
                &su,
                "/colliders",
                "protobuf",
            )?)
        };
        let stats = channel(&mut w, &mut described, &st, "/stats", "json")?;
        // Added after every older schema and channel, so theirs keep their ids.
        let collider_state = if no_colliders {
            None
        } else {
            let cs = json_schema(
                &mut w,
                collider_state::SCHEMA_NAME,
                &collider_state::schema(),
            )?;
            let topic = collider_state::TOPIC;
            Some(channel(&mut w, &mut described, &cs, topic, "json")?)
        };
        w.write_metadata(&Metadata {
            name: CHANNELS.into(),
            metadata: described,
        })?;
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

    fn put<T: Encode>(&mut self, channel: u16, time: f64, msg: &T) -> Result<()>
    where
        T::Error: std::error::Error + Send + Sync + 'static,
    {
        self.buf.clear();
        msg.encode(&mut self.buf)
            .map_err(|e| RecordError::Encode(Box::new(e)))?;
        self.raw(channel, time)
    }

    fn raw(&mut self, channel: u16, time: f64) -> Result<()> {
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
    pub fn frame(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<()> {
        let time = stats.time;
        let parts = weft_sim::body::parts(sim);
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
                && let Some((vertices, triangles)) = weft_sim::body::model_mesh(sim)
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
    /// [`Recorder::json`], e.g. the viewer's `/interaction`, and its own [`CHANNELS`] record.
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema: &str,
    ) -> Result<u16> {
        let schema = json_schema(&mut self.w, schema_name, schema)?;
        let mut described = BTreeMap::new();
        let id = channel(&mut self.w, &mut described, &schema, topic, "json")?;
        self.w.write_metadata(&Metadata {
            name: CHANNELS.into(),
            metadata: described,
        })?;
        Ok(id)
    }

    /// Writes one JSON message at simulated time `time` (s) on a channel from
    /// [`Recorder::add_json_channel`].
    pub fn json(&mut self, channel: u16, time: f64, value: &serde_json::Value) -> Result<()> {
        self.buf = serde_json::to_vec(value)?;
        self.raw(channel, time)
    }

    /// Writes the status record, the summary section and the footer, and syncs the file.
    pub fn finish(mut self, status: &Status, frames_simulated: u64) -> Result<()> {
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
