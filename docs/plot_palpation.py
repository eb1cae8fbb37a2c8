#!/usr/bin/python3
"""The palpation figure (docs/palpation_force.png) from palpate_liver logs:
    tissue-host run host/scenarios/palpate_liver.toml --offline -o OUT
    /usr/bin/python3 docs/plot_palpation.py docs/palpation_force.png OUT/log.csv[=LABEL] [OTHER/log.csv[=LABEL] ...]
The first log is the scenario's own; further ones (the same sweep by other hands) are drawn beside it,
each labelled by its LABEL (or its folder's name). Top: the vertical force; bottom: the force along the sweep and what the surface's
slope explains, -s f_z (s = dz/dx of the scripted path, which follows the rest surface 2 mm deep).
Prints per log, over the sweep past its first 5 mm: |f_x + s f_z| / |f| (median, p95, max), the
vertical force's range and how many times the contact was lost.
"""
import csv, pathlib, sys, tomllib
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt

SCENARIO = pathlib.Path(__file__).resolve().parent.parent / "host/scenarios/palpate_liver.toml"
SWEEP_S = (5.3, 9.3)  # the scenario's sweep; before it, two presses held 0.8 s (until 1.4 s and 3.6 s)
DWELL_ENDS_S = (1.4, 3.6)
waypoints = [w for w in tomllib.loads(SCENARIO.read_text())["device"]["waypoints"]
             if SWEEP_S[0] <= w["t"] <= SWEEP_S[1]]


def path_slope(x_m):
    """dz/dx of the scripted sweep at x (piecewise linear between waypoints)."""
    for a, b in zip(waypoints, waypoints[1:]):
        lo, hi = sorted((a["position"][0], b["position"][0]))
        if lo <= x_m <= hi:
            return (b["position"][2] - a["position"][2]) / (b["position"][0] - a["position"][0])
    return 0.0


def summary(rows):
    """The sweep's figures past its first 5 mm (the hand catching up with its path)."""
    sweep = [r for r in rows if SWEEP_S[0] <= float(r["time_s"]) <= SWEEP_S[1] and float(r["tool_x_m"]) > -0.070]
    errors = []
    for r in sweep:
        fx, fz = float(r["force_x_n"]), float(r["force_z_n"])
        if fx or fz:
            errors.append(abs(fx + path_slope(float(r["tool_x_m"])) * fz) / (fx * fx + fz * fz) ** 0.5)
    errors.sort()
    lost = sum(1 for a, b in zip(sweep, sweep[1:]) if a["contact"] == "1" and b["contact"] == "0")
    fz = [float(r["force_z_n"]) for r in sweep]
    return (f"along the sweep vs the slope: median {100 * errors[len(errors) // 2]:.1f} %, "
            f"p95 {100 * errors[int(0.95 * len(errors))]:.1f} %, max {100 * errors[-1]:.1f} %; "
            f"vertical force {min(fz):.2f}..{max(fz):.2f} N; contact lost {lost} times")


def read(path):
    rows = list(csv.DictReader(open(path)))
    print(f"{path}: {summary(rows)}")
    sweep = {"x": [], "fz": [], "fx": [], "explained": []}
    dwell = {end: [] for end in DWELL_ENDS_S}
    for r in rows:
        t = float(r["time_s"])
        x = float(r["tool_x_m"])
        if SWEEP_S[0] <= t <= SWEEP_S[1]:
            fz = float(r["force_z_n"])
            sweep["x"].append(1e3 * x); sweep["fz"].append(fz); sweep["fx"].append(float(r["force_x_n"]))
            sweep["explained"].append(-path_slope(x) * fz)
        for end in DWELL_ENDS_S:
            if end - 0.4 <= t < end:
                dwell[end].append((1e3 * x, float(r["force_z_n"])))
    return sweep, dwell


out = sys.argv[1]
logs = sys.argv[2:]
fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5.6), dpi=110, sharex=True)
for ax in (top, bottom):
    ax.axvspan(-45 - 8, -45 + 8, color="0.9", label="inclusion (E 1 MPa, 4 mm under)" if ax is top else None)
styles = ["-", "--", ":"]
for k, log in enumerate(logs):
    log, _, label = log.partition("=")
    sweep, dwell = read(log)
    label = label or pathlib.Path(log).parent.name
    top.plot(sweep["x"], sweep["fz"], styles[k % 3], lw=0.8, color="C0", label=f"vertical force, {label}")
    bottom.plot(sweep["x"], sweep["fx"], styles[k % 3], lw=0.8, color="C1", label=f"along the sweep, {label}")
    if k == 0:
        bottom.plot(sweep["x"], sweep["explained"], lw=1.4, color="k", alpha=0.5,
                    label="what the slope explains, -s f_z")
        for j, end in enumerate(DWELL_ENDS_S):
            px = sum(p[0] for p in dwell[end]) / len(dwell[end]); pz = sum(p[1] for p in dwell[end]) / len(dwell[end])
            top.plot([px], [pz], "ko", ms=4, label="pressed straight down and held" if j == 0 else None)
top.set_ylabel("force on the hand (N)")
bottom.set_ylabel("force on the hand (N)")
bottom.set_xlabel("probe x (mm), swept at 15 mm/s, 2 mm deep")
top.set_title("palpate_liver: the hand's rendered force (1 kHz), the probe sliding")
top.legend(fontsize=7, loc="lower right")
bottom.legend(fontsize=7, loc="lower right")
fig.tight_layout()
fig.savefig(out)
