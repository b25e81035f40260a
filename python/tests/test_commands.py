"""rocklab.run, rocklab.suite and rocklab.calibrate against the command line."""
import json
import os

import pytest

import rocklab
from conftest import CARD, ROOT, cli, write_json


def read(path):
    with open(path, "rb") as f:
        return f.read()


def test_run_equals_the_command_line(tmp_path):
    scene = os.path.join(ROOT, "examples", "ball_drop_2d.json")
    status, _, err = cli("run", scene, "-o", tmp_path / "cli", "-q")
    assert status == 0, err
    r = rocklab.run(scene, out=tmp_path / "py")
    assert read(tmp_path / "py" / "history.csv") == read(tmp_path / "cli" / "history.csv")
    assert r.summary["steps"] > 0 and "time" in r.history.dtype.names
    with open(scene, encoding="utf-8") as f:
        as_dict = rocklab.run(json.load(f))
    assert as_dict.history.tobytes() == r.history.tobytes()
    bad = json.load(open(scene, encoding="utf-8"))
    bad["local_damping"] = 2
    with pytest.raises(ValueError, match=r"<scene dict>.*local_damping"):
        rocklab.run(bad)


def tiny_suite():
    return {"name": "tiny", "units": "SI", "material": CARD, "parallel": 2,
            "tests": [{"name": "ucs_" + str(seed), "test": "ucs", "seed": seed,
                       "stop": {"strain_limit": 0.004},
                       "output": {"vtk": False, "plots": False}} for seed in (1, 2)]}


def test_suite_gives_its_tables(tmp_path):
    r = rocklab.suite(tiny_suite(), out=tmp_path / "s", threads=1)
    assert not r.failed
    tests = r.tests
    names = list(tests["name"])
    assert names == ["ucs_1", "ucs_2"]
    assert all(float(e) > 0 for e in tests["youngs_modulus_Pa"])
    assert "youngs_modulus_Pa" in list(r.summary.keys() if isinstance(r.summary, dict)
                                       else r.summary.columns)
    assert r.results["tests"] and os.path.exists(tmp_path / "s" / "summary.json")


def test_calibrate_writes_its_card_and_report(tmp_path):
    cal = {"name": "tiny", "units": "SI", "material": CARD,
           "targets": {"youngs_modulus_Pa": {"value": 3e9, "tolerance": 0.5}},
           "parameters": {"flatjoint.fj_emod": {"role": "modulus", "bounds": [1e8, 1e12]}},
           "tests": [{"name": "ucs", "test": "ucs", "stop": {"strain_limit": 0.003},
                      "output": {"vtk": False, "plots": False}}],
           "seeds": [1],
           "budget": {"elastic": 2, "strength": 0, "ratios": 0, "polish": 0, "max_seeds": 1,
                      "validation_min": 2, "validation_max": 2, "validation_rounds": 1}}
    r = rocklab.calibrate(cal, tmp_path / "cal", jobs=2)
    assert r.card["flatjoint"]["fj_emod"] > 0
    assert "youngs_modulus_Pa" in r.report or "Young" in r.report
    assert r.summary["evaluations"] >= 1
    assert os.path.exists(tmp_path / "cal" / "card.json")


def test_the_package_namespace_is_its_api():
    # dir(rocklab) lists what the package offers, not the modules it uses (json, os, typing...).
    public = {n for n in dir(rocklab) if not n.startswith("_")}
    assert public == set(rocklab.__all__)
