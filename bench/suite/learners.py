"""The methods the suite compares, all on one parameter vector of a
primo.gym.BlackBox, ``[q̂, Δθ]`` (the generalized movement G(q̂) plus a
change of its DMP parameters), all stopped at the first successful
episode or after ``budget`` episodes. Each returns its episodes.

One exploration scale for every method that explores Δθ (chosen once,
not tuned per task or method): a tenth of the generalized movement's own
scale at the context. A DoF's weights have the standard deviation 0.1 ×
the root mean square of its weights, its goal 0.1 × its amplitude
|g − y0| (at least 1 mm or mrad), τ 0.1 τ. Rewards for PoWER are
exp(−‖error‖ / tolerance); costs for CMA-ES and PI-BB ‖error‖. Every
method's first roll-out is the generalized movement (PoWER's mean
roll-out; the population methods evaluate their initial mean first),
so a context it solves costs each method one roll-out.

The ``promp-`` methods run a ProMP of the same demonstrations instead
(``primo.gym.BlackBox`` with a ``primo.ProMp``): its mean, which is not
generalized over the context, is their first roll-out; PoWER explores
its weights (0.1 × each DoF's root mean square weight), the goal learner
conditions it on the goals (and via-points) it learns.
"""

from __future__ import annotations

from typing import Any, Callable

import cma
import numpy as np

import primo
import primo.gym

def exploration(box: primo.gym.BlackBox, context: Any) -> tuple[np.ndarray, int]:
    """Per-parameter exploration standard deviations of Δθ, and how many
    of them are weights (θ is the weights, then the goals, then τ)."""
    dmp = box.dmp(box.query(context))
    w = dmp.params[: dmp.dof * dmp.kernels].reshape(dmp.dof, dmp.kernels)
    weights = 0.1 * np.sqrt(np.mean(w**2, axis=1, keepdims=True))
    goals = 0.1 * np.maximum(np.abs(dmp.goal - dmp.start), 0.01)
    sigma = np.r_[np.broadcast_to(weights, w.shape).ravel(), goals, 0.1 * dmp.tau]
    return sigma, w.size


def generalized(problem, context, budget, seed):
    box = problem.box
    return [box.episode(box.initial(context), context, seed)]


def error_learning(problem, context, budget, seed):
    """GoldenSection on a one-value query, else Secant; bounded by the box
    the contexts are drawn from."""
    q0, low, high = problem.box.query(context), problem.low, problem.high
    if len(q0) == 1:
        learner = primo.GoldenSection(low[0], high[0], q0[0], max_rollouts=budget)
    else:
        learner = primo.Secant(low, high, q0, max_rollouts=budget)
    return problem.box.learn(learner, context, budget, seed=seed)


def _goals(box, problem, context, budget, seed, path, via):
    """primo's Secant on a change of the movement's goals instead of its
    query (``BlackBox.learn(..., goals=...)``): the goals of the DoFs the
    task pairs with the error's values (the first ones but on push-v3),
    each within the robot's limits of its DoF. With ``via`` (``(time,
    dof, target)``), the via-points' positions first, each within the
    limits of its DoF too. ``path``: the movement's times, positions and
    goals."""
    dofs = list(problem.goal_dofs)
    times, y, goal = path
    now = np.r_[[np.interp(t, times, y[:, d]) for t, d, _ in via], np.asarray(goal)[dofs]]
    moved = [d for _, d, _ in via] + dofs
    low, high = (np.asarray(v)[moved] - now for v in problem.limits)
    # A generalized position beyond a limit: its change may still be 0.
    learner = primo.Secant(np.minimum(low, 0), np.maximum(high, 0), np.zeros(len(moved)), max_rollouts=budget)
    return box.learn(learner, context, budget, seed=seed, goals=dofs, via=via)


def _dmp_path(box, context):
    dmp = box.dmp(box.query(context))
    return (*dmp.run(), dmp.goal)


def _promp_path(box):
    """The ProMP's mean every millisecond, as ``Dmp.run``'s default."""
    promp = box.movement
    times = np.linspace(0.0, promp.duration, int(round(promp.duration / 0.001)) + 1)
    y = promp.mean(times / promp.duration)
    return times, y, y[-1]


def goal_learning(problem, context, budget, seed):
    """Error learning on the generalized movement's goals (``_goals``)."""
    box = problem.goal_box
    return _goals(box, problem, context, budget, seed, _dmp_path(box, context), ())


def via_learning(problem, context, budget, seed):
    """goal-learning with the task's via-points (``BlackBox.learn(...,
    via=...)``): the hand over the puck on push-v3, where it must be
    before the goals can move the puck."""
    box = problem.goal_box
    path = _dmp_path(box, context)
    return _goals(box, problem, context, budget, seed, path, problem.via(context, *path[:2]))


def promp_goal_learning(problem, context, budget, seed):
    """goal-learning on the ProMP: its mean conditioned on the goals."""
    box = problem.promp_goal_box
    return _goals(box, problem, context, budget, seed, _promp_path(box), ())


def promp_via_learning(problem, context, budget, seed):
    """via-learning on the ProMP: conditioned on via-points and goals."""
    box = problem.promp_goal_box
    path = _promp_path(box)
    return _goals(box, problem, context, budget, seed, path, problem.via(context, *path[:2]))


def promp_power(problem, context, budget, seed):
    """PoWER on the ProMP's weights, DoF by DoF; told no error."""
    box = problem.promp_box
    kernels = box.movement.kernels
    w = box.initial().reshape(-1, kernels)
    sigma = 0.1 * np.sqrt(np.mean(w**2, axis=1))
    learner = primo.Power(box.initial(), blocks=[(kernels, float(v**2), 1.0) for v in sigma], seed=seed)
    reward = lambda e: float(np.exp(-np.linalg.norm(e.error) / problem.tolerance))  # noqa: E731
    return box.learn(learner, context, budget, reward=reward, seed=seed)


def _power(query_gain: float) -> Callable:
    def run(problem, context, budget, seed):
        box = problem.box
        sigma, weights = exploration(box, context)
        # The query is learned from the error (power-el) or held (power).
        blocks = [(box.query_dim, 1e-10, 1.0)]
        kernels = box.dmp(box.query(context)).kernels
        blocks += [(kernels, float(sigma[i] ** 2), 1.0) for i in range(0, weights, kernels)]
        blocks += [(1, float(v**2), 1.0) for v in sigma[weights:]]  # goals, τ
        learner = primo.Power(
            box.initial(context), blocks=blocks, seed=seed, query_gain=query_gain, query=box.query_dim
        )
        reward = lambda e: float(np.exp(-np.linalg.norm(e.error) / problem.tolerance))  # noqa: E731
        return box.learn(learner, context, budget, reward=reward, seed=seed)

    return run


def _cost(episode):
    """‖error‖; a movement the DMP refused (a duration under 1 ms) costs
    1000, more than any error on these tasks (m, rad)."""
    return 1e3 if episode.rejected else float(np.linalg.norm(episode.error))


def _episodes_of(box, context, budget, seed, ask, tell):
    """Runs a population method's ask/tell loop over Δθ one candidate at
    a time, so that it stops at the first success."""
    q0 = box.query(context)
    episodes = [box.episode(np.r_[q0, np.zeros(box.size)], context, seed)]
    while not episodes[-1].success and len(episodes) < budget:
        population, costs = ask(), []
        for delta in population:
            episodes.append(box.episode(np.r_[q0, delta], context, seed))
            if episodes[-1].success or len(episodes) >= budget:
                return episodes
            costs.append(_cost(episodes[-1]))
        tell(population, costs)
    return episodes


def _cma(popsize: Any) -> Callable:
    def run(problem, context, budget, seed):
        box = problem.box
        sigma, _ = exploration(box, context)
        options = {"seed": seed + 1, "verbose": -9, "CMA_stds": sigma}  # pycma's seed 0 means random
        if popsize:
            options["popsize"] = popsize
        es = cma.CMAEvolutionStrategy(np.zeros(len(sigma)), 1.0, options)
        return _episodes_of(box, context, budget, seed, es.ask, es.tell)

    return run


def pibb(problem, context, budget, seed, samples=10, eliteness=10.0):
    """PI-BB as dmpbbo's UpdaterCovarAdaptation with PI-BB weighting
    (Stulp & Sigaud 2012, "Path Integral Policy Improvement with
    Covariance Matrix Adaptation", ICML; dmpbbo/bbo/updaters.py): K
    samples from N(m, Σ); w_k ∝ exp(−h (J_k − min J)/(max J − min J));
    m' = Σ w_k θ_k; Σ' = Σ w_k (θ_k − m)(θ_k − m)ᵀ around the old mean."""
    box = problem.box
    rng = np.random.default_rng(seed)
    sigma, _ = exploration(box, context)
    state = {"mean": np.zeros(len(sigma)), "cov": np.diag(sigma**2)}

    def ask():
        return rng.multivariate_normal(state["mean"], state["cov"], size=samples)

    def tell(population, costs):
        J = np.asarray(costs)
        span = J.max() - J.min()
        w = np.exp(-eliteness * (J - J.min()) / span) if span > 0 else np.ones(len(J))
        w /= w.sum()
        eps = population - state["mean"]
        state["mean"] = w @ population
        state["cov"] = (w[:, None] * eps).T @ eps

    return _episodes_of(box, context, budget, seed, ask, tell)


METHODS = {
    "generalized": generalized,
    "error-learning": error_learning,
    "goal-learning": goal_learning,
    "via-learning": via_learning,
    "power": _power(0.0),
    "power-el": _power(0.5),
    "cma": _cma(None),
    "cma-4": _cma(4),
    "pi-bb": pibb,
    "promp-power": promp_power,
    "promp-goal-learning": promp_goal_learning,
    "promp-via-learning": promp_via_learning,
}
