"""The evaluator of reach.toml: where joint 1 ended, read from the
trajectory primo checked (and the robot executed). One JSON line in, one
out (primo's evaluator protocol 2)."""

import json
import sys

for line in sys.stdin:
    ask = json.loads(line)
    with open(ask["csv"]) as f:
        last = f.read().split()[-1].split(",")
    print(json.dumps({"rollout": ask["rollout"], "measured": [float(last[1])]}), flush=True)
