//! `Simulation.record`: the MCAP log `weft run --out` writes, by weft-record's `Recorder` as
//! the CLI drives it (the state when recording starts, then every frame stepped, the status
//! on the way out), written to `<stem>.partial-<pid>-<n>.<ext>` beside the target (the CLI's
//! name, which `weft recover` reads) and renamed into place when finished.

use std::fs::{File, OpenOptions};
use std::path::{Path, PathBuf};

use weft_record::{RecordOptions, Recorder, Status};
use weft_sim::{FrameStats, Simulation};

/// A failure to write a log: its message names the file.
#[derive(Debug)]
pub struct LogError(pub String);

/// An open recording.
pub struct Recording {
    rec: Recorder,
    partial: PathBuf,
    target: PathBuf,
}

/// The `n`-th temporary name for `target`: `run.mcap` → `run.partial-<pid>-<n>.mcap`.
fn partial_name(target: &Path, n: u32) -> PathBuf {
    let tag = format!(".partial-{}-{n}", std::process::id());
    match (target.file_stem(), target.extension()) {
        (Some(stem), Some(ext)) => {
            let mut name = stem.to_owned();
            name.push(&tag);
            name.push(".");
            name.push(ext);
            target.with_file_name(name)
        }
        _ => {
            let mut name = target.as_os_str().to_owned();
            name.push(&tag);
            PathBuf::from(name)
        }
    }
}

/// Creates a temporary file of our own beside `target` (never opening an existing one).
fn create_partial(target: &Path) -> Result<(PathBuf, File), LogError> {
    for n in 0..1000 {
        let p = partial_name(target, n);
        match OpenOptions::new().write(true).create_new(true).open(&p) {
            Ok(f) => return Ok((p, f)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(LogError(format!("cannot write {}: {e}", target.display()))),
        }
    }
    Err(LogError(format!(
        "cannot write {}: no free temporary name beside it",
        target.display()
    )))
}

impl Recording {
    /// Starts a log of `sim` at `target`, its first frame the current state `last`;
    /// `planned` is the frame count written in its metadata (as `weft run --frames`).
    pub fn start(
        target: &Path,
        sim: &Simulation,
        last: &FrameStats,
        planned: u64,
        options: RecordOptions,
    ) -> Result<Self, LogError> {
        if std::fs::metadata(target).is_ok_and(|m| m.is_dir()) {
            return Err(LogError(format!(
                "cannot write an MCAP log to {}: it is a directory",
                target.display()
            )));
        }
        let (partial, file) = create_partial(target)?;
        let started = Recorder::new(file, sim, planned, options).and_then(|mut rec| {
            rec.frame(sim, last)?;
            Ok(rec)
        });
        match started {
            Ok(rec) => Ok(Self {
                rec,
                partial,
                target: target.to_path_buf(),
            }),
            Err(e) => {
                let _ = std::fs::remove_file(&partial);
                Err(LogError(format!("writing {}: {e}", target.display())))
            }
        }
    }

    /// Logs the frame just stepped.
    pub fn frame(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<(), LogError> {
        self.rec
            .frame(sim, stats)
            .map_err(|e| LogError(format!("writing {}: {e}", self.target.display())))
    }

    /// Logs the last frame stepped if `every` skipped it, as `weft run` ends its logs.
    pub fn last_frame(&mut self, sim: &Simulation, stats: &FrameStats) -> Result<(), LogError> {
        self.rec
            .last_frame(sim, stats)
            .map_err(|e| LogError(format!("writing {}: {e}", self.target.display())))
    }

    /// Writes the status (`frames` whole frames simulated), closes the file and renames it
    /// into place; returns the final path.
    pub fn finish(self, status: &Status, frames: u64) -> Result<PathBuf, LogError> {
        let target = self.target;
        if let Err(e) = self.rec.finish(status, frames) {
            let _ = std::fs::remove_file(&self.partial);
            return Err(LogError(format!("finishing {}: {e}", target.display())));
        }
        std::fs::rename(&self.partial, &target).map_err(|e| {
            LogError(format!(
                "cannot rename {} to {}: {e}",
                self.partial.display(),
                target.display()
            ))
        })?;
        Ok(target)
    }

    /// Drops the log unfinished, removing its temporary file.
    pub fn abandon(self) {
        let _ = std::fs::remove_file(&self.partial);
    }
}
