#!/usr/bin/env bash
# ROSS's figures for the flexible rotor's check, from the two ROSS versions engineers have:
# ROSS 3.1.0 (ross-rotordynamics 3.1.0 needs Python >= 3.13) and ROSS 2.3.0 (what pip installs
# on Python 3.11). For each, a venv under target/ with ROSS and plotly < 6 (with which ROSS
# imports), then fixture.py, which saves ROSS's example rotor and an AMB machine rotor with
# Rotor.save() and writes ROSS's run_modal and run_campbell figures beside them, and saves a
# shaft with one of ROSS's MagneticBearingElements (amb_element.toml: its equivalent coefficients).
#
#   scripts/ross/fixture.sh [OUT]     # OUT defaults to plant/physics/tests/fixtures/ross
#
# ROSS 3.1's files go to OUT, ROSS 2.3's to OUT/v2.3. PYTHON names the interpreter for ROSS 3.1
# (default: python3.13, else python3 if it is >= 3.13), PYTHON311 the one for ROSS 2.3 (default:
# python3.11).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:-plant/physics/tests/fixtures/ross}

# The first interpreter of the candidates whose version is at least $1.$2 and below $3.$4.
find_python() {
    local lo=$1 hi=$2
    shift 2
    for candidate in "$@"; do
        if command -v "$candidate" >/dev/null 2>&1 &&
            "$candidate" -c "import sys; sys.exit(not ($lo) <= sys.version_info[:2] < ($hi))" 2>/dev/null; then
            echo "$candidate"
            return
        fi
    done
}

# make_venv VENV PYTHON ROSS_VERSION: a venv with that ROSS, made once (kept while it imports).
make_venv() {
    local venv=$1 python=$2 version=$3
    if [[ ! -x "$venv/bin/python" ]] || ! "$venv/bin/python" -c 'import ross' >/dev/null 2>&1; then
        rm -rf "$venv"
        "$python" -m venv "$venv"
        "$venv/bin/pip" install -q "ross-rotordynamics==$version" 'plotly<6'
    fi
}

# run_fixture VENV OUT LOG: ROSS's import prints a long note about the optional REFPROP library
# (harmless): kept out of the way in LOG with everything else the run prints.
run_fixture() {
    local venv=$1 dir=$2 log=$3
    if ! "$venv/bin/python" -W ignore scripts/ross/fixture.py "$dir" >"$log" 2>&1; then
        cat "$log" >&2
        exit 1
    fi
    grep -E '^(rotor_example|amb_machine|amb_element):' "$log"
}

python=${PYTHON:-$(find_python '3, 13' '4, 0' python3.13 python3.14 "$HOME/.pyenv/versions/3.13.0/bin/python3" python3)}
python311=${PYTHON311:-$(find_python '3, 11' '3, 12' python3.11 "$HOME/.pyenv/versions/3.11.7/bin/python3")}
if [[ -z "$python" ]]; then
    echo "fixture.sh: ROSS 3.1 needs Python >= 3.13; set PYTHON" >&2
    exit 2
fi
if [[ -z "$python311" ]]; then
    echo "fixture.sh: ROSS 2.3 is made on Python 3.11; set PYTHON311" >&2
    exit 2
fi
make_venv target/ross-venv "$python" 3.1.0
make_venv target/ross23-venv "$python311" 2.3.0
run_fixture target/ross-venv "$out" target/ross-fixture.log
run_fixture target/ross23-venv "$out/v2.3" target/ross23-fixture.log
# Issue 38 item 6: ROSS 3.1's run_modal and run_amb_sensitivity on its UFU AMB rig, on the AMB
# machine with MagneticBearingElements and on soft_machine (its rotor with a soft PID) (amb_compare.json beside the files; several minutes: ROSS's
# Newmark time response of a 2 s chirp per axis and speed).
if ! target/ross-venv/bin/python -W ignore scripts/ross/amb_compare.py "$out" >target/ross-amb-compare.log 2>&1; then
    cat target/ross-amb-compare.log >&2
    exit 1
fi
grep -E '^(ufu_rig|amb_machine_ambs|soft_machine):' target/ross-amb-compare.log
