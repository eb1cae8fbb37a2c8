#!/usr/bin/env python3
"""Every shipped scenario in real time, N runs each (issue 23): tissue overruns, haptic deadline
misses, tissue step p50/p99/max, and the cut steps against the steps before the cut. Prints a
Markdown table with the machine. Real time needs the cores to itself: run nothing else meanwhile
(as root the host's threads get SCHED_FIFO).

Usage: tests/bench/realtime_table.py [--host build/release/host/tissue-host] [--runs 5] [--only NAME,NAME]
                                    [--set PARAMETER=VALUE ...] [--alternate PARAMETER=VALUE ...]
                                    [--alternate-host OTHER/tissue-host] [--timer-seconds 10]
--set overrides Tissue parameters in every scenario (e.g. the default before issue 40:
--set integrator.linearSolver=pcg --set integrator.newtonMaxIterations=5); --alternate runs each
scenario's runs twice over, interleaved, without and with these overrides, and prints both tables
(the same machine state for both: the way to compare two settings on a shared machine);
--alternate-host does the same with another build of tissue-host (a change to the host or the FMUs:
copy the other build's host/tissue-host and fmus/ aside as DIR/host/tissue-host and DIR/fmus/ first;
a tissue-host takes the FMUs of ../fmus beside it).
A scenario driven by the browser's mouse runs 5 s with the live view up and no one at it.
The progress lines (stderr) say what each overrun's slot held (slots.csv: the step, the frame).
Each run writes its frames to a temporary folder (Python's tempfile: TMPDIR): a render surface's VTU
frames are 1.7 MB each, and on the 2-core VM their writeback to disk delays the haptic thread's
wake-ups (docs/BENCHMARKS.md, Host); TMPDIR=/dev/shm measures the session without the disk.
Before each run `tissue-host timer` ticks alone for --timer-seconds (10 s): the deadline misses the
machine makes with no session at all, printed beside the session's (a run cannot miss fewer).
Uses only the Python standard library.
"""
import argparse
import csv
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
    parser.add_argument("--set", action="append", default=[], metavar="PARAMETER=VALUE",
                        help="a Tissue parameter set in every scenario")
    parser.add_argument("--alternate", action="append", default=[], metavar="PARAMETER=VALUE",
                        help="also run every scenario with these, interleaved run by run, and print both tables")
    parser.add_argument("--alternate-host", default=None, metavar="TISSUE_HOST",
                        help="also run every scenario with this tissue-host, interleaved run by run, and print both tables")
    parser.add_argument("--timer-seconds", type=float, default=10.0,
                        help="before each run, `tissue-host timer` alone this long (the machine's own deadline misses)")
    args = parser.parse_args()
    wanted = args.only.split(",")
    scenarios = sorted(p for p in (ROOT / "host" / "scenarios").glob("*.toml")
                       if not p.name.startswith(".") and any(w in p.stem for w in wanted))
    variants = [("", args.host, args.set)]
    if args.alternate:
        variants.append(("with " + " ".join(args.alternate), args.host, args.set + args.alternate))
    if args.alternate_host:
        variants.append(("with " + args.alternate_host, args.alternate_host, args.set))
    rows = {label: [] for label, _, _ in variants}
    for scenario in scenarios:
        runs = {label: [] for label, _, _ in variants}
        for k in range(args.runs):
            timer = timer_alone(args.host, args.timer_seconds)
            print("  the timer alone before run %d: misses %d of %d (%.2f %%), woke late max %.0f us"
                  % (k + 1, timer["deadline_misses"], timer["ticks"], timer_misses_percent(timer),
                     timer["wake_late_us"]["max"]), file=sys.stderr)
            for label, host, overrides in variants:
                runs[label].append(run_once(host, scenario, overrides))
                r = runs[label][-1]
                r["timer_alone"] = timer
                print("  %s%s run %d/%d: overruns %d (steps %d, slots skipped %d), misses %d of %d, step p99 %.2f ms, "
                      "SCHED_FIFO %s"
                      % (scenario.stem, " (" + label + ")" if label else "", k + 1, args.runs, r["tissue_overruns"],
                         r["tissue_steps"], r["skipped_slots"], r["deadline_misses"], r["haptic_ticks"],
                         r["tissue_step_ms"]["p99"], r["realtime_priority"]),
                      file=sys.stderr)
                for slot in r["overrun_slots"]:
                    print("    overrun at " + slot, file=sys.stderr)
        for label, _, _ in variants:
            rows[label].append((scenario.stem, runs[label]))

    print("Machine: %d cores (`nproc`); %d real-time runs of each scenario (`tissue-host run`, not offline); "
          "figures per run, listed run by run where they differ.%s\n"
          % (os.cpu_count(), args.runs, " Parameters set: " + " ".join(args.set) + "." if args.set else ""))
    for label, _, _ in variants:
        if label:
            print("\n%s (runs interleaved with the table above):\n" % label)
        print_table(rows[label])


def timer_alone(host, seconds):
    """`tissue-host timer`: the haptic thread's ticks with no session, as this machine keeps them now."""
    with tempfile.TemporaryDirectory(prefix="tissue-timer-") as out:
        path = pathlib.Path(out) / "timer.json"
        subprocess.run([host, "timer", "--duration", str(seconds), "--json", str(path)], check=True,
                       capture_output=True, text=True)
        return json.loads(path.read_text())


def timer_misses_percent(timer):
    return 100.0 * timer["deadline_misses"] / max(timer["ticks"], 1)


def toml_value(text):
    """A parameter's value as TOML: numbers and booleans as they are, anything else quoted."""
    if text in ("true", "false"):
        return text
    try:
        float(text)
        return text
    except ValueError:
        return json.dumps(text)


def run_once(host, scenario, overrides):
    """One real-time run of `scenario` with Tissue parameters `overrides` (PARAMETER=VALUE); its summary."""
    source = scenario
    if overrides:  # a copy beside the original, so that its relative paths still hold
        lines = scenario.read_text().splitlines()
        names = [o.split("=", 1)[0] for o in overrides]
        lines = [l for l in lines if not any(l.strip().startswith('"%s"' % n) for n in names)]
        if "[tissue.parameters]" not in lines:
            lines.append("[tissue.parameters]")
        at = lines.index("[tissue.parameters]") + 1
        for o in overrides:
            name, value = o.split("=", 1)
            lines.insert(at, '"%s" = %s' % (name, toml_value(value)))
        source = scenario.with_name(".realtime-table-" + scenario.name)
        source.write_text("\n".join(lines) + "\n")
    try:
        with tempfile.TemporaryDirectory(prefix="tissue-rt-") as out:
            command = [host, "run", str(source), "-o", out, "-q"]
            if 'kind = "browser"' in scenario.read_text():
                command += ["--mouse", "--duration", "5"]  # the live view's mouse, no one at it: 5 s idle
            if 'kind = "openigtlink"' in scenario.read_text():
                command += ["--duration", "5"]  # the OpenIGTLink server, no client: 5 s idle
            subprocess.run(command, check=True, capture_output=True, text=True)
            summary = json.loads((pathlib.Path(out) / "summary.json").read_text())
            summary["overrun_slots"] = overrun_slots(pathlib.Path(out) / "slots.csv")
            return summary
    finally:
        if source != scenario:
            source.unlink()


def overrun_slots(path):
    """What each overrun slot of slots.csv held: its slot, the step's ms, the frame and its capture's ms."""
    if not path.exists():
        return []
    with path.open() as f:
        rows = list(csv.DictReader(f))
    return ["slot %s: step %.1f ms%s, %+.1f ms" % (r["slot"], float(r["step_ms"]),
                                                  ", " + r["frame"] + " %.1f ms" % float(r["capture_ms"]) if r["frame"] else "",
                                                  float(r["end_after_slot_ms"]))
            for r in rows if float(r["end_after_slot_ms"]) > 0]


def print_table(rows):
    print("| scenario | tissue overruns | haptic misses (of ticks) | misses % | tissue step p50 / p99 / max (ms), "
          "median run | cut steps / before the cut: p50; p99 | the timer alone before each run: misses % |")
    print("|---|---|---|---:|---|---|---|")
    for name, runs in rows:
        overruns = [r["tissue_overruns"] for r in runs]
        misses = [r["deadline_misses"] for r in runs]
        ticks = runs[0]["haptic_ticks"]
        p99s = [r["tissue_step_ms"]["p99"] for r in runs]
        median_run = sorted(runs, key=lambda r: r["tissue_step_ms"]["p99"])[len(runs) // 2]
        s = median_run["tissue_step_ms"]
        ratios = []
        for q in ("p50", "p99"):
            during = median_run.get("tissue_step_during_cut_ms", {}).get(q, 0.0)
            before = median_run.get("tissue_step_before_cut_ms", {}).get(q, 0.0)
            if during > 0 and before > 0:
                ratios.append("%.2f / %.2f = %.2fx" % (during, before, during / before))
        cut = "; ".join(ratios) if ratios else "-"
        alone = " ".join("%.2f" % timer_misses_percent(r["timer_alone"]) for r in runs)
        print("| %s | %s | %s (of %d) | %.3f | %.2f / %.2f / %.2f (p99 of the runs %.2f-%.2f) | %s | %s |"
              % (name, " ".join(map(str, overruns)), " ".join(map(str, misses)), ticks,
                 100.0 * statistics.mean(misses) / max(ticks, 1), s["p50"], s["p99"], s["max"], min(p99s), max(p99s),
                 cut, alone))


if __name__ == "__main__":
    main()
