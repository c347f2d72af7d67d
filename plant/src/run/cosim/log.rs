//! The controller process's output (its stdout and stderr), drained as it
//! comes into `controller.log` in the run folder.
//!
//! A controller the plant starts writes into a pipe that a thread of the
//! plant reads at once, so a chatty controller never blocks on its own
//! output (it used to inherit the plant's stdout: when that was a pipe nobody
//! drained, the controller blocked before its hello and the plant gave up
//! after the connect timeout with no hint why). The file is bounded: the
//! first [`HEAD_BYTES`] go straight to it; after that only the last
//! [`TAIL_BYTES`] are kept, and they are written at the end of the session
//! after a line saying how many bytes were left out between. A respawned
//! controller appends to the same file after a line naming it. Without a run
//! folder (compare, sweeps, `bench ipc`) the output is drained and only its
//! last lines are kept, for the plant's messages.
//!
//! The plant quotes the last lines in its messages about a controller that
//! exited or did not answer, naming the file.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, Sender};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Bytes written to the file as they come.
pub const HEAD_BYTES: usize = 1 << 20;
/// Bytes kept from the end of the output once the head is full.
pub const TAIL_BYTES: usize = 256 << 10;
/// Bytes kept for the plant's messages.
const RECENT_BYTES: usize = 4096;
/// How long the plant waits for a drained controller's last bytes (its pipe's end).
const SETTLE: Duration = Duration::from_millis(500);

/// Where the output goes, shared with the drain threads.
#[derive(Default)]
struct State {
    file: Option<File>,
    head_left: usize,
    tail: VecDeque<u8>,
    /// Bytes that fell out of the tail.
    dropped: u64,
    recent: VecDeque<u8>,
    /// The first write error (the run goes on; the log says it is incomplete at the end).
    error: Option<String>,
    /// Set when the session ends: later bytes (a grandchild holding the pipe) are discarded.
    closed: bool,
}

impl State {
    fn take(&mut self, bytes: &[u8]) {
        if self.closed {
            return;
        }
        push_bounded(&mut self.recent, bytes, RECENT_BYTES, &mut 0);
        let head = bytes.len().min(self.head_left);
        if head > 0 {
            self.head_left -= head;
            if let Some(f) = &mut self.file {
                if let Err(e) = f.write_all(&bytes[..head]) {
                    self.error.get_or_insert(e.to_string());
                }
            }
        }
        let mut dropped = 0;
        push_bounded(&mut self.tail, &bytes[head..], TAIL_BYTES, &mut dropped);
        self.dropped += dropped;
    }
}

/// Appends `bytes` to `ring`, keeping its last `cap` bytes; counts what falls out.
fn push_bounded(ring: &mut VecDeque<u8>, bytes: &[u8], cap: usize, dropped: &mut u64) {
    let bytes = if bytes.len() > cap {
        *dropped += (bytes.len() - cap) as u64;
        &bytes[bytes.len() - cap..]
    } else {
        bytes
    };
    let over = (ring.len() + bytes.len()).saturating_sub(cap);
    *dropped += over as u64;
    ring.drain(..over);
    ring.extend(bytes);
}

/// The output of the controller processes of one session.
pub struct OutputLog {
    state: Arc<Mutex<State>>,
    path: Option<PathBuf>,
    /// One message per drain thread when its pipe ends.
    ended: (Sender<()>, Receiver<()>),
    running: usize,
    /// Cores the drain threads keep off ([`OutputLog::avoiding`]).
    avoid: Vec<usize>,
}

impl OutputLog {
    /// A log into `path` (created or truncated), or in memory only.
    pub fn create(path: Option<&Path>) -> std::io::Result<Self> {
        let file = path.map(crate::outfile::create).transpose()?;
        Ok(Self {
            state: Arc::new(Mutex::new(State { file, head_left: HEAD_BYTES, ..Default::default() })),
            path: path.map(Path::to_path_buf),
            ended: channel(),
            running: 0,
            avoid: Vec::new(),
        })
    }

    /// Keeps the drain threads off `cores` (a realtime run's `controller.pin_cores`).
    pub fn avoiding(mut self, cores: &[usize]) -> Self {
        self.avoid = cores.to_vec();
        self
    }

    fn state(&self) -> MutexGuard<'_, State> {
        // A drain thread cannot panic while it holds the lock (plain byte copies).
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A pipe for one controller process: its write end for the child's stdout and stderr
    /// (after a line naming `what`), its read end drained by a thread of its own.
    pub fn attach(&mut self, what: &str) -> std::io::Result<(std::io::PipeWriter, std::io::PipeWriter)> {
        let (mut reader, writer) = std::io::pipe()?;
        let second = writer.try_clone()?;
        self.state().take(format!("--- plant: started {what} ---\n").as_bytes());
        let (state, ended, avoid) = (self.state.clone(), self.ended.0.clone(), self.avoid.clone());
        std::thread::Builder::new().name("controller-output".into()).spawn(move || {
            // Started by a realtime loop: an ordinary thread, off the loop's priority and core.
            controller::link::ordinary_thread(&avoid);
            let mut buf = [0u8; 8192];
            loop {
                match reader.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => state.lock().unwrap_or_else(|p| p.into_inner()).take(&buf[..n]),
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
            let _ = ended.send(());
        })?;
        self.running += 1;
        Ok((writer, second))
    }

    /// Waits (up to half a second) for the pipes of the controllers that exited to end, so
    /// that their last bytes are in.
    pub fn settle(&mut self) {
        let until = Instant::now() + SETTLE;
        while self.running > 0 {
            match self.ended.1.recv_timeout(until.saturating_duration_since(Instant::now())) {
                Ok(()) => self.running -= 1,
                Err(_) => break,
            }
        }
    }

    /// The file, if there is one.
    pub fn path(&self) -> Option<&Path> {
        self.path.as_deref()
    }

    /// The last non-empty lines of the output (at most `n`, at most 300 characters), for a
    /// message: `; its last output (FILE): "…"`, or empty when it wrote nothing.
    pub fn quote(&self, n: usize) -> String {
        let recent: Vec<u8> = self.state().recent.iter().copied().collect();
        let text = String::from_utf8_lossy(&recent);
        let lines: Vec<&str> =
            text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with("--- plant: ")).collect();
        let last = lines[lines.len().saturating_sub(n)..].join(" | ");
        let last: String = if last.chars().count() > 300 {
            let skip = last.chars().count() - 300;
            format!("…{}", last.chars().skip(skip).collect::<String>())
        } else {
            last
        };
        let file = self.path.as_ref().map(|p| format!(" ({})", p.display())).unwrap_or_default();
        if last.is_empty() {
            match &self.path {
                Some(p) => format!("; it wrote nothing to {}", p.display()),
                None => String::new(),
            }
        } else {
            format!("; its last output{file}: \"{last}\"")
        }
    }

    /// Ends the log: waits for the controllers' pipes, then writes the kept tail after a line
    /// saying how much was left out.
    pub fn finish(&mut self) {
        self.settle();
        let mut s = self.state();
        if s.closed {
            return;
        }
        s.closed = true;
        let (tail, dropped) = (std::mem::take(&mut s.tail), s.dropped);
        let error = s.error.take();
        let Some(f) = s.file.as_mut() else { return };
        let mut end = Vec::new();
        if dropped > 0 {
            end.extend(
                format!(
                    "\n--- plant: {dropped} bytes of the controller's output left out here (the file keeps the first {HEAD_BYTES} and the last {TAIL_BYTES}) ---\n"
                )
                .as_bytes(),
            );
        }
        end.extend(tail);
        if let Some(e) = error {
            end.extend(format!("\n--- plant: this file is incomplete: {e} ---\n").as_bytes());
        }
        let _ = f.write_all(&end);
    }
}

impl Drop for OutputLog {
    fn drop(&mut self) {
        self.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read(path: &Path) -> String {
        String::from_utf8_lossy(&std::fs::read(path).unwrap()).into_owned()
    }

    /// A child that writes more than the bound: the head and the tail are kept, the middle
    /// is counted; the child never blocks (it ends).
    #[test]
    fn a_chatty_child_is_drained_and_the_file_bounded() {
        let dir = std::env::temp_dir().join(format!("plant-controller-log-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("controller.log");
        let mut log = OutputLog::create(Some(&path)).unwrap();
        let (out, err) = log.attach("`sh` (pid 1)").unwrap();
        // 3 MiB on stdout, then a last word on stderr.
        let status = std::process::Command::new("sh")
            .args(["-c", "head -c 3145728 /dev/zero | tr '\\0' x; echo; echo 'the last word' >&2"])
            .stdout(out)
            .stderr(err)
            .status()
            .unwrap();
        assert!(status.success());
        log.settle();
        assert_eq!(log.quote(1), format!("; its last output ({}): \"the last word\"", path.display()));
        drop(log);
        let text = read(&path);
        assert!(text.starts_with("--- plant: started `sh` (pid 1) ---\nxxx"), "{}", &text[..80]);
        assert!(text.ends_with("x\nthe last word\n"), "{}", &text[text.len() - 80..]);
        assert!(text.len() <= HEAD_BYTES + TAIL_BYTES + 200, "{} bytes", text.len());
        let header = "--- plant: started `sh` (pid 1) ---\n".len();
        let dropped = header + 3 * 1024 * 1024 + 1 + "the last word\n".len() - HEAD_BYTES - TAIL_BYTES;
        assert!(
            text.contains(&format!("--- plant: {dropped} bytes of the controller's output left out here")),
            "{dropped}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_short_output_is_kept_whole_and_quoted() {
        let mut log = OutputLog::create(None).unwrap();
        assert_eq!(log.quote(2), "");
        let (mut out, _err) = log.attach("c").unwrap();
        out.write_all(b"one\n\ntwo\nthree\n").unwrap();
        drop((out, _err));
        log.settle();
        assert_eq!(log.quote(2), "; its last output: \"two | three\"");
    }
}
