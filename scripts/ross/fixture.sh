#!/usr/bin/env bash
# ROSS's figures for the flexible rotor's check: makes a venv under target/ with ROSS
# (ross-rotordynamics 3.1.0 needs Python >= 3.13; plotly < 6, with which ROSS imports), then
# runs fixture.py, which saves ROSS's example rotor and an AMB machine rotor with Rotor.save()
# and writes ROSS's run_modal and run_campbell figures beside them.
#
#   scripts/ross/fixture.sh [OUT]     # OUT defaults to plant/physics/tests/fixtures/ross
#
# PYTHON names the interpreter (default: python3.13, else python3 if it is >= 3.13).
set -euo pipefail
cd "$(dirname "$0")/../.."
venv=target/ross-venv
python=${PYTHON:-}
if [[ -z "$python" ]]; then
    for candidate in python3.13 python3.14 "$HOME/.pyenv/versions/3.13.0/bin/python3" python3; do
        if command -v "$candidate" >/dev/null 2>&1 &&
            "$candidate" -c 'import sys; sys.exit(sys.version_info < (3, 13))' 2>/dev/null; then
            python=$candidate
            break
        fi
    done
fi
if [[ -z "$python" ]]; then
    echo "fixture.sh: ROSS 3.1 needs Python >= 3.13; set PYTHON" >&2
    exit 2
fi
if [[ ! -x "$venv/bin/python" ]] || ! "$venv/bin/python" -c 'import ross' >/dev/null 2>&1; then
    rm -rf "$venv"
    "$python" -m venv "$venv"
    "$venv/bin/pip" install -q 'ross-rotordynamics==3.1.0' 'plotly<6'
fi
# ROSS's import prints a long note about the optional REFPROP library (harmless): kept out of
# the way in target/ross-fixture.log with everything else the run prints.
log=target/ross-fixture.log
if ! "$venv/bin/python" -W ignore scripts/ross/fixture.py "${1:-plant/physics/tests/fixtures/ross}" >"$log" 2>&1; then
    cat "$log" >&2
    exit 1
fi
grep -E '^(rotor_example|amb_machine):' "$log"
