#!/usr/bin/python3
"""Renders a leaflux PLY (from `leaflux solve --ply` or `leaflux-grow`) to a PNG: a side and
a top view, each triangle coloured by its irradiance, both sides summed. Faces whose light
is negative (walls, ground, lamps written by leaflux-grow) are drawn as grey glass in the
side view only."""
import argparse

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from mpl_toolkits.mplot3d.art3d import Poly3DCollection


def read_ply(path):
    with open(path) as f:
        vertices = faces = 0
        for line in f:
            if line.startswith("element vertex"):
                vertices = int(line.split()[2])
            elif line.startswith("element face"):
                faces = int(line.split()[2])
            elif line.startswith("end_header"):
                break
        xyz = np.array([[float(v) for v in f.readline().split()] for _ in range(vertices)])
        rows = [f.readline().split() for _ in range(faces)]
    triangles = np.array([[int(r[1]), int(r[2]), int(r[3])] for r in rows])
    upper = np.array([float(r[4]) for r in rows])
    lower = np.array([float(r[5]) for r in rows])
    return xyz, triangles, upper, lower


def main(ply, png, title=None):
    xyz, triangles, upper, lower = read_ply(ply)
    total = upper + lower
    polygons = xyz[triangles]
    scenery = upper < 0
    if scenery.any():
        keep = ~scenery
        # Scenery far larger than the plants (an open ground) is left out.
        plant = polygons[keep].reshape(-1, 3)
        size = (plant.max(axis=0) - plant.min(axis=0)).max()
        scenery &= (polygons.max(axis=1) - polygons.min(axis=1)).max(axis=1) < 5 * size
    else:  # leave the ground out of the picture when it spans far beyond the plant
        extent = polygons.max(axis=1) - polygons.min(axis=1)
        keep = extent.max(axis=1) < 0.5 * (xyz.max(axis=0) - xyz.min(axis=0)).max()
    norm = matplotlib.colors.Normalize(vmin=0, vmax=max(np.percentile(total[keep], 99), 1e-9))
    colours = plt.cm.viridis(norm(total[keep]))
    fig = plt.figure(figsize=(12, 6))
    fig.subplots_adjust(left=0, right=0.9, bottom=0, top=0.92, wspace=0)
    if title:
        fig.suptitle(title)
    for i, (elevation, azimuth, view) in enumerate([(5, -60, "side"), (89, -90, "top")]):
        ax = fig.add_subplot(1, 2, i + 1, projection="3d")
        framed = polygons[keep]
        if view == "side" and scenery.any():
            ax.add_collection3d(Poly3DCollection(polygons[scenery], facecolors=(0.5, 0.5, 0.5, 0.06),
                                                 edgecolors=(0.3, 0.3, 0.3, 0.4), linewidths=0.5))
            framed = polygons
        ax.add_collection3d(Poly3DCollection(polygons[keep], facecolors=colours, linewidths=0))
        lo, hi = framed.reshape(-1, 3).min(axis=0), framed.reshape(-1, 3).max(axis=0)
        centre, half = (lo + hi) / 2, (hi - lo).max() / 2
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1), zoom=1.0 if framed is polygons else 1.3)
        ax.view_init(elev=elevation, azim=azimuth)
        ax.set_title(f"{view} view")
        ax.set_axis_off()
    mappable = plt.cm.ScalarMappable(norm=norm, cmap="viridis")
    fig.colorbar(mappable, ax=fig.axes, shrink=0.6, label="irradiance, both sides (W/m², first band)")
    fig.savefig(png, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=" ".join(__doc__.split()))
    parser.add_argument("ply", help="a PLY of leaflux solve --ply or leaflux-grow")
    parser.add_argument("png", help="the picture to write")
    parser.add_argument("title", nargs="?", help="its title (default: none)")
    args = parser.parse_args()
    main(args.ply, args.png, args.title)
