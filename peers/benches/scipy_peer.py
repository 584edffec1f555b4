#!/usr/bin/env python3
"""scipy's solve_ivp(method="DOP853") on the peers benchmark's problem (issue 13, point 4).

Run by `cargo bench --no-default-features --bench peers` at its end, in the same session, when
python3 with scipy is installed; by hand: `python3 benches/scipy_peer.py FILE.json`, FILE.json
written by that bench (the problem, the exact θ at the sample times, physlab's cheapest time per
target error).

The problem and the error measure are the bench's: the pendulum θ'' = -(g/L) sin θ from rest at
60°, 20 s, error = max |θ - θ_exact| over the 200 sample times (0.1 s apart). scipy runs with
rtol = atol = tol over the same half-decade grid (1e-2 to 1e-14), samples through t_eval (its
dense output), and each run is timed as the minimum of REPEATS runs (wall clock,
time.perf_counter). The right-hand side is plain Python with math.sin, as a user would write it.
Prints, per target, scipy's cheapest run reaching it and the ratio scipy time / physlab time.
"""

import json
import math
import sys
import time

REPEATS = 5


def main() -> int:
    try:
        import numpy as np
        import scipy
        from scipy.integrate import solve_ivp
    except ImportError:
        print("scipy is not installed: the scipy comparison is skipped (pip install scipy)")
        return 0
    with open(sys.argv[1]) as f:
        d = json.load(f)
    k, theta0, duration = d["g_over_l"], d["theta0"], d["duration"]
    times = np.array(d["times"])
    exact = np.array(d["exact"])

    def rhs(_t, y):
        return [y[1], -k * math.sin(y[0])]

    runs = []
    for e in range(4, 29):
        tol = 10.0 ** (-e / 2.0)
        best = math.inf
        for _ in range(REPEATS):
            t0 = time.perf_counter()
            sol = solve_ivp(rhs, (0.0, duration), [theta0, 0.0], method="DOP853",
                            t_eval=times, rtol=tol, atol=tol)
            best = min(best, time.perf_counter() - t0)
        if sol.status != 0 or sol.y.shape[1] != len(times):
            continue
        err = float(np.max(np.abs(sol.y[0] - exact)))
        runs.append((tol, err, best, sol.nfev))

    print(f"\nscipy {scipy.__version__} solve_ivp(method=\"DOP853\") against physlab, same session "
          f"(min of {REPEATS} runs; Python {sys.version.split()[0]}):")
    print("| target | scipy (cheapest) | time [µs] | evaluations | physlab (cheapest) | time [µs] "
          "| scipy / physlab |")
    print("|---|---|---|---|---|---|---|")
    worst = math.inf
    for target, ours in zip(d["targets"], d["physlab_best"]):
        ok = [r for r in runs if r[1] <= target]
        if not ok or ours is None:
            print(f"| {target:.0e} | none reached it | — | — | — | — | — |")
            continue
        tol, err, t, nfev = min(ok, key=lambda r: r[2])
        ratio = t / ours["seconds"]
        worst = min(worst, ratio)
        print(f"| {target:.0e} | rtol {tol:.1e} (error {err:.1e}) | {t * 1e6:.0f} | {nfev} "
              f"| {ours['setting']} | {ours['seconds'] * 1e6:.1f} | {ratio:.0f} |")
    if worst < math.inf:
        print(f"\nphyslab is at least {worst:.0f}x faster than scipy at every target it reaches "
              f"(goal: 100x).")
    return 0


if __name__ == "__main__":
    sys.exit(main())
