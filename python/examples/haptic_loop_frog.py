"""A simulated hand presses a probe on the frog's back through the haptic loop, as a device driver or
a controller author would close it: the tissue (tissue.Tissue, the default frog) steps in slots of
10 ms, and at each slot its sample goes to a tissue.HapticLoop ticked at 1 kHz, whose force acts on
the hand. The hand is a 0.2 kg mass with a 3 N s/m damper, pushed down by 1 N, which its grip keeps
on a vertical line (it moves along z only; the forces across are the grip's). It settles where the
tissue pushes back with 1 N; the script prints that force next to the tissue's quasi-static force at
the point the probe holds (Tissue.quasi_static_poke), and plots the force on the hand and the probe's
depth against time.

    python3 python/examples/haptic_loop_frog.py --output haptic_loop_frog.png
"""
import argparse

import numpy as np

import tissue

HAND_MASS_KG = 0.2
HAND_DAMPING_N_S_PER_M = 3.0
PUSH_N = 1.0
TICK_S = 0.001  # the HapticLoop's step_size_s default: 1 kHz
TISSUE_STEP_S = 0.001  # the Tissue's step_size_s default
TICKS_PER_SLOT = 10  # the tissue's slot: 10 ms, 100 Hz
START_ABOVE_M = 0.001  # the probe starts 1 mm above the back


def press(duration_s=1.2):
    """Runs the closed loop for duration_s. Returns (frog, loop, surface_z_m, record): record holds
    per tick time_s, force_n (n x 3, the loop's force on the hand), position_m and velocity_m_per_s
    (n x 3, the hand's after the tick)."""
    frog = tissue.Tissue(mesh="frog", step_size_s=TISSUE_STEP_S)
    loop = tissue.HapticLoop(step_size_s=TICK_S)
    rest = frog.rest_positions_m
    centre = 0.5 * (rest.min(axis=0) + rest.max(axis=0))
    below = np.linalg.norm(rest[:, :2] - centre[:2], axis=1) < 0.005
    surface_z_m = rest[below, 2].max()  # the back, within 5 mm of the vertical through the centre
    x = np.array([centre[0], centre[1], surface_z_m + START_ABOVE_M])
    v = np.zeros(3)
    push = np.array([0.0, 0.0, -PUSH_N])
    ticks = round(duration_s / TICK_S)
    record = {name: np.zeros((ticks, 3)) for name in ("force_n", "position_m", "velocity_m_per_s")}
    record["time_s"] = np.arange(1, ticks + 1) * TICK_S
    for k in range(ticks):
        force = loop.tick(x, TICK_S, mode="probe")
        if k % TICKS_PER_SLOT == 0:
            # The sample the tissue computed over the last slot arrives; the tissue starts the next
            # slot with the tool where the hand is now.
            loop.set_sample(frog)
            frog.set_tool(loop.tool_position_m, mode="probe")
            frog.step(round(TICKS_PER_SLOT * TICK_S / TISSUE_STEP_S))
        acceleration = (push + force - HAND_DAMPING_N_S_PER_M * v) / HAND_MASS_KG
        acceleration[:2] = 0.0  # the grip holds x and y
        v = v + TICK_S * acceleration  # semi-implicit Euler
        x = x + TICK_S * v
        record["force_n"][k], record["position_m"][k], record["velocity_m_per_s"][k] = force, x, v
    return frog, loop, surface_z_m, record


def plot(record, surface_z_m, quasi_static_n, output):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    t = record["time_s"]
    fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(7, 5.5))
    top.plot(t, record["force_n"][:, 2], color="tab:blue", label="haptic loop's force on the hand (z)")
    top.axhline(PUSH_N, color="0.6", linewidth=4, alpha=0.5, label=f"the hand's push, {PUSH_N:g} N")
    top.axhline(quasi_static_n, color="tab:red", linestyle="--", linewidth=1,
                label=f"quasi-static force at the held point (z), {quasi_static_n:.3f} N")
    top.set_ylabel("force [N]")
    top.legend(loc="lower right", fontsize=8)
    top.set_title(f"A {HAND_MASS_KG:g} kg hand ({HAND_DAMPING_N_S_PER_M:g} N s/m) presses the frog: "
                  "tissue at 100 Hz, haptic loop at 1 kHz", fontsize=9)
    depth_mm = 1e3 * (surface_z_m - record["position_m"][:, 2])
    bottom.plot(t, depth_mm, color="tab:green")
    bottom.axhline(0.0, color="0.4", linestyle=":", linewidth=1)
    bottom.set_ylabel("probe depth below the\nback at rest [mm]")
    bottom.set_xlabel("time [s]")
    for axis in (top, bottom):
        axis.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(output, dpi=120)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", default="haptic_loop_frog.png", help="the plot (PNG)")
    parser.add_argument("--duration", type=float, default=1.2, help="simulated time [s]")
    args = parser.parse_args()
    frog, loop, surface_z_m, record = press(args.duration)
    poke = frog.quasi_static_poke(frog.tool_contact["point_m"])
    normal = poke["normal"]
    quasi_static_n = poke["force_on_tool_n"][2]
    settled = record["force_n"][-1]
    plot(record, surface_z_m, quasi_static_n, args.output)
    print(f"settled: force on the hand {settled[2]:.4f} N along z (push {PUSH_N:g} N), "
          f"{settled @ normal:.4f} N along the normal against the quasi-static "
          f"{poke['force_on_tool_n'] @ normal:.4f} N; depth "
          f"{1e3 * (surface_z_m - record['position_m'][-1, 2]):.2f} mm, speed "
          f"{abs(record['velocity_m_per_s'][-1, 2]):.1e} m/s; passivity observer {loop.observed_energy_j:.2e} J; "
          f"plot in {args.output}")


if __name__ == "__main__":
    main()
