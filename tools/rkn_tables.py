#!/usr/bin/env python3
"""Writes the body of src/integrate/rkn_tables.rs (after its header) to stdout.

Usage: python3 tools/rkn_tables.py PATH/TO/rkn_tableaus.jl > body.rs
with OrdinaryDiffEq's lib/OrdinaryDiffEqRKN/src/rkn_tableaus.jl (commit b211787f7b18). Needs mpmath.
DPRKN12 and DPRKN8 from their exact rationals (fractions), DPRKN6 from its closed forms in
sqrt(8581) (80 digits), each value rounded once to a double; DPRKN12's and DPRKN8's dense outputs
built in exact arithmetic (FREE, FREE8: the pair's stages used as interior data; ROUNDS, ROUNDS8:
the bootstrapped points, rounds separated by ';'; see the header of rkn_tables.rs).
"""
import os, re, sys
from fractions import Fraction as F
from mpmath import mp, mpf, sqrt
mp.dps = 80
src = open(sys.argv[1]).read()

def body(name):
    i = src.index('function %s(' % name)
    j = src.index('\nend\n', i)
    return src[i:j]

def julia_to_py(text, exact=True):
    t = re.sub(r'parse\(BigInt,\s*"(-?\d+)"\)', r'\1', text)
    t = re.sub(r'Int64\((-?\d+)\)', r'\1', t)
    t = re.sub(r'convert\(\s*T2?,', 'cv(', t)
    t = t.replace('zero(T)', '0').replace('one(T2)', '1').replace('zero(T2)', '0')
    return t

class M(dict):
    pass

def dprkn12():
    b = body('DPRKN12Tableau')
    lines = b.split('\n')[1:]  # drop signature
    code = '\n'.join(l for l in lines if not l.strip().startswith('return') and 'zeros(T' not in l)
    code = julia_to_py(code)
    # integer literals -> Fraction, // -> /
    code = re.sub(r'(?<![\w.])(\d+)(?![\w.])', r'F(\1)', code)
    code = code.replace('//', '/')
    code = code.replace('T2[', '[').replace(';', '\n')
    # dedent
    code = '\n'.join(l.strip() for l in code.split('\n'))
    # join continuation lines: execute via compile of the whole text inside brackets is fine in python
    env = {'F': F, 'cv': lambda x: x, 'a': M()}
    exec(code, env)
    a = env['a']
    A = [[F(0)] * 17 for _ in range(17)]
    for (i, j), v in a.items():
        A[int(i) - 1][int(j) - 1] = v
    c = [F(0)] + env['c']
    return dict(A=A, c=c, b=env['b'], bp=env['bp'], btilde=env['btilde'], bptilde=env['bptilde'])


def dprkn8():
    """DPRKN8's exact rationals (all of its entries are), parsed from its Julia function."""
    b = body('DPRKN8Tableau')
    frac = r'(-?[\d_]+) // ([\d_]+)'
    num = lambda m, k: int(m.group(k).replace('_', ''))
    A = [[F(0)] * 9 for _ in range(9)]
    for m in re.finditer(r'a\[(\d+), (\d+)\] = convert\(T, ' + frac + r'\)', b):
        A[int(m.group(1)) - 1][int(m.group(2)) - 1] = F(num(m, 3), num(m, 4))
    def vec(name):
        i = b.index(name + ' = ')
        text = b[i:b.index(']', i)]
        out = []
        for item in text[text.index('[') + 1:].split('convert(T')[1:]:
            terms = re.findall(r'([+-]?)\s*([\d_]+) // ([\d_]+)', item)
            v = F(0)
            for sign, n, d in terms:
                v += (-1 if sign == '-' else 1) * F(int(n.replace('_', '')), int(d.replace('_', '')))
            out.append(v)
        full, it = [], iter(out)
        for m in re.finditer(r'zero\(T\)|convert\(T', text):
            full.append(F(0) if m.group(0) == 'zero(T)' else next(it))
        return full
    c = [F(0), F(1, 20), F(1, 10), F(3, 10), F(1, 2), F(7, 10), F(9, 10), F(1), F(1)]
    cj = re.findall(r'convert\(T2, (\d+) // (\d+)\)|one\(T2\)', b[b.index('c = T2['):])
    assert [F(int(n), int(d)) if n else F(1) for n, d in cj] == c[1:]
    return dict(A=A, c=c, b=vec('b'), bp=vec('bp'), btilde=vec('btilde'), bptilde=vec('bptilde'))

def body_at(marker):
    i = src.index(marker)
    j = src.index('\nend\n', i)
    return src[i:j]

def dprkn6_exact():
    b = body_at('function DPRKN6Tableau(::Type{T}')
    lines = b.split('\n')[1:]
    out = []
    for l in lines:
        s = l.strip()
        if s.startswith('return') or s.startswith('#'):
            break_ = s.startswith('return')
            if break_: break
            continue
        out.append(s)
    code = '\n'.join(out)
    code = code.replace('sqrt(big(8581))', 'sqrt(mpf(8581))')
    code = julia_to_py(code)
    code = re.sub(r'(\d)R\b', r'\1*R', code)
    code = re.sub(r'(\d)\(', r'\1*(', code)
    code = re.sub(r'(?<![\w.])(\d[\d_]*)(?![\w.(])', lambda m: "mpf(%d)" % int(m.group(1).replace('_', '')), code)
    code = code.replace('//', '/').replace('T2[', '[')
    env = {'mpf': mpf, 'sqrt': sqrt, 'cv': lambda x: x}
    exec(code, env)
    return env

def dprkn6_floats():
    b = body_at('function DPRKN6Tableau(T::Type{<:CompiledFloats}')
    d = {}
    for m in re.finditer(r'(\w+) = convert\(T2?, ([-\d.e]+)\)', b):
        d[m.group(1)] = float(m.group(2))
    return d

from fractions import Fraction as F

def birkhoff(points):
    """Q(θ) = Σ_k q_k θ^k, degree 5+m, Q(0)=Q'(0)=0: coefficients of Q as linear combos of data
    [a0, D, E, a1, a_pts...]. Returns list over data of coefficient lists (θ^0..θ^deg)."""
    m = len(points); deg = 5 + m; nu = deg - 1  # unknowns q2..q_deg
    rows = []
    def d2(th):  # Q''(th) row over q2..qdeg
        return [F(k * (k - 1)) * th ** (k - 2) if k >= 2 else F(0) for k in range(2, deg + 1)]
    rows.append(d2(F(0)))                                  # a0
    rows.append([F(1)] * nu)                               # D = Q(1)
    rows.append([F(k) for k in range(2, deg + 1)])         # E = Q'(1)
    rows.append(d2(F(1)))                                  # a1
    for p in points:
        rows.append(d2(p))
    n = len(rows)
    # invert rows (n x n) exactly
    Mx = [r[:] + [F(int(i == j)) for j in range(n)] for i, r in enumerate(rows)]
    for col in range(n):
        piv = next(r for r in range(col, n) if Mx[r][col] != 0)
        Mx[col], Mx[piv] = Mx[piv], Mx[col]
        pv = Mx[col][col]
        Mx[col] = [x / pv for x in Mx[col]]
        for r in range(n):
            if r != col and Mx[r][col] != 0:
                f = Mx[r][col]
                Mx[r] = [x - f * y for x, y in zip(Mx[r], Mx[col])]
    inv = [r[n:] for r in Mx]
    # q = inv @ data ; coefficient of θ^k (k=2..deg) for datum d: inv[k-2][d]
    return [[F(0), F(0)] + [inv[k - 2][d] for k in range(2, deg + 1)] for d in range(n)]

def ext_weights(nst, bbar, b, fsal, pts_idx, points):
    """Position weights B̄_i(θ) as coefficient lists over all stages (h² part)."""
    basis = birkhoff(points)
    deg = len(basis[0]) - 1
    W = [[F(0)] * (deg + 1) for _ in range(nst)]
    def add(i, coeffs, f):
        for k in range(deg + 1):
            W[i][k] += f * coeffs[k]
    add(0, basis[0], 1)
    for i in range(len(bbar)):
        add(i, basis[1], bbar[i]); add(i, basis[2], b[i])
    add(fsal, basis[3], 1)
    for j, idx in enumerate(pts_idx):
        add(idx, basis[4 + j], 1)
    return W

def evalp(cf, th):
    return sum(c * th ** k for k, c in enumerate(cf))

import os
from mpmath import mpf, nstr
from fractions import Fraction as F

def fl(x):
    if isinstance(x, F):
        v = float(x)
    else:
        v = float(nstr(x, 40, strip_zeros=False))
    if v == 0:
        return '0.0'
    r = repr(v)
    return r

def rows_lit(name, rows, doc):
    out = [doc, '#[rustfmt::skip]', 'pub(super) const %s: &[&[f64]] = &[' % name]
    for r in rows:
        out.append('    &[%s],' % ', '.join(fl(x) for x in r))
    out.append('];')
    return '\n'.join(out)

def vec_lit(name, v, doc, test=False):
    pre = '#[cfg(test)]\n' if test else ''
    return '%s%s\n#[rustfmt::skip]\npub(super) const %s: [f64; %d] = [%s];' % (doc, pre, name, len(v), ', '.join(fl(x) for x in v))

def point_lists(text):
    return [[F(p) for p in r.split(',')] for r in text.split(';')] if text else []

def extend(A, c, bbar, b, s, free, rounds):
    """Stages 0..s-1 of the pair, the FSAL stage s (a(x1), ā = b̄), then the bootstrapped rounds
    (lists of θ): the first interpolant uses the pair's own stages `free` as interior data, each
    round's interpolant goes through the previous round's points."""
    bbar, b = list(bbar[:s]), list(b[:s])
    nst = s + 1 + sum(len(r) for r in rounds)
    Ae = [list(A[i][:i]) for i in range(s)]
    ce = list(c[:s])
    Ae.append(list(bbar)); ce.append(F(1))
    prev_pts, prev_idx = [c[i] for i in free], list(free)
    for r in rounds:
        cur = len(Ae)
        W = ext_weights(cur, bbar + [F(0)] * (cur - s), b + [F(0)] * (cur - s), s, prev_idx, prev_pts)
        idx = []
        for p in r:
            Ae.append([evalp(W[i], p) for i in range(cur)]); ce.append(p); idx.append(len(Ae) - 1)
        prev_pts, prev_idx = r, idx
    W = ext_weights(nst, bbar + [F(0)] * (nst - s), b + [F(0)] * (nst - s), s, prev_idx, prev_pts)
    return Ae, ce, W

def poly_tables(W, nst):
    deg = len(W[0]) - 1
    return [[W[i][k] for i in range(nst)] for k in range(deg + 1)]

def pair_tables(tag, Ae, ce, bbar, b, ebar, e, PX, doc):
    """A pair's tables, named NAME + tag, each with its doc comment from `doc`."""
    bbh = [x - y for x, y in zip(bbar, ebar)]; bh = [x - y for x, y in zip(b, e)]
    return [
        rows_lit('A' + tag, Ae, doc['A']),
        vec_lit('C' + tag, ce, doc['C']),
        vec_lit('BBAR' + tag, bbar, doc['BBAR']),
        vec_lit('B' + tag, b, doc['B']),
        vec_lit('EBAR' + tag, ebar, doc['EBAR']),
        vec_lit('E' + tag, e, doc['E']),
        vec_lit('BBAR%s_HAT' % tag, bbh, doc['HAT'], True),
        vec_lit('B%s_HAT' % tag, bh, '', True),
        rows_lit('PX' + tag, PX, doc['PX']),
    ]

def bootstrapped_px_doc(tag):
    return ('/// The dense output\'s position weights B̄_i(θ) = Σ_k PX%s[k][i] θ^k over every stage; its\n'
            '/// velocity weights are their derivative, B_i(θ) = dB̄_i/dθ.' % tag)

out = []
t = dprkn12()
A, c, bbar, b = t['A'], t['c'], t['b'], t['bp']
# DPRKN12: its stages at c = 1/4, 1/2, 3/4 (positions of local order 7), then one round.
Ae, ce, W = extend(A, c, bbar, b, 17, [int(i) for i in os.environ.get('FREE', '8,10,12').split(',')],
                   point_lists(os.environ.get('ROUNDS', '1/6,1/3,1/2,2/3,5/6')))
out += pair_tables('12', Ae, ce, bbar, b, t['btilde'], t['bptilde'], poly_tables(W, len(Ae)), {
    'A': '/// ā of the 17 stages (row s holds ā_sj, j < s), then of the dense output\'s stages: a(x1)\n/// (row 17, ā = b̄) and the bootstrapped ones (rows 18..).',
    'C': '/// c of the same stages.',
    'BBAR': '/// b̄: the 12th-order position weights.',
    'B': '/// b: the 12th-order velocity weights.',
    'EBAR': '/// b̄ − b̂̄ (exact differences, then rounded): the position error weights.',
    'E': '/// b − b̂: the velocity error weights.',
    'HAT': '/// b̂̄, b̂: the 10th-order embedded weights (checked in the tests).',
    'PX': bootstrapped_px_doc('12'),
})

e6 = dprkn6_exact()
g = lambda k: e6.get(k, mpf(0))
# The same file's 17-digit table of DPRKN6 rounds to the same doubles (all 80 of its values).
for k, v in dprkn6_floats().items():
    assert float(nstr(e6[k], 40)) == v, k
c6 = [mpf(0)] + [e6['c%d' % i] for i in range(1, 6)]
A6 = [[g('a%d%d' % (i + 1, j + 1)) for j in range(i)] for i in range(6)]
# B̄_i(θ) = θ² R_i(θ), B_i(θ) = θ Rp_i(θ): as full polynomials in θ.
PX6 = [[mpf(0)] * 6 for _ in range(7)]
PV6 = [[mpf(0)] * 6 for _ in range(7)]
for i in range(6):
    for k in range(5):
        PX6[k + 2][i] = g('r%d%d' % (i + 1, k))
        PV6[k + 1][i] = g('rp%d%d' % (i + 1, k))
# The paper's velocity weights are the derivative of its position weights (to the 80 digits
# here), so only the position weights are written and the stepper derives the velocity.
for i in range(6):
    for k in range(1, 7):
        assert abs(PV6[k - 1][i] - k * PX6[k][i]) < mpf(10) ** -70, (i, k)
out += pair_tables('6', A6, c6, [g('b%d' % i) for i in range(1, 7)], [g('bp%d' % i) for i in range(1, 7)],
                   [g('btilde%d' % i) for i in range(1, 7)], [g('bptilde%d' % i) for i in range(1, 7)], PX6, {
    'A': '/// ā of the six stages (the last, at c = 1 with ā = b̄, is a(x1): first same as last).',
    'C': '/// c of the stages: 0, (209 − √8581)/900, (209 − √8581)/450, (209 + √8581)/450, 9/10, 1.',
    'BBAR': '/// b̄, b: the 6th-order position and velocity weights.',
    'B': '',
    'EBAR': '/// b̄ − b̂̄ and b − b̂: the error weights (b̂̄, b̂ the 4th-order embedded solution).',
    'E': '',
    'HAT': '/// The embedded weights themselves (checked in the tests).',
    'PX': '/// The continuous extension: B̄_i(θ) = Σ_k PX6[k][i] θ^k, B_i(θ) = dB̄_i/dθ.',
})

# DPRKN8: its stage at c = 1/2 (position of local order 5) and one round at three points: order 6
# from the first interpolant, whose positions at the round's points are of local order 7, then
# order 8 (see the header of rkn_tables.rs).
t8 = dprkn8()
A, c, bbar, b = t8['A'], t8['c'], t8['b'], t8['bp']
Ae, ce, W = extend(A, c, bbar, b, 8, [int(i) for i in os.environ.get('FREE8', '4').split(',')],
                   point_lists(os.environ.get('ROUNDS8', '1/4,1/2,3/4')))
assert Ae[8] == A[8][:8]  # the pair's own last stage is a(x1)
out += pair_tables('8', Ae, ce, bbar, b, t8['btilde'], t8['bptilde'], poly_tables(W, len(Ae)), {
    'A': '/// ā of the nine stages (the last, at c = 1 with ā = b̄, is a(x1): first same as last), then of\n/// the dense output\'s bootstrapped stages (rows 9..).',
    'C': '/// c of the same stages.',
    'BBAR': '/// b̄, b: the 8th-order position and velocity weights.',
    'B': '',
    'EBAR': '/// b̄ − b̂̄ and b − b̂: the error weights (b̂̄, b̂ the 6th-order embedded solution).',
    'E': '',
    'HAT': '/// The embedded weights themselves (checked in the tests).',
    'PX': bootstrapped_px_doc('8'),
})

text = '\n\n'.join(out)
text = re.sub(r'^(///.*)#\[cfg\(test\)\]$', r'\1\n#[cfg(test)]', text, flags=re.M)
text = text.replace('#[cfg(test)]\n\n', '#[cfg(test)]\n').replace('\n\n#[cfg(test)]', '\n#[cfg(test)]')
while '\n\n\n' in text:
    text = text.replace('\n\n\n', '\n\n')
print(text)
print('// tables written', file=sys.stderr)
