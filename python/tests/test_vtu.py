"""write_vtu's compressed binary frames, decoded here with zlib and struct
(VTK's appended vtkZLibDataCompressor layout) and compared bitwise with the
arrays written and with the ASCII frame's numbers."""
import re
import struct
import zlib

import numpy as np
import pytest

import edgefem


def _vtu_arrays(data):
    """Every DataArray of a .vtu by name ("Points" for the points): the raw
    bytes of an appended zlib array (VTK's vtkZLibDataCompressor layout,
    UInt64 headers) or the text of an ASCII one."""
    head, _, tail = data.partition(b'<AppendedData encoding="raw">')
    base = tail.index(b"_") + 1 if tail else 0
    out = {}
    for tag in re.finditer(rb"<DataArray([^>]*)>", head):
        attrs = dict(re.findall(rb'(\w+)="([^"]*)"', tag.group(1)))
        name = attrs.get(b"Name", b"Points").decode()
        if attrs[b"format"] == b"ascii":
            end = head.index(b"</DataArray>", tag.end())
            out[name] = head[tag.end():end].decode()
            continue
        at = base + int(attrs[b"offset"])
        nb, bs, last = struct.unpack_from("<3Q", tail, at)
        sizes = struct.unpack_from(f"<{nb}Q", tail, at + 24)
        at += 24 + 8 * nb
        raw = b""
        for b, size in enumerate(sizes):
            block = zlib.decompress(tail[at:at + size])
            assert len(block) == (last if b == nb - 1 and last else bs)
            raw += block
            at += size
        out[name] = raw
    return out


def test_write_vtu_binary_is_bitwise_the_arrays_and_the_ascii(tmp_path):
    mesh = edgefem.make_box(12, 10, 8, 0.01)  # arrays of several 32 KiB blocks
    u = edgefem.deformation(mesh, "twist", 0.1)
    v = np.sqrt(np.arange(mesh.num_vertices * 3, dtype=np.float64)).reshape(-1, 3) / 7
    edgefem.write_vtu(str(tmp_path / "b.vtu"), mesh, displacement=u, velocity=v)
    edgefem.write_vtu(str(tmp_path / "a.vtu"), mesh, displacement=u, velocity=v, format="ascii")
    b = _vtu_arrays((tmp_path / "b.vtu").read_bytes())
    a = _vtu_arrays((tmp_path / "a.vtu").read_bytes())
    for name, want in (("Points", mesh.X + u), ("displacement", u), ("velocity", v)):
        got = np.frombuffer(b[name], dtype="<f8")
        assert got.tobytes() == np.ascontiguousarray(want).tobytes(), name
        assert np.array_equal(np.array(a[name].split(), dtype=np.float64), got), name
    assert np.array_equal(np.frombuffer(b["connectivity"], dtype="<i4"), mesh.tets.ravel())
    assert np.array_equal(np.frombuffer(b["types"], dtype=np.uint8), np.full(mesh.num_tets, 10))
    with pytest.raises(edgefem.InvalidArgument, match="format: expected 'binary' or 'ascii', got 'xml'"):
        edgefem.write_vtu(str(tmp_path / "c.vtu"), mesh, format="xml")
