#!/usr/bin/env bash
# The tick and the derivative before and after a change (issue 28, "Speed"): the two builds'
# `plant bench tick` (cosim-10g and two-plane-asymmetric-10g), the criterion derivative bench
# (plant/benches/model.rs, `derivative/…`: planar and two-plane, in contact and levitated) and
# `plant run` of paper-10g and two-plane-asymmetric-10g in process (summary.json's
# realtime_factor, and the process's wall, user and system time), ROUNDS rounds, the two builds
# interleaved (old first in odd rounds, new first in even ones), the load average beside each.
#
# Build both trees with the same flags, each into a target folder of its own, e.g.:
#   (cd /path/to/old && CARGO_TARGET_DIR=/tmp/t-old cargo build --release --locked -p plant --bin plant --bench model)
#   CARGO_TARGET_DIR=/tmp/t-new cargo build --release --locked -p plant --bin plant --bench model
# then, from this repository (the scenes are read from its config/):
#   scripts/bench/before-after.sh /tmp/t-old/release /tmp/t-new/release runs/before-after [ROUNDS]
# It writes OUT/results.csv (one line per measurement) and prints OUT/summary.md.
set -euo pipefail
OLD=$(realpath "$1"); NEW=$(realpath "$2"); OUT=$(realpath -m "$3"); ROUNDS=${4:-3}
cd "$(dirname "$0")/../.."
mkdir -p "$OUT"
RESULTS=$OUT/results.csv
echo "kind,tree,round,what,value,load_1min" > "$RESULTS"

bench_binary() { # the newest criterion binary of plant/benches/model.rs in BIN/deps
  find "$1/deps" -maxdepth 1 -type f -executable -name 'model-*' -printf '%T@ %p\n' | sort -rn | head -1 | cut -d' ' -f2
}
load() { cut -d' ' -f1 /proc/loadavg; }
row() { echo "$1,$2,$3,$4,$5,$6" >> "$RESULTS"; }

one_round() { # TREE BIN ROUND
  local tree=$1 bin=$2 r=$3 l dir t
  for scene in cosim-10g two-plane-asymmetric-10g; do
    dir=$OUT/tick-$scene-$tree-$r; rm -rf "$dir"
    l=$(load)
    "$bin/plant" bench tick --scene "config/$scene.toml" --repeats 1 --out "$dir" > "$dir.log" 2>&1
    python3 - "$dir" "$tree" "$r" "$scene" "$l" >> "$RESULTS" <<'EOF'
import csv, sys
d, tree, r, scene, load = sys.argv[1:]
for row in csv.DictReader(open(f"{d}/tick.csv")):
    s = "realtime_fixed" if row["setting"].startswith("realtime") else "scene_integrator"
    for k in ["integration_p50_us", "contact_p50_us", "tick_p50_us", "wall_time_s"]:
        print(f"tick,{tree},{r},{scene}/{s}/{k},{row[k]},{load}")
for row in csv.DictReader(open(f"{d}/repeat.csv")):
    print(f"tick,{tree},{r},{scene}/repeated_contact_tick/p50_us,{row['p50_us']},{load}")
EOF
  done
  for scene in paper-10g two-plane-asymmetric-10g; do
    dir=$OUT/run-$scene-$tree-$r; rm -rf "$dir"
    l=$(load)
    /usr/bin/time -f '%e %U %S' -o "$dir.time" "$bin/plant" run "config/$scene.toml" --out "$dir" --quiet > "$dir.log" 2>&1
    read -r wall user sys < "$dir.time"
    rf=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['realtime_factor'])" "$dir/summary.json")
    row run "$tree" "$r" "$scene/realtime_factor" "$rf" "$l"
    row run "$tree" "$r" "$scene/process_wall_s" "$wall" "$l"
    row run "$tree" "$r" "$scene/process_cpu_s" "$(python3 -c "print($user + $sys)")" "$l"
  done
  t=$(bench_binary "$bin")
  l=$(load)
  CRITERION_HOME=$OUT/criterion-$tree "$t" --bench --noplot --warm-up-time 1 --measurement-time 3 derivative/ \
    > "$OUT/derivative-$tree-$r.log" 2>&1
  python3 - "$OUT/derivative-$tree-$r.log" "$tree" "$r" "$l" >> "$RESULTS" <<'EOF'
import re, sys
log, tree, r, load = sys.argv[1:]
unit = {"ns": 1e-3, "µs": 1.0, "us": 1.0, "ms": 1e3, "s": 1e6}
name = None
for line in open(log, encoding="utf-8"):
    m = re.match(r"^(derivative/\S+)", line)
    if m:
        name = m.group(1)
    m = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", line)
    if m and name:
        print(f"derivative,{tree},{r},{name}_us,{float(m.group(1)) * unit[m.group(2)]:.6g},{load}")
        name = None
EOF
}

echo "# before/after: $(date -u +%FT%TZ), $(nproc) cores; uptime at start: $(uptime)" > "$OUT/summary.md"
for r in $(seq 1 "$ROUNDS"); do
  if (( r % 2 )); then one_round old "$OLD" "$r"; one_round new "$NEW" "$r"
  else one_round new "$NEW" "$r"; one_round old "$OLD" "$r"; fi
  echo "round $r done; $(uptime)" >&2
done
echo "uptime at the end: $(uptime)" >> "$OUT/summary.md"
python3 - "$RESULTS" >> "$OUT/summary.md" <<'EOF'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
whats = list(dict.fromkeys(r["what"] for r in rows))
print("\n| measurement | old (median; each round) | new (median; each round) | new / old |")
print("|---|---|---|---|")
for w in whats:
    v = {t: [float(r["value"]) for r in rows if r["what"] == w and r["tree"] == t] for t in ("old", "new")}
    if not v["old"] or not v["new"]:
        continue
    m = {t: statistics.median(v[t]) for t in v}
    each = {t: ", ".join(f"{x:.4g}" for x in v[t]) for t in v}
    ratio = m["new"] / m["old"] if m["old"] else float("nan")
    print(f"| {w} | {m['old']:.4g} ({each['old']}) | {m['new']:.4g} ({each['new']}) | {ratio:.3f} |")
loads = [float(r["load_1min"]) for r in rows]
print(f"\nLoad average (1 min) before the measurements: {min(loads):.2f} to {max(loads):.2f}.")
EOF
cat "$OUT/summary.md"
