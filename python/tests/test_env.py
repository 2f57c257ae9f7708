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


def test_reset_chooses_the_context_and_the_observation_shows_it():
    # Was: the observation was always the constructor's [bottle, target]
    # and reset ignored its options.
    env = PouringEnv(kernels=10, bottle=0.7, target=0.25)
    obs, _ = env.reset(seed=2, options={"bottle": 0.9, "target": 0.3})
    np.testing.assert_array_equal(obs, [0.9, 0.3])
    assert env.context == (0.9, 0.3) and (env.cell.bottle, env.cell.target) == (0.9, 0.3)
    # The action moves the start generalized for this bottle.
    np.testing.assert_array_equal(
        env.parameters(np.zeros(env.action_space.shape)),
        primo.Cell(kernels=10, bottle=0.9, target=0.3).start()["start"],
    )
    obs, reward, *_, info = env.step(np.zeros(env.action_space.shape))
    np.testing.assert_array_equal(obs, [0.9, 0.3])
    # The target scores the same roll-out differently.
    assert info["error"] == pytest.approx(info["poured"] - 0.3)
    # A reset without options keeps the context; one key changes only it.
    np.testing.assert_array_equal(env.reset()[0], [0.9, 0.3])
    np.testing.assert_array_equal(env.reset(options={"target": 0.2})[0], [0.9, 0.2])
    with pytest.raises(ValueError, match="unknown"):
        env.reset(options={"volume": 0.5})
    with pytest.raises(ValueError, match="target"):
        env.reset(options={"bottle": 0.1, "target": 0.3})  # less in the bottle than the target
    with pytest.raises(ValueError, match=r"options: bottle has shape \(2,\), expected a number$"):
        env.reset(options={"bottle": [0.5, 0.6]})


def test_vector_env_contexts_per_environment_and_info_masks():
    envs = PouringVectorEnv(num_envs=3, kernels=10)
    obs, _ = envs.reset(seed=4, options={"bottle": [0.6, 0.9, 0.6], "target": 0.25})
    np.testing.assert_array_equal(obs, [[0.6, 0.25], [0.9, 0.25], [0.6, 0.25]])
    actions = np.zeros((3, envs.single_action_space.shape[0]))
    envs.np_random = np.random.default_rng(11)
    obs, rewards, _, _, info = envs.step(actions)
    np.testing.assert_array_equal(obs[:, 0], [0.6, 0.9, 0.6])
    # Each row is its own context's roll-out, with the seed drawn for it.
    seeds = np.random.default_rng(11).integers(0, 2**63, size=3)
    for i, bottle in enumerate([0.6, 0.9, 0.6]):
        cell = primo.Cell(kernels=10, bottle=bottle, target=0.25)
        direct = cell.rollout(cell.start()["start"], seed=int(seeds[i]))
        assert rewards[i] == direct["reward"] and info["poured"][i] == direct["poured"]
    # Gymnasium's vector info: every key k has a boolean mask _k.
    for k in ["poured", "spilled", "error", "safe", "rejected"]:
        assert info[f"_{k}"].dtype == bool and info[f"_{k}"].tolist() == [True] * 3
    # A key left out keeps each environment's own.
    obs, _ = envs.reset(options={"target": 0.3})
    np.testing.assert_array_equal(obs, [[0.6, 0.3], [0.9, 0.3], [0.6, 0.3]])
    with pytest.raises(ValueError, match="one per environment"):
        envs.reset(options={"bottle": [0.6, 0.9]})
