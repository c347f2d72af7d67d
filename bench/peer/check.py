#!/usr/bin/env python3
"""Checks the Python derivative (model.py) against the Rust one, sample by sample.

    python check.py SPEC.json [SPEC.json ...] [--tol 1e-12] [--floor 1e-300] [--no-numba]

SPEC.json is written by ``cargo run --release -p plant --example peer_dump``;
its ``samples`` hold random states y at times t with the Rust derivative dy.
For every sample and component i the disagreement is

    err_i = |dy_py_i − dy_rust_i| / max(|dy_rust_i|, floor)

and the check passes when every err_i ≤ tol (default 1e-12). The floor
(default 1e-300, i.e. purely relative) only keeps 0/0 defined: a component
the Rust model returns as exactly 0 (held spin ω̇_r, a race at rest with no
contact, a velocity copied from a zero state) must be exactly 0 in Python too.
No component scale is needed: both implementations run the same operations
in the same order on the same libm, so they agree bit for bit unless
something is wrong. Both back ends are checked: the numba-compiled one (unless
``--no-numba`` or numba is missing) and the pure-Python fallback.

Prints the worst case (sample, kind, component, both values) and how many
components agree bit for bit; exits 1 on failure.
"""

import argparse
import sys

import numpy as np

import model as peer


def check(spec_path, tol, floor, use_numba):
    spec = peer.load_spec(spec_path)
    m = peer.Model(spec, use_numba=use_numba)
    samples = spec["samples"]
    worst = (0.0, None)
    n_exact = 0
    n_total = 0
    failures = 0
    for k, s in enumerate(samples):
        y = np.array(s["y"], dtype=np.float64)
        want = np.array(s["dy"], dtype=np.float64)
        got = m.rhs(float(s["t"]), y)
        if not np.all(np.isfinite(got)):
            print(f"  sample {k} ({s['kind']}): non-finite derivative {got}")
            failures += 1
            continue
        denom = np.maximum(np.abs(want), floor)
        err = np.abs(got - want) / denom
        n_exact += int(np.sum(got == want))
        n_total += peer.N
        i = int(np.argmax(err))
        if err[i] > worst[0] or worst[1] is None:
            worst = (float(err[i]), (k, s["kind"], i, float(got[i]), float(want[i]), s["t"]))
        bad = np.nonzero(err > tol)[0]
        for i in bad:
            failures += 1
            if failures <= 20:
                print(f"  FAIL sample {k} ({s['kind']}, t={s['t']!r}) d/dt {peer.STATE_NAMES[i]}: "
                      f"python {float(got[i])!r} rust {float(want[i])!r} rel {err[i]:.3e}")
    backend = "numba" if m.use_numba else "pure-python"
    e, where = worst
    k, kind, i, got_i, want_i, t = where
    print(f"{spec_path} [{backend}]: {len(samples)} samples, {n_total} components, "
          f"{n_exact} bit-identical; worst rel. disagreement {e:.3e} "
          f"(sample {k}, {kind}, t={t!r}, d/dt {peer.STATE_NAMES[i]}: python {got_i!r}, rust {want_i!r})"
          f" -> {'PASS' if failures == 0 else 'FAIL'} at {tol:g}")
    return failures == 0, e


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("specs", nargs="+", help="peer spec JSON file(s) from peer_dump")
    ap.add_argument("--tol", type=float, default=1e-12, help="largest relative disagreement (default 1e-12)")
    ap.add_argument("--floor", type=float, default=1e-300,
                    help="denominator floor: err = |py - rust| / max(|rust|, floor) (default 1e-300)")
    ap.add_argument("--no-numba", action="store_true", help="check the pure-Python back end only")
    args = ap.parse_args()
    backends = [False] if (args.no_numba or not peer.HAVE_NUMBA) else [True, False]
    ok = True
    worst = 0.0
    for path in args.specs:
        for use_numba in backends:
            passed, e = check(path, args.tol, args.floor, use_numba)
            ok &= passed
            worst = max(worst, e)
    print(f"overall: worst relative disagreement {worst:.3e}: {'PASS' if ok else 'FAIL'}")
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
