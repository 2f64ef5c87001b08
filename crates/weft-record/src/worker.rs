//! The log's own thread: it encodes the frames the run hands over, compresses and writes them,
//! in the order they were handed over, so a log's bytes do not depend on its timing.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, SyncSender};

use foxglove::Encode;
use foxglove::messages::SceneUpdate;
use mcap::records::{MessageHeader, Metadata};
use serde_json::Value;
use weft_sim::FrameStats;
use weft_solver::glam::DVec3;

use crate::error::{RecordError, Result};
use crate::layout::{CHANNELS, Ids, LogWriter, channel, json_schema};
use crate::messages;
use crate::options::RecordOptions;
use crate::status::Status;
use crate::surface::SurfaceEncoder;

/// One frame as the run handed it over: copies, so the run may step on at once.
pub(crate) struct Frame {
    /// The frame's statistics.
    pub stats: FrameStats,
    /// Each scene cloth's positions, in particle order.
    pub cloths: Vec<Vec<DVec3>>,
    /// Whether this frame carries the surface.
    pub surface: bool,
    /// `/colliders`, when logged this frame.
    pub colliders: Option<SceneUpdate>,
    /// `/colliders/state`, when the log has it.
    pub collider_state: Option<Value>,
    /// How long the run had waited for the queue before this frame (ms), with `timing`.
    pub waited_ms: f64,
}

/// What the run asks of the log's thread.
pub(crate) enum Job {
    /// Log a frame.
    Frame(Box<Frame>),
    /// Write a JSON message on a channel added with `AddChannel`.
    Json {
        /// The channel.
        channel: u16,
        /// Simulated time (s).
        time: f64,
        /// The encoded message.
        data: Vec<u8>,
    },
    /// Add a JSON channel; its id goes back on `reply`.
    AddChannel {
        /// The channel's topic.
        topic: String,
        /// Its schema's name.
        schema_name: String,
        /// Its JSON schema.
        schema: String,
        /// Where the id (or the error) goes.
        reply: SyncSender<Result<u16>>,
    },
    /// Write the status, the summary and the footer, and sync the file.
    Finish {
        /// How the run ended.
        status: Status,
        /// Frames simulated.
        frames: u64,
    },
}

/// The log's thread's state.
pub(crate) struct Worker {
    /// The MCAP writer.
    pub w: LogWriter,
    /// Its channels.
    pub ids: Ids,
    /// Each scene cloth's surface messages.
    pub surfaces: Vec<SurfaceEncoder>,
    /// What is logged.
    pub options: RecordOptions,
    /// Position buffers handed back to the run for reuse.
    pub spare: Sender<Vec<DVec3>>,
    /// The last message's sequence number.
    pub sequence: u32,
    /// The message being encoded.
    pub buf: Vec<u8>,
    /// Frames written so far.
    pub frames: Arc<AtomicU64>,
}

impl Worker {
    /// Serves `jobs` until the run finishes the log (or drops it: the log is then closed
    /// without a status, as a killed run's would be recovered).
    pub fn run(mut self, jobs: Receiver<Job>) -> Result<()> {
        while let Ok(job) = jobs.recv() {
            match job {
                Job::Frame(f) => self.frame(*f)?,
                Job::Json {
                    channel,
                    time,
                    data,
                } => {
                    self.buf = data;
                    self.raw(channel, time)?;
                }
                Job::AddChannel {
                    topic,
                    schema_name,
                    schema,
                    reply,
                } => {
                    // The run waits on the reply; it may have gone only if it panicked.
                    let _ = reply.send(self.add_channel(&topic, &schema_name, &schema));
                }
                Job::Finish { status, frames } => return self.finish(&status, frames),
            }
        }
        self.w.finish()?;
        Ok(())
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

    /// Every cloth's channels, then the colliders, their states and the statistics.
    fn frame(&mut self, f: Frame) -> Result<()> {
        let time = f.stats.time;
        let precision = self.options.precision;
        for (i, x) in f.cloths.iter().enumerate() {
            if let Some(&ch) = self.ids.particles.get(i) {
                self.put(ch, time, &messages::point_cloud_as(time, x, precision))?;
            }
            if f.surface {
                self.surfaces[i].encode(time, x, &mut self.buf);
                self.raw(self.ids.meshes[i], time)?;
            }
        }
        if let (Some(ch), Some(m)) = (self.ids.colliders, &f.colliders) {
            self.put(ch, time, m)?;
        }
        if let (Some(ch), Some(v)) = (self.ids.collider_state, &f.collider_state) {
            self.buf = serde_json::to_vec(v)?;
            self.raw(ch, time)?;
        }
        let json = crate::stats::json(&f.stats, self.options.timing.then_some(f.waited_ms));
        self.buf = serde_json::to_vec(&json)?;
        self.raw(self.ids.stats, time)?;
        self.frames.fetch_add(1, Ordering::Relaxed);
        for x in f.cloths {
            // The run may have finished and gone: the buffer is then simply dropped.
            let _ = self.spare.send(x);
        }
        Ok(())
    }

    fn add_channel(&mut self, topic: &str, schema_name: &str, schema: &str) -> Result<u16> {
        let schema = json_schema(&mut self.w, schema_name, schema)?;
        let mut described = std::collections::BTreeMap::new();
        let id = channel(&mut self.w, &mut described, &schema, topic, "json")?;
        self.w.write_metadata(&Metadata {
            name: CHANNELS.into(),
            metadata: described,
        })?;
        Ok(id)
    }

    fn finish(mut self, status: &Status, frames_simulated: u64) -> Result<()> {
        let message = match status {
            Status::Diverged(m) => m.clone(),
            _ => String::new(),
        };
        self.w.write_metadata(&Metadata {
            name: "weft.status".into(),
            metadata: std::collections::BTreeMap::from([
                ("status".to_owned(), status.name().to_owned()),
                ("frames".to_owned(), frames_simulated.to_string()),
                ("message".to_owned(), message),
            ]),
        })?;
        self.w.finish()?;
        let sink = self
            .w
            .into_inner()
            .into_inner()
            .map_err(|e| e.into_error())?;
        sink.into_file().sync_all()?;
        Ok(())
    }
}
