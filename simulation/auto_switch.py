"""The automatic stiff-solver switch, run over a long solve in chunks: progress, bounded memory, and the switch.

:func:`solve_chunks` integrates a problem chunk by chunk (one progress-bar update per chunk, samples
kept, internal steps not). With ``method="auto"`` it starts with the compiled DP5 and watches its
stiffness test (:func:`cageless.simulation.integrators.dp5.dp5_integrate`, Hairer & Wanner's h |lambda| > 3.25).
When most steps of a chunk sit at the stability edge (fraction >= :data:`STIFF_FRACTION`), the
step is set by stiffness rather than accuracy, as the paper's "Adams-GSTIFF" scheme switches to its
stiff branch once contacts stiffen. The driver then probes the stiff backends (:data:`STIFF_METHODS`),
SUNDIALS CVODE's variable-order BDF and the compiled IMEX method ``ark4`` (:data:`ARK_MODELS`), on the same
chunk from the same state, and switches to the cheaper if its cost is clearly smaller than DP5's (``ark4`` over
CVODE only when clearly smaller than CVODE's too). The probes' results are discarded, so the trajectory up to
the switch is DP5's. ``ark4`` pays past the start-up at ordinary loads (2.6-2.8 times cheaper than CVODE by the
cost model in the default 3000 rpm, 500 N scene), but its explicit part keeps the spin modes against the
traction slope, which under 20 kN hold its step near 57 ns (20 times CVODE's cost): its probe has a step budget
(:func:`_ark_budget`), the steps that the cost it must beat would buy it, and a probe that runs out of it stops
there and does not switch. Nor may the run's refused steps reach :data:`ARK_REFUSAL_BOUND` of its steps on ark4
(the hard cases' bound): a probe that would take the run there does not choose ark4, and a run on it that gets
there leaves it (:func:`_leave_ark`).
The first probe runs on the first chunk (:data:`PROBE_CHUNKS`); a probe that does not
switch makes the next one wait twice as many chunks as the last (:data:`PROBE_BACKOFF`: 1, 2, 4, ...), so
a run where CVODE never pays spends a handful of chunks on probes, and one where it pays once the violent
start is over (a BDF restarting from order 1 costs 2-2.7 times DP5 over the first 1.2 ms of a 30 ms run at
3000 rpm, 0.2-0.4 times after) still finds it. Before the first chunk, a pilot over a tenth of it
(:data:`PILOT_FRACTION`) starts the run on CVODE where DP5 is held by stability from the first step. At the planar
level the pilot first compares ark4's probe with DP5's cost at its stability edge, a closed form
(:func:`_edge_pilot`), and starts the run on ark4 without running DP5 where that already decides it.

The decision must not depend on timing, or the same scene would give different traces on a busy
machine (the determinism rule of the project). It compares a cost model instead: each solver's
right-hand-side evaluations times the model's cost per evaluation (:data:`RHS_COST_US`) plus its trial steps
(accepted and rejected, where the method counts them) times the method's overhead per step
(:data:`STEP_COST_US`), constants measured on this project's scenes, and switches when the cheaper stiff
backend's cost is below :data:`SWITCH_GAIN` of DP5's. Each probe and switch is recorded in the solution
(``extra["switches"]``: the backend chosen, its cost ratio and every candidate's) and from there in the
trace's solver statistics.

A probe sees one chunk only. After a switch, the stiff backend's mean cost per simulated second over
its last :data:`BACK_WINDOW` chunks is compared with DP5's on the probed chunk; once it costs more, the
run goes back to DP5, and probes again later on the same growing waits. The first chunk after the switch
is not judged: it holds the integrator's cold start (order 1, small steps, a first Jacobian), which the
probe already paid and judged. Single chunks are not judged either: a burst of contacts can double one
chunk's cost. CVODE's cost per chunk varies more than DP5's, which the race damping holds at its stability
limit: over 30 ms from the start at 3000 rpm, 500 N it ran at 0.2-0.4 of DP5's cost between bursts of
contacts that cost it 1.2-3.3 times DP5's for a few chunks, and 0.66 times DP5 overall. A way back for
good after such a burst left the run on DP5 for the rest of it. The way back still matters where the
stiff backend stops paying: a dry scene at the spatial level (allowed to switch for the measurement, see
:data:`SWITCH_WHEN_DRY`) makes CVODE's Newton iterations fail on the steep dry friction law.

The stiff backend cannot take a step back; after a switch it is stopped ahead of predicted contact
onsets instead (see :func:`cageless.simulation.solve.step_cvode`).

Both stiff backends are kept across chunks (:class:`cageless.simulation.solve.CvodeSession`,
:class:`cageless.simulation.solve.ArkSession`): ``ark4`` steps on towards the run's end and returns only where a
chunk's samples are written, so a run on it takes the steps one solve takes. At the planar level
(:data:`ARK_FIRST_MODELS`) ``ark4`` is probed before CVODE, and CVODE is not probed when ``ark4`` already costs below
:data:`SWITCH_GAIN` of the least CVODE could cost on the chunk (its steps capped, one right-hand side each): the
choice is then ``ark4`` whatever CVODE's probe would give, and the probe record says so (``skipped``).
"""

from __future__ import annotations

import sys
import time
from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm.auto import tqdm

from cageless.simulation._cache import compile_notice
from cageless.simulation.kernels import PLANAR, SPATIAL, model_gaps
from cageless.simulation.models import base as B
from cageless.simulation.models.strip_damping import P_F_STRIP
from cageless.simulation.problem import Problem
from cageless.simulation.integrators.dp5 import STATUS_MAX_STEPS, STATUS_OK
from cageless.simulation.solve import ARK_MAX_STEP_S, ArkSession, CvodeSession, Solution, solve, step_ark, step_cvode

__all__ = ["solve_chunks", "default_max_step", "CONTACT_MAX_STEP_S", "MAX_STEP_S", "RTOL_FACTOR", "STIFF_FRACTION",
           "RHS_COST_US", "STEP_COST_US", "SWITCH_GAIN", "STIFF_METHODS", "ARK_MODELS", "PROBE_CHUNKS",
           "BACK_WINDOW", "SWITCH_WHEN_DRY", "PROBE_BACKOFF", "PILOT_FRACTION", "ARK_REFUSAL_BOUND", "ARK_JUDGE_STEPS",
           "ARK_FIRST_MODELS"]

#: The progress bar shows simulated seconds without tqdm's rate, which for a simulation slower than real
#: time reads as an inverted "s/s" figure; {n:.4g} also hides float noise of the summed step lengths.
_BAR_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| {n:.4g}/{total:.4g} s [{elapsed}<{remaining}]"

#: Share of a chunk's accepted DP5 steps at the stability edge that triggers a probe. Measured over 50 ms
#: at 3000 rpm: the default 500 N scene 0.82 (the race damping), R = 0 0.74, a 20 kN load 0.99; only the
#: first milliseconds after the start, while the balls spread, fall below it.
STIFF_FRACTION = 0.6
#: The stiff backends the switch probes, in order: a later one is chosen over an earlier only when clearly cheaper
#: (see :func:`_probe`).
STIFF_METHODS: tuple[str, ...] = ("CVODE", "ark4")
#: The models on which ``ark4`` is probed: both levels. The spatial level was left out while ark4 refused 21 %
#: (500 N axial only) and 14 % (1 mrad tilt) of the steps of the spatial hard cases over 20 ms, above the 10 % they
#: allow (tests/validation/test_spatial.py): the first was its force-jump test on the ring's rows (fixed, see
#: :func:`cageless.simulation.solve._ark_jump_floor`), the second the start-up (2.4-4.8 ms: 680 of 1799 steps
#: refused, median step 0.1 us, the error test on the balls' spins against the traction slope, explicit in ark4)
#: and the contact changes after it (8-20 ms: 119 of 699), which :data:`ARK_REFUSAL_BOUND` now keeps off ark4.
ARK_MODELS: frozenset[int] = frozenset({PLANAR, SPATIAL})
#: The share of the run's accepted steps that its refused steps (error test, contact-onset and force-jump retries)
#: may reach while ``ark4`` runs: the hard cases' bound on a run (tests/validation/test_hard_cases.py,
#: test_spatial.py). The run's, not ark4's own: ark4 refuses one step at most contact changes, and its steps are
#: few (settled 5 ms windows at 3000 rpm: 17 of 174 planar, 21 of 146 spatial), so its own share sits near the
#: bound without any trouble, while in the 1 mrad tilt's start-up it refused 680 of 1799 (the spins against the
#: traction slope). Since ark4 is kept across chunks (its steps no longer cut at every chunk's end, so fewer) the
#: settled spatial 5 ms window from a DP5 chunk reached a bound of 0.1 at 3 ms (18 refused, all by the error test,
#: 0.107 of the run's steps) and went on on CVODE (12.5 -> 21.9 CPU s/s); both levels now use the planar hard cases'
#: 0.2, which the tilt's start-up still exceeds. A probe whose ark4 run would take the run's share (its steps and
#: refusals added to the run's) to the bound does not choose ark4, and a run on ark4 that reaches it leaves ark4
#: (:func:`_leave_ark`). By model id, each level's hard-case bound (tests/validation/test_hard_cases.py,
#: test_spatial.py). At the planar level
#: 0.1 moved the default 500 N scene off ark4 in its burst of contacts (dp5 -> ark4 at 3 ms -> CVODE at 5 ms -> dp5
#: at 8 ms -> ark4 at 10 ms, against dp5 -> ark4 at 3 ms -> dp5 at 6 ms -> ark4 at 9 ms), and none was needed while
#: ark4 restarted at every chunk; kept across chunks, its fewer steps took the 10 N hard case to 633 refused of 3033.
#: Over 100 ms settled at 3000 rpm, 500 N (planar) ark4 itself refused 889 of 4049 steps (22 %), and the run left it
#: for DP5 at 68 ms (3181 steps and 18741 right-hand sides more); with ark4's refusal controls (contact changes
#: crossed by onset steps, the force-jump bound: :mod:`cageless.simulation.integrators.ark`) 596 of 4108 (14.5 %),
#: and the run stays on ark4.
ARK_REFUSAL_BOUND: dict[int, float] = {SPATIAL: 0.2, PLANAR: 0.2}
#: The models on which ``ark4`` is probed before CVODE and CVODE is skipped where it cannot be chosen (see
#: :func:`_probe`). Not the spatial level: there a run that reaches :data:`ARK_REFUSAL_BOUND` leaves ark4 for CVODE
#: where CVODE's probe found it paying, which needs that probe (the settled 500 N + 400 N window does, at 3 ms).
#: At the planar level a run that leaves ark4 without CVODE's figure goes back to DP5 and probes again later.
ARK_FIRST_MODELS: frozenset[int] = frozenset({PLANAR})
#: Accepted steps of the run below which the share is not judged (one refusal in a few steps is not a trend).
ARK_JUDGE_STEPS = 50
#: Cost of one right-hand-side evaluation by model id (us), the compiled DP5 loop's own work included (its
#: step overhead is spread over its six evaluations a step). Measured as the process's CPU time over
#: evaluations, chunk by chunk, over 30 ms from the start of six lubricated scenes (3000 rpm 500 N, 1800 rpm,
#: 6000 rpm, 20 kN, 5 N at the planar level: 4.04-4.29; 500 N + 400 N axial with 5 strips: 8.9), in the same
#: run as :data:`STEP_COST_US`, on the shared 2-core machine (loaded; only the ratio of the two matters).
#: Models without an entry (the test models) count 1 us.
RHS_COST_US: dict[int, float] = {PLANAR: 4.1, SPATIAL: 8.9}
#: Overhead of one accepted step by (method, model id) in us, beyond its right-hand sides at the cost above.
#: CVODE with the structured Jacobian (:mod:`cageless.simulation.jacobian`, its evaluations counted with the
#: right-hand sides; the step's Python side, the onset control and the bookkeeping): 22 planar, 34 spatial,
#: from the same chunks (CPU time per step 27-30 us planar, 51 us spatial, at 1.85-1.93 evaluations a step).
#: With these the modelled CVODE/DP5 cost over the 30 ms matched the CPU-time ratio within 0.06 on all six
#: scenes (modelled 0.03, 0.72, 0.27, 0.66, 0.51, 0.50; CPU 0.03, 0.73, 0.27, 0.66, 0.46, 0.44). scipy's LSODA
#: ~21 (its Python step loop; measured against the earlier figures below). The compiled DP5 0.
#: Pairs without an entry count 30.
#: The IMEX method ``ark4`` counts six right-hand sides a trial step; beyond them a trial runs five implicit
#: stages, the error filter and the implicit part at its end: 1.9 + 0.89 + 0.60 us planar against 4.4 us a
#: right-hand side, 6.1 + 2.7 + 1.3 us spatial against 11.7 (CPU time per call at the settled 3000 rpm, 500 N
#: state, in one process), i.e. 0.40 and 0.50 of its six right-hand sides: 9.8 and 27 us at the costs above.
STEP_COST_US: dict[tuple[str, int], float] = {
    ("CVODE", PLANAR): 22.0, ("CVODE", SPATIAL): 34.0, ("LSODA", PLANAR): 21.0, ("LSODA", SPATIAL): 21.0,
    ("dp5", PLANAR): 0.0, ("dp5", SPATIAL): 0.0, ("ark4", PLANAR): 9.8, ("ark4", SPATIAL): 27.0,
}
#: The figures the switch used before, from wall time over 5 ms settled windows on a quieter machine and
#: before the rolling losses and drag made each evaluation dearer: they put DP5's evaluation at 1.8 us
#: (planar) and CVODE's step at 17 us, which made CVODE look 1.6 times dearer relative to DP5 than the
#: CPU time says. Kept for ``benchmarks/solver_speed.py``, which runs the switch as it was beside it.
RHS_COST_US_BEFORE: dict[int, float] = {PLANAR: 1.8, SPATIAL: 6.0}
STEP_COST_US_BEFORE: dict[tuple[str, int], float] = {
    ("CVODE", PLANAR): 17.0, ("CVODE", SPATIAL): 30.0, ("LSODA", PLANAR): 21.0, ("LSODA", SPATIAL): 21.0,
    ("dp5", PLANAR): 0.0, ("dp5", SPATIAL): 0.0,
}
#: Switch only when the stiff backend's modelled cost is below this share of DP5's: a switch gives up DP5's
#: contact-onset and force-jump control (CVODE is stopped ahead of onsets instead, and keeps the slip within
#: 0.01 pp), and the model is off by up to 0.06 of the ratio. A probe is a cold start (order 1, a first
#: Jacobian), so it overstates the backend's cost on the chunks that follow.
SWITCH_GAIN = 0.8
#: Default step cap (s) for contact resolution: ~t_H / 15 for a ball-ball impact (t_H = 29 us at 0.1 m/s).
#: DP5 never reaches it in practice (the race damping holds its step at ~1.2 us) and checks onsets itself.
CONTACT_MAX_STEP_S = 2e-6
#: Per-method default caps where they differ. The Rosenbrock-W method's steps are set by its error test (the cap
#: only bounds them: 3000 rpm, 500 N, rtol 1e-7, a 10 us and a 30 us cap gave the same steps and error). CVODE is stopped ahead of contact onsets rather than retried
#: across them (:func:`cageless.simulation.solve.step_cvode`); with at least 6 steps per impact its error control
#: resolves the impacts (measured before that onset control): over 5 ms at 1800 rpm from a bunched state (105 ball-ball
#: episodes) a 5 us cap logged the same episodes as a DP5 rtol 1e-10 reference, with peak forces within
#: 0.8 % and slip within 1.7e-3 pp, in 1126 steps (a 2 us cap: 4.4e-3 pp, 2608 steps; 20 us: 8.7e-3 pp).
#: The IMEX method's steps are set by its error test and the contact changes (its explicit part's fastest modes,
#: |lambda| ~ 2e4 1/s at 3000 rpm, 500 N, allow ~200 us); its cap bounds them: at 3000 rpm, 500 N (planar,
#: settled) 20 us gave 0.0009 pp of slip in 2185 right-hand sides per 5 ms, 50 us 0.0019 pp in 1639.
MAX_STEP_S: dict[str, float] = {"CVODE": 5e-6, "rosw": 1e-5, "ark4": ARK_MAX_STEP_S}
#: Per-method factor on the caller's rtol, so that one rtol means one accuracy whichever method runs.
#: CVODE's error test (a weighted RMS norm over the states) is looser than DP5's max norm at the same rtol,
#: and CVODE works at its error bound where DP5 is held far below it by stability. Measured on the energy
#: balance, from the packed start under 20 kN over 20 ms at the spatial level: DP5 at rtol 1e-6 drifts by
#: ~1e-6 of the input work; CVODE at 1e-7 by 1.1e-5 (1.17 s), at 3e-8 by 1.3e-6 (1.24 s: its steps are
#: held by the cap, so the tighter rtol costs ~6 %). Planar, 20 kN: 1.1e-5 at 1e-6, 9e-7 at 1e-7.
RTOL_FACTOR: dict[str, float] = {"CVODE": 0.03}
#: Whether a dry scene (Coulomb-Stribeck friction, no lubricant) may switch. It may not: CVODE's energy
#: balance there drifts above the 1e-5 of the input work that the hard cases allow (20 ms from the packed start
#: at 3000 rpm, spatial level, static 0.15 / Coulomb 0.1: 1.9e-5 with the structured Jacobian, 2.3e-5 with
#: CVODE's own; DP5 3.4e-7), whatever its Jacobian, and only falls slowly with rtol (10 ms: 1.4e-5 at
#: 3e-8, 3.8e-6 at 3e-10), while DP5 costs 1.3 times as much there (9.2 s against 7.2 s).
SWITCH_WHEN_DRY = False
#: Stiff-backend chunks averaged by the way back to DP5 (see the module text).
BACK_WINDOW = 2
#: The chunks (0-based) after which a stiff DP5 chunk is probed; with :data:`PROBE_BACKOFF` only the first
#: counts. The first chunk: a run that starts where DP5 is held by stability (20 kN: CVODE at 0.24 of its cost
#: there, 0.02 later) otherwise pays DP5 until the first probe (with the first probe at chunk 5 of 50, most of
#: its time).
PROBE_CHUNKS: tuple[int, ...] = (0,)
#: Share of the first chunk over which a pilot runs before it (None: no pilot). DP5 runs the pilot; if it is
#: held by stability there, CVODE is probed on the same piece, and if that pays the run starts on CVODE. Both
#: results are discarded: the first chunk then runs from the start. Under 20 kN, where DP5 is held at ~0.1 us
#: from the start, its first chunk (1/50 of the run) was about half of the run's time with CVODE after it;
#: where DP5 is not held by stability at the start (the balls spread: 500 N scenes, stiff fraction 0.1-0.24
#: on the first chunk) the pilot costs a tenth of a DP5 chunk and nothing else.
PILOT_FRACTION: float | None = 0.1
#: DP5's stability boundary on the negative real axis, h |lambda|: the root of |R(x)| = 1 of its stability function
#: R(z) = sum_{k<=5} z^k / k! + z^6 / 600 (Hairer & Wanner, Solving ODEs II, sect. IV.2), -3.3066. Where the race
#: damping holds DP5's step there, its cost over a pilot follows in closed form (:func:`_dp5_edge_cost`).
DP5_EDGE = 3.3066
#: After a probe that does not switch, or a way back to DP5, the next probe waits this many times as many
#: chunks as the last wait (1, 2, 4, ... chunks: at most about log2 of the chunk count of probes). None:
#: probe only at :data:`PROBE_CHUNKS`, and a way back is for good (the switch before).
PROBE_BACKOFF: int | None = 2


def _cost(sol: Solution, model_id: int) -> float:
    """Modelled cost of a solve in us (see :data:`RHS_COST_US` and :data:`STEP_COST_US`)."""
    trials = sol.n_steps + sol.n_rejected  # CVODE's and scipy's rejections are not counted (0)
    return sol.n_rhs * RHS_COST_US.get(model_id, 1.0) + trials * STEP_COST_US.get((sol.method, model_id), 30.0)


def _ark_budget(target_cost: float, model_id: int) -> int:
    """The trial steps of an ``ark4`` probe that together cost ``target_cost`` (six right-hand sides and
    :data:`STEP_COST_US` each): past them it cannot win, and it stops."""
    per_trial = 6 * RHS_COST_US.get(model_id, 1.0) + STEP_COST_US.get(("ark4", model_id), 30.0)
    return max(1, int(target_cost / per_trial))


def _ark_refusing(steps: int, refused: int, model_id: int) -> bool:
    """Whether a run of model ``model_id`` with ``steps`` accepted and ``refused`` refused steps has refused too
    many for ark4 (:data:`ARK_REFUSAL_BOUND`, judged from :data:`ARK_JUDGE_STEPS` steps on)."""
    return steps >= ARK_JUDGE_STEPS and refused >= ARK_REFUSAL_BOUND.get(model_id, np.inf) * steps


class _ArkProbe:
    """An ``ark4`` probe over one chunk that can be extended: run to a cost bar's step budget (:func:`_ark_budget`)
    and, when a later bar is higher, resumed in its session (:class:`cageless.simulation.solve.ArkSession`) up to the
    new budget, so that probing it before CVODE and again after costs what one probe at the higher bar costs."""

    def __init__(self, part: Problem, t: npt.NDArray[np.float64], kw: dict[str, Any], dp5_cost: float,
                 run_counts: tuple[int, int]) -> None:
        self.part, self.t, self.settings = part, t, _settings("ark4", kw)
        self.dp5_cost, self.run_counts = dp5_cost, run_counts
        self.session: ArkSession | None = None
        self.trials = self.steps = self.refused = self.rhs = 0
        self.wall, self.done, self.failed = 0.0, False, False

    def ratio(self, bar: float) -> float:
        """ark4's modelled cost on the chunk over DP5's, probed with the step budget of ``bar`` (us); inf when it
        runs out of that budget, fails, or would take the run's refused share to :data:`ARK_REFUSAL_BOUND`."""
        budget = min(self.settings["max_steps"], _ark_budget(bar, self.part.model_id))
        if not self.done and not self.failed and budget > self.trials:
            sol = step_ark(self.part, self.t, self.settings["rtol"], self.settings["max_step"], budget - self.trials,
                           self.settings["force_jump"], session=self.session, t_stop=float(self.t[-1]))
            self.session = sol.extra["ark4"]
            self.trials += sol.n_steps + sol.n_rejected
            self.steps, self.refused = self.steps + sol.n_steps, self.refused + sol.n_rejected
            self.rhs += sol.n_rhs
            self.wall += sol.wall_s
            self.done = sol.success
            self.failed = not sol.success and sol.status != STATUS_MAX_STEPS  # out of its budget: may go on
        if not self.done or self.trials > budget or _ark_refusing(self.run_counts[0] + self.steps,
                                                                   self.run_counts[1] + self.refused,
                                                                   self.part.model_id):
            return np.inf
        cost = self.rhs * RHS_COST_US.get(self.part.model_id, 1.0) + self.trials * STEP_COST_US.get(
            ("ark4", self.part.model_id), 30.0)
        return cost / self.dp5_cost


def _cvode_floor(part: Problem, t: npt.NDArray[np.float64], kw: dict[str, Any], dp5_cost: float) -> float:
    """A lower bound of CVODE's modelled cost over DP5's on the chunk: its steps are at most its cap long, and each
    takes at least one right-hand side (see :func:`_cost`)."""
    steps = np.ceil((float(t[-1]) - part.t0) / _settings("CVODE", kw)["max_step"])
    return float(steps * (RHS_COST_US.get(part.model_id, 1.0) + STEP_COST_US.get(("CVODE", part.model_id), 30.0))
                 / dp5_cost)


def _probe(part: Problem, t: npt.NDArray[np.float64], sol: Solution, time_s: float,
           kw: dict[str, Any], run_counts: tuple[int, int] = (0, 0), ark: _ArkProbe | None = None) -> dict[str, Any]:
    """Run each stiff backend (:data:`STIFF_METHODS`, in order) over the chunk ``sol`` covered and say whether
    the chosen one pays. A later backend replaces the one chosen so far only when it costs below
    :data:`SWITCH_GAIN` of it, as a switch from DP5 needs: the cost model is off by up to 0.06 of the ratio, and
    on near ties (1800 rpm bunching: CVODE 0.48, ark4 0.45 of DP5) the run keeps CVODE, as before ark4 was a
    candidate. An ``ark4`` probe stops at the step budget of that bar (:func:`_ark_budget`) and then counts as
    inf, as does one that would take the run's refused share (``run_counts``: its accepted and refused steps so
    far, the probe's added) to :data:`ARK_REFUSAL_BOUND`. On :data:`ARK_FIRST_MODELS`, ``ark4`` is probed first,
    against :data:`SWITCH_GAIN` of CVODE's least possible cost (:func:`_cvode_floor`): below it, the rule above
    chooses ark4 whatever CVODE's probe would give, so CVODE is not probed (``skipped`` records its bound); else
    the probes run as above, ark4's resumed where the first stopped. The record names the choice (``to``), its
    cost ratio to DP5 and every probed candidate's (``costs``), and ark4's refused share (``ark4_refused``). ``ark``:
    an ark4 probe of the same chunk already run (by :func:`_edge_pilot`), resumed here."""
    dp5_cost = max(_cost(sol, part.model_id), 1.0)
    if ark is not None:
        ark.dp5_cost = dp5_cost
    elif "ark4" in STIFF_METHODS and part.model_id in ARK_MODELS:
        ark = _ArkProbe(part, t, kw, dp5_cost, run_counts)
    costs: dict[str, float] = {}
    skipped: dict[str, float] = {}
    best, wall = STIFF_METHODS[0], 0.0
    if ark is not None and "CVODE" in STIFF_METHODS and part.model_id in ARK_FIRST_MODELS:
        floor = SWITCH_GAIN * min(_cvode_floor(part, t, kw, dp5_cost), 1.0)
        first = ark.ratio(floor * dp5_cost)
        if first < floor:
            costs["ark4"], skipped["CVODE"], best = first, floor / SWITCH_GAIN, "ark4"
    for method in STIFF_METHODS if not skipped else ():
        if method == "ark4" and ark is None:
            continue
        incumbent = costs.get(best, np.inf)  # what the method must beat: the choice so far if it pays, else DP5
        bar = SWITCH_GAIN * (incumbent if incumbent < SWITCH_GAIN else 1.0) * dp5_cost
        if method == "ark4":
            costs[method] = ark.ratio(bar)
        else:
            trial = solve(part, t, method=method, **_settings(method, kw))
            wall += trial.wall_s
            costs[method] = _cost(trial, part.model_id) / dp5_cost if trial.success else np.inf
        if method != best and costs[method] * dp5_cost < bar:
            best = method
    refused = ark.refused / max(ark.steps, 1) if ark is not None and ark.trials else None
    return {"time_s": time_s, "stiff_fraction": sol.n_stiff_steps / max(sol.n_steps, 1), "cost_ratio": costs[best],
            "switch": bool(costs[best] < SWITCH_GAIN), "to": best, "costs": costs, "skipped": skipped,
            "wall_s": wall + (ark.wall if ark is not None else 0.0), "ark4_refused": refused}


def _dp5_edge_cost(pr: Problem, span: float) -> float | None:
    """DP5's modelled cost (us, see :func:`_cost`) over ``span`` seconds from ``pr``'s start if every step sat at its
    stability edge, :data:`DP5_EDGE` / |lambda|, with |lambda| = n C_ho / m the race lubricant damping of a ball with
    n closed race contacts (the most of any ball at the start; the Hertz spring moves the overdamped mode by
    k / (n C_ho), about 1 %), six right-hand sides a step. A bound DP5 cannot beat for long: its stiffness test
    flags steps past 3.25 / |lambda|. Over the settled 0.2 ms pilot at 3000 rpm, 500 N (planar) it gives 171
    steps where DP5 takes 170 (and 1027 right-hand sides against 1026 = 6 x 171). None where the closed form does not
    apply: not the planar level, no race contacts or lubricant damping, or the paper's strips."""
    p = pr.params
    if pr.model_id != PLANAR or p[B.P_F_RACE] < 0.5 or p[B.P_F_LUB] < 0.5 or p[P_F_STRIP] > 0.5:
        return None
    z = int(p[B.P_Z])
    gaps = np.zeros(3 * z)
    model_gaps(pr.model_id, pr.y0, p, gaps)
    closed = int(np.max((gaps[:z] > 0.0).astype(int) + (gaps[z:2 * z] > 0.0)))
    if closed == 0:
        return None
    rate = closed * p[B.P_CHO] / p[B.P_M]
    return span * rate / DP5_EDGE * 6 * RHS_COST_US.get(pr.model_id, 1.0)


def _edge_pilot(pr: Problem, t_end: npt.NDArray[np.float64], kw: dict[str, Any]) -> tuple[dict[str, Any] | None,
                                                                                             _ArkProbe | None]:
    """The pilot's decision without DP5, on :data:`ARK_FIRST_MODELS`: ``ark4``'s probe over the pilot against DP5's
    cost at its stability edge (:func:`_dp5_edge_cost`), a cost DP5 does not beat. Where ark4 costs below
    :data:`SWITCH_GAIN` of it and of CVODE's least possible cost (:func:`_cvode_floor`), :func:`_probe` on DP5's
    pilot would choose ark4 too (DP5 held by stability there, CVODE skipped), so the run starts on ark4 without
    the DP5 pilot (0.2 ms of DP5 at 1.1 us steps, 2.5 % of a settled planar run's time): (the probe record, None).
    Else (None, the probe to resume in :func:`_probe`), or (None, None) where the closed form does not apply."""
    span = float(t_end[0] - pr.t0)
    edge = _dp5_edge_cost(pr, span) if pr.model_id in ARK_FIRST_MODELS and "CVODE" in STIFF_METHODS else None
    if edge is None or "ark4" not in STIFF_METHODS or pr.model_id not in ARK_MODELS:
        return None, None
    ark = _ArkProbe(pr, t_end, kw, edge, (0, 0))
    gate = SWITCH_GAIN * min(_cvode_floor(pr, t_end, kw, edge), 1.0)
    ratio = ark.ratio(gate * edge)
    if not ratio < gate:
        return None, ark
    refused = ark.refused / max(ark.steps, 1)
    return {"time_s": float(pr.t0), "stiff_fraction": None, "cost_ratio": ratio, "switch": True, "to": "ark4",
            "costs": {"ark4": ratio}, "skipped": {"CVODE": gate / SWITCH_GAIN}, "wall_s": ark.wall,
            "ark4_refused": refused, "dp5_edge": True, "pilot_s": span, "dp5_rate": edge / span}, None


def _pilot(pr: Problem, t_first: float, kw: dict[str, Any]) -> dict[str, Any] | None:
    """A pilot over :data:`PILOT_FRACTION` of the first chunk (ending at ``t_first``): the decision without DP5 where
    it is certain (:func:`_edge_pilot`), else DP5 over it and, where DP5 is held by stability there, the stiff
    backends' probe on it; None when no probe ran."""
    if not PILOT_FRACTION or not _may_switch(pr):
        return None
    t_end = np.array([pr.t0 + PILOT_FRACTION * (t_first - pr.t0)])
    quick, ark = _edge_pilot(pr, t_end, kw)
    if quick is not None:
        return quick
    sol = solve(pr, t_end, method="dp5", **_settings("dp5", kw))
    if not sol.success or sol.n_stiff_steps < STIFF_FRACTION * max(sol.n_steps, 1):
        return None
    probe = _probe(pr, t_end, sol, float(pr.t0), kw, ark=ark)
    probe["wall_s"] += sol.wall_s
    probe["pilot_s"] = float(t_end[0] - pr.t0)
    probe["dp5_rate"] = _cost(sol, pr.model_id) / probe["pilot_s"]
    return probe


def _may_switch(pr: Problem) -> bool:
    """Whether the automatic switch may take ``pr`` to the stiff backend (see :data:`SWITCH_WHEN_DRY`)."""
    return SWITCH_WHEN_DRY or "dry_friction" not in pr.effects


def default_max_step(method: str) -> float:
    """The step cap (s) a method gets when the caller gives none (see :data:`MAX_STEP_S`)."""
    return MAX_STEP_S.get(method, CONTACT_MAX_STEP_S)


def _settings(method: str, kw: dict[str, Any]) -> dict[str, Any]:
    """The caller's solver settings as ``method`` runs them: its default cap when none was given, and its
    rtol factor (:data:`RTOL_FACTOR`)."""
    return {**kw, "max_step": kw["max_step"] or default_max_step(method),
            "rtol": kw["rtol"] * RTOL_FACTOR.get(method, 1.0)}


Warm = CvodeSession | ArkSession | None


def _step_chunk(part: Problem, t: npt.NDArray[np.float64], current: str, kw: dict[str, Any], warm: Warm,
                t_stop: float) -> Solution:
    """One chunk with the current method, warm from the chunk before when it ran the same method: CVODE and the
    IMEX method keep their sessions (:class:`cageless.simulation.solve.CvodeSession`,
    :class:`cageless.simulation.solve.ArkSession`; the latter steps on towards the run's end ``t_stop`` and only
    returns where a chunk's samples are written). DP5 starts afresh each chunk, as it always has."""
    settings = _settings(current, kw)
    if current == "CVODE":
        return step_cvode(part, t, settings["rtol"], settings["max_step"], max_steps=settings["max_steps"],
                          session=warm if isinstance(warm, CvodeSession) else None)
    if current == "ark4":
        return step_ark(part, t, settings["rtol"], settings["max_step"], settings["max_steps"], settings["force_jump"],
                        session=warm if isinstance(warm, ArkSession) else None, t_stop=t_stop)
    return solve(part, t, method=current, **settings)


def _warm_state(current: str, sol: Solution, before: Warm) -> Warm:
    """What the next chunk of the same method starts from (see :func:`_step_chunk`)."""
    if current == "CVODE":
        return sol.extra.get("cvode", before)
    return sol.extra.get("ark4") if current == "ark4" else None


def _chunk(pr: Problem, t: npt.NDArray[np.float64], current: str, kw: dict[str, Any], warm: Warm, t_stop: float,
           left: ArkSession | None) -> tuple[Solution, Problem, npt.NDArray[np.float64], ArkSession | None]:
    """One chunk from ``pr`` over the samples ``t``, where ``left`` is an ark4 session the run has just left: its
    integrator is up to one step past the last sample written, so the chunk's samples up to there come from its
    last step, and ``current`` goes on from its time, state and contact log. (The solution, the problem and the
    samples ``current`` ran, the session still left when the whole chunk lay behind it.)"""
    if left is None:
        return _step_chunk(pr, t, current, kw, warm, t_stop), pr, t, None
    behind = t[t <= left.t]
    if len(behind) == len(t):
        sol = Solution(t=t, y=left.samples(t), status=STATUS_OK, message="reached the end", method=current,
                       extra={"log": left.log})
        return sol, pr, t, left
    part, rest = left.handover(pr), t[len(behind):]
    sol = _step_chunk(part, rest, current, kw, warm, t_stop)
    sol.t, sol.y = t, np.vstack([left.samples(behind), sol.y])
    return sol, part, rest, None


def _leave_ark(steps: int, refused: int, model_id: int, chosen_by: dict[str, Any],
               time_s: float) -> dict[str, Any] | None:
    """The way off ark4 once the run's refused steps reach :data:`ARK_REFUSAL_BOUND` of its ``steps``: to CVODE
    when the probe that chose ark4 (``chosen_by``) found CVODE paying too, else to DP5."""
    if not _ark_refusing(steps, refused, model_id):
        return None
    cvode = chosen_by.get("costs", {}).get("CVODE", np.inf)
    return {"time_s": time_s, "switch": True, "to": "CVODE" if cvode < SWITCH_GAIN else "dp5",
            "cost_ratio": float(cvode), "stiff_fraction": None, "wall_s": 0.0,
            "run_refused": refused / steps}


def _go_back(stiff_rates: list[float], dp5_rate: float, time_s: float) -> dict[str, Any] | None:
    """The way back to DP5, when the stiff backend now costs more per simulated second than DP5 did."""
    # the first chunk after the switch holds the integrator's cold start, paid once: not judged;
    # then the mean of the last BACK_WINDOW chunks, so that one burst of contacts does not decide
    recent = stiff_rates[1:][-BACK_WINDOW:]
    if len(recent) == BACK_WINDOW and _mean(recent) > dp5_rate:
        # the probe's chunk was not representative: go back to DP5 for good
        return {"time_s": time_s, "switch": True, "to": "dp5", "cost_ratio": _mean(recent) / dp5_rate,
                "stiff_fraction": None, "wall_s": 0.0}
    return None


def _mean(values: list[float]) -> float:
    """The mean of a few floats, summed in order as numpy sums fewer than eight (np.mean on a list cost 16 us a
    chunk, a fifth of the driver's time on ark4 chunks)."""
    total = 0.0
    for v in values:
        total += v
    return total / len(values)


class _Schedule:
    """When the next probe may run (see :data:`PROBE_CHUNKS` and :data:`PROBE_BACKOFF`)."""

    def __init__(self) -> None:
        self.next, self.wait, self.listed = (PROBE_CHUNKS[0] if PROBE_CHUNKS else -1), 1, list(PROBE_CHUNKS[1:])

    def due(self, i: int) -> bool:
        """Whether a stiff DP5 chunk ``i`` is probed."""
        return i == self.next

    def not_stiff(self, i: int) -> None:
        """Chunk ``i`` was due but not stiff: with a backoff the next stiff chunk is probed."""
        if i == self.next:
            self.next = i + 1 if PROBE_BACKOFF else (self.listed.pop(0) if self.listed else -1)

    def wait_longer(self, i: int, for_good: bool = False) -> None:
        """After a probe that did not switch (or, ``for_good``, a way back) at chunk ``i``."""
        if PROBE_BACKOFF:
            self.wait *= PROBE_BACKOFF
            self.next = i + self.wait
        else:
            self.next = -1 if for_good else (self.listed.pop(0) if self.listed else -1)


def _begin(pr: Problem, t: npt.NDArray[np.float64], edges: npt.NDArray[np.int64], method: str, progress: bool,
           kw: dict[str, Any]) -> tuple[str, float, list[dict[str, Any]]]:
    """The compile notice (with ``progress``), then for ``"auto"`` the pilot probe over the first chunk: the
    method to start with, DP5's cost rate (inf until measured) and the probes so far."""
    notice = compile_notice() if progress else None
    if notice:
        tqdm.write(notice, file=sys.stderr)
    if method != "auto":
        return method, np.inf, []
    pilot = _pilot(pr, float(t[edges[1]]), kw) if len(edges) > 1 else None
    if pilot is None:
        return "dp5", np.inf, []
    rate = pilot.pop("dp5_rate")
    if pilot["switch"]:
        return pilot["to"], rate, [pilot]
    return "dp5", np.inf, [pilot]


def solve_chunks(pr: Problem, t: npt.NDArray[np.float64], rtol: float, method: str, max_step: float | None,
                 chunks: int, progress: bool, max_steps: int, force_jump: float) -> Solution:
    """Integrate ``pr`` over the samples ``t`` in about ``chunks`` pieces; ``method`` is a key of
    :data:`cageless.simulation.solve.METHODS` (``"auto"``: see the module text). ``max_step`` None gives each
    method its default cap (:func:`default_max_step`), also after a switch; a number applies to all.
    ``rtol`` is scaled per method by :data:`RTOL_FACTOR`. The solution's ``wall_s`` is the whole call's."""
    start = time.perf_counter()
    edges = np.unique(np.linspace(0, len(t) - 1, chunks + 1).astype(int))
    ys = [pr.y0[None, :]]
    totals = dict.fromkeys(("n_steps", "n_rejected", "n_rhs", "n_onset_retries", "n_contact_changes",
                            "n_force_jump_retries", "n_stiff_steps"), 0)
    y0, log, t0 = pr.y0.copy(), pr.log.copy(), float(t[0])
    auto = method == "auto"
    schedule, sol = _Schedule(), None
    warm: Warm = None
    left: ArkSession | None = None  # an ark4 session the run has left (see _chunk)
    sessions = 0  # ark4 sessions started
    stiff_rates: list[float] = []  # cost per simulated second of each stiff chunk since the switch
    current, dp5_rate, probes = _begin(pr, t, edges, method, progress, {
        "rtol": rtol, "max_step": max_step, "force_jump": force_jump, "max_steps": max_steps})
    with tqdm(total=float(t[-1] - t[0]), desc="simulated", disable=not progress, leave=False,
              bar_format=_BAR_FORMAT) as bar:
        for i, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
            # a kept ark4 session goes on from its own state: no problem to build for it
            part = pr if isinstance(warm, ArkSession) else replace(pr, log=log, y0=y0, t0=t0)
            kw = {"rtol": rtol, "max_step": max_step, "force_jump": force_jump,
                  "max_steps": max(1, max_steps - totals["n_steps"] - totals["n_rejected"])}
            sol, part, t_part, left = _chunk(part, t[a + 1:b + 1], current, kw, warm, float(t[-1]), left)
            before, warm = warm, _warm_state(current, sol, warm)
            sessions += isinstance(warm, ArkSession) and warm is not before
            ys.append(sol.y)
            totals = {key: n + getattr(sol, key) for key, n in totals.items()}
            bar.update(float(t[b] - t[a]))
            if not sol.success:
                break
            rate = _cost(sol, pr.model_id) / float(t[b] - t[a])
            if auto and current != "dp5":
                stiff_rates.append(rate)
                back = (_leave_ark(totals["n_steps"], totals["n_rejected"], pr.model_id, probes[-1], float(t[b]))
                        if current == "ark4" else None)
                back = back or _go_back(stiff_rates, dp5_rate, float(t[b]))
                if back is not None:
                    probes.append(back)
                    left = warm if isinstance(warm, ArkSession) else None
                    current, stiff_rates, warm = back["to"], [], None
                    if current == "dp5":
                        schedule.wait_longer(i, for_good=True)
            elif auto and current == "dp5" and schedule.due(i):
                if sol.n_stiff_steps >= STIFF_FRACTION * max(sol.n_steps, 1) and _may_switch(pr):
                    probes.append(_probe(part, t_part, sol, float(t[b]), kw,  # the run as if ark4 ran the chunk
                                         (totals["n_steps"] - sol.n_steps, totals["n_rejected"] - sol.n_rejected)))
                    if probes[-1]["switch"]:
                        current, dp5_rate, warm = probes[-1]["to"], rate, None
                    else:
                        schedule.wait_longer(i)
                else:
                    schedule.not_stiff(i)
            y0, log, t0 = sol.y[-1].copy(), sol.extra.get("log", log), float(t[b])
    return _joined(t, ys, sol, method, probes, time.perf_counter() - start, log, totals, sessions)


def _joined(t: npt.NDArray[np.float64], ys: list[npt.NDArray[np.float64]], sol: Solution | None, method: str,
            probes: list[dict[str, Any]], wall: float, log: npt.NDArray[np.float64],
            totals: dict[str, int], sessions: int) -> Solution:
    """The chunks' samples and statistics as one solution (NaN after a failure), with the ark4 sessions the run
    started."""
    y = np.concatenate(ys)
    if len(y) < len(t):
        y = np.vstack([y, np.full((len(t) - len(y), y.shape[1]), np.nan)])
    assert sol is not None
    used = method if method != "auto" else ("auto: dp5" + "".join(f" -> {p['to']} at {p['time_s']:.4g} s"
                                                                  for p in probes if p["switch"]))
    return Solution(t=t, y=y, status=sol.status, message=sol.message, method=used, wall_s=wall,
                    extra={"log": log, "switches": probes, "ark4_sessions": sessions}, **totals)
