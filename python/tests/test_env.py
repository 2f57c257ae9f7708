"""The Gymnasium environment and its vector form."""

import numpy as np
import pytest

gymnasium = pytest.importorskip("gymnasium", reason="the [gym] extra: pip install './python[gym]'")
from gymnasium.utils.env_checker import check_env  # noqa: E402

import primo  # noqa: E402
from primo.env import PouringEnv, PouringVectorEnv  # noqa: E402


def test_passes_the_environment_checker():
    env = gymnasium.make(primo.ENV_ID, kernels=10, glass="small")
    check_env(env.unwrapped, skip_render_check=True)
    assert env.observation_space.contains(env.reset(seed=3)[0])


def test_one_step_is_one_rollout_of_the_cell():
    env = PouringEnv(kernels=10, bottle=0.7, target=0.25)
    obs, _ = env.reset(seed=5)
    np.testing.assert_array_equal(obs, [0.7, 0.25])
    action = np.linspace(-0.3, 0.3, env.action_space.shape[0])
    _, reward, terminated, truncated, info = env.step(action)
    assert terminated and not truncated
    env.reset(seed=5)
    noise = int(env.np_random.integers(0, 2**63))
    direct = env.cell.rollout(env.parameters(action), seed=noise)
    assert reward == direct["reward"] and info["poured"] == direct["poured"]


def test_vector_env_runs_the_rollouts_in_rust():
    envs = gymnasium.make_vec(primo.ENV_ID, num_envs=4, vectorization_mode="vector_entry_point",
                              kernels=10)
    assert isinstance(envs, PouringVectorEnv)
    obs, _ = envs.reset(seed=1)
    assert obs.shape == (4, 2)
    actions = np.zeros((4, envs.single_action_space.shape[0]))
    actions[1] = 0.5
    obs, rewards, terminated, truncated, info = envs.step(actions)
    assert obs.shape == (4, 2) and rewards.shape == (4,) and terminated.all() and not truncated.any()
    assert info["safe"].dtype == bool and info["poured"].shape == (4,)
    single = PouringEnv(cell=envs.cell)
    assert rewards[0] == pytest.approx(single.cell.rollout(single.parameters(actions[0]),
                                                           seed=0)["reward"], abs=0.05)
    with pytest.raises(ValueError, match="rows"):
        envs.step(actions[:2])
