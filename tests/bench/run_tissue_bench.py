#!/usr/bin/env python3
"""Runs tissue-bench over the project's meshes and the Vega reference meshes at the dissertation's
two settings (strict: eps 1e-6, <= 10000 PCG iterations; real-time: eps 1e-3, 10 iterations) and
prints a Markdown table of the medians, for docs/BENCHMARKS.md.

Usage: tests/bench/run_tissue_bench.py [--bench build/release/apps/tissue-bench] [--quick]
Uses only the Python standard library.
"""
import argparse
import json
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
VEGA = ROOT.parent / "shared" / "meshes" / "vega"
DISSERTATION = dict(young=1e5, poisson=0.4, density=1000.0)
BRIDGE = dict(young=1e5, poisson=0.33, density=100.0)

# name, mesh, fixed .bou (None = minimum x), step [s] (the dissertation's where it gives one), material
CASES = [
    ("frog (ours)", ROOT / "meshes" / "frog.veg", None, 0.1, DISSERTATION),
    ("bar_40x8x8 (ours)", ROOT / "meshes" / "bar_40x8x8.veg", None, 0.04, BRIDGE),
    ("turtle (Vega)", VEGA / "turtle" / "turtle-volumetric-homogeneous.veg", VEGA / "turtle" / "turtle-volumetric.bou",
     0.01, DISSERTATION),
    ("comb (Vega)", VEGA / "comb" / "comb.tet.veg", None, 0.04, DISSERTATION),
    ("simpleBridge (Vega)", VEGA / "simpleBridge" / "simpleBridge-ic_128_0.15_.1.veg",
     VEGA / "simpleBridge" / "simpleBridge.bou", 0.07, BRIDGE),
]
SETTINGS = [("real-time", 1e-3, 10), ("strict", 1e-6, 10000)]


def run(bench, mesh, bou, dt, material, tolerance, iterations, steps, solver="pcg", extra=(), prefix=(), env=None):
    """One tissue-bench run; its JSON. `extra`: more options; `prefix`: e.g. a taskset command."""
    command = list(prefix) + [str(bench), "--mesh", str(mesh), "--steps", str(steps), "--dt", str(dt), "--solver", solver,
               "--tolerance", str(tolerance), "--max-iterations", str(iterations),
               "--young", str(material["young"]), "--poisson", str(material["poisson"]),
               "--density", str(material["density"])]
    if bou is not None:
        command += ["--fixed", str(bou)]
    command += list(extra)
    output = subprocess.run(command, check=True, capture_output=True, text=True, env=env).stdout
    return json.loads(output)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "apps" / "tissue-bench"))
    parser.add_argument("--quick", action="store_true", help="fewer steps (a smoke run, not for the docs)")
    args = parser.parse_args()
    print("| mesh | vertices | tets | dofs | nonzeros | dt [s] | setting | ms/step median | p90 | max "
          "| assembly ms | solve ms | CG iterations mean (max) | final KE [J] |")
    print("|---|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, mesh, bou, dt, material in CASES:
        runs = [(label, tol, its) for label, tol, its in SETTINGS] + [("cholmod", 0.0, 0)]
        for label, tolerance, iterations in runs:
            steps = (20 if args.quick else 400) if label == "real-time" else (5 if args.quick else 50)
            if label == "cholmod":
                r = run(args.bench, mesh, bou, dt, material, 1e-6, 1, steps, solver="cholmod")
            else:
                r = run(args.bench, mesh, bou, dt, material, tolerance, iterations, steps)
            s = r["ms_per_step"]
            print(f"| {name} | {r['vertices']} | {r['tets']} | {r['dofs']} | {r['nonzeros']} | {dt:g} | {label} "
                  f"| {s['median']:.3f} | {s['p90']:.3f} | {s['max']:.3f} | {r['assembly_ms']:.3f} "
                  f"| {r['solve_ms']:.3f} | {r['cg_iterations']['mean']:.1f} ({r['cg_iterations']['max']}) "
                  f"| {r['final_kinetic_energy_J']:.3g} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
