"""The part-based filter: per-part weighting beats a whole-vector filter of the same budget,
and shuffling (eq. 4) recombines the parts."""

import numpy as np

from occupose.filters import make_filter


def _track(name, problem, n, seed, steps, **options):
    pf = make_filter(name, problem, n, np.random.default_rng(seed), **options)
    pf.initialise(np.zeros(problem.num_dofs), 0.5)
    errors = []
    for _ in range(steps):
        problem.target += np.random.default_rng(len(errors)).normal(0, 0.02, problem.num_dofs)
        errors.append(np.abs(pf.step() - problem.target).mean())
    return np.mean(errors[steps // 2:]), pf


def test_part_based_beats_a_whole_vector_filter_of_the_same_budget(separable):
    """6 parts x 4 DOFs (24, about a body): over 5 seeds part-based 0.013, SIR 0.033-0.05 mean error."""
    results = {}
    for name in ("part-based", "sir"):
        problem = separable(num_parts=6, width=4, sigma=0.1, step=0.05, seed=1)
        results[name], pf = _track(name, problem, 200, 2, 40)
        assert problem.calls == 40  # the same budget: one likelihood call of 200 particles per step
    assert results["part-based"] < 0.5 * results["sir"], results
    assert pf.log_weights.shape == (200,)


def test_shuffling_recombines_the_parts(shared_score):
    """Systematic resampling returns sorted ancestors, so without the permutation of eq. 4 a new
    particle takes every part from ancestors of about the same rank: with equal group weights
    (they differ only by each draw's random offset) 30 % of the new particles are plain copies
    of old ones. With it, almost every new particle is a new combination of parts."""
    novel = {}
    for shuffle in (True, False):
        problem = shared_score(num_parts=5, width=2, sigma=2.0, seed=3)
        problem.diffusion[:] = 0.0  # only resampling and shuffling change the particles
        pf = make_filter("part-based", problem, 200, np.random.default_rng(8), shuffle=shuffle)
        pf.initialise(np.zeros(10), 0.5)
        pf.step()
        before = {row.tobytes() for row in pf.particles}
        pf.step()
        novel[shuffle] = np.mean([row.tobytes() not in before for row in pf.particles])
        assert pf.log_weights.shape == (200, 5)
        assert pf.diagnostics["group_survival"].shape == (5,)
        assert pf.diagnostics["group_survival"].min() > 0.3
    assert novel[True] > 0.95 and novel[False] < 0.8, novel
