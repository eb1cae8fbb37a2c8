#!/usr/bin/python3
"""Builds the organ-scale specimens (issues 23, 42): a liver-sized organ as a 52k-tet reference, as the
6k-tet physics mesh of the real-time scenes, and its fine render surface.

    /usr/bin/python3 meshes/make_liver.py [--gmsh gmsh] [--only NAME]

The shape is one smooth closed surface: the unit sphere mapped by a smooth function into a
liver-like wedge (a thick right lobe tapering to a thin left lobe, domed on top, 22 cm across),
with a ridge on its back, the "ligament": the vertices of that ridge (the slab of the mesh within
LIGAMENT_FRACTION of its extent from the minimum y, `fixedRegion.axis = 1`) are the fixed region,
as the coronary ligament and the bare area hold a liver to the diaphragm. The script writes the
mapped sphere as an STL (a fine triangulation of the smooth shape), lets Gmsh re-mesh that
surface and fill it with tets (VARIANTS: liver.geo, at most 4.6 mm; liver_coarse.geo, at most 14 mm
and graded by the surface's curvature), checks each result (every tet positive, one closed surface,
the tet count within 15% of its target, the ligament slab holding only ridge vertices), renumbers
the vertices and tets for locality and writes meshes/NAME.veg and the ligament's vertices as
meshes/NAME.bou (Vega's fixed-vertex list, 1-based, for side-by-side runs). The render surface
meshes/liver_surface.obj is the shape itself, the map of a finer icosphere (81 920 triangles,
outward, closed). Gmsh 4.8.4 (single thread, fixed seed) wrote the committed files; the script
reuses make_frog.py's reader, checks and writers. Frame: x from the right lobe to the left, y from
back to front, z up; metres.
"""

import argparse
import math
import os
import subprocess
import sys

from make_bar import signed_volume
from make_frog import GMSH_OPTIONS, check, oriented_surface, read_msh41, write_obj, write_veg

TOLERANCE = 0.15
SPHERE_LEVEL = 5  # icosphere subdivisions of the shape's STL (20480 triangles)
RENDER_LEVEL = 6  # the render surface: the shape itself at 6 subdivisions (81920 triangles)
MIN_RENDER_TRIANGLES = 50000


class Variant:
    """A committed tet mesh of the organ: its name (name.veg, name.bou, name.geo), largest tet edge,
    Gmsh's curvature sizing (elements per 2 pi of radius; 0: none), the tet count it must land near,
    and optionally a box meshed finer: (edge [m], (x0, x1, y0, y1, z0, z1) [m], grading distance [m])."""

    def __init__(self, name, mesh_size_m, curvature, target_tets, fine_box=None):
        self.name, self.mesh_size_m, self.curvature, self.target_tets = name, mesh_size_m, curvature, target_tets
        self.fine_box = fine_box


# The 52k-tet reference (issue 23), uniform; and the physics mesh of the real-time scenes (issue 42):
# coarse where the organ is thick, graded by the surface's curvature so that the thin left lobe and
# the rims keep several tets across (and the render surface lies within a quarter of a mean edge of
# the tets, as the embedding requires).
REFERENCE = Variant("liver", 0.0046, 0, 50000)
COARSE = Variant("liver_coarse", 0.014, 12, 6000)
# The palpation scene's physics mesh (issue 42): the coarse mesh, and the top of the thick right lobe
# where the hand palpates (make_palpation.py's sweep over x in [-7.5, -1.5] cm and the inclusion under
# it) meshed at FINE_BOX_EDGE_M, graded to the coarse size over 2 cm: a pad of 1 cm radius then spans
# several edges there (point_contact.hpp, "A pad").
FINE_BOX_EDGE_M = 0.006
PALPATION = Variant("liver_palpation", 0.014, 16, 11500,
                    (FINE_BOX_EDGE_M, (-0.09, 0.0, -0.025, 0.025, 0.0, 0.08), 0.02))
VARIANTS = (REFERENCE, COARSE, PALPATION)

HALF_LENGTH_M = 0.11  # x: right lobe tip to left lobe tip, 22 cm
HALF_DEPTH_M = 0.075  # y: back to front at mid length
HALF_THICKNESS_M = 0.06  # z: the right lobe's half thickness before tapering
DOME_M = 0.012  # the upper (diaphragmatic) surface bulges up this much at mid length
RIDGE_M = 0.012  # how far the ligament ridge stands out of the back
RIDGE_CENTRE = (-0.1, 0.25)  # (u, w) on the unit sphere: right of centre, upper back
RIDGE_WIDTH = (0.45, 0.35)
LIGAMENT_FRACTION = 0.04  # the fixed slab: the ridge's top 4% of the extent in y (~7 mm)


def liver_point(u, v, w):
    """The smooth map of a point (u, v, w) of the unit sphere onto the organ's surface [m]."""
    taper = 0.55 - 0.35 * u  # 0.9 at the right lobe's tip, 0.2 at the left's
    x = HALF_LENGTH_M * u
    y = HALF_DEPTH_M * v * (0.85 - 0.15 * u)
    z = HALF_THICKNESS_M * taper * w + DOME_M * (1.0 - u * u) * (1.0 - 0.5 * v * v)
    back = max(0.0, -v) ** 3  # C2: the ridge grows out of the back only
    du = (u - RIDGE_CENTRE[0]) / RIDGE_WIDTH[0]
    dw = (w - RIDGE_CENTRE[1]) / RIDGE_WIDTH[1]
    y -= RIDGE_M * back * math.exp(-du * du - dw * dw)
    return (x, y, z)


def icosphere(level):
    """Vertices on the unit sphere and triangles (outward), an icosahedron subdivided `level` times."""
    t = (1.0 + math.sqrt(5.0)) / 2.0
    points = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
              (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    points = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in points]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        middle = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in middle:
                p = [(points[a][n] + points[b][n]) / 2.0 for n in range(3)]
                norm = math.sqrt(sum(x * x for x in p))
                points.append(tuple(x / norm for x in p))
                middle[key] = len(points) - 1
            return middle[key]

        finer = []
        for a, b, c in faces:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            finer += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = finer
    return points, faces


def write_stl(path, points, faces):
    def normal(a, b, c):
        e1 = [b[n] - a[n] for n in range(3)]
        e2 = [c[n] - a[n] for n in range(3)]
        n = (e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0])
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        return tuple(x / length for x in n)

    lines = ["solid liver"]
    for face in faces:
        a, b, c = (points[k] for k in face)
        lines.append("facet normal %.9e %.9e %.9e" % normal(a, b, c))
        lines.append("outer loop")
        lines += ["vertex %.9e %.9e %.9e" % p for p in (a, b, c)]
        lines += ["endloop", "endfacet"]
    lines.append("endsolid liver")
    with open(path, "w", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


def fine_box_text(mesh_size_m, fine_box):
    """Gmsh's Box field for a variant's fine box, as the background size (none: no lines)."""
    if fine_box is None:
        return []
    edge_m, (x0, x1, y0, y1, z0, z1), grading_m = fine_box
    return [
        "// The fine box: this edge inside, the coarse size beyond the grading distance.",
        "Field[1] = Box;",
        "Field[1].VIn = %r;" % edge_m,
        "Field[1].VOut = %r;" % mesh_size_m,
        "Field[1].XMin = %r; Field[1].XMax = %r;" % (x0, x1),
        "Field[1].YMin = %r; Field[1].YMax = %r;" % (y0, y1),
        "Field[1].ZMin = %r; Field[1].ZMax = %r;" % (z0, z1),
        "Field[1].Thickness = %r;" % grading_m,
        "Background Field = 1;",
    ]


def geo_text(stl_name, mesh_size_m, curvature, fine_box=None):
    options = [o.replace("Mesh.MeshSizeFromCurvature = 0;", "Mesh.MeshSizeFromCurvature = %d;" % curvature)
               for o in GMSH_OPTIONS]
    return "\n".join([
        "// Liver-sized organ, written by meshes/make_liver.py: edit the script, not this file.",
        "// The smooth shape comes as an STL (%s, written by the script); Gmsh re-meshes it." % stl_name,
        *options,
        "Mesh.MeshSizeMin = 0;",
        "Mesh.MeshSizeMax = %r;" % mesh_size_m,
        "Mesh.ElementOrder = 1;",
        'Merge "%s";' % stl_name,
        "// One smooth surface: split into patches Gmsh can parametrize, then re-mesh them.",
        "ClassifySurfaces{Pi / 4, 1, 1, Pi};",
        "CreateGeometry;",
        "Surface Loop(1) = Surface{:};",
        "Volume(1) = {1};",
        *fine_box_text(mesh_size_m, fine_box),
        "",
    ])


def renumbered_for_locality(coords, tets):
    """Vertices in reverse Cuthill-McKee order (from a pseudo-peripheral vertex, neighbours by
    degree) and tets by their earliest vertex: Gmsh numbers the vertices as its Delaunay kernel
    inserted them, scattered through the volume, and a step that gathers and scatters by vertex
    then misses the cache on nearly every access (docs/BENCHMARKS.md, issue 23)."""
    n = len(coords)
    neighbours = [set() for _ in range(n)]
    for tet in tets:
        for a in tet:
            neighbours[a].update(b for b in tet if b != a)
    degree = [len(nb) for nb in neighbours]
    neighbours = [sorted(nb, key=lambda w: (degree[w], w)) for nb in neighbours]

    def sweep(root):
        level = {root: 0}
        order = [root]
        for v in order:
            for w in neighbours[v]:
                if w not in level:
                    level[w] = level[v] + 1
                    order.append(w)
        last = level[order[-1]]
        return order, min((v for v in order if level[v] == last), key=lambda v: (degree[v], v))

    _, root = sweep(0)  # the gmsh volume is one piece (check() refuses otherwise)
    _, root = sweep(root)
    order, _ = sweep(root)
    order.reverse()
    new_id = {v: k for k, v in enumerate(order)}
    tets = sorted((tuple(new_id[v] for v in tet) for tet in tets), key=lambda t: (min(t), sorted(t)))
    return [coords[v] for v in order], tets


def build(args, out_dir, name, mesh_size_m, curvature, target_tets, fine_box=None):
    """Meshes the shape into out_dir/name.veg and name.bou (its work files, and name.geo unless target_tets
    is None, in out_dir too); target_tets None: no count check."""
    stl_name = "liver_shape.stl"  # temporary: removed after meshing
    points, faces = icosphere(SPHERE_LEVEL)
    write_stl(os.path.join(out_dir, stl_name), [liver_point(*p) for p in points], faces)
    geo_name = name + ".geo" if target_tets is not None else "liver_size_tmp.geo"
    with open(os.path.join(out_dir, geo_name), "w", newline="\n") as out:
        out.write(geo_text(stl_name, mesh_size_m, curvature, fine_box))
    tmp = os.path.join(out_dir, "liver.msh.tmp")
    result = subprocess.run([args.gmsh, geo_name, "-3", "-nt", "1", "-format", "msh41", "-o",
                             os.path.basename(tmp)], cwd=out_dir, capture_output=True, text=True)
    os.remove(os.path.join(out_dir, stl_name))
    if target_tets is None:
        os.remove(os.path.join(out_dir, geo_name))
    if result.returncode != 0 or not os.path.exists(tmp):
        sys.stderr.write(result.stdout + result.stderr)
        sys.exit("gmsh failed")

    tags, coords, tets, _ = read_msh41(tmp)
    os.remove(tmp)
    index_of = {tag: n for n, tag in enumerate(tags)}
    tets = [tuple(index_of[tag] for tag in tet) for tet in tets]
    used = sorted(set(v for tet in tets for v in tet))  # drop the STL's nodes that no tet uses
    renumber = {v: n for n, v in enumerate(used)}
    coords = [coords[v] for v in used]
    tets = [tuple(renumber[v] for v in tet) for tet in tets]
    coords, tets = renumbered_for_locality(coords, tets)
    problems, (lower, upper) = check(coords, tets, 1)
    if target_tets is not None and abs(len(tets) - target_tets) > TOLERANCE * target_tets:
        problems.append("%d tets, target %d within %d%%: tune the variant's mesh size" % (len(tets), target_tets,
                                                                                      round(100 * TOLERANCE)))
    # The fixed slab must hold the ridge and nothing else: its vertices lie within the ridge's width.
    slab_top = lower[1] + LIGAMENT_FRACTION * (upper[1] - lower[1])
    fixed_ids = [n for n, c in enumerate(coords) if c[1] <= slab_top]
    fixed = [coords[n] for n in fixed_ids]
    ridge_x = HALF_LENGTH_M * RIDGE_CENTRE[0]
    if not 10 <= len(fixed) <= 1000 or any(abs(c[0] - ridge_x) > 2.0 * HALF_LENGTH_M * RIDGE_WIDTH[0] for c in fixed):
        problems.append("the ligament slab holds %d vertices, not only the ridge's: tune RIDGE_M or "
                        "LIGAMENT_FRACTION" % len(fixed))
    if problems:
        sys.exit("liver mesh %s refused:\n  " % name + "\n  ".join(problems))

    size = [upper[n] - lower[n] for n in range(3)]
    volume_l = 1e3 * sum(signed_volume(*(coords[v] for v in tet)) for tet in tets)
    comment = ("liver-sized organ by meshes/make_liver.py (%.3f x %.3f x %.3f m, %.2f l); fixed region: "
               "fixedRegion.axis = 1, fixedRegion.fraction = %g (%d vertices, the ligament ridge)"
               % (size[0], size[1], size[2], volume_l, LIGAMENT_FRACTION, len(fixed)))
    write_veg(os.path.join(out_dir, name + ".veg"), coords, tets, comment)
    with open(os.path.join(out_dir, name + ".bou"), "w", newline="\n") as out:  # the same vertices, for Vega
        ids = [str(n + 1) for n in fixed_ids]
        out.write("".join(",".join(ids[k:k + 8]) + ",\n" for k in range(0, len(ids), 8)))
    print("%s: %d vertices, %d tets, %.3f x %.3f x %.3f m, %.2f l, %d ligament vertices"
          % ((name, len(coords), len(tets)) + tuple(size) + (volume_l, len(fixed))))


def write_render_surface(out_dir):
    """The organ's own shape, finely: the mapped icosphere at RENDER_LEVEL, wound outward."""
    points, faces = icosphere(RENDER_LEVEL)
    coords = [tuple(round(c, 6) for c in liver_point(*p)) for p in points]
    triangles, problems = oriented_surface(coords, [tuple(f) for f in faces])
    if len(triangles) < MIN_RENDER_TRIANGLES:
        problems.append("%d triangles, fewer than %d" % (len(triangles), MIN_RENDER_TRIANGLES))
    if problems:
        sys.exit("liver render surface refused:\n  " + "\n  ".join(problems))
    write_obj(os.path.join(out_dir, "liver_surface.obj"), coords, triangles,
              "liver render surface by meshes/make_liver.py: the shape's map of an icosphere of %d subdivisions"
              % RENDER_LEVEL)
    print("liver render surface: %d triangles" % len(triangles))


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--gmsh", default="gmsh", help="the gmsh executable (4.8.4 made the committed files)")
    parser.add_argument("--mesh-size", type=float, default=None,
                        help="largest tet edge [m]: one mesh of that size (the scaling benchmark's sizes), "
                             "named liver, without the tet-count target")
    parser.add_argument("--curvature", type=int, default=0,
                        help="with --mesh-size: Gmsh's curvature sizing, elements per 2 pi of radius (0: none)")
    parser.add_argument("--output-dir", default=None, help="where the files go (default: meshes/)")
    parser.add_argument("--only", default=None, help="build only the variant of this name (and no render surface)")
    args = parser.parse_args()

    here = os.path.dirname(os.path.abspath(__file__))
    out_dir = os.path.abspath(args.output_dir) if args.output_dir else here
    if args.mesh_size is not None:
        build(args, out_dir, "liver", args.mesh_size, args.curvature, None)
        return 0
    for variant in VARIANTS:
        if args.only is not None and variant.name != args.only:
            continue
        build(args, out_dir, variant.name, variant.mesh_size_m, variant.curvature, variant.target_tets,
              variant.fine_box)
    if args.only is None:
        write_render_surface(out_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main())
