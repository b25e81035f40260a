"""The example parameter study (examples/python/param_study.py) on the tests' tiny card, and the
package installed by `cmake --install` importing and finding its rocklab binary."""
import json
import os
import subprocess
import sys

import pytest

import rocklab
from conftest import ROOT

sys.path.insert(0, os.path.join(ROOT, "examples", "python"))
import param_study  # noqa: E402


def test_the_parameter_study_runs_and_draws_its_figure(tmp_path):
    assert param_study.main(["-o", str(tmp_path), "--tiny"]) == 0
    with open(tmp_path / "study.json", encoding="utf-8") as f:
        rows = json.load(f)["rows"]
    assert len(rows) == 4 and {r["parameter"] for r in rows} == {"fj_ten", "slit"}
    assert all(r["ucs_Pa"] > 0 and r["youngs_modulus_Pa"] > 0 for r in rows)
    ten = sorted((r["value"], r["ucs_Pa"]) for r in rows if r["parameter"] == "fj_ten")
    assert ten[1][1] > ten[0][1]  # stronger bonds, stronger rock (+33 % tension)
    with open(tmp_path / "study.png", "rb") as f:
        assert f.read(8) == b"\x89PNG\r\n\x1a\n"


def build_dir():
    d = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(rocklab.__file__))))
    return d if os.path.exists(os.path.join(d, "CMakeCache.txt")) else None


@pytest.mark.skipif(build_dir() is None, reason="the package is not the build tree's")
def test_cmake_install_gives_an_importable_package(tmp_path):
    subprocess.run(["cmake", "--install", build_dir(), "--prefix", str(tmp_path)], check=True,
                   capture_output=True)
    site = [os.path.join(d, "dist-packages") for d, _, files in os.walk(tmp_path)
            if os.path.basename(d).startswith("python3")]
    assert site, "no lib/python3.X in the install tree"
    env = dict(os.environ, PYTHONPATH=site[0])
    env.pop("ROCKLAB_EXECUTABLE", None)
    out = subprocess.run([sys.executable, "-c", "import rocklab; print(rocklab.__file__); "
                          "print(rocklab.executable()); print(rocklab.lab_tests())"],
                         env=env, capture_output=True, text=True, check=True, cwd=str(tmp_path))
    lines = out.stdout.splitlines()
    assert lines[0].startswith(str(tmp_path))
    assert lines[1] == os.path.join(str(tmp_path), "bin", "rocklab")
    assert "ucs" in lines[2]
