#!/usr/bin/env python3
"""Compares two displacement files (one 'ux uy uz' line per vertex, '#'
comments and blank lines ignored):

  compare_disp.py REFERENCE TEST [TOLERANCE]

prints max |test - reference| / max |reference| (over all components) and
the vertex where the difference is largest; exits 0 iff it is <= TOLERANCE
(default 1e-8), 1 if larger, 2 on unusable input. Needs only the standard
library.
"""
import math
import sys


def read(path):
    rows = []
    try:
        with open(path) as f:
            for no, line in enumerate(f, 1):
                tok = line.split("#", 1)[0].split()
                if not tok:
                    continue
                if len(tok) != 3:
                    raise ValueError("%s:%d: expected 'ux uy uz', got %r" % (path, no, line.strip()))
                row = [float(t) for t in tok]
                if not all(math.isfinite(x) for x in row):
                    raise ValueError("%s:%d: non-finite value" % (path, no))
                rows.append(row)
    except OSError as e:
        raise ValueError("%s: %s" % (path, e.strerror))
    if not rows:
        raise ValueError("%s: no displacement lines" % path)
    return rows


def main(argv):
    if len(argv) not in (3, 4):
        print(__doc__.strip(), file=sys.stderr)
        return 2
    try:
        ref, test = read(argv[1]), read(argv[2])
        tol = float(argv[3]) if len(argv) == 4 else 1e-8
    except ValueError as e:
        print("compare_disp.py: %s" % e, file=sys.stderr)
        return 2
    if len(ref) != len(test):
        print("compare_disp.py: %d vertices in %s, %d in %s" % (len(ref), argv[1], len(test), argv[2]),
              file=sys.stderr)
        return 2
    scale = max(abs(x) for row in ref for x in row)
    diff, worst = 0.0, 0
    for v, (a, b) in enumerate(zip(ref, test)):
        d = max(abs(x - y) for x, y in zip(a, b))
        if d > diff:
            diff, worst = d, v
    rel = diff / scale if scale > 0 else diff
    ok = rel <= tol
    print("max |u| %.6e, max |du| %.6e at vertex %d, relative %.3e (tolerance %.1e): %s"
          % (scale, diff, worst, rel, tol, "ok" if ok else "FAIL"))
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
