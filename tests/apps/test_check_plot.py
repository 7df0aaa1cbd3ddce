"""A check at a glance: ``diagnose CHECK --plot`` draws one panel per role titled with its phase
and verdict (read from the axes titles, not the pixels), the high-load averages are those the
diagnosis's SNRs were read from, and a recording that is no check keeps the window figure."""

import json
import math

import pytest

from prsm_health.apps.check_plot import ROLE_TITLES, check_figure, panel_title
from prsm_health.apps.cli import main
from prsm_health.diagnostics.check_verdicts import check_verdicts
from prsm_health.diagnostics.diagnosis import diagnose, load_bundle
from prsm_health.io.parquet import write_run_parquet
from prsm_health.signals.check_averages import high_load_averages
from prsm_health.signals.check_indicators import SNR_PERIODS


@pytest.fixture(scope="module")
def bundle():
    return load_bundle()


@pytest.fixture(scope="module")
def check(short_check_run, bundle):
    run = short_check_run().without_truth()
    return run, diagnose(run, bundle)


def test_one_panel_per_role_titled_with_its_phase_and_verdict(check, bundle):
    import matplotlib.pyplot as plt

    run, result = check
    fig = check_figure(run, result, design=bundle.design, reference=run)
    try:
        titles = [ax.get_title(loc="left") for ax in fig.axes]
        assert len(titles) == len(ROLE_TITLES)
        phases = result.check_phases
        for title, (role, head) in zip(titles, ROLE_TITLES.items()):
            assert title.startswith(f"{head}: phase '{phases[role]}' — read"), title
        reversal = titles[list(ROLE_TITLES).index("reversal")]
        low, high = (f"{1e6 * result.clearance[k]:.1f}" for k in ("lower", "upper"))
        assert f"[{low}, {high}]" in reversal  # the clearance interval of the diagnosis
        assert "P(spall)" in titles[list(ROLE_TITLES).index("high_load")]
        assert result.fault_class in fig._suptitle.get_text()
        # the reference's averages drawn behind the recording's
        high_load = fig.axes[list(ROLE_TITLES).index("high_load")]
        assert "reference (baseline)" in [t.get_text() for t in high_load.get_legend().texts]
    finally:
        plt.close(fig)


def test_a_role_the_check_lacks_is_titled_not_read(check):
    _, result = check
    d = result.to_json()
    d["check_phases"] = {k: v for k, v in d["check_phases"].items() if k != "high_load"}
    verdict = next(v for v in check_verdicts(d) if v["role"] == "high_load")
    assert panel_title(verdict) == (
        f"{ROLE_TITLES['high_load']}: not read — the check has no {verdict['condition']}"
    )


def test_the_averages_are_those_the_diagnosis_read(check, bundle):
    run, result = check
    phase = run.phases()[result.check_phases["high_load"]]
    averages = high_load_averages(phase, bundle.design, run.operating.gear_ratio)
    compared = 0
    for name in SNR_PERIODS:
        read = result.indicators[f"check_highload_snr_{name}"]
        if read is None:  # fewer than two periods in the short check's phase
            assert not math.isfinite(averages[name].snr)
            continue
        assert averages[name].snr == pytest.approx(read, rel=1e-9, abs=1e-12)
        compared += 1
    assert compared >= 2


def test_diagnose_plot_draws_the_check(check, tmp_path, capsys):
    run, _ = check
    recording = write_run_parquet(run, tmp_path / "check.parquet")
    out = tmp_path / "figures" / "check.png"
    assert main(["diagnose", str(recording), "--plot", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["check_phases"]
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
