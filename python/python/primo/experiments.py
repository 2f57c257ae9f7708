"""The paper's experiments, one seeded run at a time, and their files.

``golden_run`` (Fig. 3: an error learner per bottle volume) and
``power_run`` (Figs. 5 and 6: extended or ordinary PoWER, or PoWER with
the query learned from the error) are the
functions ``primo experiment golden`` and ``primo experiment power`` call
for each run in their parallel loops, so a run here is the command
line's run with the same seed, bit for bit. Each runs on one core with
the GIL released and returns a plain dict (numbers, NumPy columns of
every roll-out) that pickles: spread runs over threads, processes or Ray
(``primo.sweep`` does) and gather them. ``write_golden`` and
``write_power`` write gathered runs into the files the command writes,
with the command's own writers; like the command, they refuse a
directory holding an earlier result unless ``force=True``
(``check_out`` asks before a sweep's runs begin).

>>> from primo.experiments import golden_run, power_run
>>> run = golden_run(0.5, method="golden", seed=1)
>>> run["method"], run["rollouts_to_precision"]
('golden', 8)
>>> run = power_run(seed=3, variant="extended", kernels=10, updates=5)
>>> sorted(run["rollouts_to"]), run["final_reward"] > 0.5
([0.95, 0.99], True)
"""

from primo._primo import check_out, golden_run, power_run, write_golden, write_power

#: The error learners of the golden experiment, in the order it reports them.
METHODS = ("golden", "illinois", "secant", "fixed-gain", "weighted-gain")
#: The power experiment's PoWER variants: s1 = 0.2, s1 = 0, and the query
#: learned from the error (``primo pour --method power-el``).
VARIANTS = ("extended", "ordinary", "error-learned")
#: The mean policy's reward levels the power experiment times runs to.
THRESHOLDS = (0.95, 0.99)

__all__ = [
    "METHODS",
    "THRESHOLDS",
    "VARIANTS",
    "check_out",
    "golden_run",
    "power_run",
    "write_golden",
    "write_power",
]
