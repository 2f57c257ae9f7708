"""primo in Python: robots learning movement skills from demonstrations.

A thin, typed layer over the compiled module ``primo._primo`` (Rust,
through PyO3): Dynamic Movement Primitives, statistical generalization
over a task query, the error learners (golden section, Illinois, secant)
and PoWER with ``ask()``/``tell()``, the simulated pouring cell, and
robot models (``Robot``: a serial arm from its URDF, its forward and
inverse kinematics and Jacobian, in float64).
Arrays go in as anything NumPy turns into float64 and come out as
float64 arrays; the core computes in float32 (the DMP fit's normal
equations in float64), so values must be finite in float32.

>>> import numpy as np
>>> import primo
>>> t = np.linspace(0.0, 1.0, 101)
>>> s = t * t * (3 - 2 * t)  # from rest to rest
>>> y = np.stack([0.6 * s, 0.1 + 0.15 * np.sin(np.pi * s) ** 2], axis=1)
>>> dmp = primo.Dmp.fit(t, y, names=["x", "z"], kernels=30)
>>> times, positions = dmp.run(dt=0.01)
>>> positions.shape
(101, 2)
>>> bool(np.abs(positions - y).max() < 1e-4)
True

``primo.env`` has the Gymnasium environment (``primo/Pouring-v0``,
registered on import when Gymnasium is installed), ``primo.gym``
(``import primo.gym``) ``BlackBox``, which makes any Gymnasium task an
episodic one for primo's learners, ``primo.experiments``
one seeded run of each of the paper's experiments (``primo experiment``'s
own), and ``primo.sweep`` (``import primo.sweep``) sweeps of them
(methods × settings × seeds) on local processes or Ray, written as
``primo experiment`` writes them.
"""

from primo._primo import (
    Cell,
    Dmp,
    DmpRun,
    Generalizer,
    GoldenSection,
    Illinois,
    Power,
    ProMp,
    Robot,
    Secant,
    __version__,
)

__all__ = [
    "Cell",
    "Dmp",
    "DmpRun",
    "Generalizer",
    "GoldenSection",
    "Illinois",
    "Power",
    "ProMp",
    "Robot",
    "Secant",
    "__version__",
]

ENV_ID = "primo/Pouring-v0"


def _register_env() -> None:
    """Registers the pouring environment with Gymnasium, if installed."""
    try:
        import gymnasium
    except ImportError:
        return
    if ENV_ID not in gymnasium.registry:
        gymnasium.register(
            id=ENV_ID,
            entry_point="primo.env:PouringEnv",
            vector_entry_point="primo.env:PouringVectorEnv",
        )


_register_env()

from primo import experiments  # noqa: E402  (after the native module)
