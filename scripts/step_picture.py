"""Draws docs/img/step_curves.png: the B-spline curves of `meshtrim edges
CLOUD -o OUT.step`, as OpenCASCADE reads them back (through gmsh) and
samples them, over the cloud they came from, with the corners the STEP file
lists. Two panels: the blade with holes (seen along its normal) and the
Stanford bunny seen from below (its base holes).

    .venv-test/bin/python scripts/step_picture.py [MESHTRIM]

Runs the given binary (default target/release/meshtrim); writes the PNG with
numpy and zlib alone, so no plotting library is needed.
"""

from __future__ import annotations

import pathlib
import re
import struct
import subprocess
import sys
import tempfile
import zlib

import gmsh
import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
PANEL = (560, 420)
MARGIN = 24
COLOURS = [(31, 119, 180), (214, 39, 40), (44, 160, 44), (148, 103, 189), (255, 127, 14), (23, 190, 207)]


def read_ply_points(path):
    """Vertices of a PLY cloud, ASCII or binary, through Open3D."""
    import open3d

    return np.asarray(open3d.io.read_point_cloud(str(path)).points)


def step_curves(path):
    """Each curve's samples and the corners (CARTESIAN_POINTs not used as
    control points are not told apart by gmsh, so they are parsed)."""
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    try:
        gmsh.model.occ.importShapes(str(path))
        gmsh.model.occ.synchronize()
        curves = []
        for dim, tag in gmsh.model.getEntities(1):
            lo, hi = gmsh.model.getParametrizationBounds(dim, tag)
            u = np.linspace(lo[0], hi[0], 4001)
            curves.append(np.array(gmsh.model.getValue(dim, tag, u)).reshape(-1, 3))
    finally:
        gmsh.finalize()
    text = path.read_text()
    corners = [
        [float(v) for v in m.group(1).split(",")]
        for m in re.finditer(r"CARTESIAN_POINT\('corner',\(([^)]*)\)\)", text)
    ]
    return curves, np.array(corners).reshape(-1, 3)


def draw_panel(points, curves, corners, axes):
    """One panel: the cloud in grey, the curves in colour, the corners as
    black squares, all projected on `axes` (two rows) and fitted to PANEL."""
    w, h = PANEL
    image = np.full((h, w, 3), 255, np.uint8)
    flat = points @ axes.T
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    scale = min((w - 2 * MARGIN) / (hi[0] - lo[0]), (h - 2 * MARGIN) / (hi[1] - lo[1]))
    centre = (lo + hi) / 2

    def pixels(p):
        q = (p @ axes.T - centre) * scale
        return np.round(q[:, 0] + w / 2).astype(int), np.round(h / 2 - q[:, 1]).astype(int)

    def plot(p, colour, radius):
        x, y = pixels(p)
        for dx in range(-radius, radius + 1):
            for dy in range(-radius, radius + 1):
                xx, yy = x + dx, y + dy
                keep = (xx >= 0) & (xx < w) & (yy >= 0) & (yy < h)
                image[yy[keep], xx[keep]] = colour

    plot(points, (190, 190, 190), 0)
    for i, samples in enumerate(curves):
        plot(samples, COLOURS[i % len(COLOURS)], 1)
    plot(corners, (0, 0, 0), 3)
    return image


def write_png(path, image):
    h, w, _ = image.shape
    raw = b"".join(b"\x00" + image[row].tobytes() for row in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    path.write_bytes(png)


def plane_axes(points):
    """The cloud's two principal directions."""
    centred = points - points.mean(axis=0)
    return np.linalg.svd(centred, full_matrices=False)[2][:2]


def main():
    binary = sys.argv[1] if len(sys.argv) > 1 else str(ROOT / "target" / "release" / "meshtrim")
    bunny = ROOT.parent / "shared" / "data" / "stanford_bunny" / "bun_zipper.ply"
    cases = [
        (ROOT / "fixtures" / "meshes" / "blade_holes.ply", None),
        # The bunny's y axis is up: from below, x to the right, z up the page.
        (bunny, np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])),
    ]
    panels = []
    with tempfile.TemporaryDirectory() as work:
        for cloud, axes in cases:
            step = pathlib.Path(work) / "edges.step"
            subprocess.run([binary, "edges", str(cloud), "-o", str(step)], check=True, capture_output=True)
            points = read_ply_points(cloud)
            curves, corners = step_curves(step)
            panels.append(draw_panel(points, curves, corners, plane_axes(points) if axes is None else axes))
    out = ROOT / "docs" / "img" / "step_curves.png"
    write_png(out, np.hstack(panels))
    print(out)


if __name__ == "__main__":
    main()
