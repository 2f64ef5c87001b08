//! Output files that never destroy an input or each other: a command's outputs are checked
//! against its inputs and against one another (same path once canonicalised, or the same file
//! by device and inode), and each is written to a temporary file beside its target,
//! `<stem>.partial-<pid>-<n>.<ext>`, created exclusively (it never replaces a file, an input's
//! or another writer's, whatever the names given on the command line) and held under an
//! exclusive lock, then renamed into place only when finished. A file under its final name is
//! therefore always whole; a failed write leaves none; a killed run leaves its temporary file,
//! which `weft recover` reads, and which a later writer never empties.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::{Context, bail};

/// Partial files being written, removed by the signal handler when it ends the process.
static PARTIALS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes every partial file still being written (the process is about to end).
pub fn remove_partials() {
    if let Ok(list) = PARTIALS.lock() {
        for p in list.iter() {
            let _ = std::fs::remove_file(p);
        }
    }
}

/// What identifies a file: its canonical path, and its device and inode when it exists.
#[derive(Debug)]
struct Identity {
    path: PathBuf,
    inode: Option<(u64, u64)>,
}

impl Identity {
    fn of(path: &Path) -> Self {
        let inode = std::fs::metadata(path).ok().map(|m| dev_ino(&m));
        // A file that does not exist yet: its directory canonicalised, then its name.
        let canonical = std::fs::canonicalize(path).ok().or_else(|| {
            let name = path.file_name()?;
            let dir = match path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            Some(std::fs::canonicalize(dir).ok()?.join(name))
        });
        Self {
            path: canonical.unwrap_or_else(|| path.to_path_buf()),
            inode: inode.flatten(),
        }
    }

    fn same(&self, other: &Self) -> bool {
        self.path == other.path || (self.inode.is_some() && self.inode == other.inode)
    }
}

/// Takes an exclusive lock on `file` without waiting (flock(2): held by the open file, so
/// released when the last handle closes, a killed process's included); false when another
/// process (or another handle) holds it.
#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use rustix::fs::{FlockOperation, flock};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(e) if e == rustix::io::Errno::WOULDBLOCK => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// No locking where flock(2) does not exist: the partial-then-rename still keeps whole files.
#[cfg(not(unix))]
fn try_lock(_: &File) -> std::io::Result<bool> {
    Ok(true)
}

#[cfg(unix)]
fn dev_ino(m: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((m.dev(), m.ino()))
}

#[cfg(not(unix))]
fn dev_ino(_: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

/// A file a command reads or writes, with what it is called in messages (e.g. `--out`).
pub struct Named<'a> {
    /// E.g. "the scene", "--out".
    pub role: &'a str,
    /// The path as given.
    pub path: &'a Path,
}

/// Refuses an output that is one of the inputs, or the same file as another output.
pub fn refuse_clashes(inputs: &[Named<'_>], outputs: &[Named<'_>]) -> anyhow::Result<()> {
    let ins: Vec<Identity> = inputs.iter().map(|n| Identity::of(n.path)).collect();
    let outs: Vec<Identity> = outputs.iter().map(|n| Identity::of(n.path)).collect();
    for (o, oid) in outputs.iter().zip(&outs) {
        for (i, iid) in inputs.iter().zip(&ins) {
            if oid.same(iid) {
                bail!(
                    "{} {} is {} {}: refusing to overwrite an input",
                    o.role,
                    o.path.display(),
                    i.role,
                    i.path.display()
                );
            }
        }
    }
    for (a, (x, xid)) in outputs.iter().zip(&outs).enumerate() {
        for (y, yid) in outputs.iter().zip(&outs).skip(a + 1) {
            if xid.same(yid) {
                bail!(
                    "{} {} and {} {} are the same file: give each output its own path",
                    x.role,
                    x.path.display(),
                    y.role,
                    y.path.display()
                );
            }
        }
    }
    Ok(())
}

/// An output being written: a temporary file of its own beside `target`, locked, renamed to it by
/// [`Output::commit`]; removed if dropped unfinished. A target that exists and is not a regular
/// file (a device such as `/dev/null`, a FIFO) is written directly.
#[derive(Debug)]
pub struct Output {
    target: PathBuf,
    /// The file written (the partial, or the target itself when it is not a regular file).
    written: PathBuf,
    file: File,
    committed: bool,
}

/// The marker of a temporary file's name: `<stem>.partial-<pid>-<n>.<ext>`.
const PARTIAL: &str = ".partial";

/// The `n`-th name this process may write `target` under until it is finished:
/// `<stem>.partial-<pid>-<n>.<ext>` (`run.mcap` → `run.partial-4242-0.mcap`, so the file keeps
/// its type), or `<name>.partial-<pid>-<n>` for a name with no extension.
fn partial_candidate(target: &Path, n: u32) -> PathBuf {
    let tag = format!("{PARTIAL}-{}-{n}", std::process::id());
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

/// The final name a temporary file's name stands for (`run.partial-4242-0.mcap` → `run.mcap`,
/// and an older `run.partial.mcap` → `run.mcap`), or `None` for a name that is not one.
pub fn target_of_partial(name: &str) -> Option<String> {
    let at = name.rfind(PARTIAL)?;
    let rest = &name[at + PARTIAL.len()..];
    let (tag, ext) = match rest.find('.') {
        Some(dot) => (&rest[..dot], &rest[dot..]),
        None => (rest, ""),
    };
    let numbered = tag.strip_prefix('-').is_some_and(|t| {
        let mut parts = t.split('-');
        let digits = |p: Option<&str>| {
            p.is_some_and(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_digit()))
        };
        digits(parts.next()) && digits(parts.next()) && parts.next().is_none()
    });
    (tag.is_empty() || numbered).then(|| format!("{}{ext}", &name[..at]))
}

/// The temporary files beside `target` that stand for it (any writer's, finished or not).
fn partials_of(target: &Path) -> Vec<PathBuf> {
    let (Some(dir), Some(name)) = (target.parent(), target.file_name()) else {
        return Vec::new();
    };
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let name = name.to_string_lossy();
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .filter_map(|e| e.ok())
        .filter(|e| {
            let n = e.file_name();
            target_of_partial(&n.to_string_lossy()).is_some_and(|t| t == name)
        })
        .map(|e| target.with_file_name(e.file_name()))
        .collect();
    found.sort();
    found
}

/// Whether another open file holds `path` locked (a weft writing it now); a file that cannot
/// be opened is taken as not held.
fn held_by_another(path: &Path) -> bool {
    let Ok(file) = File::open(path) else {
        return false;
    };
    matches!(try_lock(&file), Ok(false))
}

/// Creates this process's temporary file for `target`, exclusively (`O_EXCL`): the first
/// free name of [`partial_candidate`]'s, so no existing file is ever opened for writing.
fn create_exclusive(target: &Path) -> anyhow::Result<(PathBuf, File)> {
    for n in 0..1000 {
        let partial = partial_candidate(target, n);
        match OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&partial)
        {
            Ok(file) => return Ok((partial, file)),
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
            Err(e) => {
                return Err(e).with_context(|| format!("cannot write {}", target.display()));
            }
        }
    }
    bail!(
        "cannot write {}: no free temporary name beside it",
        target.display()
    )
}

impl Output {
    /// Starts writing `target`; fails, naming it, when it cannot be created or when another
    /// weft is writing it.
    pub fn create(target: &Path) -> anyhow::Result<Self> {
        let special = std::fs::metadata(target).is_ok_and(|m| !m.is_file() && !m.is_dir());
        if special {
            let file = OpenOptions::new()
                .write(true)
                .open(target)
                .with_context(|| format!("cannot write {}", target.display()))?;
            return Ok(Self {
                target: target.to_path_buf(),
                written: target.to_path_buf(),
                file,
                committed: false,
            });
        }
        if target.is_dir() {
            bail!("cannot write {}: it is a directory", target.display());
        }
        // A target held locked is another writer's file (its temporary file, named as ours).
        if target.is_file() && held_by_another(target) {
            bail!(
                "another weft is writing {} (it holds it locked): refusing to replace it; choose \
                 another path",
                target.display()
            );
        }
        let (partial, file) = create_exclusive(target)?;
        if !try_lock(&file).with_context(|| format!("cannot lock {}", partial.display()))? {
            let _ = std::fs::remove_file(&partial);
            bail!("cannot lock {}", partial.display());
        }
        // Another writer of the same target (its temporary file held locked) is refused; a
        // killed run's temporary file is left as it is, for `weft recover`.
        if let Some(other) = partials_of(target)
            .into_iter()
            .find(|p| p.file_name() != partial.file_name() && held_by_another(p))
        {
            drop(file);
            let _ = std::fs::remove_file(&partial);
            bail!(
                "another weft is writing {} (it holds {} locked); wait for it or choose another \
                 path",
                target.display(),
                other.display()
            );
        }
        if let Ok(mut list) = PARTIALS.lock() {
            list.push(partial.clone());
        }
        Ok(Self {
            target: target.to_path_buf(),
            written: partial,
            file,
            committed: false,
        })
    }

    /// Starts writing the MCAP log `target`, as [`Output::create`], after refusing a target that
    /// is not a regular file (`/dev/null`, a FIFO, a terminal): an MCAP writer seeks back into
    /// its file to fill in each chunk's length and CRC, which such a file cannot take (written
    /// to `/dev/null`, a whole run was simulated and then failed to sync it).
    pub fn create_log(target: &Path) -> anyhow::Result<Self> {
        if std::fs::metadata(target).is_ok_and(|m| !m.is_file() && !m.is_dir()) {
            bail!(
                "cannot write an MCAP log to {}: it is not a regular file, and an MCAP log is \
                 written by seeking back into it (to fill in each chunk's length and CRC), which \
                 a device or a pipe does not allow; give the path of a file",
                target.display()
            );
        }
        Self::create(target)
    }

    /// The final path.
    pub fn target(&self) -> &Path {
        &self.target
    }

    /// The path being written (the partial, or the target when it is not a regular file), for
    /// writers that open the path themselves.
    pub fn partial(&self) -> &Path {
        &self.written
    }

    /// A handle on the file being written (sharing its lock).
    pub fn handle(&self) -> anyhow::Result<File> {
        self.file
            .try_clone()
            .with_context(|| format!("cannot write {}", self.written.display()))
    }

    /// Writes all of `bytes` (for small outputs written in one go).
    pub fn write_all(&mut self, bytes: &[u8]) -> anyhow::Result<()> {
        self.file
            .write_all(bytes)
            .with_context(|| format!("cannot write {}", self.target.display()))
    }

    /// Syncs the finished file and renames it into place.
    pub fn commit(mut self) -> anyhow::Result<()> {
        if self.written != self.target {
            self.file
                .sync_all()
                .with_context(|| format!("cannot write {}", self.target.display()))?;
            std::fs::rename(&self.written, &self.target).with_context(|| {
                format!(
                    "cannot rename {} to {}",
                    self.written.display(),
                    self.target.display()
                )
            })?;
            forget(&self.written);
        }
        self.committed = true;
        Ok(())
    }
}

fn forget(partial: &Path) {
    if let Ok(mut list) = PARTIALS.lock() {
        list.retain(|p| p != partial);
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if !self.committed && self.written != self.target {
            let _ = std::fs::remove_file(&self.written);
            forget(&self.written);
        }
    }
}

/// Writes `bytes` to `target` whole or not at all.
pub fn write_file(target: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let mut out = Output::create(target)?;
    out.write_all(bytes)?;
    out.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("weft-output-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("temp dir");
        d
    }

    #[test]
    fn an_output_that_is_an_input_by_another_name_is_refused() {
        let d = dir("clash");
        let scene = d.join("s.toml");
        std::fs::write(&scene, "x").expect("write");
        let other = d.join("sub").join("..").join("s.toml");
        std::fs::create_dir_all(d.join("sub")).expect("sub");
        let err = refuse_clashes(
            &[Named {
                role: "the scene",
                path: &scene,
            }],
            &[Named {
                role: "--out",
                path: &other,
            }],
        )
        .expect_err("same file");
        assert!(err.to_string().contains("refusing to overwrite"), "{err}");
        let link = d.join("hard.toml");
        std::fs::hard_link(&scene, &link).expect("hard link");
        assert!(
            refuse_clashes(
                &[Named {
                    role: "the scene",
                    path: &scene
                }],
                &[Named {
                    role: "--out",
                    path: &link
                }],
            )
            .is_err(),
            "a hard link is the same file"
        );
        let a = d.join("a.mcap");
        let b = d.join("./a.mcap");
        let err = refuse_clashes(
            &[],
            &[
                Named {
                    role: "--out",
                    path: &a,
                },
                Named {
                    role: "--dump-final",
                    path: &b,
                },
            ],
        )
        .expect_err("two outputs, one file");
        assert!(err.to_string().contains("same file"), "{err}");
        refuse_clashes(
            &[Named {
                role: "the scene",
                path: &scene,
            }],
            &[Named {
                role: "--out",
                path: &a,
            }],
        )
        .expect("distinct files pass");
    }

    #[test]
    fn a_second_writer_is_refused_and_nothing_shows_before_commit() {
        let d = dir("lock");
        let target = d.join("a.mcap");
        let mut first = Output::create(&target).expect("first writer");
        let err = Output::create(&target).expect_err("second writer");
        assert!(err.to_string().contains("another weft"), "{err}");
        first.write_all(b"whole").expect("write");
        assert!(
            !target.exists(),
            "nothing under the final name before commit"
        );
        first.commit().expect("commit");
        assert_eq!(std::fs::read(&target).expect("read"), b"whole");
        assert!(partials_of(&target).is_empty());
        let mut dropped = Output::create(&target).expect("a new writer after commit");
        dropped.write_all(b"half").expect("write");
        drop(dropped);
        assert_eq!(std::fs::read(&target).expect("read"), b"whole", "kept");
        assert!(
            partials_of(&target).is_empty(),
            "an unfinished partial goes"
        );
    }

    #[test]
    fn temporary_names_map_back_to_their_target_and_nothing_else_does() {
        let target = Path::new("/tmp/x/run.mcap");
        for n in [0, 7, 999] {
            let p = partial_candidate(target, n);
            let name = p.file_name().expect("name").to_string_lossy().into_owned();
            assert_eq!(
                target_of_partial(&name).as_deref(),
                Some("run.mcap"),
                "{name}"
            );
        }
        assert_eq!(
            target_of_partial("run.partial.mcap").as_deref(),
            Some("run.mcap")
        );
        assert_eq!(
            target_of_partial("log.partial-12-3").as_deref(),
            Some("log")
        );
        for not in [
            "run.mcap",
            "run.partially.mcap",
            "run.partial-x-1.mcap",
            "run.partial-1.mcap",
        ] {
            assert_eq!(target_of_partial(not), None, "{not}");
        }
    }

    #[test]
    fn a_killed_run_s_partial_is_kept_and_another_writer_s_is_never_replaced() {
        let d = dir("names");
        let target = d.join("a.mcap");
        // A killed run's temporary file (no lock held): a new writer leaves it whole.
        let stale = d.join("a.partial-999999-0.mcap");
        std::fs::write(&stale, b"killed run").expect("write");
        let mut out = Output::create(&target).expect("writer beside a stale partial");
        assert_ne!(out.partial(), stale.as_path());
        out.write_all(b"new").expect("write");
        out.commit().expect("commit");
        assert_eq!(std::fs::read(&stale).expect("read"), b"killed run", "kept");
        assert_eq!(std::fs::read(&target).expect("read"), b"new");
        // An output named as a running writer's temporary file is refused; a file named as
        // the old fixed partial (an input, say) is never opened for writing: a new writer's
        // temporary file is its own.
        let first = Output::create(&d.join("b.mcap")).expect("first");
        let err = Output::create(first.partial()).expect_err("another writer's file");
        assert!(err.to_string().contains("another weft"), "{err}");
        let input = d.join("c.partial.mcap");
        std::fs::write(&input, b"input").expect("write");
        let mut out = Output::create(&d.join("c.mcap")).expect("writer");
        out.write_all(b"output").expect("write");
        out.commit().expect("commit");
        assert_eq!(
            std::fs::read(&input).expect("read"),
            b"input",
            "input untouched"
        );
    }
}
