"""The Python module against a caller's mistakes (issues #26 and #27): no
crash, no silent misreading, no dangling view, no race; every bad input gets
an edgefem error (or numpy's read-only ValueError) that names it."""
import threading

import numpy as np
import pytest

import edgefem


def box():
    return edgefem.make_box(4, 2, 2)


def scene_of(mesh):
    X = mesh.X
    fixed = np.flatnonzero(X[:, 0] < X[:, 0].min() + 1e-9)
    return edgefem.Scene(mesh, edgefem.Material(1e5, 0.3, 1000), fixed=fixed.tolist(), gravity=(0, 0, -9.81))


def with_tet(mesh, t, row):
    tets = mesh.tets.copy()
    tets[t] = row
    return edgefem.Mesh(mesh.X, tets)


# ---- #26 bug 1, #27 item 2: unvalidated meshes never reach a kernel ----

def bad_meshes():
    b = box()
    dup = np.vstack([b.tets, b.tets[7:8]])
    return [
        ("shifted", edgefem.Mesh(b.X, b.tets + 1000), "out of range"),
        ("negative", with_tet(b, 5, [0, 1, 2, -5]), "-5"),
        ("past the end", with_tet(b, 5, [0, 1, 2, b.num_vertices]), str(b.num_vertices)),
        ("repeated vertex", with_tet(b, 5, [0, 1, 1, 2]), "twice"),
        ("duplicated tet", edgefem.Mesh(b.X, dup), "duplicate"),
    ]


@pytest.mark.parametrize("name,mesh,what", bad_meshes(), ids=[c[0] for c in bad_meshes()])
def test_unvalidated_meshes_are_refused_at_every_entry_point(name, mesh, what, tmp_path):
    with pytest.raises(edgefem.MeshError, match=what):
        edgefem.ElasticModel(mesh)
    with pytest.raises(edgefem.MeshError, match=what):
        edgefem.ElasticModel(mesh, backend="reference", method=edgefem.Method.Tet)
    with pytest.raises(edgefem.MeshError, match=what):
        edgefem.bench_forces(mesh, 0.01)
    with pytest.raises(edgefem.MeshError, match=what):
        edgefem.Simulator(scene_of(mesh))
    if name != "duplicated tet" and name != "repeated vertex":  # connectivity outside the mesh
        path = tmp_path / "bad.vtu"
        with pytest.raises(edgefem.MeshError, match=what):
            edgefem.write_vtu(str(path), mesh)
        assert not path.exists()


# ---- #26 bug 2: exact shapes and dtypes ----

def test_mesh_arrays_need_their_exact_shape_and_an_integer_index_dtype():
    b = box()
    X, T = b.X, b.tets
    bad = [
        (X[:, :2], T, r"X.*\(N, 3\).*\(45, 2\)"),
        (X.reshape(-1), T, r"X.*\(N, 3\).*\(135,\)"),
        (X, T[:, :3], r"tets.*\(T, 4\).*\(96, 3\)"),
        (X, T.reshape(-1), r"tets.*\(T, 4\)"),
        (X, T + 0.7, r"tets.*float64.*integer"),
        (X, T.astype(np.float64), r"tets.*float64.*integer"),
        (X, T.astype(np.int64) + 2**32, r"tets\[0, 0\] = 4294967296"),
        (X, T.astype(np.int64) - 2**33, r"tets\[0, 0\] = -"),
        (X, T.astype(bool), r"tets.*bool"),
        (X.astype(np.complex128), T, r"X.*complex128"),
        (X.astype(object), T, r"X.*object"),
        ("no", T, r"X"),
    ]
    for Xb, Tb, msg in bad:
        with pytest.raises(edgefem.InvalidArgument, match=msg):
            edgefem.Mesh(Xb, Tb)
    # documented conversions: any real float or integer X, any integer tets
    m = edgefem.Mesh(X.astype(np.float32).astype(np.float64), T.astype(np.uint16))
    assert np.array_equal(m.tets, T) and m.X.dtype == np.float64
    m = edgefem.Mesh(X.tolist(), T.astype(np.int64))
    assert np.array_equal(m.X, X) and np.array_equal(m.tets, T)
    m = edgefem.Mesh(np.asfortranarray(X), T[::1])
    assert np.array_equal(m.X, X)
    with pytest.raises(edgefem.InvalidArgument, match="region"):
        edgefem.Mesh(X, T, region=[0, 1])


def test_vector_arguments_need_shape_n_by_3():
    b = box()
    n = b.num_vertices
    sim = edgefem.Simulator(scene_of(b))
    em = edgefem.ElasticModel(b)
    for value, msg in [(np.zeros((3, n)), rf"\({n}, 3\).*\(3, {n}\)"), (np.zeros(3 * n), rf"\({n}, 3\).*\({3 * n},\)"),
                       (np.zeros((n, 3), dtype=np.complex128), "complex128"), (np.zeros((n + 1, 3)), rf"\({n + 1}, 3\)")]:
        for name in ("external_forces", "velocity", "displacement"):
            with pytest.raises(edgefem.InvalidArgument, match=name + ".*" + msg):
                setattr(sim, name, value)
        with pytest.raises(edgefem.InvalidArgument, match="u.*" + msg):
            em.forces(value)
        with pytest.raises(edgefem.InvalidArgument, match="u.*" + msg):
            em.energy(value)
        with pytest.raises(edgefem.InvalidArgument, match="displacement.*" + msg):
            edgefem.write_vtu("/nonexistent/never.vtu", b, displacement=value)
    with pytest.raises(edgefem.InvalidArgument, match="X.*" + rf"\({n}, 3\).*\(3, {n}\)"):
        b.X = np.zeros((3, n))
    assert np.all(sim.external_forces == 0) and np.all(sim.displacement == 0)


# ---- #26 bug 3: what the simulator holds is read-only ----

def test_simulator_scene_is_read_only():
    scene = scene_of(box())
    sim = edgefem.Simulator(scene)
    view = sim.scene
    with pytest.raises(ValueError, match="read-only"):
        view.mesh.X[:] = np.nan
    with pytest.raises(ValueError, match="read-only"):
        view.mesh.tets[0, 0] = 3
    for attr, value in [("dt", 5.0), ("steps", 3), ("gravity", (0, 0, 0)), ("mesh", box()), ("fixed", []),
                        ("integrator", edgefem.Integrator.Explicit), ("material", edgefem.Material())]:
        with pytest.raises(AttributeError):
            setattr(view, attr, value)
    with pytest.raises(AttributeError):
        view.mesh.X = np.zeros((view.mesh.num_vertices, 3))
    # what it reads is the simulator's scene
    assert view.dt == scene.dt and view.mesh.num_tets == scene.mesh.num_tets
    assert np.array_equal(view.mesh.X, scene.mesh.X) and view.fixed == scene.fixed
    # a copy is a Scene of one's own
    mine = view.copy()
    mine.dt = 5.0
    assert sim.scene.dt == scene.dt
    sim.run(3)
    assert np.isfinite(sim.displacement).all()
    # the view keeps the simulator alive
    X = sim.scene.mesh.X
    del sim, view
    assert np.array_equal(X, scene.mesh.X)


# ---- #26 bug 4: NaN inputs named, negative counts refused ----

def test_non_finite_inputs_are_named_as_inputs():
    sim = edgefem.Simulator(scene_of(box()))
    n = sim.num_vertices
    f = np.zeros((n, 3))
    f[7, 2] = np.nan
    with pytest.raises(edgefem.InvalidArgument, match=r"external_forces.*vertex 7"):
        sim.external_forces = f
    sim.external_forces[9, 1] = np.inf  # through the view: caught at the next step
    for call in (sim.step, lambda: sim.run(2), sim.solve_static):
        with pytest.raises(edgefem.InvalidArgument, match=r"external_forces.*vertex 9"):
            call()
    sim.external_forces[9, 1] = 0.0
    sim.velocity[4, 0] = np.nan
    with pytest.raises(edgefem.InvalidArgument, match=r"velocity.*vertex 4"):
        sim.step()
    sim.velocity[4, 0] = 0.0
    sim.step()
    assert sim.step_index == 1
    em = edgefem.ElasticModel(box())
    u = np.zeros((n, 3))
    u[3, 0] = np.nan
    with pytest.raises(edgefem.InvalidArgument, match=r"u.*vertex 3"):
        em.forces(u)
    X = box().X
    X[2, 2] = np.inf
    with pytest.raises(edgefem.MeshError, match="(?i)finite"):
        edgefem.ElasticModel(edgefem.Mesh(X, box().tets))


def test_negative_counts_are_refused():
    sim = edgefem.Simulator(scene_of(box()))
    with pytest.raises(edgefem.InvalidArgument, match="steps.*-1"):
        sim.run(-1)
    assert sim.step_index == 0
    with pytest.raises(edgefem.InvalidArgument, match="threads.*-5"):
        edgefem.Simulator(scene_of(box()), threads=-5)
    with pytest.raises(edgefem.InvalidArgument, match="threads.*-5"):
        edgefem.ElasticModel(box(), threads=-5)
    with pytest.raises(edgefem.InvalidArgument, match="threads.*-5"):
        edgefem.bench_forces(box(), 0.01, threads=-5)


# ---- #27 item 1: views keep their storage alive ----

def test_a_replaced_mesh_array_leaves_old_views_valid():
    m = edgefem.make_box(2, 2, 2)
    x = m.X
    before = x.copy()
    m.X = np.full((27, 3), 7.0)
    assert np.all(m.X == 7.0)
    assert np.all(x == 7.0)  # the setter copied into the array the view shows
    x[:] = 42  # writes the mesh's own storage, nothing freed
    assert np.all(m.X == 42)
    other = np.zeros(1000)
    assert np.all(other == 0)
    del before


def test_replacing_a_scene_mesh_never_leaves_a_dangling_view():
    scene = scene_of(edgefem.make_box(2, 2, 2))
    y = scene.mesh.X
    old = y.copy()
    big = edgefem.make_box(8, 8, 8)
    with pytest.raises(edgefem.InvalidArgument, match="mesh"):
        scene.mesh = big  # a view of the old mesh is alive: refused, not freed
    assert np.array_equal(y, old) and scene.mesh.num_vertices == 27
    same = edgefem.make_box(2, 2, 2, 0.02)
    scene.mesh = same  # same counts: copied into place, the view shows it
    assert np.array_equal(y, same.X)
    del y
    import gc
    gc.collect()
    scene.mesh = big  # no view left: replaced
    assert scene.mesh.num_vertices == big.num_vertices
    assert np.array_equal(scene.mesh.X, big.X)


# ---- #27 item 6: one simulator, two threads ----

def test_one_simulator_stepped_from_two_threads_raises_instead_of_racing():
    sim = edgefem.Simulator(scene_of(edgefem.make_box(16, 8, 8)), threads=1)
    done, errors = [0, 0], []
    stop = threading.Event()

    def worker(k):
        for _ in range(200):
            if stop.is_set():
                return
            try:
                sim.step()  # releases the GIL
                done[k] += 1
            except edgefem.InvalidArgument as e:
                errors.append(str(e))
                stop.set()

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert errors, "the two threads never overlapped"
    assert "one thread at a time" in errors[0]
    assert sim.step_index == sum(done)  # no lost or doubled step
    assert np.isfinite(sim.displacement).all()
    # distinct simulators are independent
    a, b = (edgefem.Simulator(scene_of(box()), threads=1) for _ in range(2))
    ts = [threading.Thread(target=s.run, args=(20,)) for s in (a, b)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert a.step_index == b.step_index == 20
    assert np.array_equal(a.displacement, b.displacement)
