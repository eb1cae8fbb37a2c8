#!/usr/bin/python3
"""The organ's physics resolution against the 52k-tet reference (issue 42, item 2): for each tet mesh
of the liver-sized organ (meshes/make_liver.py), through `import tissue`:

* cost: the defaults' step (10 ms, two threads) hanging by the ligament, E 300 kPa, as in
  host/scenarios/cut_organ.toml: median and p99 of steps 100-199 (settled), and of the 290 steps
  of cut_organ's stroke (a vertical scalpel through the left lobe at 80% of the length, 6 cm/s);
* sag: the static equilibrium under gravity (backward Euler with 0.5 s steps and exact solves until
  it stops moving), the displacement of the left lobe's tip (the material point at x = 9.5 cm on the
  lobe's mid-plane, interpolated in its tet);
* held probe: the organ held by its bottom quarter as in host/scenarios/palpate_liver.toml (E 100
  kPa), a point probe pressed 2 mm below the surface straight down at x = -1.5 and -4.5 cm and held
  until static (0.5 s steps, exact solves): the force on the tool;
* cut piece: the volume of the mesh beyond the stroke's plane (x at 80% of the length): what the
  stroke frees, cut exactly.

Each figure's error is against the first mesh (the reference, meshes/liver.veg). Prints a Markdown
table (docs/BENCHMARKS.md, "The organ's resolution").

Usage: /usr/bin/python3 tests/bench/organ_resolution.py [--mesh FILE ...] [--module DIR]
(default meshes: meshes/liver.veg then meshes/liver_coarse.veg; DIR: where tissue*.so is, default
build/release/python). Needs python3-numpy and python3-scipy (Debian). Run nothing else meanwhile.
"""
import argparse
import os
import statistics
import sys
import time

import numpy as np
from scipy.spatial import ConvexHull

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
sys.path.insert(0, os.path.join(ROOT, "meshes"))
from make_palpation import boundary_triangles, read_veg  # noqa: E402  (the meshes' own .veg reader)
STEP_S = 0.01
CUT_FRACTION = 0.8  # cut_organ's stroke: x at 80% of the rest box's length
TIP_X_M = 0.095  # the left lobe's tip material point (x; y = 0, mid-thickness)
PROBE_XS_M = (-0.015, -0.045)  # palpate_liver's two dwells (beside and over its inclusion)
PROBE_DEPTH_M = 0.002


def read_mesh(path):
    """Rest positions (n x 3) and tets (m x 4, 0-based) of a .veg file, by make_palpation.py's reader."""
    _, vertices, tets = read_veg(path)
    return np.array(vertices), np.array(tets)


def boundary_faces(tets):
    return np.array(boundary_triangles(tets.tolist()))


def vertical_hits(x, faces, px, py):
    """The heights at which the vertical line through (px, py) meets the surface (x: positions)."""
    a, b, c = x[faces[:, 0]], x[faces[:, 1]], x[faces[:, 2]]
    e1, e2, d = b[:, :2] - a[:, :2], c[:, :2] - a[:, :2], np.array([px, py]) - a[:, :2]
    det = e1[:, 0] * e2[:, 1] - e2[:, 0] * e1[:, 1]
    ok = np.abs(det) > 1e-18
    safe = np.where(ok, det, 1.0)
    s = (d[:, 0] * e2[:, 1] - e2[:, 0] * d[:, 1]) / safe
    r = (e1[:, 0] * d[:, 1] - d[:, 0] * e1[:, 1]) / safe
    inside = ok & (s >= -1e-12) & (r >= -1e-12) & (s + r <= 1 + 1e-12)
    return (a[:, 2] + s * (b[:, 2] - a[:, 2]) + r * (c[:, 2] - a[:, 2]))[inside]


def barycentric_in_mesh(vertices, tets, point):
    """(tet, weights) of the tet holding `point` at rest."""
    a = vertices[tets[:, 0]]
    m = np.stack([vertices[tets[:, k]] - a for k in (1, 2, 3)], axis=2)  # columns: edges
    coefficients = np.linalg.solve(m, (point - a)[:, :, None])[:, :, 0]
    weights = np.concatenate([1.0 - coefficients.sum(axis=1, keepdims=True), coefficients], axis=1)
    inside = np.where(weights.min(axis=1) >= -1e-9)[0]
    if len(inside) == 0:
        raise SystemExit("no tet holds %s" % point)
    return inside[0], weights[inside[0]]


def clipped_volume(vertices, tets, axis, at):
    """Volume of the mesh beyond the plane x[axis] = at, each tet clipped exactly."""
    total = 0.0
    for tet in tets:
        p = vertices[tet]
        s = p[:, axis] - at
        if (s >= 0).all():
            total += abs(np.dot(p[1] - p[0], np.cross(p[2] - p[0], p[3] - p[0]))) / 6.0
        elif (s > 0).any():
            points = [p[i] for i in range(4) if s[i] >= 0]
            points += [p[i] + s[i] / (s[i] - s[j]) * (p[j] - p[i])
                       for i in range(4) for j in range(i + 1, 4) if (s[i] > 0) != (s[j] > 0) and s[i] * s[j] < 0]
            total += ConvexHull(np.array(points)).volume
    return total


def hanging(tissue, mesh, **extra):
    kwargs = dict(mesh=mesh, fixed_axis=1, fixed_fraction=0.04, young_modulus_pa=3e5, step_size_s=STEP_S, threads=2)
    kwargs.update(extra)
    return tissue.Tissue(**kwargs)


def step_costs(tissue, mesh):
    """Settled steps and the stroke's steps: (median, p99) of each [ms]."""
    body = hanging(tissue, mesh)
    settled = []
    for n in range(200):
        report = body.step()
        if n >= 100:
            settled.append(1e3 * report["total_s"])
    rest = body.rest_positions_m
    lower, upper = rest.min(axis=0), rest.max(axis=0)
    size = upper - lower
    x = lower[0] + CUT_FRACTION * size[0]
    stroke = []
    steps = 290
    for n in range(steps + 1):
        y = lower[1] + (1.15 - 1.3 * n / steps) * size[1]
        body.set_tool((x, y, lower[2] - size[2]), mode="scalpel")
        stroke.append(1e3 * body.step()["total_s"])
    body.set_tool((x, lower[1] - 0.3 * size[1], lower[2] - size[2]), mode="none")
    for _ in range(20):
        body.step()
    tip = rest[:, 0] > lower[0] + 0.95 * size[0]
    fallen_m = -(body.positions_m[tip, 2] - rest[tip, 2]).mean()

    def p99(values):
        return sorted(values)[min(len(values) - 1, int(round(0.99 * (len(values) - 1))))]

    return (statistics.median(settled), p99(settled)), (statistics.median(stroke), p99(stroke)), fallen_m


def static(body, steps=60, tolerance_m=1e-9):
    before = None
    for _ in range(steps):
        body.step()
        now = body.positions_m
        if before is not None and np.abs(now - before).max() < tolerance_m:
            return
        before = now


def sag(tissue, mesh, vertices, tets, reference_vertices, reference_faces):
    # The tip point: x = TIP_X_M, y = 0, halfway between the reference surface's bottom and top there.
    hits = vertical_hits(reference_vertices, reference_faces, TIP_X_M, 0.0)
    point = np.array([TIP_X_M, 0.0, 0.5 * (hits.min() + hits.max())])
    tet, weights = barycentric_in_mesh(vertices, tets, point)
    body = hanging(tissue, mesh, step_size_s=0.5, linear_solver="cholmod")
    static(body)
    u = body.positions_m - body.rest_positions_m
    return weights @ u[tets[tet]]


def probe_forces(tissue, mesh, faces):
    body = tissue.Tissue(mesh=mesh, young_modulus_pa=1e5, step_size_s=0.5, linear_solver="cholmod", threads=2)
    static(body)
    forces = []
    for px in PROBE_XS_M:
        top = vertical_hits(body.positions_m, faces, px, 0.0).max()
        body.set_tool((px, 0.0, top + 0.002), mode="probe")
        body.step()
        body.set_tool((px, 0.0, top - PROBE_DEPTH_M), mode="probe")
        static(body)
        forces.append(np.array(body.tool_contact["force_on_tool_n"]))
        body.set_tool((px, 0.0, top + 0.02), mode="none")
        static(body)
    return forces


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--mesh", action="append", default=None, help="a tet mesh (.veg); the first is the reference")
    parser.add_argument("--module", default=os.path.join(ROOT, "build", "release", "python"))
    args = parser.parse_args()
    sys.path.insert(0, args.module)
    import tissue

    meshes = args.mesh or [os.path.join(ROOT, "meshes", "liver.veg"), os.path.join(ROOT, "meshes", "liver_coarse.veg")]
    rows = []
    reference_vertices, reference_tets = read_mesh(meshes[0])
    reference_faces = boundary_faces(reference_tets)
    for mesh in meshes:
        start = time.time()
        vertices, tets = read_mesh(mesh)
        faces = boundary_faces(tets)
        lower, upper = vertices.min(axis=0), vertices.max(axis=0)
        cut_volume = clipped_volume(vertices, tets, 0, lower[0] + CUT_FRACTION * (upper[0] - lower[0]))
        settled, stroke, fallen_m = step_costs(tissue, mesh)
        tip_u = sag(tissue, mesh, vertices, tets, reference_vertices, reference_faces)
        forces = probe_forces(tissue, mesh, faces)
        rows.append(dict(mesh=os.path.relpath(mesh, ROOT), tets=len(tets), vertices=len(vertices), settled=settled,
                         stroke=stroke, fallen_m=fallen_m, tip_u=tip_u, forces=forces, cut_volume=cut_volume))
        print("%s: %d tets, settled %.2f / %.2f ms, stroke %.2f / %.2f ms, tip fell %.1f mm, sag %s mm, "
              "probe %s N, cut piece %.2f cm^3 (%.0f s)"
              % (rows[-1]["mesh"], len(tets), settled[0], settled[1], stroke[0], stroke[1], 1e3 * fallen_m,
                 np.round(1e3 * tip_u, 2), [round(f[2], 4) for f in forces], 1e6 * cut_volume, time.time() - start),
              flush=True)

    ref = rows[0]
    print()
    print("| mesh | tets | step p50 / p99, settled [ms] | stroke p50 / p99 [ms] | lobe tip sag [mm] (error) | "
          "held probe beside / over [N] (error) | cut piece [cm^3] (error) |")
    print("|---|---:|---|---|---|---|---|")
    for row in rows:
        sag_error = np.linalg.norm(row["tip_u"] - ref["tip_u"]) / np.linalg.norm(ref["tip_u"])
        force_errors = [abs(f[2] - r[2]) / abs(r[2]) for f, r in zip(row["forces"], ref["forces"])]
        volume_error = (row["cut_volume"] - ref["cut_volume"]) / ref["cut_volume"]
        print("| `%s` | %d | %.2f / %.2f | %.2f / %.2f | %.1f (%.1f%%) | %.3f / %.3f (%.1f%%, %.1f%%) | %.2f (%+.1f%%) |"
              % (row["mesh"], row["tets"], row["settled"][0], row["settled"][1], row["stroke"][0], row["stroke"][1],
                 1e3 * np.linalg.norm(row["tip_u"]), 100 * sag_error, -row["forces"][0][2], -row["forces"][1][2],
                 100 * force_errors[0], 100 * force_errors[1], 1e6 * row["cut_volume"], 100 * volume_error))


if __name__ == "__main__":
    sys.exit(main())
