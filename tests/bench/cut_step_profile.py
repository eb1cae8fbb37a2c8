#!/usr/bin/env python3
"""Where each kind of cut step spends its time, function by function (issue 41, item 5): the steps of
cut_step_parts.py (a tissue-host scenario, or its frog or organ stroke, through `import tissue`) run
under `perf record -k CLOCK_MONOTONIC --call-graph dwarf`; each sample is given the kind of the step
it fell in (before the cut, enriching, re-layout, plain), and the script prints, for two kinds, the
sampled microseconds a step spends under each child of --anchor (default tissue::Tissue::step, to
--depth frames), largest difference first. perf's unwinding slows the steps about twofold: read the
figures as shares and differences, and the step times from cut_step_parts.py. Needs linux-perf (a
profiling tool, not a dependency of the project) and a release build's Python module.

Usage: /usr/bin/python3 tests/bench/cut_step_profile.py --scenario host/scenarios/cut_frog_complete.toml
       [--runs 3] [--kinds before,enriching] [--anchor tissue::CutSession::apply_new_cuts] [--depth 2]
       [--frequency 20000] [--module DIR]
"""
import argparse
import bisect
import collections
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.join(HERE, "..", "..")
TIME_LINE = re.compile(r"^\s*\d+\.\d+:")


def record_steps(args, out_path):
    """The child: the steps of cut_step_parts, their kinds and times, into out_path (JSON)."""
    sys.path.insert(0, args.module)
    sys.path.insert(0, HERE)
    import tissue  # noqa: E402
    import cut_step_parts  # noqa: E402
    steps = []
    for _ in range(args.runs):
        kinds = (cut_step_parts.scenario_steps(tissue, args.scenario) if args.scenario
                 else cut_step_parts.stroke(tissue, "", args.organ))
        for kind, reports in kinds.items():
            steps += [(r["started_s"], r["ended_s"], kind) for r in reports]
    steps.sort()
    with open(out_path, "w") as out:
        json.dump(steps, out)


def samples(script_path):
    """(time [s], stack from the leaf) of each sample of `perf script -F time,ip,sym`."""
    time_s, stack = None, []
    with open(script_path) as lines:
        for line in lines:
            line = line.rstrip("\n")
            if not line.strip():
                if time_s is not None and stack:
                    yield time_s, stack
                time_s, stack = None, []
            elif TIME_LINE.match(line):  # some perf versions indent it as the frames
                time_s = float(line.split(":")[0])
            else:
                parts = line.strip().split(None, 1)
                stack.append(re.sub(r"\(.*", "", parts[1] if len(parts) > 1 else parts[0]))
    if time_s is not None and stack:
        yield time_s, stack


def fold(steps, script_path, anchor, depth, frequency):
    """Per kind: sampled us a step under each path of up to `depth` frames below the anchor."""
    starts = [s[0] for s in steps]
    count = collections.Counter(s[2] for s in steps)
    per_kind = collections.defaultdict(collections.Counter)
    for time_s, stack in samples(script_path):
        i = bisect.bisect_right(starts, time_s) - 1
        if i < 0 or time_s > steps[i][1]:
            continue
        key = "(not under the anchor)"
        for j in range(len(stack) - 1, -1, -1):
            if stack[j] == anchor or stack[j].endswith(anchor):
                key = " < ".join(reversed(stack[max(0, j - depth):j])) if j > 0 else "(the anchor itself)"
                break
        per_kind[steps[i][2]][key] += 1
    us_per_sample = 1e6 / frequency
    return {kind: {key: n * us_per_sample / count[kind] for key, n in keys.items()} for kind, keys in per_kind.items()}, count


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenario", default="")
    parser.add_argument("--organ", action="store_true")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--kinds", default="before,enriching")
    parser.add_argument("--anchor", default="tissue::Tissue::step")
    parser.add_argument("--depth", type=int, default=2)
    parser.add_argument("--frequency", type=int, default=20000)
    parser.add_argument("--module", default=os.path.join(ROOT, "build", "release", "python"))
    parser.add_argument("--child", default="", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        record_steps(args, args.child)
        return
    first, second = args.kinds.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        steps_path, data, script = (os.path.join(tmp, n) for n in ("steps.json", "perf.data", "perf.txt"))
        child = [sys.executable, os.path.abspath(__file__), "--child", steps_path, "--runs", str(args.runs),
                 "--module", args.module] + (["--scenario", args.scenario] if args.scenario else []) + (
                     ["--organ"] if args.organ else [])
        subprocess.run(["perf", "record", "-q", "-k", "CLOCK_MONOTONIC", "-F", str(args.frequency), "--call-graph",
                        "dwarf,16384", "-o", data] + child, check=True, stdout=subprocess.DEVNULL)
        with open(script, "w") as out:
            subprocess.run(["perf", "script", "-i", data, "-F", "time,ip,sym"], check=True, stdout=out,
                           stderr=subprocess.DEVNULL)
        with open(steps_path) as f:
            steps = json.load(f)
        per_kind, count = fold(steps, script, args.anchor, args.depth, args.frequency)
    a, b = per_kind.get(first, {}), per_kind.get(second, {})
    print(f"sampled us a step under {args.anchor}: {first} ({count[first]} steps) | {second} ({count[second]} steps)"
          " | difference | path below the anchor")
    rows = sorted(set(a) | set(b), key=lambda k: -(b.get(k, 0.0) - a.get(k, 0.0)))
    for key in rows:
        print(f"{a.get(key, 0.0):9.1f} | {b.get(key, 0.0):9.1f} | {b.get(key, 0.0) - a.get(key, 0.0):+9.1f} | {key[:160]}")


if __name__ == "__main__":
    main()
