"""The same scene gives the same trace whether its kernels were just compiled or loaded from numba's cache.

With LLVM's "reassoc" fast-math flag the two disagreed at round-off (the settled state of one scene
differed in the last bits, and the chaotic ball ring then amplified that), so a user's first run after
an install differed from every later one. This runs one short solve twice in fresh processes sharing
an empty cache directory: the first compiles, the second loads; the outputs must match bit for bit.
"""

from __future__ import annotations

import os
import subprocess
import sys

_SCRIPT = """
import hashlib, numpy as np
from cageless.conditions import OperatingConditions
from cageless.simulation.effects import choose_model
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.scene import Scene
from cageless.simulation.run import build_problem
from cageless.simulation.solve import solve
scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 0.0))
pr = build_problem(scene, choose_model(scene), ModelParameters())
sol = solve(pr, np.linspace(0.0, 2e-3, 21), rtol=1e-6, max_step=2e-6)
print(hashlib.sha256(sol.y.tobytes()).hexdigest(), sol.n_steps)
"""


def test_fresh_compile_and_cached_code_give_identical_traces(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache")}
    runs = [subprocess.run([sys.executable, "-c", _SCRIPT], capture_output=True, text=True, env=env, check=True,
                           timeout=600).stdout.split() for _ in range(2)]
    assert any((tmp_path / "numba-cache").rglob("*.nbc")), "the first run should have filled the cache"
    assert runs[0] == runs[1]
