#!/usr/bin/env bash
# The re-levitation question from one saved dry whirl: relev-10g with the delay-aware PD (pd_delay) into the
# dry whirl, the state saved at 0.5 s; then pd_delay, relev (armed at once), the naive pd and a stiffer pd_delay
# each from that same state.
set -u
cd "$(dirname "$0")/.."
P=${PLANT:-target/release/plant}; C=config/relev-10g.toml; O=${OUT:-runs/relev-from-state}
rm -rf $O; mkdir -p $O
COMMON=(--quiet --set 'controller.mode="sampled"')
$P run $C --out $O/whirl "${COMMON[@]}" --set 'controller.law="pd_delay"' --set 'controller.params={}' --save-state-at 0.5 > $O/whirl.log 2>&1; echo "whirl $?"
S=$O/whirl/state-0.5.json
$P run $C --out $O/from-pd_delay "${COMMON[@]}" --set 'controller.law="pd_delay"' --set 'controller.params={}' --from-state $S > $O/a.log 2>&1; echo "pd_delay $?"
$P run $C --out $O/from-relev "${COMMON[@]}" --set 'controller.law="relev"' --set 'controller.params.arm_ms=0.0' --from-state $S > $O/b.log 2>&1; echo "relev $?"
$P run $C --out $O/from-pd "${COMMON[@]}" --set 'controller.law="pd"' --set 'controller.params={}' --from-state $S > $O/c.log 2>&1; echo "pd $?"
$P run $C --out $O/from-stiff "${COMMON[@]}" --set 'controller.law="pd_delay"' --set 'controller.params={}' --set controller.stiffness_n_per_m=2e6 --set controller.damping_ratio=0.1 --from-state $S > $O/d.log 2>&1; echo "stiff $?"
for d in whirl from-pd_delay from-relev from-pd from-stiff; do
  python3 - $O/$d/summary.json $d <<'PY'
import json,sys
s=json.load(open(sys.argv[1])); a=s.get('analysis',{})
print(sys.argv[2], s['status'], 'started', s.get('started_s'), 'recovery_s', s.get('recovery_s'), 'contact_time_s', round(s['contact_time_s'],4), 'max_force', s.get('max_contact_force_n'), 'mode', a.get('post_shock_mode', a.get('motion_mode')), 'steady', a.get('steady_class'))
PY
done
