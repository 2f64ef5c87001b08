//! `weft recover`: a valid log from one cut short by SIGKILL or a power cut, or damaged, as the
//! MCAP toolchain's `mcap recover` does: every record that reads whole (a chunk only when its
//! CRC holds) with its messages, the schemas and channels, the scene attachments and the
//! metadata, under status `recovered` (summary, indexes and CRCs written anew).
//!
//! A damaged record does not end the reading: when its length still holds, only it is lost;
//! otherwise reading resumes at the next offset from which records read whole up to one a CRC
//! vouches for (a chunk, an attachment) or up to the closing magic. Schemas and channels lost
//! with a damaged chunk are rebuilt from the log's `weft.channels` metadata
//! ([`weft_record::CHANNELS`]); messages on a channel that cannot be rebuilt are lost.

use std::collections::{BTreeMap, BTreeSet};
use std::io::{BufWriter, Read};
use std::process::ExitCode;

use anyhow::{Context, bail};
use mcap::read::parse_record;
use mcap::records::{Channel, MessageHeader, Metadata, Record, op};
use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
use mcap::{Attachment, Compression, MAGIC, WriteOptions};
use serde_json::Value;

use crate::cli::RecoverArgs;
use crate::output::{Named, Output, refuse_clashes};
use weft_record::{CHANNELS, foxglove_schema, verify::looks_like_mcap};

/// What was recovered, and what was lost.
#[derive(Debug, Default, PartialEq, Eq)]
pub struct Recovered {
    /// Messages written.
    pub messages: u64,
    /// Chunks kept.
    pub chunks: u64,
    /// Chunk records found whole whose contents are damaged (their CRC or compression fails).
    pub dropped_chunks: u64,
    /// Damaged stretches: a damaged record (a chunk with a damaged length field is still read),
    /// or the bytes up to where records read whole again.
    pub damaged: u64,
    /// Bytes skipped: the damaged stretches, and an incomplete record at the end.
    pub lost_bytes: u64,
    /// Messages lost, at least: as many as the log's sequence numbers (and its statistics, when
    /// it has them) say it held, less those written.
    pub lost_messages: u64,
    /// Messages read whole but not written: no intact record or `weft.channels` entry holds
    /// their channel (and its schema). Counted among the messages lost.
    pub orphaned: u64,
    /// Channels rebuilt from the `weft.channels` metadata (no intact record held them).
    pub rebuilt_channels: u64,
    /// Frames: the `/stats` messages kept (one per logged frame, frame 0 included).
    pub frames: u64,
    /// Whether the input ends inside a record without the closing magic: it was cut short.
    pub truncated: bool,
}

/// A record kept, in file order.
enum Kept<'a> {
    Message(MessageHeader, Vec<u8>),
    Attachment(Attachment<'a>),
    Metadata(Metadata),
}

/// What the records that read whole hold.
#[derive(Default)]
struct Found<'a> {
    /// Schemas by id: name, encoding, data (the first record of each id wins).
    schemas: BTreeMap<u16, (String, String, Vec<u8>)>,
    channels: BTreeMap<u16, Channel>,
    kept: Vec<Kept<'a>>,
    /// The messages the log's statistics record counts, if it was read.
    statistics: u64,
}

impl<'a> Found<'a> {
    /// Keeps a schema, channel or message record, inside a chunk or outside one.
    fn take(&mut self, record: Record<'_>) {
        match record {
            Record::Schema { header, data } => {
                self.schemas.entry(header.id).or_insert((
                    header.name,
                    header.encoding,
                    data.into_owned(),
                ));
            }
            Record::Channel(c) => {
                self.channels.entry(c.id).or_insert(c);
            }
            Record::Message { header, data } => {
                self.kept.push(Kept::Message(header, data.into_owned()));
            }
            Record::Statistics(s) => self.statistics = s.message_count,
            _ => {}
        }
    }

    /// Adds the channels (and their schemas) a `weft.channels` record describes that no intact
    /// record held; returns how many channels it added.
    fn describe(&mut self, described: &BTreeMap<String, String>) -> u64 {
        let mut added = 0;
        for (id, entry) in described {
            let (Ok(id), Ok(v)) = (id.parse::<u16>(), serde_json::from_str::<Value>(entry)) else {
                continue;
            };
            let s = &v["schema"];
            let schema_id = s["id"].as_u64().and_then(|i| u16::try_from(i).ok());
            let (Some(topic), Some(encoding), Some(schema_id), Some(name), Some(schema_encoding)) = (
                v["topic"].as_str(),
                v["message_encoding"].as_str(),
                schema_id,
                s["name"].as_str(),
                s["encoding"].as_str(),
            ) else {
                continue;
            };
            if self.channels.contains_key(&id) {
                continue;
            }
            if schema_id != 0 && !self.schemas.contains_key(&schema_id) {
                let text = s["text"].as_str().map(|t| t.as_bytes().to_vec());
                let Some(data) = text.or_else(|| foxglove_schema(name)) else {
                    continue;
                };
                let schema = (name.to_owned(), schema_encoding.to_owned(), data);
                self.schemas.insert(schema_id, schema);
            }
            self.channels.insert(
                id,
                Channel {
                    id,
                    schema_id,
                    topic: topic.to_owned(),
                    message_encoding: encoding.to_owned(),
                    metadata: BTreeMap::new(),
                },
            );
            added += 1;
        }
        added
    }
}

/// A record that reads whole at some offset.
struct Whole<'a> {
    record: Record<'a>,
    /// The records of a chunk (its CRC held).
    inner: Vec<Record<'static>>,
    /// The offset after it.
    end: usize,
    /// Whether a CRC vouches for it: a chunk or an attachment that has one.
    vouched: bool,
    /// Whether its length field is damaged (a chunk read as its own header says).
    repaired: bool,
}

/// The opcode, body and end of the record whose header is at `pos`, when it all fits.
fn extent(bytes: &[u8], pos: usize) -> Option<(u8, &[u8], usize)> {
    let opcode = *bytes.get(pos)?;
    let len = u64::from_le_bytes(bytes.get(pos + 1..pos.checked_add(9)?)?.try_into().ok()?);
    let end = (pos + 9).checked_add(usize::try_from(len).ok()?)?;
    Some((opcode, bytes.get(pos + 9..end)?, end))
}

/// The body and end of the chunk at `pos` as its own header says (its compressed size), for a
/// chunk whose length field is damaged.
fn chunk_extent(bytes: &[u8], pos: usize) -> Option<(&[u8], usize)> {
    if *bytes.get(pos)? != op::CHUNK {
        return None;
    }
    let start = pos.checked_add(9)?;
    // Start and end times and the uncompressed size (8 bytes each), the CRC (4), then the
    // compression's name (a length and the bytes), then the compressed size.
    let name = u32::from_le_bytes(bytes.get(start + 28..start + 32)?.try_into().ok()?);
    let at = (start + 32).checked_add(usize::try_from(name).ok()?)?;
    let size = u64::from_le_bytes(bytes.get(at..at.checked_add(8)?)?.try_into().ok()?);
    let end = (at + 8).checked_add(usize::try_from(size).ok()?)?;
    Some((bytes.get(start..end)?, end))
}

/// The record at `pos` when it reads whole: an opcode MCAP defines (or a private one), a body
/// that fits and parses (an attachment's CRC holds), and for a chunk, records that decompress
/// and match its CRC. A chunk whose length field is damaged is read as its header says.
fn whole_at(bytes: &[u8], pos: usize) -> Option<Whole<'_>> {
    let stated = extent(bytes, pos).and_then(|(opcode, body, end)| whole(opcode, body, end));
    stated.or_else(|| {
        let (body, end) = chunk_extent(bytes, pos)?;
        let w = whole(op::CHUNK, body, end)?;
        Some(Whole {
            repaired: true,
            ..w
        })
    })
}

/// The record `body` of type `opcode`, ending at `end`, when it reads whole (see [`whole_at`]).
fn whole(opcode: u8, body: &[u8], end: usize) -> Option<Whole<'_>> {
    if opcode == 0 || (op::DATA_END < opcode && opcode < 0x80) {
        return None;
    }
    let record = parse_record(opcode, body).ok()?;
    let (inner, vouched) = match &record {
        Record::Chunk { header, .. } => {
            // A damaged size must not ask for more memory than a chunk of this file can need.
            let limit = usize::try_from(header.uncompressed_size).ok()?;
            if limit > body.len().saturating_mul(100).max(1 << 30) {
                return None;
            }
            let inner = chunk_records(body, limit.max(body.len()))?;
            (inner, header.uncompressed_crc != 0)
        }
        Record::Attachment { crc, .. } => (Vec::new(), *crc != 0),
        _ => (Vec::new(), false),
    };
    Some(Whole {
        record,
        inner,
        end,
        vouched,
        repaired: false,
    })
}

/// The records of the chunk whose record body is `body` when they decompress and match its
/// CRC; none may be longer than `limit` bytes.
fn chunk_records(body: &[u8], limit: usize) -> Option<Vec<Record<'static>>> {
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_start_magic(true)
            .with_skip_end_magic(true)
            .with_validate_chunk_crcs(true)
            .with_record_length_limit(limit),
    );
    let mut head = [op::CHUNK, 0, 0, 0, 0, 0, 0, 0, 0];
    head[1..].copy_from_slice(&(body.len() as u64).to_le_bytes());
    let mut rest = (&head[..]).chain(body);
    let mut left = head.len() + body.len();
    let mut records = Vec::new();
    while let Some(event) = reader.next_event() {
        match event.ok()? {
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(left);
                rest.read_exact(reader.insert(n)).ok()?;
                reader.notify_read(n);
                left -= n;
            }
            LinearReadEvent::Record { opcode, data } => {
                records.push(parse_record(opcode, data).ok()?.into_owned());
            }
        }
    }
    Some(records)
}

/// Whether reading can resume at `pos`: records read whole from there up to one a CRC vouches
/// for, or up to the closing magic (within 64 records).
fn resumes_at(bytes: &[u8], pos: usize) -> bool {
    let mut at = pos;
    for _ in 0..64 {
        if bytes.get(at..) == Some(MAGIC) {
            return true;
        }
        match whole_at(bytes, at) {
            Some(w) if w.vouched => return true,
            Some(w) => at = w.end,
            None => return false,
        }
    }
    false
}

/// Reads every record of `bytes` that reads whole, skipping damaged stretches.
fn scan<'a>(bytes: &'a [u8], report: &mut Recovered) -> Found<'a> {
    let mut found = Found::default();
    let mut described = Vec::new();
    let mut pos = MAGIC.len();
    // Where the last record that read whole starts.
    let mut last = pos;
    while pos < bytes.len() && bytes.get(pos..) != Some(MAGIC) {
        let Some(w) = whole_at(bytes, pos) else {
            // A damaged record: when its length still holds, only it is lost; else the bytes up
            // to where records read whole again, looked for from inside the last record that
            // read whole (a damaged length can make a record read whole over those after it).
            let held = extent(bytes, pos)
                .map(|(_, _, end)| end)
                .filter(|&end| end == bytes.len() || resumes_at(bytes, end));
            let resumes = |p: &usize| *p != pos && resumes_at(bytes, *p);
            // Not inside the data of a chunk already read (an uncompressed chunk's messages
            // read whole there, and would be taken twice): from where its header ends it.
            let from = chunk_extent(bytes, last).map_or(last + 1, |(_, end)| end.max(last + 1));
            let Some(next) = held.or_else(|| (from..bytes.len()).find(resumes)) else {
                report.lost_bytes += (bytes.len() - pos) as u64;
                if bytes.ends_with(MAGIC) {
                    report.damaged += 1;
                } else {
                    report.truncated = true;
                }
                break;
            };
            if held.is_some() && bytes[pos] == op::CHUNK {
                report.dropped_chunks += 1;
            }
            report.damaged += 1;
            report.lost_bytes += next.saturating_sub(pos) as u64;
            pos = next;
            continue;
        };
        last = pos;
        pos = w.end;
        report.damaged += u64::from(w.repaired);
        match w.record {
            Record::Chunk { .. } => {
                report.chunks += 1;
                for r in w.inner {
                    found.take(r);
                }
            }
            Record::Attachment { header, data, .. } => {
                found.kept.push(Kept::Attachment(Attachment {
                    log_time: header.log_time,
                    create_time: header.create_time,
                    name: header.name,
                    media_type: header.media_type,
                    data,
                }))
            }
            Record::Metadata(m) if m.name == "weft.status" => {}
            Record::Metadata(m) => {
                if m.name == CHANNELS {
                    described.push(m.metadata.clone());
                }
                found.kept.push(Kept::Metadata(m));
            }
            other => found.take(other),
        }
    }
    for d in &described {
        report.rebuilt_channels += found.describe(d);
    }
    found
}

/// Reads every record of `bytes` that reads whole (skipping damaged ones, tolerating a cut
/// tail) and writes a valid log to `out`; fails when nothing at all reads whole.
pub fn rebuild<W: std::io::Write + std::io::Seek>(
    bytes: &[u8],
    out: W,
) -> anyhow::Result<(Recovered, W)> {
    let mut report = Recovered::default();
    let found = scan(bytes, &mut report);
    if found.kept.is_empty() && found.channels.is_empty() {
        bail!("no record in it reads whole: nothing to recover");
    }
    let mut w = WriteOptions::new()
        .compression(Some(Compression::Zstd))
        .compression_threads(0)
        .profile("")
        .create(out)?;
    for (id, (name, encoding, data)) in &found.schemas {
        w.add_schema_with_id(*id, name, encoding, data)?;
    }
    let mut known = BTreeSet::new();
    for c in found.channels.values() {
        if c.schema_id == 0 || found.schemas.contains_key(&c.schema_id) {
            w.add_channel_with_id(
                c.id,
                c.schema_id,
                &c.topic,
                &c.message_encoding,
                &c.metadata,
            )?;
            known.insert(c.id);
        }
    }
    let frames_channel = found
        .channels
        .values()
        .find(|c| c.topic == "/stats")
        .map(|c| c.id);
    let mut last_frame = None;
    let mut last_sequence = 0;
    for k in &found.kept {
        match k {
            Kept::Message(h, data) => {
                last_sequence = last_sequence.max(h.sequence);
                if !known.contains(&h.channel_id) {
                    report.orphaned += 1;
                    continue;
                }
                w.write_to_known_channel(h, data)?;
                report.messages += 1;
                if Some(h.channel_id) == frames_channel {
                    report.frames += 1;
                    last_frame = serde_json::from_slice::<Value>(data)
                        .ok()
                        .and_then(|v| v["frame"].as_u64());
                }
            }
            Kept::Attachment(a) => w.attach(a)?,
            Kept::Metadata(m) => w.write_metadata(m)?,
        }
    }
    let held = u64::from(last_sequence).max(found.statistics);
    report.lost_messages = held.saturating_sub(report.messages);
    w.write_metadata(&Metadata {
        name: "weft.status".into(),
        metadata: BTreeMap::from([
            ("status".to_owned(), "recovered".to_owned()),
            // Frames simulated after frame 0, as `complete` and `interrupted` logs count them.
            ("frames".to_owned(), last_frame.unwrap_or(0).to_string()),
            (
                "message".to_owned(),
                format!("{}{}", summary(&report), lost(&report)),
            ),
        ]),
    })?;
    w.finish()?;
    Ok((report, w.into_inner()))
}

/// What was recovered, in a few words.
fn summary(r: &Recovered) -> String {
    format!(
        "recovered {} frame(s), {} message(s) from {} complete chunk(s)",
        r.frames.saturating_sub(1),
        r.messages,
        r.chunks
    )
}

/// What was lost, or nothing when nothing was.
fn lost(r: &Recovered) -> String {
    let mut parts = Vec::new();
    if r.damaged > 0 {
        let chunks = match r.dropped_chunks {
            0 => String::new(),
            n => format!(" ({n} damaged chunk(s) among them)"),
        };
        parts.push(format!("found {} damaged stretch(es){chunks}", r.damaged));
    }
    if r.truncated {
        parts.push("the log ends inside a record (cut short)".to_owned());
    }
    if r.rebuilt_channels > 0 {
        parts.push(format!(
            "rebuilt {} channel(s) lost with their chunk from the weft.channels metadata",
            r.rebuilt_channels
        ));
    }
    if r.orphaned > 0 {
        parts.push(format!(
            "dropped {} message(s) whose channel was lost with its chunk",
            r.orphaned
        ));
    }
    if r.lost_bytes > 0 || r.lost_messages > 0 {
        let messages = match r.lost_messages {
            0 => String::new(),
            n => format!(" and at least {n} message(s)"),
        };
        parts.push(format!("lost {} byte(s){messages}", r.lost_bytes));
    }
    if parts.is_empty() {
        String::new()
    } else {
        format!("; {}", parts.join("; "))
    }
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
            "{log} is not an MCAP log (it does not start with MCAP's magic bytes): refusing to recover it"
        );
    }
    let out = Output::create_log(&args.out)?;
    let target = out.target().display().to_string();
    let (report, file) = rebuild(&bytes, BufWriter::new(out.handle()?))
        .with_context(|| format!("recovering {log} into {target}"))?;
    file.into_inner()
        .map_err(|e| e.into_error())
        .with_context(|| format!("cannot write {target}"))?;
    out.commit()?;
    say!("{} of {log}; wrote {target}", summary(&report))?;
    let lost = lost(&report);
    if let Some(lost) = lost.strip_prefix("; ") {
        say!("{lost}")?;
    }
    Ok(ExitCode::SUCCESS)
}
