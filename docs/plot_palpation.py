#!/usr/bin/python3
"""The palpation figure (docs/palpation_force.png) from a palpate_liver log:
    tissue-host run host/scenarios/palpate_liver.toml --offline -o OUT
    /usr/bin/python3 docs/plot_palpation.py OUT/log.csv docs/palpation_force.png
"""
import csv, sys
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
rows = list(csv.DictReader(open(sys.argv[1])))
SWEEP_S = (5.3, 9.3)  # the scenario's sweep; before it, two presses held 0.8 s (until 1.4 s and 3.6 s)
DWELL_ENDS_S = (1.4, 3.6)
x, fz, fx = [], [], []
dwell = {end: [] for end in DWELL_ENDS_S}
for r in rows:
    t = float(r["time_s"])
    if SWEEP_S[0] <= t <= SWEEP_S[1]:
        x.append(1e3 * float(r["tool_x_m"])); fz.append(float(r["force_z_n"])); fx.append(float(r["force_x_n"]))
    for end in DWELL_ENDS_S:
        if end - 0.4 <= t < end:
            dwell[end].append((1e3 * float(r["tool_x_m"]), float(r["force_z_n"])))
fig, ax = plt.subplots(figsize=(7, 3.6), dpi=110)
ax.axvspan(-45 - 8, -45 + 8, color="0.88", label="inclusion (E 1 MPa, 4 mm under the surface)")
ax.plot(x, fz, lw=0.8, label="vertical force on the hand (N)")
ax.plot(x, fx, lw=0.8, label="force along the sweep (N): drag")
for k, end in enumerate(DWELL_ENDS_S):
    px = sum(p[0] for p in dwell[end]) / len(dwell[end]); pz = sum(p[1] for p in dwell[end]) / len(dwell[end])
    ax.plot([px], [pz], "ko", ms=4, label="pressed straight down and held (test_palpation)" if k == 0 else None)
ax.set_xlabel("probe x (mm), swept at 15 mm/s, 2 mm deep")
ax.set_ylabel("force (N)")
ax.set_title("palpate_liver: the hand's rendered force (1 kHz)")
ax.legend(fontsize=7, loc="lower right")
fig.tight_layout()
fig.savefig(sys.argv[2])
