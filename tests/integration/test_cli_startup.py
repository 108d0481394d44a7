"""The command line starts lazily: ``--version`` and ``--help`` import no heavy library.

Start-up time is benchmarked (``benchmarks/track.py``), not asserted; what is asserted here is
the cause of a slow start: which modules a fresh interpreter has imported after the call.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from cageless.app.cli import SUBCOMMANDS, SUMMARIES, build_parser

#: Libraries that cost 0.1-1 s each to import; none is needed to print the version or the help.
HEAVY = ("numpy", "numba", "scipy", "pandas", "matplotlib", "cv2", "h5py", "dask", "tqdm",
         "cageless.tracking", "cageless.simulation", "cageless.comparison")


def _modules_after(code: str) -> set[str]:
    probe = (
        "import sys, json, contextlib, io\n"
        f"with contextlib.redirect_stdout(io.StringIO()):\n    {code}\n"
        "print(json.dumps(sorted(sys.modules)))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True)
    return set(json.loads(out.stdout.strip().splitlines()[-1]))


@pytest.mark.parametrize("code", [
    "import cageless.app.cli",
    "import cageless",
    "from cageless.app.cli import main; main(['--version'])",
    "from cageless.app.cli import main; main(['--help'])",
    "from cageless.app.cli import main; main([])",
])
def test_startup_imports_no_heavy_module(code):
    loaded = {m.split(".")[0] for m in _modules_after(code)}
    assert not loaded & set(HEAVY), f"{code!r} imported {sorted(loaded & set(HEAVY))}"


def test_a_subcommand_imports_its_own_module_only():
    loaded = _modules_after("from cageless.app.cli import main; main(['compare', '--help'])")
    assert "cageless.app.cli.compare" in loaded
    assert not {f"cageless.app.cli.{name}" for name in SUBCOMMANDS if name != "compare"} & loaded


def test_summaries_match_the_registered_help():
    """The help lines listed without importing a subcommand are the ones its module registers."""
    parser = build_parser()
    sub = parser._subparsers._group_actions[0]  # type: ignore[union-attr]
    registered = {a.dest: a.help for a in sub._choices_actions}
    assert registered == SUMMARIES
    assert tuple(SUMMARIES) == SUBCOMMANDS


def test_track_parser_states_the_tracking_defaults():
    """``cageless track`` writes out the detector names and speed window instead of importing them (the modules
    that define them bring in numba and SciPy); they must stay the tracking package's."""
    from cageless.app.cli import track
    from cageless.tracking.detect import DETECTORS
    from cageless.tracking.kinematics import DEFAULT_WINDOW

    assert track.DETECTORS == DETECTORS
    assert track.DEFAULT_WINDOW == DEFAULT_WINDOW


def test_track_starts_hashing_before_the_heavy_imports(tmp_path):
    """The input's hash starts (in a thread) before numba, SciPy or OpenCV is imported, so that it runs on the
    other core during those imports (benchmarks/track.py --speed measures the cold run)."""
    from pathlib import Path

    clip = Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "clip_3000rpm.mkv"
    probe = (
        "import sys, json, cageless.provenance as pv\n"
        "def seen(*a, **k):\n"
        "    print(json.dumps(sorted(m for m in ('numba', 'scipy', 'cv2', 'cageless.tracking') if m in sys.modules)))\n"
        "    raise SystemExit(0)\n"
        "pv.prefetch_hash = seen\n"
        "from cageless.app.cli import main\n"
        f"main(['track', {str(clip)!r}, '--speed-rpm', '3000', '-o', {str(tmp_path / 'out')!r}, '-q'])\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []


def test_the_tracking_pipeline_leaves_the_later_scipy_modules_to_a_thread():
    """``scipy.optimize`` and ``scipy.signal`` (0.5-0.7 and 0.35-0.42 s of CPU to import) are first needed after
    the median background; importing the pipeline must not load them, so that a cold ``cageless track``
    imports them on a thread beside its first stages (:func:`cageless.tracking.pipeline._import_late_modules`)."""
    loaded = _modules_after("import cageless.tracking.pipeline")
    assert "cageless.tracking.pipeline" in loaded
    assert not {"scipy.optimize", "scipy.signal"} & loaded


def test_track_never_imports_scipy_signal(tmp_path):
    """The speed's Savitzky-Golay filter is computed without ``scipy.signal`` (0.4-0.5 s of CPU to import with
    the ``scipy.stats`` it brings in, beyond ``scipy.optimize``): a whole ``cageless track`` run must not load
    it (:func:`cageless.tracking.kinematics._savgol_filter`)."""
    from pathlib import Path

    clip = Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    probe = (
        "import sys, json\n"
        "from cageless.app.cli import main\n"
        f"rc = main(['track', {str(clip)!r}, '-o', {str(tmp_path / 'out')!r}, '-q'])\n"
        "print(json.dumps([rc, sorted(m for m in ('scipy.signal', 'scipy.stats') if m in sys.modules)]))\n"
    )
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout.strip().splitlines()[-1]) == [0, []]
