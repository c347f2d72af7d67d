//! The scene's `controller.fmu` key ([`Spec`]): the FMU's path, the mapping table, the
//! model-exchange integrator and the host's step watchdog; read from the scene (a path, or a
//! table), and passed to the `controller-fmu` process as command-line arguments.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The fixed-step method a model-exchange FMU is integrated with over each controller period.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Explicit Euler.
    Euler,
    /// The classical Runge–Kutta method of order 4.
    Rk4,
}

impl Solver {
    /// Its name in the scene.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Euler => "euler",
            Solver::Rk4 => "rk4",
        }
    }

    /// From its name in the scene.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "euler" => Some(Solver::Euler),
            "rk4" => Some(Solver::Rk4),
            _ => None,
        }
    }
}

/// The default watchdog on one tick's FMI calls (ms).
pub const DEFAULT_STEP_TIMEOUT_MS: f64 = 1000.0;

/// `controller.fmu`: which FMU, how its variables meet the wire's signals, how a
/// model-exchange FMU is integrated.
#[derive(Clone, Debug, PartialEq)]
pub struct Spec {
    /// The `.fmu` file.
    pub path: PathBuf,
    /// Wire signal → FMU variable name (signals not listed follow the naming convention).
    pub map: BTreeMap<String, String>,
    /// Model exchange: the fixed-step method.
    pub solver: Solver,
    /// Model exchange: steps per controller period.
    pub substeps: u32,
    /// The controller process ends (exit 3) when one tick's FMI calls take longer (ms).
    pub step_timeout_ms: f64,
}

impl Spec {
    /// A spec of `path` with the defaults (the naming convention, RK4 with one step per
    /// period, a 1 s watchdog).
    pub fn new(path: impl Into<PathBuf>) -> Self {
        Self {
            path: path.into(),
            map: BTreeMap::new(),
            solver: Solver::Rk4,
            substeps: 1,
            step_timeout_ms: DEFAULT_STEP_TIMEOUT_MS,
        }
    }

    /// Reads `controller.fmu` (a path, or a table `path`, `map`, `solver`, `substeps`,
    /// `step_timeout_ms`), a relative path taken from `base_dir` (the scene file's folder).
    /// Errors name the key, the value and what is wrong.
    pub fn from_toml(value: &toml::Value, base_dir: &Path) -> Result<Self, String> {
        const KEYS: &str = "path, map, solver, substeps, step_timeout_ms";
        let path_of = |v: &toml::Value, key: &str| -> Result<PathBuf, String> {
            match v.as_str() {
                Some(s) if !s.is_empty() => {
                    let p = Path::new(s);
                    Ok(if p.is_relative() {
                        std::path::absolute(base_dir.join(p)).unwrap_or(base_dir.join(p))
                    } else {
                        p.into()
                    })
                }
                _ => Err(format!("{key} = {v}: must be the path of an .fmu file (a string)")),
            }
        };
        let table = match value {
            toml::Value::String(_) => return Ok(Self::new(path_of(value, "controller.fmu")?)),
            toml::Value::Table(t) => t,
            other => {
                return Err(format!(
                    "controller.fmu = {other}: must be the path of an .fmu file, or a table with {KEYS}"
                ))
            }
        };
        let path = table.get("path").ok_or_else(|| "controller.fmu.path: missing (the .fmu file)".to_string())?;
        let mut spec = Self::new(path_of(path, "controller.fmu.path")?);
        for (key, v) in table {
            match key.as_str() {
                "path" => {}
                "map" => {
                    let map = v.as_table().ok_or_else(|| {
                        format!("controller.fmu.map = {v}: must be a table signal = \"FMU variable\"")
                    })?;
                    for (signal, var) in map {
                        let var = var.as_str().filter(|s| !s.is_empty()).ok_or_else(|| {
                            format!("controller.fmu.map.{signal} = {var}: must be an FMU variable's name (a string)")
                        })?;
                        // Two signals on one variable: one of them would be lost silently.
                        if let Some((other, _)) = spec.map.iter().find(|(_, v)| v.as_str() == var) {
                            return Err(format!(
                                "controller.fmu.map.{signal} = \"{var}\": controller.fmu.map.{other} maps that variable \
                                 already; each FMU variable carries one signal"
                            ));
                        }
                        spec.map.insert(signal.clone(), var.to_string());
                    }
                }
                "solver" => {
                    spec.solver = v.as_str().and_then(Solver::parse).ok_or_else(|| {
                        format!("controller.fmu.solver = {v}: must be \"euler\" or \"rk4\" (model exchange)")
                    })?;
                }
                "substeps" => {
                    spec.substeps =
                        v.as_integer().filter(|n| (1..=100_000).contains(n)).ok_or_else(|| {
                            format!("controller.fmu.substeps = {v}: must be an integer from 1 to 100000")
                        })? as u32;
                }
                "step_timeout_ms" => {
                    let ms = v.as_float().or_else(|| v.as_integer().map(|i| i as f64)).unwrap_or(f64::NAN);
                    if !(ms.is_finite() && ms > 0.0 && ms <= 3.6e6) {
                        return Err(format!(
                            "controller.fmu.step_timeout_ms = {v} ms: must be a number > 0 and <= 3600000"
                        ));
                    }
                    spec.step_timeout_ms = ms;
                }
                other => return Err(format!("controller.fmu.{other}: unknown key (controller.fmu has {KEYS})")),
            }
        }
        Ok(spec)
    }

    /// The command-line arguments of `controller-fmu` that carry this spec.
    pub fn to_args(&self) -> Vec<String> {
        let mut args = vec!["--fmu".to_string(), self.path.display().to_string()];
        for (signal, var) in &self.map {
            args.push("--map".into());
            args.push(format!("{signal}={var}"));
        }
        args.extend([
            "--solver".into(),
            self.solver.name().into(),
            "--substeps".into(),
            self.substeps.to_string(),
            "--step-timeout-ms".into(),
            self.step_timeout_ms.to_string(),
        ]);
        args
    }

    /// Takes this spec's arguments ([`Spec::to_args`]) out of a command line; the rest is
    /// returned in order. `Ok(None)`: no `--fmu`.
    pub fn take_args(argv: Vec<String>) -> Result<(Option<Self>, Vec<String>), String> {
        let mut rest = Vec::new();
        let mut spec: Option<Spec> = None;
        let mut pending: Vec<(String, String)> = Vec::new();
        let mut it = argv.into_iter();
        while let Some(a) = it.next() {
            let (flag, inline) = match a.split_once('=') {
                Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
                _ => (a.clone(), None),
            };
            if !matches!(flag.as_str(), "--fmu" | "--map" | "--solver" | "--substeps" | "--step-timeout-ms") {
                rest.push(a);
                continue;
            }
            let value = match inline {
                Some(v) => v,
                None => it.next().ok_or_else(|| format!("{flag}: missing its value"))?,
            };
            pending.push((flag, value));
        }
        for (flag, value) in pending {
            let s = spec.get_or_insert_with(|| Spec::new(""));
            match flag.as_str() {
                "--fmu" => s.path = PathBuf::from(value),
                "--map" => {
                    let (signal, var) = value
                        .split_once('=')
                        .filter(|(a, b)| !a.is_empty() && !b.is_empty())
                        .ok_or_else(|| format!("--map {value}: must be SIGNAL=VARIABLE"))?;
                    if let Some(before) = s.map.get(signal) {
                        return Err(format!(
                            "--map {value}: {signal} is mapped already (to {before}); map each signal once"
                        ));
                    }
                    if let Some((other, _)) = s.map.iter().find(|(_, v)| v.as_str() == var) {
                        return Err(format!(
                            "--map {value}: {var} carries {other} already; each FMU variable carries one signal"
                        ));
                    }
                    s.map.insert(signal.to_string(), var.to_string());
                }
                "--solver" => {
                    s.solver = Solver::parse(&value).ok_or_else(|| format!("--solver {value}: must be euler or rk4"))?
                }
                "--substeps" => {
                    s.substeps = value
                        .parse::<u32>()
                        .ok()
                        .filter(|n| (1..=100_000).contains(n))
                        .ok_or_else(|| format!("--substeps {value}: must be an integer from 1 to 100000"))?
                }
                _ => {
                    s.step_timeout_ms = value
                        .parse::<f64>()
                        .ok()
                        .filter(|ms| ms.is_finite() && *ms > 0.0)
                        .ok_or_else(|| format!("--step-timeout-ms {value}: must be a number > 0"))?
                }
            }
        }
        if let Some(s) = &spec {
            if s.path.as_os_str().is_empty() {
                return Err("--fmu PATH is missing (the .fmu file to serve)".into());
            }
        }
        Ok((spec, rest))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_or_a_table_and_back_through_the_command_line() {
        let base = Path::new("/scenes");
        let s = Spec::from_toml(&toml::Value::String("ctl.fmu".into()), base).unwrap();
        assert_eq!(s, Spec::new("/scenes/ctl.fmu"));
        let t: toml::Table = toml::from_str(
            "path = \"/x/me.fmu\"\nsolver = \"euler\"\nsubsteps = 4\nstep_timeout_ms = 50\n[map]\ncurrent_x = \"u[1]\"",
        )
        .unwrap();
        let s = Spec::from_toml(&toml::Value::Table(t), base).unwrap();
        assert_eq!((s.solver, s.substeps, s.step_timeout_ms), (Solver::Euler, 4, 50.0));
        assert_eq!(s.map.get("current_x").map(String::as_str), Some("u[1]"));
        let mut argv = vec!["controller-fmu".to_string()];
        argv.extend(s.to_args());
        argv.extend(["--run-id".into(), "r".into()]);
        let (back, rest) = Spec::take_args(argv).unwrap();
        assert_eq!(back, Some(s));
        assert_eq!(rest, ["controller-fmu", "--run-id", "r"]);
        let bad = |text: &str| Spec::from_toml(&toml::Value::Table(toml::from_str(text).unwrap()), base).unwrap_err();
        assert!(bad("path = \"a.fmu\"\nsolver = \"dopri\"").contains("controller.fmu.solver = \"dopri\""));
        assert!(bad("path = \"a.fmu\"\nsubsteps = 0").contains("controller.fmu.substeps = 0"));
        assert!(bad("path = \"a.fmu\"\nbogus = 1").contains("controller.fmu.bogus: unknown key"));
        assert!(bad("solver = \"rk4\"").contains("controller.fmu.path: missing"));
        assert!(Spec::take_args(vec!["--map".into(), "x".into()]).unwrap_err().contains("SIGNAL=VARIABLE"));
        // A mapping that would lose a signal silently: two signals on one variable, one signal twice.
        let e = bad("path = \"a.fmu\"\n[map]\ncurrent_x = \"u\"\ncurrent_y = \"u\"");
        assert!(
            e.contains("controller.fmu.map.current_y = \"u\": controller.fmu.map.current_x maps that variable"),
            "{e}"
        );
        let args = |m: [&str; 2]| {
            let mut a = vec!["x".to_string(), "--fmu".into(), "a.fmu".into()];
            for v in m {
                a.extend(["--map".to_string(), v.to_string()]);
            }
            Spec::take_args(a).unwrap_err()
        };
        assert!(args(["current_x=u", "current_x=v"]).contains("current_x is mapped already (to u)"));
        assert!(args(["current_x=u", "current_y=u"]).contains("u carries current_x already"));
    }
}
