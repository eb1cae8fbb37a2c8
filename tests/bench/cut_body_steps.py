#!/usr/bin/env python3
"""What a cut body's step costs against the uncut body's (issue 41, item 5): a scenario's tissue
through `import tissue` (`tissue.Scenario`), stepped STEPS times with the tool at its start pose,
once uncut and once after the scenario's whole tool path (its cuts made). Prints per run the unknowns
and the medians of the step and its parts (TissueStepReport's wall times, ms), then the ratios of
the medians over the runs. The step of a cut body carries the ghosts' rows and the pieces of its cut
tets: this is the cost a real-time table's "cut steps / before the cut" ratio is made of once the
strokes are over.

Usage: /usr/bin/python3 tests/bench/cut_body_steps.py [--scenario host/scenarios/flap_frog.toml]
       [--steps 400] [--runs 2] [--module DIR]
(DIR: where tissue*.so is, default build/release/python.) One thread; run nothing else meanwhile.
"""
import argparse
import pathlib
import statistics
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
PARTS = ("total_s", "assembly_s", "solve_s", "positions_s")


def measure(tissue, scenario_path, cut, steps):
    scenario = tissue.Scenario(str(scenario_path))
    body = scenario.tissue()
    step = 0
    while cut and step * scenario.tissue_step_s < scenario.duration_s:
        position, orientation, mode = scenario.tool_at(step * scenario.tissue_step_s)
        body.set_tool(position, orientation, mode=mode)
        body.step()
        step += 1
    position, orientation, mode = scenario.tool_at(0.0)
    body.set_tool(position, orientation, mode=mode)
    reports = [body.step() for _ in range(steps)]
    medians = {part: 1e3 * statistics.median(r[part] for r in reports) for part in PARTS}
    newton = sum(1 for r in reports if r["newton_iterations"] > 0)
    return body.dof_count, medians, newton


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenario", default=str(ROOT / "host" / "scenarios" / "flap_frog.toml"))
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--runs", type=int, default=2)
    parser.add_argument("--module", default=str(ROOT / "build" / "release" / "python"))
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue  # noqa: E402 (the module chosen above)

    ratios = {part: [] for part in PARTS}
    for run in range(args.runs):
        rows = {}
        for cut in (False, True):
            dofs, medians, newton = measure(tissue, args.scenario, cut, args.steps)
            rows[cut] = medians
            print("run %d, %s: %d unknowns; %s; steps with Newton corrections %d" %
                  (run + 1, "cut" if cut else "uncut", dofs,
                   ", ".join("%s %.3f ms" % (p[:-2], medians[p]) for p in PARTS), newton), flush=True)
        for part in PARTS:
            if rows[False][part] > 0:
                ratios[part].append(rows[True][part] / rows[False][part])
    print("cut / uncut, median over the runs: " +
          ", ".join("%s %.2fx" % (p[:-2], statistics.median(v)) for p, v in ratios.items() if v))


if __name__ == "__main__":
    main()
