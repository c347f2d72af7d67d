#!/usr/bin/env python3
"""Work-precision runs of the Python peer with scipy's solve_ivp.

    python run_peer.py SPEC.json REFERENCE.csv [--scene NAME] [--out peer.csv]
        [--methods RK45,DOP853,LSODA] [--rtols 1e-3,1e-4,...] [--repeats 5]
        [--atol 1e-9] [--timeout 600] [--no-python-solve]

SPEC.json comes from ``cargo run --release -p plant --example peer_dump``;
REFERENCE.csv has columns ``t_s,dx_m,dy_m``: the reference rotor position
relative to the housing on the controller-tick grid over the error window
(the Rust bench writes it). For each method and rtol the peer integrates the
scene from y0 over [0, duration] with ``solve_ivp``, evaluating its dense
output on the reference's time grid (``t_eval``), and writes one row:

    error per grid point = |(dx, dy)_peer − (dx, dy)_ref| / r0  → err_rms, err_max
    wall_s_per_sim_s     = wall time of the solve_ivp call (minimum of --repeats
                           runs; a single run when it takes over 60 s) / duration
    rhs_evals            = derivative evaluations (solve_ivp's nfev; for LSODA it
                           includes those of its finite-difference Jacobians)

Absolute tolerance: ``atol_i = rtol × atol_scale_i`` when the spec has an
``atol_scale`` array (peer_dump --atol-scale), else the scalar ``--atol``
(default 1e-9, the scene default); the ``setting`` column says which.

A run that ends with solve_ivp status < 0, produces non-finite values, or takes
longer than --timeout seconds (default 600) is a row with status ``failed``
(error columns empty), not dropped. Each run executes in a forked child so a
hung run can be stopped. The derivative is numba-compiled and warmed up
before any timing. Afterwards the pure-Python derivative is timed per call
and, unless --no-python-solve, in one RK45 rtol=1e-6 solve, to report the
numba speed-up; these figures, the timing repeats and the library versions
go to OUT with the suffix ``.json`` and to stdout.
"""

import argparse
import csv
import json
import math
import multiprocessing as mp
import os
import platform
import sys
import time
import traceback

import numpy as np
import scipy
from scipy.integrate import solve_ivp

import model as peer

COLUMNS = ["scene", "implementation", "method", "setting", "rtol", "substeps", "status", "err_rms", "err_max",
           "wall_s_per_sim_s", "rhs_evals", "sim_s"]
DEFAULT_RTOLS = [1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10]
LONG_RUN_S = 60.0


def fmt_num(x):
    """Short text for a number: 1e-06 → 1e-6, 0.001 → 1e-3, 2.5e-07 → 2.5e-7."""
    return np.format_float_scientific(x, trim="-", exp_digits=1)


def read_reference(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    for col in ("t_s", "dx_m", "dy_m"):
        if col not in rows[0]:
            raise SystemExit(f"{path}: missing column {col} (need t_s,dx_m,dy_m)")
    t = np.array([float(r["t_s"]) for r in rows])
    xy = np.array([[float(r["dx_m"]), float(r["dy_m"])] for r in rows])
    if np.any(np.diff(t) <= 0):
        raise SystemExit(f"{path}: t_s must increase strictly")
    return t, xy


def solve_once(rhs, y0, duration, method, rtol, atol, t_grid):
    t0 = time.perf_counter()
    sol = solve_ivp(rhs, (0.0, duration), y0, method=method, rtol=rtol, atol=atol, t_eval=t_grid)
    wall = time.perf_counter() - t0
    return sol, wall


def errors(sol, t_grid, ref_xy, r0):
    """(err_rms, err_max) of the rotor position against the reference, scaled by r0; None if incomplete."""
    if sol.y.shape[1] != len(t_grid) or not np.all(np.isfinite(sol.y)):
        return None
    d = np.hypot(sol.y[0] - ref_xy[:, 0], sol.y[1] - ref_xy[:, 1]) / r0
    return float(np.sqrt(np.mean(d * d))), float(np.max(d))


def child(conn, rhs, y0, duration, method, rtol, atol, t_grid, ref_xy, r0, repeats):
    """Runs one setting `repeats` times (once if a run exceeds LONG_RUN_S); sends a dict per run."""
    try:
        for k in range(repeats):
            sol, wall = solve_once(rhs, y0, duration, method, rtol, atol, t_grid)
            msg = {"wall": wall, "status": int(sol.status), "message": str(sol.message), "nfev": int(sol.nfev),
                   "njev": int(getattr(sol, "njev", 0)), "t_end": float(sol.t[-1]) if len(sol.t) else 0.0}
            if k == 0:
                msg["err"] = errors(sol, t_grid, ref_xy, r0) if sol.status >= 0 else None
            conn.send(msg)
            if sol.status < 0 or wall > LONG_RUN_S:
                break
    except Exception:  # a crash in the solver is a failed run
        conn.send({"exception": traceback.format_exc()})
    finally:
        conn.send(None)
        conn.close()


def run_setting(rhs, y0, duration, method, rtol, atol, t_grid, ref_xy, r0, repeats, timeout):
    """Runs a setting in a forked child; returns a result dict."""
    ctx = mp.get_context("fork")
    recv, send = ctx.Pipe(duplex=False)
    p = ctx.Process(target=child, args=(send, rhs, y0, duration, method, rtol, atol, t_grid, ref_xy, r0, repeats))
    p.start()
    send.close()
    runs = []
    failure = None
    while True:
        if not recv.poll(timeout):
            failure = f"timeout: no result within {timeout:g} s"
            p.kill()
            break
        try:
            msg = recv.recv()
        except EOFError:
            failure = failure or "the run's process died"
            break
        if msg is None:
            break
        if "exception" in msg:
            failure = "exception: " + msg["exception"].strip().splitlines()[-1]
            continue
        runs.append(msg)
    p.join()
    res = {"runs": runs, "failure": failure}
    if failure is None and runs:
        first = runs[0]
        if first["status"] < 0:
            res["failure"] = f"solve_ivp status {first['status']}: {first['message']}"
        elif first.get("err") is None:
            res["failure"] = "non-finite or incomplete solution"
    elif failure is None:
        res["failure"] = "no run completed"
    return res


def time_per_call(rhs, samples, min_time=0.5):
    """Mean wall time of one derivative call (s) over the given (t, y) samples."""
    n = 0
    t0 = time.perf_counter()
    while True:
        for t, y in samples:
            rhs(t, y)
        n += len(samples)
        el = time.perf_counter() - t0
        if el >= min_time:
            return el / n


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("spec")
    ap.add_argument("reference")
    ap.add_argument("--scene", help="scene name for the CSV (default: the spec's)")
    ap.add_argument("--out", default="peer.csv")
    ap.add_argument("--methods", default="RK45,DOP853,LSODA")
    ap.add_argument("--rtols", default=",".join(fmt_num(r) for r in DEFAULT_RTOLS))
    ap.add_argument("--repeats", type=int, default=5, help="timed runs per setting; the minimum is kept")
    ap.add_argument("--atol", type=float, default=1e-9, help="scalar atol when the spec has no atol_scale")
    ap.add_argument("--timeout", type=float, default=600.0, help="a run longer than this (s) fails")
    ap.add_argument("--no-python-solve", action="store_true",
                    help="skip the RK45 rtol=1e-6 solve with the pure-Python derivative")
    args = ap.parse_args()

    spec = peer.load_spec(args.spec)
    scene = args.scene or spec["scene"]
    model = peer.Model(spec, use_numba=True)
    if not model.use_numba:
        print("warning: numba unavailable, timing the pure-Python derivative", file=sys.stderr)
    duration = model.duration
    r0 = model.r0
    t_ref, ref_xy = read_reference(args.reference)
    if t_ref[0] < 0 or t_ref[-1] > duration * (1 + 1e-12):
        raise SystemExit(f"{args.reference}: times {t_ref[0]}..{t_ref[-1]} s fall outside [0, {duration}] s")
    t_grid = np.minimum(t_ref, duration)
    y0 = model.y0
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    rtols = [float(r) for r in args.rtols.split(",") if r.strip()]
    scale = spec.get("atol_scale")
    if scale is not None:
        scale = np.array(scale, dtype=np.float64)
        atol_text = "atol=rtol*scale"
    else:
        atol_text = f"atol={fmt_num(args.atol)}"

    # Warm up: compile the derivative, then let each method take a few steps.
    t0 = time.perf_counter()
    model.warm_up()
    compile_s = time.perf_counter() - t0
    for method in methods:
        solve_ivp(model.rhs, (0.0, 1e-4), y0, method=method, rtol=1e-6, atol=1e-9)
    print(f"{scene}: duration {duration:g} s, r0 {r0:g} m, {len(t_grid)} reference points "
          f"[{t_grid[0]:g}, {t_grid[-1]:g}] s; numba compile {compile_s:.2f} s; {atol_text}")

    rows = []
    details = []
    for method in methods:
        for rtol in rtols:
            atol = rtol * scale if scale is not None else args.atol
            res = run_setting(model.rhs, y0, duration, method, rtol, atol, t_grid, ref_xy, r0, args.repeats,
                              args.timeout)
            runs = res["runs"]
            setting = f"rtol={fmt_num(rtol)} {atol_text}"
            row = {"scene": scene, "implementation": "scipy", "method": method, "setting": setting,
                   "rtol": fmt_num(rtol), "substeps": ""}
            walls = [r["wall"] for r in runs if "wall" in r]
            if res["failure"]:
                wall = min(walls) if walls else args.timeout
                row.update(status="failed", err_rms="", err_max="", wall_s_per_sim_s=repr(wall / duration),
                           rhs_evals=str(runs[0]["nfev"]) if runs else "",
                           sim_s=repr(runs[0]["t_end"]) if runs else "")
                print(f"  {method:6s} rtol={fmt_num(rtol):6s} FAILED: {res['failure']}")
            else:
                first = runs[0]
                err_rms, err_max = first["err"]
                wall = min(walls)
                if len(walls) < args.repeats:
                    row["setting"] = f"{setting} timed_runs={len(walls)}"
                row.update(status="ok", err_rms=repr(err_rms), err_max=repr(err_max),
                           wall_s_per_sim_s=repr(wall / duration), rhs_evals=str(first["nfev"]), sim_s=repr(duration))
                print(f"  {method:6s} rtol={fmt_num(rtol):6s} err rms {err_rms:.3e} max {err_max:.3e}  "
                      f"wall {wall:.4g} s ({wall / duration:.4g} s/sim s, {len(walls)} run(s))  "
                      f"nfev {first['nfev']}" + (f" njev {first['njev']}" if first["njev"] else ""))
            rows.append(row)
            details.append({"method": method, "rtol": rtol, "failure": res["failure"], "walls_s": walls,
                            "nfev": runs[0]["nfev"] if runs else None, "njev": runs[0]["njev"] if runs else None,
                            "status": runs[0]["status"] if runs else None,
                            "message": runs[0]["message"] if runs else None})

    with open(args.out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS)
        w.writeheader()
        w.writerows(rows)

    # Numba against the pure-Python derivative (same source).
    pure = peer.Model(spec, use_numba=False)
    samples = [(float(s["t"]), np.array(s["y"], dtype=np.float64)) for s in spec.get("samples", [])][:100]
    samples = samples or [(0.0, y0)]
    per_call_nb = time_per_call(model.rhs, samples)
    per_call_py = time_per_call(pure.rhs, samples)
    speed = {"per_call_numba_s": per_call_nb, "per_call_python_s": per_call_py,
             "per_call_speedup": per_call_py / per_call_nb}
    print(f"derivative per call: numba {per_call_nb * 1e6:.3f} µs, pure Python {per_call_py * 1e6:.3f} µs "
          f"(×{per_call_py / per_call_nb:.1f}; both through the solve_ivp calling convention)")
    if not args.no_python_solve:
        atol = 1e-6 * scale if scale is not None else args.atol
        solves = {}
        for name, m in (("numba", model), ("python", pure)):
            res = run_setting(m.rhs, y0, duration, "RK45", 1e-6, atol, t_grid, ref_xy, r0, 1, args.timeout)
            solves[name] = None if res["failure"] else res["runs"][0]["wall"]
        if solves["numba"] and solves["python"]:
            speed.update(rk45_1e6_numba_s=solves["numba"], rk45_1e6_python_s=solves["python"],
                         rk45_1e6_speedup=solves["python"] / solves["numba"])
            print(f"RK45 rtol=1e-6 solve (one run each): numba {solves['numba']:.3f} s, pure Python "
                  f"{solves['python']:.3f} s (×{solves['python'] / solves['numba']:.2f})")

    meta = {"scene": scene, "spec": os.path.abspath(args.spec), "reference": os.path.abspath(args.reference),
            "duration_s": duration, "r0_m": r0, "reference_points": len(t_grid),
            "error_window_s": [float(t_grid[0]), float(t_grid[-1])], "atol": atol_text,
            "atol_scale": None if scale is None else scale.tolist(), "scalar_atol": None if scale is not None else args.atol,
            "repeats": args.repeats, "long_run_s": LONG_RUN_S, "timeout_s": args.timeout,
            "numba_compile_s": compile_s, "speed": speed, "runs": details,
            "versions": {"python": platform.python_version(), "numpy": np.__version__, "scipy": scipy.__version__,
                         "numba": getattr(peer.numba, "__version__", None)},
            "machine": {"cpu_count": os.cpu_count(), "platform": platform.platform()}}
    root, _ = os.path.splitext(args.out)
    with open(root + ".json", "w") as f:
        json.dump(meta, f, indent=1)
    print(f"wrote {args.out} and {root}.json")


if __name__ == "__main__":
    main()
