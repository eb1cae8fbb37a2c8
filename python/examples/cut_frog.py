#!/usr/bin/env python3
"""Press the frog's back with the probe, cut across the body next to the pressed point, press
again, and plot the force against depth before and after the cut (the cut softens the back).

Usage: python3 python/examples/cut_frog.py [--output cut_frog_force.png]
(after ./scripts/setup and the build: `import tissue` finds build/release/python).
"""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import tissue  # noqa: E402


def press(frog, point, top_z, depth_m, steps=30):
    """Lower the probe from 2 mm above the surface to depth_m below it: (depths, forces along z)."""
    depths, forces = [], []
    for n in range(steps + 1):
        depth = -0.002 + (depth_m + 0.002) * n / steps
        frog.set_tool((point[0], point[1], top_z - depth), mode="probe")
        frog.step(2)
        depths.append(depth)
        forces.append(frog.contact["force_on_tool_n"][2] if frog.contact["active"] else 0.0)
    frog.set_tool((point[0], point[1], top_z + 0.02), mode="none")  # lift off and let it settle
    frog.step(50)
    return np.array(depths), np.array(forces)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--output", default="cut_frog_force.png")
    args = parser.parse_args()

    frog = tissue.Tissue(mesh="frog", step_size_s=0.01, damping_alpha_per_s=5.0, blade_length_m=0.1,
                         gravity_m_per_s2=(0.0, 0.0, -9.81), fixed_axis=2, fixed_fraction=0.25)
    frog.step(50)  # settle under gravity, held by its belly
    rest = frog.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    centre = 0.5 * (lower + upper)
    point = (centre[0] + 0.006, centre[1])
    near = np.argmin(np.hypot(rest[:, 0] - point[0], rest[:, 1] - point[1]) - 1e-3 * rest[:, 2])
    top_z = frog.positions_m[near, 2]

    before = press(frog, point, top_z, 0.003)
    for n in range(41):  # a vertical blade drawn across the body, 6 mm from the pressed point
        y = lower[1] - 0.01 + n / 40 * (upper[1] - lower[1] + 0.02)
        frog.set_tool((centre[0], y, lower[2] - 0.01), mode="scalpel")
        frog.step()
    frog.set_tool((centre[0], upper[1] + 0.05, upper[2] + 0.05), mode="none")
    frog.step(50)
    print(f"cut {frog.cut_tets} tets, {frog.enriched_vertices} enriched vertices")
    after = press(frog, point, top_z, 0.003)

    plt.figure(figsize=(6, 4))
    plt.plot(1e3 * before[0], before[1], "o-", label="before the cut")
    plt.plot(1e3 * after[0], after[1], "s-", label=f"after the cut ({frog.cut_tets} tets cut)")
    plt.xlabel("probe depth below the settled surface (mm)")
    plt.ylabel("force on the probe along z (N)")
    plt.title("Pressing the frog's back next to a cut")
    plt.grid(alpha=0.3)
    plt.legend()
    plt.tight_layout()
    plt.savefig(args.output, dpi=120)
    print(f"force at 3 mm: {before[1][-1]:.3f} N before, {after[1][-1]:.3f} N after; plot in {args.output}")


if __name__ == "__main__":
    main()
