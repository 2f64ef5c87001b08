//! The MCAP recorder: the run copies each frame and hands it to the log's own thread behind a
//! bounded queue (it waits only when the queue is full, and never drops a frame); a status
//! record is written on every way out.

use std::fs::File;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, SyncSender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use weft_sim::{FrameStats, Simulation};
use weft_solver::glam::DVec3;

use crate::error::{RecordError, Result};
use crate::layout::{self, Ids};
use crate::options::RecordOptions;
use crate::sink::Sink;
use crate::status::Status;
use crate::surface::SurfaceEncoder;
use crate::worker::{Frame, Job, Worker};
use crate::{body, collider_state, messages};

/// Most bytes of frame copies the queue holds: 64 MiB, at least 2 and at most 16 frames.
pub const QUEUE_BYTES: usize = 64 << 20;

/// How far a log has got.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LogProgress {
    /// Frames handed to the log.
    pub frames: u64,
    /// Frames written by the log's thread.
    pub written_frames: u64,
    /// Bytes written to the file so far.
    pub bytes: u64,
    /// Time the run has waited for a full queue.
    pub waited: Duration,
}

/// Writes one run to an MCAP file on its own thread.
pub struct Recorder {
    jobs: Option<SyncSender<Job>>,
    worker: Option<JoinHandle<Result<()>>>,
    /// Buffers the log's thread hands back (in a mutex only to make the recorder `Sync`).
    spare: Mutex<Receiver<Vec<DVec3>>>,
    ids: Ids,
    moving_colliders: bool,
    options: RecordOptions,
    written: Arc<AtomicU64>,
    written_frames: Arc<AtomicU64>,
    handed: u64,
    last_logged: Option<u64>,
    waited: Duration,
}

impl Recorder {
    /// Starts the log in `file` (already created): schemas, channels, the scene and settings,
    /// written before this returns; frames are written by the log's thread.
    pub fn new(file: File, sim: &Simulation, frames: u64, options: RecordOptions) -> Result<Self> {
        let written = Arc::new(AtomicU64::new(0));
        let (w, ids) = layout::open(Sink::new(file, Arc::clone(&written)), sim, frames, &options)?;
        let scene = &sim.scene;
        let surfaces = scene
            .cloths
            .iter()
            .filter(|_| options.has_surface())
            .map(|c| {
                SurfaceEncoder::new(&c.name, &c.mesh.triangles, messages::method_color(c.method))
            })
            .collect();
        let particles: usize = (0..scene.cloths.len())
            .map(|i| sim.cloth_positions(i).len())
            .sum();
        let frame_bytes = (particles * std::mem::size_of::<DVec3>()).max(1);
        let depth = (QUEUE_BYTES / frame_bytes).clamp(2, 16);
        let (jobs, queue) = mpsc::sync_channel(depth);
        let (give_back, spare) = mpsc::channel();
        let written_frames = Arc::new(AtomicU64::new(0));
        let worker = Worker {
            frames: Arc::clone(&written_frames),
            w,
            ids: ids.clone(),
            surfaces,
            options,
            spare: give_back,
            sequence: 0,
            buf: Vec::new(),
        };
        let worker = std::thread::Builder::new()
            .name("weft-log".into())
            .spawn(move || worker.run(queue))?;
        let has_body = !weft_sim::body::parts(sim).is_empty() || scene.model.is_some();
        let moving_colliders = has_body
            || scene
                .colliders
                .iter()
                .any(|c| c.motion != weft_solver::Motion::Static);
        Ok(Self {
            jobs: Some(jobs),
            worker: Some(worker),
            spare: Mutex::new(spare),
            ids,
            moving_colliders,
            options,
            written,
            written_frames,
            handed: 0,
            last_logged: None,
            waited: Duration::ZERO,
        })
    }

    /// How far the log has got.
    pub fn progress(&self) -> LogProgress {
        LogProgress {
            frames: self.handed,
            written_frames: self.written_frames.load(Ordering::Relaxed),
            bytes: self.written.load(Ordering::Relaxed),
            waited: self.waited,
        }
    }

    /// The log thread's error, once it has stopped on one.
    fn failed(&mut self) -> RecordError {
        self.jobs = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(Err(e))) => e,
            Some(Err(_)) => RecordError::Worker("the log's thread panicked".into()),
            _ => RecordError::Worker("the log's thread has stopped".into()),
        }
    }

    /// Hands `job` to the log's thread, waiting while the queue is full.
    fn send(&mut self, job: Job) -> Result<()> {
        let Some(jobs) = &self.jobs else {
            return Err(self.failed());
        };
        let start = Instant::now();
        let sent = jobs.send(job);
        self.waited += start.elapsed();
        match sent {
            Ok(()) => Ok(()),
            Err(_) => Err(self.failed()),
        }
    }

    /// Logs the current state of every cloth, the colliders and the frame's statistics, if
    /// the options log this frame.
    pub fn frame(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<()> {
        if self.options.logs_frame(stats.frame) {
            self.hand_over(sim, stats)?;
        }
        Ok(())
    }

    /// Logs the run's last state if `every` skipped it, so that the log ends where the run
    /// did.
    pub fn last_frame(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<()> {
        if self.last_logged != Some(stats.frame) {
            self.hand_over(sim, stats)?;
        }
        Ok(())
    }

    fn hand_over(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<()> {
        let time = stats.time;
        let parts = weft_sim::body::parts(sim);
        let cloths = (0..sim.scene.cloths.len())
            .map(|i| {
                let spare = self.spare.get_mut().map(|r| r.try_recv().ok());
                let mut x = spare.ok().flatten().unwrap_or_default();
                x.clear();
                x.extend_from_slice(sim.cloth_positions(i));
                x
            })
            .collect();
        let colliders = (self.ids.colliders.is_some()
            && (stats.frame == 0 || self.moving_colliders))
            .then(|| {
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
                m
            });
        let collider_state = self.ids.collider_state.map(|_| {
            let states = collider_state::states(time, &sim.scene.colliders, &parts);
            collider_state::message(stats.frame, time, &states)
        });
        let frame = Frame {
            stats: *stats,
            cloths,
            surface: self.options.logs_surface(stats.frame),
            colliders,
            collider_state,
            waited_ms: self.waited.as_secs_f64() * 1e3,
        };
        self.send(Job::Frame(Box::new(frame)))?;
        self.handed += 1;
        self.last_logged = Some(stats.frame);
        Ok(())
    }

    /// Adds a JSON channel (described by a JSON schema) for messages written with
    /// [`Recorder::json`], e.g. the viewer's `/interaction`, and its own `weft.channels` record.
    pub fn add_json_channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema: &str,
    ) -> Result<u16> {
        let (reply, answer) = mpsc::sync_channel(1);
        self.send(Job::AddChannel {
            topic: topic.into(),
            schema_name: schema_name.into(),
            schema: schema.into(),
            reply,
        })?;
        match answer.recv() {
            Ok(id) => id,
            Err(_) => Err(self.failed()),
        }
    }

    /// Writes one JSON message at simulated time `time` (s) on a channel from
    /// [`Recorder::add_json_channel`].
    pub fn json(&mut self, channel: u16, time: f64, value: &serde_json::Value) -> Result<()> {
        let data = serde_json::to_vec(value)?;
        self.send(Job::Json {
            channel,
            time,
            data,
        })
    }

    /// Waits for every frame handed over to be written, then writes the status record, the
    /// summary section and the footer, and syncs the file.
    pub fn finish(mut self, status: &Status, frames_simulated: u64) -> Result<()> {
        self.send(Job::Finish {
            status: status.clone(),
            frames: frames_simulated,
        })?;
        self.jobs = None;
        match self.worker.take().map(JoinHandle::join) {
            Some(Ok(r)) => r,
            _ => Err(RecordError::Worker("the log's thread panicked".into())),
        }
    }
}

impl Drop for Recorder {
    /// A recorder dropped unfinished closes its log without a status (the log's thread
    /// writes the summary and footer), and waits for that.
    fn drop(&mut self) {
        self.jobs = None;
        if let Some(w) = self.worker.take() {
            let _ = w.join();
        }
    }
}
