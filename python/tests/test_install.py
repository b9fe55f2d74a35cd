"""`cmake --install` puts the package where the interpreter's site-packages
layout expects it: installed into a temporary prefix, `import edgefem` works
from another folder with PYTHONPATH set to <prefix>/<site-packages dir>, and
the stubs (PEP 561) are installed beside it (issue #26)."""
import os
import pathlib
import subprocess
import sys

import pytest

BUILD = os.environ.get("EDGEFEM_BUILD_DIR")
CMAKE = os.environ.get("EDGEFEM_CMAKE")
SITE = os.environ.get("EDGEFEM_PYTHON_INSTALL_DIR")


@pytest.mark.skipif(not (BUILD and CMAKE and SITE) or os.path.isabs(SITE or ""),
                    reason="run by ctest (needs the build folder and a relative install dir)")
def test_cmake_install_into_a_prefix_then_import_from_any_folder(tmp_path):
    prefix = tmp_path / "prefix"
    subprocess.run([CMAKE, "--install", BUILD, "--prefix", str(prefix), "--component", "python"], check=True,
                   stdout=subprocess.DEVNULL)
    package = prefix / SITE / "edgefem"
    assert (package / "__init__.pyi").is_file() and (package / "py.typed").is_file()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    env = dict(os.environ, PYTHONPATH=str(prefix / SITE))
    code = ("import edgefem, numpy as np; s = edgefem.Simulator(edgefem.Scene(edgefem.make_box(2, 2, 2), "
            "gravity=(0, 0, -9.81))); s.run(2); print(edgefem.__file__); print(np.abs(s.displacement).max() > 0)")
    out = subprocess.run([sys.executable, "-c", code], cwd=elsewhere, env=env, check=True, capture_output=True,
                         text=True).stdout.split()
    assert pathlib.Path(out[0]).resolve().is_relative_to(prefix.resolve()), out
    assert out[1] == "True"
