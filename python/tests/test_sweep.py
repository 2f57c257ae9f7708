"""Sweeps of the paper's experiments: each seed's run is `primo experiment
... --seed S`'s, bit for bit, on every backend, and the files written are
the command's (reduced sizes: a few volumes, 2 seeds, 3 updates)."""

import pickle
import re
import subprocess
import sys

import numpy as np
import pytest

from primo.experiments import check_out, golden_run, power_run, write_golden, write_power
from primo.sweep import Sweep, main

POWER = {"kernels": 10, "updates": 3}
POWER_FLAGS = ["--kernels", "10", "--updates", "3"]


def same(a, b):
    """Runs (dicts of numbers, NumPy columns, lists) equal bit for bit."""
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list):
        return isinstance(b, list) and len(a) == len(b) and all(map(same, a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and a.dtype == b.dtype and np.array_equal(a, b)
    return type(a) is type(b) and a == b


def without_time(summary: str) -> str:
    return re.sub(r'"seconds": [^\n]*', '"seconds": -', summary)


@pytest.fixture(scope="module")
def golden_sweep():
    return Sweep("golden", grid={"volume": [0.4, 0.7]}, seeds=[2])


@pytest.fixture(scope="module")
def power_sweep():
    return Sweep("power", grid=POWER, seeds=[3, 4])


def test_golden_files_are_the_command_lines(golden_sweep, run_primo, tmp_path):
    run_primo("experiment", "golden", "--volumes", "0.4,0.7", "--seed", "2",
              "--out", str(tmp_path / "cli"))
    written = golden_sweep.run("serial").write(tmp_path / "py")
    assert written == [tmp_path / "py"]
    for name in ["golden.csv", "summary.json", "golden.png"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name


def test_power_files_and_each_seed_are_the_command_lines(power_sweep, run_primo, tmp_path):
    run_primo("experiment", "power", "--runs", "2", "--seed", "3", *POWER_FLAGS,
              "--out", str(tmp_path / "cli"))
    results = power_sweep.run("processes", workers=2)
    results.write(tmp_path / "py")
    for name in ["power_runs.csv", "power.csv", "power.png"]:
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    ours, cli = ((tmp_path / d / "summary.json").read_text() for d in ["py", "cli"])
    assert without_time(ours) == without_time(cli)
    # Seed 4 alone on the command line: the same rows as in the sweep.
    run_primo("experiment", "power", "--runs", "1", "--seed", "4", *POWER_FLAGS,
              "--out", str(tmp_path / "alone"))
    alone = (tmp_path / "alone" / "power_runs.csv").read_text().splitlines()[1:]
    swept = (tmp_path / "py" / "power_runs.csv").read_text().splitlines()[1:]
    assert [r for r in swept if r.split(",")[1] == "4"] == alone
    # The run's figures are the row's.
    row = alone[0].split(",")
    run = next(r for r in results if (r["variant"], r["seed"]) == ("extended", 4))
    assert row[2] == str(run["rollouts_to"][0.95] or "")
    assert row[6:] == [f"{run['regret']:.4f}", *(f"{run[k]:.6f}" for k in
                       ["final_error", "final_spilled", "final_reward"])]


def test_processes_threads_and_serial_agree(golden_sweep, power_sweep):
    for sweep in [golden_sweep, power_sweep]:
        serial = sweep.run("serial").runs
        assert len(serial) == len(sweep)
        for backend in ["processes", "threads"]:
            assert same(sweep.run(backend, workers=2).runs, serial), backend


def test_ray_agrees_with_serial(golden_sweep):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        runs = golden_sweep.run("ray").runs
        assert same(runs, golden_sweep.run("serial").runs)
        assert runs[0]["rollouts"]["error"].flags.writeable
    finally:
        ray.shutdown()


def test_without_ray_the_ray_backend_says_how_to_get_it(monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)
    with pytest.raises(ImportError, match=r"pip install './python\[ray\]'"):
        Sweep("golden", grid={"volume": 0.5}).run("ray")


def test_a_grid_writes_a_directory_per_setting(tmp_path, run_primo):
    sweep = Sweep("golden", grid={"volume": 0.5, "method": ["secant", "golden"]}, seeds=[1, 2])
    assert [t["seed"] for t in sweep.tasks()] == [1, 1, 2, 2]
    results = sweep.run("threads")
    dirs = results.write(tmp_path)
    assert dirs == [tmp_path / "seed=1", tmp_path / "seed=2"]
    run_primo("experiment", "golden", "--volumes", "0.5", "--seed", "2",
              "--out", str(tmp_path / "cli"))
    cli = (tmp_path / "cli" / "golden.csv").read_text().splitlines()
    ours = (tmp_path / "seed=2" / "golden.csv").read_text().splitlines()
    assert ours[0] == cli[0]
    assert sorted(ours[1:]) == sorted(r for r in cli[1:] if ",secant," in r or ",golden," in r)
    power = Sweep("power", grid={"kernels": [6, 8], "updates": 1, "variant": "ordinary"}, seeds=1)
    assert [d.name for d in power.run("serial").write(tmp_path / "p")] == ["kernels=6", "kernels=8"]


def test_an_earlier_result_is_replaced_only_with_force(tmp_path, capsys):
    run = golden_run(0.5, "secant")
    write_golden(tmp_path, [run])
    earlier = (tmp_path / "golden.csv").read_bytes()
    (tmp_path / "summary.json").write_text("a long run's summary")
    for call in [
        lambda: write_golden(tmp_path, [run]),
        lambda: write_power(tmp_path, [power_run(1, "extended", kernels=6, updates=1)]),
        lambda: check_out(tmp_path, "golden"),
        lambda: Sweep("golden", grid={"volume": 0.5, "method": "secant"}).check_out(tmp_path),
    ]:
        with pytest.raises(ValueError, match="an earlier result is here: .*force=True"):
            call()
    assert (tmp_path / "summary.json").read_text() == "a long run's summary"
    assert (tmp_path / "golden.csv").read_bytes() == earlier
    # The shell command refuses before any run, and replaces with --force.
    argv = ["golden", "--volumes", "0.5", "--methods", "secant", "--backend", "serial",
            "--out", str(tmp_path)]
    assert main(argv) == 2
    assert "an earlier result is here" in capsys.readouterr().err
    assert main([*argv, "--force"]) == 0
    assert (tmp_path / "summary.json").read_text().startswith("{")
    with pytest.raises(ValueError, match="kind: `pour`"):
        check_out(tmp_path, "pour")


def test_a_directory_in_use_is_refused(tmp_path):
    # A `primo learn` holding the directory: its lock, taken by another
    # process, refuses the writer whatever the force.
    holder = subprocess.Popen(
        [sys.executable, "-c", "import fcntl, sys, time\n"
         "f = open(sys.argv[1], 'a'); fcntl.flock(f, fcntl.LOCK_EX)\n"
         "print('held', flush=True); time.sleep(60)", str(tmp_path / "primo.lock")],
        stdout=subprocess.PIPE, text=True,
    )
    try:
        assert holder.stdout.readline() == "held\n"
        with pytest.raises(ValueError, match="in use"):
            write_golden(tmp_path, [golden_run(0.5, "secant")], force=True)
        assert not (tmp_path / "golden.csv").exists()
    finally:
        holder.kill()
        holder.wait()


def test_runs_pickle():
    run = power_run(seed=5, variant="extended", kernels=6, updates=1)
    assert same(pickle.loads(pickle.dumps(run)), run)
    assert run["parameters"] == 7 * 6 + 7 + 1 + 1
    assert list(run["rollouts"]["rollout"]) == [1, 2, 3, 4, 5]


def test_the_shell_command(tmp_path):
    done = subprocess.run(
        [sys.executable, "-m", "primo.sweep", "golden", "--volumes", "0.5", "--methods",
         "secant", "--seeds", "1-2", "--backend", "serial", "--out", str(tmp_path)],
        capture_output=True, text=True,
    )
    assert done.returncode == 0, done.stderr
    assert "seed 2: median roll-outs to precision: golden -, illinois -, secant 3" in done.stdout
    assert (tmp_path / "seed=1" / "golden.csv").exists()


def test_bad_input_is_a_value_error(tmp_path, capsys):
    run = golden_run(0.5, "secant")
    two = [power_run(s, v, kernels=6, updates=1) for v, s in [("extended", 1), ("ordinary", 2)]]
    for call, message in [
        (lambda: golden_run(5.0), "volume 5: bottle 5: error learning searches the query"),
        (lambda: golden_run(1.2), "volume 1.2: the cell's bottle holds 1.056 l"),
        (lambda: golden_run(0.5, method="power"), "method: `power`"),
        (lambda: golden_run(0.5, method="power-el"), "method: `power-el`"),
        (lambda: golden_run(0.5, seed=-1), "seed"),
        (lambda: golden_run(0.5, precision=0.0), "precision 0"),
        (lambda: power_run(updates=0), "updates 0"),
        (lambda: power_run(kernels=1), "kernels 1"),
        (lambda: power_run(variant="both"), "variant: `both`"),
        (lambda: power_run(glass="huge"), "glass"),
        (lambda: write_golden(tmp_path, []), "no runs"),
        (lambda: write_golden(tmp_path, [run, golden_run(0.5, "secant", seed=2)]), "`seed` differs"),
        (lambda: write_golden(tmp_path, [{**run, "rollouts": {}}]), "no `rollout`"),
        (lambda: write_golden(tmp_path / "golden.csv" / "x", [run]), None),
        (lambda: write_power(tmp_path, two), "seeds \\[1\\] and ordinary's \\[2\\] differ"),
        (lambda: write_power(tmp_path, two[:1], seconds=float("nan")), "seconds"),
        (lambda: Sweep("pour"), "kind"),
        (lambda: Sweep("golden", grid={"kernels": 10}), "no axis `kernels`"),
        (lambda: Sweep("golden", grid={"seed": 1}), "seeds="),
        (lambda: Sweep("golden", grid={"method": "newton"}), "method: `newton`"),
        (lambda: Sweep("golden", grid={"volume": []}), "no values"),
        (lambda: Sweep("golden", seeds=[1, 1]), "repeats"),
        (lambda: Sweep("golden").run("cluster"), "backend"),
        (lambda: Sweep("golden").run("serial", address="auto"), "address"),
    ]:
        if message is None:
            write_golden(tmp_path, [run])
            with pytest.raises(ValueError, match="not a directory"):
                call()
            continue
        with pytest.raises(ValueError, match=message):
            call()
    with pytest.raises(SystemExit):
        main(["power", "--volumes", "0.5"])
    assert "--volumes is not a setting of the power experiment" in capsys.readouterr().err
    assert main(["golden", "--volumes", "5", "--backend", "serial",
                 "--out", str(tmp_path / "new")]) == 2
    assert "error: volume 5: bottle 5" in capsys.readouterr().err
