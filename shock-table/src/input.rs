//! Reading a file a user names, without trusting it: a regular file only (a
//! device such as `/dev/zero`, a FIFO or a folder is refused at once, before
//! it is read: opening a FIFO would wait for a writer, reading `/dev/zero`
//! would never end), opened without blocking (`O_NONBLOCK`: a regular file of `/proc` such
//! as `/proc/kmsg` waits in its reads for data that may never come; issue 40 item 7) and
//! with a size (a file whose size is 0 but whose read gives bytes, or would wait, is a file
//! of `/proc` or `/sys`, refused), and at most a given number of bytes. The plant's scene,
//! programme, sweep and summary files, the shock records and the controller's
//! `--config` go through here; `plant analyze` opens `trace.csv` with
//! [`open_regular`] and bounds its lines itself.
//!
//! ```
//! let dir = std::env::temp_dir().join(format!("input-doc-{}", std::process::id()));
//! std::fs::create_dir_all(&dir).unwrap();
//! std::fs::write(dir.join("a.toml"), "x = 1\n").unwrap();
//! assert_eq!(shock_table::input::read_text(&dir.join("a.toml"), 100).unwrap(), "x = 1\n");
//! let e = shock_table::input::read_text(&dir.join("a.toml"), 3).unwrap_err().to_string();
//! assert_eq!(e, "6 bytes: an input file may have at most 3 bytes");
//! let e = shock_table::input::read_text(std::path::Path::new("/dev/zero"), 100).unwrap_err().to_string();
//! assert_eq!(e, "not a regular file (a device, a FIFO or a folder)");
//! let e = shock_table::input::read_text(std::path::Path::new("/proc/self/status"), 100).unwrap_err().to_string();
//! assert!(e.starts_with("not a regular file with a size: its size is 0 but reading it gives bytes"), "{e}");
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::fs::File;
use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The most a TOML input file (scene, programme, sweep) may hold: far beyond any real one.
pub const MAX_TOML_BYTES: u64 = 16 << 20;

/// Opens `path` for reading if it names a regular file (links followed); anything else is
/// refused with an `InvalidInput` error before it is opened. It is opened with `O_NONBLOCK`:
/// should the path be replaced by a FIFO between the look-up and the opening, the opening does
/// not wait for a writer (and is refused after it), and a regular file of `/proc` that would
/// wait for data (`/proc/kmsg`) fails its read at once instead.
pub fn open_regular(path: &Path) -> std::io::Result<File> {
    let refuse = || Error::new(ErrorKind::InvalidInput, "not a regular file (a device, a FIFO or a folder)");
    // Looked up before opening: a device is not even opened.
    if !std::fs::metadata(path)?.is_file() {
        return Err(refuse());
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    // And what was opened (the path may have been replaced in between).
    if !file.metadata()?.is_file() {
        return Err(refuse());
    }
    Ok(file)
}

/// Reads a regular file of at most `max` bytes as UTF-8 text.
pub fn read_text(path: &Path, max: u64) -> std::io::Result<String> {
    String::from_utf8(read_bytes(path, max)?).map_err(|e| Error::new(ErrorKind::InvalidData, e.utf8_error()))
}

/// Reads a regular file of at most `max` bytes.
pub fn read_bytes(path: &Path, max: u64) -> std::io::Result<Vec<u8>> {
    let mut bytes = Vec::new();
    open_bounded(path, max)?.read_to_end(&mut bytes)?;
    Ok(bytes)
}

/// Opens a regular file of at most `max` bytes for reading as a stream (a CSV table): its
/// reads fail (`InvalidInput`) once more than `max` bytes came, should it grow while read.
pub fn open_bounded(path: &Path, max: u64) -> std::io::Result<impl Read> {
    let mut file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > max {
        return Err(Error::new(
            ErrorKind::InvalidInput,
            format!("{len} bytes: an input file may have at most {max} bytes"),
        ));
    }
    if len == 0 {
        // An empty file reads as empty; a file of /proc or /sys says 0 and reads on (or waits).
        let refuse = |why: &str| {
            Error::new(ErrorKind::InvalidInput, format!("not a regular file with a size: its size is 0 but {why}"))
        };
        match file.read(&mut [0u8; 1]) {
            Ok(0) => {}
            Ok(_) => return Err(refuse("reading it gives bytes (a file of /proc or /sys)")),
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                return Err(refuse("reading it would wait (a file of /proc such as /proc/kmsg)"))
            }
            Err(e) => return Err(e),
        }
    }
    Ok(Bounded { inner: file, left: max })
}

/// A reader that fails once it has given more than `left` bytes.
struct Bounded<R> {
    inner: R,
    left: u64,
}

impl<R: Read> Read for Bounded<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        // At most one byte past the bound, to tell a file that grew from one that ended.
        let room = usize::try_from(self.left.saturating_add(1)).unwrap_or(usize::MAX).min(buf.len());
        let n = self.inner.read(&mut buf[..room])?;
        if n as u64 > self.left {
            return Err(Error::new(ErrorKind::InvalidInput, "grew past its bound while it was read"));
        }
        self.left -= n as u64;
        Ok(n)
    }
}
