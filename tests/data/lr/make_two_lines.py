# make_two_lines.py — writes two_lines.lr (stdout): a biquadratic tensor spline on [0,3]^2 x [0,1]
# (orders 3 3 1, knots 0 0 0 1 2 3 3 3), refined by the mesh lines u = 1.5 over v in [0,2] and
# v = 1.5 over u in [0,2] with LR knot insertion in exact fractions (split every function a line
# traverses, merge equal knot vectors adding scaling weights, repeat), which leaves scaling
# weights 7/16. Test data for tests/unit/test_load_lr.c, which checks the file against the
# unrefined tensor spline. Usage: python3 make_two_lines.py > two_lines.lr
from fractions import Fraction as F
import itertools
p = [3, 3]  # orders u, v
T = [[0, 0, 0, 1, 2, 3, 3, 3], [0, 0, 0, 1, 2, 3, 3, 3]]
def coef(i, j): return 1.0 + 0.5 * i - 0.25 * j + 0.125 * i * j + (0.3 if (i, j) == (2, 1) else 0.0)
basis = {}  # (ku, kv) -> [gamma, c]
for i in range(len(T[0]) - p[0]):
    for j in range(len(T[1]) - p[1]):
        basis[(tuple(F(x) for x in T[0][i:i + p[0] + 1]), tuple(F(x) for x in T[1][j:j + p[1] + 1]))] = [F(1), coef(i, j)]
# mesh lines: (d, value, lo, hi): constant coordinate d = value, extent [lo, hi] in the other direction
lines = []
for d in range(2):
    for x in sorted(set(T[d])):
        lines.append((d, F(x), F(T[1 - d][0]), F(T[1 - d][-1]), T[d].count(x)))
new_lines = [(0, F(3, 2), F(0), F(2), 1), (1, F(3, 2), F(0), F(2), 1)]
def split_once():
    for key, (g, c) in list(basis.items()):
        for (d, x, lo, hi, m) in lines:
            k = key[d]
            o = key[1 - d]
            if not (k[0] < x < k[-1]) or x in k:
                continue
            if not (lo <= o[0] and o[-1] <= hi):
                continue
            q = len(k) - 2  # degree
            a1 = min(F(1), (x - k[0]) / (k[q] - k[0])) if k[q] > k[0] else F(1)
            a2 = min(F(1), (k[q + 1] - x) / (k[q + 1] - k[1])) if k[q + 1] > k[1] else F(1)
            merged = tuple(sorted(k + (x,)))
            k1, k2 = merged[:q + 2], merged[1:]
            del basis[key]
            for kk, a in ((k1, a1), (k2, a2)):
                nk = (kk, o) if d == 0 else (o, kk)
                if nk in basis:
                    g0, c0 = basis[nk]
                    gn = g0 + g * a
                    basis[nk] = [gn, (c0 * float(g0) + c * float(g * a)) / float(gn)]
                else:
                    basis[nk] = [g * a, c]
            return True
    return False
for L in new_lines:
    lines.append(L)
    while split_once():
        pass
# elements: split tensor cells by lines crossing them fully
els = []
for a in range(len(T[0]) - 1):
    for b in range(len(T[1]) - 1):
        if T[0][a] < T[0][a + 1] and T[1][b] < T[1][b + 1]:
            els.append(([F(T[0][a]), F(T[1][b])], [F(T[0][a + 1]), F(T[1][b + 1])]))
changed = True
while changed:
    changed = False
    for e in list(els):
        lo, hi = e
        for (d, x, l0, l1, m) in lines:
            if lo[d] < x < hi[d] and l0 <= lo[1 - d] and hi[1 - d] <= l1:
                els.remove(e)
                h1 = list(hi); h1[d] = x
                l2 = list(lo); l2[d] = x
                els += [(lo, h1), (l2, hi)]
                changed = True
                break
        if changed:
            break
bl = sorted(basis.items(), key=lambda kv: (kv[0][1], kv[0][0]))
ids = {k: n for n, (k, _) in enumerate(bl)}
els.sort(key=lambda e: (e[0][1], e[0][0]))
out = []
out.append("# LRSPLINE VOLUME\n#\tp1\tp2\tp3\tNbasis\tNline\tNel\tdim\trat\n\t3\t3\t1\t%d\t%d\t%d\t1\t0\n" % (len(bl), len(lines) + 2, len(els)))
out.append("# Basis functions:\n")
fmt = lambda v: ("%.17g" % float(v))
for n, (k, (g, c)) in enumerate(bl):
    out.append("%d: [%s ] x [%s ] x [0 1 ] %s (%s)\n" % (n, " ".join(fmt(x) for x in k[0]), " ".join(fmt(x) for x in k[1]), "%.17g" % c, fmt(g)))
out.append("# Mesh rectangles:\n")
for (d, x, lo, hi, m) in lines:
    if d == 0:
        out.append("[%s, %s] x [%s, %s] x [0, 1] (%d)\n" % (fmt(x), fmt(x), fmt(lo), fmt(hi), m))
    else:
        out.append("[%s, %s] x [%s, %s] x [0, 1] (%d)\n" % (fmt(lo), fmt(hi), fmt(x), fmt(x), m))
out.append("[0, 3] x [0, 3] x [0, 0] (1)\n[0, 3] x [0, 3] x [1, 1] (1)\n")
out.append("# Elements:\n")
for n, (lo, hi) in enumerate(els):
    sup = [ids[k] for k in ids if k[0][0] <= lo[0] and hi[0] <= k[0][-1] and k[1][0] <= lo[1] and hi[1] <= k[1][-1]
           and not any(lo[0] < t < hi[0] for t in k[0]) and not any(lo[1] < t < hi[1] for t in k[1])]
    out.append("%d [3] : (%s, %s, 0) x (%s, %s, 1)    {%s}\n" % (n, fmt(lo[0]), fmt(lo[1]), fmt(hi[0]), fmt(hi[1]), ", ".join(str(s) for s in sorted(sup))))
import sys
sys.stdout.write("".join(out))
gs = sorted(set(g for g, c in basis.values()))
sys.stderr.write("weights %s, %d basis, %d elements\n" % ([str(g) for g in gs], len(bl), len(els)))
