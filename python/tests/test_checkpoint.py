"""Checkpoints from Python (docs/api.md, "Checkpoints"): N steps, a
checkpoint, a new Simulator loading it and N more steps equal 2N steps
straight, bit for bit; a checkpoint of another simulator, a missing,
truncated or corrupt file is edgefem.CheckpointError naming it, the state
unchanged."""
import numpy as np
import pytest

import edgefem


def scene(integrator=edgefem.Integrator.Bdf2):
    mesh = edgefem.make_box(6, 2, 2, 0.01)
    fixed = np.flatnonzero(mesh.X[:, 0] < mesh.X[:, 0].min() + 1e-9)
    s = edgefem.Scene(mesh, edgefem.Material(2e4, 0.3, 1000), fixed=fixed.tolist(), gravity=(0, 0, -9.81),
                      dt=5e-4 if integrator == edgefem.Integrator.Verlet else 2e-3)
    s.integrator = integrator
    return s


@pytest.mark.parametrize("integrator", [edgefem.Integrator.Bdf2, edgefem.Integrator.Newmark,
                                        edgefem.Integrator.Verlet])
def test_restart_is_bitwise(tmp_path, integrator):
    path = str(tmp_path / "a.ckpt")
    straight = edgefem.Simulator(scene(integrator), threads=2)
    straight.run(8)
    first = edgefem.Simulator(scene(integrator), threads=2)
    first.run(4)
    first.save_checkpoint(path)
    resumed = edgefem.Simulator(scene(integrator), threads=2)
    resumed.load_checkpoint(path)
    assert resumed.step_index == 4 and resumed.time == first.time
    resumed.run(4)
    assert np.array_equal(straight.displacement, resumed.displacement)
    assert np.array_equal(straight.velocity, resumed.velocity)
    assert straight.displacement.tobytes() == resumed.displacement.tobytes()


def test_errors_name_the_file_and_keep_the_state(tmp_path):
    path = str(tmp_path / "a.ckpt")
    sim = edgefem.Simulator(scene())
    sim.run(3)
    sim.save_checkpoint(path)
    good = open(path, "rb").read()
    other = edgefem.Simulator(scene(edgefem.Integrator.Newmark))
    other.run(2)
    before = other.displacement.copy()
    with pytest.raises(edgefem.CheckpointError, match="integrator 'bdf2'.*'newmark'"):
        other.load_checkpoint(path)
    with pytest.raises(edgefem.CheckpointError, match="cannot be opened"):
        other.load_checkpoint(str(tmp_path / "missing.ckpt"))
    open(path, "wb").write(good[: len(good) // 2])
    with pytest.raises(edgefem.CheckpointError, match="truncated"):
        sim.load_checkpoint(path)
    flipped = bytearray(good)
    flipped[len(good) // 2] ^= 1
    open(path, "wb").write(bytes(flipped))
    with pytest.raises(edgefem.CheckpointError, match="checksum"):
        sim.load_checkpoint(path)
    assert np.array_equal(other.displacement, before) and other.step_index == 2
    assert issubclass(edgefem.CheckpointError, edgefem.Error)
    with pytest.raises(edgefem.Error, match="no_such_dir"):
        sim.save_checkpoint(str(tmp_path / "no_such_dir" / "a.ckpt"))
