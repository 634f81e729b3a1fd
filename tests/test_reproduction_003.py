"""Paper 003's section-4 scenario as ``python -m baselines.reproduce --paper 003`` runs it.

Runs the reproduction's seven 12 000-s episodes (about 20 s) and checks what the paper shows
and the suite reproduces: ‖r‖ within [195, 205] m for the whole horizon, the attitude error
settling near zero, visible burst ripples in the settled body rate, a smaller α confining ‖r‖
more tightly. It also pins the documented discrepancies (docs/fidelity.md), so that a change
of physics that moves them is noticed: eq. (15) fires back to back (hundreds of bursts where the
paper reports 8), the radius range stops shrinking near 0.2 m, and the literal section-4 start
collides with the rotating body.
"""

import pytest

from baselines.reproductions import asteroid


@pytest.fixture(scope="module")
def result():
    return asteroid.reproduce()


def _claims(result) -> dict[str, dict]:
    return {item["claim"]: item for item in result["claims"]}


def test_tables_put_the_paper_beside_the_suite(result):
    names = [table["name"] for table in result["tables"]]
    assert len(names) == 3
    section_4 = result["tables"][0]["rows"][0]["metrics"]
    assert section_4["bursts"]["paper"] == 8
    assert section_4["sim_time_s"]["ours"] == section_4["sim_time_s"]["paper"] == 12000.0
    assert section_4["time_outside_s"]["ours"] == 0.0
    assert 195.0 <= section_4["min_radius_m"]["ours"] <= section_4["max_radius_m"]["ours"] <= 205.0


def test_claims_the_suite_reproduces_hold(result):
    claims = _claims(result)
    for statement in (
        "|r| stays within [195, 205] m for 12000 s (Fig. 7)",
        "the attitude error converges near zero (Fig. 14)",
        "visible variations of the body rate and torque at the bursts (Figs. 12, 15)",
        "a smaller alpha confines |r| more tightly",
    ):
        assert claims[statement]["holds"], claims[statement]


def test_documented_discrepancies_stay_as_documented(result):
    claims = _claims(result)
    section_4 = result["tables"][0]["rows"][0]["metrics"]
    assert not claims["about 8 bursts in 200 min, with long gaps (Figs. 10-11)"]["holds"]
    assert 150 <= section_4["bursts"]["ours"] <= 300
    assert not claims["with alpha small enough |r| stays within 0.01 m"]["holds"]
    literal = claims["the section-4 start (r(0) in the equator, v(0) along z) orbits 12000 s"]
    assert not literal["holds"]
    geometry = result["tables"][1]["rows"]
    assert geometry[0]["metrics"]["sim_time_s"]["ours"] < 6000.0  # r(0) on +y
    assert 11000.0 < geometry[1]["metrics"]["sim_time_s"]["ours"] < 12000.0  # best azimuth
    assert geometry[2]["metrics"]["min_clearance_m"]["ours"] > 50.0  # the default start
