#!/usr/bin/env python3
"""The stability limits of the higher-order compositions of position Verlet on x'' = -x.

One drift-kick-drift step of size t maps (x, v) by

    M(t) = [[1 - t^2/2, t - t^3/4],
            [-t,        1 - t^2/2]]      (det M = 1),

and a composition of weights w_1 ... w_s takes the step M(w_s h) ... M(w_1 h). It is stable while
|trace| < 2. For these compositions the trace can come back below 2 past its first crossing
(stability intervals with gaps), so the limit is the FIRST h > 0 at which |trace| exceeds 2: a
scan on a grid of 1e-4 finds the first grid point past 2 and findroot the crossing in that cell.
The script also prints where the trace goes back below 2 (the end of the first gap), to show the
gaps. The weights are those of src/integrate/composition.rs, typed here from the same sources
(Yoshida 1990 solution A as GNI prints it, Kahan & Li s17odr8a, Sofroniou & Spaletta s35odr10).

    python3 tests/data/composition_stability.py     # needs mpmath
"""

from mpmath import mp, mpf, findroot, matrix

mp.dps = 40


def palindrome(half):
    half = [mpf(w) for w in half]
    return half + half[-2::-1]


Y6 = ["0.784513610477557263819497633866349875", "0.235573213359358133684793182978534602",
      "-1.17767998417887100694641568096431573"]
Y6 = Y6 + [str(1 - 2 * sum(mpf(w) for w in Y6))]
KL8 = ["0.13020248308889008087881763", "0.56116298177510838456196441",
       "-0.38947496264484728640807860", "0.15884190655515560089621075",
       "-0.39590389413323757733623154", "0.18453964097831570709183254",
       "0.25837438768632204729397911", "0.29501172360931029887096624",
       "-0.60550853383003451169892108"]
SS10 = ["0.078795722521686419263907679337684", "0.31309610341510852776481247192647",
        "0.027918383235078066109520273275299", "-0.22959284159390709415121339679655",
        "0.13096206107716486317465685927961", "-0.26973340565451071434460973222411",
        "0.074973343155891435666137105641410", "0.11199342399981020488957508073640",
        "0.36613344954622675119314812353150", "-0.39910563013603589787862981058340",
        "0.10308739852747107731580277001372", "0.41143087395589023782070411897608",
        "-0.0048663605831352617621956593099771", "-0.39203335370863990644808193642610",
        "0.051942502962449647037182904015976", "0.050665090759924496335874344156866",
        "0.049674370639729879054568800279461", "0.049317735759594537917680008339338"]


def m(t):
    return matrix([[1 - t**2 / 2, t - t**3 / 4], [-t, 1 - t**2 / 2]])


def trace(weights, h):
    p = matrix([[1, 0], [0, 1]])
    for w in weights:
        p = m(w * h) * p
    return p[0, 0] + p[1, 1]


for name, half in [("yoshida6", Y6), ("kahan-li8", KL8), ("sofroniou10", SS10)]:
    w = palindrome(half)
    assert abs(sum(w) - 1) < mpf(10) ** -25
    grid = mpf("1e-4")
    k = 1
    while abs(trace(w, k * grid)) <= 2:
        k += 1
    lo, hi = (k - 1) * grid, k * grid
    sign = 1 if trace(w, hi) > 0 else -1
    limit = findroot(lambda h: trace(w, h) - 2 * sign, (lo, hi), solver="anderson")
    j = k
    while abs(trace(w, j * grid)) > 2 and j * grid < 6:
        j += 1
    back = "none below 6" if j * grid >= 6 else mp.nstr(j * grid, 6)
    print(f"{name}: stability limit h* = {mp.nstr(limit, 30)} (trace {'+' if sign > 0 else '-'}2; "
          f"stable again near h = {back})")
