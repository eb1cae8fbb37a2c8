#!/usr/bin/env python3
"""Our step against Vega FEM's on the same meshes and settings, in one run, alternating (issue 12).

Vega FEM 4.0's own semi-implicit backward-Euler step, driven by ../shared/peers' `vega_bench`
(build it with ../shared/peers/build-vega.sh; a tool, never a dependency of the project), and
`tissue-bench` (build/release/fmu_src/apps/): the same mesh, fixed vertices (Vega's .bou, or the
vertices within 1% of the x extent of the minimum x), material, gravity (0, -9.81, 0), no damping,
time step and PCG setting (Jacobi-preconditioned, relative residual eps, at most K iterations).
One thread each (OMP/OpenBLAS limited to 1, both pinned to the same core when taskset exists).
Each round runs Vega and ours twice (the same linearized step as Vega's, and our defaults with the
large-turn protections), each first in turn; a run's figure is its median ms per step; the table
gives the median over rounds and the ratios Vega / ours. Prints a Markdown table with the machine.

Usage: tests/bench/side_by_side_vega.py [--vega PATH] [--bench PATH] [--rounds 5] [--steps 200]
Uses only the Python standard library.
"""
import argparse
import os
import pathlib
import platform
import re
import shutil
import statistics
import subprocess
import sys

from run_tissue_bench import BRIDGE, DISSERTATION, ROOT, VEGA as VEGA_MESHES, run as run_tissue_bench

PEERS = pathlib.Path(os.environ.get("PEERS", ROOT.parent / "peers"))

# name, mesh, fixed .bou (None: minimum x), dt [s], material (issue 12's table)
CASES = [
    ("simpleBridge (Vega), 12.8k tets", VEGA_MESHES / "simpleBridge" / "simpleBridge-ic_128_0.15_.1.veg",
     VEGA_MESHES / "simpleBridge" / "simpleBridge.bou", 0.07, BRIDGE),
    ("frog (ours), 2450 tets", ROOT / "meshes" / "frog.veg", None, 0.01, DISSERTATION),
]
SETTING = (1e-3, 10)  # the real-time setting: eps, iteration cap


def environment():
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_THREAD_LIMIT="1")
    return env


def pinned(command):
    return (["taskset", "-c", "0"] if shutil.which("taskset") else []) + command


def run_vega(vega, case, steps):
    name, mesh, bou, dt, material = case
    eps, cap = SETTING
    command = [str(vega), "--mesh", str(mesh), "--E", str(material["young"]), "--nu", str(material["poisson"]),
               "--rho", str(material["density"]), "--dt", str(dt), "--steps", str(steps), "--cg-eps", str(eps),
               "--cg-max", str(cap), "--alpha", "0", "--beta", "0"]
    if bou is not None:
        command += ["--fix-bou", str(bou)]
    out = subprocess.run(pinned(command), check=True, capture_output=True, text=True, env=environment()).stdout
    match = re.search(r"step_med=([0-9.eE+-]+)", out)
    if not match:
        sys.exit("vega_bench printed no step_med: " + out)
    return float(match.group(1))


def run_ours(bench, case, steps, protection):
    name, mesh, bou, dt, material = case
    eps, cap = SETTING
    extra = ["--mass-damping", "0", "--stiffness-damping", "0"] + ([] if protection else ["--no-large-turn-protection"])
    result = run_tissue_bench(bench, mesh, bou, dt, material, eps, cap, steps, extra=extra, prefix=pinned([]),
                              env=environment())
    return result["ms_per_step"]["median"], result


def cpu_model():
    try:
        for line in subprocess.run(["lscpu"], capture_output=True, text=True).stdout.splitlines():
            if line.startswith("Model name:"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--vega", default=str(PEERS / "vega" / "bench" / "build" / "vega_bench"))
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "fmu_src" / "apps" / "tissue-bench"))
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--steps", type=int, default=200)
    args = parser.parse_args()
    for path in (args.vega, args.bench):
        if not pathlib.Path(path).exists():
            sys.exit("missing " + path + " (Vega: ../shared/peers/build-vega.sh; ours: cmake --build --preset release)")

    rows = []
    for case in CASES:
        times = {"vega": [], "same": [], "defaults": []}
        details = {}
        for k in range(args.rounds):
            order = ["vega", "same", "defaults"]
            order = order[k % 3:] + order[:k % 3]  # each goes first in turn
            for who in order:
                if who == "vega":
                    times["vega"].append(run_vega(args.vega, case, args.steps))
                else:
                    ms, details[who] = run_ours(args.bench, case, args.steps, protection=(who == "defaults"))
                    times[who].append(ms)
            print("  %s: round %d/%d: Vega %.3f ms, ours %.3f ms (same step), %.3f ms (defaults)"
                  % (case[0], k + 1, args.rounds, times["vega"][-1], times["same"][-1], times["defaults"][-1]),
                  file=sys.stderr)
        rows.append((case, {who: statistics.median(t) for who, t in times.items()},
                     {who: (min(t), max(t)) for who, t in times.items()}, details))

    print("Machine: %d cores (`nproc`), %s; one thread each; %d rounds of %d steps, each program first in "
          "turn; PCG eps %g, at most %d iterations; no damping; medians over rounds of each run's median step. "
          "\"Same step\": ours without the large-turn protections (`--no-large-turn-protection`), the "
          "linearized step Vega takes; \"defaults\": with them (Newton corrections and energy guard, which "
          "act on steps that turn elements far).\n"
          % (os.cpu_count(), cpu_model(), args.rounds, args.steps, SETTING[0], SETTING[1]))
    print("| mesh | dt | Vega (ms/step) | ours, same step (ms/step) | Vega / ours | ours, defaults (ms/step) | "
          "Vega / ours | defaults: Newton iterations, guarded steps | same step: assembly / solve (ms) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for case, median, span, details in rows:
        same, defaults = details["same"], details["defaults"]
        print("| %s | %g s | %.3f (%.3f-%.3f) | %.3f (%.3f-%.3f) | %.2f | %.3f (%.3f-%.3f) | %.2f | %d, %d | %.3f / %.3f |"
              % (case[0], case[3], median["vega"], *span["vega"], median["same"], *span["same"],
                 median["vega"] / median["same"], median["defaults"], *span["defaults"],
                 median["vega"] / median["defaults"], defaults["newton_iterations"],
                 defaults["energy_guarded_steps"], same["assembly_ms"], same["solve_ms"]))


if __name__ == "__main__":
    main()
