//! `weft export`: a log's cloth and colliders for the tools garments are finished in, as an OBJ
//! sequence (`obj.rs`) or an animated GLB (`glb.rs`). The log is checked whole first, the frames
//! are chosen (`select.rs`), the memory and disk the export needs are estimated before anything
//! is read or written (`estimate.rs`), the tracks are read (`log.rs`), and every file is written
//! through `crate::output` (a partial renamed when whole, never over the log). A signal stops the
//! export between two messages or frames: files finished stay, the one in progress goes.
//!
//! Its modules:
//!
//! - `body`: the character's body in an export, each part a collider track.
//! - `collider_track`: a collider's track over the exported frames, and its logged pose.
//! - `estimate`: the memory and disk an export will need, checked before any frame is read.
//! - `glb`: the exported frames as one animated GLB, cloths as shape keys for Blender.
//! - `log`: what an export reads from a log: frames, cloth triangles and positions, colliders.
//! - `obj`: one frame as Wavefront OBJ text, each cloth and each collider an object.
//! - `select`: which logged frames an export writes: `--frames A..B` and `--every N`.

pub mod body;
pub mod collider_track;
pub mod estimate;
pub mod glb;
pub mod log;
pub mod obj;
pub mod select;

use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, bail};

use crate::cli::{ExportArgs, ExportFormat, Interpolation};
use crate::output::{Named, Output, refuse_clashes};
use crate::stop::{EXIT_INTERRUPTED, Stopped};
use estimate::Needs;
use log::Tracks;

/// Runs `weft export`.
pub fn export(args: &ExportArgs, stop: &Arc<AtomicBool>) -> anyhow::Result<ExitCode> {
    let _polling = crate::stop::Polling::start();
    match run(args, stop) {
        Err(e) if e.is::<Stopped>() => {
            eprintln!("weft: export stopped; the files already finished are whole");
            Ok(ExitCode::from(EXIT_INTERRUPTED as u8))
        }
        other => other,
    }
}

fn poll(stop: &AtomicBool) -> anyhow::Result<()> {
    if stop.load(Ordering::Relaxed) {
        return Err(Stopped.into());
    }
    Ok(())
}

/// The files an export writes, in order.
fn targets(args: &ExportArgs, frames: &[u64]) -> Vec<PathBuf> {
    match args.format {
        ExportFormat::Obj => frames
            .iter()
            .map(|&f| args.out.join(obj::file_name(f)))
            .collect(),
        ExportFormat::Glb => {
            let stem = args
                .log
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "weft".into());
            vec![args.out.join(glb::file_name(&stem))]
        }
    }
}

/// What the export of `frames` frames of `scene` needs, for a log of `log_bytes`.
fn needs(format: ExportFormat, scene: &weft_scene::Scene, frames: u64, log_bytes: u64) -> Needs {
    let particles: Vec<u64> = scene
        .cloths
        .iter()
        .map(|c| c.mesh.positions.len() as u64)
        .collect();
    let cloth_triangles: u64 = scene
        .cloths
        .iter()
        .map(|c| c.mesh.triangles.len() as u64)
        .sum();
    // Colliders as drawn: 48 × 24 vertices for a ball or capsule, the mesh itself otherwise.
    let (mut cv, mut ct) = (0u64, 0u64);
    for c in &scene.colliders {
        let (v, t) = match &c.shape {
            weft_collide::ShapeDesc::TriMesh(mesh) => {
                (mesh.vertices.len() as u64, mesh.triangles.len() as u64)
            }
            weft_collide::ShapeDesc::ConvexHull { points } => {
                (points.len() as u64, 2 * points.len() as u64)
            }
            _ => (2000, 4000),
        };
        cv += v;
        ct += t;
    }
    let body_parts = body::part_count(scene) as u64;
    cv += 2000 * body_parts;
    ct += 4000 * body_parts;
    let held = frames * particles.iter().sum::<u64>() * 12;
    match format {
        ExportFormat::Obj => {
            let per_frame =
                obj::size_estimate(particles.iter().sum::<u64>() + cv, cloth_triangles + ct);
            Needs {
                memory: log_bytes + held + 2 * per_frame,
                output: frames * per_frame,
                largest_file: per_frame,
            }
        }
        ExportFormat::Glb => {
            let size = glb::size_estimate(
                frames,
                &particles,
                cloth_triangles,
                cv,
                ct,
                scene.colliders.len() as u64 + body_parts,
            );
            Needs {
                memory: log_bytes + held + size,
                output: size,
                largest_file: size,
            }
        }
    }
}

fn run(args: &ExportArgs, stop: &AtomicBool) -> anyhow::Result<ExitCode> {
    let path = args.log.as_path();
    let limits = args.limits.limits();
    if args.out.exists() && !args.out.is_dir() {
        bail!("--out {} is not a directory", args.out.display());
    }
    let size = std::fs::metadata(path)
        .with_context(|| format!("cannot read {}", path.display()))?
        .len();
    let no_output = Needs {
        memory: size,
        output: 0,
        largest_file: 0,
    };
    estimate::check(
        no_output,
        false,
        limits.max_memory.as_ref(),
        None,
        &args.out,
    )?;
    let bytes = weft_scene::read_regular(path, u64::MAX)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", path.display()))?;
    match weft_record::verify::verify(&bytes, stop) {
        Ok(()) => {}
        Err(weft_record::verify::Fault::Stopped) => return Err(Stopped.into()),
        Err(fault) => bail!("{}", fault.message(path)),
    }
    let logged = crate::replay::read_log(&bytes).with_context(|| format!("{}", path.display()))?;
    let scene = crate::replay::logged_scene(&logged, &limits)
        .with_context(|| format!("{}", path.display()))?;
    let all = log::logged_frames(&bytes, stop).with_context(|| format!("{}", path.display()))?;
    let numbers: Vec<u64> = all.values().copied().collect();
    let chosen: BTreeSet<u64> = select::select(&numbers, args.frames, args.every)
        .into_iter()
        .collect();
    if chosen.is_empty() {
        bail!(
            "{} holds frames {}..={}: none in --frames",
            path.display(),
            numbers.first().copied().unwrap_or(0),
            numbers.last().copied().unwrap_or(0)
        );
    }
    let wanted: BTreeMap<u64, u64> = all
        .into_iter()
        .filter(|(_, f)| chosen.contains(f))
        .collect();
    let frames: Vec<u64> = wanted.values().copied().collect();
    let files = targets(args, &frames);
    refuse_clashes(
        &[Named {
            role: "the log",
            path,
        }],
        &files
            .iter()
            .map(|p| Named {
                role: "--out",
                path: p,
            })
            .collect::<Vec<_>>(),
    )?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create the output directory {}", args.out.display()))?;
    let needs = needs(args.format, &scene, frames.len() as u64, size);
    estimate::check(
        needs,
        args.format == ExportFormat::Glb,
        limits.max_memory.as_ref(),
        estimate::free_space(&args.out),
        &args.out,
    )?;
    // The first file is opened before the log is decoded: an unwritable directory is said at
    // once.
    let first = Output::create(&files[0])?;
    let tracks = log::read_tracks(&bytes, &scene, &wanted, stop)
        .with_context(|| format!("{}", path.display()))?;
    drop(bytes);
    match args.format {
        ExportFormat::Obj => write_obj(&tracks, &files, first, path, stop)?,
        ExportFormat::Glb => write_glb(&tracks, args.interpolation, first, stop)?,
    }
    if !args.quiet {
        say!(
            "exported {} frame(s) ({}..={}) of {}: {} cloth(s), {} collider(s) → {}",
            frames.len(),
            frames[0],
            frames[frames.len() - 1],
            path.display(),
            tracks.cloths.len(),
            tracks.colliders.len(),
            match args.format {
                ExportFormat::Obj =>
                    format!("{} OBJ file(s) in {}", files.len(), args.out.display()),
                ExportFormat::Glb => files[0].display().to_string(),
            }
        )?;
    }
    Ok(ExitCode::SUCCESS)
}

fn write_obj(
    tracks: &Tracks,
    files: &[PathBuf],
    first: Output,
    log: &Path,
    stop: &AtomicBool,
) -> anyhow::Result<()> {
    let name = log.display().to_string();
    let mut first = Some(first);
    for (k, file) in files.iter().enumerate() {
        poll(stop)?;
        let mut out = match first.take() {
            Some(o) => o,
            None => Output::create(file)?,
        };
        out.write_all(obj::frame_text(tracks, k, &name).as_bytes())?;
        out.commit()?;
    }
    Ok(())
}

fn write_glb(
    tracks: &Tracks,
    interpolation: Interpolation,
    out: Output,
    stop: &AtomicBool,
) -> anyhow::Result<()> {
    let (json, bin) = glb::build(tracks, interpolation.gltf(), || poll(stop))?;
    // The document is checked as a glTF reader checks it before it is written.
    let root = gltf::json::deserialize::from_slice(&json)
        .context("internal error: the glTF written does not parse")?;
    gltf::Document::from_json(root)
        .map_err(|e| anyhow::anyhow!("internal error: the glTF written is invalid: {e}"))?;
    poll(stop)?;
    let target = out.target().display().to_string();
    let glb = gltf::binary::Glb {
        header: gltf::binary::Header {
            magic: *b"glTF",
            version: 2,
            // Written by `to_writer` from the chunks.
            length: 0,
        },
        json: Cow::Owned(json),
        bin: Some(Cow::Owned(bin)),
    };
    let mut w = BufWriter::new(out.handle()?);
    glb.to_writer(&mut w)
        .map_err(|e| anyhow::anyhow!("cannot write {target}: {e}"))?;
    w.flush()
        .with_context(|| format!("cannot write {target}"))?;
    drop(w);
    out.commit()
}
