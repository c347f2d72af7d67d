#!/usr/bin/env bash
# The fidelity charts of docs/results/fidelity.md (docs/charts/fidelity_{sampled,continuous,all}.png
# and .csv) from the finished sweeps of config/sweeps/fidelity/, run first with
#   for n in ideal voltage current-loop sensor-bandwidth runout range realistic relev-ideal relev-realistic \
#     relev-voltage relev-current-loop relev-sensor-bandwidth relev-runout \
#     paper-ideal paper-voltage paper-current-loop paper-sensor-bandwidth paper-runout paper-range \
#     paper-realistic paper-redesign-ideal paper-redesign-realistic; do
#     plant sweep config/sweeps/fidelity/$n.toml --out runs/fid/$n --jobs 2
#   done
# Run from the repository root; PLANT names the binary (default target/release/plant). Copy
# runs/fidelity-NAME/overlay.png and overlay.csv to docs/charts/fidelity_NAME.png and .csv.
#
#   scripts/fidelity-charts.sh --redraw
# draws the four charts again from the committed tables docs/charts/fidelity_NAME.csv alone
# (no sweep; `plant overlay --redraw`, the 0.5 crossings found again from the points) into
# runs/fidelity-NAME/overlay.png.
set -eu
P=${PLANT:-target/release/plant}
F=runs/fid
declare -A TITLE=(
 [sampled]="realistic-10g, sampled PD at 20 kHz, ξ_e = 0.045: recovery against the shock's peak"
 [continuous]="the study's continuous PD (paper-10g, ξ_e = 0.01): recovery against the shock's peak"
 [all]="every controller, ideal against realistic loop: recovery against the shock's peak"
 [relev]="relev (relev-10g, sampled at 20 kHz): recovery against the shock's peak"
)
if [ "${1:-}" = "--redraw" ]; then
  for name in sampled continuous all relev; do
    $P overlay --redraw "docs/charts/fidelity_$name.csv" --title "${TITLE[$name]}" --out "runs/fidelity-$name"
  done
  exit 0
fi
$P overlay $F/ideal $F/voltage $F/current-loop $F/sensor-bandwidth $F/runout $F/range $F/realistic \
 --label "ideal loop (ζ = 0.029)" --label "voltage limit alone (150 V, 58 mH, 20 kHz loop)" --label "current loop alone (1.5 kHz; ζ = 0.007)" --label "sensor bandwidth alone (5 kHz; ζ = 0.020)" --label "runout alone (1.5 µm 1×, 0.75 µm 2×)" --label "range ±160 µm alone (clips in contact)" --label "all, ±250 µm (the scene; ζ = 0.010)" \
 --title "${TITLE[sampled]}" --out runs/fidelity-sampled
$P overlay $F/paper-ideal $F/paper-voltage $F/paper-current-loop $F/paper-sensor-bandwidth $F/paper-runout $F/paper-range $F/paper-realistic \
 --label "ideal loop (ζ = 0.010)" --label "voltage limit alone (150 V, 58 mH, 20 kHz loop; ζ = 0.008)" --label "current loop alone (1.5 kHz; ζ = −0.012: unstable)" --label "sensor bandwidth alone (5 kHz; ζ = 0.0005)" --label "runout alone" --label "range ±160 µm alone (clips in contact)" --label "all, ±250 µm (ζ = −0.009: unstable)" \
 --title "${TITLE[continuous]}" --out runs/fidelity-continuous
$P overlay $F/ideal $F/realistic $F/paper-ideal $F/paper-realistic $F/paper-redesign-ideal $F/paper-redesign-realistic $F/relev-ideal $F/relev-realistic \
 --label "sampled PD ξ_e = 0.045, ideal loop" --label "sampled PD ξ_e = 0.045, realistic loop" --label "continuous PD ξ_e = 0.01 (the study's), ideal loop" --label "continuous PD ξ_e = 0.01, realistic loop (unstable)" --label "continuous PD ξ_e = 0.029, ideal loop" --label "continuous PD ξ_e = 0.029, realistic loop" --label "relev, ideal loop" --label "relev, realistic loop" \
 --title "${TITLE[all]}" --out runs/fidelity-all
$P overlay $F/relev-ideal $F/relev-voltage $F/relev-current-loop $F/relev-sensor-bandwidth $F/relev-runout $F/relev-realistic \
 --label "ideal loop" --label "voltage limit alone (150 V, 58 mH, 20 kHz loop)" --label "current loop alone (1.5 kHz)" --label "sensor bandwidth alone (5 kHz)" --label "runout alone" --label "all, ±250 µm" \
 --title "${TITLE[relev]}" --out runs/fidelity-relev
