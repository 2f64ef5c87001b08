//! The real viewer in a virtual X server (Xvfb), driven by `xdotool`: start the server, open
//! the viewer on it, send keys and mouse moves, wait for it to exit.
//!
//! Needs `Xvfb` and `xdotool` (scripts/install-test-deps.sh installs them); a test using them
//! fails when they are missing.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread::sleep;
use std::time::{Duration, Instant};

use super::weft;

/// Kills a child process when dropped (the X server, or a viewer left running on failure).
pub struct Guard(pub Child);

impl Drop for Guard {
    fn drop(&mut self) {
        if self.0.try_wait().ok().flatten().is_some() {
            return;
        }
        // SIGTERM first, so that Xvfb removes its lock file and socket.
        let _ = Command::new("kill").arg(self.0.id().to_string()).status();
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(5) {
            if self.0.try_wait().ok().flatten().is_some() {
                return;
            }
            sleep(Duration::from_millis(50));
        }
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// Fails the test with an install hint when `tool` (from `package`) is missing.
pub fn require(tool: &str, package: &str) {
    let found = Command::new("sh")
        .args(["-c", &format!("command -v {tool}")])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        found,
        "{tool} is missing: install {package} (scripts/install-test-deps.sh does)"
    );
}

/// Checks for Xvfb and xdotool.
pub fn require_x11_tools() {
    require("Xvfb", "xvfb");
    require("xdotool", "xdotool");
}

/// Starts Xvfb on a free display number (searched from `offset`, so that the tests that use
/// it start apart); returns the display name and its guard.
pub fn start_xvfb(offset: u32) -> (String, Guard) {
    let base = 100 + (std::process::id() % 200) * 4 + offset * 100;
    for n in base..base + 50 {
        if Path::new(&format!("/tmp/.X{n}-lock")).exists()
            || Path::new(&format!("/tmp/.X11-unix/X{n}")).exists()
        {
            continue;
        }
        // The screen is kept in a file there (XWD), for screenshots (`screen.rs`).
        let fbdir = super::screen::fb_dir(&format!(":{n}"));
        let _ = std::fs::create_dir_all(&fbdir);
        let child = Command::new("Xvfb")
            .args([
                format!(":{n}"),
                "-screen".into(),
                "0".into(),
                "1280x1024x24".into(),
                "-fbdir".into(),
                fbdir.to_string_lossy().into_owned(),
                "-nolisten".into(),
                "tcp".into(),
                // No server reset when the last client leaves (the readiness check below is
                // one): a viewer connecting during a reset would be refused.
                "-noreset".into(),
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb starts");
        let mut guard = Guard(child);
        let socket = format!("/tmp/.X11-unix/X{n}");
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(10) {
            // Ready once a client can talk to it; another server may own the socket, so
            // ours must also still be running.
            let display = format!(":{n}");
            if Path::new(&socket).exists()
                && Command::new("xdotool")
                    .arg("getdisplaygeometry")
                    .env("DISPLAY", &display)
                    .output()
                    .is_ok_and(|o| o.status.success())
            {
                sleep(Duration::from_millis(300));
                if guard.0.try_wait().ok().flatten().is_none() {
                    return (display, guard);
                }
                break;
            }
            if guard.0.try_wait().ok().flatten().is_some() {
                break; // lost a race for this number: try the next
            }
            sleep(Duration::from_millis(50));
        }
    }
    panic!("could not start Xvfb on any display number");
}

/// Runs `xdotool` with `args` on `display`; returns its standard output.
pub fn xdotool(display: &str, args: &[&str]) -> String {
    let out = Command::new("xdotool")
        .args(args)
        .env("DISPLAY", display)
        .output()
        .expect("xdotool runs");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Starts `weft` with `args` on the X display `display` (Wayland hidden), its output kept.
pub fn viewer_on(display: &str, args: &[&str]) -> Guard {
    let child = weft()
        .args(args)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("weft view starts");
    Guard(child)
}

/// Starts `weft` with `args` on `display` and waits for its window and a few frames; returns
/// the process and the window id.
pub fn open_window(display: &str, args: &[&str]) -> (Guard, String) {
    let mut viewer = viewer_on(display, args);
    let start = Instant::now();
    let window = loop {
        let pid = viewer.0.id().to_string();
        let found = xdotool(display, &["search", "--pid", &pid, "--name", "Weft"]);
        if let Some(id) = found.split_whitespace().next() {
            break id.to_owned();
        }
        if let Some(status) = viewer.0.try_wait().expect("wait") {
            let out = viewer.0.wait_with_output_now();
            panic!("the viewer exited before opening its window on {display} ({status}): {out}");
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "no viewer window after 120 s"
        );
        sleep(Duration::from_millis(200));
    };
    sleep(Duration::from_secs(3));
    (viewer, window)
}

/// Waits for the viewer to exit (at most `limit`); returns its status and output.
pub fn wait_exit(
    viewer: &mut Guard,
    limit: Duration,
    what: &str,
) -> (std::process::ExitStatus, String) {
    let start = Instant::now();
    let status = loop {
        if let Some(s) = viewer.0.try_wait().expect("wait") {
            break s;
        }
        assert!(start.elapsed() < limit, "the viewer did not quit on {what}");
        sleep(Duration::from_millis(100));
    };
    (status, viewer.0.wait_with_output_now())
}

/// Output of a finished child, for messages.
pub trait OutputText {
    /// Its standard output then its standard error, as far as they can be read.
    fn wait_with_output_now(&mut self) -> String;
}

impl OutputText for Child {
    fn wait_with_output_now(&mut self) -> String {
        use std::io::Read;
        let mut s = String::new();
        if let Some(o) = self.stdout.as_mut() {
            let _ = o.read_to_string(&mut s);
        }
        if let Some(e) = self.stderr.as_mut() {
            let _ = e.read_to_string(&mut s);
        }
        s
    }
}

/// `v` as `X,Y,Z` for `--eye` and `--target`.
pub fn xyz(v: glam::Vec3) -> String {
    format!("{},{},{}", v.x, v.y, v.z)
}
