"""Screened-Poisson reconstruction with PyMeshLab, the density-trimming
baseline, and mesh metrics in numpy (+ scipy's cKDTree).

Reconstruction (``reconstruct``), as a user would do it in MeshLab:

1. the cloud's points only (the true normals are *not* given);
2. ``compute_normal_for_point_clouds`` (k = 10 neighbours, no smoothing),
   oriented consistently towards a viewpoint far out on the side of the
   cloud's mean normal (``viewpos``; the filter turns each normal to face
   it). On these open, gently curved sheets that orients every normal the
   same way as the truth (``normal_agreement`` checks it);
3. ``generate_surface_reconstruction_screened_poisson`` with depth 8 by
   default, the filter's other defaults (scale 1.1, samplespernode 1.5,
   pointweight 4) and ``preclean=False``: the synthetic clouds have no
   duplicate points and no invalid normals, so there is nothing to clean,
   and with it off the input PyMeshLab sees is exactly the cloud meshtrim
   reads.

The filter stores the Poisson sample density at each output vertex as the
vertex *quality* (PyMeshLab: ``vertex_scalar_array()``; saved to PLY as
``quality``). Density trimming (``density_trim``) removes the vertices whose
quality is below a quantile (5 % or 10 %) of all vertex qualities, and the
faces that use them, as MeshLab's "select by vertex quality" + "delete
selected vertices" or Open3D's quantile recipe do. It is done in numpy (the
same result as ``compute_selection_by_condition_per_vertex`` with
``condselect='(q < t)'`` then ``meshing_remove_selected_vertices``;
``density_trim_pymeshlab`` does that, for cross-checking).
"""

from __future__ import annotations

import numpy as np
import pymeshlab
from scipy.spatial import cKDTree


# --------------------------------------------------------------------------
# Reconstruction.


def estimate_normals(points, k=10):
    """Normals from PyMeshLab's ``compute_normal_for_point_clouds``, oriented
    towards a viewpoint far out along the cloud's mean normal (the normal of
    its best-fit plane, turned to +z when not vertical)."""
    pts = np.asarray(points, dtype=np.float64)
    c = pts.mean(axis=0)
    _, _, vt = np.linalg.svd(pts - c, full_matrices=False)
    axis = vt[2]
    if axis[np.argmax(np.abs(axis))] < 0:
        axis = -axis
    diag = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    view = c + 10.0 * diag * axis
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=pts))
    ms.compute_normal_for_point_clouds(k=k, smoothiter=0, flipflag=False, viewpos=view)
    return ms.current_mesh().vertex_normal_matrix().copy()


def normal_agreement(normals, true_normals):
    """Fraction of normals on the same side as the true ones (1.0 or 0.0
    when orientation is consistent)."""
    return float(np.mean(np.einsum("ij,ij->i", normals, true_normals) > 0))


def reconstruct(points, normals=None, depth=8, preclean=False, k=10, threads=2):
    """Screened Poisson. ``normals`` None: estimated with
    :func:`estimate_normals`. Returns (V (n, 3), F (m, 3), quality (n,)).
    With ``threads`` > 1 the output's vertex and face *order* varies from
    run to run (the geometry and the metrics do not); ``threads=1`` makes it
    byte-reproducible."""
    pts = np.asarray(points, dtype=np.float64)
    if normals is None:
        normals = estimate_normals(pts, k=k)
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=pts, v_normals_matrix=np.asarray(normals, dtype=np.float64)))
    ms.generate_surface_reconstruction_screened_poisson(depth=depth, preclean=preclean, threads=threads)
    m = ms.current_mesh()
    return (
        m.vertex_matrix().copy(),
        m.face_matrix().astype(np.int64),
        m.vertex_scalar_array().copy(),
    )


def save_mesh(path, vertices, faces, quality=None, binary=True):
    """Writes a mesh with PyMeshLab (format from the extension: .ply, .obj,
    .stl, ...). For PLY the quality is kept as a vertex property."""
    ms = pymeshlab.MeshSet()
    kw = {}
    if quality is not None:
        kw["v_scalar_array"] = np.asarray(quality, dtype=np.float64)
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.asarray(vertices, float), face_matrix=np.asarray(faces, np.int32), **kw))
    path = str(path)
    if path.lower().endswith(".ply"):
        ms.save_current_mesh(path, binary=binary, save_vertex_quality=quality is not None,
                             save_vertex_normal=False, save_vertex_color=False, save_face_color=False)
    else:
        ms.save_current_mesh(path)


def load_mesh(path):
    """Reads a mesh with PyMeshLab. Returns (V, F)."""
    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(path))
    m = ms.current_mesh()
    return m.vertex_matrix().copy(), m.face_matrix().astype(np.int64)


# --------------------------------------------------------------------------
# Density trimming (the baseline meshtrim must beat).


def remove_vertices(vertices, faces, remove):
    """Drops the vertices flagged in ``remove`` and every face using one;
    then drops unreferenced vertices. Returns (V, F, kept vertex indices)."""
    keep_face = ~np.any(remove[faces], axis=1)
    f = faces[keep_face]
    used = np.zeros(len(vertices), dtype=bool)
    used[f.ravel()] = True
    new_index = np.full(len(vertices), -1, dtype=np.int64)
    new_index[used] = np.arange(used.sum())
    return vertices[used], new_index[f], np.flatnonzero(used)


def density_trim(vertices, faces, quality, quantile):
    """Removes the vertices whose quality is below the ``quantile`` (e.g.
    0.05, 0.10) of all vertex qualities. Returns (V, F)."""
    t = np.quantile(quality, quantile)
    v, f, _ = remove_vertices(vertices, faces, quality < t)
    return v, f


def density_trim_pymeshlab(vertices, faces, quality, quantile):
    """The same with PyMeshLab's filters (for cross-checking)."""
    t = float(np.quantile(quality, quantile))
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=vertices, face_matrix=faces.astype(np.int32),
                               v_scalar_array=np.asarray(quality, np.float64)))
    ms.compute_selection_by_condition_per_vertex(condselect=f"(q < {t!r})")
    ms.meshing_remove_selected_vertices()
    ms.meshing_remove_unreferenced_vertices()
    m = ms.current_mesh()
    return m.vertex_matrix().copy(), m.face_matrix().astype(np.int64)


# --------------------------------------------------------------------------
# Metrics.


def edge_use(faces):
    """Undirected edges (sorted vertex pairs, unique) and how many faces use
    each."""
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    e.sort(axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    return edges, counts


def is_edge_manifold(faces):
    """True if no edge is used by more than two faces."""
    if len(faces) == 0:
        return True
    _, counts = edge_use(faces)
    return bool(counts.max() <= 2)


def orientation_consistent(faces):
    """True if every edge shared by two faces is traversed in opposite
    directions by them (no directed edge used twice)."""
    d = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    _, counts = np.unique(d, axis=0, return_counts=True)
    return bool(len(counts) == 0 or counts.max() == 1)


def boundary_edges(faces):
    """Directed boundary edges (a, b) as the faces traverse them: edges
    used by exactly one face."""
    d = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    s = np.sort(d, axis=1)
    _, inv, counts = np.unique(s, axis=0, return_inverse=True, return_counts=True)
    return d[counts[inv.ravel()] == 1]


def boundary_loops(faces):
    """Boundary loops as lists of vertex indices (closed, first not
    repeated), chained along the directed boundary edges. At a vertex where
    several loops touch, the walk takes the outgoing edges in order; every
    boundary edge ends up in exactly one loop."""
    be = boundary_edges(faces)
    out = {}
    for a, b in be:
        out.setdefault(int(a), []).append(int(b))
    loops = []
    while out:
        start = next(iter(out))
        loop = [start]
        cur = start
        while True:
            nxt = out[cur].pop()
            if not out[cur]:
                del out[cur]
            if nxt == start:
                break
            loop.append(nxt)
            cur = nxt
            if cur not in out:  # open chain (non-manifold input): stop
                break
        loops.append(loop)
    return loops


def sample_polyline(points, closed=True, step=1.0):
    """Points along a polyline, at most ``step`` apart (vertices included)."""
    p = np.asarray(points, float)
    q = np.roll(p, -1, axis=0) if closed else p[1:]
    p = p if closed else p[:-1]
    out = [p]
    seg = np.linalg.norm(q - p, axis=1)
    m = np.maximum(1, np.ceil(seg / step)).astype(int)
    for k in range(1, int(m.max())):
        sel = m > k
        t = (k / m[sel])[:, None]
        out.append(p[sel] + t * (q[sel] - p[sel]))
    return np.concatenate(out)


def border_samples(vertices, faces, step):
    """The mesh's border (every boundary edge) sampled at most ``step``
    apart."""
    be = boundary_edges(faces)
    if len(be) == 0:
        return np.zeros((0, 3))
    a, b = vertices[be[:, 0]], vertices[be[:, 1]]
    seg = np.linalg.norm(b - a, axis=1)
    m = np.maximum(1, np.ceil(seg / step)).astype(int)
    out = [a]
    for k in range(1, int(m.max())):
        sel = m > k
        t = (k / m[sel])[:, None]
        out.append(a[sel] + t * (b[sel] - a[sel]))
    return np.concatenate(out)


class PolylineDistance:
    """Exact distance from points to a set of closed, densely sampled
    polylines (the true boundary): the nearest samples by cKDTree, then the
    distance to the segments on both sides of each."""

    def __init__(self, loops, k=4):
        self.a = np.concatenate([np.asarray(lp, float) for lp in loops])
        self.b = np.concatenate([np.roll(np.asarray(lp, float), -1, axis=0) for lp in loops])
        self.prev = np.concatenate([np.roll(np.arange(len(lp)), 1) + off for lp, off in
                                    zip(loops, np.cumsum([0] + [len(lp) for lp in loops[:-1]]))])
        self.tree = cKDTree(self.a)
        self.k = k

    def __call__(self, q):
        q = np.asarray(q, float)
        if len(q) == 0:
            return np.zeros(0)
        _, idx = self.tree.query(q, k=self.k)
        best = np.full(len(q), np.inf)
        for j in range(self.k):
            for seg in (idx[:, j], self.prev[idx[:, j]]):
                a, b = self.a[seg], self.b[seg]
                ab = b - a
                t = np.einsum("ij,ij->i", q - a, ab) / np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
                t = np.clip(t, 0.0, 1.0)
                d = np.linalg.norm(q - (a + t[:, None] * ab), axis=1)
                best = np.minimum(best, d)
        return best


def mesh_area(vertices, faces):
    return float(triangle_areas(vertices, faces).sum())


def triangle_areas(vertices, faces):
    a, b, c = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    return 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)


def degenerate_triangles(vertices, faces, scale):
    """Number of triangles with area < 1e-12 * scale^2 (scale: e.g. the
    bounding-box diagonal) or with a repeated vertex index."""
    area = triangle_areas(vertices, faces)
    repeated = (faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2])
    return int(np.sum((area < 1e-12 * scale * scale) | repeated))


def max_distance_to_cloud(vertices, cloud_points):
    """Largest distance from a mesh vertex to its nearest cloud point."""
    if len(vertices) == 0:
        return 0.0
    d, _ = cKDTree(cloud_points).query(vertices)
    return float(d.max())


def max_distance_in_local_spacings(vertices, cloud_points, k=6):
    """Largest distance from a mesh vertex to its nearest cloud point, in
    that point's local spacing: the mean distance to its ``k`` nearest
    other points. A scan is sampled unevenly (the zippered bunny's base
    about twice as sparsely as the median), and a cut through a gap there
    lies about half the local gap from the cloud."""
    if len(vertices) == 0:
        return 0.0
    tree = cKDTree(cloud_points)
    d, nearest = tree.query(vertices)
    spacing = tree.query(cloud_points, k=k + 1)[0][:, 1:].mean(axis=1)
    return float((d / spacing[nearest]).max())


def border_metrics(vertices, faces, cloud):
    """Border accuracy of a mesh against a :class:`synthetic.Cloud`'s true
    boundary, in spacings: border -> truth mean and max (the border sampled
    every spacing/10 along its edges), truth -> border max (a missed hole
    shows here), loop counts, area ratio."""
    h = cloud.spacing
    loops = boundary_loops(faces)
    samples = border_samples(vertices, faces, h / 10)
    truth = PolylineDistance(cloud.loops)
    d = truth(samples) / h
    if len(samples):
        back, _ = cKDTree(samples).query(np.concatenate(cloud.loops))
        back_max = float(back.max() / h)
    else:
        back_max = float("inf")
    scale = float(np.linalg.norm(cloud.points.max(0) - cloud.points.min(0)))
    return {
        "loops": len(loops),
        "true_loops": len(cloud.loops),
        "border_mean": float(d.mean()) if len(d) else float("inf"),
        "border_max": float(d.max()) if len(d) else float("inf"),
        "truth_to_border_max": back_max,
        "area": mesh_area(vertices, faces),
        "area_ratio": mesh_area(vertices, faces) / cloud.area,
        "edge_manifold": is_edge_manifold(faces),
        "degenerate": degenerate_triangles(vertices, faces, scale),
        "max_vertex_to_cloud": max_distance_to_cloud(vertices, cloud.points) / h,
        "faces": int(len(faces)),
        "vertices": int(len(vertices)),
    }


def fan_boundary_loops(faces):
    """Boundary loops with pinched vertices split: at a vertex where
    several border loops touch, an incoming boundary edge continues with
    the outgoing one of the same fan of faces (found by turning around the
    vertex through the faces), so the count does not depend on the order of
    a walk. Needs an edge-manifold mesh."""
    faces = np.asarray(faces, np.int64)
    n = int(faces.max()) + 1 if len(faces) else 0
    d = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    third = np.concatenate([faces[:, 2], faces[:, 0], faces[:, 1]])
    key = d[:, 0] * n + d[:, 1]
    order = np.argsort(key)
    skey, sthird = key[order], third[order]
    twin = np.isin(d[:, 1] * n + d[:, 0], skey)
    border = d[~twin]
    nxt = {}
    for a, b in border:
        a, b = int(a), int(b)
        # Turn around b: from the face with a->b, the edge b->c; across it.
        i = np.searchsorted(skey, a * n + b)
        c = int(sthird[i])
        while True:
            j = np.searchsorted(skey, c * n + b)
            if j < len(skey) and skey[j] == c * n + b:
                c = int(sthird[j])
            else:
                break
        nxt[(a, b)] = (b, c)
    loops, seen = [], set()
    for e in nxt:
        if e in seen:
            continue
        loop = []
        while e not in seen:
            seen.add(e)
            loop.append(e[0])
            e = nxt[e]
        loops.append(loop)
    return loops


def min_angle(vertices, faces):
    """Smallest interior angle of the triangles, degrees."""
    x = vertices[faces]
    best = np.inf
    for k in range(3):
        a = x[:, (k + 1) % 3] - x[:, k]
        b = x[:, (k + 2) % 3] - x[:, k]
        c = np.einsum("ij,ij->i", a, b) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        best = min(best, float(np.degrees(np.arccos(np.clip(c, -1, 1))).min()))
    return best


def meshset(vertices, faces):
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vertex_matrix=np.asarray(vertices, np.float64),
                               face_matrix=np.asarray(faces, np.int32)))
    return ms


def pymeshlab_validity(vertices, faces):
    """What PyMeshLab says about a mesh: its topological measures
    (non-manifold edges and vertices, boundary loops as ``boundary_edges``
    and ``number_holes``, connected components), and what its repair filters
    would change: faces re-oriented by ``meshing_re_orient_faces_coherently``
    (compared face by face), vertices merged by
    ``meshing_remove_duplicate_vertices``, faces removed by
    ``meshing_remove_null_faces`` and
    ``meshing_remove_duplicate_faces``."""
    ms = meshset(vertices, faces)
    topo = ms.get_topological_measures()
    out = {
        "non_manifold_edges": int(topo["non_two_manifold_edges"]),
        "non_manifold_vertices": int(topo["non_two_manifold_vertices"]),
        "boundary_edges": int(topo["boundary_edges"]),
        "holes": int(topo["number_holes"]),
        "components": int(topo["connected_components_number"]),
    }
    f0 = ms.current_mesh().face_matrix().copy()
    ms.meshing_re_orient_faces_coherently()
    f1 = ms.current_mesh().face_matrix()
    # A coherent piece may come back unchanged or flipped as a whole; count
    # the faces turned against the majority of their piece (-1: the filter
    # changed more than the orientation).
    if f0.shape != f1.shape or not np.array_equal(np.sort(f0, 1), np.sort(f1, 1)):
        out["reoriented"] = -1
    else:
        kept = np.zeros(len(f0), dtype=bool)
        for k in range(3):
            kept |= np.all(np.roll(f0, k, axis=1) == f1, axis=1)
        flipped = int((~kept).sum())
        out["reoriented"] = min(flipped, len(f0) - flipped) if out["components"] == 1 else flipped
    ms = meshset(vertices, faces)
    n = ms.current_mesh().vertex_number()
    ms.meshing_remove_duplicate_vertices()
    out["duplicate_vertices"] = n - ms.current_mesh().vertex_number()
    ms = meshset(vertices, faces)
    m = ms.current_mesh().face_number()
    ms.meshing_remove_null_faces()
    out["null_faces"] = m - ms.current_mesh().face_number()
    ms.meshing_remove_duplicate_faces()
    out["duplicate_faces"] = m - out["null_faces"] - ms.current_mesh().face_number()
    return out
