#!/usr/bin/env python3
"""Compares two trajectory.csv files (t,x,y,theta; slam_offline's and the
estimator's format) step by step: the step counts, how many poses are
bit-identical, the largest time, position and heading differences.
  scripts/compare_trajectories.py A/trajectory.csv B/trajectory.csv [...more pairs]
Exit 0 when every pair has the same number of steps, 1 otherwise."""
import csv
import math
import sys


def load(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    return [tuple(float(v) for v in row[:4]) for row in rows[1:] if row]


def compare(a_path, b_path):
    a, b = load(a_path), load(b_path)
    n = min(len(a), len(b))
    identical = sum(1 for i in range(n) if a[i][1:] == b[i][1:])
    dt = max((abs(a[i][0] - b[i][0]) for i in range(n)), default=0.0)
    dpos = [math.hypot(a[i][1] - b[i][1], a[i][2] - b[i][2]) for i in range(n)]
    dth = max((abs(math.remainder(a[i][3] - b[i][3], 2 * math.pi)) for i in range(n)), default=0.0)
    print(f"{a_path} vs {b_path}: steps {len(a)} / {len(b)}, bit-identical poses {identical} of {n}, "
          f"max |dt| {dt:.3g} s, position difference max {max(dpos, default=0):.4f} m "
          f"mean {sum(dpos) / max(n, 1):.5f} m, max |dtheta| {math.degrees(dth):.3f} deg")
    return len(a) == len(b)


def main(args):
    if len(args) < 2 or len(args) % 2:
        print(__doc__, file=sys.stderr)
        return 2
    ok = all([compare(args[i], args[i + 1]) for i in range(0, len(args), 2)])
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
