"""ProMPs: primo.ProMp against movement_primitives.promp.ProMP on the same
demonstrations, before and after conditioning on a via-point.

Usage: bench/compare_python.sh bench/compare_promp.py
(a throw-away venv with movement_primitives 0.9.1 and primo built from
./python); prints the Markdown tables of
bench/results/2026-12-04-promp-vs-movement-primitives.md.

The demonstrations (chosen before running, seed 27): 10 variants of a 2-D
reach over 1.5 s, 151 samples each from t = 0: x goes 0.4 m ± 3 cm with a
bump of 5 ± 2 cm, y rises 10 ± 2 cm with a wave of 5 cm × (1 ± 0.2); every
sample with 0.5 mm of Gaussian noise. 10 and 20 kernels per column.

Fits, each library's defaults:
- primo: `ProMp.fit(demos, names=["x", "y"], kernels=K)` (ridge 1e-6): each
  demonstration's weights by least squares, their mean and covariance
  (n − 1), a ridge of 1e-6 × the mean weight variance on the diagonal, and
  the mean squared residual as observation noise, which `variance` adds.
- movement_primitives, the way its docs teach: `ProMP(n_dims=2,
  n_weights_per_dim=K).imitate(Ts, Ys)`, its EM learner (Lazaric &
  Ghavamzadeh 2010; defaults n_iter 1000, min_delta 1e-5).
- movement_primitives, primo's estimator: its `weights(T, Y)` per
  demonstration (least squares, lmbda 1e-12) and their sample mean and
  covariance (n − 1) into `from_weight_distribution`: the same estimator
  as primo's on its own kernels.
- the same with primo's kernel width (a subclass passing the `overlap` that
  gives exp(−0.5 (K−1)² (z − c)²), primo's): what is left is f32, primo's
  ridge and its noise term.
Both libraries use K normalized Gaussians centred evenly on the phase
[0, 1] (the time over the demonstration's duration); movement_primitives'
are exp(−4 ln(1/0.7) K² (z − c)²): 3.5 × primo's exponent at K = 10,
3.2 × at K = 20 (narrower kernels).

Conditioning: x and y together at phase 0.6, each one standard deviation
of the demonstrations away from their mean there (x up, y down), exactly
(primo variance 0, movement_primitives y_cov None). movement_primitives'
`condition_position` conditions every dimension at once; so both do here.
Compared: the mean and the variance on 201 phases, as max differences, and
each against the demonstrations' own mean and variance (n − 1) at their
samples; and, where the two fits share kernels and estimator, the weights'
mean and covariance themselves (primo's read from its pickled values).
"""

import numpy as np
from movement_primitives.promp import ProMP

import primo

N_DEMOS, SAMPLES, SECONDS = 10, 151, 1.5
VIA_PHASE = 0.6
Z = np.linspace(0.0, 1.0, 201)


def mj(s):
    return s**3 * (10 - 15 * s + 6 * s * s)


def demonstrations(rng):
    t = np.linspace(0.0, SECONDS, SAMPLES)
    u = t / SECONDS
    demos = []
    for _ in range(N_DEMOS):
        a, b, c, e = rng.normal([0.0, 0.05, 0.1, 0.0], [0.03, 0.02, 0.02, 0.2])
        x = 0.3 + (0.4 + a) * mj(u) + b * np.sin(np.pi * u) ** 2
        y = 0.1 + c * mj(u) + 0.05 * (1 + e) * np.sin(2 * np.pi * u)
        y = np.column_stack([x, y]) + rng.normal(0.0, 5e-4, (SAMPLES, 2))
        demos.append((t, y))
    return demos


class PrimoWidth(ProMP):
    """movement_primitives' ProMP with primo's kernel width: its exponent
    4 ln(1/overlap) K² set to primo's 0.5 (K − 1)²."""

    def _overlap(self):
        k = self.n_weights_per_dim
        return np.exp(-0.125 * (k - 1) ** 2 / k**2)

    def _rbfs_1d_sequence(self, T, overlap=None, normalize=True):
        return super()._rbfs_1d_sequence(T, self._overlap(), normalize)

    def _rbfs_1d_point(self, t, t_max=1.0, overlap=None):
        return super()._rbfs_1d_point(t, t_max, self._overlap())

    def condition_position(self, *args, **kwargs):
        q = super().condition_position(*args, **kwargs)
        return PrimoWidth(q.n_dims, q.n_weights_per_dim).from_weight_distribution(
            q.weight_mean, q.weight_cov)


def sample_fit(cls, demos, k):
    """primo's estimator with movement_primitives' least squares."""
    p = cls(2, k)
    w = np.array([p.weights(t.copy(), y) for t, y in demos])
    return p.from_weight_distribution(w.mean(axis=0), np.cov(w, rowvar=False))


def mp_curves(p):
    # T is normalized in place by movement_primitives: pass a copy.
    return p.mean_trajectory(Z.copy()), p.var_trajectory(Z.copy())


def primo_values(p):
    """primo's pickled values (`ProMp::values`): [dof, kernels, duration,
    noise, weight mean (column by column), weight covariance (row-major)]."""
    return np.asarray(p.__reduce__()[1][1])


def primo_noise(p):
    """primo's observation noise."""
    return float(primo_values(p)[3])


def weight_gap(ours, theirs):
    """Max differences of the weights' mean and covariance, primo against a
    movement_primitives ProMP (the same order: column, then kernel)."""
    v = primo_values(ours)
    n = int(v[0] * v[1])
    mean, cov = v[4:4 + n], v[4 + n:].reshape(n, n)
    return (np.abs(mean - theirs.weight_mean).max(), np.abs(cov - theirs.weight_cov).max(),
            np.abs(cov).max())


def main():
    rng = np.random.default_rng(27)
    demos = demonstrations(rng)
    ys = np.array([y for _, y in demos])
    emp_mean, emp_var = ys.mean(axis=0), ys.var(axis=0, ddof=1)
    u = demos[0][0] / SECONDS
    at = int(round(VIA_PHASE * (SAMPLES - 1)))
    via = emp_mean[at] + np.array([1.0, -1.0]) * np.sqrt(emp_var[at])

    print(f"Via-point at phase {VIA_PHASE}: x = {via[0]:.5f}, y = {via[1]:.5f} "
          f"(demonstrations' mean {emp_mean[at].round(5).tolist()}, "
          f"std {np.sqrt(emp_var[at]).round(5).tolist()})\n")
    for k in (10, 20):
        ours = primo.ProMp.fit(demos, names=["x", "y"], kernels=k)
        em = ProMP(2, k)
        em.imitate(np.array([t.copy() for t, _ in demos]), ys)
        fits = {"mp imitate (EM)": em, "mp weights + sample cov": sample_fit(ProMP, demos, k),
                "mp sample cov, primo's width": sample_fit(PrimoWidth, demos, k)}
        noise = primo_noise(ours)
        cond = ours.condition(VIA_PHASE, {"x": via[0], "y": via[1]})
        curves = {"primo": (ours.mean(Z), ours.variance(Z), cond.mean(Z), cond.variance(Z))}
        conditioned = {}
        for name, p in fits.items():
            conditioned[name] = c = p.condition_position(via, t=VIA_PHASE)
            curves[name] = (*mp_curves(p), *mp_curves(c))

        print(f"### {k} kernels per column\n")
        print(f"primo's observation noise (added to its variance): {noise:.3g} m²; "
              f"the demonstrations' mean variance: {emp_var.mean():.3g} m².\n")
        print("Against the demonstrations (their mean and variance at their 151 samples; "
              "before conditioning):\n")
        print("| fit | mean: max error (m) | variance: max error (m²) | variance: median ratio to the demonstrations' |")
        print("|---|---:|---:|---:|")
        for name, p in [("primo", ours)] + list(fits.items()):
            if name == "primo":
                m, v = ours.mean(u), ours.variance(u)
            else:
                m, v = p.mean_trajectory(u.copy()), p.var_trajectory(u.copy())
            print(f"| {name} | {np.abs(m - emp_mean).max():.2e} | {np.abs(v - emp_var).max():.2e} | "
                  f"{np.median(v / emp_var):.3g} |")
        print("\nprimo against each movement_primitives fit, on 201 phases (max over both "
              "columns; variance also with primo's noise taken off):\n")
        print("| against | mean before (m) | variance before (m²) | variance before, no noise (m²) | "
              "mean after (m) | variance after (m²) | variance after, no noise (m²) |")
        print("|---|---:|---:|---:|---:|---:|---:|")
        pm, pv, cm, cv = curves["primo"]
        for name in fits:
            m, v, m2, v2 = curves[name]
            print(f"| {name} | {np.abs(pm - m).max():.2e} | {np.abs(pv - v).max():.2e} | "
                  f"{np.abs(pv - noise - v).max():.2e} | {np.abs(cm - m2).max():.2e} | "
                  f"{np.abs(cv - v2).max():.2e} | {np.abs(cv - noise - v2).max():.2e} |")
        same = "mp sample cov, primo's width"
        print(f"\nThe weights themselves, primo against \"{same}\" (max |difference|; "
              "the covariance's largest entry for scale):\n")
        print("| | weight mean | weight covariance | covariance's largest entry |")
        print("|---|---:|---:|---:|")
        for when, a, b in (("before", ours, fits[same]), ("after", cond, conditioned[same])):
            m, c, big = weight_gap(a, b)
            print(f"| {when} conditioning | {m:.2e} | {c:.2e} | {big:.2e} |")
        print("\nAt the via-point (phase 0.6) after conditioning:\n")
        print("| fit | mean − via, x (m) | mean − via, y (m) | variance x (m²) | variance y (m²) | "
              "mean moved at phase 1, x (m) |")
        print("|---|---:|---:|---:|---:|---:|")
        iv, end = int(round(VIA_PHASE * (len(Z) - 1))), len(Z) - 1
        for name, (m, v, m2, v2) in curves.items():
            d = m2[iv] - via
            print(f"| {name} | {d[0]:.2e} | {d[1]:.2e} | {v2[iv, 0]:.2e} | {v2[iv, 1]:.2e} | "
                  f"{m2[end, 0] - m[end, 0]:.2e} |")
        print()


main()
