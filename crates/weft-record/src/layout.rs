//! A log's opening: its schemas and channels, the scene and settings as metadata and
//! attachments. Written on the caller's thread before any frame, so a log that cannot be
//! started fails at once.

use std::collections::BTreeMap;
use std::io::BufWriter;

use foxglove::Encode;
use foxglove::messages::{PointCloud, SceneUpdate};
use mcap::records::Metadata;
use mcap::{Attachment, WriteOptions, Writer};
use serde_json::{Value, json};

use crate::collider_state;
use crate::error::{RecordError, Result};
use crate::options::{Compression, RecordOptions};
use crate::sink::Sink;
use weft_sim::Simulation;

/// The MCAP writer of a log.
pub(crate) type LogWriter = Writer<BufWriter<Sink>>;

/// The metadata record that describes a log's channels again, outside chunks: the recorder
/// adds every schema and channel to the log's first chunk, and when that chunk is damaged
/// `weft recover` rebuilds them from this. Keys are channel ids; each value is a JSON object
/// with the channel's `topic`, `message_encoding` and `schema` (`id`, `name`, `encoding`, and
/// for a JSON schema its `text`; a foxglove schema is named only, see [`foxglove_schema`]).
pub const CHANNELS: &str = "weft.channels";

/// The zstd level of the log's chunks with `--compression zstd`, chosen by measurement
/// (docs/performance-notes.md, "Logging"): on the 128² reference's frames level 1 compresses
/// 1.4× to 1.7× as fast as zstd's default (level 3) to within 1 % of its size.
pub const ZSTD_LEVEL: u32 = 1;

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
fn schema_of<T: Encode>(w: &mut LogWriter) -> Result<Added> {
    let s = T::get_schema().ok_or(RecordError::SchemaMissing(std::any::type_name::<T>()))?;
    let id = w.add_schema(&s.name, &s.encoding, &s.data)?;
    Ok((
        id,
        json!({"id": id, "name": s.name, "encoding": s.encoding}),
    ))
}

/// Adds a JSON schema, described with its text.
pub(crate) fn json_schema(w: &mut LogWriter, name: &str, text: &str) -> Result<Added> {
    let id = w.add_schema(name, "jsonschema", text.as_bytes())?;
    Ok((
        id,
        json!({"id": id, "name": name, "encoding": "jsonschema", "text": text}),
    ))
}

/// Adds a channel, and its entry to `described` (the [`CHANNELS`] metadata).
pub(crate) fn channel(
    w: &mut LogWriter,
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

/// The channel ids of an opened log.
#[derive(Clone, Debug, Default)]
pub(crate) struct Ids {
    /// `/cloth/<name>/particles` per scene cloth, when logged.
    pub particles: Vec<u16>,
    /// `/cloth/<name>/mesh` per scene cloth, when logged.
    pub meshes: Vec<u16>,
    /// `/colliders`, when the scene has colliders or a body.
    pub colliders: Option<u16>,
    /// `/colliders/state`, beside `/colliders`.
    pub collider_state: Option<u16>,
    /// `/stats`.
    pub stats: u16,
}

/// Starts the log in `sink`: schemas, channels, the scene and settings.
pub(crate) fn open(
    sink: Sink,
    sim: &Simulation,
    frames: u64,
    options: &RecordOptions,
) -> Result<(LogWriter, Ids)> {
    let (compression, workers) = match options.compression {
        Compression::None => (None, 0),
        Compression::Zstd => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            (
                Some(mcap::Compression::Zstd),
                u32::try_from(cores).unwrap_or(1),
            )
        }
    };
    let mut w = WriteOptions::new()
        .compression(compression)
        .compression_level(ZSTD_LEVEL)
        .compression_threads(workers)
        .profile("")
        .create(BufWriter::new(sink))?;
    let pc = schema_of::<PointCloud>(&mut w)?;
    let su = schema_of::<SceneUpdate>(&mut w)?;
    let st = json_schema(&mut w, "weft.FrameStats", crate::stats::STATS_SCHEMA)?;
    let mut described = BTreeMap::new();
    let scene = &sim.scene;
    // A character's body is logged with the colliders, and moves every frame.
    let has_body = !weft_sim::body::parts(sim).is_empty() || scene.model.is_some();
    let no_colliders = scene.colliders.is_empty() && !has_body;
    let mut ids = Ids::default();
    for c in &scene.cloths {
        if options.logs_particles() {
            let topic = format!("/cloth/{}/particles", c.name);
            ids.particles
                .push(channel(&mut w, &mut described, &pc, &topic, "protobuf")?);
        }
        if options.has_surface() {
            let topic = format!("/cloth/{}/mesh", c.name);
            ids.meshes
                .push(channel(&mut w, &mut described, &su, &topic, "protobuf")?);
        }
    }
    if !no_colliders {
        ids.colliders = Some(channel(
            &mut w,
            &mut described,
            &su,
            "/colliders",
            "protobuf",
        )?);
    }
    ids.stats = channel(&mut w, &mut described, &st, "/stats", "json")?;
    // Added after every older schema and channel, so theirs keep their ids.
    if !no_colliders {
        let cs = json_schema(
            &mut w,
            collider_state::SCHEMA_NAME,
            &collider_state::schema(),
        )?;
        let topic = collider_state::TOPIC;
        ids.collider_state = Some(channel(&mut w, &mut described, &cs, topic, "json")?);
    }
    w.write_metadata(&Metadata {
        name: CHANNELS.into(),
        metadata: described,
    })?;
    write_run(&mut w, sim, frames, options)?;
    Ok((w, ids))
}

/// The `weft.run` and `weft.resolved` metadata and the scene's attachments.
fn write_run(
    w: &mut LogWriter,
    sim: &Simulation,
    frames: u64,
    options: &RecordOptions,
) -> Result<()> {
    let scene = &sim.scene;
    let overrides: Vec<String> = scene.overrides.iter().map(|o| o.to_string()).collect();
    let mut run: BTreeMap<String, String> = [
        ("scene", scene.name.clone()),
        ("frames", frames.to_string()),
        ("overrides", serde_json::to_string(&overrides)?),
        ("mesh_every", options.mesh_every.to_string()),
        ("timing", options.timing.to_string()),
        ("crossings", sim.measures_crossings().to_string()),
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
    for (key, value) in [
        ("log", options.channels.name().to_owned()),
        ("every", options.every.to_string()),
        ("precision", options.precision.name().to_owned()),
        ("compression", options.compression.name().to_owned()),
    ] {
        run.insert(key.into(), value);
    }
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
    Ok(())
}
