#!/usr/bin/env python3
"""Times two commands in alternation (A B A B ...) after one warm-up run of each, and prints the
medians of each one's wall and CPU time (user + system, children) and the median of the per-pair
ratios B / A. On a shared machine a burst of load hits both runs of a pair, so per-pair ratios are
steadier than the ratio of two separate series.

Usage: bench/paired.py RUNS 'COMMAND A' 'COMMAND B'
Prints: wall_a wall_b wall_ratio cpu_a cpu_b cpu_ratio (seconds; ratios are B / A).
SPDX-License-Identifier: MIT
"""
import os
import shlex
import statistics
import subprocess
import sys
import time


def timed(argv):
    before = os.times()
    start = time.perf_counter()
    subprocess.run(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    wall = time.perf_counter() - start
    after = os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    return wall, max(cpu, 0.01)  # clock-tick resolution: never 0


def main():
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    runs = int(sys.argv[1])
    a, b = shlex.split(sys.argv[2]), shlex.split(sys.argv[3])
    timed(a)
    timed(b)
    pairs = [(timed(a), timed(b)) for _ in range(runs)]
    med = statistics.median
    print("%.3f %.3f %.2f %.3f %.3f %.2f" % (
        med(p[0][0] for p in pairs), med(p[1][0] for p in pairs), med(p[1][0] / p[0][0] for p in pairs),
        med(p[0][1] for p in pairs), med(p[1][1] for p in pairs), med(p[1][1] / p[0][1] for p in pairs)))


if __name__ == "__main__":
    main()
