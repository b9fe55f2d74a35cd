#!/usr/bin/env python3
"""Poke the bunny: load bunny-4k (../shared/meshes; a generated box when it
is absent), glue its base (the lowest 5% along the up axis: y for the
Stanford meshes, z for the box), push a few top vertices sideways for a
while, let go, and write a VTU series for ParaView.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/poke_bunny.py --out poke-out
    paraview poke-out/poke.pvd
"""
import argparse
import os
import pathlib

import numpy as np

import edgefem

HERE = pathlib.Path(__file__).resolve().parent


def find_bunny():
    for d in (os.environ.get("EDGEFEM_MESH_DIR"), HERE.parents[2] / "shared" / "meshes", "../shared/meshes"):
        if d and (pathlib.Path(d) / "bunny-4k.node").exists():
            return str(pathlib.Path(d) / "bunny-4k")
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--mesh", help="mesh file (default: bunny-4k, else a box)")
    ap.add_argument("--steps", type=int, default=400, help="time steps (dt = 1 ms)")
    ap.add_argument("--poke-steps", type=int, default=None, help="steps the force acts (default: half)")
    ap.add_argument("--force", type=float, default=0.2, help="total poke force (N)")
    ap.add_argument("--every", type=int, default=10, help="write a frame every this many steps")
    ap.add_argument("--out", default="poke-out", help="output folder")
    args = ap.parse_args()

    path = args.mesh or find_bunny()
    if path:
        mesh = edgefem.read_mesh(path)
        up = 1  # the Stanford frame is y-up
    else:
        mesh = edgefem.make_box(10, 5, 4)
        up = 2
    X = mesh.X
    height = X[:, up].max() - X[:, up].min()
    base = np.flatnonzero(X[:, up] <= X[:, up].min() + 0.05 * height)
    top = np.argsort(X[:, up])[-5:]  # the five highest vertices
    print(f"mesh: {path or 'box 10x5x4'} ({mesh.num_vertices} vertices, {mesh.num_tets} tets)")
    print(f"fixed: {base.size} base vertices; poking vertices {top.tolist()}")

    gravity = [0.0, 0.0, 0.0]
    gravity[up] = -9.81
    scene = edgefem.Scene(mesh, edgefem.Material(young=5e4, poisson=0.4, density=1000), fixed=base.tolist(),
                          gravity=gravity, dt=1e-3, integrator=edgefem.Integrator.SemiImplicit)
    scene.rayleigh_alpha = 2.0
    sim = edgefem.Simulator(scene)

    # The poke: sideways (+x) on the top vertices, through the zero-copy view.
    fext = sim.external_forces
    poke_steps = args.poke_steps if args.poke_steps is not None else args.steps // 2

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    frames = 0
    with edgefem.PvdSeries(str(out / "poke.pvd")) as pvd:
        for k in range(args.steps + 1):
            if k % args.every == 0 or k == args.steps:
                vtu = out / f"poke_{k:05d}.vtu"
                edgefem.write_vtu(str(vtu), sim.scene.mesh, displacement=sim.displacement, force=sim.forces)
                pvd.add(sim.time, str(vtu))
                frames += 1
            if k == args.steps:
                break
            fext[top, 0] = args.force / top.size if k < poke_steps else 0.0
            sim.step()
    u = sim.displacement
    tip = np.abs(u[top]).max()
    print(f"steps: {sim.step_index}, top displacement: {1e3 * tip:.3f} mm, "
          f"energy: {sim.energies().total:.4g} J, finite: {bool(np.isfinite(u).all())}")
    print(f"wrote {frames} frames to {out / 'poke.pvd'}")


if __name__ == "__main__":
    main()
