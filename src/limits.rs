//! The command-line limits: the memory a scene may need once built (by default the machine's
//! available memory) and the largest scene or mesh file read.

use clap::Args;
use weft_scene::Limits;

/// `--max-memory` and `--max-file-size`.
#[derive(Clone, Debug, Args)]
pub struct LimitArgs {
    /// Most memory the scene may need once built, e.g. `8G`, `512M` (default: the memory the
    /// machine has available, MemAvailable in /proc/meminfo). A scene estimated above it is
    /// refused before any cloth is built.
    #[arg(long, value_name = "SIZE", value_parser = parse_bytes)]
    pub max_memory: Option<u64>,
    /// Largest scene or mesh file read, e.g. `1G`.
    #[arg(long, value_name = "SIZE", value_parser = parse_bytes, default_value = "256M")]
    pub max_file_size: u64,
}

impl LimitArgs {
    /// The limits a load enforces.
    pub fn limits(&self) -> Limits {
        let available = Limits::available();
        Limits {
            max_file_bytes: self.max_file_size,
            max_memory: match self.max_memory {
                Some(b) => Some((b, "--max-memory".to_owned())),
                None => available.max_memory,
            },
        }
    }
}

pub use weft_scene::peak_memory;

/// A size in bytes: `123`, `64K`, `512M`, `8G`, `1T` (powers of 1024; `B`/`iB` suffixes
/// accepted).
pub fn parse_bytes(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let t = t
        .strip_suffix("iB")
        .or_else(|| t.strip_suffix('B'))
        .unwrap_or(t);
    let (num, shift) = match t.char_indices().last() {
        Some((i, c)) if c.is_ascii_alphabetic() => {
            let shift = match c.to_ascii_uppercase() {
                'K' => 10,
                'M' => 20,
                'G' => 30,
                'T' => 40,
                _ => return Err(format!("expected a size such as 512M or 8G, got {s:?}")),
            };
            (&t[..i], shift)
        }
        _ => (t, 0),
    };
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("expected a size such as 512M or 8G, got {s:?}"))?;
    let bytes = v * (1u64 << shift) as f64;
    if !(1.0..1.8e19).contains(&bytes) {
        return Err(format!(
            "a size must be at least 1 byte and below 16 EiB, got {s:?}"
        ));
    }
    Ok(bytes as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_bytes("512"), Ok(512));
        assert_eq!(parse_bytes("64K"), Ok(64 << 10));
        assert_eq!(parse_bytes("1.5G"), Ok(3 << 29));
        assert_eq!(parse_bytes("8GiB"), Ok(8 << 30));
        for bad in ["", "G", "-1M", "0", "12Q", "nan"] {
            assert!(parse_bytes(bad).is_err(), "{bad}");
        }
    }
}
