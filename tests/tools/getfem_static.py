#!/usr/bin/env python3
"""Static StVK equilibrium of a TetGen mesh solved by GetFEM: the independent
reference for `edgefem static` (tests/tools/static_reference.sh).

Physics (the same as edgefem's FE model): linear (P1) tetrahedra, the
GetFEM hyperelastic law "SaintVenant Kirchhoff",
    W = lambda/2 tr(E)^2 + mu E:E,  E = (F^T F - I)/2,
    lambda = Y nu / ((1 + nu)(1 - 2 nu)),  mu = Y / (2 (1 + nu)),
the body force rho g (GetFEM's source term brick; for P1 tets its consistent
load is rho Vol/4 g per vertex, edgefem's lumped load), and Dirichlet
conditions on vertices: fixed ones u = 0, prescribed ones u = target - X.

The Dirichlet conditions are imposed exactly by elimination: GetFEM assembles
the tangent matrix and the residual of the unconstrained model, and the
Newton loop here solves only for the free degrees of freedom (the
constrained ones are set to their values, scaled by the load factor). Newton
runs with load stepping (an increment is halved when Newton fails) until
|R_free| <= tol * (|f_int| + |f_ext|), f_int including the reactions.

Usage:
  getfem_static.py --mesh PREFIX --young Y --poisson NU [--density RHO]
      [--gravity GX GY GZ] --fixed FILE [--prescribed FILE] --out FILE
  getfem_static.py --scene SCENE.json --out FILE   (an edgefem scene: only
      "mesh" (a TetGen path), "material", "gravity", "fixed" ({"file"} or
      {"vertices"} or {"box"}, or an array of them) and "prescribed" ({"file"})
      are read; explicit options override it)

Vertex numbers in the fixed ('index' per line) and prescribed ('index x y z'
per line, '#' comments allowed) files, and the output line order, are the
order of the vertices in the .node file (0-based, whatever the TetGen base).
The output has one 'ux uy uz' line per vertex (%.17g).
"""
import argparse
import json
import math
import os
import sys

import numpy as np

try:
    import getfem as gf
except ImportError:
    sys.exit("getfem_static.py: cannot import getfem (Debian: apt-get install python3-getfem; "
             "it installs for the system /usr/bin/python3)")


def fail(msg):
    sys.exit("getfem_static.py: " + msg)


# ---- Input -----------------------------------------------------------------

def data_lines(path):
    """The non-blank lines of a file with '#' comments removed, as token lists."""
    try:
        with open(path) as f:
            for no, line in enumerate(f, 1):
                tok = line.split("#", 1)[0].split()
                if tok:
                    yield no, tok
    except OSError as e:
        fail("%s: %s" % (path, e.strerror))


def read_tetgen(prefix):
    """(X [n x 3], tets [m x 4], 0-based by position in the .node file)."""
    if prefix.endswith(".node") or prefix.endswith(".ele"):
        prefix = prefix.rsplit(".", 1)[0]
    lines = data_lines(prefix + ".node")
    _, head = next(lines, (0, None))
    if head is None:
        fail(prefix + ".node: empty")
    n, dim = int(head[0]), int(head[1])
    if dim != 3:
        fail(prefix + ".node: expected dimension 3, got %d" % dim)
    ids, X = [], []
    for _, tok in lines:
        ids.append(int(tok[0]))
        X.append([float(t) for t in tok[1:4]])
    if len(X) != n:
        fail(prefix + ".node: header says %d vertices, found %d" % (n, len(X)))
    base = ids[0]
    if base not in (0, 1) or ids != list(range(base, base + n)):
        fail(prefix + ".node: vertices must be numbered consecutively from 0 or 1")
    lines = data_lines(prefix + ".ele")
    _, head = next(lines, (0, None))
    if head is None:
        fail(prefix + ".ele: empty")
    m, k = int(head[0]), int(head[1])
    if k != 4:
        fail(prefix + ".ele: only linear tets (4 nodes) are supported, got %d" % k)
    tets = [[int(t) - base for t in tok[1:5]] for _, tok in lines]
    if len(tets) != m:
        fail(prefix + ".ele: header says %d tets, found %d" % (m, len(tets)))
    tets = np.array(tets, dtype=np.int64)
    if tets.min() < 0 or tets.max() >= n:
        fail(prefix + ".ele: vertex index out of range")
    return np.array(X, dtype=float), tets


def read_indices(path, n):
    out = []
    for no, tok in data_lines(path):
        v = int(tok[0])
        if len(tok) != 1 or not 0 <= v < n:
            fail("%s:%d: expected one vertex index in [0, %d)" % (path, no, n))
        out.append(v)
    return out


def read_prescribed(path, n):
    out = {}
    for no, tok in data_lines(path):
        if len(tok) != 4 or not 0 <= int(tok[0]) < n:
            fail("%s:%d: expected 'index x y z' with index in [0, %d)" % (path, no, n))
        out[int(tok[0])] = [float(t) for t in tok[1:]]
    return out


def scene_defaults(path):
    """The subset of an edgefem scene file this script understands."""
    with open(path) as f:
        s = json.load(f)
    base = os.path.dirname(os.path.abspath(path))
    res = lambda p: p if os.path.isabs(p) else os.path.join(base, p)
    unsupported = set(s) - {"mesh", "material", "gravity", "fixed", "prescribed", "solver", "output",
                            "integrator", "dt", "steps", "damping"}
    if unsupported or s.get("model", "fe") != "fe":
        fail("%s: unsupported scene keys %s" % (path, sorted(unsupported)))
    if not isinstance(s.get("mesh"), str) or s["mesh"].startswith("box:"):
        fail("%s: \"mesh\" must be a TetGen path" % path)
    mat = s.get("material", {})
    d = {"mesh": res(s["mesh"]), "young": mat.get("young"), "poisson": mat.get("poisson"),
         "density": mat.get("density", 1000.0), "gravity": s.get("gravity", [0, 0, 0]),
         "fixed_selectors": [], "prescribed": None}
    fx = s.get("fixed", [])
    for sel in fx if isinstance(fx, list) else [fx]:
        if "file" in sel:
            sel = {"file": res(sel["file"])}
        d["fixed_selectors"].append(sel)
    if "prescribed" in s:
        d["prescribed"] = res(s["prescribed"]["file"])
    return d


def select_fixed(selectors, X):
    fixed = set()
    for sel in selectors:
        if "file" in sel:
            fixed.update(read_indices(sel["file"], len(X)))
        elif "vertices" in sel:
            fixed.update(int(v) for v in sel["vertices"])
        elif "box" in sel:
            lo = np.array(sel["box"].get("min", [-math.inf] * 3), dtype=float)
            hi = np.array(sel["box"].get("max", [math.inf] * 3), dtype=float)
            fixed.update(np.nonzero(np.all((X >= lo) & (X <= hi), axis=1))[0].tolist())
        else:
            fail("unsupported fixed selector %r" % (sel,))
    return sorted(fixed)


# ---- GetFEM ----------------------------------------------------------------

def dof_to_vertex(mf, X):
    """For each basic dof of the vector P1 MeshFem: (vertex, component).
    The dof nodes are matched to the vertices by their coordinates (exactly
    when GetFEM kept them bit for bit, else the nearest vertex)."""
    nodes = np.asarray(mf.basic_dof_nodes()).T  # ndof x 3
    exact = {tuple(x): v for v, x in enumerate(X.tolist())}
    scale = max(1.0, float(np.abs(X).max()))
    vert = np.empty(len(nodes), dtype=np.int64)
    for d, p in enumerate(nodes.tolist()):
        v = exact.get(tuple(p))
        if v is None:
            dist = np.abs(X - p).max(axis=1)
            v = int(dist.argmin())
            if dist[v] > 1e-10 * scale:
                fail("GetFEM dof %d at %s matches no mesh vertex" % (d, p))
        vert[d] = v
    # GetFEM numbers the components of a vector dof consecutively.
    comp = np.arange(len(nodes)) % 3
    if len(nodes) != 3 * len(X) or not np.all(vert.reshape(-1, 3) == vert[::3, None]):
        fail("unexpected GetFEM dof layout (%d dofs for %d vertices)" % (len(nodes), len(X)))
    if len(set(vert[::3].tolist())) != len(X):
        fail("GetFEM merged mesh vertices (points closer than its 1e-8 tolerance?)")
    return vert, comp


class Problem:
    def __init__(self, X, tets, young, poisson, density, gravity):
        self.X = X
        pts = X.T.copy()
        mesh = gf.Mesh("ptND", pts, tets.T.copy())
        if mesh.nbpts() != len(X) or mesh.nbcvs() != len(tets):
            fail("GetFEM mesh has %d points / %d tets, expected %d / %d (duplicate points?)"
                 % (mesh.nbpts(), mesh.nbcvs(), len(X), len(tets)))
        self.mf = gf.MeshFem(mesh, 3)
        self.mf.set_fem(gf.Fem("FEM_PK(3,1)"))
        # P1: the StVK integrand is constant per tet, the source term linear.
        self.mim = gf.MeshIm(mesh, gf.Integ("IM_TETRAHEDRON(2)"))
        lam = young * poisson / ((1 + poisson) * (1 - 2 * poisson))
        mu = young / (2 * (1 + poisson))
        self.md = gf.Model("real")
        self.md.add_fem_variable("u", self.mf)
        self.md.add_initialized_data("params", [lam, mu])
        self.md.add_finite_strain_elasticity_brick(self.mim, "SaintVenant Kirchhoff", "u", "params")
        self.body = density * np.asarray(gravity, dtype=float)
        self.md.add_initialized_data("f", self.body)
        self.md.add_source_term_brick(self.mim, "u", "f")
        self.vert, self.comp = dof_to_vertex(self.mf, X)
        self.nd = self.mf.nbdof()

    def dofs_of(self, vertices):
        """Our (vertex, component) -> GetFEM dof."""
        lookup = {(int(v), int(c)): d for d, (v, c) in enumerate(zip(self.vert, self.comp))}
        return np.array([lookup[(v, c)] for v in vertices for c in range(3)], dtype=np.int64)

    def assemble(self, U, load):
        """(K, r) at U under load factor `load`: r = f_ext - f_int (GetFEM's rhs)."""
        self.md.set_variable("u", U)
        self.md.set_variable("f", load * self.body)
        self.md.assembly("build_all")
        return self.md.tangent_matrix(), np.asarray(self.md.rhs(), dtype=float)

    def forces(self, U, load):
        """(f_int, f_ext): the internal forces (reactions included) and the load."""
        self.md.set_variable("u", U)
        self.md.set_variable("f", 0 * self.body)
        self.md.assembly("build_rhs")
        fint = -np.asarray(self.md.rhs(), dtype=float)
        self.md.set_variable("f", load * self.body)
        self.md.assembly("build_rhs")
        return fint, np.asarray(self.md.rhs(), dtype=float) + fint


def solve_linear(K, b, free):
    Kf = gf.Spmat("copy", K, free.tolist(), free.tolist())
    if len(free) <= 3000:
        return np.linalg.solve(Kf.full(), b)
    x = gf.linsolve_superlu(Kf, b)
    return np.asarray(x[0] if isinstance(x, tuple) else x, dtype=float).ravel()


def newton(prob, U, cons, cons_val, free, load, tol, max_iter, log):
    """Newton on the free dofs with the constrained ones at load * cons_val.
    Returns (converged, iterations, relative residual)."""
    U[cons] = load * cons_val
    best = math.inf
    for it in range(max_iter + 1):
        K, r = prob.assemble(U, load)
        fint, fext = prob.forces(U, load)
        ref = np.linalg.norm(fint) + np.linalg.norm(fext)
        res = np.linalg.norm(r[free]) / ref if ref > 0 else np.linalg.norm(r[free])
        if not math.isfinite(res):
            return False, it, res
        log(it, res)
        if res <= tol:
            return True, it, res
        if it == max_iter or (it > 3 and res > 1e3 * best):
            return False, it, res
        best = min(best, res)
        du = solve_linear(K, r[free], free)
        if not np.all(np.isfinite(du)):
            return False, it, math.inf
        U[free] += du
    return False, max_iter, res


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", help="an edgefem scene (JSON) to take the inputs from")
    ap.add_argument("--mesh", help="TetGen prefix (PREFIX.node, PREFIX.ele) or the .node file")
    ap.add_argument("--young", type=float)
    ap.add_argument("--poisson", type=float)
    ap.add_argument("--density", type=float)
    ap.add_argument("--gravity", type=float, nargs=3)
    ap.add_argument("--fixed", help="file of fixed vertex indices, one per line")
    ap.add_argument("--prescribed", help="file of 'index x y z' target positions")
    ap.add_argument("--out", required=True, help="output: one 'ux uy uz' line per vertex")
    ap.add_argument("--tol", type=float, default=1e-12,
                    help="relative residual |R_free| / (|f_int| + |f_ext|) (default 1e-12)")
    ap.add_argument("--load-steps", type=int, default=1, help="initial number of load steps (default 1)")
    ap.add_argument("--max-iter", type=int, default=40, help="Newton iterations per load step (default 40)")
    ap.add_argument("--verbose", action="store_true", help="print every Newton iteration")
    a = ap.parse_args()
    gf.util_trace_level(0)  # GetFEM's assembly traces

    d = scene_defaults(a.scene) if a.scene else {"density": 1000.0, "gravity": [0, 0, 0],
                                                 "fixed_selectors": [], "prescribed": None}
    for key in ("mesh", "young", "poisson", "density", "gravity", "prescribed"):
        if getattr(a, key) is not None:
            d[key] = getattr(a, key)
    if a.fixed is not None:
        d["fixed_selectors"] = [{"file": a.fixed}]
    for key in ("mesh", "young", "poisson"):
        if d.get(key) is None:
            fail("--%s (or --scene) is required" % key)

    X, tets = read_tetgen(d["mesh"])
    fixed = select_fixed(d["fixed_selectors"], X)
    prescribed = read_prescribed(d["prescribed"], len(X)) if d["prescribed"] else {}
    both = set(fixed) & set(prescribed)
    if both:
        fail("vertices both fixed and prescribed: %s" % sorted(both)[:10])
    if not fixed and not prescribed:
        fail("no fixed or prescribed vertex: the static problem is singular")

    prob = Problem(X, tets, d["young"], d["poisson"], d["density"], d["gravity"])
    cvert = fixed + sorted(prescribed)
    cons = prob.dofs_of(cvert)
    cons_val = np.zeros(len(cons))
    for k, v in enumerate(sorted(prescribed)):
        cons_val[3 * (len(fixed) + k):3 * (len(fixed) + k) + 3] = np.array(prescribed[v]) - X[v]
    mask = np.ones(prob.nd, dtype=bool)
    mask[cons] = False
    free = np.nonzero(mask)[0]

    def log(it, res):
        if a.verbose:
            print("  newton %d: relative residual %.3e" % (it, res))

    U = np.zeros(prob.nd)
    done, inc, steps, halvings, total_it, res = 0.0, 1.0 / a.load_steps, 0, 0, 0, math.nan
    while done < 1 - 1e-15:
        load = min(1.0, done + inc)
        saved = U.copy()
        ok, it, res = newton(prob, U, cons, cons_val, free, load, a.tol, a.max_iter, log)
        total_it += it
        if not ok:
            U = saved
            halvings += 1
            if halvings > 12:
                fail("Newton failed (relative residual %.3e) even with load increment %g" % (res, inc))
            inc /= 2
            if a.verbose:
                print("load %.6g failed, increment halved to %g" % (load, inc))
            continue
        done = load
        steps += 1

    out = np.empty((len(X), 3))
    out[prob.vert, prob.comp] = U
    with open(a.out, "w") as f:
        for row in out:
            f.write("%.17g %.17g %.17g\n" % tuple(row))
    print("vertices %d" % len(X))
    print("tets %d" % len(tets))
    print("fixed %d prescribed %d" % (len(fixed), len(prescribed)))
    print("load_steps %d" % steps)
    print("newton_iterations %d" % total_it)
    print("residual %.3e" % res)
    print("max_displacement %.17g" % np.abs(out).max())


if __name__ == "__main__":
    main()
