//! Checks a log before it is trusted: whole (ends with its footer and magic), and every CRC
//! (chunks, data section, summary) intact. A log cut short points to `weft recover`.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// What is wrong with a log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Fault {
    /// No bytes at all.
    Empty,
    /// Does not start with the MCAP magic.
    NotMcap,
    /// Ends inside a record, without the closing magic: the writer was killed, or the file
    /// was cut.
    Truncated,
    /// A CRC or a record does not hold: the bytes changed after they were written.
    Corrupt(String),
    /// The stop flag was raised before the check finished.
    Stopped,
}

impl Fault {
    /// A message for `path` with what to do about it.
    pub fn message(&self, path: &Path) -> String {
        let p = path.display();
        match self {
            Fault::Stopped => format!("the check of {p} was stopped"),
            Fault::Empty => {
                format!("{p} is empty: the run that wrote it was killed before its first chunk")
            }
            Fault::NotMcap => format!("{p} is not an MCAP log (bad magic number at its start)"),
            Fault::Truncated => format!(
                "{p} is truncated: it ends inside a record, as the log of a killed run does; \
                 `weft recover {p} --out FIXED.mcap` writes a valid log with every complete chunk"
            ),
            Fault::Corrupt(e) => format!(
                "{p} is corrupt ({e}): its bytes changed after they were written; \
                 `weft recover {p} --out FIXED.mcap` keeps the chunks whose CRCs hold"
            ),
        }
    }
}

/// Whether `bytes` look like an MCAP log, whole or damaged: the MCAP magic at its start, a
/// start of it (a log cut inside its magic), the magic at its end (a damaged start), or a
/// Header record right after the first eight bytes.
pub fn looks_like_mcap(bytes: &[u8]) -> bool {
    let m = mcap::MAGIC.len();
    let header = bytes.get(m + 1..m + 9).and_then(|l| {
        let len = usize::try_from(u64::from_le_bytes(l.try_into().ok()?)).ok()?;
        bytes.get(m + 9..(m + 9).checked_add(len)?)
    });
    bytes.starts_with(mcap::MAGIC)
        || (!bytes.is_empty() && mcap::MAGIC.starts_with(bytes))
        || (bytes.len() >= 2 * m && bytes.ends_with(mcap::MAGIC))
        || (bytes.get(m) == Some(&mcap::records::op::HEADER)
            && header.is_some_and(|h| mcap::parse_record(mcap::records::op::HEADER, h).is_ok()))
}

/// Reads every record of `bytes`, checking every CRC. A log is truncated only when its last
/// record fails and it lacks the closing magic: one that ends with it is whole in length, so a
/// record running past its end has a damaged length field (corruption, not a cut), and a
/// record that fails before the last is corruption too. A raised `stop` ends the check.
pub fn verify(bytes: &[u8], stop: &AtomicBool) -> Result<(), Fault> {
    if bytes.is_empty() {
        return Err(Fault::Empty);
    }
    if !looks_like_mcap(bytes) {
        return Err(Fault::NotMcap);
    }
    if mcap::MAGIC.starts_with(bytes) {
        return Err(Fault::Truncated);
    }
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(Fault::Corrupt("bad magic number at its start".into()));
    }
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            // A chunk decompresses to more than its share of the file; a damaged length field
            // must still not ask for more memory than a hundredfold the file (at least 1 GiB).
            .with_record_length_limit(bytes.len().saturating_mul(100).max(1 << 30)),
    );
    let cut = first_unfit(bytes);
    let mut rest = bytes;
    while let Some(event) = reader.next_event() {
        // Checking a log of hundreds of MB takes seconds: a stop must not wait for it.
        if stop.load(Ordering::Relaxed) {
            return Err(Fault::Stopped);
        }
        match event {
            Ok(LinearReadEvent::ReadRequest(need)) => {
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            Ok(LinearReadEvent::Record { opcode, data }) => {
                if let Err(e) = mcap::parse_record(opcode, data) {
                    return Err(Fault::Corrupt(e.to_string()));
                }
            }
            // No closing magic (nor a damaged one), and the failing record is the one that
            // runs past the end: it is cut (a killed writer's last chunk still has its
            // placeholder header, lengths all ones).
            Err(e)
                if !bytes.ends_with(mcap::MAGIC)
                    && !matches!(e, mcap::McapError::BadMagic)
                    && {
                        let read = bytes.len() - rest.len();
                        read > cut || (read == cut && cut == bytes.len())
                    } =>
            {
                return Err(Fault::Truncated);
            }
            Err(mcap::McapError::UnexpectedEof) => {
                return Err(Fault::Corrupt(
                    "a record runs past the end of the file, which ends with MCAP's closing \
                     magic: a damaged length field"
                        .into(),
                ));
            }
            Err(e) => return Err(Fault::Corrupt(e.to_string())),
        }
    }
    Ok(())
}

/// Where the records of `bytes` stop fitting in it: the offset of the first record that runs
/// past its end, or the end.
fn first_unfit(bytes: &[u8]) -> usize {
    let mut pos = mcap::MAGIC.len();
    while let Some(len) = bytes.get(pos + 1..pos + 9) {
        let len = u64::from_le_bytes(len.try_into().unwrap_or_default());
        match usize::try_from(len)
            .ok()
            .and_then(|l| (pos + 9).checked_add(l))
        {
            Some(end) if end <= bytes.len() => pos = end,
            _ => return pos,
        }
    }
    pos.min(bytes.len())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{RecordOptions, Recorder, Status};
    use weft_sim::Simulation;

    /// A flag never raised.
    static GO: AtomicBool = AtomicBool::new(false);

    /// A small log: a 4×4 cloth, two frames.
    fn small_log() -> Vec<u8> {
        let text = "[sim]\ndt = \"1/60\"\nsubsteps = 2\n\n[cloth.c]\nresolution = [4, 4]\n\
                    size = [0.2, 0.2]\ncenter = [0.0, 1.0, 0.0]\nmass = 0.1\npins = [\"top-left\"]\n";
        let scene = weft_scene::from_text("s.toml", text, &[], &weft_scene::DirFiles(".".into()))
            .expect("the scene loads");
        let mut sim = Simulation::new(scene).expect("the scene builds");
        // One file per call: the tests that call this run side by side in one process.
        static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let name = format!("weft-verify-{}-{call}.mcap", std::process::id());
        let path = std::env::temp_dir().join(name);
        let file = std::fs::File::create(&path).expect("a temporary file");
        let options = RecordOptions {
            mesh_every: 0,
            ..RecordOptions::default()
        };
        let mut rec = Recorder::new(file, &sim, 2, options).expect("a recorder");
        rec.frame(&sim, &sim.stats(0.0, 0)).expect("frame 0");
        for _ in 0..2 {
            let stats = sim.step().expect("a step");
            rec.frame(&sim, &stats).expect("a frame");
        }
        rec.finish(&Status::Complete, 2).expect("finished");
        let bytes = std::fs::read(&path).expect("the log");
        let _ = std::fs::remove_file(&path);
        bytes
    }

    /// Every byte of a small log flipped (four ways) is corruption, never truncation (before,
    /// 84 to 87 of its 13,170 flips were called truncated: length fields made to run past the
    /// end, the footer's header, the closing magic); every cut is truncation.
    #[test]
    fn a_flipped_byte_is_corruption_and_a_cut_is_truncation() {
        let bytes = small_log();
        assert_eq!(verify(&bytes, &GO), Ok(()));
        for x in [0xFF_u8, 0x01, 0x80, 0xA5] {
            for i in 0..bytes.len() {
                let mut b = bytes.clone();
                b[i] ^= x;
                let r = verify(&b, &GO);
                assert!(
                    matches!(r, Err(Fault::Corrupt(_))),
                    "byte {i} of {} xor {x:#04x}: {r:?}",
                    bytes.len()
                );
            }
        }
        for cut in 1..bytes.len() {
            assert_eq!(
                verify(&bytes[..cut], &GO),
                Err(Fault::Truncated),
                "cut at {cut}"
            );
        }
        // A killed writer's log: its last chunk has the placeholder header (lengths all ones)
        // and part of its data.
        let mut pos = mcap::MAGIC.len();
        while bytes[pos] != mcap::records::op::DATA_END {
            let len = u64::from_le_bytes(bytes[pos + 1..pos + 9].try_into().expect("8 bytes"));
            pos += 9 + usize::try_from(len).expect("a length");
        }
        let mut killed = bytes[..pos].to_vec();
        killed.push(mcap::records::op::CHUNK);
        killed.extend(u64::MAX.to_le_bytes());
        killed.extend([0; 16]);
        killed.extend(u64::MAX.to_le_bytes());
        killed.extend(u32::MAX.to_le_bytes());
        killed.extend(4_u32.to_le_bytes());
        killed.extend(b"zstd");
        killed.extend(u64::MAX.to_le_bytes());
        killed.extend(&bytes[100..400]);
        assert_eq!(verify(&killed, &GO), Err(Fault::Truncated));
        assert_eq!(verify(b"a = 1\n", &GO), Err(Fault::NotMcap));
    }

    #[test]
    fn a_raised_stop_ends_the_check() {
        let bytes = small_log();
        assert_eq!(verify(&bytes, &AtomicBool::new(true)), Err(Fault::Stopped));
        assert_eq!(verify(&bytes, &GO), Ok(()));
    }
}
