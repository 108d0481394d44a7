"""Shared test configuration: hypothesis profiles, the slow marker and the shared reference folder."""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

REPO_ROOT = Path(__file__).resolve().parents[1]
#: The read-only reference folder beside the repository (DESIGN: never copied into the project).
SHARED_DIR = REPO_ROOT.parent / "shared"

# Deterministic in CI (same input and seed give the same output), exploratory locally.
settings.register_profile(
    "ci", derandomize=True, deadline=None, max_examples=60,
    suppress_health_check=[HealthCheck.too_slow],
)
settings.register_profile("dev", deadline=None, max_examples=100)
settings.load_profile("ci" if os.environ.get("CI") else os.environ.get("HYPOTHESIS_PROFILE", "dev"))


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--runslow", action="store_true", default=False, help="also run tests marked slow")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if config.getoption("--runslow"):
        return
    skip = pytest.mark.skip(reason="slow: run with --runslow")
    for item in items:
        if item.get_closest_marker("slow") is not None:  # a marker, not a keyword: a folder named "slow" is no mark
            item.add_marker(skip)


@pytest.fixture(scope="session")
def shared_dir() -> Path:
    """The ../shared reference folder; tests using it skip with a reason when it is absent."""
    if not (SHARED_DIR / "reference").is_dir():
        pytest.skip(f"the read-only reference folder {SHARED_DIR} is absent (it sits beside the repository)")
    return SHARED_DIR


def pytest_report_header(config: pytest.Config) -> list[str]:
    """Show the versions of the packages the results depend on at the top of every run."""
    from importlib.metadata import PackageNotFoundError, version

    names = ("cageless", "numpy", "scipy", "pandas", "h5py", "numba", "opencv-python-headless", "hypothesis")
    found = []
    for name in names:
        try:
            found.append(f"{name} {version(name)}")
        except PackageNotFoundError:
            found.append(f"{name} (not installed)")
    return ["versions: " + ", ".join(found)]


@pytest.fixture(autouse=True)
def _isolated_cache(tmp_path_factory, monkeypatch):
    """Every test gets its own cageless cache folder (hash cache and the like)."""
    monkeypatch.setenv("CAGELESS_CACHE_DIR", str(tmp_path_factory.mktemp("cache")))
