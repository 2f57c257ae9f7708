"""The pouring cell: the same numbers as `primo rollout`, in parallel."""

import csv
import json
import pickle
import subprocess

import numpy as np
import pytest

import primo

SETTINGS = {"glass": "small", "kernels": 10, "bottle": 0.6, "target": 0.2, "seed": 7}
FLAGS = ["--glass", "small", "--kernels", "10", "--bottle", "0.6", "--target", "0.2", "--seed", "7"]


@pytest.fixture(scope="module")
def cell():
    return primo.Cell(**SETTINGS)


def test_start_is_print_start(cell, run_primo):
    cli = json.loads(run_primo("rollout", "--print-start", *FLAGS))
    ours = cell.start()
    for key in ["layout", "space", "dof", "kernels", "bottle"]:
        assert ours[key] == cli[key], key
    assert (ours["glass"], ours["target"]) == ("small", 0.2)
    np.testing.assert_array_equal(ours["start"], np.array(cli["start"], dtype=np.float32))
    np.testing.assert_array_equal(ours["std"], np.array(cli["std"], dtype=np.float32))
    assert len(cell) == cell.size == 7 * 10 + 7 + 1 + 1


def test_the_cartesian_cell_moves_the_mouth_and_a_quaternion(run_primo):
    cart = primo.Cell(**{**SETTINGS, "space": "cartesian"})
    assert cart.names == ["x", "y", "z", "qw", "qx", "qy", "qz"]
    cli = json.loads(run_primo("rollout", "--print-start", "--space", "cartesian", *FLAGS))
    ours = cart.start()
    # One orientation DMP: 6 DoFs, its goal a rotation vector.
    assert ours["dof"] == cli["dof"] == 6 and len(cart) == 6 * 10 + 6 + 1 + 1
    assert ours["layout"] == cli["layout"] and "log coordinates" in ours["layout"]
    np.testing.assert_array_equal(ours["start"], np.array(cli["start"], dtype=np.float32))
    series = cart.rollout(ours["start"], series=True)["series"]
    q = np.column_stack([series[n] for n in ["qw", "qx", "qy", "qz"]])
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)


def test_rollout_is_the_command_lines(cell, run_primo, tmp_path):
    start = cell.start()
    rng = np.random.default_rng(1)
    theta = start["start"] + 0.3 * start["std"] * rng.standard_normal(len(cell))
    theta = theta.astype(np.float32).astype(np.float64)
    (tmp_path / "theta.json").write_text(json.dumps(theta.tolist()))
    cli = json.loads(
        run_primo("rollout", "--params", str(tmp_path / "theta.json"), "--series",
                  str(tmp_path / "series.csv"), *FLAGS)
    )
    ours = cell.rollout(theta, series=True)
    for key in ["poured", "spilled", "error", "reward", "safe"]:
        assert ours[key] == cli[key], key
    assert ours["rejected"] == cli["rejected"]
    csv = np.loadtxt(tmp_path / "series.csv", delimiter=",", skiprows=1)
    header = (tmp_path / "series.csv").read_text().splitlines()[0].split(",")
    assert list(ours["series"]) == header
    for j, name in enumerate(header):
        if name not in ("t", "scale_g") and name not in cell.names:
            np.testing.assert_array_equal(ours["series"][name], csv[:, j], err_msg=name)
    np.testing.assert_allclose(ours["series"]["t"], csv[:, 0], atol=1e-6)


def test_rollout_many_is_a_loop_of_rollout(cell, primo_bin):
    start = cell.start()
    rng = np.random.default_rng(2)
    thetas = start["start"] + 0.5 * start["std"] * rng.standard_normal((5, len(cell)))
    thetas[4, 0] = 1e6  # a huge weight: a rejected, unsafe movement
    many = cell.rollout_many(thetas)
    assert many == [cell.rollout(t, seed=cell.seed + i) for i, t in enumerate(thetas)]
    assert many[4]["safe"] is False and many[4]["reward"] == 0.0 and "limit" in many[4]["rejected"]
    assert cell.rollout_many(thetas[:2], seeds=[3, 4]) == [
        cell.rollout(thetas[0], seed=3), cell.rollout(thetas[1], seed=4)
    ]
    # `primo rollout --serve` numbers its lines' seeds the same way.
    lines = "\n".join(json.dumps(t.tolist()) for t in thetas[:3]) + "\n"
    done = subprocess.run([str(primo_bin), "rollout", "--serve", *FLAGS], input=lines,
                          capture_output=True, text=True, check=True)
    served = [json.loads(line) for line in done.stdout.splitlines()]
    assert [s["poured"] for s in served] == [m["poured"] for m in many[:3]]


def test_pickles_as_its_settings(cell):
    copy = pickle.loads(pickle.dumps(cell))
    assert repr(copy) == repr(cell)
    theta = cell.start()["start"]
    assert copy.rollout(theta) == cell.rollout(theta)


def test_bad_input_is_a_value_error(cell):
    n = len(cell)
    for call, message in [
        (lambda: cell.rollout([1.0, 2.0]), f"theta: 2 values, the layout needs {n}"),
        (lambda: cell.rollout(np.full(n, np.nan)), "theta: value 1 is NaN"),
        (lambda: cell.rollout(np.full(n, 1e300)), "out of f32 range"),
        (lambda: cell.rollout(np.zeros((2, n))), "1-D array"),
        (lambda: cell.rollout_many(np.zeros(n)), "2-D array"),
        (lambda: cell.rollout_many(np.zeros((2, n)), seeds=[1]), "1 seeds for 2 rows"),
        (lambda: cell.rollout_many(np.zeros((0, n + 1))), None),
        (lambda: cell.rollout(np.zeros(n), seed=-1), "seed"),
        (lambda: primo.Cell(glass="huge"), "glass"),
        (lambda: primo.Cell(bottle=0.1, target=0.2), "target 0.2"),
        (lambda: primo.Cell(kernels=1), "^kernels=1: a DMP needs 2 to 128 kernels per DoF$"),
        (lambda: primo.Cell(kernels=-1), "^kernels=-1: a DMP needs 2 to 128"),
        (lambda: primo.Cell(bottle=float("nan")), "bottle"),
    ]:
        if message is None:
            assert call() == []
            continue
        with pytest.raises(ValueError, match=message):
            call()
    # A duration outside (0, 600] s is out of bounds: refused before any
    # work, naming the bound.
    with pytest.raises(ValueError, match="τ 0 s: a movement lasts more than 0 and at most 600 s"):
        cell.rollout(np.zeros(n))
    # Joints driven 3 rad from zero, in a movement of the demonstrated
    # duration: a movement the gate refuses, not an error.
    theta = np.zeros(n)
    dof, kernels = cell.start()["dof"], cell.start()["kernels"]
    theta[dof * kernels : dof * kernels + dof] = 3.0
    theta[-2] = cell.start()["start"][-2]
    assert cell.rollout(theta)["safe"] is False


def pour(primo_bin, tmp_path, *flags):
    """`primo pour` on the joint-space cell: its summary and roll-outs."""
    out = tmp_path / "pour"
    subprocess.run([str(primo_bin), "pour", "--space", "joint", "--glass", "small", "--kernels",
                    "10", "--bottle", "0.6", "--target", "0.2", "--seed", "7", "--out", str(out),
                    *flags], check=True, capture_output=True, text=True)
    with open(out / "rollouts.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    return json.loads((out / "summary.json").read_text()), rows


def same_as_logged(result, row):
    """A roll-out's numbers are those rollouts.csv logged (its 6 decimals)."""
    for key in ["poured", "spilled", "error", "reward"]:
        assert f"{result[key]:.6f}" == row[f"{key}_l" if key != "reward" else key], (key, row)
    assert (result["rejected"] or "") == row["rejected"]


def test_a_python_loop_repeats_primo_pours_error_learning(primo_bin, tmp_path):
    # Was impossible without internals: the per-roll-out seed and the
    # glass's capacity (which bounds the search) were not exposed.
    summary, rows = pour(primo_bin, tmp_path, "--method", "golden", "--max-rollouts", "8")
    cell = primo.Cell(**{**SETTINGS, "bottle": 0.6, "target": 0.2, "seed": 7})
    assert cell.glass_holds == summary["settings"]["glass_holds"]
    low = max(np.float32(0.1), np.float32(0.6 + 0.2 - cell.glass_holds))
    search = primo.GoldenSection(float(low), 1.5, desired=0.6, precision=0.002, max_rollouts=8)
    start = cell.start()["start"]
    assert len(rows) >= 3
    for k, row in enumerate(rows, start=1):
        query = search.ask()
        assert np.float32(query) == np.float32(row["query"]), k
        result = cell.rollout(np.append(start[:-1], query), seed=cell.pour_seed(k))
        same_as_logged(result, row)
        if result["rejected"]:
            search.tell_infeasible()
        else:
            search.tell(result["error"])


@pytest.mark.parametrize("method, defaults", [
    ("power", {}),
    ("power-el", {"s1": 0.0, "query_gain": 1.0}),
])
def test_power_defaults_repeat_primo_pours_power(primo_bin, tmp_path, method, defaults):
    # Power.defaults is the exploration `primo pour` builds, and
    # rollout_delta executes [q̂, Δθ] as it does: the same roll-outs, bit
    # for bit, for 3 updates.
    summary, rows = pour(primo_bin, tmp_path, "--method", method, "--max-rollouts", "12")
    assert (summary["settings"]["s1"], summary["settings"]["s2"]) == (
        defaults.get("s1", 0.2), 0.05)
    cell = primo.Cell(**{**SETTINGS, "bottle": 0.6, "target": 0.2, "seed": 7})
    power = primo.Power.defaults(cell, seed=7, **defaults)
    for k, row in enumerate(rows, start=1):
        assert (power.updates, power.next_is_mean) == (int(row["update"]), row["mean"] == "true")
        params = power.ask()
        assert np.float32(params[0]) == np.float32(row["query"]), k
        result = cell.rollout_delta(params[:1], params[1:], seed=cell.pour_seed(k))
        same_as_logged(result, row)
        power.tell(result["reward"], error=[result["error"]] if power.query and defaults else None)
    assert power.updates == 3


def test_pour_seed_and_with_context():
    cell = primo.Cell(**SETTINGS)
    seeds = {cell.pour_seed(k) for k in range(1, 50)}
    assert len(seeds) == 49 and cell.pour_seed(3, seed=8) != cell.pour_seed(3)
    for bad in [0, -1, 2**32]:
        with pytest.raises(ValueError, match=f"rollout={bad}: roll-outs are numbered from 1"):
            cell.pour_seed(bad)
    other = cell.with_context(bottle=0.9)
    assert (other.bottle, other.target, other.kernels, other.seed) == (0.9, 0.2, 10, 7)
    np.testing.assert_array_equal(other.start()["start"],
                                  primo.Cell(**{**SETTINGS, "bottle": 0.9}).start()["start"])
    with pytest.raises(ValueError, match="target"):
        cell.with_context(target=2.0)
