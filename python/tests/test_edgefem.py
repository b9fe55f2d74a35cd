"""pytest suite for the edgefem Python module (run by ctest python_pytest;
by hand: PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests)."""
import math
import os

import numpy as np
import pytest

import edgefem


def small_box():
    return edgefem.make_box(4, 3, 2, 0.01)


def clamped_box_scene(nx=10, ny=5, nz=4):
    mesh = edgefem.make_box(nx, ny, nz, 0.01)
    X = mesh.X
    fixed = np.flatnonzero(X[:, 0] < X[:, 0].min() + 1e-9)
    return edgefem.Scene(mesh, edgefem.Material(1e5, 0.3, 1000), fixed=fixed.tolist(),
                         gravity=(0, 0, -9.81), dt=1e-3)


def test_mesh_loading():
    mesh = edgefem.make_box(10, 5, 4)
    assert (mesh.num_vertices, mesh.num_tets) == (11 * 6 * 5, 1200)
    assert mesh.X.shape == (mesh.num_vertices, 3) and mesh.tets.shape == (1200, 4)
    assert mesh.tets.dtype == np.int32
    box = edgefem.read_mesh("box:3x2x2")
    assert box.num_tets == 6 * 12
    # a mesh from arrays round-trips
    copy = edgefem.Mesh(mesh.X, mesh.tets)
    assert np.array_equal(copy.X, mesh.X) and np.array_equal(copy.tets, mesh.tets)
    assert copy.validate() == []


@pytest.mark.parametrize("model", [edgefem.ModelKind.FE, edgefem.ModelKind.SN])
def test_forces_are_the_energy_gradient(model):
    mesh = small_box()
    em = edgefem.ElasticModel(mesh, edgefem.Material(1e5, 0.3, 1000), model=model)
    rng = np.random.default_rng(1)
    u = 0.1 * edgefem.deformation(mesh, "twist") + 1e-4 * rng.standard_normal((mesh.num_vertices, 3))
    W, f = em.forces(u)
    assert f.shape == u.shape and W > 0
    assert W == pytest.approx(em.energy(u), rel=1e-12)
    # central differences along random directions and a few coordinates
    h = 1e-7
    for _ in range(5):
        d = rng.standard_normal(u.shape)
        fd = (em.energy(u + h * d) - em.energy(u - h * d)) / (2 * h)
        assert fd == pytest.approx(np.sum(f * d), rel=1e-6)
    for (v, r) in [(0, 0), (7, 2), (mesh.num_vertices - 1, 1)]:
        e = np.zeros_like(u)
        e[v, r] = h
        fd = (em.energy(u + e) - em.energy(u - e)) / (2 * h)
        assert fd == pytest.approx(f[v, r], rel=1e-5, abs=1e-9 * np.abs(f).max())


def test_stiffness_is_the_force_derivative():
    mesh = small_box()
    em = edgefem.ElasticModel(mesh)
    rng = np.random.default_rng(2)
    u = 0.05 * edgefem.deformation(mesh, "twist")
    x = rng.standard_normal(u.shape)
    em.build_stiffness(u)
    Kx = em.multiply(x)
    h = 1e-7
    fd = (em.forces(u + h * x)[1] - em.forces(u - h * x)[1]) / (2 * h)
    assert np.allclose(Kx, fd, rtol=1e-5, atol=1e-6 * np.abs(fd).max())
    with pytest.raises(edgefem.InvalidArgument, match="build_stiffness"):
        em.multiply(x)  # forces() above invalidated K
    em.build_stiffness(u)
    D = em.diagonal_blocks()
    assert D.shape == (mesh.num_vertices, 3, 3) and np.allclose(D, D.transpose(0, 2, 1), atol=1e-9 * np.abs(D).max())


def test_views_alias_the_simulator_state():
    sim = edgefem.Simulator(clamped_box_scene(4, 2, 2))
    u, v, fe = sim.displacement, sim.velocity, sim.external_forces
    assert u.shape == (sim.num_vertices, 3)
    assert not u.flags.owndata and u.base is sim
    # write through numpy, read through a fresh view (and the C++ positions())
    u[3, 1] = 0.125
    assert sim.displacement[3, 1] == 0.125
    assert sim.positions()[3, 1] == pytest.approx(sim.scene.mesh.X[3, 1] + 0.125)
    u[3, 1] = 0.0
    # the simulator writes, the old numpy view sees it
    fe[:] = 0
    fe[-1, 2] = -0.01
    assert sim.external_forces[-1, 2] == -0.01
    sim.step()
    assert np.array_equal(u, sim.displacement) and np.abs(u).max() > 0
    assert np.abs(v).max() > 0
    # the view keeps the simulator alive
    del sim
    assert np.isfinite(u).all()
    # read-only views stay read-only
    sim2 = edgefem.Simulator(clamped_box_scene(4, 2, 2))
    with pytest.raises(ValueError):
        sim2.forces[0, 0] = 1.0
    assert sim2.lumped_mass.shape == (sim2.num_vertices,) and (sim2.lumped_mass > 0).all()
    # whole-array assignment copies into the state
    sim2.velocity = np.ones((sim2.num_vertices, 3))
    assert (sim2.velocity == 1).all()


def test_short_simulation_stays_finite_and_sags():
    scene = clamped_box_scene()
    sim = edgefem.Simulator(scene)
    stats = sim.run(30)
    assert stats.solver_iterations > 0
    u = sim.displacement
    assert np.isfinite(u).all()
    free_end = scene.mesh.X[:, 0] > scene.mesh.X[:, 0].max() - 1e-9
    assert u[free_end, 2].mean() < -1e-4
    assert np.abs(u[scene.fixed]).max() == 0.0
    e = sim.energies()
    assert math.isfinite(e.total) and e.elastic > 0
    assert sim.step_index == 30 and sim.time == pytest.approx(0.03)
    r = edgefem.bench_step(sim, 0.05)
    assert r["steps"] >= 5 and r["median_ms_per_step"] > 0


def test_solve_static_converges():
    sim = edgefem.Simulator(clamped_box_scene(6, 2, 2))
    r = sim.solve_static()
    assert r.converged and np.isfinite(sim.displacement).all()
    assert sim.displacement[:, 2].min() < 0


def test_scene_from_json(tmp_path):
    scene_file = tmp_path / "s.json"
    scene_file.write_text('{"mesh": "box:4x2x2", "material": {"young": 2e5, "poisson": 0.25, "density": 900},'
                          ' "gravity": [0, 0, -9.81], "dt": 0.002, "steps": 3}')
    scene = edgefem.Scene.from_json(str(scene_file))
    assert scene.dt == 0.002 and scene.material.young == 2e5 and scene.mesh.num_tets == 96
    sim = edgefem.Simulator(scene)
    sim.run(3)
    assert np.isfinite(sim.displacement).all()


def test_errors_become_exceptions(tmp_path):
    with pytest.raises(edgefem.MeshError, match="no_such_mesh"):
        edgefem.read_mesh(str(tmp_path / "no_such_mesh.node"))
    X = edgefem.make_box(2, 2, 2).X.copy()
    X[5, 1] = np.nan
    bad = edgefem.Mesh(X, edgefem.make_box(2, 2, 2).tets)
    with pytest.raises(edgefem.MeshError, match="(?i)finite|nan"):
        bad.validate()
    scene = clamped_box_scene(2, 2, 2)
    scene.dt = -1.0
    with pytest.raises(edgefem.InvalidArgument, match="dt"):
        edgefem.Simulator(scene)
    scene.dt = 1e-3
    scene.material = edgefem.Material(1e5, 0.7, 1000)
    with pytest.raises(edgefem.InvalidArgument, match="(?i)poisson"):
        edgefem.Simulator(scene)
    with pytest.raises(edgefem.InvalidArgument, match="twist|deformation|frobnicate"):
        edgefem.deformation(edgefem.make_box(2, 2, 2), "frobnicate")
    sim = edgefem.Simulator(clamped_box_scene(2, 2, 2))
    with pytest.raises(edgefem.InvalidArgument, match="external_forces"):
        sim.external_forces = np.zeros(5)
    bad_json = tmp_path / "bad.json"
    bad_json.write_text('{"mesh": "box:2x2x2", "frobnicate": 1}')
    with pytest.raises(edgefem.InvalidArgument, match="frobnicate"):
        edgefem.load_scene(str(bad_json))
    # every edgefem error is an edgefem.Error and a RuntimeError
    assert issubclass(edgefem.SimulationError, edgefem.Error)
    assert issubclass(edgefem.Error, RuntimeError)


def test_explicit_blow_up_raises_simulation_error():
    scene = clamped_box_scene(4, 2, 2)
    scene.integrator = edgefem.Integrator.Explicit
    scene.material = edgefem.Material(1e9, 0.3, 1000)
    scene.dt = 1e-2
    sim = edgefem.Simulator(scene)
    with pytest.raises(edgefem.SimulationError, match="step"):
        sim.run(200)


def test_energy_guard_setting_and_stats():
    # The guard stops an unstable explicit run with a message that names it,
    # and lets a normal semi-implicit run through while reporting its ratio.
    scene = clamped_box_scene(4, 2, 2)
    assert scene.solver.max_energy_growth == 10 and scene.solver.fail_on_unconverged
    assert scene.solver.warm_start is True
    scene.solver.warm_start = False
    assert scene.solver.warm_start is False
    with pytest.raises(TypeError):
        scene.solver.warm_start = "no"
    scene.solver.warm_start = True
    scene.integrator = edgefem.Integrator.Explicit
    scene.material = edgefem.Material(1e9, 0.3, 1000)
    scene.dt = 1e-2
    with pytest.raises(edgefem.SimulationError, match="(?i)energy"):
        edgefem.Simulator(scene).run(200)
    ok = clamped_box_scene(4, 2, 2)
    ok.solver.stiffness_interval = 2
    sim = edgefem.Simulator(ok)
    stats = sim.run(10)
    assert 1.0 <= stats.energy_growth < ok.solver.max_energy_growth
    assert stats.unconverged_solves == 0 and not stats.newton_round_off
    ok.solver.max_energy_growth = 0.5  # neither 0 (off) nor >= 1
    with pytest.raises(edgefem.InvalidArgument, match="max_energy_growth"):
        edgefem.Simulator(ok)


def test_second_order_integrators_parameters_and_initial_state():
    # Each new integrator runs; a free body given a uniform initial velocity
    # translates rigidly; bad parameters name their key.
    for integ in [edgefem.Integrator.Newmark, edgefem.Integrator.NewmarkLinear, edgefem.Integrator.GeneralizedAlpha,
                  edgefem.Integrator.GeneralizedAlphaLinear, edgefem.Integrator.Bdf2, edgefem.Integrator.Bdf2Linear,
                  edgefem.Integrator.Verlet]:
        scene = clamped_box_scene(4, 1, 1)
        scene.integrator = integ
        scene.fixed = []
        scene.gravity = (0.0, 0.0, 0.0)
        n = 3 * scene.mesh.num_vertices
        scene.initial_velocity = [0.1 if i % 3 == 0 else 0.0 for i in range(n)]
        sim = edgefem.Simulator(scene)
        sim.run(10)
        u = np.asarray(sim.displacement).reshape(-1, 3)
        assert np.allclose(u[:, 0], 10 * scene.dt * 0.1, atol=1e-12) and np.allclose(u[:, 1:], 0, atol=1e-12)
    scene = clamped_box_scene(4, 1, 1)
    scene.integrator = edgefem.Integrator.GeneralizedAlpha
    params = scene.integrator_parameters
    params.rho_inf = 1.5
    scene.integrator_parameters = params
    with pytest.raises(edgefem.InvalidArgument, match="generalized_alpha.rho_inf"):
        edgefem.Simulator(scene)
    scene = clamped_box_scene(4, 1, 1)
    scene.prescribed_keyframes = [edgefem.Keyframe(0.0, 0.0), edgefem.Keyframe(0.0, 1.0)]
    with pytest.raises(edgefem.InvalidArgument, match="prescribed.keyframes"):
        edgefem.Simulator(scene)


def test_preconditioner_setting():
    # AMG-preconditioned CG reaches block-Jacobi's solution; a bad name is an
    # error that names the setting.
    scene = clamped_box_scene(8, 3, 3)
    assert scene.solver.preconditioner == "auto"
    assert scene.solver.auto_amg_iterations == 60
    scene.dt = 4e-3
    scene.solver.cg_tolerance = 1e-11
    u = {}
    for name in ("block-jacobi", "amg", "auto"):
        scene.solver.preconditioner = name
        sim = edgefem.Simulator(scene)
        sim.run(3)
        u[name] = np.array(sim.displacement)
    assert np.linalg.norm(u["amg"] - u["block-jacobi"]) <= 1e-8 * np.linalg.norm(u["block-jacobi"])
    assert np.linalg.norm(u["auto"] - u["block-jacobi"]) <= 1e-8 * np.linalg.norm(u["block-jacobi"])
    with pytest.raises(edgefem.InvalidArgument, match="solver.preconditioner"):
        scene.solver.preconditioner = "ilu"


def test_vtu_series(tmp_path):
    mesh = small_box()
    u = edgefem.deformation(mesh, "twist", 0.1)
    with edgefem.PvdSeries(str(tmp_path / "s.pvd")) as pvd:
        for k in range(2):
            path = str(tmp_path / f"s_{k}.vtu")
            edgefem.write_vtu(path, mesh, displacement=u * k)
            pvd.add(0.1 * k, path)
    assert (tmp_path / "s_1.vtu").read_bytes().count(b"<Piece") == 1
    assert (tmp_path / "s.pvd").read_text().count("<DataSet") == 2


def test_bench_forces():
    r = edgefem.bench_forces(small_box(), seconds=0.05)
    assert r["calls"] >= 5 and r["median_ns_per_tet"] > 0
    # A budget that never ends (or absurdly long) is refused, not run.
    for bad in (float("inf"), float("nan"), 1e300, 0.0):
        with pytest.raises(edgefem.InvalidArgument):
            edgefem.bench_forces(small_box(), seconds=bad)


@pytest.mark.skipif(not edgefem.has_parallel, reason="built without the parallel module")
def test_threads_adaptive_or_not_give_the_same_steps():
    runs = {}
    for backend, adaptive in [("omp", True), ("omp", False), ("tbb", True), ("pool", False)]:
        sim = edgefem.Simulator(clamped_box_scene(6, 2, 2), backend=backend, threads=2, adaptive=adaptive)
        sim.run(8)
        runs[(backend, adaptive)] = sim.displacement.copy()
    assert np.abs(runs[("omp", False)]).max() > 0
    # deterministic kernels: bitwise the same whichever loops ran serially
    assert (runs[("omp", True)] == runs[("omp", False)]).all()
    assert (runs[("tbb", True)] == runs[("omp", False)]).all()
    assert (runs[("pool", False)] == runs[("omp", False)]).all()


def test_run_options_defaults_orderings_and_back_ends_agree():
    # The defaults (every core, rcm), the input numbering, the reference
    # back-end and the serial loops in another numbering: the same motion,
    # with the views and the scene in the mesh's own numbering throughout.
    scene = clamped_box_scene(6, 3, 2)
    runs = {}
    for key, kw in [("default", {}), ("input", dict(ordering="input")), ("reference", dict(backend="reference")),
                    ("serial-morton", dict(backend="serial", ordering="morton"))]:
        sim = edgefem.Simulator(scene, **kw)
        sim.external_forces[-1, 2] = -0.02  # written into the view: takes effect at the next step
        sim.run(10)
        runs[key] = sim.displacement.copy()
        assert np.array_equal(sim.scene.mesh.X, scene.mesh.X)
        assert sim.positions() == pytest.approx(scene.mesh.X + runs[key], abs=1e-15)
    ref = runs["reference"]
    assert np.abs(ref[-1]).max() > 1e-6
    for key, u in runs.items():
        assert np.abs(u - ref).max() <= 1e-9 * np.abs(ref).max(), key


@pytest.mark.parametrize("kw,name", [(dict(backend="gpu"), "backend"), (dict(ordering="zigzag"), "ordering"),
                                     (dict(variant="scatter"), "variant"), (dict(threads=-1), "threads"),
                                     (dict(schedule="guided"), "schedule"), (dict(layout="soa"), "layout"),
                                     (dict(backend="reference", variant="owner"), "variant")])
def test_bad_run_options_name_themselves(kw, name):
    with pytest.raises(edgefem.InvalidArgument, match=name):
        edgefem.Simulator(clamped_box_scene(2, 2, 2), **kw)
    if name in ("backend", "threads", "variant") and "ordering" not in kw:
        with pytest.raises(edgefem.InvalidArgument, match=name):
            edgefem.ElasticModel(small_box(), **{k: v for k, v in kw.items() if k in ("backend", "threads", "variant")})


def test_retain_freed_memory_leaves_a_users_malloc_tunables_alone(monkeypatch):
    monkeypatch.setenv("GLIBC_TUNABLES", "glibc.malloc.check=0")
    assert edgefem.retain_freed_memory() is False


def test_retain_freed_memory_changes_glibcs_settings_in_a_fresh_process():
    # A child process, so that this one's malloc keeps glibc's defaults.
    import platform
    import subprocess
    import sys

    if platform.libc_ver()[0] != "glibc":
        pytest.skip("glibc only")
    env = {k: v for k, v in os.environ.items() if k != "GLIBC_TUNABLES"}
    out = subprocess.run([sys.executable, "-c", "import edgefem; print(edgefem.retain_freed_memory())"],
                         env=env, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"
