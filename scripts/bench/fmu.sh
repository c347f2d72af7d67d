#!/usr/bin/env bash
# The FMI side's speed (issue 29, "Speed"), from a release build:
#   1. the plant FMU of config/cosim-10g.toml (1.5 s, 30 000 ticks) in FMPy's closed loop with the
#      Python kit's pd (plant/fmu/python/closed_loop.py): the process's wall and CPU time, and
#      each part of a tick timed apart (scripts/bench/fmu_timing.py: outputs read, law, inputs
#      set, doStep), FMI 2.0 and 3.0; against `plant run` of the same scene in sampled mode
#      (summary.json's wall_time_s and realtime_factor, the process's wall and CPU time);
#   2. the state: get/set/serialise/deserialise of the FMU's state at 0.5 s (fmu_timing.py), and
#      Plant::snapshot/restore, the snapshot as JSON and as a file (the criterion bench
#      plant/benches/stepper.rs, if built);
#   3. a controller FMU's round trip over the wire against the Rust pd's: `plant bench ipc`
#      with the `controller` binary's pd (spawned, and started apart as controller-fmu is), and
#      with `controller-fmu` serving the C pd FMU (tests/fmu/pd.c, built by pd_fmu.py);
# ROUNDS rounds (default 3), interleaved, the load average beside each.
#
#   cargo build --release --locked -p plant -p plant-fmu -p controller -p controller-fmu
#   cargo build --release --locked -p plant --bench stepper        # for 2.'s Rust side
#   scripts/bench/fmu.sh runs/bench-fmu [ROUNDS]
#
# SAMPLES (default 20000) round trips per `plant bench ipc`. BIN (default target/release) holds the binaries; VENV (default target/fmpy-venv, which the
# FMU tests make) a Python with FMPy 0.3.32 and the kit: made here if it lacks them.
set -euo pipefail
cd "$(dirname "$0")/../.."
OUT=$(realpath -m "${1:-runs/bench-fmu}"); ROUNDS=${2:-3}
BIN=$(realpath "${BIN:-target/release}"); VENV=${VENV:-target/fmpy-venv}; SAMPLES=${SAMPLES:-20000}
P=$BIN/plant
mkdir -p "$OUT"
if ! "$VENV/bin/python" -c "import fmpy, amb_testbed_controller" 2> /dev/null; then
  python3 -m venv "$VENV"
  "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check fmpy==0.3.32 --editable python/
fi
PY=$VENV/bin/python
load() { cut -d' ' -f1 /proc/loadavg; }
RESULTS=$OUT/results.csv
echo "what,round,value,unit,load_1min" > "$RESULTS"
row() { echo "$1,$2,$3,$4,$5" >> "$RESULTS"; }
timed() { # NAME ROUND CMD…: the process's wall and CPU (user + system) time
  local name=$1 r=$2 l; shift 2; l=$(load)
  /usr/bin/time -f '%e %U %S' -o "$OUT/$name-$r.time" "$@" > "$OUT/$name-$r.log" 2>&1
  read -r wall user sys < "$OUT/$name-$r.time"
  row "$name/process_wall" "$r" "$wall" s "$l"
  row "$name/process_cpu" "$r" "$(python3 -c "print($user + $sys)")" s "$l"
}

"$P" fmu config/cosim-10g.toml --out "$OUT/plant.fmu" > /dev/null
"$P" fmu config/cosim-10g.toml --fmi 3 --out "$OUT/plant3.fmu" > /dev/null
python3 scripts/bench/pd_fmu.py "$OUT/pd.fmu"
echo "# FMI speed: $(date -u +%FT%TZ), $(nproc) cores; uptime at start: $(uptime)" > "$OUT/summary.md"

for r in $(seq 1 "$ROUNDS"); do
  # 1. The closed loop against plant run in sampled mode.
  timed closed_loop_fmi2 "$r" "$PY" plant/fmu/python/closed_loop.py "$OUT/plant.fmu" "$OUT/loop.csv"
  rm -rf "$OUT/sampled"
  timed plant_run_sampled "$r" "$P" run config/cosim-10g.toml --set 'controller.mode="sampled"' \
    --set output.plots=false --out "$OUT/sampled" --quiet
  l=$(load)
  python3 - "$OUT/sampled/summary.json" "$r" "$l" >> "$RESULTS" <<'EOF'
import json, sys
s, r, load = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3]
print(f"plant_run_sampled/loop_wall,{r},{s['wall_time_s']},s,{load}")
print(f"plant_run_sampled/realtime_factor,{r},{s['realtime_factor']},x,{load}")
print(f"plant_run_sampled/loop_per_tick,{r},{s['wall_time_s'] / 30000 * 1e6},us,{load}")
EOF
  for v in 2 3; do
    fmu=$OUT/plant.fmu; [ "$v" = 3 ] && fmu=$OUT/plant3.fmu
    l=$(load)
    "$PY" scripts/bench/fmu_timing.py "$fmu" > "$OUT/timing-fmi$v-$r.json"
    python3 - "$OUT/timing-fmi$v-$r.json" "$r" "$l" "$v" >> "$RESULTS" <<'EOF'
import json, sys
t, r, load, v = json.load(open(sys.argv[1])), sys.argv[2], sys.argv[3], sys.argv[4]
print(f"fmpy_fmi{v}/loop_wall,{r},{t['loop_wall_s']},s,{load}")
print(f"fmpy_fmi{v}/loop_cpu,{r},{t['loop_cpu_s']},s,{load}")
print(f"fmpy_fmi{v}/realtime_factor,{r},{t['realtime_factor']},x,{load}")
for k, f in t["per_tick"].items():
    print(f"fmpy_fmi{v}/{k}_mean,{r},{f['mean_us']},us,{load}")
    print(f"fmpy_fmi{v}/{k}_median,{r},{f['median_us']},us,{load}")
for k, f in t["state"].items():
    print(f"fmpy_fmi{v}/state_{k}_median,{r},{f['median_us']},us,{load}")
print(f"fmpy_fmi{v}/serialized_state,{r},{t['serialized_bytes']},bytes,{load}")
EOF
  done
  # 3. Round trips over the wire: the Rust pd (spawned; started apart) and the C pd FMU.
  for who in pd_spawned pd_external fmu_external; do
    l=$(load); id=bench-$$-$r-$who
    case $who in
      pd_spawned) "$P" bench ipc --samples "$SAMPLES" --warmup "$((SAMPLES / 10))" > "$OUT/ipc-$who-$r.log" 2>&1 ;;
      pd_external)
        "$BIN/controller" --run-id "$id" --law pd --quiet > "$OUT/ipc-$who-$r.ctl.log" 2>&1 &
        "$P" bench ipc --samples "$SAMPLES" --warmup "$((SAMPLES / 10))" --controller external --run-id "$id" > "$OUT/ipc-$who-$r.log" 2>&1
        wait ;;
      fmu_external)
        "$BIN/controller-fmu" --fmu "$OUT/pd.fmu" --run-id "$id" --law fmu --quiet > "$OUT/ipc-$who-$r.ctl.log" 2>&1 &
        "$P" bench ipc --samples "$SAMPLES" --warmup "$((SAMPLES / 10))" --controller external --run-id "$id" > "$OUT/ipc-$who-$r.log" 2>&1
        wait ;;
    esac
    python3 - "$OUT/ipc-$who-$r.log" "$r" "$l" "$who" >> "$RESULTS" <<'EOF'
import re, sys
log, r, load, who = sys.argv[1:]
m = re.search(r"round trip .*?p50 (\S+) us, p99 (\S+) us, p99.9 (\S+) us, max (\S+) us", open(log).read())
for name, v in zip(["p50", "p99", "p99.9", "max"], m.groups()):
    print(f"ipc_{who}/round_trip_{name},{r},{v},us,{load}")
EOF
  done
  echo "round $r done; $(uptime)" >&2
done

# 2.'s Rust side, once: the criterion bench of Plant::step, snapshot and restore.
bench=$(find "$BIN/deps" -maxdepth 1 -type f -executable -name 'stepper-*' -printf '%T@ %p\n' | sort -rn | head -1 | cut -d' ' -f2)
if [ -n "$bench" ]; then
  l=$(load)
  CRITERION_HOME=$OUT/criterion "$bench" --bench --noplot > "$OUT/stepper.log" 2>&1
  python3 - "$OUT/stepper.log" "$l" >> "$RESULTS" <<'EOF'
import re, sys
unit = {"ns": 1e-3, "µs": 1.0, "us": 1.0, "ms": 1e3, "s": 1e6}
name = None
for line in open(sys.argv[1], encoding="utf-8"):
    m = re.match(r"^((plant_step|snapshot)/\S+)", line)
    if m:
        name = m.group(1)
    m = re.search(r"time:\s+\[\S+ \S+ (\S+) (\S+) \S+ \S+\]", line)
    if m and name:
        print(f"rust_{name},1,{float(m.group(1)) * unit[m.group(2)]:.6g},us,{sys.argv[2]}")
        name = None
EOF
else
  echo "no stepper bench in $BIN/deps: build it (cargo build --release --locked -p plant --bench stepper)" >&2
fi

echo "uptime at the end: $(uptime)" >> "$OUT/summary.md"
python3 - "$RESULTS" >> "$OUT/summary.md" <<'EOF'
import csv, statistics, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("\n| measurement | median | each round | unit |")
print("|---|---|---|---|")
for w in dict.fromkeys(r["what"] for r in rows):
    v = [float(r["value"]) for r in rows if r["what"] == w]
    unit = next(r["unit"] for r in rows if r["what"] == w)
    print(f"| {w} | {statistics.median(v):.4g} | {', '.join(f'{x:.4g}' for x in v)} | {unit} |")
loads = [float(r["load_1min"]) for r in rows]
print(f"\nLoad average (1 min) before the measurements: {min(loads):.2f} to {max(loads):.2f}.")
EOF
cat "$OUT/summary.md"
