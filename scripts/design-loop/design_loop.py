"""The control engineer's loop, worked (issue 39 item 4; docs/guide/design-loop.md).

1. export the linear plant of a scene at its speed (`plant linear`),
2. design a decentralised lead-lag with a notch in python-control from `linear.npz` alone,
3. write it as a `state_space` law file (`law.json`, python-control's `StateSpace` fields),
4. grade it with `plant assess` (the ISO 14839-3 sensitivity and the margins),
5. run it through the scene's shock (`plant run`),

and print python-control's margins and sensitivity peaks beside the report card's.

    python design_loop.py PLANT SCENE OUT [--quick]

PLANT the `plant` binary, SCENE the scene file (config/two-plane-asymmetric-10g.toml), OUT a
folder of its own. `--quick`: the sensitivity measured on 24 frequencies and a 0.1 s shock run
(what the test runs); without, 40 frequencies and the scene's whole 1.5 s.
Needs numpy and python-control (0.10).
"""

import json
import subprocess
import sys
from pathlib import Path

import control as ct
import numpy as np

TAU = 2 * np.pi


def run(*args):
    print("$", " ".join(str(a) for a in args), flush=True)
    subprocess.run([str(a) for a in args], check=True)


def first_order(num, den):
    """`(n1 s + n0) / (d1 s + d0)` as a one-state system."""
    return ct.ss(ct.tf(num, den))


def notch(wn, zeta_zero, zeta_pole):
    """`(s² + 2 ζ_z ω s + ω²) / (s² + 2 ζ_p ω s + ω²)` = `1 + 2 (ζ_z − ζ_p) ω s / (s² + 2 ζ_p ω s + ω²)`,
    realised with states of the same scale (`ẋ₁ = ω x₂`, `ẋ₂ = −ω x₁ − 2 ζ_p ω x₂ + ω u`, `x₂ = ω s
    u / (…)`): python-control's realisation of the transfer (the companion form, `ω²` beside 1)
    leaves Tustin's `I − A T/2` ill-conditioned."""
    a = np.array([[0.0, wn], [-wn, -2 * zeta_pole * wn]])
    return ct.ss(a, [[0.0], [wn]], [[0.0, 2 * (zeta_zero - zeta_pole)]], [[1.0]])


def lead_lag_notch(plant_kk, dt, f_c, f_notch):
    """One axis' law, sensor volts to current amps, `i = bias + C u` (a restoring law has a
    negative DC gain). A lead of 3:1 centred on the crossover `f_c` (55° of phase there), a lag
    that raises the low-frequency stiffness tenfold from `f_c / 10` down, a first-order roll-off
    at 3 kHz, and a notch at `f_notch` (the spin speed: the coils leave the unbalance alone).
    The gain puts `|P C| = 1` at `f_c` on the exported discrete axis `plant_kk` alone. Each
    factor a small state-space system of its own, in series."""
    wc, wn = TAU * f_c, TAU * f_notch
    lead = first_order([3 / wc, 1], [1 / (3 * wc), 1])
    lag = first_order([1, wc / 10], [1, wc / 100])
    roll = first_order([1], [1 / (TAU * 3000), 1])
    shape = ct.series(lead, lag, roll, notch(wn, 0.05, 0.5))
    shape_d = ct.sample_system(shape, dt, "tustin")
    p = ct.frequency_response(plant_kk, [wc]).complex.ravel()[0]
    c = ct.frequency_response(shape_d, [wc]).complex.ravel()[0]
    return shape * (-1 / abs(p * c))


def block_diagonal(systems):
    """The decentralised law of every axis: one SISO state-space system per axis."""
    parts = list(systems)
    n = sum(p.nstates for p in parts)
    m = len(parts)
    a, b, c, d = np.zeros((n, n)), np.zeros((n, m)), np.zeros((m, n)), np.zeros((m, m))
    i = 0
    for k, p in enumerate(parts):
        j = i + p.nstates
        a[i:j, i:j], b[i:j, k], c[k, i:j], d[k, k] = p.A, p.B[:, 0], p.C[0], p.D[0, 0]
        i = j
    return ct.ss(a, b, c, d)


def loop_of_axis(plant_d, law_d, k):
    """Axis k's open loop `G_o` (negative-feedback form) with every other axis closed, broken
    where the plant measures the sensitivity: `S_kk = 1/(1 + G_o)` (docs/guide/linear.md)."""
    m = plant_d.ninputs
    others = law_d * np.diag([0.0 if j == k else 1.0 for j in range(m)])
    closed = ct.feedback(plant_d, others, sign=+1)  # the other loops closed: i = K u
    return -closed[k, k] * law_d[k, k]


def main():
    plant, scene, out = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    quick = "--quick" in sys.argv[4:]
    out.mkdir(parents=True, exist_ok=True)
    speed_hz = 500.0

    # 1. The linear plant at the speed.
    run(plant, "linear", scene, "--speed-hz", speed_hz, "--out", out / "lin")
    z = np.load(out / "lin" / "linear.npz")
    dt = float(z["dt"])
    axes = [str(a) for a in z["inputs"]]
    plant_d = ct.ss(z["Ad"], z["Bd"], z["Cd"], z["Dd"], dt)

    # 2. The design, from the file alone: one lead-lag with a notch per axis, its gain set on
    # its own axis of the exported discrete plant (the hold and the delay in).
    f_c = 120.0
    laws = [lead_lag_notch(plant_d[k, k], dt, f_c, speed_hz) for k in range(len(axes))]
    law = block_diagonal(laws)
    law_d = ct.sample_system(law, dt, "tustin")  # what `state_space` runs (discretisation = "tustin")

    # 3. The law file: python-control's StateSpace fields, continuous (`dt` 0): the plant
    # discretises it by Tustin at the controller's rate, as `sample_system` does.
    law_file = out / "law.json"
    law_file.write_text(json.dumps({"A": law.A.tolist(), "B": law.B.tolist(), "C": law.C.tolist(),
                                    "D": law.D.tolist(), "dt": 0}))
    sets = ['controller.mode="sampled"', 'controller.law="state_space"',
            f'controller.params.file="{law_file.resolve()}"']

    # python-control's figures on the exported model.
    ours = []
    grid = TAU * np.logspace(np.log10(0.01), np.log10(0.499 / dt), 20000)
    for k, name in enumerate(axes):
        g_o = loop_of_axis(plant_d, law_d, k)
        resp = ct.frequency_response(g_o, grid).complex.ravel()
        gm, pm, sm, w180, wc, ws = ct.stability_margins(ct.frd(resp, grid))
        s_peak = np.max(np.abs(1 / (1 + resp)))
        ours.append({"axis": name.removeprefix("i_ref_"), "gain_margin_db": float(20 * np.log10(gm)),
                     "gain_margin_hz": float(w180 / TAU), "phase_margin_deg": float(pm), "phase_margin_hz": float(wc / TAU),
                     "s_peak_db": float(20 * np.log10(s_peak)), "s_peak_hz": float(grid[np.argmax(np.abs(1 / (1 + resp)))] / TAU)})

    # The closed loop's poles (the other loops closed too): their largest modulus.
    largest_pole = float(np.max(np.abs(ct.feedback(plant_d, law_d, sign=+1).poles())))

    # 4. The report card: the sensitivity at the speed (the ladder is `plant assess`'s
    # default parts; left out here: the shock run below is the one that matters).
    points = 24 if quick else 40
    assessment = out / "assess.toml"
    assessment.write_text(
        f'scene = {json.dumps(str(scene.resolve()))}\nparts = ["sensitivity"]\n'
        f"set = {json.dumps(sets)}\n"
        f'[[controller]]\nlabel = "lead-lag-notch"\nset = []\n'
        f'[sensitivity]\nspeeds = ["rated"]\npoints = {points}\nf_min_hz = 5.0\nf_max_hz = 2000.0\n')
    run(plant, "assess", assessment, "--out", out / "assess", "--quiet")
    card = json.loads((out / "assess" / "report.json").read_text())
    sens = card["controllers"][0]["sensitivity"]["result"]
    margins = {m["axis"]: m for m in sens["margins"]}
    peaks = {a["axis"]: a["peak"] for a in sens["axes"]}
    forms = {f["axis"]: f for f in sens["closed_form_axes"]}

    # 5. The shock.
    duration = ["--set", "scene.duration_s=0.1"] if quick else []
    sets_run = [x for s in sets for x in ("--set", s)]
    run(plant, "run", scene, *sets_run, *duration, "--set", "output.plots=false", "--out", out / "shock")

    rows = []
    for o in ours:
        m = margins[o["axis"]]
        c = m["computed"] or {}
        me = m["measured"] or {}
        o["largest_pole"] = largest_pole
        form = {k: v for k, v in forms.get(o["axis"], {}).items() if k != "curve"}
        rows.append({"python_control": o, "computed": c, "measured": me, "peak": peaks[o["axis"]],
                     "closed_form": form})
        print(f"{o['axis']}: PM {o['phase_margin_deg']:.3f} deg at {o['phase_margin_hz']:.2f} Hz "
              f"(card: computed {c.get('phase_margin_deg')}, measured {me.get('phase_margin_deg')}); "
              f"GM {o['gain_margin_db']:.3f} dB at {o['gain_margin_hz']:.2f} Hz "
              f"(card: computed {c.get('gain_margin_db')} at {c.get('gain_margin_hz')} Hz); "
              f"|S| peak {o['s_peak_db']:.3f} dB at {o['s_peak_hz']:.1f} Hz "
              f"(card: {peaks[o['axis']]['s_db']:.3f} dB at {peaks[o['axis']]['f_hz']:.1f} Hz measured, "
              f"{form.get('s_db')} dB at {form.get('f_hz')} Hz closed form); "
              f"largest closed-loop pole {largest_pole:.12f} (card: {form.get('largest_pole')})")
    (out / "figures.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
