"""Jagged meshes of the synthetic clouds, built independently of the Rust
generator (``crates/testkit/src/synthetic/jagged.rs``): what scanner software
makes of a cloud, with the cloud's known boundary as ground truth for
``meshtrim clean``.

:func:`jagged_mesh` triangulates the samples in their parameter domain with
``scipy.spatial.Delaunay`` and keeps a triangle when its centroid lies in
the true region (so holes and notches open up) and its circumradius is at
most ``MAX_CIRCUMRADIUS`` spacings (the long slivers across a concave part
of the border or along the convex hull go). Faces are oriented along the
true normal; where the kept faces around a vertex form several fans (two
border loops touching there), all fans but the largest are removed, until
none is left; then only the largest edge-connected piece is kept and
unused vertices are dropped. The border runs through the outermost samples
and zig-zags between them, as a scan's border does.

:func:`border_error` measures a mesh's border as the Rust tests do: the
border loops' vertices and their edges' midpoints, distance to the true
boundary in spacings (the clouds' pitch is uniform, so the local spacing is
``cloud.spacing`` everywhere).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import Delaunay

import poisson

MAX_CIRCUMRADIUS = 2.0
"""Largest kept circumradius, in spacings."""


def circumradii(p):
    """Circumradii of 2D triangles ``p`` of shape (m, 3, 2)."""
    a = np.linalg.norm(p[:, 1] - p[:, 2], axis=1)
    b = np.linalg.norm(p[:, 2] - p[:, 0], axis=1)
    c = np.linalg.norm(p[:, 0] - p[:, 1], axis=1)
    e1, e2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    with np.errstate(divide="ignore"):
        return a * b * c / (4.0 * area)


def vertex_fans(faces, n_vertices):
    """For every vertex, its faces grouped into fans (faces around it joined
    through shared edges at it). Returns {vertex: [fan face lists]} for the
    vertices with more than one fan."""
    corners = {}
    for fi, f in enumerate(faces):
        for k in range(3):
            corners.setdefault(int(f[k]), []).append((fi, int(f[(k + 1) % 3]), int(f[(k + 2) % 3])))
    bad = {}
    for v, cs in corners.items():
        if len(cs) == 1:
            continue
        parent = list(range(len(cs)))

        def find(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        by_neighbour = {}
        for i, (_, a, b) in enumerate(cs):
            for w in (a, b):
                if w in by_neighbour:
                    parent[find(i)] = find(by_neighbour[w])
                else:
                    by_neighbour[w] = i
        groups = {}
        for i in range(len(cs)):
            groups.setdefault(find(i), []).append(cs[i][0])
        if len(groups) > 1:
            bad[v] = sorted(groups.values(), key=lambda g: (-len(g), min(g)))
    return bad


def remove_bow_ties(faces, n_vertices):
    """Removes every fan but the largest around vertices with several
    (ties: the one holding the lowest face index stays), repeatedly."""
    removed_total = 0
    while True:
        bad = vertex_fans(faces, n_vertices)
        if not bad:
            return faces, removed_total
        drop = set()
        for fans in bad.values():
            for fan in fans[1:]:
                drop.update(fan)
        keep = np.ones(len(faces), dtype=bool)
        keep[sorted(drop)] = False
        faces = faces[keep]
        removed_total += len(drop)


def largest_piece(faces):
    """The faces of the largest edge-connected piece."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e.sort(axis=1)
    owner = np.tile(np.arange(len(faces)), 3)
    _, inv = np.unique(e, axis=0, return_inverse=True)
    inv = inv.ravel()
    order = np.argsort(inv, kind="stable")
    same = inv[order][1:] == inv[order][:-1]
    a, b = owner[order][:-1][same], owner[order][1:][same]
    g = coo_matrix((np.ones(len(a)), (a, b)), shape=(len(faces), len(faces)))
    n, labels = connected_components(g, directed=False)
    if n == 1:
        return faces
    big = np.argmax(np.bincount(labels))
    return faces[labels == big]


def jagged_mesh(cloud, max_circumradius=MAX_CIRCUMRADIUS):
    """(V, F, source): the jagged mesh of ``cloud`` (see the module doc);
    ``source`` maps each vertex to its cloud point."""
    tri = Delaunay(cloud.uv)
    s = tri.simplices.astype(np.int64)
    p = cloud.uv[s]
    keep = cloud.region.contains(p.mean(axis=1)) & (circumradii(p) <= max_circumradius * cloud.spacing)
    s = s[keep]
    # Orient along the true normal (the mean of the vertices' normals).
    x = cloud.points[s]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    flip = np.einsum("ij,ij->i", n, cloud.normals[s].sum(axis=1)) < 0
    s[flip] = s[flip][:, ::-1]
    s, _ = remove_bow_ties(s, len(cloud.points))
    s = largest_piece(s)
    used = np.zeros(len(cloud.points), dtype=bool)
    used[s.ravel()] = True
    new_index = np.full(len(cloud.points), -1, dtype=np.int64)
    new_index[used] = np.arange(used.sum())
    source = np.flatnonzero(used)
    return cloud.points[source], new_index[s], source


def border_samples(vertices, faces):
    """The border's vertices, then the midpoints of its edges (each border
    vertex once per border edge leaving it)."""
    be = poisson.boundary_edges(faces)
    return np.concatenate([vertices[be[:, 0]], 0.5 * (vertices[be[:, 0]] + vertices[be[:, 1]])])


def border_error(vertices, faces, cloud, truth=None):
    """(mean, max) distance of the border samples to the true boundary, in
    spacings."""
    truth = truth or poisson.PolylineDistance(cloud.loops)
    d = truth(border_samples(vertices, faces)) / cloud.spacing
    return float(d.mean()), float(d.max())
