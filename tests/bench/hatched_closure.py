#!/usr/bin/env python3
"""Whether the render surface stays closed under hatched strokes on trajectories next to the one the
suite checks (issue 41, item 4). `test_host_session --gtest_filter='*HatchedFrog*'` checks three
trajectories: docs/hatched_frog.toml (10 + 10 strokes through the sagging frog) through tissue-host,
as it is and with Young's modulus x 1.03 and x 1.05.
Cut decisions are sensitive to rounding (a step's results moved by 1e-13 m flip a tet's cut a few
dozen steps later), so a change to the arithmetic anywhere in a step moves the strokes onto a
neighbouring trajectory. This runs the scenario's tissue and tool path through `import tissue`
(`tissue.Scenario`, one step per communication step) with Young's modulus scaled by 1 + k/100 for k
in --moduli, reads the render surface after every step that cut, and prints per run the border
edges (directed edges without their twin) at the first step that had any and at the end.

Usage: /usr/bin/python3 tests/bench/hatched_closure.py [--scenario docs/hatched_frog.toml]
       [--moduli 0,1,2,3,4,5,6] [--module DIR]
(DIR: where tissue*.so is, default build/release/python.) About 20 s a run on one core.
"""
import argparse
import pathlib
import re
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[2]


def border_edges(triangles):
    directed = set()
    for a, b, c in triangles.tolist():
        directed.update(((a, b), (b, c), (c, a)))
    return sum(1 for (u, v) in directed if (v, u) not in directed)


def run(tissue, scenario_path):
    scenario = tissue.Scenario(str(scenario_path))
    body = scenario.tissue()
    step, cut_tets, first = 0, -1, None
    while step * scenario.tissue_step_s < scenario.duration_s:
        position, orientation, mode = scenario.tool_at(step * scenario.tissue_step_s)
        body.set_tool(position, orientation, mode=mode)
        body.step()
        step += 1
        if body.cut_tets == cut_tets:
            continue
        cut_tets = body.cut_tets
        border = border_edges(body.render_surface()["triangles"])
        if border > 0 and first is None:
            first = (step, border)
    return first, border_edges(body.render_surface()["triangles"]), body.cut_tets


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--scenario", default=str(ROOT / "docs" / "hatched_frog.toml"))
    parser.add_argument("--moduli", default="0,1,2,3,4,5,6",
                        help="k: Young's modulus times 1 + k/100 (comma-separated)")
    parser.add_argument("--module", default=str(ROOT / "build" / "release" / "python"))
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue  # noqa: E402 (the module chosen above)

    text = pathlib.Path(args.scenario).read_text()
    match = re.search(r'"material.youngModulus" = ([0-9.eE+-]+)', text)
    if match is None:
        sys.exit("the scenario sets no material.youngModulus")
    young = float(match.group(1))
    print("| Young's modulus | first border (step: edges) | border edges at the end | cut tets |")
    print("|---|---|---:|---:|")
    closed = 0
    for k in [int(v) for v in args.moduli.split(",")]:
        modulus = young * (1 + k / 100)
        with tempfile.TemporaryDirectory() as folder:
            path = pathlib.Path(folder) / "scenario.toml"
            path.write_text(text.replace(match.group(0), '"material.youngModulus" = %r' % modulus))
            first, end, cut_tets = run(tissue, path)
        closed += 1 if first is None else 0
        print("| %.4g Pa | %s | %d | %d |" % (modulus, "none" if first is None else "%d: %d" % first, end, cut_tets),
              flush=True)
    print("\n%d of %d runs closed after every cutting step." % (closed, len(args.moduli.split(","))))


if __name__ == "__main__":
    main()
