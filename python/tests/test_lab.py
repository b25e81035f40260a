"""rocklab.test: the command line's results, history and cracks; dict and file protocols; a
Specimen object; errors; Ctrl-C; progress; threads."""
import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import rocklab
from conftest import CARD, cli, ucs_protocol, write_json


def read(path):
    with open(path, "rb") as f:
        return f.read()


def without_timing(results):
    """results.json without what depends on the machine (wall time, threads)."""
    r = json.loads(json.dumps(results))
    for section in (r, r.get("provenance", {})):
        for key in ("wall_time_s", "threads"):
            section.pop(key, None)
    return r


def long_protocol():
    """A UCS test of about 5 s: the tiny card's grains in a 32 mm x 64 mm rectangle (500 grains)
    to 3 % strain."""
    p = ucs_protocol(strain_limit=0.03)
    p["specimen"]["shape"] = {"shape": "rectangle", "width": 0.032, "height": 0.064}
    return p


def test_results_history_and_cracks_equal_the_command_lines(tmp_path):
    protocol = write_json(tmp_path / "ucs.json", ucs_protocol())
    status, _, err = cli("test", protocol, "-o", tmp_path / "cli", "-q")
    assert status == 0, err
    r = rocklab.test(protocol, out=tmp_path / "py")
    for name in ("history.csv", "cracks.csv", "events.csv", "specimen.rlspec"):
        assert read(tmp_path / "py" / name) == read(tmp_path / "cli" / name), name
    cli_results = json.loads(read(tmp_path / "cli" / "results.json"))
    assert without_timing(r.results) == without_timing(cli_results)
    # The arrays are the files' columns.
    names = read(tmp_path / "cli" / "history.csv").decode().splitlines()[0].split(",")
    assert list(r.history.dtype.names) == names
    assert r.history["axial_stress_Pa"].dtype == np.float64
    assert len(r.history) == len(read(tmp_path / "cli" / "history.csv").splitlines()) - 1
    assert r.out_dir == str(tmp_path / "py")
    assert r["test"] == "ucs" and r.results["youngs_modulus_Pa"] > 0


def test_a_dict_protocol_and_a_specimen_object(tmp_path):
    spec = rocklab.genesis(CARD)
    spec.save(tmp_path / "s.rlspec")
    p = ucs_protocol()
    by_object = rocklab.test(p, specimen=spec)
    p_file = dict(p, specimen={"file": str(tmp_path / "s.rlspec")})
    by_file = rocklab.test(write_json(tmp_path / "p.json", p_file))
    assert np.array_equal(by_object.history["axial_stress_Pa"], by_file.history["axial_stress_Pa"])
    assert by_object.out_dir is None  # a temporary folder, removed
    assert by_object.results["peak_stress_Pa"] == by_file.results["peak_stress_Pa"]
    if len(by_file.cracks):
        assert set(by_file.cracks["mode"]) <= {"tension", "shear"}


def test_threads_give_identical_histories():
    a = rocklab.test(ucs_protocol(), threads=1)
    b = rocklab.test(ucs_protocol(), threads=2)
    assert a.history.tobytes() == b.history.tobytes()


def test_bad_protocol_raises_value_error_with_the_command_lines_message(tmp_path):
    p = ucs_protocol()
    p["loading"] = {"strain_rate": -1}
    f = write_json(tmp_path / "bad.json", p)
    status, _, err = cli("test", f, "-o", tmp_path / "cli", "-q")
    assert status == 2
    with pytest.raises(ValueError) as e:
        rocklab.test(f, out=tmp_path / "py")
    assert err.strip() == "rocklab: input error: " + str(e.value)
    assert "strain_rate" in str(e.value)
    assert not os.path.exists(tmp_path / "py")
    with pytest.raises(ValueError, match=r"<protocol dict>.*strain_rate"):
        rocklab.test(p)
    with pytest.raises(ValueError, match="threads"):
        rocklab.test(ucs_protocol(), threads=-2)


def test_ctrl_c_raises_keyboard_interrupt_and_writes_nothing(tmp_path):
    # A test of about 5 s, interrupted after 1.5 s.
    timer = threading.Timer(1.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t0 = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            rocklab.test(long_protocol(), out=tmp_path / "out")
    finally:
        timer.cancel()
    assert time.monotonic() - t0 < 4  # it stopped soon after Ctrl-C
    assert not os.path.exists(tmp_path / "out") or not os.listdir(tmp_path / "out")


def test_progress_reaches_the_callback_and_its_exception_stops_the_test(tmp_path):
    seen = []
    rocklab.test(long_protocol(), progress=seen.append)
    assert seen and all(isinstance(p, rocklab.Progress) for p in seen)
    assert {p.tag for p in seen} <= {"genesis", "test"} and seen[-1].elapsed_s > 0

    class Stop(Exception):
        pass

    def stop(p):
        raise Stop()

    with pytest.raises(Stop):
        rocklab.test(long_protocol(), out=tmp_path / "out", progress=stop)
    assert not os.path.exists(tmp_path / "out") or not os.listdir(tmp_path / "out")


def test_the_gil_is_released_during_a_test():
    # A Python thread counts while a test runs: with the GIL held for the call it could not.
    ticks, stop = [], threading.Event()

    def count():
        while not stop.is_set():
            ticks.append(1)
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    try:
        before = len(ticks)
        rocklab.test(long_protocol(), threads=1)
        during = len(ticks) - before
    finally:
        stop.set()
        t.join()
    assert during > 100
