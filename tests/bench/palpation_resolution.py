#!/usr/bin/python3
"""The palpation mesh against the 52k-tet reference (issue 42, item 2): held pokes of a point and of pads.

    PYTHONPATH=build/release/python /usr/bin/python3 tests/bench/palpation_resolution.py [MESHES] [PAD_RADII]

MESHES (comma-separated, in meshes/; default liver_tumour.veg,liver_palpation_tumour.veg) and PAD_RADII
(contact.padRadius [m], comma-separated; default 0,0.008,0.01). Per mesh and radius: the organ as
host/scenarios/palpate_liver.toml holds it (its bottom quarter, gravity, the file's regions), settled
under gravity, a probe lowered straight down to 2 mm below the rest top surface beside the inclusion
(x = -1.5 cm) and over it (x = -4.5 cm) and held: quasi-static (exact CHOLMOD solves, 50 ms steps,
mass damping 20 /s, 36 steps), the force along z and K_c's zz. Prints one line per mesh and radius.
"""
import pathlib
import sys
import time

import numpy as np
import tissue

MESHES = pathlib.Path(__file__).resolve().parents[2] / "meshes"
DEPTH_M = 0.002
XS_M = (-0.015, -0.045)  # palpate_liver's dwells: beside and over the inclusion


def top_height(t, x, y):
    """The largest z at which the vertical line through (x, y) meets the surface at rest."""
    points, triangles = t.surface()
    best = None
    for a, b, c in triangles:
        pa, pb, pc = points[a], points[b], points[c]
        det = (pb[1] - pc[1]) * (pa[0] - pc[0]) + (pc[0] - pb[0]) * (pa[1] - pc[1])
        if abs(det) < 1e-18:
            continue
        l1 = ((pb[1] - pc[1]) * (x - pc[0]) + (pc[0] - pb[0]) * (y - pc[1])) / det
        l2 = ((pc[1] - pa[1]) * (x - pc[0]) + (pa[0] - pc[0]) * (y - pc[1])) / det
        l3 = 1.0 - l1 - l2
        if min(l1, l2, l3) < -1e-12:
            continue
        z = l1 * pa[2] + l2 * pb[2] + l3 * pc[2]
        best = z if best is None else max(best, z)
    return best


def poke(mesh, pad_m, x_m):
    t = tissue.Tissue(mesh=str(MESHES / mesh), step_size_s=0.05, damping_alpha_per_s=20.0, damping_beta_s=0.0,
                      linear_solver="cholmod", contact_pad_radius_m=pad_m, newton_max_iterations=5)
    top = top_height(t, x_m, 0.0)
    t.step(20)  # settled under gravity
    for k in range(11):
        t.set_tool((x_m, 0.0, top + 0.003 - (0.003 + DEPTH_M) * k / 10), mode="probe")
        t.step()
    t.step(25)
    return t.contact["force_on_tool_n"][2], np.array(t.contact["stiffness_n_per_m"])[2, 2]


def main():
    meshes = (sys.argv[1] if len(sys.argv) > 1 else "liver_tumour.veg,liver_palpation_tumour.veg").split(",")
    pads = [float(a) for a in (sys.argv[2] if len(sys.argv) > 2 else "0,0.008,0.01").split(",")]
    for pad_m in pads:
        for mesh in meshes:
            start = time.time()
            (beside_n, beside_k), (over_n, over_k) = (poke(mesh, pad_m, x) for x in XS_M)
            print("%s, pad %.3f m: beside %.4f N (K_c %.0f N/m), over %.4f N (K_c %.0f N/m), over / beside %.3f [%.0f s]"
                  % (mesh, pad_m, beside_n, beside_k, over_n, over_k, over_n / beside_n, time.time() - start),
                  flush=True)


if __name__ == "__main__":
    main()
