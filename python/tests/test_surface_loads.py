"""Tagged surfaces and surface loads from Python: the Gmsh test mesh's
physical surface (tag 7, "skin") as read, selected by tag and name (an
interior triangle cannot carry a load; a tag or name that is not there is
named); a uniform pressure on a closed box sums to zero and on a face to
p x area; a keyframed traction on a free box gives it the momentum of its
impulse; bad triangle arrays are named."""
import os

import numpy as np
import pytest

import edgefem

DATA = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data")


def test_tagged_triangles_as_read():
    m = edgefem.read_mesh(os.path.join(DATA, "small22.msh"))
    assert m.surface_triangles.tolist() == [[0, 1, 2], [1, 2, 4]]
    assert m.surface_tags == [7, 7]
    assert m.surface_names == {7: "skin"}
    assert edgefem.select_surface(m, "skin", outward=False).tolist() == [[0, 1, 2], [1, 2, 4]]
    with pytest.raises(edgefem.MeshError, match="not on the boundary"):
        edgefem.select_surface(m, 7)
    with pytest.raises(edgefem.InvalidArgument, match="surface tag 3"):
        edgefem.select_surface(m, 3)
    with pytest.raises(edgefem.InvalidArgument, match='"clamp"'):
        edgefem.select_surface(m, "clamp")


def test_pressure_totals():
    m = edgefem.make_box(4, 3, 2, 0.01)
    tri, _ = edgefem.boundary_surface(m)
    f = edgefem.surface_load_forces(m, edgefem.SurfaceLoad(tri, pressure=1e3))
    assert np.abs(f.sum(axis=0)).max() < 1e-14 * 1e3 * 2 * (0.04 * 0.03 + 0.04 * 0.02 + 0.03 * 0.02)
    X = np.asarray(m.X)
    face = tri[np.all(X[tri][:, :, 0] > 0.0199, axis=1)]
    assert len(face) == 12
    f = edgefem.surface_load_forces(m, edgefem.SurfaceLoad(face, pressure=1e3, traction=(0, 2e3, 0)))
    assert f.sum(axis=0) == pytest.approx([-1e3 * 0.03 * 0.02, 2e3 * 0.03 * 0.02, 0], abs=1e-15)


def test_keyframed_traction_gives_its_impulse():
    m = edgefem.make_box(3, 2, 2, 0.01)
    tri, _ = edgefem.boundary_surface(m)
    X = np.asarray(m.X)
    face = tri[np.all(X[tri][:, :, 0] > 0.0149, axis=1)]
    scene = edgefem.Scene(m, edgefem.Material(1e5, 0.3, 1000), dt=1e-4, integrator=edgefem.Integrator.Explicit)
    keys = [edgefem.Keyframe(0, 0), edgefem.Keyframe(1e-3, 1)]
    scene.surface_loads = [edgefem.SurfaceLoad(face, traction=(40, 0, 0), keyframes=keys)]
    assert len(scene.surface_loads) == 1 and scene.surface_loads[0].triangles.shape == (8, 3)
    sim = edgefem.Simulator(scene)
    sim.run(10)
    p = (np.asarray(sim.lumped_mass)[:, None] * sim.velocity).sum(axis=0)
    impulse = sum(40 * 0.02 * 0.02 * (k + 0.5) * 1e-4 / 1e-3 * 1e-4 for k in range(10))
    assert p == pytest.approx([impulse, 0, 0], abs=1e-10 * impulse)


def test_bad_triangles_are_named():
    with pytest.raises(edgefem.InvalidArgument, match="triangles"):
        edgefem.SurfaceLoad(np.zeros((2, 4), dtype=np.int32))
    with pytest.raises(edgefem.InvalidArgument, match="triangles"):
        edgefem.SurfaceLoad(np.zeros((2, 3), dtype=np.float64))
    m = edgefem.make_box(1, 1, 1, 0.01)
    scene = edgefem.Scene(m)
    scene.surface_loads = [edgefem.SurfaceLoad([[0, 1, 99]], pressure=1)]
    with pytest.raises(edgefem.InvalidArgument, match=r"surface_loads\[0\].triangles\[0\]"):
        edgefem.Simulator(scene)
