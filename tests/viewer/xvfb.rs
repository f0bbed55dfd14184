//! Running the real `marbre` binary in a window under a private Xvfb
//! server: temporary folders, the X server, the child process and its log.
//! Shared by the window and soak tests.
//!
//! Each test starts its own Xvfb (`-displayfd` lets the server pick a free
//! display number itself, so a desktop session or another test run on the
//! same machine is never disturbed) and kills it on the way out. Without
//! `Xvfb` (or another tool a test names) or a GPU adapter the tests skip
//! loudly through `marbre_render::gpu::testing::skip`, which fails instead when
//! `MARBRE_REQUIRE_GPU=1` (as in CI).

use marbre_render::gpu::testing::{gpu_or_skip, skip};
use std::ffi::OsString;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::os::unix::fs::DirBuilderExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Mutex, MutexGuard, mpsc};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

const BIN: &str = env!("CARGO_BIN_EXE_marbre");

static SERIAL: Mutex<()> = Mutex::new(());

/// One window at a time within a test binary: on a software rasteriser
/// each frame takes about a second of every core, and two windows at once
/// would only make both slower and the timeouts less meaningful.
pub fn serial() -> MutexGuard<'static, ()> {
    // A failed test poisons the lock; the next one may still run.
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}

/// A private temporary folder, removed on drop unless the test failed (then
/// its path is printed so the logs and images can be inspected).
pub struct TempDir(PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> Self {
        let nanos = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .unwrap()
            .as_nanos();
        let path =
            std::env::temp_dir().join(format!("marbre-xvfb-{tag}-{}-{nanos}", std::process::id()));
        make_private_dir(&path);
        Self(path)
    }

    pub fn path(&self) -> &Path {
        &self.0
    }

    /// A 0700 subfolder (`XDG_RUNTIME_DIR` must be private to its user).
    pub fn subdir(&self, name: &str) -> PathBuf {
        let path = self.0.join(name);
        make_private_dir(&path);
        path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("kept {} for inspection", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

fn make_private_dir(path: &Path) {
    std::fs::DirBuilder::new()
        .recursive(true)
        .mode(0o700)
        .create(path)
        .unwrap_or_else(|e| panic!("creating {}: {e}", path.display()));
}

fn on_path(program: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
}

/// A child process killed on drop, so a failing assertion never leaves a
/// window or an X server behind.
pub struct Guard(pub Child);

impl Drop for Guard {
    fn drop(&mut self) {
        if let Ok(None) = self.0.try_wait() {
            let _ = self.0.kill();
        }
        let _ = self.0.wait();
    }
}

/// A private X server.
pub struct Xvfb {
    _server: Guard,
    pub display: String,
}

impl Xvfb {
    pub fn start(log_dir: &Path) -> Result<Self, String> {
        let log_path = log_dir.join("xvfb.log");
        let log = File::create(&log_path).map_err(|e| e.to_string())?;
        // `-displayfd 1`: the server picks the first free display number and
        // writes it to its stdout once it accepts connections, so there is
        // neither a race for a number nor a socket to poll for.
        // `-noreset`: by default the server resets whenever its last client
        // disconnects, and a client connecting meanwhile is refused. The
        // tests poll with xdotool (a client that connects and leaves) while
        // the viewer opens its first connection: `f12_writes_png_and_exr`
        // once failed so, with winit's "Failed to open connection to X
        // server" (2026-11-27).
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-noreset",
                "-screen",
                "0",
                "1280x800x24",
                "-nolisten",
                "tcp",
            ])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(log)
            .spawn()
            .map_err(|e| format!("cannot run Xvfb: {e}"))?;
        let stdout = child.stdout.take().unwrap();
        let server = Guard(child);
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = BufReader::new(stdout).read_line(&mut line);
            let _ = tx.send(line);
        });
        let line = rx.recv_timeout(Duration::from_secs(30)).unwrap_or_default();
        let number = line.trim();
        if number.is_empty() || !number.bytes().all(|b| b.is_ascii_digit()) {
            let log = std::fs::read_to_string(&log_path).unwrap_or_default();
            return Err(format!(
                "Xvfb did not report a display number; its log:\n{log}"
            ));
        }
        Ok(Self {
            _server: server,
            display: format!(":{number}"),
        })
    }
}

/// Xvfb and a GPU adapter, or `None` after a loud skip. `extra_tools` must be
/// on `PATH` too.
pub fn display_or_skip(test: &str, dir: &TempDir, extra_tools: &[&str]) -> Option<Xvfb> {
    for tool in std::iter::once(&"Xvfb").chain(extra_tools) {
        if !on_path(tool) {
            skip(
                test,
                &format!("`{tool}` is not on PATH (Debian: apt-get install xvfb xdotool)"),
            );
            return None;
        }
    }
    // The child finds its own adapter for the window's surface; this only
    // tells "no GPU at all" (skip) from "the viewer is broken" (fail).
    gpu_or_skip(test)?;
    match Xvfb::start(dir.path()) {
        Ok(x) => Some(x),
        Err(why) => {
            skip(test, &why);
            None
        }
    }
}

/// Starts the viewer on `x`'s display, its output going to `marbre.log` in
/// `dir`, its settings in a folder of `dir` (never the user's own).
/// Runs the viewer (or `args[0]`'s subcommand) on the virtual display,
/// with its own runtime and configuration folders. Unless `args` name a
/// kernel, it traces with the fragment kernel: `auto`, the default, would
/// time both kernels on a second device in every test (seconds of CPU on
/// lavapipe, with a fresh configuration folder each time).
pub fn spawn_marbre(x: &Xvfb, dir: &TempDir, cwd: &Path, args: &[OsString]) -> Guard {
    let log = File::create(dir.path().join("marbre.log")).unwrap();
    let mut args = args.to_vec();
    if !args.iter().any(|a| a == "--kernel") {
        args.extend(["--kernel".into(), "fragment".into()]);
    }
    let child = Command::new(BIN)
        .args(&args)
        .current_dir(cwd)
        .env("DISPLAY", &x.display)
        .env("XDG_RUNTIME_DIR", dir.subdir("runtime"))
        .env("MARBRE_CONFIG_DIR", dir.subdir("config"))
        // Loads wait while this file exists (`hold_loads`); none does
        // unless a test makes it.
        .env("MARBRE_TEST_HOLD_LOADS", hold_loads(dir))
        // The count of frames shown, which `wait_for_frames` reads.
        .env("MARBRE_TEST_SHOWN_FRAMES", shown_frames_file(dir))
        // The panel's messages too (the screenshots saved, the start-up
        // scene in): a failure's log then says how far the viewer got.
        .env("RUST_LOG", "warn,marbre=info")
        // winit would prefer Wayland if the test itself runs in a Wayland session.
        .env_remove("WAYLAND_DISPLAY")
        .stdin(Stdio::null())
        .stdout(log.try_clone().unwrap())
        .stderr(log)
        .spawn()
        .unwrap_or_else(|e| panic!("cannot run {BIN}: {e}"));
    Guard(child)
}

/// The file whose existence holds the viewer's scene loads before their
/// meshes are read (`MARBRE_TEST_HOLD_LOADS`): a slow disk, on demand.
pub fn hold_loads(dir: &TempDir) -> std::path::PathBuf {
    dir.path().join("hold-loads")
}

/// The file the viewer writes its count of frames shown to
/// (`MARBRE_TEST_SHOWN_FRAMES`, `src/app/shown_frames.rs`).
fn shown_frames_file(dir: &TempDir) -> PathBuf {
    dir.path().join("shown-frames")
}

/// How many frames the viewer started in `dir` has shown so far (0 before
/// its first).
pub fn shown_frames(dir: &TempDir) -> u64 {
    std::fs::read_to_string(shown_frames_file(dir))
        .ok()
        .and_then(|text| text.trim().parse().ok())
        .unwrap_or(0)
}

/// How long the viewer may take to show a few frames: a generous bound
/// that fails loudly. A frame takes about a second on lavapipe, several
/// with both cores busy, and a preset load's shader build tens of them.
const FRAMES_TIMEOUT: Duration = Duration::from_secs(180);

/// Waits until the viewer has shown `n` more frames than now: after an
/// input event, two more mean a frame has read it (the event makes the
/// next frame shown, and egui reads input once a frame). The wait the
/// window tests use between input steps instead of a fixed sleep, so a
/// slow or loaded machine only makes them slower (issue 47). Fails, with
/// the log, after [`FRAMES_TIMEOUT`].
pub fn wait_for_frames(dir: &TempDir, n: u64) {
    frames_or(dir, n, || None);
}

/// Waits for `n` more frames shown, unless `exited` first returns the
/// viewer's exit status, which it then returns; fails loudly after
/// [`FRAMES_TIMEOUT`]. The one loop of [`wait_for_frames`] and
/// [`frames_or_exit`].
fn frames_or(
    dir: &TempDir,
    n: u64,
    mut exited: impl FnMut() -> Option<ExitStatus>,
) -> Option<ExitStatus> {
    let target = shown_frames(dir) + n;
    let start = Instant::now();
    while shown_frames(dir) < target {
        if let Some(status) = exited() {
            return Some(status);
        }
        if start.elapsed() > FRAMES_TIMEOUT {
            panic!(
                "the viewer showed {} of {target} frames within {FRAMES_TIMEOUT:?}; its log:\n{}",
                shown_frames(dir),
                marbre_log(dir)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
}

pub fn marbre_log(dir: &TempDir) -> String {
    std::fs::read_to_string(dir.path().join("marbre.log")).unwrap_or_default()
}

/// The viewer's closing line (`quality: …`, written when it ends
/// cleanly): what the Quality strip showed, the frames drawn, the images
/// thrown away. Fails, with the log, if there is none.
pub fn quality_line(dir: &TempDir) -> String {
    let log = marbre_log(dir);
    log.lines()
        .find(|l| l.starts_with("quality: "))
        .map(str::to_owned)
        .unwrap_or_else(|| panic!("no quality line in the log:\n{log}"))
}

/// The number written just before `word` (`12 spp`, `0 restarts;`) in
/// `line`.
pub fn number_before(line: &str, word: &str) -> u32 {
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = words
        .iter()
        .position(|w| w.trim_end_matches(';') == word)
        .unwrap_or_else(|| panic!("no `{word}` in: {line}"));
    words[at - 1]
        .parse()
        .unwrap_or_else(|_| panic!("no number before `{word}` in: {line}"))
}

/// Waits for the viewer to exit; fails (and kills it) after `timeout`.
pub fn wait_for_exit(child: &mut Guard, dir: &TempDir, timeout: Duration) -> ExitStatus {
    let start = Instant::now();
    loop {
        if let Some(status) = child.0.try_wait().unwrap() {
            return status;
        }
        if start.elapsed() > timeout {
            let _ = child.0.kill();
            panic!(
                "marbre did not exit within {timeout:?}; its log:\n{}",
                marbre_log(dir)
            );
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

pub fn assert_success(status: ExitStatus, dir: &TempDir) {
    assert!(
        status.success(),
        "marbre exited with {status}; its log:\n{}",
        marbre_log(dir)
    );
}

/// Every thread's stack in process `pid`, as gdb prints them, or why there
/// are none: what a viewer that stopped answering was doing (`.ci/run`
/// installs gdb).
pub fn backtraces(pid: u32) -> String {
    if !on_path("gdb") {
        return "(gdb is not installed)".to_owned();
    }
    let pid = pid.to_string();
    match Command::new("timeout")
        .args(["120", "gdb", "-q", "-batch", "-p", &pid])
        .args(["-ex", "info threads", "-ex", "thread apply all bt 40"])
        .stdin(Stdio::null())
        .output()
    {
        Ok(out) => String::from_utf8_lossy(&out.stdout)
            .lines()
            .filter(|l| l.starts_with('#') || l.starts_with("Thread") || l.contains("  Id "))
            .collect::<Vec<_>>()
            .join("\n"),
        Err(e) => format!("(gdb did not run: {e})"),
    }
}

pub fn xdotool(x: &Xvfb, args: &[&str]) -> std::process::Output {
    Command::new("xdotool")
        .args(args)
        .env("DISPLAY", &x.display)
        .output()
        .unwrap_or_else(|e| panic!("cannot run xdotool: {e}"))
}

/// Asks window `window` (an id as xdotool prints it) to close, as a window
/// manager's close button does: a `WM_PROTOCOLS` client message carrying
/// `WM_DELETE_WINDOW` (winit's `CloseRequested`).
pub fn request_close(x: &Xvfb, window: &str) {
    use x11rb::protocol::xproto::{ClientMessageEvent, ConnectionExt, EventMask};

    let send = || -> Result<(), Box<dyn std::error::Error>> {
        let window: u32 = window.trim().parse()?;
        let (conn, _) = x11rb::connect(Some(&x.display))?;
        let protocols = conn.intern_atom(false, b"WM_PROTOCOLS")?.reply()?.atom;
        let delete = conn.intern_atom(false, b"WM_DELETE_WINDOW")?.reply()?.atom;
        let message = ClientMessageEvent::new(32, window, protocols, [delete, 0, 0, 0, 0]);
        // Checked: a round trip, so the server has the event before this
        // connection closes.
        conn.send_event(false, window, EventMask::NO_EVENT, message)?
            .check()?;
        Ok(())
    };
    send().unwrap_or_else(|e| panic!("sending WM_DELETE_WINDOW to window {window}: {e}"));
}

/// What window `window` (an id as xdotool prints it) shows now, read from
/// the X server: unlike F12, which the viewer handles between frames, this
/// sees the window whatever the viewer is busy with.
pub fn grab_window(x: &Xvfb, window: &str) -> image::RgbImage {
    use x11rb::protocol::xproto::{ConnectionExt, ImageFormat};

    let grab = || -> Result<image::RgbImage, Box<dyn std::error::Error>> {
        let window: u32 = window.trim().parse()?;
        let (conn, _) = x11rb::connect(Some(&x.display))?;
        let geometry = conn.get_geometry(window)?.reply()?;
        let (w, h) = (geometry.width, geometry.height);
        let reply = conn
            .get_image(ImageFormat::Z_PIXMAP, window, 0, 0, w, h, !0)?
            .reply()?;
        // Xvfb's 24-bit screen: 32 bits a pixel, blue first.
        if reply.depth != 24 || reply.data.len() != usize::from(w) * usize::from(h) * 4 {
            return Err(format!("unexpected image: depth {}", reply.depth).into());
        }
        let rgb = reply
            .data
            .chunks_exact(4)
            .flat_map(|bgrx| [bgrx[2], bgrx[1], bgrx[0]])
            .collect();
        Ok(image::RgbImage::from_raw(w.into(), h.into(), rgb).expect("the size matches"))
    };
    grab().unwrap_or_else(|e| panic!("reading window {window}'s pixels: {e}"))
}

/// Drops the file `path` on window `window` (an id as xdotool prints it)
/// as a file manager does, by the XDND protocol (version 5): this
/// connection owns `XdndSelection` and offers `text/uri-list`, sends
/// `XdndEnter` and `XdndPosition` (at the window's centre), hands the URI
/// over when the window asks for it (winit asks on the position), waits
/// for `XdndStatus`, then sends `XdndDrop` and waits for `XdndFinished`.
/// winit turns that into `WindowEvent::DroppedFile`. xdotool has no drag
/// with data, and Xvfb runs no file manager.
pub fn drop_file(x: &Xvfb, window: &str, path: &Path) {
    use x11rb::connection::Connection;
    use x11rb::protocol::Event;
    use x11rb::protocol::xproto::{
        ClientMessageEvent, ConnectionExt, CreateWindowAux, EventMask, PropMode,
        SELECTION_NOTIFY_EVENT, SelectionNotifyEvent, WindowClass,
    };
    use x11rb::wrapper::ConnectionExt as _;

    let send = || -> Result<(), Box<dyn std::error::Error>> {
        let target: u32 = window.trim().parse()?;
        let (conn, screen) = x11rb::connect(Some(&x.display))?;
        let root = conn.setup().roots[screen].root;
        let atom = |name: &str| -> Result<u32, Box<dyn std::error::Error>> {
            Ok(conn.intern_atom(false, name.as_bytes())?.reply()?.atom)
        };
        let [
            selection,
            enter,
            position,
            status,
            drop,
            finished,
            copy,
            uri_list,
        ] = [
            "XdndSelection",
            "XdndEnter",
            "XdndPosition",
            "XdndStatus",
            "XdndDrop",
            "XdndFinished",
            "XdndActionCopy",
            "text/uri-list",
        ]
        .map(atom);
        let (selection, enter, position, status) = (selection?, enter?, position?, status?);
        let (drop, finished, copy, uri_list) = (drop?, finished?, copy?, uri_list?);
        let source = conn.generate_id()?;
        conn.create_window(
            0,
            source,
            root,
            0,
            0,
            1,
            1,
            0,
            WindowClass::INPUT_ONLY,
            0,
            &CreateWindowAux::new(),
        )?;
        conn.set_selection_owner(source, selection, x11rb::CURRENT_TIME)?;
        let geometry = conn.get_geometry(target)?.reply()?;
        let centre = conn
            .translate_coordinates(
                target,
                root,
                (geometry.width / 2) as i16,
                (geometry.height / 2) as i16,
            )?
            .reply()?;
        let message = |kind: u32, data: [u32; 5]| -> Result<(), Box<dyn std::error::Error>> {
            let event = ClientMessageEvent::new(32, target, kind, data);
            conn.send_event(false, target, EventMask::NO_EVENT, event)?
                .check()?;
            Ok(())
        };
        // Version 5, at most three types (no XdndTypeList), the first ours.
        message(enter, [source, 5 << 24, uri_list, 0, 0])?;
        let at = ((centre.dst_x as u32) << 16) | (centre.dst_y as u16 as u32);
        message(position, [source, 0, at, x11rb::CURRENT_TIME, copy])?;
        let uri = format!("file://{}\r\n", percent_encode(path));
        let deadline = Instant::now() + Duration::from_secs(60);
        let (mut accepted, mut served, mut dropped) = (false, false, false);
        while Instant::now() < deadline {
            let Some(event) = conn.poll_for_event()? else {
                std::thread::sleep(Duration::from_millis(20));
                continue;
            };
            match event {
                Event::SelectionRequest(request) if request.selection == selection => {
                    conn.change_property8(
                        PropMode::REPLACE,
                        request.requestor,
                        request.property,
                        uri_list,
                        uri.as_bytes(),
                    )?;
                    let notify = SelectionNotifyEvent {
                        response_type: SELECTION_NOTIFY_EVENT,
                        sequence: 0,
                        time: request.time,
                        requestor: request.requestor,
                        selection: request.selection,
                        target: request.target,
                        property: request.property,
                    };
                    conn.send_event(false, request.requestor, EventMask::NO_EVENT, notify)?
                        .check()?;
                    served = true;
                }
                Event::ClientMessage(reply) if reply.type_ == status => {
                    if reply.data.as_data32()[1] & 1 == 0 {
                        return Err("the window refused the drag (XdndStatus)".into());
                    }
                    accepted = true;
                }
                Event::ClientMessage(reply) if reply.type_ == finished => {
                    return if reply.data.as_data32()[1] & 1 == 1 {
                        Ok(())
                    } else {
                        Err("the window refused the drop (XdndFinished)".into())
                    };
                }
                _ => {}
            }
            // The data is the window's before the drop reaches it: the
            // selection notice was sent first.
            if accepted && served && !dropped {
                message(drop, [source, 0, x11rb::CURRENT_TIME, 0, 0])?;
                dropped = true;
            }
        }
        Err(format!(
            "no XdndFinished within 60 s (status received: {accepted}, data served: {served})"
        )
        .into())
    };
    send().unwrap_or_else(|e| panic!("dropping {} on window {window}: {e}", path.display()));
}

/// `path` as a file URI's path: bytes other than unreserved ones and `/`
/// percent-encoded (winit decodes them).
fn percent_encode(path: &Path) -> String {
    use std::os::unix::ffi::OsStrExt;
    path.as_os_str()
        .as_bytes()
        .iter()
        .map(|&b| match b {
            b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => {
                (b as char).to_string()
            }
            _ => format!("%{b:02X}"),
        })
        .collect()
}

/// Waits, as [`wait_for_frames`] does, for `n` more frames shown, unless
/// the viewer exits first; its exit status then. The wait of a check
/// that the viewer must not act on a request (a close it must ask about):
/// once two more frames are shown the viewer has handled the request,
/// however slow the machine, where a fixed sleep only guessed (issue 47);
/// a viewer that wrongly exits is seen at once, not after the timeout.
pub fn frames_or_exit(child: &mut Guard, dir: &TempDir, n: u64) -> Option<ExitStatus> {
    frames_or(dir, n, || child.0.try_wait().unwrap()).or_else(|| child.0.try_wait().unwrap())
}

/// Waits until `done` holds, polling; fails loudly, naming `what` and
/// with the log, after `timeout` (a generous bound, never one a figure
/// depends on).
pub fn wait_until(what: &str, timeout: Duration, dir: &TempDir, mut done: impl FnMut() -> bool) {
    let start = Instant::now();
    while !done() {
        assert!(
            start.elapsed() < timeout,
            "{what}: not within {timeout:?}; marbre's log:\n{}",
            marbre_log(dir)
        );
        std::thread::sleep(Duration::from_millis(100));
    }
}
