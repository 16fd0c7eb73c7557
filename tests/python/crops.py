"""Crops of real scans: the shapes a user cuts out of a scan before
processing it (a ball round a region of interest, one side of a plane,
small holes punched where something was masked), as marginal inputs for
the tests and scripts/soak.py. Plain numpy, independent of meshtrim."""

from __future__ import annotations

from collections import defaultdict

import numpy as np

KINDS = ("ball", "half", "punched")


def compact(vertices, faces, keep_face):
    """The faces kept and the vertices they use, renumbered in order."""
    f = faces[keep_face]
    used = np.zeros(len(vertices), bool)
    used[f.ravel()] = True
    index = np.full(len(vertices), -1)
    index[used] = np.arange(used.sum())
    return vertices[used], index[f]


def crop(vertices, faces, rng, kind=None):
    """(kind, (V, F)): a random crop of the mesh. ``ball``: the faces within
    0.1-0.5 of the bounding-box diagonal of a random vertex; ``half``: the
    faces on one side of a random plane through the 20-80 % quantile of
    the vertices along its normal; ``punched``: the mesh less 5-40 balls of
    0.5-6 median edges round random vertices."""
    v, f = vertices, faces
    kind = kind or rng.choice(KINDS)
    if kind == "ball":
        diag = np.linalg.norm(v.max(0) - v.min(0))
        centre = v[rng.integers(len(v))]
        inside = np.linalg.norm(v - centre, axis=1) < rng.uniform(0.1, 0.5) * diag
        return kind, compact(v, f, inside[f].all(1))
    if kind == "half":
        normal = rng.normal(size=3)
        height = v @ (normal / np.linalg.norm(normal))
        cut = np.quantile(height, rng.uniform(0.2, 0.8))
        return kind, compact(v, f, (height[f] > cut).all(1))
    edge = np.median(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1))
    out = np.zeros(len(v), bool)
    for centre in v[rng.integers(len(v), size=rng.integers(5, 40))]:
        out |= np.linalg.norm(v - centre, axis=1) < rng.uniform(0.5, 6) * edge
    return kind, compact(v, f, ~out[f].any(1))


def pinched_vertices(faces) -> set[int]:
    """Vertices whose faces make more than one fan (faces round a vertex
    are one fan when they connect through edges at it)."""
    faces_of = defaultdict(list)
    for k, face in enumerate(faces):
        for x in face:
            faces_of[int(x)].append(k)
    pinched = set()
    for v, star in faces_of.items():
        parent = {k: k for k in star}

        def find(a):
            while parent[a] != a:
                parent[a] = parent[parent[a]]
                a = parent[a]
            return a

        by_other = defaultdict(list)
        for k in star:
            for w in faces[k]:
                if w != v:
                    by_other[int(w)].append(k)
        for ks in by_other.values():
            for k in ks[1:]:
                parent[find(k)] = find(ks[0])
        if len({find(k) for k in star}) > 1:
            pinched.add(v)
    return pinched
