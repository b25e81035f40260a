"""rocklab.genesis and Specimen: byte-identical to `rocklab genesis`, dict and file cards,
overrides, errors, threads."""
import json
import os

import pytest

import rocklab
from conftest import CARD, cli


def read(path):
    with open(path, "rb") as f:
        return f.read()


def test_genesis_equals_the_command_line_byte_for_byte(tmp_path):
    status, _, err = cli("genesis", CARD, "-o", tmp_path / "cli.rlspec", "--seed", 5, "-q")
    assert status == 0, err
    s = rocklab.genesis(CARD, seed=5)
    s.save(tmp_path / "py.rlspec")
    assert read(tmp_path / "py.rlspec") == read(tmp_path / "cli.rlspec")
    cli_report = json.loads(read(tmp_path / "cli.rlspec.report.json"))
    py_report = json.loads(read(tmp_path / "py.rlspec.report.json"))
    cli_report.pop("seconds"), py_report.pop("seconds")  # wall time
    assert py_report == cli_report
    assert s.dimension == 2 and s.grains == py_report["grains"] > 50
    assert s.meta["seed"] == 5


def test_a_saved_specimen_loads_back(tmp_path):
    s = rocklab.genesis(CARD)
    s.save(tmp_path / "a.rlspec")
    back = rocklab.Specimen.load(tmp_path / "a.rlspec")
    assert back.grains == s.grains and back.report["contacts"] == s.report["contacts"]
    back.save(tmp_path / "b.rlspec")
    assert read(tmp_path / "b.rlspec") == read(tmp_path / "a.rlspec")


def test_a_dict_card_makes_the_same_specimen_as_its_file():
    with open(CARD, encoding="utf-8") as f:
        card = json.load(f)
    a, b = rocklab.genesis(CARD), rocklab.genesis(card)
    ra, rb = a.report, b.report
    ra.pop("seconds"), rb.pop("seconds")
    assert ra == rb
    assert b.meta["material_file"] == "<card dict>"


def test_overrides_set_keys_like_a_calibration():
    s = rocklab.genesis(CARD, overrides={"flatjoint.fj_ten": 4e6, "porosity": 0.25})
    card = s.meta["material"]
    assert card["flatjoint"]["fj_ten"] == {"mean": 4e6, "sd": pytest.approx(8e5)}  # CoV kept
    assert card["porosity"] == 0.25
    assert s.report["porosity_target"] == 0.25


def test_threads_do_not_change_the_specimen(tmp_path):
    rocklab.genesis(CARD, threads=1).save(tmp_path / "1.rlspec")
    rocklab.genesis(CARD, threads=2).save(tmp_path / "2.rlspec")
    assert read(tmp_path / "1.rlspec") == read(tmp_path / "2.rlspec")


def test_bad_input_raises_value_error_with_the_command_lines_message(tmp_path):
    with open(CARD, encoding="utf-8") as f:
        card = json.load(f)
    card["porosity"] = 1.5
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(card))
    status, _, err = cli("genesis", bad, "-o", tmp_path / "x.rlspec", "-q")
    assert status == 2
    with pytest.raises(ValueError) as e:
        rocklab.genesis(bad)
    assert err.strip() == "rocklab: input error: " + str(e.value)
    assert "porosity" in str(e.value) and "1.5" in str(e.value)
    with pytest.raises(ValueError, match=r"<card dict>.*porosity"):
        rocklab.genesis(card)
    with pytest.raises(ValueError, match=r"override 'nosuch\.fj_ten'.*no section"):
        rocklab.genesis(CARD, overrides={"nosuch.fj_ten": 1e6})
    with pytest.raises(ValueError, match="seed"):
        rocklab.genesis(CARD, seed=-1)
    with pytest.raises(TypeError):
        rocklab.genesis(42)
    assert not os.path.exists(tmp_path / "x.rlspec")


def test_the_first_progress_event_is_the_estimate():
    # A specimen far larger than meant shows itself before genesis starts: the first event the
    # callback gets is the estimate (grains, memory, time on one core); raising there stops it.
    class Seen(Exception):
        pass

    first = []

    def stop(p):
        first.append(p)
        raise Seen()

    with pytest.raises(Seen):
        rocklab.genesis(CARD, progress=stop)
    assert first[0].tag == "genesis"
    assert first[0].message.startswith("estimate: about ")
    assert first[0].message.endswith(" on one core")
