"""Stage 3 for one person: the pose problem and its priors, the estimator, proposals, occlusion, the person."""
