//! What an export will need before it reads any frame: memory (the log, the chosen frames'
//! positions and, for a GLB, the file built in memory) against `--max-memory`, and the files'
//! size against the space free where they go (and a GLB's 4 GiB format limit).

use std::path::Path;

use anyhow::bail;
use weft_scene::human;

/// The needs of one export (bytes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// Memory at the peak.
    pub memory: u64,
    /// Everything written.
    pub output: u64,
    /// The largest single file.
    pub largest_file: u64,
}

/// A GLB's length is a 32-bit field.
pub const GLB_LIMIT: u64 = u32::MAX as u64;

/// Bytes free to an unprivileged writer in the file system holding `dir`.
#[cfg(unix)]
pub fn free_space(dir: &Path) -> Option<u64> {
    let s = rustix::fs::statvfs(dir).ok()?;
    Some(s.f_bavail.saturating_mul(s.f_frsize))
}

/// Unknown where statvfs(2) does not exist.
#[cfg(not(unix))]
pub fn free_space(_: &Path) -> Option<u64> {
    None
}

/// Refuses an export whose needs pass `max_memory` (with what set it), the free space `free`
/// in `dir`, or the GLB limit; the messages say how to export less.
pub fn check(
    needs: Needs,
    glb: bool,
    max_memory: Option<&(u64, String)>,
    free: Option<u64>,
    dir: &Path,
) -> anyhow::Result<()> {
    let fewer = "export fewer frames (--frames A..B, --every N)";
    if let Some((limit, by)) = max_memory
        && needs.memory > *limit
    {
        bail!(
            "the export needs about {} of memory, above {} ({by}); {fewer}",
            human(needs.memory),
            human(*limit)
        );
    }
    if glb && needs.largest_file > GLB_LIMIT {
        bail!(
            "the GLB would be about {}, above the format's 4 GiB; {fewer}, or --format obj",
            human(needs.largest_file)
        );
    }
    if let Some(free) = free
        && needs.output > free
    {
        bail!(
            "the export writes about {} but {} has {} free; {fewer}",
            human(needs.output),
            dir.display(),
            human(free)
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_limit_refuses_with_its_reason() {
        let needs = Needs {
            memory: 3 << 30,
            output: 2 << 30,
            largest_file: 5 << 30,
        };
        let dir = Path::new("out");
        let limit = (1u64 << 30, "--max-memory".to_owned());
        let e = check(needs, false, Some(&limit), None, dir).expect_err("memory");
        assert!(e.to_string().contains("--max-memory"), "{e}");
        let e = check(needs, true, None, None, dir).expect_err("glb");
        assert!(e.to_string().contains("4 GiB"), "{e}");
        check(needs, false, None, None, dir).expect("an OBJ sequence has no 4 GiB limit");
        let e = check(needs, false, None, Some(1 << 30), dir).expect_err("disk");
        assert!(e.to_string().contains("free"), "{e}");
        check(needs, false, None, Some(4 << 30), dir).expect("enough room");
    }
}
