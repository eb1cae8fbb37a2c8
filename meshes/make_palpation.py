#!/usr/bin/python3
"""Builds the palpation specimen (issue 25): the organ of make_liver.py with a stiff inclusion.

    /usr/bin/python3 meshes/make_palpation.py

Reads meshes/liver.veg and writes meshes/liver_tumour.veg (and liver_palpation.veg, the palpation scene's
physics mesh, into liver_palpation_tumour.veg): the same vertices and tets in two
regions (Vega *SET / *MATERIAL / *REGION): "tumour", the tets whose centroid lies within a sphere of
RADIUS_M under the top of the thick right lobe, its top DEPTH_M below the surface, with E ten times
the rest; and "liver", every other tet. It prints the probe's sweep for host/scenarios/palpate_liver.toml:
points along x through the inclusion's centre, PROBE_DEPTH_M below the top surface (the surface's
height there, read off its triangles), so that the probe presses equally deep everywhere. Python 3
standard library only; re-running it rewrites the file byte for byte.
"""

import math
import os

RADIUS_M = 0.008  # the inclusion: 1.6 cm across
DEPTH_M = 0.004  # from the top surface to the inclusion's top
CENTRE_XY_M = (-0.045, 0.0)  # over the thick right lobe, at mid depth
PROBE_DEPTH_M = 0.002  # the sweep: how far below the top surface the probe's tip is held
SWEEP_HALF_LENGTH_M = 0.03  # along x, either side of the centre
SWEEP_POINTS = 25
LIVER = ("liverTissue", 1060.0, 1.0e5, 0.45)  # name, density, E, nu
TUMOUR = ("tumourTissue", 1100.0, 1.0e6, 0.45)


def read_veg(path):
    lines = open(path).read().split("\n")
    vertices, tets = [], []
    k = lines.index("*VERTICES")
    count = int(lines[k + 1].split()[0])
    for line in lines[k + 2:k + 2 + count]:
        vertices.append(tuple(float(v) for v in line.split()[1:4]))
    k = lines.index("*ELEMENTS")
    count = int(lines[k + 2].split()[0])
    for line in lines[k + 3:k + 3 + count]:
        tets.append(tuple(int(v) - 1 for v in line.split()[1:5]))
    return lines, vertices, tets


def boundary_triangles(tets):
    """Faces used by one tet only: the surface (unoriented)."""
    count = {}
    for tet in tets:
        for face in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
            key = tuple(sorted(tet[f] for f in face))
            count[key] = count.get(key, 0) + 1
    return [face for face, n in count.items() if n == 1]


def top_height(vertices, triangles, x, y):
    """The largest z at which the vertical line through (x, y) meets the surface."""
    best = None
    for a, b, c in triangles:
        (ax, ay, az), (bx, by, bz), (cx, cy, cz) = vertices[a], vertices[b], vertices[c]
        det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
        if abs(det) < 1e-18:
            continue
        l1 = ((by - cy) * (x - cx) + (cx - bx) * (y - cy)) / det
        l2 = ((cy - ay) * (x - cx) + (ax - cx) * (y - cy)) / det
        l3 = 1.0 - l1 - l2
        if min(l1, l2, l3) < -1e-12:
            continue
        z = l1 * az + l2 * bz + l3 * cz
        best = z if best is None else max(best, z)
    if best is None:
        raise SystemExit("no surface over (%g, %g)" % (x, y))
    return best


def top_normal(vertices, triangles, x, y, step=0.002):
    """The top surface's upward unit normal at (x, y), from its heights +-step around."""
    dz_dx = (top_height(vertices, triangles, x + step, y) - top_height(vertices, triangles, x - step, y)) / (2 * step)
    dz_dy = (top_height(vertices, triangles, x, y + step) - top_height(vertices, triangles, x, y - step)) / (2 * step)
    length = math.sqrt(dz_dx * dz_dx + dz_dy * dz_dy + 1.0)
    return (-dz_dx / length, -dz_dy / length, 1.0 / length)


# The meshes tagged: the 52k-tet reference and the palpation scene's physics mesh (make_liver.py's
# liver_palpation, meshed finer over the sweep), each with the same inclusion (its centre from the
# reference's surface).
MESHES = (("liver.veg", "liver_tumour.veg"), ("liver_palpation.veg", "liver_palpation_tumour.veg"))


def tag(here, source, output, centre):
    """Writes meshes/output: meshes/source's vertices and tets in the regions liver and tumour."""
    lines, vertices, tets = read_veg(os.path.join(here, source))
    tumour = []
    volume = 0.0
    for n, tet in enumerate(tets):
        c = [sum(vertices[v][i] for v in tet) / 4.0 for i in range(3)]
        if math.dist(c, centre) <= RADIUS_M:
            tumour.append(n + 1)
            p = [vertices[v] for v in tet]
            e = [[p[k][i] - p[0][i] for i in range(3)] for k in (1, 2, 3)]
            volume += abs(e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                          e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                          e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0])) / 6.0
    if not 30 <= len(tumour) <= 2000:
        raise SystemExit("the inclusion has %d tets in %s: check RADIUS_M against the mesh size" % (len(tumour), source))
    tumour_set = set(tumour)
    liver = [n for n in range(1, len(tets) + 1) if n not in tumour_set]
    diameter = 2.0 * (3.0 * volume / (4.0 * math.pi)) ** (1.0 / 3.0)

    def id_lines(ids):
        return [", ".join(str(i) for i in ids[k:k + 16]) + "," for k in range(0, len(ids), 16)]

    header = lines[:3]
    header[1] = ("# the organ of meshes/%s with a stiff inclusion, by meshes/make_palpation.py: region tumour "
                 "(%d tets, %.1f cm across, its top %.0f mm under the top surface at x = %g, y = %g m), E %gx the "
                 "liver's" % (source, len(tumour), 100 * diameter, 1000 * DEPTH_M, CENTRE_XY_M[0], CENTRE_XY_M[1],
                              TUMOUR[2] / LIVER[2]))
    body = lines[3:]
    while body and body[-1] == "":
        body.pop()
    out = header + body + [""]
    for name, density, young, poisson in (LIVER, TUMOUR):
        out += ["*MATERIAL %s" % name, "ENU, %r, %r, %r" % (density, young, poisson), ""]
    out += ["*SET liver"] + id_lines(liver) + ["", "*SET tumour"] + id_lines(tumour) + [""]
    out += ["*REGION", "liver, %s" % LIVER[0], "tumour, %s" % TUMOUR[0]]
    with open(os.path.join(here, output), "w", newline="\n") as f:
        f.write("\n".join(out) + "\n")
    print("meshes/%s: tumour %d tets (%.2f cm across, centre %s), liver %d tets" %
          (output, len(tumour), 100 * diameter, tuple(round(c, 5) for c in centre), len(liver)))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    _, vertices, tets = read_veg(os.path.join(here, MESHES[0][0]))
    triangles = boundary_triangles(tets)
    top = top_height(vertices, triangles, *CENTRE_XY_M)
    centre = (CENTRE_XY_M[0], CENTRE_XY_M[1], top - DEPTH_M - RADIUS_M)
    for source, output in MESHES:
        tag(here, source, output, centre)
    print("sweep at %.0f mm below the top surface (x, y, z) [m], and the surface's normal there (a pad held "
          "flat on it: the tool's axis):" % (1000 * PROBE_DEPTH_M))
    for k in range(SWEEP_POINTS):
        x = CENTRE_XY_M[0] - SWEEP_HALF_LENGTH_M + 2 * SWEEP_HALF_LENGTH_M * k / (SWEEP_POINTS - 1)
        y = CENTRE_XY_M[1]
        z = top_height(vertices, triangles, x, y) - PROBE_DEPTH_M
        print("  [%.4f, %.4f, %.5f], axis [%.4f, %.4f, %.4f]" % ((x, y, z) + top_normal(vertices, triangles, x, y)))


if __name__ == "__main__":
    main()
