//! `weft recover`: a valid log from one cut short by SIGKILL or a power cut (or with damaged
//! chunks), as the MCAP toolchain's `mcap recover` does: every complete chunk whose CRC holds,
//! with its messages, the schemas and channels, the scene attachments and the metadata, under
//! status `recovered` (summary, indexes and CRCs written anew).

use std::collections::BTreeMap;
use std::io::BufWriter;
use std::process::ExitCode;

use anyhow::{Context, bail};
use mcap::read::{ChunkReader, LinearReader, Options};
use mcap::records::{MessageHeader, Metadata, Record};
use mcap::{Attachment, Compression, WriteOptions};

use crate::cli::RecoverArgs;
use crate::output::{Named, Output, refuse_clashes};
use crate::record::verify::looks_like_mcap;

/// What was recovered.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Recovered {
    /// Messages written.
    pub messages: u64,
    /// Chunks kept.
    pub chunks: u64,
    /// Chunks dropped (incomplete, or their CRC failed).
    pub dropped_chunks: u64,
    /// Frames: the `/stats` messages kept (one per logged frame, frame 0 included).
    pub frames: u64,
    /// Whether the input ended inside a record.
    pub truncated: bool,
}

/// A record kept, in file order.
enum Kept<'a> {
    Schema(u16, String, String, Vec<u8>),
    Channel(mcap::records::Channel),
    Message(MessageHeader, std::borrow::Cow<'a, [u8]>),
    Attachment(Attachment<'a>),
    Metadata(Metadata),
}

/// Keeps a schema, channel or message record, inside a chunk or outside one (noting the `/stats`
/// channel, whose messages count the frames); ignores every other record.
fn keep<'a>(record: Record<'_>, kept: &mut Vec<Kept<'a>>, frames_channel: &mut Option<u16>) {
    match record {
        Record::Schema { header, data } => kept.push(Kept::Schema(
            header.id,
            header.name,
            header.encoding,
            data.into_owned(),
        )),
        Record::Channel(c) => {
            if c.topic == "/stats" {
                *frames_channel = Some(c.id);
            }
            kept.push(Kept::Channel(c));
        }
        Record::Message { header, data } => kept.push(Kept::Message(
            header,
            std::borrow::Cow::Owned(data.into_owned()),
        )),
        _ => {}
    }
}

/// Reads every complete record of `bytes` (tolerating a cut tail) and writes a valid log to
/// `out`.
pub fn rebuild<W: std::io::Write + std::io::Seek>(
    bytes: &[u8],
    out: W,
) -> anyhow::Result<(Recovered, W)> {
    let mut report = Recovered::default();
    let mut kept: Vec<Kept<'_>> = Vec::new();
    let mut frames_channel: Option<u16> = None;
    let reader = LinearReader::new_with_options(bytes, Options::IgnoreEndMagic.into())
        .context("not an MCAP log (bad magic number at its start)")?;
    for record in reader {
        let record = match record {
            Ok(r) => r,
            Err(mcap::McapError::UnexpectedEof) => {
                report.truncated = true;
                break;
            }
            Err(e) => {
                // A record that does not parse: everything after it is suspect.
                report.truncated = true;
                eprintln!("weft: recover: stopped at a damaged record: {e}");
                break;
            }
        };
        match record {
            Record::Chunk { header, data } => {
                // A chunk is kept whole or not at all: its CRC covers every record in it.
                let inner: Result<Vec<_>, _> =
                    ChunkReader::new(header, &data).and_then(|r| r.collect::<Result<Vec<_>, _>>());
                match inner {
                    Ok(records) => {
                        report.chunks += 1;
                        for r in records {
                            keep(r, &mut kept, &mut frames_channel);
                        }
                    }
                    Err(_) => report.dropped_chunks += 1,
                }
            }
            Record::Attachment { header, data, .. } => kept.push(Kept::Attachment(Attachment {
                log_time: header.log_time,
                create_time: header.create_time,
                name: header.name,
                media_type: header.media_type,
                data,
            })),
            Record::Metadata(m) if m.name != "weft.status" => kept.push(Kept::Metadata(m)),
            other => keep(other, &mut kept, &mut frames_channel),
        }
    }
    if kept.is_empty() {
        bail!("no record in it reads whole: nothing to recover");
    }
    let mut w = WriteOptions::new()
        .compression(Some(Compression::Zstd))
        .compression_threads(0)
        .profile("")
        .create(out)?;
    let mut last_frame = None;
    for k in &kept {
        match k {
            Kept::Schema(id, name, encoding, data) => {
                w.add_schema_with_id(*id, name, encoding, data)?;
            }
            Kept::Channel(c) => {
                w.add_channel_with_id(
                    c.id,
                    c.schema_id,
                    &c.topic,
                    &c.message_encoding,
                    &c.metadata,
                )?;
            }
            Kept::Message(h, data) => {
                w.write_to_known_channel(h, data)?;
                report.messages += 1;
                if Some(h.channel_id) == frames_channel {
                    report.frames += 1;
                    last_frame = serde_json::from_slice::<serde_json::Value>(data)
                        .ok()
                        .and_then(|v| v["frame"].as_u64());
                }
            }
            Kept::Attachment(a) => w.attach(a)?,
            Kept::Metadata(m) => w.write_metadata(m)?,
        }
    }
    w.write_metadata(&Metadata {
        name: "weft.status".into(),
        metadata: BTreeMap::from([
            ("status".to_owned(), "recovered".to_owned()),
            // Frames simulated after frame 0, as `complete` and `interrupted` logs count them.
            ("frames".to_owned(), last_frame.unwrap_or(0).to_string()),
            (
                "message".to_owned(),
                format!(
                    "recovered {} messages from {} complete chunk(s); {} chunk(s) dropped",
                    report.messages, report.chunks, report.dropped_chunks
                ),
            ),
        ]),
    })?;
    w.finish()?;
    Ok((report, w.into_inner()))
}

/// Runs `weft recover`.
pub fn recover(args: &RecoverArgs) -> anyhow::Result<ExitCode> {
    refuse_clashes(
        &[Named {
            role: "the damaged log",
            path: &args.log,
        }],
        &[Named {
            role: "--out",
            path: &args.out,
        }],
    )?;
    let bytes = weft_scene::read_regular(&args.log, u64::MAX)
        .map_err(|e| anyhow::anyhow!("cannot read {}: {e}", args.log.display()))?;
    let log = args.log.display();
    if bytes.is_empty() {
        bail!("{log} is empty: nothing to recover");
    }
    if !looks_like_mcap(&bytes) {
        bail!(
            "{log} is not an MCAP log (it does not start with MCAP's magic bytes): refusing to \
             recover it"
        );
    }
    let out = Output::create(&args.out)?;
    let target = out.target().display().to_string();
    let (report, file) = rebuild(&bytes, BufWriter::new(out.handle()?))
        .with_context(|| format!("recovering {} into {target}", args.log.display()))?;
    file.into_inner()
        .map_err(|e| e.into_error())
        .with_context(|| format!("cannot write {target}"))?;
    out.commit()?;
    say!(
        "recovered {} frame(s), {} message(s) from {} complete chunk(s) of {}{}; wrote {target}",
        report.frames.saturating_sub(1),
        report.messages,
        report.chunks,
        args.log.display(),
        if report.dropped_chunks > 0 {
            format!(" ({} damaged chunk(s) dropped)", report.dropped_chunks)
        } else {
            String::new()
        }
    )?;
    Ok(ExitCode::SUCCESS)
}
