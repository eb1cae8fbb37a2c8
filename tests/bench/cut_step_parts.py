#!/usr/bin/env python3
"""Where a cut step's time goes (issue 41, item 5): the frog of cut_frog_complete (held at its hind
30%, E 300 kPa, 10 ms steps) through `import tissue`, a vertical scalpel drawn across at 60% of its
length in 175 steps. Prints, per kind of step, the medians of the step's parts (TissueStepReport's
wall times, ms) and how often the tangent was re-laid out:

* before: 40 steps with the scalpel beside the body, before any cut;
* enriching: the stroke's steps that cut tets (the volume cutter's new cuts, enriched at once);
* plain: the stroke's other steps.

Usage: tests/bench/cut_step_parts.py [--runs 3] [--solver pcgTwoLevel] [--module DIR]
(DIR: where tissue*.so is, default build/release/python). One thread; run nothing else meanwhile.
"""
import argparse
import os
import statistics
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
PARTS = ("total_s", "assembly_s", "solve_s", "cut_s", "enrich_s")


def stroke(tissue, solver):
    kwargs = dict(mesh="frog", step_size_s=0.01, fixed_axis=0, fixed_fraction=0.3, young_modulus_pa=3e5,
                  blade_length_m=0.2)
    if solver:
        kwargs["linear_solver"] = solver
    frog = tissue.Tissue(**kwargs)
    rest = frog.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    frog.step(20)  # settle under gravity
    x = lower[0] + 0.6 * (upper[0] - lower[0])
    kinds = {"before": [], "enriching": [], "plain": []}
    for _ in range(40):
        frog.set_tool((x, lower[1] - 0.05, lower[2] - 0.05), mode="scalpel")
        kinds["before"].append(frog.step())
    steps = 175
    for n in range(steps + 1):
        y = lower[1] - 0.01 + n / steps * (upper[1] - lower[1] + 0.02)
        frog.set_tool((x, y, lower[2] - 0.05), mode="scalpel")
        report = frog.step()
        kinds["enriching" if report["newly_cut_tets"] > 0 else "plain"].append(report)
    return kinds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--solver", default="")
    parser.add_argument("--module", default=os.path.join(ROOT, "build", "release", "python"))
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue  # noqa: E402

    print("| run | steps | n | total | assembly | solve | cut | enrich | re-layouts | total / before |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for run in range(args.runs):
        kinds = stroke(tissue, args.solver)
        before_ms = 1e3 * statistics.median(r["total_s"] for r in kinds["before"])
        for name, reports in kinds.items():
            medians = [1e3 * statistics.median(r[p] for r in reports) for p in PARTS]
            relayouts = sum(bool(r["matrix_relayout"]) for r in reports)
            print("| %d | %s | %d | %s | %d | %.2fx |" % (run + 1, name, len(reports),
                                                       " | ".join("%.2f" % m for m in medians), relayouts,
                                                       medians[0] / before_ms))


if __name__ == "__main__":
    main()
