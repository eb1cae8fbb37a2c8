#!/usr/bin/python3
"""Renders the frog at rest and after tissue-demo (its --surface-obj output) side by side into a PNG.

Usage: docs/render_frog.py DEFORMED.obj OUTPUT.png
Needs Debian's python3-matplotlib (run with /usr/bin/python3). Rest positions come from meshes/frog.veg,
which numbers the vertices as the OBJ does.
"""
import pathlib
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[1]


def read_obj(path):
    vertices, faces = [], []
    for line in open(path):
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append(tuple(float(x) for x in parts[1:4]))
        elif parts and parts[0] == "f":
            faces.append(tuple(int(x) - 1 for x in parts[1:4]))
    return vertices, faces


def read_veg_vertices(path):
    lines = [l.strip() for l in open(path)]
    start = lines.index("*VERTICES")
    count = int(lines[start + 1].split()[0])
    return [tuple(float(x) for x in lines[start + 2 + i].split()[1:4]) for i in range(count)]


def draw(ax, vertices, faces, title):
    # Matplotlib's y-up scene is drawn with z up: map (x, y, z) -> (x, z, y).
    polys = [[(vertices[i][0], vertices[i][2], vertices[i][1]) for i in f] for f in faces]
    ax.add_collection3d(Poly3DCollection(polys, facecolor="#7fb069", edgecolor="#2d4a22", linewidth=0.15))
    ax.set_xlim(-0.01, 0.13)
    ax.set_ylim(-0.05, 0.09)
    ax.set_zlim(-0.09, 0.05)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=15, azim=-60)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x [m]", fontsize=7)
    ax.set_zlabel("y [m]", fontsize=7)
    ax.tick_params(labelsize=6)


def main():
    deformed, faces = read_obj(sys.argv[1])
    rest = read_veg_vertices(ROOT / "meshes" / "frog.veg")
    fig = plt.figure(figsize=(8, 4), dpi=120)
    draw(fig.add_subplot(1, 2, 1, projection="3d"), rest, faces, "frog.veg at rest (817 vertices, 2450 tets)")
    draw(fig.add_subplot(1, 2, 2, projection="3d"), deformed, faces, "after tissue-demo: tail end held, gravity")
    fig.tight_layout()
    fig.savefig(sys.argv[2])


if __name__ == "__main__":
    main()
