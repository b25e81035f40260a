"""rocklab in Python: the virtual rock-mechanics laboratory's commands, in-process.

Every quantity in and out is SI (m, kg, s, N, Pa, J, rad); column and key names say their unit
(``axial_stress_Pa``, ``time_s``). The functions follow the command line (docs/python.md):

- :func:`genesis` - a material card to a :class:`Specimen` (``rocklab genesis``)
- :func:`test` - a laboratory test to a :class:`TestResult` (``rocklab test``)
- :func:`suite` - a suite of tests to a :class:`SuiteResult` (``rocklab suite``)
- :func:`calibrate` - a calibration campaign to a :class:`CalibrationResult` (``rocklab calibrate``)
- :func:`run` - a hand-built scene to a :class:`RunResult` (``rocklab run``)

A card, protocol, suite, calibration or scene is a file path or a dict of the file's JSON; a
dict's relative paths resolve against the working directory, a file's against its folder.
Bad input raises ``ValueError`` with the message ``rocklab`` prints before exiting with status 2
(file, key, value, allowed range), a physical blow-up :class:`PhysicsError` (status 3), an output
that cannot be written ``OSError`` (status 4). Long calls release the GIL; Ctrl-C stops them with
``KeyboardInterrupt`` and nothing half-written. ``progress`` takes a callable given a
:class:`Progress` about twice a second.
"""
# The standard modules under private names: the package's namespace is its API (dir(rocklab)).
import json as _json
import os as _os
import shutil as _shutil
import tempfile as _tempfile
from typing import NamedTuple as _NamedTuple, Optional as _Optional

from . import _rocklab
from ._rocklab import PhysicsError
from ._tables import read_structured as _read_structured, read_table as _read_table

__version__ = _rocklab.VERSION
__all__ = ["genesis", "test", "suite", "calibrate", "run", "Specimen", "TestResult",
           "SuiteResult", "CalibrationResult", "RunResult", "Progress", "PhysicsError",
           "lab_tests", "executable"]


class Progress(_NamedTuple):
    """One progress report: the command (``tag``: "test", "genesis", "suite", ...), its state as
    ``rocklab`` prints it, the fraction done in [0, 1] (None: unknown), the elapsed time [s] and
    the estimated time left [s] (None: unknown)."""
    tag: str
    message: str
    fraction: _Optional[float]
    elapsed_s: float
    eta_s: _Optional[float]


def _source(value, kind):
    """(name, text) for the extension: a path as itself, a dict as its JSON under "<KIND dict>"."""
    if isinstance(value, dict):
        return "<%s dict>" % kind, _json.dumps(value)
    if isinstance(value, (str, _os.PathLike)):
        return _os.fspath(value), None
    raise TypeError("%s: expected a file path or a dict, got %s" % (kind, type(value).__name__))


def _threads(threads):
    if threads is None:
        return 0
    if not isinstance(threads, int) or isinstance(threads, bool) or threads < 0:
        raise ValueError("threads: %r is not a number of threads (a whole number >= 0; 0 or "
                         "None: every core)" % (threads,))
    return threads


def _callback(progress):
    if progress is None:
        return None
    if not callable(progress):
        raise TypeError("progress: expected a callable taking a rocklab.Progress")
    return lambda *fields: progress(Progress(*fields))


def executable():
    """The ``rocklab`` binary that suites and calibrations start for their tests: the
    ROCKLAB_EXECUTABLE environment variable when set, else the one built or installed with this
    module."""
    path = _os.environ.get("ROCKLAB_EXECUTABLE")
    if not path:
        from ._config import EXECUTABLE
        path = EXECUTABLE
    if not _os.access(path, _os.X_OK):
        raise FileNotFoundError("rocklab binary %s not found (build the project, or set "
                                "ROCKLAB_EXECUTABLE)" % path)
    return path


def lab_tests():
    """The laboratory tests a protocol's "test" may name."""
    return list(_rocklab.lab_tests())


class _Output:
    """The output folder asked for, or a temporary one removed after the results are read."""

    def __init__(self, out):
        self.asked = out is not None
        self.tmp = None if self.asked else _tempfile.mkdtemp(prefix="rocklab-")
        self.path = _os.fspath(out) if self.asked else _os.path.join(self.tmp, "out")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.tmp:
            _shutil.rmtree(self.tmp, ignore_errors=True)

    def file(self, name):
        return _os.path.join(self.path, name)


class Specimen:
    """A specimen made by :func:`genesis` or read by :meth:`load`: a bonded packing of grains
    (lengths in m, stresses in Pa)."""

    def __init__(self, handle):
        self._h = handle

    @staticmethod
    def load(path):
        """Read a specimen file written by ``rocklab genesis`` or :meth:`save` (with its
        PATH.report.json when present)."""
        return Specimen(_rocklab.load_specimen(_os.fspath(path)))

    def save(self, path):
        """Write the specimen to ``path`` and its genesis report to ``path + ".report.json"``,
        byte for byte what ``rocklab genesis -o path`` writes (the report's wall time aside)."""
        self._h.save(_os.fspath(path))

    @property
    def report(self):
        """The genesis report (grains, contacts, porosity, stresses [Pa], steps, wall time [s]) as
        a dict; None for a file without its report."""
        return _json.loads(self._h.report_json)

    @property
    def meta(self):
        """What the specimen file records of its making: rocklab version, the card (file, name,
        hash, JSON), the seed and the genesis report."""
        return _json.loads(self._h.meta_json)

    @property
    def grains(self):
        """The number of grains (balls)."""
        return self._h.grains

    @property
    def dimension(self):
        """2 or 3."""
        return self._h.dimension

    def __repr__(self):
        return "<rocklab.Specimen %dD, %d grains>" % (self.dimension, self.grains)


def genesis(card, seed=None, threads=None, overrides=None, progress=None):
    """Make a specimen from a material card (``rocklab genesis``; docs/material-format.md).

    card: a card file path or a dict of its JSON. seed: replaces the card's random seed, a whole
    number in [0, 2^63). threads: OpenMP threads (None: every core). overrides: a dict of
    "section.key" -> value patched into the card first, named as a calibration names its
    parameters: a number on a {"mean", "sd"} strength keeps its coefficient of variation
    ({"flatjoint.fj_ten": 2e8} in Pa), a slit or gapped fraction takes its share from the bonded
    one, any other value replaces ({"specimen": {...}}). Returns a :class:`Specimen`.
    """
    name, text = _source(card, "card")
    if seed is not None and (not isinstance(seed, int) or isinstance(seed, bool) or
                             not 0 <= seed < 2**63):
        raise ValueError("seed: %r is not a seed: a whole number in [0, 2^63)" % (seed,))
    if overrides is not None and not isinstance(overrides, dict):
        raise TypeError("overrides: expected a dict of \"section.key\" -> value")
    handle = _rocklab.genesis(name, text, _json.dumps(overrides or {}),
                              -1 if seed is None else seed, _threads(threads),
                              _callback(progress))
    return Specimen(handle)


class TestResult:
    """A laboratory test's outcome: ``results`` (results.json as a dict: E [Pa], nu, peak stress
    [Pa], crack counts, warnings, ...), ``history`` and ``cracks`` (history.csv and cracks.csv as
    NumPy structured arrays, their column names kept: ``history["axial_stress_Pa"]``), ``events``
    (events.csv) and ``out_dir`` (the output folder, None when none was asked for)."""
    __test__ = False  # not a pytest class

    def __init__(self, results, history, cracks, events, out_dir):
        self.results, self.history, self.cracks, self.events = results, history, cracks, events
        self.out_dir = out_dir

    def __getitem__(self, key):
        return self.results[key]

    @property
    def warnings(self):
        """Doubtful or impossible measurements (also in results["warnings"])."""
        return list(self.results.get("warnings", []))

    def __repr__(self):
        return "<rocklab.TestResult %s, %d history rows, %d cracks>" % (
            self.results.get("test", "?"), len(self.history), len(self.cracks))


def test(protocol, specimen=None, out=None, threads=None, progress=None):
    """Run a laboratory test (``rocklab test``; docs/protocol-format.md): UCS, triaxial,
    Brazilian, direct tension or drop.

    protocol: a protocol file path or a dict of its JSON. specimen: a :class:`Specimen` or a
    specimen file path to test instead of the protocol's own "specimen". out: the output folder
    (results.json, history.csv, cracks.csv, vtk/, plots); None: a temporary one, removed once
    read. threads: OpenMP threads (None: every core). Returns a :class:`TestResult`.
    """
    name, text = _source(protocol, "protocol")
    with _Output(out) as o, _tempfile.TemporaryDirectory(prefix="rocklab-") as scratch:
        specimen_file = ""
        if isinstance(specimen, Specimen):
            specimen_file = _os.path.join(scratch, "specimen.rlspec")
            specimen.save(specimen_file)
        elif specimen is not None:
            specimen_file = _os.path.abspath(_os.fspath(specimen))
        results = _rocklab.test(name, text, specimen_file, o.path, _threads(threads),
                                _callback(progress))
        if not results:
            raise KeyboardInterrupt("rocklab test interrupted; nothing was written")
        return TestResult(_json.loads(results), _read_structured(o.file("history.csv")),
                          _read_structured(o.file("cracks.csv")),
                          _read_structured(o.file("events.csv")), o.path if o.asked else None)


class SuiteResult:
    """A suite's outcome: ``summary`` (summary.csv, the material's row of E, nu, UCS, BTS, direct
    tension, UCS/BTS, envelope, validity share), ``tests`` (tests.csv, one row per test), each a
    pandas DataFrame when pandas is installed, else a dict of column -> NumPy array; ``results``
    (summary.json as a dict) and ``out_dir``."""

    def __init__(self, summary, tests, results, out_dir):
        self.summary, self.tests, self.results, self.out_dir = summary, tests, results, out_dir

    @property
    def failed(self):
        """Whether a test of the suite failed (its status in ``tests``)."""
        return bool(self.results.get("failed", False))


def suite(suite, out=None, threads=None, progress=None):
    """Run a suite of laboratory tests on one material in parallel processes (``rocklab suite``;
    docs/protocol-format.md). suite: a suite file path or a dict (its "material" a card path).
    out: the output folder (None: a temporary one). threads: OpenMP threads per test process.
    Returns a :class:`SuiteResult`."""
    name, text = _source(suite, "suite")
    with _Output(out) as o:
        results = _json.loads(_rocklab.suite(name, text, o.path, _threads(threads), executable(),
                                            _callback(progress)))
        return SuiteResult(_read_table(o.file("summary.csv")), _read_table(o.file("tests.csv")),
                           results, o.path if o.asked else None)


class CalibrationResult:
    """A calibration campaign's outcome: ``met`` (every target met), ``validation_met`` (also on
    the fresh validation seeds, True when there were none), ``card`` (the fitted card as a dict),
    ``report`` (report.md's text), ``summary`` (evaluations, suites run and cached, wall time [s])
    and ``out_dir``."""

    def __init__(self, summary, card, report, out_dir):
        self.summary, self.card, self.report, self.out_dir = summary, card, report, out_dir
        self.met = bool(summary["met"])
        self.validation_met = summary["validation_seeds"] == 0 or bool(summary["validation_met"])


def calibrate(calibration, out, jobs=None, progress=None):
    """Fit a material card's micro-parameters to laboratory targets (``rocklab calibrate``;
    docs/calibration.md). calibration: a calibration file path or a dict. out: the output folder
    (card.json, report.md, convergence.csv/svg; its evaluations/ folder is the cache a rerun
    reuses). jobs: test processes at once (None: one per core). Returns a
    :class:`CalibrationResult`."""
    name, text = _source(calibration, "calibration")
    out = _os.fspath(out)
    summary = _json.loads(_rocklab.calibrate(name, text, out, _threads(jobs), executable(),
                                            _callback(progress)))
    with open(_os.path.join(out, "card.json"), encoding="utf-8") as f:
        card = _json.load(f)
    with open(_os.path.join(out, "report.md"), encoding="utf-8") as f:
        report = f.read()
    return CalibrationResult(summary, card, report, out)


class RunResult:
    """A scene's outcome: ``summary`` (steps, model time [s], wall time [s], event counts),
    ``results`` (results.json as a dict), ``history`` (history.csv as a NumPy structured array)
    and ``out_dir``."""

    def __init__(self, summary, results, history, out_dir):
        self.summary, self.results, self.history, self.out_dir = summary, results, history, out_dir


def run(scene, out=None, threads=None, progress=None):
    """Run a hand-built scene (``rocklab run``; docs/scene-format.md). scene: a scene file path or
    a dict. out: the output folder (None: a temporary one). threads: OpenMP threads (None: every
    core). Returns a :class:`RunResult`."""
    name, text = _source(scene, "scene")
    with _Output(out) as o:
        summary = _json.loads(_rocklab.run(name, text, o.path, _threads(threads),
                                          _callback(progress)))
        with open(o.file("results.json"), encoding="utf-8") as f:
            results = _json.load(f)
        return RunResult(summary, results, _read_structured(o.file("history.csv")),
                         o.path if o.asked else None)
