//! The `[ensemble]` table: how many members, the seed, what is drawn per member, when a point
//! stops adding members, and the integrator settings of members and of their verification.
//!
//! ```toml
//! [ensemble]
//! members = 64            # most members per point (1 … 10 000)
//! seed = 1                # integer ≥ 0
//! batch = 16              # members per round (default: members, one round)
//! target_width = 0.2      # a point stops once its 95 % interval is at most this wide
//! agree = 16              # … or once at least this many members all agree
//! angle = true            # the rotor's angle at the shock's arrival, uniform over a turn
//! direction_deg = 10      # each shock's direction ± 10° (uniform)
//! peak_rel = 0.05         # each shock's peak × (1 ± 0.05) (uniform)
//! eccentricity_rel = 0.1  # rotor.eccentricity_um × (1 ± 0.1) (uniform)
//! integrator = "fast"     # members' setting: "fast" (default) or "scene"
//! verify = true           # re-run members close to a decision at the reference setting
//! verify_rtol = 1e-10     # DOP853 tolerance of the reference setting
//! verify_late = 0.75      # "late": last contact after this share of shock → steady window
//! verify_rebound = 0.5    # "intermittent": a rebound in contact for less than this share
//!
//! [[ensemble.vary]]       # any scene key over a range (repeatable)
//! key = "contact.friction_dynamic"
//! from = 0.08
//! to = 0.12
//! distribution = "uniform"   # or "log_uniform"
//! ```
//!
//! Draws are the same on every machine and independent of sharding, threads and order: the
//! value of variable `v` for member `j` comes from `SplitMix64::stream(seed ^ h(v), j)`, with
//! `h` the first 8 bytes of the SHA-256 of the variable's name (`angle`, `direction`, `peak`,
//! `eccentricity`, or the key of a `vary` entry). Adding a variable leaves the others' draws
//! as they were, and member `j` draws the same values at every point of a sweep (common random
//! numbers: neighbouring points differ by the swept value, not by their draws).

use crate::config::ConfigError;
use crate::rng::SplitMix64;
use serde::Serialize;
use sha2::{Digest, Sha256};

/// Most members per point.
pub const MAX_MEMBERS: usize = 10_000;
/// Most member runs of a sweep (points × members).
pub const MAX_RUNS: usize = 1_000_000;

/// How a `vary` key is drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Distribution {
    /// Uniform in `[from, to]`.
    Uniform,
    /// Uniform in `[ln from, ln to]` (`from`, `to` > 0).
    LogUniform,
}

/// One `[[ensemble.vary]]` entry.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Vary {
    /// Scene key, as for `--set`.
    pub key: String,
    /// Lower end.
    pub from: f64,
    /// Upper end.
    pub to: f64,
    /// Distribution.
    pub distribution: Distribution,
}

/// The integrator setting members run on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MemberSetting {
    /// The parked race on RK4, one step per tick, `contact_substeps` from the stability estimate
    /// (the cheapest setting of `plant bench engineering` that keeps every mode).
    Fast,
    /// The scene's own integrator.
    Scene,
}

/// A validated `[ensemble]` table.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EnsembleSpec {
    /// Most members per point.
    pub members: usize,
    /// Seed of the draws.
    pub seed: u64,
    /// Members per round.
    pub batch: usize,
    /// A point stops once its Wilson interval is at most this wide (0: never by width).
    pub target_width: f64,
    /// A point stops once at least this many members all agree (0: never by agreement).
    pub agree: usize,
    /// Draw the rotor's angle at the shock's arrival.
    pub angle: bool,
    /// Half-width of the shock direction's draw (deg).
    pub direction_deg: f64,
    /// Relative half-width of the shock peak's draw.
    pub peak_rel: f64,
    /// Relative half-width of the eccentricity's draw.
    pub eccentricity_rel: f64,
    /// Further keys drawn.
    pub vary: Vec<Vary>,
    /// Members' integrator.
    pub integrator: MemberSetting,
    /// Verify members close to a decision.
    pub verify: bool,
    /// DOP853 relative tolerance of the verification.
    pub verify_rtol: f64,
    /// A recovered member is "late" when its last contact comes after this share of the time
    /// from the shock's start to the steady window's start.
    pub verify_late: f64,
    /// A rebounding member is close to a decision when its contact share over the steady window
    /// is below this (intermittent impacts); 1 verifies every rebounding member.
    pub verify_rebound: f64,
}

impl Default for EnsembleSpec {
    fn default() -> Self {
        Self {
            members: 64,
            seed: 1,
            batch: 64,
            target_width: 0.0,
            agree: 0,
            angle: true,
            direction_deg: 0.0,
            peak_rel: 0.0,
            eccentricity_rel: 0.0,
            vary: Vec::new(),
            integrator: MemberSetting::Fast,
            verify: true,
            verify_rtol: 1e-10,
            verify_late: 0.75,
            verify_rebound: 0.5,
        }
    }
}

/// The values drawn for one member.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Draw {
    /// Rotor angle at the shock's arrival (deg, `[0, 360)`), if drawn.
    pub angle_deg: Option<f64>,
    /// Offset of every shock's direction (deg).
    pub direction_offset_deg: f64,
    /// Factor on every shock's peak.
    pub peak_factor: f64,
    /// Factor on the eccentricity.
    pub eccentricity_factor: f64,
    /// Values of the `vary` keys, in order.
    pub vary: Vec<f64>,
}

fn range(key: &str, value: impl std::fmt::Display, unit: &str, why: &str) -> ConfigError {
    ConfigError::Range {
        key: format!("ensemble.{key}"),
        value: value.to_string(),
        unit: if unit.is_empty() { String::new() } else { format!(" {unit}") },
        why: why.to_string(),
    }
}

/// Reads an integer key; a float or a string is refused naming the key, the value and the unit.
fn integer(t: &toml::Table, key: &str, unit: &str, lo: i64, hi: i64) -> Result<Option<i64>, ConfigError> {
    let why = format!("must be an integer between {lo} and {hi}");
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::Integer(i)) if (lo..=hi).contains(i) => Ok(Some(*i)),
        Some(toml::Value::Integer(i)) => Err(range(key, i, unit, &why)),
        Some(other) => Err(range(key, other, unit, &why)),
    }
}

fn number(t: &toml::Table, prefix: &str, key: &str, unit: &str) -> Result<Option<f64>, ConfigError> {
    let full = format!("{prefix}{key}");
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::Float(v)) if v.is_finite() => Ok(Some(*v)),
        Some(toml::Value::Integer(i)) => Ok(Some(*i as f64)),
        Some(other) => Err(range(&full, other, unit, "must be a finite number")),
    }
}

fn boolean(t: &toml::Table, key: &str) -> Result<Option<bool>, ConfigError> {
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::Boolean(b)) => Ok(Some(*b)),
        Some(other) => Err(range(key, other, "", "must be true or false")),
    }
}

fn string<'a>(t: &'a toml::Table, prefix: &str, key: &str) -> Result<Option<&'a str>, ConfigError> {
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::String(s)) => Ok(Some(s)),
        Some(other) => Err(range(&format!("{prefix}{key}"), other, "", "must be a string")),
    }
}

fn unknown_keys(t: &toml::Table, prefix: &str, allowed: &[&str]) -> Result<(), ConfigError> {
    match t.keys().find(|k| !allowed.contains(&k.as_str())) {
        None => Ok(()),
        Some(k) => Err(ConfigError::Parse {
            path: format!("[ensemble] {prefix}{k}"),
            message: format!("unknown key `{prefix}{k}` (known: {})", allowed.join(", ")),
        }),
    }
}

/// The `[[ensemble.vary]]` tables: each key drawn once, from a range and a distribution.
fn vary_list(t: &toml::Table) -> Result<Vec<Vary>, ConfigError> {
    let mut vary = Vec::new();
    match t.get("vary") {
        None => {}
        Some(toml::Value::Array(items)) => {
            for (i, item) in items.iter().enumerate() {
                let prefix = format!("vary[{i}].");
                let v = item.as_table().ok_or_else(|| range(&format!("vary[{i}]"), item, "", "must be a table"))?;
                unknown_keys(v, &prefix, &["key", "from", "to", "distribution"])?;
                let key = string(v, &prefix, "key")?
                    .ok_or_else(|| range(&format!("{prefix}key"), "(missing)", "", "is required"))?
                    .to_string();
                let get = |k: &str| {
                    number(v, &prefix, k, "")?
                        .ok_or_else(|| range(&format!("{prefix}{k}"), "(missing)", "", "is required"))
                };
                let (from, to) = (get("from")?, get("to")?);
                if from > to {
                    return Err(range(&format!("{prefix}to"), to, "", &format!("must be >= from = {from}")));
                }
                let distribution = match string(v, &prefix, "distribution")? {
                    None | Some("uniform") => Distribution::Uniform,
                    Some("log_uniform") => Distribution::LogUniform,
                    Some(other) => {
                        return Err(range(
                            &format!("{prefix}distribution"),
                            format!("\"{other}\""),
                            "",
                            "must be \"uniform\" or \"log_uniform\"",
                        ))
                    }
                };
                if distribution == Distribution::LogUniform && from <= 0.0 {
                    return Err(range(&format!("{prefix}from"), from, "", "must be > 0 with \"log_uniform\""));
                }
                if vary.iter().any(|x: &Vary| x.key == key) {
                    return Err(range(&format!("{prefix}key"), format!("\"{key}\""), "", "is drawn twice"));
                }
                vary.push(Vary { key, from, to, distribution });
            }
        }
        Some(other) => return Err(range("vary", other, "", "must be an array of tables ([[ensemble.vary]])")),
    }
    Ok(vary)
}

impl EnsembleSpec {
    /// Validates an `[ensemble]` table (the checks that need no scene; the draws' ranges are
    /// checked against each point's scene by [`crate::sweep::Sweep::load`]).
    pub fn from_table(t: &toml::Table) -> Result<Self, ConfigError> {
        const KEYS: [&str; 15] = [
            "members",
            "seed",
            "batch",
            "target_width",
            "agree",
            "angle",
            "direction_deg",
            "peak_rel",
            "eccentricity_rel",
            "vary",
            "integrator",
            "verify",
            "verify_rtol",
            "verify_late",
            "verify_rebound",
        ];
        unknown_keys(t, "", &KEYS)?;
        let d = Self::default();
        let members = integer(t, "members", "members", 1, MAX_MEMBERS as i64)?.map_or(d.members, |v| v as usize);
        let seed = integer(t, "seed", "", 0, i64::MAX)?.map_or(d.seed, |v| v as u64);
        let batch = integer(t, "batch", "members", 1, members as i64)?.map_or(members, |v| v as usize);
        let agree = integer(t, "agree", "members", 0, members as i64)?.map_or(d.agree, |v| v as usize);
        let target_width = number(t, "", "target_width", "")?.unwrap_or(d.target_width);
        if !(0.0..=1.0).contains(&target_width) {
            return Err(range("target_width", target_width, "", "must be between 0 (off) and 1"));
        }
        let direction_deg = number(t, "", "direction_deg", "deg")?.unwrap_or(0.0);
        if !(0.0..=180.0).contains(&direction_deg) {
            return Err(range("direction_deg", direction_deg, "deg", "must be between 0 and 180"));
        }
        let rel = |key: &str| -> Result<f64, ConfigError> {
            let v = number(t, "", key, "")?.unwrap_or(0.0);
            if (0.0..1.0).contains(&v) {
                Ok(v)
            } else {
                Err(range(key, v, "", "must be >= 0 and < 1 (a relative half-width)"))
            }
        };
        let (peak_rel, eccentricity_rel) = (rel("peak_rel")?, rel("eccentricity_rel")?);
        let integrator = match string(t, "", "integrator")? {
            None | Some("fast") => MemberSetting::Fast,
            Some("scene") => MemberSetting::Scene,
            Some(other) => {
                return Err(range("integrator", format!("\"{other}\""), "", "must be \"fast\" or \"scene\""))
            }
        };
        let verify_rtol = number(t, "", "verify_rtol", "")?.unwrap_or(d.verify_rtol);
        if !(1e-14..=1e-6).contains(&verify_rtol) {
            return Err(range("verify_rtol", verify_rtol, "", "must be between 1e-14 and 1e-6"));
        }
        let verify_late = number(t, "", "verify_late", "")?.unwrap_or(d.verify_late);
        if !(0.0..=1.0).contains(&verify_late) {
            return Err(range("verify_late", verify_late, "", "must be between 0 and 1"));
        }
        let verify_rebound = number(t, "", "verify_rebound", "")?.unwrap_or(d.verify_rebound);
        if !(0.0..=1.0).contains(&verify_rebound) {
            return Err(range("verify_rebound", verify_rebound, "", "must be between 0 and 1"));
        }
        let vary = vary_list(t)?;
        let spec = Self {
            members,
            seed,
            batch,
            target_width,
            agree,
            angle: boolean(t, "angle")?.unwrap_or(d.angle),
            direction_deg,
            peak_rel,
            eccentricity_rel,
            vary,
            integrator,
            verify: boolean(t, "verify")?.unwrap_or(d.verify),
            verify_rtol,
            verify_late,
            verify_rebound,
        };
        for v in &spec.vary {
            if spec.angle && v.key == "rotor.unbalance_phase_deg" {
                return Err(range(
                    "vary.key",
                    "\"rotor.unbalance_phase_deg\"",
                    "",
                    "is drawn already by ensemble.angle = true (set angle = false to draw it yourself)",
                ));
            }
            if v.key.starts_with("integrator.") || v.key.starts_with("ensemble.") {
                return Err(range(
                    "vary.key",
                    format!("\"{}\"", v.key),
                    "",
                    "must be a key of the physics or the shock",
                ));
            }
        }
        Ok(spec)
    }

    /// Number of rounds: batches of `batch` members up to `members`.
    pub fn rounds(&self) -> usize {
        self.members.div_ceil(self.batch)
    }

    /// Members of round `r`.
    pub fn batch_members(&self, r: usize) -> std::ops::Range<usize> {
        (r * self.batch).min(self.members)..((r + 1) * self.batch).min(self.members)
    }

    /// The draw of member `j` (the same wherever and whenever it is made).
    pub fn draw(&self, j: usize) -> Draw {
        let rng = |name: &str| SplitMix64::stream(self.seed ^ name_hash(name), j as u64);
        let sym = |r: &mut SplitMix64, half: f64| if half > 0.0 { r.uniform([-half, half]) } else { 0.0 };
        Draw {
            angle_deg: self.angle.then(|| rng("angle").uniform([0.0, 360.0])),
            direction_offset_deg: sym(&mut rng("direction"), self.direction_deg),
            peak_factor: 1.0 + sym(&mut rng("peak"), self.peak_rel),
            eccentricity_factor: 1.0 + sym(&mut rng("eccentricity"), self.eccentricity_rel),
            vary: self
                .vary
                .iter()
                .map(|v| {
                    let u = rng(&v.key).unit();
                    match v.distribution {
                        Distribution::Uniform => v.from + u * (v.to - v.from),
                        Distribution::LogUniform => (v.from.ln() + u * (v.to.ln() - v.from.ln())).exp(),
                    }
                })
                .collect(),
        }
    }

    /// The two extreme draws (every variable at its lower end, then at its upper end), for
    /// checking the ranges against a scene before anything runs.
    pub fn extremes(&self) -> [Draw; 2] {
        let end = |s: f64| Draw {
            angle_deg: None,
            direction_offset_deg: s * self.direction_deg,
            peak_factor: 1.0 + s * self.peak_rel,
            eccentricity_factor: 1.0 + s * self.eccentricity_rel,
            vary: self.vary.iter().map(|v| if s < 0.0 { v.from } else { v.to }).collect(),
        };
        [end(-1.0), end(1.0)]
    }
}

/// First 8 bytes of the SHA-256 of `name`, as the stream offset of a variable.
fn name_hash(name: &str) -> u64 {
    let d = Sha256::digest(name.as_bytes());
    u64::from_le_bytes([d[0], d[1], d[2], d[3], d[4], d[5], d[6], d[7]])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).expect("toml")
    }

    #[test]
    fn draws_repeat_and_do_not_depend_on_other_variables() {
        let a = EnsembleSpec::from_table(&table("members = 8\nseed = 3")).expect("spec");
        let b = EnsembleSpec::from_table(&table("members = 8\nseed = 3\npeak_rel = 0.1")).expect("spec");
        for j in 0..8 {
            assert_eq!(a.draw(j).angle_deg, b.draw(j).angle_deg);
            assert_eq!(a.draw(j), a.draw(j));
            let angle = a.draw(j).angle_deg.expect("angle");
            assert!((0.0..360.0).contains(&angle));
            assert!((0.9..=1.1).contains(&b.draw(j).peak_factor));
        }
        assert_ne!(a.draw(0).angle_deg, a.draw(1).angle_deg);
    }

    #[test]
    fn bad_tables_name_key_value_and_unit() {
        let msg = |text: &str| EnsembleSpec::from_table(&table(text)).expect_err(text).to_string();
        assert!(msg("members = 0").contains("ensemble.members = 0 members"));
        assert!(msg("members = 20000").contains("ensemble.members = 20000 members"));
        assert!(msg("seed = 1.5").contains("ensemble.seed = 1.5"));
        assert!(msg("seed = \"x\"").contains("ensemble.seed"));
        assert!(msg("direction_deg = 200").contains("ensemble.direction_deg = 200 deg"));
        assert!(msg("peak_rel = 1.5").contains("ensemble.peak_rel = 1.5"));
        assert!(msg("bogus = 1").contains("bogus"));
        assert!(msg("[[vary]]\nkey = \"rotor.mass_kg\"\nfrom = 2.0\nto = 1.0").contains("ensemble.vary[0].to = 1"));
    }

    #[test]
    fn rounds_cover_the_members() {
        let s = EnsembleSpec::from_table(&table("members = 40\nbatch = 16")).expect("spec");
        assert_eq!(s.rounds(), 3);
        assert_eq!(s.batch_members(2), 32..40);
    }
}
