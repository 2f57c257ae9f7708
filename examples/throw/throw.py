#!/usr/bin/env python3
"""A planar throw, as a primo evaluator (JSON lines; docs/src/reference/evaluator.md).

A two-joint arm stands with its shoulder 1.0 m above the floor (upper arm
0.40 m, forearm 0.35 m; angles in rad, the shoulder's from the horizontal,
the elbow's relative to the upper arm). It swings a ball underhand and lets
go at 70 % of the movement's duration; the ball flies without drag and
lands on the floor. The query is where it lands (m from the shoulder) or,
with --height, also how high it flies (m above the floor).

    python3 throw.py [--height]          evaluate: JSON lines on stdin/stdout
    python3 throw.py --demos DIR         write the demonstrations into DIR

Evaluating (evaluator protocol 2), primo sends one line per roll-out,
{"protocol": 2, "rollout": N, "csv": PATH}, PATH a CSV of columns t,
shoulder, elbow that passed the task's limits; this program answers
{"rollout": N, "measured": [distance]} or
{"rollout": N, "measured": [distance, height]}, or
{"rollout": N, "failed": why} when the file cannot be read as a throw.
Only the standard library is used.
"""

import csv
import json
import math
import os
import sys

UPPER, FORE, SHOULDER_HEIGHT, G, RELEASE = 0.40, 0.35, 1.0, 9.81, 0.7


def hand(shoulder, elbow):
    """The hand's position (x forward, y up), m."""
    return (
        UPPER * math.cos(shoulder) + FORE * math.cos(shoulder + elbow),
        SHOULDER_HEIGHT + UPPER * math.sin(shoulder) + FORE * math.sin(shoulder + elbow),
    )


def at(t, values, time):
    """`values` at `time`, linearly interpolated between samples."""
    k = max(1, min(len(t) - 1, next((i for i, ti in enumerate(t) if ti >= time), len(t) - 1)))
    w = (time - t[k - 1]) / (t[k] - t[k - 1])
    return values[k - 1] + w * (values[k] - values[k - 1])


def throw(t, shoulder, elbow):
    """Landing distance and apex height of the ball released at RELEASE·T.

    The release instant and the hand's velocity there (a central
    difference one sample step wide) are interpolated between samples, so
    the outcome changes smoothly with the movement's duration."""
    if len(t) < 3:
        raise ValueError("a throw needs at least three samples")
    release = t[0] + RELEASE * (t[-1] - t[0])
    h = (t[-1] - t[0]) / (len(t) - 1)
    x0, y0 = hand(at(t, shoulder, release), at(t, elbow, release))
    xa, ya = hand(at(t, shoulder, release - h), at(t, elbow, release - h))
    xb, yb = hand(at(t, shoulder, release + h), at(t, elbow, release + h))
    vx, vy = (xb - xa) / (2 * h), (yb - ya) / (2 * h)
    if y0 <= 0:
        raise ValueError("the hand is below the floor at the release")
    flight = (vy + math.sqrt(vy * vy + 2 * G * y0)) / G
    return x0 + vx * flight, y0 + max(vy, 0.0) ** 2 / (2 * G)


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    names = [n.strip() for n in rows[0]]
    col = {n: names.index(n) for n in ("t", "shoulder", "elbow")}
    data = [[float(r[i]) for i in range(len(names))] for r in rows[1:] if r]
    return tuple([r[col[n]] for r in data] for n in ("t", "shoulder", "elbow"))


def minimum_jerk(s):
    return 10 * s**3 - 15 * s**4 + 6 * s**5


def demonstration(duration, swing, rate=100):
    """A demonstrator's throw: the shoulder swings `swing` rad up from
    -2.0 rad (arm down and back) while the elbow straightens by 0.3 rad,
    both minimum-jerk over `duration` s, recorded at `rate` Hz."""
    n = int(round(duration * rate)) + 1
    t = [duration * i / (n - 1) for i in range(n)]
    s = [minimum_jerk(x / duration) for x in t]
    return t, [-2.0 + swing * v for v in s], [0.6 - 0.3 * v for v in s]


# (file, duration s, swing rad): a fast and a slow throw for the distance,
# and a 2 x 2 grid of speed and swing for distance and height.
DEMOS = [
    ("fast.csv", 0.45, 1.6),
    ("slow.csv", 0.9, 1.6),
    ("fast-low.csv", 0.45, 1.4),
    ("fast-high.csv", 0.45, 1.8),
    ("slow-low.csv", 0.8, 1.4),
    ("slow-high.csv", 0.8, 1.8),
]


def write_demos(directory):
    os.makedirs(directory, exist_ok=True)
    for name, duration, swing in DEMOS:
        t, sh, el = demonstration(duration, swing)
        with open(os.path.join(directory, name), "w") as f:
            f.write("t,shoulder,elbow\n")
            for row in zip(t, sh, el):
                f.write(",".join(repr(round(v, 9)) for v in row) + "\n")
        distance, height = throw(t, sh, el)
        print(f"{name}: distance {distance:.4f} m, height {height:.4f} m")


def serve(with_height):
    for line in sys.stdin:
        if not line.strip():
            continue
        request = json.loads(line)
        try:
            distance, height = throw(*read(request["csv"]))
            answer = {"measured": [distance, height] if with_height else [distance]}
        except (OSError, ValueError, KeyError, IndexError, ZeroDivisionError) as e:
            answer = {"failed": str(e)}
        answer["rollout"] = request["rollout"]
        print(json.dumps(answer), flush=True)


if __name__ == "__main__":
    if len(sys.argv) == 3 and sys.argv[1] == "--demos":
        write_demos(sys.argv[2])
    elif sys.argv[1:] in ([], ["--height"]):
        serve(sys.argv[1:] == ["--height"])
    else:
        sys.exit(__doc__)
