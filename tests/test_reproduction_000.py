"""Paper 000's section IV is reproduced by the environment's defaults.

Runs the four 300-s episodes of ``python -m baselines.reproduce --paper 000`` (a few minutes)
and checks the paper's statements that the suite reproduces: settling within 180 s / 200 s and
steady tracking errors within the paper's bounds for P1 and P2, the ESO's steady e1 within
Figs. 1-2's bounds and its convergence in about 10 s (Z1) and 15 s (Z2), and Case 2's fewer
transmissions with worse accuracy. The observer comparison with ref. [19] and the steady e2
bound are reported with their numbers (docs/fidelity.md explains why they are not asserted);
the steady e2 is checked to sit at the size of the disturbance jumps that transmissions cause.
"""

import pytest

from baselines.reproductions import orbit_attitude

pytestmark = pytest.mark.slow  # four 300-s episodes at 1 ms: about two minutes

REPRODUCED = (
    "P1: attitude settles",
    "P1: steady tracking errors",
    "P2: attitude settles",
    "P2: steady tracking errors",
    "ESO eq. (14): steady e1",
    "ESO eq. (14): Z1 tracks S",
    "Case 2 (larger gamma) transmits less",
    "Case 2 tracks less accurately",
)


@pytest.fixture(scope="module")
def result():
    return orbit_attitude.reproduce()


def test_every_reproduced_claim_holds(result):
    claims = {item["claim"]: item for item in result["claims"]}
    for prefix in REPRODUCED:
        matches = [item for text, item in claims.items() if text.startswith(prefix)]
        assert len(matches) == 1, prefix
        assert matches[0]["holds"], matches[0]


def test_tables_compare_every_reported_bound(result):
    tracking, observer, communication = result["tables"]
    for row in tracking["rows"]:
        for name, entry in row["metrics"].items():
            assert entry["ours"] is not None and entry["ours"] <= entry["paper"], (name, entry)
    assert [row["scenario"] for row in observer["rows"]] == [
        "Case 1, P1",
        "Case 1, P1, observer of ref. [19]",
    ]
    for row in observer["rows"]:
        assert set(row["metrics"]) >= {"e1_rot", "e1_trans", "e2_rot_Nm", "e2_trans_N"}
    case1, case2 = communication["rows"]
    assert case2["metrics"]["transmissions"]["ours"] < case1["metrics"]["transmissions"]["ours"]


def test_observer_comparison_is_reported_with_numbers(result):
    texts = [item for item in result["claims"] if "ref. [19]" in item["claim"]]
    assert len(texts) == 2
    for item in texts:
        assert "vs" in item["detail"]


def test_steady_e2_is_set_by_the_disturbance_jumps_at_transmissions(result):
    """The steady max of |e2| is of the size of the largest jump of Ξ·Δd at a transmission (an
    observer cannot track a step before it sees it), for both observers; on the torque side
    that jump alone exceeds Figs. 1-2's bound."""
    _, observer, _ = result["tables"]
    for row in observer["rows"]:
        metrics = {name: entry["ours"] for name, entry in row["metrics"].items()}
        for error, jump in (("e2_rot_Nm", "dd_step_rot_Nm"), ("e2_trans_N", "dd_step_trans_N")):
            assert 0.5 * metrics[jump] <= metrics[error] <= 2.0 * metrics[jump], (error, metrics)
        assert (
            metrics["dd_step_rot_Nm"]
            > orbit_attitude.OBSERVER_BOUNDS[orbit_attitude.P1]["e2_rot_Nm"]
        )
