#!/usr/bin/env python3
"""Long fuzz runs measured in CPU time, door after door (issue 44: an hour per door, over sessions).

Each door's target (build/fuzz/fuzz/fuzz_<door>, the `fuzz` preset) runs at nice 19 with a random
seed, new inputs into WORK/corpus/<door> and the door's seeds read only, until its process has used
the door's CPU budget; then SIGINT, and libFuzzer prints its final stats. JOBS doors at a time. A
door's budget is --cpu-seconds less what the ledger (--ledger, one line per run: door, CPU seconds,
executions, edges, features, the date) already holds for it, so a run stopped early (or a session's
end) is continued by running the same command again. CPU time, not wall time: the machine may
build or measure meanwhile (stop the targets with SIGSTOP while timing something; SIGCONT after).

Stop early with SIGTERM to the script (`pkill -TERM -f fuzz/long_run.py`): it interrupts its targets,
writes each run to the ledger as interrupted with the CPU it used, and exits (a SIGINT to a target
alone ends that run the same way, and the script starts the next door). Wall-clock pauses (SIGSTOP, a build at nice 0) would read as hangs under -timeout=1, so the runs use
-timeout=60 and --replay runs every slow or timed-out input kept in WORK/art again under -timeout=1
(with -runs=3): a real hang fails there.

Usage: fuzz/long_run.py [--doors a,b] [--cpu-seconds 3600] [--jobs 2] [--work DIR] [--ledger FILE]
       fuzz/long_run.py --replay [--work DIR]
       fuzz/long_run.py --summary [--ledger FILE]      # per door: CPU seconds, executions, edges
Uses only the Python standard library; Linux (/proc).
"""
import argparse
import datetime
import os
import pathlib
import random
import re
import signal
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
BIN = ROOT / "build" / "fuzz" / "fuzz"
DOORS = ["udp_packet", "igtl", "view_message", "fmu_state", "scenario", "veg", "tetgen", "gmsh", "bou", "obj",
         "surface_binary"]
TICK = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pid):
    """User + system CPU seconds of process `pid`, or None once it is gone."""
    try:
        fields = pathlib.Path("/proc/%d/stat" % pid).read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / TICK
    except (OSError, IndexError, ValueError):
        return None


def ledger_runs(path):
    """The ledger's runs that count, as (door, CPU seconds, executions, edges). A run whose note
    starts with "not counted" (it fuzzed nothing real, e.g. on seeds the target refused) is kept in
    the ledger for the record but counts toward neither a door's budget nor its summary."""
    runs = []
    for line in path.read_text().splitlines() if path.exists() else []:
        if line.startswith("#") or not line.strip():
            continue
        fields = line.split("\t")
        if len(fields) > 6 and fields[6].startswith("not counted"):
            continue
        runs.append((fields[0], float(fields[1]), int(fields[2]), int(fields[3])))
    return runs


def read_ledger(path):
    done = {}
    for door, seconds, _, _ in ledger_runs(path):
        done[door] = done.get(door, 0.0) + seconds
    return done


def final_stats(log_text):
    """(executions, edges, features) of the last run in a log: libFuzzer's final stats and last cov: line."""
    runs = log_text.rsplit("\n### ", 1)[-1]
    executions = re.findall(r"stat::number_of_executed_units:\s*(\d+)", runs)
    coverage = re.findall(r"cov: (\d+) ft: (\d+)", runs)
    return (int(executions[-1]) if executions else 0,
            int(coverage[-1][0]) if coverage else 0, int(coverage[-1][1]) if coverage else 0)


def start(door, work):
    corpus = work / "corpus" / door
    corpus.mkdir(parents=True, exist_ok=True)
    (work / "art").mkdir(exist_ok=True)
    (work / "logs").mkdir(exist_ok=True)
    command = ["nice", "-n", "19", str(BIN / ("fuzz_" + door)), "-seed=%d" % random.randint(1, 2**31 - 1),
               "-max_total_time=1000000", "-timeout=60", "-rss_limit_mb=2560", "-malloc_limit_mb=1024",
               "-print_final_stats=1", "-artifact_prefix=%s/art/%s-" % (work, door)]
    dictionary = ROOT / "fuzz" / "dict" / (door + ".dict")
    if dictionary.exists():
        command.append("-dict=%s" % dictionary)
    command += [str(corpus), str(ROOT / "fuzz" / "corpus" / door)]
    # One log per door and script: two scripts fuzzing the same door at once must not read each
    # other's final stats.
    log_path = work / "logs" / ("%s-%d.log" % (door, os.getpid()))
    with open(log_path, "a") as log:
        log.write("\n### %s %s\n" % (time.strftime("%F %T"), " ".join(command)))
    log = open(log_path, "a")
    return subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT), log_path


def run(args):
    work, ledger = pathlib.Path(args.work), pathlib.Path(args.ledger)
    done = read_ledger(ledger)
    pending = [(d, args.cpu_seconds - done.get(d, 0.0)) for d in args.doors.split(",")]
    pending = [(d, budget) for d, budget in pending if budget > 0]
    running = {}
    # SIGTERM (a session's end): interrupt the targets and write their runs to the ledger, then exit.
    stop = {"requested": False}
    signal.signal(signal.SIGTERM, lambda *_: stop.update(requested=True))
    while pending or running:
        if stop["requested"]:
            pending.clear()
            for process, *_ in running.values():
                if process.poll() is None:
                    process.send_signal(signal.SIGINT)
        while pending and len(running) < args.jobs:
            door, budget = pending.pop(0)
            process, log_path = start(door, work)
            running[door] = (process, log_path, budget, 0.0)
            print("%s %s started, %.0f s of CPU to go" % (time.strftime("%T"), door, budget), flush=True)
        time.sleep(1 if stop["requested"] else 10)
        for door, (process, log_path, budget, used) in list(running.items()):
            now = cpu_seconds(process.pid)
            if now is not None and process.poll() is None:
                used = now
                running[door] = (process, log_path, budget, used)
                if used < budget or stop["requested"]:
                    continue
                process.send_signal(signal.SIGINT)
                stopped = True
            else:
                stopped = False
            process.wait()
            # libFuzzer exits 72 when interrupted: by us at the budget, or by a SIGINT from outside (a stop)
            interrupted = process.returncode == 72
            executions, edges, features = final_stats(log_path.read_text(errors="replace"))
            with open(ledger, "a") as out:
                ended = ("its budget" if stopped else "interrupted" if interrupted
                         else "exit %d (a finding: WORK/art)" % process.returncode)
                out.write("%s\t%.0f\t%d\t%d\t%d\t%s\t%s\n" % (door, used, executions, edges, features,
                                                             datetime.date.today(), ended))
            print("%s %s: %.0f s of CPU, %d executions, %d edges, exit %d" % (
                time.strftime("%T"), door, used, executions, edges, process.returncode), flush=True)
            del running[door]


def replay(args):
    failures = 0
    for artifact in sorted((pathlib.Path(args.work) / "art").glob("*")):
        door = re.sub(r"-(slow-unit|timeout|crash|leak|oom)-.*$", "", artifact.name)
        result = subprocess.run([str(BIN / ("fuzz_" + door)), "-timeout=1", "-runs=3", str(artifact)],
                                capture_output=True, text=True)
        ok = result.returncode == 0
        failures += 0 if ok else 1
        print("%s %s" % ("ok  " if ok else "FAIL", artifact.name))
    return 1 if failures else 0


def summary(args):
    totals = {}
    for door, seconds, executions, edges in ledger_runs(pathlib.Path(args.ledger)):
        t = totals.setdefault(door, [0.0, 0, 0, 0])
        t[0] += seconds
        t[1] += executions
        t[2] = max(t[2], edges)
        t[3] += 1
    print("| door | CPU seconds | executions | edges (largest run) | runs |")
    print("|---|---:|---:|---:|---:|")
    for door in DOORS:
        if door in totals:
            seconds, executions, edges, runs = totals[door]
            print("| %s | %.0f | %d | %d | %d |" % (door, seconds, executions, edges, runs))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--doors", default=",".join(DOORS))
    parser.add_argument("--cpu-seconds", type=float, default=3600.0)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--work", default="/tmp/tissue-fuzz-long")
    parser.add_argument("--ledger", default=str(ROOT / "fuzz" / "long_runs.tsv"))
    parser.add_argument("--replay", action="store_true")
    parser.add_argument("--summary", action="store_true")
    args = parser.parse_args()
    if args.replay:
        return replay(args)
    if args.summary:
        return summary(args)
    run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
