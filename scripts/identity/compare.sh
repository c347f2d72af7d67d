#!/usr/bin/env bash
# compare.sh OLD NEW: cmp every CSV of two output trees of run.sh, and report.json without its wall times.
# rss.csv (measured memory) differs between any two runs.
# compare.sh A B: cmp every CSV, and report.json figures, between two output trees
A=$1; B=$2; same=0; diff=0
cd $A
for f in $(find . -name '*.csv' | sort); do
  if cmp -s "$A/$f" "$B/$f"; then same=$((same+1)); else diff=$((diff+1)); echo "DIFF $f"; fi
done
for f in $(find . -name 'report.json' | sort); do
  python3 - "$A/$f" "$B/$f" <<'PY'
import json,sys
def strip(o):
    if isinstance(o,dict): return {k:strip(v) for k,v in o.items() if k not in ('wall_time_s','wall_s','elapsed_s','generated','seconds','cost_s')}
    if isinstance(o,list): return [strip(v) for v in o]
    return o
a=strip(json.load(open(sys.argv[1]))); b=strip(json.load(open(sys.argv[2])))
print(("SAME " if a==b else "DIFF ")+sys.argv[1])
PY
done
echo "csv same $same differ $diff"
