//! The one reader of the files the plant is given or finds in a folder (scenes,
//! programmes, sweep files, assessment files, a sweep's unit files and manifest,
//! `sweep.json` for `overlay`, `summary.json` and `trace.csv` for `analyze`, CSV
//! tables): [`shock_table::input`], which opens a regular file only (a device
//! such as `/dev/zero`, a FIFO or a folder is refused at once, before it is
//! read: opening a FIFO would wait for a writer for ever, reading `/dev/zero`
//! would never end) and reads at most a given number of bytes. Issue 31 item 8:
//! `plant assess` on `/dev/zero` grew without bound, on a FIFO it blocked
//! for ever; a sweep's unit files and `overlay`'s `manifest.json` likewise.
//!
//! A test (`no_reader_bypasses_the_bounded_input`) fails on a `read_to_string`,
//! `fs::read`, `File::open` or `Reader::from_path` in `plant/src` outside the
//! reads of the system's own files (`/proc`, `/dev/urandom`).

pub use shock_table::input::{open_bounded, open_regular, read_bytes, read_text, MAX_TOML_BYTES};

/// The most a JSON file the plant reads back may hold (a unit's result, a manifest,
/// `sweep.json`, an assessment's chart): far beyond any it writes.
pub const MAX_JSON_BYTES: u64 = 64 << 20;

/// The most a CSV table the plant reads may hold (`plant bench`'s peer rows, a soak's envelope).
pub const MAX_TABLE_BYTES: u64 = 1 << 30;

#[cfg(test)]
mod tests {
    /// The class of issue 31 item 8: a reader that opens its file itself can block on a FIFO
    /// or read `/dev/zero` for ever. Every read of `plant/src` goes through this module's
    /// functions; a new one that does not fails here, named with its line.
    #[test]
    fn no_reader_bypasses_the_bounded_input() {
        const FORBIDDEN: &[&str] =
            &["read_to_string(", "fs::read(", "File::open(", "Reader::from_path", "read_to_end("];
        let mut found = Vec::new();
        for (path, code) in crate::outfile::tests::sources() {
            for (i, line) in code.lines().enumerate() {
                let line_code = line.split("//").next().unwrap_or_default();
                // The system's own files, and the claim's lock on the output folder itself.
                let system = ["\"/proc", "/dev/urandom", "File::open(dir)"].iter().any(|s| line.contains(s));
                if !system && FORBIDDEN.iter().any(|f| line_code.contains(f)) {
                    found.push(format!("{}:{}: {}", path.display(), i + 1, line.trim()));
                }
            }
        }
        assert!(found.is_empty(), "readers that bypass plant::input:\n{}", found.join("\n"));
    }
}
