//! Writes a "peer spec": everything an independent implementation of the
//! plant's derivative needs (SI parameters, continuous PD gains, the shock
//! programme, the initial state, the tick grid), plus seeded random states
//! with the Rust derivative at each, so that the peer can be checked to
//! rounding. The Python peer in `bench/peer/` reads it.
//!
//! ```text
//! cargo run --release -p plant --example peer_dump -- SCENE.toml [--set K=V]... --out spec.json
//!     [--samples N] [--seed S] [--atol-scale P,V,A,W]
//! ```
//!
//! `--atol-scale` adds an `atol_scale` array (per state component: P for
//! positions (m), V for velocities (m/s), A for angles (rad), W for angular
//! speeds (rad/s)); a peer then uses `atol_i = rtol · atol_scale_i`. Without
//! it the spec has no `atol_scale` and the peer uses a scalar atol.
//!
//! Only scenes whose shocks are all double half-sines are accepted (the
//! peer implements that pulse only), with `controller.mode = "continuous"`.

use anyhow::{bail, Context};
use plant::config::load_scene;
use std::path::PathBuf;

struct Args {
    scene: PathBuf,
    sets: Vec<String>,
    out: PathBuf,
    samples: usize,
    seed: u64,
    atol_scale: Option<[f64; 4]>,
}

fn parse_args() -> anyhow::Result<Args> {
    let mut it = std::env::args().skip(1);
    let (mut scene, mut sets, mut out, mut samples, mut seed, mut atol_scale) = (None, Vec::new(), None, 400, 1, None);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().with_context(|| format!("{name} needs a value"));
        match a.as_str() {
            "--set" => sets.push(value("--set")?),
            "--out" => out = Some(PathBuf::from(value("--out")?)),
            "--samples" => samples = value("--samples")?.parse().context("--samples")?,
            "--seed" => seed = value("--seed")?.parse().context("--seed")?,
            "--atol-scale" => {
                let v: Vec<f64> = value("--atol-scale")?
                    .split(',')
                    .map(|s| s.trim().parse::<f64>())
                    .collect::<Result<_, _>>()
                    .context("--atol-scale P,V,A,W")?;
                let [p, v, an, w] = v[..] else { bail!("--atol-scale takes four numbers P,V,A,W") };
                atol_scale = Some([p, v, an, w]);
            }
            "-h" | "--help" => {
                println!(
                    "peer_dump SCENE.toml [--set K=V]... --out spec.json [--samples N] [--seed S] \
                     [--atol-scale P,V,A,W]"
                );
                std::process::exit(0);
            }
            s if s.starts_with("--") => bail!("unknown option {s}"),
            s => {
                if scene.replace(PathBuf::from(s)).is_some() {
                    bail!("one scene file only");
                }
            }
        }
    }
    Ok(Args {
        scene: scene.context("missing SCENE.toml")?,
        sets,
        out: out.context("missing --out spec.json")?,
        samples,
        seed,
        atol_scale,
    })
}

fn main() -> anyhow::Result<()> {
    let args = parse_args()?;
    let scene = load_scene(&args.scene, &args.sets)?;
    let scale = args
        .atol_scale
        .map(|[pos, vel, ang, angvel]| [pos, pos, ang, pos, pos, ang, vel, vel, angvel, vel, vel, angvel]);
    let mut spec = plant::bench::peer::spec(&scene, args.samples, args.seed, scale)?;
    spec["scene_file"] = serde_json::json!(args.scene.display().to_string());
    spec["overrides"] = serde_json::json!(args.sets);
    let text = serde_json::to_string_pretty(&spec)?;
    std::fs::write(&args.out, text).with_context(|| format!("cannot write {}", args.out.display()))?;
    eprintln!("peer_dump: {} samples → {}", args.samples + 1, args.out.display());
    Ok(())
}
