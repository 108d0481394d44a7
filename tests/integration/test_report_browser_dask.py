"""The report in a real browser, and the same workflow on a Dask cluster.

* Browser: the sample report opens in headless Chromium (Debian's package, installed by ``.ci/run``)
  with no console errors, and every embedded figure has loaded (natural width > 0). A screenshot is
  kept in ``artifacts/`` (or ``$CAGELESS_ARTIFACT_DIR``).
* Dask: ``run_lab`` with the address of a ``distributed.LocalCluster`` gives the same table as the
  local run (DESIGN §10: nothing home-made stands in for a scheduler).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import pandas as pd
import pytest

from cageless.app.lab import LabOptions, run_lab

ROOT = Path(__file__).resolve().parents[2]
LAB = ROOT / "sample_data" / "lab"
#: The report's default simulates 20 cage revolutions after the start-up; these tests check the page and
#: the scheduler, not the statistics, so they state a shorter run (one revolution, 0.1 s at 6000 r/min).
QUICK = {"revolutions": 1.0}
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


@pytest.fixture(scope="module")
def small_lab(tmp_path_factory):
    lab = tmp_path_factory.mktemp("lab")
    shutil.copy(LAB / "n6000_Fr500_Fa0.cine", lab)
    return lab


@pytest.mark.skipif(CHROMIUM is None, reason="Chromium is not installed (.ci/run installs Debian's chromium)")
def test_report_opens_in_headless_chromium(small_lab, tmp_path):
    sync_api = pytest.importorskip("playwright.sync_api", reason="playwright (the test extra) is not installed")
    res = run_lab(small_lab, tmp_path / "out", LabOptions(workers=1, **QUICK), progress=False)
    errors: list[str] = []
    art = Path(os.environ.get("CAGELESS_ARTIFACT_DIR", ROOT / "artifacts"))
    art.mkdir(parents=True, exist_ok=True)
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=[
            "--no-sandbox", "--disable-gpu", "--disable-background-networking", "--disable-component-update",
            "--disable-sync", "--no-first-run"])
        page = browser.new_page(viewport={"width": 1300, "height": 900})
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.goto(res.report.resolve().as_uri())
        page.wait_for_load_state("load")
        images = page.eval_on_selector_all("img", "els => els.map(e => [e.complete, e.naturalWidth])")
        page.screenshot(path=str(art / "report.png"), full_page=True)
        browser.close()
    assert errors == []
    # four figures in the condition's section and the slip overlay on its summary card
    assert len(images) == 5 and all(done and width > 0 for done, width in images)
    assert (art / "report.png").stat().st_size > 10_000


def test_dask_cluster_gives_the_same_table(small_lab, tmp_path):
    distributed = pytest.importorskip("distributed", reason="dask[distributed] (the test extra) is not installed")
    local = run_lab(small_lab, tmp_path / "local", LabOptions(workers=2, **QUICK), progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        remote = run_lab(small_lab, tmp_path / "dask", LabOptions(scheduler=cl.scheduler_address, **QUICK), progress=False)
    a, b = pd.read_csv(local.table), pd.read_csv(remote.table)
    pd.testing.assert_frame_equal(a, b)
    assert local.n_failed == remote.n_failed == 0
