"""The answer of a criterion and its linear first exit."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.analysis.analyze import analyze
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.criterion import CRITERION_NAMES, Criterion
from impact_balance.criteria.linear_exit import first_exit, speed_interval
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.criteria.zmp import ZmpCriterion


@pytest.mark.parametrize(
    ("limit", "interval"),
    [
        (ContactVelocityLimit(0.4, "ok", 1, 2), (0.0, 0.4)),
        (ContactVelocityLimit(math.inf, "unbounded"), (0.0, math.inf)),
        (ContactVelocityLimit(0.0, "already_falling"), None),
        (ContactVelocityLimit(0.0, "cannot_balance"), None),
    ],
)
def test_a_limit_from_inside_gives_the_interval_from_zero(limit, interval):
    assert limit.interval_from_inside() == interval
    assert limit.from_inside == (interval is not None)
    assert limit.is_finite == math.isfinite(limit.max_contact_velocity)


small = st.floats(-2.0, 2.0, allow_nan=False, allow_subnormal=False)


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(0.0, 2.0), min_size=1, max_size=5), st.data())
def test_first_exit_is_the_top_of_the_safe_interval_from_inside(margins, data):
    rates = np.array(
        data.draw(
            st.lists(
                st.lists(small, min_size=len(margins), max_size=len(margins)),
                min_size=1,
                max_size=4,
            )
        )
    )
    margins = np.array(margins)
    limit = first_exit(margins, rates)
    interval = speed_interval(margins, rates)
    assert limit.from_inside and interval is not None
    assert interval == pytest.approx(limit.interval_from_inside())
    if limit.status == "ok":
        # a brute-force check: every point stays inside at the limit, one is on the boundary
        slack = margins[None, :] - limit.max_contact_velocity * rates
        assert slack.min() >= -1e-9
        j, k = limit.limiting_vertex, limit.limiting_edge
        assert slack[j, k] == pytest.approx(0.0, abs=1e-9)


def test_first_exit_from_outside_is_already_falling():
    limit = first_exit([0.1, -0.5], [[1.0, -1.0]])
    assert limit == ContactVelocityLimit(0.0, "already_falling")
    assert limit.interval_from_inside() is None
    # the impact moves the point back in (rate -1 on the violated edge) from s = 0.5, and out
    # of the other edge at s = margin / rate: none with margin 0.1, (0.5, 1) with margin 1
    assert speed_interval([0.1, -0.5], [[1.0, -1.0]]) is None
    assert speed_interval([1.0, -0.5], [[1.0, -1.0]]) == pytest.approx((0.5, 1.0))


def test_the_criteria_are_a_family_and_answer_as_the_analysis():
    analysis = analyze("palm_push_two_feet")
    im, areas, scenario = analysis.impact, analysis.areas, analysis.scenario
    criteria: list[Criterion] = [
        ComCriterion(areas.com_velocity_area, im.model),
        ZmpCriterion(
            areas.zmp_area,
            im.model,
            analysis.stance.com,
            scenario.plane_height,
            scenario.gravity,
            scenario.impact.duration,
        ),
    ]
    assert [c.name for c in criteria] == list(CRITERION_NAMES)
    com, zmp = (c.limit(np.asarray(scenario.com_velocity)) for c in criteria)
    assert com == im.com and zmp == im.zmp
    assert (im.max_contact_velocity, im.status) == (com.max_contact_velocity, com.status)
    assert (im.zmp_max_contact_velocity, im.zmp_status) == (zmp.max_contact_velocity, zmp.status)
    assert analysis.to_dict()["impact"]["status"] == im.status
