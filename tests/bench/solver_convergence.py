#!/usr/bin/env python3
"""The relative residual per CG iteration of a step's solve on the organ (and the frog), Jacobi
against the lagged Cholesky factor and the two-level preconditioner (the default since issue 40): runs build/release/apps/tissue-convergence and plots
docs/solver_convergence.png (residual per iteration and per millisecond). Needs Debian's
python3-matplotlib. Usage: tests/bench/solver_convergence.py [--lag-steps N] [--out PNG]."""
import argparse
import csv
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "build", "release", "apps", "tissue-convergence")
MESHES = {
    "organ (meshes/liver.veg, 51.9k tets)": ["--mesh", os.path.join(ROOT, "meshes", "liver.veg"),
                                            "--fixed", os.path.join(ROOT, "meshes", "liver.bou")],
    "frog (2450 tets, tail-held 30%)": ["--mesh", "frog", "--fixed-fraction", "0.3"],
}


def measure(args, lag_steps, folder, index):
    out = os.path.join(folder, "run%d.csv" % index)
    command = [TOOL, *args, "--lag-steps", str(lag_steps), "--single-material", "-o", out]
    print(" ".join(command), flush=True)
    subprocess.run(command, check=True)
    runs = {}
    with open(out) as f:
        for row in csv.DictReader(f):
            run = runs.setdefault(row["preconditioner"], {"k": [], "r": [], "ms": float(row["ms_per_iteration"]),
                                                          "setup": float(row["setup_ms"])})
            run["k"].append(int(row["iteration"]))
            run["r"].append(float(row["relative_residual"]))
    return runs


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--lag-steps", type=int, default=10)
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "solver_convergence.png"))
    options = parser.parse_args()
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with tempfile.TemporaryDirectory() as folder:
        results = {name: measure(args, options.lag_steps, folder, i) for i, (name, args) in enumerate(MESHES.items())}
    figure, axes = plt.subplots(len(results), 2, figsize=(12, 4.2 * len(results)), squeeze=False)
    for row, (mesh, runs) in enumerate(results.items()):
        for name, run in runs.items():
            axes[row][0].semilogy(run["k"], run["r"], label=name)
            axes[row][1].semilogy([k * run["ms"] for k in run["k"]], run["r"],
                                  label="%s (%.3f ms/iteration; setup %.0f ms)" % (name, run["ms"], run["setup"]))
            print("%s | %s | iterations to 1e-3: %s, to 1e-6: %s | %.3f ms per iteration" % (
                mesh, name, first_below(run, 1e-3), first_below(run, 1e-6), run["ms"]))
        for ax in axes[row]:
            ax.axhline(1e-3, color="grey", lw=0.8, ls="--")
            ax.axhline(1e-6, color="grey", lw=0.8, ls=":")
            ax.grid(True, which="both", alpha=0.3)
            ax.set_ylabel("relative residual |r| / |b|")
            ax.set_title(mesh)
        axes[row][0].axvline(10, color="red", lw=0.8, ls="--")
        axes[row][0].text(11, 0.5, "real-time cap: 10 iterations", color="red", fontsize=8)
        axes[row][0].set_xlabel("CG iteration")
        axes[row][0].set_xscale("symlog", linthresh=10)
        axes[row][1].set_xlabel("solve time [ms] (one core, setup not counted)")
        axes[row][1].set_xscale("symlog", linthresh=1)
        for ax in axes[row]:
            ax.set_xlim(left=0)
        axes[row][1].legend(fontsize=8)
    figure.suptitle("A backward-Euler step's solve (10 ms step, %d steps of fall from rest): "
                    "Jacobi, the lagged Cholesky factor, the two-level preconditioner" % options.lag_steps)
    figure.tight_layout()
    figure.savefig(options.out, dpi=90)
    print("wrote", options.out)


def first_below(run, level):
    for k, r in zip(run["k"], run["r"]):
        if r <= level:
            return k
    return "not in %d" % run["k"][-1]


if __name__ == "__main__":
    sys.exit(main())
