"""Person.recheck: an estimate that no longer explains its points is found again, the
person keeping its id (issue 24), and a search that finds nothing better changes nothing."""

import numpy as np
import pytest

from occupose.config import TrackerConfig
from occupose.evaluation.errors import frame_errors, joint_errors
from occupose.pose.search import explained_share
from occupose.tracker import Tracker

LOST_AT = 30  # the estimate is thrown off its person after this frame (walk: 60 frames)


def _run(walk, settings: dict, throw: float) -> tuple[Tracker, list[float]]:
    """Track ``walk`` with ``settings``; after frame LOST_AT move the person's estimate (and
    its particles) ``throw`` metres along x; the frame errors (metres) from then on."""
    scenario, rendered = walk
    tracker = Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values(settings), seed=0)
    errors = []
    for f in rendered:
        out = tracker.update(f.depth).estimates
        if f.index == LOST_AT:
            person = tracker.people[1]
            offset = np.zeros(person.model.num_dofs)
            offset[0] = throw
            person.estimator.shift(offset)
            person.pose = person.estimator.filter.estimate.copy()
        elif f.index > LOST_AT:
            assert list(out) == [1]
            errors.append(frame_errors(joint_errors(f.joints[0][None], out[1].joints[None]))[0])
    return tracker, errors


def test_the_test_fires_on_a_lost_estimate_and_not_on_a_good_one(walk):
    """With no search on the schedule, nothing is doubtful over the 30 frames of the
    undisturbed walk; thrown 0.6 m off (none of its points near it), the estimate is
    doubtful at once and searched for again after ``recover.frames`` frames."""
    scenario, rendered = walk
    config = TrackerConfig().with_values({"recover.enabled": True, "recover.every": 1000})
    tracker = Tracker(scenario.cameras, scenario.fps, config, seed=0)
    for f in rendered[:LOST_AT + 1]:
        tracker.update(f.depth)
    person = tracker.people[1]
    assert person.searches == 0 and person.doubtful == 0
    offset = np.zeros(person.model.num_dofs)
    offset[0] = 0.6
    person.estimator.shift(offset)
    person.pose = person.estimator.filter.estimate.copy()
    for f in rendered[LOST_AT + 1:LOST_AT + 1 + config.recover.frames]:
        tracker.update(f.depth)
    assert person.searches == 1 and list(tracker.people) == [1]


@pytest.mark.parametrize("throw", [0.6, -0.4])
def test_an_estimate_thrown_off_its_person_comes_back_sooner(walk, throw):
    """With the searches on (every 15 frames, and at once after doubtful ones; off by
    default) the estimate thrown 0.6 m or 0.4 m off is back 4 frames later and stays there
    (measured with the measured noise model: medians of 5.5 and 6.6 cm from then on, at
    most 7.5 and 9.5 cm), the same id, no other track; without the searches it comes back
    by itself more slowly (measured: a mean of 14.6 and 14.2 cm over the 10 frames from
    then on, against 5.4 and 7.4 cm with them). Not on every seed: with seed 1 the one
    thrown 0.4 m is found worse by the search (19.9 cm) than by itself (5.6 cm)."""
    tracker, errors = _run(walk, {"recover.enabled": True}, throw)
    assert tracker.people[1].recoveries >= 1 and list(tracker.people) == [1]
    assert np.median(errors[4:]) < 0.07 and max(errors[4:]) < 0.12, np.round(errors, 3)
    _, without = _run(walk, {"recover.enabled": False}, throw)
    assert np.mean(without[4:14]) > 0.10 and np.mean(errors[4:14]) < np.mean(without[4:14]) - 0.05, \
        np.round(without, 3)


def test_searching_on_schedule_keeps_a_good_estimate(walk):
    """On the undisturbed walk the searches every 15 frames change the error by at most a
    centimetre on average."""
    scenario, rendered = walk
    means = []
    for enabled in (True, False):
        tracker = Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values({"recover.enabled": enabled}),
                          seed=0)
        errors = []
        for f in rendered:
            out = tracker.update(f.depth).estimates
            if 1 in out and f.index >= 10:
                errors.append(frame_errors(joint_errors(f.joints[0][None], out[1].joints[None]))[0])
        means.append(np.mean(errors))
        if enabled:
            assert tracker.people[1].searches >= 2
    assert abs(means[0] - means[1]) < 0.01, means


def test_explained_share():
    points = np.array([[0.0, 0, 0], [0.05, 0, 0], [0.2, 0, 0], [1.0, 0, 0]])
    distance = lambda p: np.abs(p[:, 0])  # noqa: E731  (a body: the plane x = 0)
    assert explained_share(distance, points, 0.05) == 0.5
    assert explained_share(distance, points[:0], 0.05) == 1.0
