"""`cageless bench accuracy` runs and prints its table (times are not asserted: benchmarks measure, tests check)."""

from __future__ import annotations

from cageless.simulation.bench import CANDIDATES, CVODE_VARIANTS, accuracy_study, format_accuracy, plot_accuracy


def test_accuracy_study_table_and_plot(tmp_path):
    result = accuracy_study(window_s=0.001, settle_s=0.03, numpy_window_s=0.0002)
    # the candidates, the CVODE variants, the automatic switch (first, the speed-up's base) and numpy LSODA
    assert len(result["rows"]) == len(CANDIDATES) + len(CVODE_VARIANTS) + 2
    assert all(r["ok"] for r in result["rows"])
    auto = result["rows"][0]
    # the automatic switch's row names its path: past the start-up, the probe after its second 20 us chunk takes
    # ark4 (measured), in one session
    assert auto["label"] == "auto (as simulate runs it: dp5 -> ark4 at 4e-05 s)" and auto["speedup_vs_auto"] == 1.0
    assert auto["method"] == "auto: dp5 -> ark4 at 4e-05 s"
    assert auto["slip_error_pp"] < 0.01  # the issue's bar, as ark4's own rows below
    assert "| auto (as simulate runs it: dp5 -> ark4 at 4e-05 s) |" in format_accuracy(result)
    dp5 = [r for r in result["rows"] if r["solver"].startswith("dp5")]
    # past the start-up every tolerance stays well within the 0.5 pp convergence bar of DESIGN §7
    assert all(r["slip_error_pp"] < 0.05 for r in dp5)
    cvode = [r for r in result["rows"] if r["solver"].startswith("CVODE")]
    assert len(cvode) == 5 + len(CVODE_VARIANTS) and all(r["slip_error_pp"] < 0.05 for r in cvode)
    rosw = [r for r in result["rows"] if r["solver"].startswith("rosw")]
    assert len(rosw) == 3 and all(r["slip_error_pp"] < 0.05 for r in rosw)
    ark = [r for r in result["rows"] if r["solver"].startswith("ark4")]
    # the IMEX method within the 0.01 pp bar against the tight reference at every tolerance shown
    assert len(ark) == 3 and all(r["slip_error_pp"] < 0.01 for r in ark)
    text = format_accuracy(result)
    assert "| dp5 (compiled RHS) | 1e-06 |" in text and "| LSODA (numpy RHS; rolling losses and film traction" in text
    numpy_row = result["rows"][-1]
    # against a reference of the physics it computes (no rolling losses, no regime traction); against the full
    # model it read 1.45 pp over 1 ms, the missing effects (found by a new user)
    assert numpy_row["solver"].startswith("LSODA (numpy") and numpy_row["slip_error_pp"] < 0.05
    plot_accuracy(result, str(tmp_path / "wp.png"))
    assert (tmp_path / "wp.png").stat().st_size > 1000


def test_model_fidelity_study_table():
    from cageless.simulation.bench import format_models, model_study

    result = model_study(window_s=0.001, settle_s=0.01)
    rows = result["rows"]
    assert [r["model"] for r in rows] == ["planar", "spatial, m = 1", "spatial, m = 5", "spatial, m = 1",
                                          "spatial, m = 5", "spatial, m = 11", "spatial, m = 21",
                                          "spatial, m = 5, CVODE (rtol 3e-08, cap 2 us)",
                                          "spatial, m = 5, CVODE (rtol 3e-08, cap 5 us)"]
    assert all(r["ok"] for r in rows)
    # under pure radial load the spatial model is the planar one: same answer whatever m
    assert all(r["slip_error_pp"] < 0.05 for r in rows[:3])
    assert "| 500 N + 400 N axial | spatial, m = 21 |" in format_models(result)
    # the stiff backend solves the same model: its error is the strip count's, as DP5's is at m = 5
    by = {r["model"]: r for r in rows[3:]}
    cvode = by["spatial, m = 5, CVODE (rtol 3e-08, cap 5 us)"]["slip_error_pp"]
    assert cvode < 3 * by["spatial, m = 5"]["slip_error_pp"] + 1e-3


def test_effects_ablation_table():
    from cageless.simulation.bench import effects_study, format_effects
    from cageless.simulation.effects import removable_effects

    result = effects_study(rpm=6000.0, duration_s=0.02, settle_s=0.01)
    rows = {r["removed"]: r for r in result["rows"]}
    # every effect of the table but the two contacts that make the model (race, ball-ball)
    assert set(rows) == {"(none: full model)", *removable_effects()}
    assert {"film_traction", "ball_ball_friction", "dry_friction"} <= set(rows)
    assert rows["drag"].get("note") is None  # on by default in a lubricated scene (issue 16)
    assert rows["race_traction"]["peak_slip_pct"] > 50  # nothing drives the balls without traction
    # the film sets the rolling force (issue 16): removing either moves the profile
    assert rows["ehl_film"]["profile_change_pp"] > 0.0
    assert rows["rolling_losses"]["profile_change_pp"] > 0.0
    assert rows["rolling_losses"]["peak_slip_pct"] < rows["(none: full model)"]["peak_slip_pct"]
    assert "| lubricant_damping |" in format_effects(result)


def test_effects_table_header_rounds_the_start_up():
    """The header names the window and the start-up in whole milliseconds (it printed 'profiles after
    75.6661 ms' for 6000 rpm: a new user's trial)."""
    from cageless.simulation.bench import format_effects

    scene = {"speed_rpm": 6000.0, "radial_load_n": 500.0, "axial_load_n": 0.0, "level": "planar",
             "duration_s": 0.15, "settle_s": 0.0756661}
    head = format_effects({"scene": scene, "rows": []}).splitlines()[0]
    assert head == ("Effect ablation, 6000 rpm, 500 N radial, 0 N axial (planar): 150 ms simulated after a start-up "
                    "of 76 ms, which the profiles leave out")


def test_work_precision_plot_tells_every_solver_apart_and_hides_no_point():
    """Fourteen series: each colour and marker pair once, and the legend outside the axes (the matplotlib
    colour cycle repeated after ten series, and the legend covered most points: a new user's trial)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from cageless.simulation.bench import accuracy_figure

    rows = [{"solver": f"s{k}", "wall_s_per_sim_s": 10.0 * (k + 1), "slip_error_pp": 10.0 ** -(k % 7)}
            for k in range(14)]
    fig = accuracy_figure({"rows": rows})
    try:
        ax = fig.axes[0]
        styles = {(line.get_color(), line.get_marker()) for line in ax.get_lines()}
        assert len(ax.get_lines()) == 14 and len(styles) == 14
        fig.canvas.draw()
        assert ax.get_legend().get_window_extent().x0 >= ax.get_window_extent().x1
    finally:
        plt.close(fig)
