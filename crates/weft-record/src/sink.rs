//! The log's file, counting the bytes written so far for a progress line.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

/// A file that publishes how far into it the writer has got (its furthest position).
pub(crate) struct Sink {
    file: File,
    position: u64,
    furthest: Arc<AtomicU64>,
}

impl Sink {
    /// Wraps `file`, its size so far published in `furthest`.
    pub fn new(file: File, furthest: Arc<AtomicU64>) -> Self {
        Self {
            file,
            position: 0,
            furthest,
        }
    }

    /// The file, to sync it.
    pub fn into_file(self) -> File {
        self.file
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.file.write(buf)?;
        self.position += n as u64;
        self.furthest.fetch_max(self.position, Ordering::Relaxed);
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.file.flush()
    }
}

impl Seek for Sink {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        self.position = self.file.seek(pos)?;
        Ok(self.position)
    }
}
