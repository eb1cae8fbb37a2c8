#!/usr/bin/env python3
"""Every shipped scenario in real time, N runs each (issue 23): tissue overruns, haptic deadline
misses, tissue step p50/p99/max, and the cut steps against the steps before the cut. Prints a
Markdown table with the machine. Real time needs the cores to itself: run nothing else meanwhile
(as root the host's threads get SCHED_FIFO).

Usage: tests/bench/realtime_table.py [--host build/release/host/tissue-host] [--runs 5] [--only NAME,NAME]
A scenario driven by the browser's mouse runs 5 s with the live view up and no one at it.
Uses only the Python standard library.
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--host", default=str(ROOT / "build" / "release" / "host" / "tissue-host"))
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--only", default="", help="only these scenarios (comma-separated parts of file names)")
    args = parser.parse_args()
    wanted = args.only.split(",")
    scenarios = sorted(p for p in (ROOT / "host" / "scenarios").glob("*.toml") if any(w in p.stem for w in wanted))
    rows = []
    for scenario in scenarios:
        runs = []
        for k in range(args.runs):
            with tempfile.TemporaryDirectory(prefix="tissue-rt-") as out:
                command = [args.host, "run", str(scenario), "-o", out, "-q"]
                if 'kind = "browser"' in scenario.read_text():
                    command += ["--mouse", "--duration", "5"]  # the live view's mouse, no one at it: 5 s idle
                if 'kind = "openigtlink"' in scenario.read_text():
                    command += ["--duration", "5"]  # the OpenIGTLink server, no client: 5 s idle
                subprocess.run(command, check=True, capture_output=True, text=True)
                runs.append(json.loads((pathlib.Path(out) / "summary.json").read_text()))
            r = runs[-1]
            print("  %s run %d/%d: overruns %d, misses %d of %d, step p99 %.2f ms, SCHED_FIFO %s"
                  % (scenario.stem, k + 1, args.runs, r["tissue_overruns"], r["deadline_misses"], r["haptic_ticks"],
                     r["tissue_step_ms"]["p99"], r["realtime_priority"]), file=sys.stderr)
        rows.append((scenario.stem, runs))

    print("Machine: %d cores (`nproc`); %d real-time runs of each scenario (`tissue-host run`, not offline); "
          "figures per run, listed run by run where they differ.\n" % (os.cpu_count(), args.runs))
    print("| scenario | tissue overruns | haptic misses (of ticks) | misses % | tissue step p50 / p99 / max (ms), "
          "median run | cut steps p50 / before the cut p50 |")
    print("|---|---|---|---:|---|---|")
    for name, runs in rows:
        overruns = [r["tissue_overruns"] for r in runs]
        misses = [r["deadline_misses"] for r in runs]
        ticks = runs[0]["haptic_ticks"]
        p99s = [r["tissue_step_ms"]["p99"] for r in runs]
        median_run = sorted(runs, key=lambda r: r["tissue_step_ms"]["p99"])[len(runs) // 2]
        s = median_run["tissue_step_ms"]
        during = median_run.get("tissue_step_during_cut_ms", {}).get("p50", 0.0)
        before = median_run.get("tissue_step_before_cut_ms", {}).get("p50", 0.0)
        cut = "%.2f / %.2f = %.2fx" % (during, before, during / before) if during > 0 and before > 0 else "-"
        print("| %s | %s | %s (of %d) | %.3f | %.2f / %.2f / %.2f (p99 of the runs %.2f-%.2f) | %s |"
              % (name, " ".join(map(str, overruns)), " ".join(map(str, misses)), ticks,
                 100.0 * statistics.mean(misses) / max(ticks, 1), s["p50"], s["p99"], s["max"], min(p99s), max(p99s),
                 cut))


if __name__ == "__main__":
    main()
