#!/usr/bin/env python3
"""Our step against Vega FEM's on the same meshes and settings, in one run, alternating (issue 12).

Vega FEM 4.0's own semi-implicit backward-Euler step, driven by ../shared/peers' `vega_bench`
(build it with ../shared/peers/build-vega.sh; a tool, never a dependency of the project), and
`tissue-bench` (build/release/apps/): the same mesh, fixed vertices (Vega's .bou, or the
vertices within 1% of the x extent of the minimum x), material, gravity (0, -9.81, 0), no damping,
time step and PCG setting (Jacobi-preconditioned, relative residual eps, at most K iterations).
One thread each (OMP/OpenBLAS limited to 1, both pinned to the same core when taskset exists).
Each round runs Vega and ours twice (the same linearized step as Vega's, and our defaults with the
large-turn protections), each first in turn; a run's figure is its median ms per step; the table
gives the median over rounds and the ratios Vega / ours. Prints a Markdown table with the machine.

Usage: tests/bench/side_by_side_vega.py [--vega PATH] [--bench PATH] [--rounds 5] [--steps 200] [--only TEXT]
                                       [--scaling [--plot PNG]] [--converged]
--converged (issue 40): converged steps instead, one thread, no protections, no damping: Vega's strict
PCG (eps 1e-6) against ours converged to a relative residual of 1e-6 five ways: Jacobi PCG, PCG
preconditioned by the lagged Cholesky factor (warm-started), the two-level preconditioner (the
real-time default's solver) from zero and warm-started (the Galerkin projection onto the last eight
steps' velocity changes), CHOLMOD.
Ours is also run with two threads (defaults), unpinned. --scaling adds the organ at two sizes between the
bridge and it (meshes/make_liver.py and Gmsh) and prints ms per step against tet count with the fitted
exponent (and a log-log plot with matplotlib). Uses only the Python standard library otherwise.
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
    ("organ (meshes/liver.veg), 51.9k tets", ROOT / "meshes" / "liver.veg", ROOT / "meshes" / "liver.bou", 0.01,
     DISSERTATION),
]
# --scaling: the organ's shape meshed at these largest edges [m] as well (meshes/make_liver.py, Gmsh),
# sizes between the bridge and the organ.
SCALING_SIZES_M = (0.0072, 0.0058)
SETTING = (1e-3, 10)  # the real-time setting: eps, iteration cap


def environment():
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", OMP_THREAD_LIMIT="1")
    return env


def pinned(command):
    return (["taskset", "-c", "0"] if shutil.which("taskset") else []) + command


def run_vega(vega, case, steps, setting=SETTING):
    name, mesh, bou, dt, material = case
    eps, cap = setting
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


def run_ours(bench, case, steps, protection, threads=1):
    name, mesh, bou, dt, material = case
    eps, cap = SETTING
    extra = ["--mass-damping", "0", "--stiffness-damping", "0", "--threads", str(threads)]
    extra += [] if protection else ["--no-large-turn-protection"]
    pin = pinned([]) if threads == 1 else []
    result = run_tissue_bench(bench, mesh, bou, dt, material, eps, cap, steps, extra=extra, prefix=pin,
                              env=environment())
    return result["ms_per_step"]["median"], result


# --converged: ours four ways, each to a relative residual of 1e-6: name, solver, more tissue-bench
# options (the lagged factor is refactorized in the stepping thread: one core each).
CONVERGED = (("pcg", "pcg", []),
             ("pcgCholesky (warm)", "pcgCholesky", ["--warm-start", "--no-background-refactor"]),
             ("pcgTwoLevel", "pcgTwoLevel", []),
             ("pcgTwoLevel (warm)", "pcgTwoLevel", ["--warm-start"]),
             ("cholmod", "cholmod", []))
ITERATIVE = [name for name, solver, _ in CONVERGED if solver != "cholmod"]
STRICT = (1e-6, 10000)


def run_converged(bench, case, steps, solver, options):
    name, mesh, bou, dt, material = case
    extra = ["--mass-damping", "0", "--stiffness-damping", "0", "--no-large-turn-protection"] + options
    result = run_tissue_bench(bench, mesh, bou, dt, material, STRICT[0], STRICT[1], steps, solver=solver,
                              extra=extra, prefix=pinned([]), env=environment())
    return result["ms_per_step"]["median"], result


def converged_table(args, cases):
    rows = []
    for case in cases:
        times = {who: [] for who in ["vega"] + [name for name, _, _ in CONVERGED]}
        details = {}
        for k in range(args.rounds):
            order = list(times)
            order = order[k % len(order):] + order[:k % len(order)]
            for who in order:
                if who == "vega":
                    times[who].append(run_vega(args.vega, case, args.steps, STRICT))
                else:
                    _, solver, options = next(c for c in CONVERGED if c[0] == who)
                    ms, details[who] = run_converged(args.bench, case, args.steps, solver, options)
                    times[who].append(ms)
            print("  %s: round %d/%d: %s" % (case[0], k + 1, args.rounds,
                                             ", ".join("%s %.3f ms" % (w, t[-1]) for w, t in times.items())),
                  file=sys.stderr)
        rows.append((case, {who: statistics.median(t) for who, t in times.items()}, details))
    print("Machine: %d cores (`nproc`), %s; one thread each (pinned); %d rounds of %d steps, each first in turn; "
          "converged steps: Vega's PCG to eps %g, ours to a relative residual of %g; no damping, no protections; "
          "medians over rounds of each run's median step.\n" % (os.cpu_count(), cpu_model(), args.rounds, args.steps,
                                                                 STRICT[0], STRICT[0]))
    names = [name for name, _, _ in CONVERGED]
    print("| mesh | dt | Vega, strict PCG (ms/step) | %s | Vega / best of ours | best of ours | "
          "CHOLMOD / best iterative | CG iterations mean / max: %s |"
          % (" | ".join("ours, " + name for name in names), ", ".join(ITERATIVE[1:])))
    print("|---|---|---:|%s---:|---|---:|---|" % ("---:|" * len(names)))
    for case, median, details in rows:
        best = min(names, key=lambda name: median[name])
        best_iterative = min(median[name] for name in ITERATIVE)
        iterations = ", ".join("%.1f / %d" % (details[name]["cg_iterations"]["mean"], details[name]["cg_iterations"]["max"])
                               for name in ITERATIVE[1:])
        print("| %s | %g s | %.2f | %s | %.1f | %s | %.2f | %s |"
              % (case[0], case[3], median["vega"], " | ".join("%.2f" % median[name] for name in names),
                 median["vega"] / median[best], best, median["cholmod"] / best_iterative, iterations))


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
    parser.add_argument("--bench", default=str(ROOT / "build" / "release" / "apps" / "tissue-bench"))
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--only", default="", help="run only the cases whose name contains this")
    parser.add_argument("--scaling", action="store_true",
                        help="also the organ at two sizes between the bridge and it (needs gmsh); print the "
                             "scaling table and the fitted exponents")
    parser.add_argument("--plot", default="", help="with --scaling: write the log-log plot here (needs matplotlib)")
    parser.add_argument("--converged", action="store_true",
                        help="converged steps (issue 40): Vega strict PCG against ours four ways, to 1e-6")
    args = parser.parse_args()
    for path in (args.vega, args.bench):
        if not pathlib.Path(path).exists():
            sys.exit("missing " + path + " (Vega: ../shared/peers/build-vega.sh; ours: cmake --build --preset release)")

    cases = [case for case in CASES if args.only in case[0]]
    if args.converged:
        converged_table(args, cases)
        return
    if args.scaling:
        cases += scaling_cases()
    two_threads = (os.cpu_count() or 1) >= 2
    rows = []
    for case in cases:
        times = {"vega": [], "same": [], "defaults": [], "defaults2": []}
        details = {}
        for k in range(args.rounds):
            order = ["vega", "same", "defaults"] + (["defaults2"] if two_threads else [])
            order = order[k % len(order):] + order[:k % len(order)]  # each goes first in turn
            for who in order:
                if who == "vega":
                    times["vega"].append(run_vega(args.vega, case, args.steps))
                else:
                    ms, details[who] = run_ours(args.bench, case, args.steps, protection=(who != "same"),
                                                threads=2 if who == "defaults2" else 1)
                    times[who].append(ms)
            print("  %s: round %d/%d: Vega %.3f ms, ours %.3f ms (same step), %.3f ms (defaults), %s (2 threads)"
                  % (case[0], k + 1, args.rounds, times["vega"][-1], times["same"][-1], times["defaults"][-1],
                     "%.3f ms" % times["defaults2"][-1] if two_threads else "-"),
                  file=sys.stderr)
        if not two_threads:
            times["defaults2"] = [float("nan")]
        rows.append((case, {who: statistics.median(t) for who, t in times.items()},
                     {who: (min(t), max(t)) for who, t in times.items()}, details))

    print("Machine: %d cores (`nproc`), %s; one thread each; %d rounds of %d steps, each program first in "
          "turn; PCG eps %g, at most %d iterations; no damping; medians over rounds of each run's median step. "
          "\"Same step\": ours without the large-turn protections (`--no-large-turn-protection`), the "
          "linearized step Vega takes; \"defaults\": with them (Newton corrections and energy guard, which "
          "act on steps that turn elements far).\n"
          % (os.cpu_count(), cpu_model(), args.rounds, args.steps, SETTING[0], SETTING[1]))
    print("| mesh | dt | Vega (ms/step) | ours, same step (ms/step) | Vega / ours | ours, defaults (ms/step) | "
          "Vega / ours | defaults / same step | defaults, 2 threads (ms/step) | defaults: Newton iterations, "
          "guarded steps | same step: assembly / solve (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for case, median, span, details in rows:
        same, defaults = details["same"], details["defaults"]
        print("| %s | %g s | %.3f (%.3f-%.3f) | %.3f (%.3f-%.3f) | %.2f | %.3f (%.3f-%.3f) | %.2f | %.2f | %.3f (%.3f-%.3f) "
              "| %d, %d | %.3f / %.3f |"
              % (case[0], case[3], median["vega"], *span["vega"], median["same"], *span["same"],
                 median["vega"] / median["same"], median["defaults"], *span["defaults"],
                 median["vega"] / median["defaults"], median["defaults"] / median["same"], median["defaults2"],
                 *span["defaults2"], defaults["newton_iterations"],
                 defaults["energy_guarded_steps"], same["assembly_ms"], same["solve_ms"]))
    if args.scaling:
        print_scaling(rows, args.plot)


def scaling_cases():
    """The organ's shape at SCALING_SIZES_M, made into a temporary folder by meshes/make_liver.py."""
    import tempfile
    folder = pathlib.Path(tempfile.mkdtemp(prefix="tissue-scaling-"))
    cases = []
    for size in SCALING_SIZES_M:
        out = folder / ("%g" % size)
        out.mkdir()
        subprocess.run(["/usr/bin/python3", str(ROOT / "meshes" / "make_liver.py"), "--mesh-size", str(size),
                        "--output-dir", str(out)], check=True, capture_output=True, text=True)
        tets = int(re.search(r"# (\d+) vertices, (\d+) elements", (out / "liver.veg").read_text()).group(2))
        cases.append(("organ at %g m, %.1fk tets" % (size, tets / 1000), out / "liver.veg", out / "liver.bou", 0.01,
                      DISSERTATION))
    return cases


def print_scaling(rows, plot):
    """ms per step against tet count, the least-squares exponent of ms ~ tets^k, and a log-log plot."""
    import math
    points = sorted((details["same"]["tets"], median) for case, median, span, details in rows)
    print("\n| tets | Vega (ms/step) | ours, same step | ours, defaults | ours, defaults, 2 threads |")
    print("|---:|---:|---:|---:|---:|")
    for tets, median in points:
        print("| %d | %.3f | %.3f | %.3f | %.3f |" % (tets, median["vega"], median["same"], median["defaults"],
                                                    median["defaults2"]))
    fits = {}
    for who in ("vega", "same", "defaults", "defaults2"):
        xs = [math.log(tets) for tets, median in points if math.isfinite(median[who])]
        ys = [math.log(median[who]) for tets, median in points if math.isfinite(median[who])]
        if len(xs) < 2:
            continue
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        fits[who] = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
    print("\nFitted exponent k of ms/step ~ tets^k (least squares in log-log): " +
          ", ".join("%s %.3f" % (who, k) for who, k in fits.items()))
    if plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        labels = {"vega": "Vega FEM 4.0 (1 thread)", "same": "ours, same step (1 thread)",
                  "defaults": "ours, defaults (1 thread)", "defaults2": "ours, defaults (2 threads)"}
        fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=120)
        for who, marker in (("vega", "s"), ("same", "o"), ("defaults", "^"), ("defaults2", "v")):
            if who not in fits:
                continue
            ax.loglog([t for t, m in points], [m[who] for t, m in points], marker=marker,
                      label="%s, k = %.2f" % (labels[who], fits[who]))
        ax.axhline(10.0, color="grey", linestyle=":", linewidth=1)
        ax.text(points[0][0], 10.5, "10 ms: a 100 Hz step", color="grey", fontsize=8)
        ax.set_xlabel("tets")
        ax.set_ylabel("ms per step (median)")
        ax.set_title("Step time against mesh size (real-time setting: PCG 1e-3 / 10)", fontsize=10)
        ax.grid(True, which="both", linewidth=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(plot)
        print("plot: " + plot)


if __name__ == "__main__":
    main()
