"""A target the model could not see is shown as "not observable", never as a number
(prsm_health.diagnostics.not_observable): in the ``diagnose`` table, replay's lines, the diagnosis
figure and the check figure's panel titles; a clearance a health check measured stays a number.
Diagnoses built by hand, no model, no simulation."""

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from prsm_health.apps.check_plot import panel_title  # noqa: E402
from prsm_health.apps.cli.models import _replay_line, diagnosis_rows  # noqa: E402
from prsm_health.apps.plots import diagnosis_figure, plot_diagnosis  # noqa: E402
from prsm_health.diagnostics.answer import not_observable  # noqa: E402
from prsm_health.diagnostics.contract import (  # noqa: E402
    Diagnosis,
    MeasuredClearance,
    WindowSpan,
)
from prsm_health.diagnostics.not_observable import (  # noqa: E402
    NOT_OBSERVABLE,
    not_observable_text,
    observable,
)

MODEL = {"name": "m", "version": "1", "design": "paper01", "instrumentation": None}
PROBABILITIES = {"healthy": 0.2, "wear": 0.38, "spall": 0.42}
#: What the user saw for a 40 µm unit whose clearance the recording did not show.
HIDDEN_CLEARANCE = {"estimate": 4.7e-6, "lower": 0.1e-6, "upper": 39.3e-6}


def window(index: int, seen: bool) -> Diagnosis:
    clearance = {"estimate": 24e-6, "lower": 20e-6, "upper": 30e-6} if seen else HIDDEN_CLEARANCE
    return Diagnosis(
        clearance=clearance,
        fault_class="wear" if seen else "cannot_tell",
        class_probabilities=PROBABILITIES,
        observability={"clearance": seen, "fault": seen},
        indicators={},
        model=MODEL,
        window=WindowSpan(index, 0.5 * index, 0.5 * index + 0.5),
        undecided=None if seen else not_observable(["a load or motion reversal"], has_check=True),
    )


def recording(*seen: bool) -> Diagnosis:
    """A recording of windows that could or could not see the clearance: its values are those
    of the windows that did (of all where none did), its observability their share."""
    windows = [window(k, s) for k, s in enumerate(seen)]
    told = [w for w in windows if w.observability.clearance] or windows
    share = sum(seen) / len(seen)
    return Diagnosis(
        clearance=told[0].clearance,
        fault_class=told[0].fault_class,
        class_probabilities=PROBABILITIES,
        observability={"clearance": share, "fault": share},
        indicators={},
        model=MODEL,
        windows=windows,
        undecided=told[0].undecided,
        warnings=[] if any(seen) else ["no load or motion reversal in this window: …"],
    )


def test_the_rule():
    hidden = recording(False, False)
    assert not observable(hidden, "clearance") and not observable(hidden, "fault")
    assert not_observable_text(hidden, "clearance") == (
        "not observable — needs a load or motion reversal (interval 0.1–39.3 µm)"
    )
    assert (
        not_observable_text(hidden, "fault") == "not observable — needs a load or motion reversal"
    )
    # the JSON reads the same
    assert not_observable_text(hidden.to_json(), "clearance") == not_observable_text(
        hidden, "clearance"
    )
    # seen in some windows: the recording's value is of those windows, a reading
    assert observable(recording(True, False), "clearance")
    assert not_observable_text(recording(True, False), "fault") is None
    # no reason carried: the words alone
    assert not_observable_text({"observability": {"clearance": False}}, "clearance") == (
        NOT_OBSERVABLE
    )
    # an answer stored before observability was kept is shown as it was
    assert observable({"clearance": HIDDEN_CLEARANCE}, "clearance")


def test_a_measured_clearance_is_observable():
    d = window(0, False)
    d.measured_clearance = MeasuredClearance(30e-6, None, [], True, {}, None, None)
    assert observable(d, "clearance") and not observable(d, "fault")
    rows = {name: (value, unit) for name, value, unit in diagnosis_rows("c.parquet", d)}
    assert rows["clearance"] == ("  4.7 [  0.1,  39.3]", "µm (90 % interval)")


def test_diagnose_table_says_not_observable_instead_of_numbers():
    rows = diagnosis_rows("r.mcap", recording(False, False))
    named = {name: (value, unit) for name, value, unit in rows}
    assert named["clearance"] == (
        "not observable — needs a load or motion reversal (interval 0.1–39.3 µm)",
        "",
    )
    assert named["class probabilities"] == ("not observable — needs a load or motion reversal", "")
    assert not any(name.startswith("P(") for name, _, _ in rows)
    assert not any("4.7" in str(value) for _, value, _ in rows)
    # observable: the numbers, as before
    seen = {name: (value, unit) for name, value, unit in diagnosis_rows("r.mcap", recording(True))}
    assert seen["clearance"] == (" 24.0 [ 20.0,  30.0]", "µm (90 % interval)")
    assert seen["P(spall)"] == (0.42, "")


def test_replay_line_says_not_observable():
    entry = {"index": 0, "start": 0.0, "end": 0.5}
    hidden = _replay_line({**entry, "diagnosis": window(0, False).to_json()})
    assert "clearance not observable — needs a load or motion reversal" in hidden
    assert "4.7" not in hidden
    seen = _replay_line({**entry, "diagnosis": window(0, True).to_json()})
    assert seen.endswith("clearance  24.0 µm [ 20.0,  30.0]")


def texts(fig) -> list[str]:
    return [t.get_text() for t in fig.findobj(matplotlib.text.Text)]


@pytest.mark.parametrize("seen", [(False, True, False), (False, False)])
def test_the_diagnosis_figure_labels_what_is_not_observable(seen, tmp_path):
    result = recording(*seen)
    fig = diagnosis_figure(result)
    try:
        shown = texts(fig)
        assert "window not observable: estimate" in shown
        assert "window not observable: interval" in shown
        assert "class not observable (no probabilities)" in shown
        assert ("spall" in shown) == any(seen)  # the classes named where they are drawn
        title = fig._suptitle.get_text()
        if any(seen):
            assert "clearance 24.0 µm [20.0, 30.0]" in title
        else:
            assert "not observable" in title and "4.7" not in title
            assert {"clearance not observable", "class not observable"} <= set(shown)
        # the hidden estimate is hollow and grey, not the observable blue
        hollow = [line for line in fig.axes[0].get_lines() if line.get_label().endswith("estimate")]
        assert hollow and all(line.get_markerfacecolor() == "none" for line in hollow)
    finally:
        plt.close(fig)
    assert plot_diagnosis(result, tmp_path / "d.png").stat().st_size > 0


def test_the_check_panel_says_not_observable():
    verdict = {
        "role": "reversal",
        "condition": "a slow reversal under load",
        "phase": "slow reversal",
        "read": True,
        "readings": [],
        "classes": {"wear": 0.38},
        "clearance": None,  # check_verdicts: none where not observable
    }
    d = window(0, False).to_json()
    title = panel_title(verdict, d)
    assert "clearance not observable — needs a load or motion reversal" in title
    assert "wear: not observable" in title and "P(wear)" not in title
    assert "P(wear) 0.38" in panel_title(verdict)  # without the diagnosis: as before


def test_the_messages_foxglove_plots_leave_a_gap_where_the_model_did_not_see():
    from prsm_health.diagnostics.not_observable import OBSERVABLE, diagnosis_message

    hidden = diagnosis_message(window(0, seen=False).to_json())
    seen = diagnosis_message(window(1, seen=True).to_json())
    assert hidden["clearance"]["estimate"] == 4.7e-6  # the contract's numbers stay as they were
    assert hidden["shown"]["clearance"] is None and hidden["shown"]["clearance_upper"] is None
    assert set(hidden["shown"]["class_probabilities"]) == set(PROBABILITIES)
    assert all(p is None for p in hidden["shown"]["class_probabilities"].values())
    assert hidden["shown"]["clearance_state"].startswith(NOT_OBSERVABLE + " — needs a load")
    assert seen["shown"]["clearance"] == 24e-6 and seen["shown"]["clearance_lower"] == 20e-6
    assert seen["shown"]["class_probabilities"] == PROBABILITIES
    assert seen["shown"]["clearance_state"] == seen["shown"]["fault_state"] == OBSERVABLE
    assert set(seen["shown"]) == set(hidden["shown"])  # one schema for every message
