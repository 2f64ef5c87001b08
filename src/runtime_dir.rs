//! A private `XDG_RUNTIME_DIR` for commands that open the GPU, where none is set (a container,
//! ssh, CI). Mesa's Vulkan drivers look for a Wayland display as they start and, without one,
//! print "error: XDG_RUNTIME_DIR is invalid or not set in the environment." — harmless (the
//! window is X11 or there is none), but it reads as a failure. The variable can only be set
//! safely before any thread starts, so weft re-executes itself (same process, same pid) with
//! it pointing at an empty directory of its own.

use std::ffi::OsString;
use std::os::unix::fs::{DirBuilderExt, MetadataExt, PermissionsExt};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};

/// The variable.
const VAR: &str = "XDG_RUNTIME_DIR";

/// Whether `value` (the variable's value, if set) is one the Wayland client accepts: an
/// absolute path.
pub fn usable(value: Option<&OsString>) -> bool {
    value.is_some_and(|v| Path::new(v).is_absolute())
}

/// `<temp>/weft-runtime-<uid>`, created with mode 0700 if missing; `None` if it cannot be
/// made, or exists but is not a private directory of this user.
fn private_dir() -> Option<PathBuf> {
    let uid = std::fs::metadata("/proc/self").ok()?.uid();
    let dir = std::env::temp_dir().join(format!("weft-runtime-{uid}"));
    let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
    let m = std::fs::symlink_metadata(&dir).ok()?;
    (m.is_dir() && m.uid() == uid && m.permissions().mode() & 0o077 == 0).then_some(dir)
}

/// When `gpu` (the command opens the GPU) and the variable is unusable, re-executes weft with
/// it set to a private directory; returns only if that is not needed or not possible (weft
/// then goes on as it was, messages and all).
pub fn ensure(gpu: bool) {
    if !gpu || usable(std::env::var_os(VAR).as_ref()) {
        return;
    }
    let (Some(dir), Ok(exe)) = (private_dir(), std::env::current_exe()) else {
        return;
    };
    // `exec` returns only on failure.
    let _ = std::process::Command::new(exe)
        .args(std::env::args_os().skip(1))
        .env(VAR, dir)
        .exec();
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_an_absolute_path_is_usable() {
        assert!(usable(Some(&"/run/user/1000".into())));
        assert!(!usable(Some(&"run/user".into())));
        assert!(!usable(Some(&"".into())));
        assert!(!usable(None));
    }

    #[test]
    fn the_private_directory_is_this_users_alone() {
        let dir = private_dir().expect("a private directory");
        let m = std::fs::metadata(&dir).expect("exists");
        assert!(m.is_dir());
        assert_eq!(m.permissions().mode() & 0o777, 0o700);
    }
}
