"""Surfaces for rendering from Python: the boundary of a box (its triangle
count and outward winding: the divergence theorem gives the box volume),
a render surface's points embedded and moved with an affine displacement
exactly, normals, and bad arrays named."""
import numpy as np
import pytest

import edgefem


def test_boundary_of_a_box_is_closed_and_outward():
    m = edgefem.make_box(4, 2, 2, 0.01)
    tri, tet = edgefem.boundary_surface(m)
    assert tri.shape == (80, 3) and tri.dtype == np.int32 and tet.shape == (80,)
    X = np.asarray(m.X)
    a, b, c = X[tri[:, 0]], X[tri[:, 1]], X[tri[:, 2]]
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6
    assert volume == pytest.approx(0.04 * 0.02 * 0.02, rel=1e-12)
    n = edgefem.vertex_normals(tri, X)
    assert n.shape == X.shape
    used = np.unique(tri)
    assert np.allclose(np.linalg.norm(n[used], axis=1), 1.0)
    inner = np.setdiff1d(np.arange(len(X)), used)  # no triangle: 0
    assert len(inner) == 3 and np.all(n[inner] == 0)


def test_embedded_points_follow_an_affine_motion():
    m = edgefem.make_box(4, 2, 2, 0.01)
    X = np.asarray(m.X)
    rng = np.random.default_rng(1)
    pts = rng.uniform(X.min(axis=0) - 0.002, X.max(axis=0) + 0.002, size=(50, 3))
    e = edgefem.embed_points(m, pts)
    assert e.tet.shape == (50,) and e.weight.shape == (50, 4)
    assert np.allclose(e.weight.sum(axis=1), 1.0)
    A = np.array([[0.1, -0.2, 0.05], [0.3, 0.02, -0.1], [-0.05, 0.15, 0.2]])
    c = np.array([0.01, -0.02, 0.03])
    u = X @ A.T + c
    moved = edgefem.embedded_positions(m, e, u)
    assert np.allclose(moved, pts + pts @ A.T + c, atol=1e-12)


def test_bad_arrays_are_named():
    m = edgefem.make_box(2, 2, 2, 0.01)
    with pytest.raises(edgefem.InvalidArgument, match="points"):
        edgefem.embed_points(m, np.zeros((3, 2)))
    with pytest.raises(edgefem.InvalidArgument, match="triangles"):
        edgefem.vertex_normals(np.zeros((2, 3)), np.asarray(m.X))
    e = edgefem.embed_points(m, np.zeros((1, 3)))
    with pytest.raises(edgefem.InvalidArgument, match="u"):
        edgefem.embedded_positions(m, e, np.zeros((5, 3)))
