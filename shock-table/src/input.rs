//! Reading a file a user names, without trusting it: a regular file only (a
//! device such as `/dev/zero`, a FIFO or a folder is refused at once, before
//! it is read: opening a FIFO would wait for a writer, reading `/dev/zero`
//! would never end), and at most a given number of bytes. The plant's scene,
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
//! # std::fs::remove_dir_all(&dir).unwrap();
//! ```

use std::fs::File;
use std::io::{Error, ErrorKind, Read};
use std::path::Path;

/// The most a TOML input file (scene, programme, sweep) may hold: far beyond any real one.
pub const MAX_TOML_BYTES: u64 = 16 << 20;

/// Opens `path` for reading if it names a regular file (links followed); anything else is
/// refused with an `InvalidInput` error before it is opened.
pub fn open_regular(path: &Path) -> std::io::Result<File> {
    let refuse = || Error::new(ErrorKind::InvalidInput, "not a regular file (a device, a FIFO or a folder)");
    // Looked up before opening: opening a FIFO would wait for a writer.
    if !std::fs::metadata(path)?.is_file() {
        return Err(refuse());
    }
    let file = File::open(path)?;
    // And what was opened (the path may have been replaced in between).
    if !file.metadata()?.is_file() {
        return Err(refuse());
    }
    Ok(file)
}

/// Reads a regular file of at most `max` bytes as UTF-8 text.
pub fn read_text(path: &Path, max: u64) -> std::io::Result<String> {
    let file = open_regular(path)?;
    let too_long = |len: u64| {
        Error::new(ErrorKind::InvalidInput, format!("{len} bytes: an input file may have at most {max} bytes"))
    };
    let len = file.metadata()?.len();
    if len > max {
        return Err(too_long(len));
    }
    // At most one byte past the bound, in case the file grows while it is read.
    let mut text = String::new();
    file.take(max + 1).read_to_string(&mut text)?;
    if text.len() as u64 > max {
        return Err(Error::new(ErrorKind::InvalidInput, format!("grew past {max} bytes while it was read")));
    }
    Ok(text)
}
