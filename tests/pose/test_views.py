"""The likelihood's views of a person: the validation gate around its predicted body."""

from occupose.config import PoseConfig
from occupose.grid.pixels import PersonPixels
from occupose.pose.views import views_from_pixels

import numpy as np


def test_points_far_from_the_predicted_body_are_left_out_of_the_likelihood(tracking):
    """The validation gate: pixels of the person's blob whose points are farther than PoseConfig.gate_m
    from its predicted body (a chair it carries) are not given to the likelihood; its own
    are. Without a predicted body (a new person), or with one so far off that the gate
    would leave fewer than PoseConfig.gate_keep of them, every pixel is."""
    tracker, depths = tracking
    person, observation = tracker.people[1], tracker._previous[1]
    cam = tracker.cameras[0].name
    own = observation.pixels[cam]
    # a carried box: pixels beside the person's, its points 0.65 .. 0.85 m in front of the
    # pelvis (beyond the hand that swings forward), at the pelvis's height
    box = np.setdiff1d(np.arange(own.max() + 1, own.max() + 400, 2), own)
    heading = person.pose[person.model.dof_names.index("heading")]
    ahead = np.linspace(0.65, 0.85, len(box))
    box_points = person.pose[:3] + np.column_stack([ahead * np.cos(heading), ahead * np.sin(heading),
                                                    np.linspace(-0.1, 0.1, len(box))])
    carried = PersonPixels(1, {cam: np.concatenate([own, box])},
                              {cam: np.concatenate([observation.camera_points[cam], box_points])})
    assert person.body_distance()(box_points).min() > PoseConfig.gate_m
    assert len(box) < (1 - PoseConfig.gate_keep) * len(own)  # the box is a small share: the gate applies
    mask = views_from_pixels(carried, depths, tracker.cameras, person.model, tracker.config.pose, person.body_distance())[0].mask.ravel()
    assert not mask[box].any()
    assert mask[own].mean() > 0.98  # measured 1.0: the walker's estimate fits its points
    everything = views_from_pixels(carried, depths, tracker.cameras, person.model, tracker.config.pose)[0].mask.ravel()
    assert everything[box].all() and everything[own].all()
    # a prediction 1 m off would keep none of the person's points: the gate stands aside
    off = person.pose.copy()
    off[0] += 1.0
    assert person.body_distance(off)(carried.camera_points[cam]).min() > PoseConfig.gate_m
    assert views_from_pixels(carried, depths, tracker.cameras, person.model, tracker.config.pose, person.body_distance(off))[0].mask.ravel()[own].all()

