#!/usr/bin/python3
"""Builds the frog specimen: writes meshes/frog.geo, meshes it with Gmsh (OpenCASCADE union
of ellipsoids and cylinders), checks the result and converts it to meshes/frog.veg. Also meshes
the same shape's surface finely (RENDER_SIZE_M) into meshes/frog_surface.obj, the render surface
that rides on the tets (issue 22): closed, manifold, oriented outward.

    /usr/bin/python3 meshes/make_frog.py [--gmsh gmsh]

The dissertation's frog had 826 vertices and 2301 tets; this one is tuned (MESH_SIZE_M) to
land within 15% of both. Gmsh runs single-threaded with a fixed random seed so that the same
Gmsh version (4.8.4 here) writes the same file every time; the script refuses to overwrite the
outputs if the counts or the checks fail. Frame: x from tail to head, y to the frog's left,
z up, metres; the frog is about 0.12 m long.
"""

import argparse
import math
import os
import subprocess
import sys

from make_bar import signed_volume  # one tet-volume formula for both generators

TARGET_VERTICES = 826
TARGET_TETS = 2301
TOLERANCE = 0.15

# Largest tet edge [m]. Uniform sizing; the legs (radius 4.5-5.5 mm) get about one element
# across, which is what a coarse real-time specimen of ~800 vertices can afford.
MESH_SIZE_M = 0.0070

# Largest triangle edge of the render surface [m]: over 20k triangles.
RENDER_SIZE_M = 0.0013
MIN_RENDER_TRIANGLES = 20000

# (centre, semi-axes) of the ellipsoids [m].
BODY = ((0.0, 0.0, 0.020), (0.035, 0.024, 0.016))
HEAD = ((0.036, 0.0, 0.024), (0.020, 0.020, 0.012))
# Leg segments as cylinders (start, end, radius) [m] for the left side (y > 0); the right side
# is the mirror image. Each leg starts deep enough in the body that its whole end cap is inside
# (a cap rim grazing the body surface leaves sub-millimetre edges and sliver tets), so the union
# is one connected volume. Back legs: thigh from the hip out to the knee, shin back to the foot.
FRONT_LEG = ((0.016, 0.008, 0.016), (0.034, 0.030, -0.002), 0.0045)
THIGH = ((-0.018, 0.008, 0.018), (-0.040, 0.040, 0.008), 0.0055)
SHIN = ((-0.040, 0.040, 0.008), (-0.068, 0.028, 0.004), 0.0045)
KNEE_RADIUS_M = 0.0055  # a sphere rounds the joint between thigh and shin


# Gmsh's options for a reproducible first-order mesh (shared with make_liver.py).
GMSH_OPTIONS = [
    "General.NumThreads = 1;        // single-threaded meshing is reproducible",
    "Mesh.RandomSeed = 1;",
    "Mesh.RandomFactor = 1e-9;",
    "Mesh.Algorithm = 6;            // Frontal-Delaunay surfaces",
    "Mesh.Algorithm3D = 1;          // Delaunay volume",
    "Mesh.Optimize = 1;",
    "Mesh.MeshSizeFromCurvature = 0;",
]


def mirror(point):
    return (point[0], -point[1], point[2])


def geo_text():
    def num(x):
        return "%.6g" % x

    def ellipsoid(tag, centre, semi_axes):
        return ["Sphere(%d) = {0, 0, 0, 1};" % tag,
                "Dilate {{0, 0, 0}, {%s}} { Volume{%d}; }" % (", ".join(map(num, semi_axes)), tag),
                "Translate {%s} { Volume{%d}; }" % (", ".join(map(num, centre)), tag)]

    def cylinder(tag, start, end, radius):
        axis = [end[n] - start[n] for n in range(3)]
        return ["Cylinder(%d) = {%s, %s, %s};" % (tag, ", ".join(map(num, start)), ", ".join(map(num, axis)),
                                                   num(radius))]

    lines = [
        "// Frog specimen, written by meshes/make_frog.py: edit the script, not this file.",
        "// Body and head are ellipsoids, the legs cylinders; one OpenCASCADE union.",
        'SetFactory("OpenCASCADE");',
        *GMSH_OPTIONS,
        "Mesh.MeshSizeExtendFromBoundary = 1;",
        "Mesh.MeshSizeMin = 0;",
        "Mesh.MeshSizeMax = %s;" % num(MESH_SIZE_M),
        "Mesh.ElementOrder = 1;",
        "",
    ]
    lines += ellipsoid(1, *BODY)
    lines += ellipsoid(2, *HEAD)
    tag = 3
    for start, end, radius in (FRONT_LEG, THIGH, SHIN):
        lines += cylinder(tag, start, end, radius)
        lines += cylinder(tag + 1, mirror(start), mirror(end), radius)
        tag += 2
    knee = THIGH[1]
    lines.append("Sphere(%d) = {%s, %s};" % (tag, ", ".join(map(num, knee)), num(KNEE_RADIUS_M)))
    lines.append("Sphere(%d) = {%s, %s};" % (tag + 1, ", ".join(map(num, mirror(knee))), num(KNEE_RADIUS_M)))
    lines.append("BooleanUnion{ Volume{1}; Delete; }{ Volume{2:%d}; Delete; }" % (tag + 1))
    return "\n".join(lines) + "\n"


def read_msh41(path, element_type=4):
    """Minimal Gmsh 4.1 ASCII reader: returns (node tags, coordinates, elements of `element_type`
    (4 tets, 2 triangles) as node tags, volumes)."""
    with open(path) as f:
        lines = f.read().split("\n")

    def section(name):
        return lines.index(name) + 1

    p = section("$MeshFormat")
    assert lines[p].split()[:2] == ["4.1", "0"], "expected an ASCII 4.1 .msh"
    p = section("$Entities")
    volumes = int(lines[p].split()[3])

    p = section("$Nodes")
    blocks = int(lines[p].split()[0])
    p += 1
    tags, coords = [], []
    for _ in range(blocks):
        dim, _, parametric, count = map(int, lines[p].split())
        assert parametric == 0
        p += 1
        tags += [int(lines[p + n]) for n in range(count)]
        coords += [tuple(map(float, lines[p + count + n].split()[:3])) for n in range(count)]
        p += 2 * count

    p = section("$Elements")
    blocks = int(lines[p].split()[0])
    p += 1
    tets = []
    for _ in range(blocks):
        _, _, block_type, count = map(int, lines[p].split())
        p += 1
        if block_type == element_type:
            corners = 4 if element_type == 4 else 3
            tets += [tuple(map(int, lines[p + n].split()[1:1 + corners])) for n in range(count)]
        p += count
    return tags, coords, tets, volumes


def check(coords, tets, volumes):
    """Refuses a mesh the simulator would refuse or that is not one closed solid."""
    problems = []
    if volumes != 1:
        problems.append("the union has %d volumes, expected 1 (a leg does not touch the body?)" % volumes)
    lower = [min(c[n] for c in coords) for n in range(3)]
    upper = [max(c[n] for c in coords) for n in range(3)]
    diagonal = math.dist(lower, upper)
    small = 1e-12 * diagonal ** 3  # the zero-volume threshold of the C++ readers
    for n, tet in enumerate(tets):
        volume = signed_volume(*(coords[v] for v in tet))
        if volume <= small:
            problems.append("tet %d has volume %g" % (n + 1, volume))
    used = set(v for tet in tets for v in tet)
    if len(used) != len(coords):
        problems.append("%d vertices are not used by any tet" % (len(coords) - len(used)))
    faces = {}
    for tet in tets:
        for face in ((1, 2, 3), (0, 3, 2), (0, 1, 3), (0, 2, 1)):
            key = tuple(sorted(tet[k] for k in face))
            faces[key] = faces.get(key, 0) + 1
    if any(count > 2 for count in faces.values()):
        problems.append("a face is shared by more than two tets")
    # One closed surface of genus 0: V - E + F = 2 over the boundary triangles.
    boundary = [key for key, count in faces.items() if count == 1]
    edges = set()
    for a, b, c in boundary:
        edges.update(((a, b), (a, c), (b, c)))
    surface_vertices = set(v for face in boundary for v in face)
    euler = len(surface_vertices) - len(edges) + len(boundary)
    if euler != 2:
        problems.append("surface Euler characteristic %d, expected 2" % euler)
    return problems, (lower, upper)


def oriented_surface(coords, triangles):
    """The triangles wound consistently (a flood over shared edges), outward (positive enclosed
    volume), and the problems that refuse them: an edge not shared by exactly two triangles, more
    than one piece, a surface that is not a sphere's (V - E + F != 2)."""
    problems = []
    edge_triangles = {}
    for n, (a, b, c) in enumerate(triangles):
        for u, v in ((a, b), (b, c), (c, a)):
            edge_triangles.setdefault((min(u, v), max(u, v)), []).append(n)
    bad = [edge for edge, users in edge_triangles.items() if len(users) != 2]
    if bad:
        return triangles, ["%d edges are not shared by exactly two triangles (first: %s)" % (len(bad), bad[0])]
    wound = [None] * len(triangles)
    wound[0] = triangles[0]
    stack = [0]
    while stack:
        n = stack.pop()
        a, b, c = wound[n]
        for u, v in ((a, b), (b, c), (c, a)):
            for m in edge_triangles[(min(u, v), max(u, v))]:
                if wound[m] is not None:
                    continue
                x, y, z = triangles[m]
                # A neighbour wound the same way runs the shared edge the other way (v -> u).
                runs_uv = (x, y) == (u, v) or (y, z) == (u, v) or (z, x) == (u, v)
                wound[m] = (x, z, y) if runs_uv else (x, y, z)
                stack.append(m)
    if any(t is None for t in wound):
        problems.append("the surface is in more than one piece")
        return triangles, problems
    volume = sum(signed_volume((0.0, 0.0, 0.0), coords[a], coords[b], coords[c]) for a, b, c in wound)
    if volume < 0.0:
        wound = [(a, c, b) for a, b, c in wound]
    used = set(v for t in wound for v in t)
    if len(used) - len(edge_triangles) + len(wound) != 2:
        problems.append("surface Euler characteristic %d, expected 2" % (len(used) - len(edge_triangles) + len(wound)))
    return wound, problems


def write_obj(path, coords, triangles, comment):
    used = sorted(set(v for t in triangles for v in t))
    index_of = {v: n + 1 for n, v in enumerate(used)}
    lines = ["# " + comment, "# %d vertices, %d triangles" % (len(used), len(triangles))]
    lines += ["v %r %r %r" % coords[v] for v in used]
    lines += ["f %d %d %d" % tuple(index_of[v] for v in t) for t in triangles]
    with open(path, "w", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


def make_render_surface(gmsh, here):
    """Meshes the frog's surface at RENDER_SIZE_M into frog_surface.obj (refused if not closed)."""
    render_geo = os.path.join(here, "frog_surface.geo")
    with open(render_geo, "w", newline="\n") as out:
        out.write('// The frog render surface (meshes/make_frog.py): frog.geo meshed in 2D, finer.\n'
                  'Include "frog.geo";\nMesh.MeshSizeMax = %r;\n' % RENDER_SIZE_M)
    tmp = os.path.join(here, "frog_surface.msh.tmp")
    result = subprocess.run([gmsh, "frog_surface.geo", "-2", "-nt", "1", "-format", "msh41", "-o",
                             os.path.basename(tmp)], cwd=here, capture_output=True, text=True)
    if result.returncode != 0 or not os.path.exists(tmp):
        sys.stderr.write(result.stdout + result.stderr)
        sys.exit("gmsh failed on the render surface")
    tags, coords, triangles, _ = read_msh41(tmp, element_type=2)
    os.remove(tmp)
    index_of = {tag: n for n, tag in enumerate(tags)}
    triangles = [tuple(index_of[tag] for tag in t) for t in triangles]
    triangles, problems = oriented_surface(coords, triangles)
    if len(triangles) < MIN_RENDER_TRIANGLES:
        problems.append("%d triangles, fewer than %d: lower RENDER_SIZE_M" % (len(triangles), MIN_RENDER_TRIANGLES))
    if problems:
        sys.exit("frog render surface refused:\n  " + "\n  ".join(problems))
    write_obj(os.path.join(here, "frog_surface.obj"), coords, triangles,
              "frog render surface from frog_surface.geo by meshes/make_frog.py (largest edge %g m)" % RENDER_SIZE_M)
    print("frog render surface: %d triangles" % len(triangles))


def write_veg(path, coords, tets, comment):
    lines = ["# Vega mesh file.", "# " + comment, "# %d vertices, %d elements" % (len(coords), len(tets)), "",
             "*VERTICES", "%d 3 0 0" % len(coords)]
    lines += ["%d %r %r %r" % (n + 1, x, y, z) for n, (x, y, z) in enumerate(coords)]
    lines += ["", "*ELEMENTS", "TET", "%d 4 0" % len(tets)]
    lines += ["%d %d %d %d %d" % ((n + 1,) + tuple(v + 1 for v in tet)) for n, tet in enumerate(tets)]
    with open(path, "w", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--gmsh", default="gmsh", help="the gmsh executable (4.8.4 made the committed files)")
    args = parser.parse_args()

    here = os.path.dirname(os.path.abspath(__file__))
    geo = os.path.join(here, "frog.geo")
    msh = os.path.join(here, "frog.msh")
    veg = os.path.join(here, "frog.veg")
    tmp = msh + ".tmp"

    with open(geo, "w", newline="\n") as out:
        out.write(geo_text())
    # Relative names, run from meshes/, so nothing machine-specific ends up in the outputs.
    result = subprocess.run([args.gmsh, "frog.geo", "-3", "-nt", "1", "-format", "msh41", "-o",
                             os.path.basename(tmp)], cwd=here, capture_output=True, text=True)
    if result.returncode != 0 or not os.path.exists(tmp):
        sys.stderr.write(result.stdout + result.stderr)
        sys.exit("gmsh failed")

    tags, coords, tets, volumes = read_msh41(tmp)
    index_of = {tag: n for n, tag in enumerate(tags)}
    tets = [tuple(index_of[tag] for tag in tet) for tet in tets]
    problems, (lower, upper) = check(coords, tets, volumes)
    vertex_error = abs(len(coords) - TARGET_VERTICES) / TARGET_VERTICES
    tet_error = abs(len(tets) - TARGET_TETS) / TARGET_TETS
    if vertex_error > TOLERANCE or tet_error > TOLERANCE:
        problems.append("%d vertices / %d tets, target %d / %d within %d%%: tune MESH_SIZE_M" % (
            len(coords), len(tets), TARGET_VERTICES, TARGET_TETS, round(100 * TOLERANCE)))
    if problems:
        os.remove(tmp)
        sys.exit("frog mesh refused:\n  " + "\n  ".join(problems))

    os.replace(tmp, msh)
    size = [upper[n] - lower[n] for n in range(3)]
    comment = "frog specimen converted from frog.msh by meshes/make_frog.py (%.3f x %.3f x %.3f m)" % tuple(size)
    write_veg(veg, coords, tets, comment)
    print("frog: %d vertices, %d tets, %.3f x %.3f x %.3f m" % ((len(coords), len(tets)) + tuple(size)))
    make_render_surface(args.gmsh, here)
    return 0


if __name__ == "__main__":
    sys.exit(main())
