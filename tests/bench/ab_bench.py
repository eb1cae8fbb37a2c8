#!/usr/bin/env python3
"""Two tissue-bench builds measured side by side, run by run (A/B on a shared, noisy machine).

    tests/bench/ab_bench.py --a OLD/tissue-bench --b NEW/tissue-bench [--rounds 10] [--pin 1]
                            [--haptic-load BUSY_US] -- TISSUE_BENCH_OPTIONS...

Each round runs both builds once, in turn (the order alternating by round), so that a round's two
runs share the machine's spells; the figures are each build's medians and minima over the rounds
and the median of the rounds' B/A ratios of the median step. --pin C pins each run to core C (one
thread); without it the runs may use every core (--threads 2).

--haptic-load BUSY_US stands in for the 1 kHz haptic thread that shares the cores with the
dynamics team in a real session: a SCHED_FIFO 80 process on the last core busy BUSY_US of every
millisecond for the length of each run, the bench itself at SCHED_FIFO 70 (as tissue-host runs
them; needs root, else refused).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

HOG = r"""
import os, sys, time
core, busy = int(sys.argv[1]), float(sys.argv[2]) * 1e-6
os.sched_setaffinity(0, {core})
os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(80))
print("ready", flush=True)
tick = time.perf_counter()
while True:
    start = time.perf_counter()
    while time.perf_counter() - start < busy:
        pass
    tick += 1e-3
    wait = tick - time.perf_counter()
    if wait > 0:
        time.sleep(wait)
"""


def run(binary, options, args):
    command = [binary] + options
    if args.pin is not None:
        command = ["taskset", "-c", str(args.pin)] + command
    if args.haptic_load is not None:
        command = ["chrt", "-f", "70"] + command
    hog = None
    if args.haptic_load is not None:
        hog = subprocess.Popen([sys.executable, "-c", HOG, str(os.cpu_count() - 1), str(args.haptic_load)],
                               stdout=subprocess.PIPE, text=True)
        if hog.stdout.readline().strip() != "ready":
            sys.exit("the haptic stand-in could not start (SCHED_FIFO needs root)")
    try:
        out = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    finally:
        if hog is not None:
            hog.kill()
            hog.wait()
    return json.loads(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--a", required=True, help="tissue-bench of build A (the reference)")
    parser.add_argument("--b", required=True, help="tissue-bench of build B")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--pin", type=int, help="pin each run to this core")
    parser.add_argument("--haptic-load", type=float, metavar="BUSY_US",
                        help="a 1 kHz SCHED_FIFO 80 load on the last core, busy BUSY_US per tick")
    parser.add_argument("options", nargs=argparse.REMAINDER, help="-- then tissue-bench's options")
    args = parser.parse_args()
    options = args.options[1:] if args.options[:1] == ["--"] else args.options
    results = {"A": [], "B": []}
    for k in range(args.rounds):
        for who in (("A", "B") if k % 2 == 0 else ("B", "A")):
            results[who].append(run(args.a if who == "A" else args.b, options, args))
        a, b = results["A"][-1], results["B"][-1]
        print("round %d/%d: A %.3f ms, B %.3f ms (median step)" %
              (k + 1, args.rounds, a["ms_per_step"]["median"], b["ms_per_step"]["median"]), file=sys.stderr)
        time.sleep(0.1)
    cpu = next((line.split(":", 1)[1].strip() for line in open("/proc/cpuinfo") if line.startswith("model name")), "?")
    print("Machine: %d cores, %s; %d rounds; tissue-bench %s%s%s" %
          (os.cpu_count(), cpu, args.rounds, " ".join(options),
           "; pinned to core %d" % args.pin if args.pin is not None else "",
           "; haptic stand-in busy %g us/ms" % args.haptic_load if args.haptic_load is not None else ""))
    print("| build | median step: median / min (ms) | p90 step: median (ms) | max step: median (ms) | assembly (ms) | solve (ms) |")
    print("|---|---:|---:|---:|---:|---:|")
    for who in ("A", "B"):
        rows = results[who]
        med = [r["ms_per_step"]["median"] for r in rows]
        print("| %s | %.3f / %.3f | %.3f | %.3f | %.3f | %.3f |" %
              (who, statistics.median(med), min(med), statistics.median(r["ms_per_step"]["p90"] for r in rows),
               statistics.median(r["ms_per_step"]["max"] for r in rows),
               statistics.median(r["assembly_ms"] for r in rows), statistics.median(r["solve_ms"] for r in rows)))
    ratios = [b["ms_per_step"]["median"] / a["ms_per_step"]["median"] for a, b in zip(results["A"], results["B"])]
    print("\nB / A per round (median step): median %.3f, rounds %s" %
          (statistics.median(ratios), " ".join("%.2f" % r for r in ratios)))


if __name__ == "__main__":
    main()
