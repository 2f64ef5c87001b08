//! Checks a log before it is trusted: whole (ends with its footer and magic), and every CRC
//! (chunks, data section, summary) intact. A log cut short points to `weft recover`.

use std::path::Path;

use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};

/// What is wrong with a log.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Fault {
    /// No bytes at all.
    Empty,
    /// Does not start with the MCAP magic.
    NotMcap,
    /// Ends inside a record: the writer was killed, or the file was cut.
    Truncated,
    /// A CRC or a record does not hold: the bytes changed after they were written.
    Corrupt(String),
}

impl Fault {
    /// A message for `path` with what to do about it.
    pub fn message(&self, path: &Path) -> String {
        let p = path.display();
        match self {
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

/// Reads every record of `bytes`, checking every CRC.
pub fn verify(bytes: &[u8]) -> Result<(), Fault> {
    if bytes.is_empty() {
        return Err(Fault::Empty);
    }
    if !bytes.starts_with(mcap::MAGIC) {
        return Err(Fault::NotMcap);
    }
    if bytes.len() < 2 * mcap::MAGIC.len() || !bytes.ends_with(mcap::MAGIC) {
        return Err(Fault::Truncated);
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
    let mut rest = bytes;
    while let Some(event) = reader.next_event() {
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
            Err(mcap::McapError::UnexpectedEof) => return Err(Fault::Truncated),
            Err(e) => return Err(Fault::Corrupt(e.to_string())),
        }
    }
    Ok(())
}
