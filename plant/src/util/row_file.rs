//! A CSV file that holds its header and whole rows between its writes, so that
//! a process killed between them (SIGKILL included) leaves a file every reader
//! can read to its last row: `trace.csv` and the soak's `soak.csv`,
//! `envelope.csv` and `rss.csv`.
//!
//! Hand-written around the `csv` crate because neither it nor `BufWriter`
//! does this: both flush at a byte count and cut a row in two.

use std::fs::File;
use std::io::Write;
use std::path::Path;

/// Pending bytes past which a [`RowFile`] writes its rows out.
const FLUSH_BYTES: usize = 64 * 1024;

/// A CSV file that only ever holds its header and whole rows: the `csv`
/// crate formats each record into memory, and [`RowFile::flush`] hands the
/// pending rows to the file in one `write` of whole rows. A SIGKILL between two
/// writes leaves whole rows; one that lands during a write can cut it at a page
/// boundary (the kernel stops a write at a fatal signal), leaving a last line
/// without its line end. The header is written at creation.
pub struct RowFile {
    file: File,
    csv: csv::Writer<Pending>,
    pending: Pending,
}

/// The rows the `csv` writer has formatted, not yet in the file. Shared with the writer
/// through an `Arc<Mutex>` (never contended: one thread has both) so that a `RowFile` can
/// be handed to another thread ([`crate::offload`]).
#[derive(Clone, Default)]
struct Pending(std::sync::Arc<std::sync::Mutex<Vec<u8>>>);

impl Pending {
    fn bytes(&self) -> std::sync::MutexGuard<'_, Vec<u8>> {
        // A panic while the lock was held left whole rows or none: the bytes are still good.
        self.0.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl Write for Pending {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.bytes().extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

impl RowFile {
    /// Creates (truncates) `path` with its header row.
    pub fn create(path: &Path, header: &[&str]) -> std::io::Result<Self> {
        let file = crate::outfile::create(path)?;
        let pending = Pending::default();
        let csv = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(pending.clone());
        let mut f = Self { file, csv, pending };
        f.csv.write_record(header)?;
        f.flush()?;
        Ok(f)
    }

    /// Opens `path` again to append to it ([`crate::outfile::reopen_at`]): its first `len`
    /// bytes, which must begin with `header`, are kept; what came after them is cut.
    pub fn reopen(path: &Path, header: &[&str], len: u64) -> std::io::Result<Self> {
        use std::io::{Read, Seek, SeekFrom};
        let mut file = crate::outfile::reopen_at(path, len)?;
        let expected = format!("{}\n", header.join(","));
        let mut found = vec![0; expected.len().min(len as usize)];
        file.seek(SeekFrom::Start(0))?;
        file.read_exact(&mut found)?;
        if found != expected.as_bytes() {
            let message = format!("{}: its header is not `{}`", path.display(), header.join(","));
            return Err(std::io::Error::new(std::io::ErrorKind::InvalidData, message));
        }
        file.seek(SeekFrom::End(0))?;
        let pending = Pending::default();
        let csv = csv::WriterBuilder::new().terminator(csv::Terminator::Any(b'\n')).from_writer(pending.clone());
        Ok(Self { file, csv, pending })
    }

    /// The bytes in the file once the pending rows are written out.
    pub fn written(&mut self) -> std::io::Result<u64> {
        self.flush()?;
        Ok(self.file.metadata()?.len())
    }

    /// Appends a row (fields already formatted); written out past 64 KiB pending.
    pub fn row<I, T>(&mut self, fields: I) -> std::io::Result<()>
    where
        I: IntoIterator<Item = T>,
        T: AsRef<[u8]>,
    {
        self.csv.write_record(fields)?;
        // Out of the csv writer's own buffer after each record, so that `pending` holds
        // whole rows only.
        self.csv.flush()?;
        if self.pending.bytes().len() >= FLUSH_BYTES {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the pending whole rows to the file.
    pub fn flush(&mut self) -> std::io::Result<()> {
        self.csv.flush()?;
        let mut pending = self.pending.bytes();
        if !pending.is_empty() {
            self.file.write_all(&pending)?;
            pending.clear();
        }
        Ok(())
    }
}
