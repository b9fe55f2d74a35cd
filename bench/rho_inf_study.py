#!/usr/bin/env python3
"""Generalized-alpha's rho_inf on a nearly incompressible bar: the stress
suite's `poisson=0.499` case (bench/lab/stress_suite.cpp: a 6x2x2 cm bar,
Y = 1e5 Pa, clamped at x = min, released from the bend u_z = 0.2 L s^2,
mass damping alpha = 10 /s, dt = 1 ms, max_step_halvings 3, the energy
guard at 2) under generalized-alpha and its linearised form at several
rho_inf, and BDF2 for comparison. Prints, per run, max |u| / size every
0.5 s, the step halvings, the tets inverted at the end and how the run
ended.

    PYTHONPATH=build/python /usr/bin/python3 bench/rho_inf_study.py
"""
import argparse

import numpy as np

import edgefem


def run(integrator, rho_inf, nu, seconds):
    mesh = edgefem.make_box(6, 2, 2, 0.01)
    X = mesh.X
    x0 = X[:, 0].min()
    L = X[:, 0].max() - x0
    fixed = np.flatnonzero(X[:, 0] <= x0 + 1e-9)
    sc = edgefem.Scene(mesh, edgefem.Material(young=1e5, poisson=nu, density=1000), fixed=fixed.tolist(), dt=1e-3,
                       integrator=integrator)
    sc.rayleigh_alpha = 10
    sc.solver.max_step_halvings = 3
    sc.solver.max_energy_growth = 2
    sc.count_inverted_tets = True
    p = sc.integrator_parameters
    p.rho_inf = rho_inf
    sc.integrator_parameters = p
    sim = edgefem.Simulator(sc, backend="serial")
    s = (X[:, 0] - x0) / L
    sim.displacement[:, 2] = 0.2 * L * s * s
    size = np.linalg.norm(X.max(0) - X.min(0))
    halvings, marks, inverted = 0, [], 0
    steps = int(round(seconds / 1e-3))
    try:
        for k in range(steps):
            st = sim.step()
            halvings += st.halvings
            inverted = st.inverted_tets
            if (k + 1) % 500 == 0:
                marks.append(np.linalg.norm(sim.displacement, axis=1).max() / size)
        end = "ran"
    except edgefem.SimulationError as e:
        end = "failed at step %d: %s" % (k + 1, str(e).split(":")[1].strip()[:40])
    return marks, halvings, inverted, end


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seconds", type=float, default=2.0)
    ap.add_argument("--poisson", type=float, default=0.499)
    args = ap.parse_args()
    I = edgefem.Integrator
    rows = [(I.Bdf2Linear, 0.8), (I.Bdf2, 0.8)]
    for integ in (I.GeneralizedAlphaLinear, I.GeneralizedAlpha):
        for rho in (1.0, 0.8, 0.6, 0.5, 0.3, 0.0):
            rows.append((integ, rho))
    print("| integrator | rho_inf | max /u/ / size every 0.5 s | halvings | tets inverted at the end | end |")
    print("|---|---:|---|---:|---:|---|")
    for integ, rho in rows:
        marks, halvings, inverted, end = run(integ, rho, args.poisson, args.seconds)
        name = str(integ).split(".")[-1]
        print("| %s | %s | %s | %d | %d | %s |" % (name, rho if "Alpha" in name else "-",
                                                 ", ".join("%.2g" % m for m in marks), halvings, inverted, end))


if __name__ == "__main__":
    main()
