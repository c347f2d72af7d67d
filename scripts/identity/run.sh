#!/usr/bin/env bash
# Byte identity of a change that should change no result: runs every shipped scene, a fixed-step
# two-plane run, realistic-10g continuous, soak-short, a single-run and an ensemble sweep and two
# assessments with the binaries in BIN_DIR, into OUT. Run it with the previous binaries and the
# new ones, then compare.sh OUT_OLD OUT_NEW.
#   scripts/identity/run.sh /path/to/old/target/release runs/identity-old
set -u
BIN=$(realpath "$1"); OUT=$(realpath -m "$2")
cd "$(dirname "$0")/../.."
ID=scripts/identity
mkdir -p "$OUT"; : > "$OUT/rc.txt"
P=$BIN/plant
run() { local name=$1; shift; timeout 900 "$@" > "$OUT/$name.log" 2>&1; echo "$name $?" >> "$OUT/rc.txt"; }
for s in config/*.toml; do
  n=$(basename "$s" .toml)
  run "$n" "$P" run "$s" --out "$OUT/$n" --quiet --set output.plots=false
done
run tp-fixed "$P" run config/two-plane-asymmetric-10g.toml --out "$OUT/tp-fixed" --quiet --set output.plots=false \
  --set 'integrator.method="rk4"' --set integrator.substeps=1 --set integrator.contact_substeps=3 \
  --set 'touchdown.race_when_clear="parked"' --set 'touchdown.race_release="equilibrium"'
run realistic-cont "$P" run config/realistic-10g.toml --out "$OUT/realistic-cont" --quiet --set output.plots=false --set 'controller.mode="continuous"'
run soak "$P" soak config/soak/soak-short.toml --out "$OUT/soak-short" --quiet
run sweep-single "$P" sweep $ID/sweep-single.toml --out "$OUT/sweep-single" --quiet
run sweep-ens "$P" sweep $ID/sweep-ens.toml --out "$OUT/sweep-ens" --quiet
run assess-sens "$P" assess config/assess/study-pd-sensitivity.toml --out "$OUT/assess-sens"
run assess-tp "$P" assess config/assess/two-plane.toml --out "$OUT/assess-tp"
