#!/usr/bin/env python3
"""Runs tissue-cut-bench (the dissertation's tables 6.3 and 6.4 on our frog) with PCG (real-time
setting), CHOLMOD and CG with a lagged Cholesky factor (at 1e-6, near-exact), several times each, and prints Markdown tables of the per-field medians over
the runs, for docs/BENCHMARKS.md.

Usage: tests/bench/run_cut_bench.py [--bench build/release/apps/tissue-cut-bench] [--runs 5]
Uses only the Python standard library.
"""
import argparse
import json
import pathlib
import statistics
import subprocess

ROOT = pathlib.Path(__file__).resolve().parents[2]


# Each solver with its options: PCG at the bench's real-time defaults, pcgCholesky near-exact.
SOLVERS = {"pcg": [], "cholmod": [], "pcgCholesky": ["--tolerance", "1e-6", "--max-iterations", "200"]}


def run(bench, solver):
    command = [str(bench), "--solver", solver] + SOLVERS[solver]
    output = subprocess.run(command, check=True, capture_output=True, text=True).stdout
    return json.loads(output)


def median_of(runs, scenario, *path):
    values = []
    for r in runs:
        value = r[scenario]
        for key in path:
            value = value[key]
        values.append(value)
    return statistics.median(values)


def median_worst_over_after(runs, scenario):
    return statistics.median(r[scenario]["step_ms_during_cuts"]["max"] / r[scenario]["ms_per_step_after"] for r in runs)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "apps" / "tissue-cut-bench"))
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    for solver in SOLVERS:
        runs = [run(args.bench, solver) for _ in range(args.runs)]
        first = runs[0]
        print(f"\n{solver}, dt = {first[0]['dt_s']} s, scalpel {first[0]['speed_m_per_s']} m/s "
              f"(medians of {args.runs} runs)\n")
        print("| test | cuts | dofs before | after | enriched vertices | cut tets | non-zeros before | after "
              "| ms/step before | after | cutter ms/step median (max) | new tets/step mean (max) "
              "| step during cuts median | worst | worst / before | worst / after | relayouts |")
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        by_name = [{s["scenario"]: s for s in r} for r in runs]
        for s in first:
            name = s["scenario"]
            m = lambda *path: median_of(by_name, name, *path)  # noqa: E731
            print(f"| {name} | {s['cuts']} | {s['dofs_before']} | {s['dofs_after']} | {s['enriched_vertices']} "
                  f"| {s['cut_tets']} | {s['nonzeros_before']} | {s['nonzeros_after']} "
                  f"| {m('ms_per_step_before'):.3f} | {m('ms_per_step_after'):.3f} "
                  f"| {m('cutter_ms', 'median'):.3f} ({m('cutter_ms', 'max'):.3f}) "
                  f"| {m('new_tets_per_cutting_step', 'mean'):.1f} ({m('new_tets_per_cutting_step', 'max'):.0f}) "
                  f"| {m('step_ms_during_cuts', 'median'):.3f} | {m('step_ms_during_cuts', 'max'):.3f} "
                  f"| {m('worst_over_normal'):.2f} | {median_worst_over_after(by_name, name):.2f} "
                  f"| {m('matrix_relayouts'):.0f} |")


if __name__ == "__main__":
    main()
