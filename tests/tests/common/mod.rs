//! Helpers for the end-to-end tests: building and locating the workspace's
//! binaries, per-test output folders, and small independent readers for the
//! files a run writes (the tests do not reuse the plant's own readers).
// Each test binary uses a subset of these helpers.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

/// The workspace root (the parent of this package's folder).
pub fn workspace_root() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest.parent().expect("the test package lives inside the workspace").to_path_buf()
}

/// A scene file from the workspace's `config/` folder.
pub fn scene(name: &str) -> PathBuf {
    workspace_root().join("config").join(name)
}

/// The committed ROSS file of the AMB machine (saved by ROSS 3.1), as text.
pub fn ross_amb_machine() -> String {
    read_text(&workspace_root().join("plant/physics/tests/fixtures/ross/amb_machine.toml"))
}

/// The shipped flexible scene with its shaft from a ROSS file (`rotor.ross_file`) of text
/// `machine` instead of its `[rotor.shaft]` table: writes `machine.toml` and `scene.toml` into
/// `dir` and returns the scene's path.
pub fn flexible_scene_on_ross_file(dir: &TempDir, machine: &str) -> PathBuf {
    std::fs::write(dir.join("machine.toml"), machine).unwrap();
    let mut table: toml::Table = read_text(&scene("flexible-10g.toml")).parse().unwrap();
    let rotor = table["rotor"].as_table_mut().unwrap();
    rotor.remove("shaft");
    rotor.insert("ross_file".into(), "machine.toml".into());
    let path = dir.join("scene.toml");
    std::fs::write(&path, toml::to_string(&table).unwrap()).unwrap();
    path
}

/// Writes `assess.toml` into `dir`: a small assessment of the study's scene (0.3 s runs in
/// process, a damped `pd_delay`, the vibration and a ladder of one 3 G rung with two members),
/// and returns its path.
#[allow(dead_code)] // not every test binary uses it
pub fn small_assessment(dir: &TempDir) -> PathBuf {
    let path = dir.join("assess.toml");
    let text = format!(
        "scene = {:?}\nset = [\"controller.mode=\\\"sampled\\\"\", \"scene.duration_s=0.3\"]\nparts = [\"vibration\", \"ladder\"]\n\
         [[controller]]\nlabel = \"damped\"\nset = [\"controller.law=\\\"pd_delay\\\"\", \"controller.damping_ratio=0.2\"]\n\
         [ladder]\npeaks_g = [3.0]\nduty_g = 3.0\nmembers = 2\nbatch = 2\nverify = false\n",
        scene("paper-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
    path
}

/// Writes `sweep.toml` into `dir`: an ensemble sweep of the study's scene over the shock's peak
/// (2 points of 2 members, 60 ms runs), and returns its path.
#[allow(dead_code)] // not every test binary uses it
pub fn small_ensemble_sweep(dir: &TempDir) -> PathBuf {
    let path = dir.join("sweep.toml");
    let text = format!(
        "scene = {:?}\nset = [\"scene.duration_s=0.06\", \"shock[0].start_s=0.005\"]\nkey = \"shock[0].peak_g\"\n\
         from = 1.0\nto = 10.0\npoints = 2\n\n[ensemble]\nmembers = 2\nbatch = 2\nagree = 2\nseed = 3\nverify = false\n",
        scene("paper-10g.toml").display().to_string()
    );
    std::fs::write(&path, text).unwrap_or_else(|e| panic!("writing {}: {e}", path.display()));
    path
}

/// The workspace's binaries the tests start, all built by one `cargo build` per test binary
/// (in the profile these tests were built in); maps a binary's name to its executable.
///
/// The paths are taken from Cargo's own `compiler-artifact` messages rather than guessed from
/// the target folder, so `CARGO_TARGET_DIR`, `build.target-dir` in a Cargo config, and
/// `--release` are all honoured without special cases.
///
/// The build selects the whole workspace and names a test target too (`--test docs`, any
/// would do: one fixed, so that a test binary does not compile itself a second time): that
/// resolves the dependencies' features as `cargo test --workspace` (CI's command) did,
/// dev-dependencies included, so after it every binary is already fresh. A narrower
/// selection (`-p plant --bin plant`) resolves other features (criterion's, proptest's,
/// png's are left out) and compiled the plant, nalgebra and iceoryx2 again, once per
/// selection: minutes of a CI run on two cores.
fn workspace_bins() -> &'static std::collections::HashMap<String, PathBuf> {
    &workspace_build().0
}

/// The artifacts of the one `cargo build` ([`workspace_bins`]): the binaries by name, and the
/// libraries' files (`libplant_fmu.so`, `libamb_testbed_controller.a` and `.so`: `--lib` builds
/// the workspace's C and FMI libraries in the same resolution of features) by target name.
#[allow(clippy::type_complexity)]
fn workspace_build(
) -> &'static (std::collections::HashMap<String, PathBuf>, std::collections::HashMap<String, Vec<PathBuf>>) {
    static BUILT: OnceLock<(
        std::collections::HashMap<String, PathBuf>,
        std::collections::HashMap<String, Vec<PathBuf>>,
    )> = OnceLock::new();
    BUILT.get_or_init(|| {
        const BINS: [&str; 6] =
            ["plant", "controller", "rogue-controller", "peak-rss", "shock-table", "controller-fmu"];
        let mut cmd = Command::new(env!("CARGO"));
        cmd.current_dir(workspace_root()).args(["build", "-q", "--message-format=json", "--workspace", "--lib"]);
        for bin in BINS {
            cmd.args(["--bin", bin]);
        }
        cmd.args(["--test", "docs"]);
        if !cfg!(debug_assertions) {
            cmd.arg("--release");
        }
        let out = cmd.output().unwrap_or_else(|e| panic!("cannot start cargo to build {BINS:?}: {e}"));
        assert!(out.status.success(), "{cmd:?} failed ({}):\n{}", out.status, String::from_utf8_lossy(&out.stderr));
        let stdout = String::from_utf8_lossy(&out.stdout);
        let artifacts: Vec<serde_json::Value> = stdout
            .lines()
            .filter_map(|line| serde_json::from_str::<serde_json::Value>(line).ok())
            .filter(|m| m["reason"] == "compiler-artifact")
            .collect();
        let bins: std::collections::HashMap<String, PathBuf> = artifacts
            .iter()
            .filter(|m| m["target"]["kind"][0] == "bin")
            .filter_map(|m| Some((m["target"]["name"].as_str()?.to_string(), PathBuf::from(m["executable"].as_str()?))))
            .collect();
        for bin in BINS {
            assert!(bins.contains_key(bin), "cargo built no executable named {bin}");
        }
        let libs = artifacts
            .iter()
            .filter(|m| m["target"]["kind"].as_array().is_some_and(|k| k.iter().any(|k| k != "bin" && k != "test")))
            .filter_map(|m| {
                let files = m["filenames"].as_array()?.iter().filter_map(|f| f.as_str().map(PathBuf::from)).collect();
                Some((m["target"]["name"].as_str()?.to_string(), files))
            })
            .collect();
        (bins, libs)
    })
}

/// A file of the workspace library `target` (its target name, `plant_fmu`) with extension
/// `ext` (`so`, `a`), built by the one `cargo build` ([`workspace_bins`]).
#[allow(dead_code)] // used by c_api.rs, fmu_plant.rs and flexible.rs only
pub fn workspace_lib(target: &str, ext: &str) -> PathBuf {
    let files = workspace_build().1.get(target).unwrap_or_else(|| panic!("cargo built no library {target}"));
    files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == ext))
        .cloned()
        .unwrap_or_else(|| panic!("no .{ext} of {target} in {files:?}"))
}

/// A binary of the workspace (`controller-fmu`), built by the one `cargo build`.
#[allow(dead_code)] // used by fmu_controller.rs only
pub fn workspace_bin(bin: &str) -> PathBuf {
    build_bin(bin)
}

/// Builds `bin` (a binary of the workspace) and returns the executable's path.
fn build_bin(bin: &str) -> PathBuf {
    workspace_bins().get(bin).cloned().unwrap_or_else(|| panic!("cargo built no executable named {bin}"))
}

/// The `plant` binary, built once per test binary.
pub fn plant_bin() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| build_bin("plant"))
}

/// The `controller` binary (the co-simulation's controller process), built
/// once per test binary; `plant` finds it next to itself.
#[allow(dead_code)] // used by cosim.rs only
pub fn controller_bin() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| build_bin("controller"))
}

/// The `rogue-controller` test binary (a controller that misbehaves on purpose, see
/// `tests/bin/rogue_controller.rs`), built once per test binary.
pub fn rogue_bin() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| build_bin("rogue-controller"))
}

/// The `shock-table` binary, built once per test binary.
pub fn shock_table_bin() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| build_bin("shock-table"))
}

/// Overrides that keep a paper scene short: 50 ms with the shock from 10 ms,
/// no plots.
pub const SHORT: &[&str] = &["scene.duration_s=0.05", "shock[0].start_s=0.01", "output.plots=false"];

/// A `plant run <scene> --out <out> --set …` command (not started).
pub fn plant_run(scene: &Path, out: &Path, sets: &[&str]) -> Command {
    let mut cmd = Command::new(plant_bin());
    cmd.arg("run").arg(scene).arg("--out").arg(out);
    for s in sets {
        cmd.args(["--set", s]);
    }
    cmd
}

/// `plant sweep FILE --out OUT EXTRA…` (not started).
pub fn plant_sweep(file: &Path, out: &Path, extra: &[&str]) -> Command {
    let mut cmd = Command::new(plant_bin());
    cmd.arg("sweep").arg(file).arg("--out").arg(out).args(extra);
    cmd
}

/// A text file's contents; the test fails naming the file if it cannot be read.
pub fn read_text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

/// The limit of a command run by [`output`]: far above any test's command in a debug build on
/// a loaded 2-core machine, so that only a hang reaches it.
pub const DEFAULT_LIMIT: std::time::Duration = std::time::Duration::from_secs(300);

/// Runs a command to completion within [`DEFAULT_LIMIT`] (a hang fails the test); prefer
/// [`output_within`] with a limit of the command's own.
pub fn output(cmd: &mut Command) -> Output {
    output_within(cmd, DEFAULT_LIMIT)
}

/// A child process whose stderr lines arrive on a channel, with bounded waits; killed on
/// drop (a test that fails or hangs leaves no process behind).
pub struct Proc {
    child: std::process::Child,
    lines: std::sync::mpsc::Receiver<String>,
    log: Vec<String>,
}

impl Proc {
    /// Starts `cmd` (stdout to /dev/null, stderr read line by line).
    pub fn spawn(cmd: &mut Command) -> Self {
        use std::io::BufRead;
        let mut child = cmd
            .stdin(std::process::Stdio::null())
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap_or_else(|e| panic!("{cmd:?}: {e}"));
        let pipe = child.stderr.take().expect("piped stderr");
        let (tx, lines) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(pipe).lines().map_while(Result::ok) {
                if tx.send(line).is_err() {
                    break;
                }
            }
        });
        Self { child, lines, log: Vec::new() }
    }

    /// Process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// True while the process has not exited.
    pub fn running(&mut self) -> bool {
        self.child.try_wait().expect("waiting for the child").is_none()
    }

    /// Waits (up to 60 s) for a stderr line containing `needle`.
    pub fn wait_line(&mut self, needle: &str) -> String {
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
        loop {
            match self.lines.recv_timeout(deadline.saturating_duration_since(std::time::Instant::now())) {
                Ok(line) => {
                    self.log.push(line.clone());
                    if line.contains(needle) {
                        return line;
                    }
                }
                Err(_) => panic!("no line with {needle:?} within 60 s; stderr so far:\n{}", self.log.join("\n")),
            }
        }
    }

    /// Waits (up to `limit`) for the exit; returns the exit code and all of stderr.
    pub fn finish_within(mut self, limit: std::time::Duration) -> (Option<i32>, String) {
        let deadline = std::time::Instant::now() + limit;
        let status = loop {
            if let Some(s) = self.child.try_wait().expect("waiting for the child") {
                break s;
            }
            if std::time::Instant::now() > deadline {
                let _ = self.child.kill();
                let _ = self.child.wait();
                while let Ok(line) = self.lines.try_recv() {
                    self.log.push(line);
                }
                panic!("process did not exit within {limit:?} (killed):\n{}", self.log.join("\n"));
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        };
        // The reader thread ends at EOF.
        let end = std::time::Instant::now() + std::time::Duration::from_secs(5);
        while let Ok(line) = self.lines.recv_timeout(end.saturating_duration_since(std::time::Instant::now())) {
            self.log.push(line);
        }
        (status.code(), self.log.join("\n"))
    }

    /// Waits (up to 60 s) for the exit; returns the exit code and all of stderr.
    pub fn finish(self) -> (Option<i32>, String) {
        self.finish_within(std::time::Duration::from_secs(60))
    }

    /// Sends a signal.
    #[cfg(unix)]
    pub fn signal(&self, signal: libc::c_int) {
        let pid = libc::pid_t::try_from(self.child.id()).expect("pid");
        // SAFETY: kill(2) has no memory-safety preconditions; the child is not reaped yet.
        assert_eq!(unsafe { libc::kill(pid, signal) }, 0, "kill({pid}, {signal})");
    }
}

/// Waits (up to 60 s) until process `pid` catches `signal` (its handler is installed, from
/// `/proc/PID/status`), so that a test signals it at a moment its handling is defined; panics
/// if the process ends first.
#[cfg(target_os = "linux")]
pub fn wait_for_handler(pid: u32, signal: i32) {
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    let bit = 1u64 << (signal - 1);
    loop {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status"))
            .unwrap_or_else(|e| panic!("process {pid} ended before it caught signal {signal}: {e}"));
        let caught = status
            .lines()
            .find_map(|l| l.strip_prefix("SigCgt:"))
            .and_then(|m| u64::from_str_radix(m.trim(), 16).ok())
            .unwrap_or(0);
        let state = status.lines().find_map(|l| l.strip_prefix("State:")).unwrap_or("").trim().to_string();
        assert!(!state.starts_with('Z'), "process {pid} ended before it caught signal {signal}");
        if caught & bit != 0 {
            return;
        }
        assert!(std::time::Instant::now() < deadline, "process {pid} never caught signal {signal}");
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Runs a command to completion within `limit`, killing it (and failing the test) if it takes
/// longer: a hang fails the test instead of stalling the suite.
pub fn output_within(cmd: &mut Command, limit: std::time::Duration) -> Output {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    let drain = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            let _ = pipe.read_to_end(&mut bytes);
            bytes
        })
    };
    let out = drain(Box::new(child.stdout.take().expect("piped stdout")));
    let err = drain(Box::new(child.stderr.take().expect("piped stderr")));
    let deadline = std::time::Instant::now() + limit;
    let status = loop {
        if let Some(status) = child.try_wait().expect("waiting for the child") {
            break status;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            let err = String::from_utf8_lossy(&err.join().unwrap_or_default()).into_owned();
            panic!("{cmd:?} did not finish within {limit:?} (killed); stderr:\n{err}");
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    };
    Output { status, stdout: out.join().unwrap_or_default(), stderr: err.join().unwrap_or_default() }
}

/// Standard error as text.
pub fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Asserts the exit code, showing standard error when it differs.
pub fn assert_exit(out: &Output, code: i32) {
    assert_eq!(out.status.code(), Some(code), "exit status {}; stderr:\n{}", out.status, stderr(out));
}

/// A fresh folder under the system temp folder, unique per test and
/// process. Removed on drop unless the test is failing (kept to inspect).
pub struct TempDir(PathBuf);

impl TempDir {
    /// Creates `<tmp>/testbed-tests-<name>-<pid>`, emptying any leftover.
    pub fn new(name: &str) -> Self {
        let path = std::env::temp_dir().join(format!("testbed-tests-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&path);
        std::fs::create_dir_all(&path).unwrap_or_else(|e| panic!("creating {}: {e}", path.display()));
        Self(path)
    }

    /// A path inside the folder.
    pub fn join(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        if std::thread::panicking() {
            eprintln!("keeping {} for inspection", self.0.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}

/// A numeric CSV file with a header row.
pub struct Csv {
    /// Column names.
    pub header: Vec<String>,
    /// Rows, each as long as the header.
    pub rows: Vec<Vec<f64>>,
}

impl Csv {
    /// Reads a CSV file of numbers; panics naming the line on malformed data.
    pub fn read(path: &Path) -> Self {
        let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
        let mut lines = text.lines();
        let header: Vec<String> = lines
            .next()
            .unwrap_or_else(|| panic!("{} is empty", path.display()))
            .split(',')
            .map(str::to_string)
            .collect();
        let rows = lines
            .enumerate()
            .map(|(n, line)| {
                let row: Vec<f64> = line
                    .split(',')
                    .map(|v| v.parse().unwrap_or_else(|e| panic!("{} line {}: {v:?}: {e}", path.display(), n + 2)))
                    .collect();
                assert_eq!(row.len(), header.len(), "{} line {}: wrong number of fields", path.display(), n + 2);
                row
            })
            .collect();
        Self { header, rows }
    }

    /// One column by name.
    pub fn column(&self, name: &str) -> Vec<f64> {
        let i = self
            .header
            .iter()
            .position(|h| h == name)
            .unwrap_or_else(|| panic!("no column {name} in {:?}", self.header));
        self.rows.iter().map(|r| r[i]).collect()
    }
}

/// Reads a JSON file.
pub fn read_json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A number field of a JSON object.
pub fn num(v: &serde_json::Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("`{key}` is not a number in {v:#}"))
}

/// The `peak-rss` helper (`tests/bin/peak_rss.rs`), built once per test binary.
pub fn peak_rss_bin() -> &'static Path {
    static BIN: OnceLock<PathBuf> = OnceLock::new();
    BIN.get_or_init(|| build_bin("peak-rss"))
}

/// Runs a command to completion within `limit` (killed past it, failing the test) and
/// returns its exit code and its peak resident memory (KiB, `ru_maxrss` of that command
/// alone). The command is started by the small `peak-rss` helper, not by this test process:
/// a child this process started would carry this process's own memory peak (reads of large
/// traces, other tests' threads) into its `ru_maxrss` (see `tests/bin/peak_rss.rs`).
#[cfg(target_os = "linux")]
pub fn peak_rss_within(cmd: &mut Command, limit: std::time::Duration) -> (Option<i32>, u64) {
    let mut helper = Command::new(peak_rss_bin());
    helper.arg(cmd.get_program()).args(cmd.get_args());
    for (key, value) in cmd.get_envs() {
        match value {
            Some(v) => helper.env(key, v),
            None => helper.env_remove(key),
        };
    }
    if let Some(dir) = cmd.get_current_dir() {
        helper.current_dir(dir);
    }
    let out = output_within(&mut helper, limit);
    assert_exit(&out, 0);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    let mut fields = text.split_whitespace();
    let code = fields.next().and_then(|c| c.parse().ok());
    let kib = fields.next().and_then(|k| k.parse().ok()).unwrap_or_else(|| panic!("peak-rss printed {text:?}"));
    (code, kib)
}

/// A decoded PNG, as RGB pixels.
pub struct Png {
    /// Width (px).
    pub width: usize,
    /// Height (px).
    pub height: usize,
    /// Pixels, row by row from the top.
    pub rgb: Vec<[u8; 3]>,
}

impl Png {
    /// Decodes a PNG file; panics naming the file if it is not one.
    pub fn read(path: &Path) -> Self {
        let file = std::fs::File::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let mut decoder = png::Decoder::new(std::io::BufReader::new(file));
        decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
        let mut reader = decoder.read_info().unwrap_or_else(|e| panic!("{} is not a PNG: {e}", path.display()));
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let channels = info.color_type.samples();
        let rgb = buf[..info.buffer_size()].chunks(channels).map(|p| [p[0], p[1], p[2]]).collect();
        Self { width: info.width as usize, height: info.height as usize, rgb }
    }

    /// Pixels of exactly `rgb` in the chart's plotting region (right of the y labels,
    /// below the title, above the x labels).
    pub fn count_in_plot(&self, rgb: [u8; 3]) -> usize {
        let mut n = 0;
        for y in 60..self.height.saturating_sub(80) {
            for x in 130..self.width.saturating_sub(30) {
                n += usize::from(self.rgb[y * self.width + x] == rgb);
            }
        }
        n
    }
}

/// The first series colour of the charts (matplotlib's tab10 blue).
pub const SERIES_BLUE: [u8; 3] = [0x1f, 0x77, 0xb4];

/// The FMPy release the FMU tests install.
pub const FMPY: &str = "0.3.32";
/// The pythonfmu release the FMU tests install (builds a Python controller FMU).
pub const PYTHONFMU: &str = "0.7.0";

/// `target/fmpy-venv` with FMPy, pythonfmu and the Python kit (tests/tests/fmu_plant.rs,
/// fmu_controller.rs): made if absent or stale, under a file lock.
pub fn fmpy_venv() -> &'static Path {
    static VENV: OnceLock<PathBuf> = OnceLock::new();
    VENV.get_or_init(|| {
        let target = Path::new(env!("CARGO_TARGET_TMPDIR")).parent().expect("CARGO_TARGET_TMPDIR is target/tmp");
        let dir = target.join("fmpy-venv");
        let kit = workspace_root().join("python");
        let pyproject = std::fs::read_to_string(kit.join("pyproject.toml")).expect("python/pyproject.toml");
        let stamp = format!("fmpy {FMPY}\npythonfmu {PYTHONFMU}\nkit: {}\n{pyproject}", kit.display());
        let lock = std::fs::File::create(target.join("fmpy-venv.lock")).expect("venv lock file");
        lock.lock().expect("locking the venv");
        let stamp_file = dir.join("amb-testbed.stamp");
        if dir.join("bin/python").exists() && std::fs::read_to_string(&stamp_file).ok().as_deref() == Some(&stamp) {
            return dir;
        }
        let _ = std::fs::remove_dir_all(&dir);
        let venv =
            output_within(Command::new("python3").arg("-m").arg("venv").arg(&dir), std::time::Duration::from_secs(120));
        assert_exit(&venv, 0);
        let install = output_within(
            Command::new(dir.join("bin/python"))
                .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check"])
                .arg(format!("fmpy=={FMPY}"))
                .arg(format!("pythonfmu=={PYTHONFMU}"))
                .arg("--editable")
                .arg(&kit),
            std::time::Duration::from_secs(600),
        );
        assert_exit(&install, 0);
        std::fs::write(&stamp_file, stamp).expect("venv stamp");
        dir
    })
}

/// `plant run SCENE` with `set` exits 2 within 30 s (the refusal comes while the scene loads),
/// names every needle, writes nothing, never panics.
#[allow(dead_code)] // used by bounds.rs, two_plane.rs and flexible.rs only
pub fn refused(name: &str, scene_file: &Path, set: &[&str], needles: &[&str]) {
    let dir = TempDir::new(name);
    let out = dir.join("run");
    let run = output_within(&mut plant_run(scene_file, &out, set), std::time::Duration::from_secs(30));
    let err = stderr(&run);
    assert_exit(&run, 2);
    assert!(!err.contains("panicked"), "{set:?}:\n{err}");
    for n in needles {
        assert!(err.contains(n), "{set:?}: no {n:?} in:\n{err}");
    }
    assert!(!out.exists(), "{set:?}: bad input created {}", out.display());
}

/// A CSV file of text fields with a header row (`compare.rs`, `flexible.rs`): fields read by
/// column name, as text or as numbers.
pub struct Table {
    /// The header's column names.
    pub header: Vec<String>,
    /// Each row's fields.
    pub rows: Vec<Vec<String>>,
}

impl Table {
    /// Reads `path`; panics naming it if it cannot be read or is empty.
    pub fn read(path: &Path) -> Self {
        let text = read_text(path);
        let mut lines = text.lines().map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>());
        let header = lines.next().unwrap_or_else(|| panic!("{} is empty", path.display()));
        Self { header, rows: lines.collect() }
    }

    /// Row `row`'s field in column `name`.
    pub fn text(&self, row: usize, name: &str) -> &str {
        let i = self.header.iter().position(|h| h == name).unwrap_or_else(|| panic!("no column {name}"));
        &self.rows[row][i]
    }

    /// The same, as a number.
    pub fn num(&self, row: usize, name: &str) -> f64 {
        self.text(row, name).parse().unwrap_or_else(|e| panic!("{name} of row {row}: {e}"))
    }
}

/// Puts an executable at `to`, a copy of `from` with mode 755, written by a child process
/// (`install`), never through a file descriptor of this test process. A test binary runs
/// its tests on threads, and a sibling test's fork inherits every descriptor open at that
/// moment: an executable this process held open for writing would then fail to start with
/// "Text file busy" (ETXTBSY) until that child execs, as `plant fmu`'s test did in CI.
pub fn install_executable(from: &Path, to: &Path) {
    let status = Command::new("install")
        .args(["-m", "755"])
        .arg(from)
        .arg(to)
        .status()
        .unwrap_or_else(|e| panic!("install {} {}: {e}", from.display(), to.display()));
    assert!(status.success(), "install {} {}: {status}", from.display(), to.display());
}

/// Writes a script `text` as the executable `to` (mode 755), by way of
/// [`install_executable`]: the text goes to a plain file first, which is never executed.
pub fn write_script(to: &Path, text: &str) {
    let draft = to.with_extension("draft");
    std::fs::write(&draft, text).unwrap_or_else(|e| panic!("{}: {e}", draft.display()));
    install_executable(&draft, to);
    std::fs::remove_file(&draft).unwrap_or_else(|e| panic!("{}: {e}", draft.display()));
}

/// Writes into `out` (made if missing) files named as an earlier command of the same kind
/// would have left them (`earlier`, names this run will not write) and a file of the user's,
/// `notes.txt`; [`assert_only_this_runs_outputs`] checks the folder afterwards.
pub fn seed_earlier_outputs(out: &Path, earlier: &[&str]) {
    std::fs::create_dir_all(out).expect("the output folder");
    for name in earlier.iter().chain(&["notes.txt"]) {
        std::fs::write(out.join(name), b"an earlier run's").expect("seed");
    }
}

/// After a command ran into a folder seeded by [`seed_earlier_outputs`]: none of `earlier` is
/// left, the user's `notes.txt` is, and every other file is one the command says it writes
/// (`files`: names, each with at most one `*`), so the list it clears by stays that of its
/// writers.
pub fn assert_only_this_runs_outputs(out: &Path, earlier: &[&str], files: &[&str]) {
    let matches = |name: &str| {
        files.iter().any(|f| match f.split_once('*') {
            None => name == *f,
            Some((head, tail)) => {
                name.len() >= head.len() + tail.len() && name.starts_with(head) && name.ends_with(tail)
            }
        })
    };
    let mut left: Vec<String> = std::fs::read_dir(out)
        .expect("the output folder")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .collect();
    left.sort();
    for name in earlier {
        assert!(!left.iter().any(|l| l == name), "{name}: an earlier run's file left in {}", out.display());
    }
    assert!(left.iter().any(|l| l == "notes.txt"), "the user's notes.txt was removed");
    for name in left.iter().filter(|l| *l != "notes.txt") {
        assert!(matches(name), "{name}: written but not in the command's list of files ({files:?})");
    }
}
