#!/usr/bin/env python3
"""Where a cut step's time goes (issue 41, item 5): the frog of cut_frog_complete (held at its hind
30%, E 300 kPa, 10 ms steps) through `import tissue`, a vertical scalpel drawn across at 60% of its
length in 175 steps. Prints, per kind of step, the medians of the step's parts (TissueStepReport's
wall times, ms), how often the tangent was re-laid out, the mean Newton corrections (a step that
turns an element far is corrected: a cost that follows the trajectory, not the code) and the page
faults a step took (getrusage's minor faults: memory first touched within the step; tissue-host,
which locks what it holds at its start, pays them only for memory allocated since):

* before: 40 steps with the scalpel beside the body, before any cut;
* enriching: the stroke's steps that cut tets (the volume cutter's new cuts, enriched at once)
  without moving the tangent's storage;
* re-layout: those whose cuts needed room the rows did not have (the tangent re-laid out);
* plain: the stroke's other steps.

With --organ: the 52k-tet organ of host/scenarios/cut_organ.toml (meshes/liver.veg hung by its
ridge, E 300 kPa) and a vertical scalpel through its left lobe at 80% of its length in 150 steps,
20 steps before, and 40 "after" steps with the tool put away.

With --scenario FILE: a tissue-host scenario's tissue and tool path (`tissue.Scenario`, its settings,
threads included), stepped offline: "before" is the steps before its first cut, "plain" the steps
after it that cut nothing (e.g. host/scenarios/cut_organ.toml: the 6.1k-tet organ on two threads).

Usage: /usr/bin/python3 tests/bench/cut_step_parts.py [--runs 3] [--solver pcgTwoLevel] [--organ]
       [--scenario FILE] [--module DIR]
(DIR: where tissue*.so is, default build/release/python). One thread; run nothing else meanwhile.
"""
import argparse
import os
import resource
import statistics
import sys
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
PARTS = ("total_s", "assembly_s", "solve_s", "guard_s", "cut_s", "enrich_s", "positions_s")


def step_counting_faults(body):
    """body.step()'s report, with the page faults the step took (memory first touched in it) and when
    it began and ended (time.monotonic: CLOCK_MONOTONIC, as cut_step_profile.py's perf samples)."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    started_s = time.monotonic()
    report = body.step()
    report["ended_s"] = time.monotonic()
    report["started_s"] = started_s
    report["page_faults"] = resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
    return report


def stroke(tissue, solver, organ):
    kwargs = dict(step_size_s=0.01, young_modulus_pa=3e5, blade_length_m=0.2, threads=1)
    if organ:
        kwargs.update(mesh=os.path.join(ROOT, "meshes", "liver.veg"), fixed_axis=1, fixed_fraction=0.04)
    else:
        kwargs.update(mesh="frog", fixed_axis=0, fixed_fraction=0.3)
    if solver:
        kwargs["linear_solver"] = solver
    body = tissue.Tissue(**kwargs)
    rest = body.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    size = upper - lower
    body.step(5 if organ else 20)  # settle under gravity
    x = lower[0] + (0.8 if organ else 0.6) * size[0]
    tip_z = lower[2] - (0.02 if organ else 0.05)
    kinds = {"before": [], "enriching": [], "re-layout": [], "plain": []}
    for _ in range(20 if organ else 40):
        body.set_tool((x, lower[1] - 0.05, tip_z), mode="scalpel")
        kinds["before"].append(step_counting_faults(body))
    steps = 150 if organ else 175
    for n in range(steps + 1):
        if organ:  # from the front to the back, as cut_organ's
            y = upper[1] + 0.15 * size[1] - n / steps * 1.3 * size[1]
        else:
            y = lower[1] - 0.01 + n / steps * (size[1] + 0.02)
        body.set_tool((x, y, tip_z), mode="scalpel")
        report = step_counting_faults(body)
        if report["newly_cut_tets"] == 0:
            kinds["plain"].append(report)
        else:
            kinds["re-layout" if report.get("matrix_relayout") else "enriching"].append(report)
    if organ:
        kinds["after"] = []
        body.set_tool((x, lower[1] - 0.1, upper[2] + 0.1), mode="none")
        for _ in range(40):
            kinds["after"].append(step_counting_faults(body))
    return kinds


def scenario_steps(tissue, path):
    scenario = tissue.Scenario(path)
    body = scenario.tissue()
    kinds = {"before": [], "enriching": [], "re-layout": [], "plain": []}
    cut = False
    n = 0
    while n * scenario.tissue_step_s < scenario.duration_s:
        position, orientation, mode = scenario.tool_at(n * scenario.tissue_step_s)
        body.set_tool(position, orientation, mode=mode)
        report = step_counting_faults(body)
        if report["newly_cut_tets"] > 0:
            cut = True
            kinds["re-layout" if report["matrix_relayout"] else "enriching"].append(report)
        else:
            kinds["plain" if cut else "before"].append(report)
        n += 1
    return kinds


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--solver", default="")
    parser.add_argument("--organ", action="store_true")
    parser.add_argument("--scenario", default="")
    parser.add_argument("--module", default=os.path.join(ROOT, "build", "release", "python"))
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue  # noqa: E402

    print("| run | steps | n | total | assembly | solve | energy guard | cut | enrich | positions | re-layouts "
          "| Newton corrections (mean) | page faults (median / max) | total / before |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for run in range(args.runs):
        kinds = scenario_steps(tissue, args.scenario) if args.scenario else stroke(tissue, args.solver, args.organ)
        before_ms = 1e3 * statistics.median(r["total_s"] for r in kinds["before"])
        for name, reports in kinds.items():
            if not reports:
                continue
            # A module from before a part was reported (--module of an older build) leaves it "-".
            medians = [1e3 * statistics.median(r[p] for r in reports) if p in reports[0] else None for p in PARTS]
            relayouts = sum(bool(r["matrix_relayout"]) for r in reports) if "matrix_relayout" in reports[0] else "-"
            newton = statistics.mean(r["newton_iterations"] for r in reports)
            faults = [r["page_faults"] for r in reports]
            print("| %d | %s | %d | %s | %s | %.2f | %d / %d | %.2fx |" % (
                run + 1, name, len(reports), " | ".join("-" if m is None else "%.2f" % m for m in medians), relayouts,
                newton, statistics.median(faults), max(faults), medians[0] / before_ms))


if __name__ == "__main__":
    main()
