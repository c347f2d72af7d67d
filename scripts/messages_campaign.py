"""The hostile campaign of issue 40 item 8 (docs/dev/messages.md): every number-taking flag of
`plant` with hostile values, the path arguments as a folder, a FIFO, a missing and an empty
file, and scene keys of each class through --set; prints one line per case (exit code,
command, the error line) and writes OUT.json.

    python3 scripts/messages_campaign.py target/debug/plant /tmp/campaign > /tmp/campaign.tsv
"""
import subprocess, sys, os, json, shlex
P = sys.argv[1]; out = sys.argv[2]
W = os.path.abspath(os.path.join(os.path.dirname(__file__), '..'))
S = W + '/config/paper-10g.toml'
TP = W + '/config/two-plane-asymmetric-10g.toml'
VALUES = ['-1', '0', 'nan', 'inf', '1e-300', '1e300', '', 'abc', '-0']
short = ['--set', 'scene.duration_s=0.002', '--set', 'output.plots=false']
cases = []
def flag(verb, name, base, vals=VALUES):
    for v in vals:
        cases.append(verb + base + [name, v])
# numeric flags
flag(['run', S], '--save-state-at', short)
flag(['run', S], '--robustness', short)
flag(['campbell', TP], '--max-speed-hz', ['--points', '2', '--decay-speeds-hz', ''])
flag(['campbell', TP], '--points', ['--decay-speeds-hz', ''])
flag(['campbell', TP], '--decay-speeds-hz', ['--points', '2'])
flag(['linear', S], '--speed-hz', [])
flag(['compare', S], '--rates', short + ['--no-cosim'])
flag(['compare', S], '--robustness', short + ['--no-cosim', '--rates', '5k'])
flag(['compare', S], '--runs', short + ['--realtime'])
flag(['fmu', S], '--fmi', [])
flag(['ensemble', S], '--jobs', ['--set', 'ensemble.members=2', '--set', 'scene.duration_s=0.002'])
flag(['ensemble', S], '--round', ['--set', 'ensemble.members=2', '--set', 'scene.duration_s=0.002'])
flag(['ensemble', S], '--shard', ['--set', 'ensemble.members=2', '--set', 'scene.duration_s=0.002'])
flag(['bench', 'ipc'], '--samples', ['--warmup', '1'])
flag(['bench', 'ipc'], '--warmup', ['--samples', '1'])
flag(['bench', 'ipc'], '--spin-us', ['--samples', '1', '--warmup', '1'])
flag(['bench', 'host'], '--rate-hz', ['--seconds', '0.001'])
flag(['bench', 'host'], '--seconds', ['--rate-hz', '1000'])
flag(['bench', 'tick'], '--repeats', short)
flag(['bench', 'tick'], '--pin-core', short + ['--repeats', '1'])
flag(['bench', 'tick'], '--realtime-priority', short + ['--repeats', '1'])
flag(['bench', 'accuracy'], '--repeats', ['--quick'])
flag(['bench', 'ensemble'], '--members', ['--set', 'scene.duration_s=0.002'])
# path arguments
C = os.path.join(out + '-inputs', '')
os.makedirs(C + 'adir.toml', exist_ok=True)
if not os.path.exists(C + 'fifo.toml'):
    os.mkfifo(C + 'fifo.toml')
open(C + 'empty.toml', 'w').close()
for p in [C + 'adir.toml', C + 'fifo.toml', C + 'missing.toml', C + 'empty.toml']:
    for verb in (['run'], ['campbell'], ['linear'], ['fmu'], ['assess'], ['ensemble'], ['soak'], ['compare'], ['sweep'], ['analyze']):
        cases.append(verb + [p] + (['--out', 'X'] if verb == ['fmu'] else []))
    cases.append(['run', S, '--from-state', p] + short)
    cases.append(['overlay', p])
    cases.append(['bench', 'tick', '--scene', p])
# scene key classes
KEYS = ['rotor.mass_kg', 'rotor.speed_hz', 'touchdown.air_gap_mm', 'integrator.substeps', 'integrator.rtol',
        'controller.rate_hz', 'controller.damping_ratio', 'shock[0].peak_g', 'scene.duration_s', 'output.interval_s',
        'amb.current_limit_a', 'sensor.noise_um', 'initial.rotor_x_um', 'output.plots', 'integrator.method', 'robustness.members']
KV = ['-1', '0', 'nan', 'inf', '1e-300', '1e300', '""', '"abc"', '[1]', '{}', 'true']
for k in KEYS:
    for v in KV:
        cases.append(['run', S, '--set', 'scene.duration_s=0.002', '--set', 'output.plots=false', '--set', f'{k}={v}'])
rows = []
for i, c in enumerate(cases):
    d = f'{out}/{i}'
    args = [P] + c
    if '--out' not in c and c[0] not in ('analyze',):
        args += ['--out', d]
    args = [a if a != 'X' else d for a in args]
    try:
        r = subprocess.run(args, capture_output=True, text=True, timeout=8, stdin=subprocess.DEVNULL)
        code = r.returncode
        err = [l for l in r.stderr.splitlines() if l.strip() and not l.startswith('plant: t =')]
        msg = next((l for l in err if 'error' in l.lower()), err[-1] if err else '')
    except subprocess.TimeoutExpired:
        code, msg = 'timeout', '(still running after 8 s: accepted)'
    rows.append({'cmd': ' '.join(shlex.quote(x) for x in c), 'exit': code, 'msg': msg[:300]})
    print(f"{code}\t{' '.join(shlex.quote(x) for x in c)}\t{msg[:300]}", flush=True)
json.dump(rows, open(out + '.json', 'w'), indent=1)
