"""Shared fixtures of the Python tests: the source tree, the rocklab binary built beside the module
and a tiny 2D flat-jointed card (tests/data/lab_2d_fj.json) with UCS and Brazilian protocols that
run in seconds. Units SI."""
import json
import os
import subprocess

import pytest

import rocklab

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CARD = os.path.join(ROOT, "tests", "data", "lab_2d_fj.json")


def cli(*args, cwd=None):
    """Run the rocklab binary; (exit status, stdout, stderr)."""
    p = subprocess.run([rocklab.executable(), *map(str, args)], capture_output=True, text=True,
                       cwd=cwd)
    return p.returncode, p.stdout, p.stderr


def ucs_protocol(card=CARD, strain_limit=0.004):
    """A UCS test of the tiny card, stopped at `strain_limit` axial strain, no VTK."""
    return {"test": "ucs", "units": "SI", "specimen": {"material": card},
            "stop": {"strain_limit": strain_limit},
            "output": {"vtk": False, "plots": False, "history_every": 200}}


def write_json(path, value):
    with open(path, "w", encoding="utf-8") as f:
        json.dump(value, f, indent=1)
    return str(path)


@pytest.fixture
def card_file():
    return CARD
