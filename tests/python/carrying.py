"""An independent carrying of per-vertex values, for the tests that check
meshtrim's: Open3D's closest point on the input surface and its
barycentric coordinates there."""

from __future__ import annotations

import numpy as np


def closest_corners_and_weights(vertices, faces, points):
    """For each point, the corners of the input face holding its closest
    point on the input surface and their barycentric weights there, by
    Open3D's ray-casting scene (in float32)."""
    import open3d as o3d

    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(
        o3d.core.Tensor(vertices.astype(np.float32)), o3d.core.Tensor(faces.astype(np.uint32))
    )
    found = scene.compute_closest_points(o3d.core.Tensor(points.astype(np.float32)))
    corners = faces[found["primitive_ids"].numpy()]
    u, v = found["primitive_uvs"].numpy().T
    return corners, np.stack([1 - u - v, u, v], axis=1)


def expected_at(vertices, faces, values, points):
    """`values` (per input vertex) at `points`, blended with the
    barycentric coordinates of each point's closest point on the input
    surface."""
    corners, weights = closest_corners_and_weights(vertices, faces, points)
    return np.einsum("ij,ijk->ik", weights, values[corners])


def kept_and_new(v_in, v_out):
    """Output vertex indices at an input vertex's exact position (and
    those input vertices), and the others."""
    at = {tuple(p): i for i, p in reversed(list(enumerate(v_in)))}
    kept = [(o, at[tuple(p)]) for o, p in enumerate(v_out) if tuple(p) in at]
    new = [o for o, p in enumerate(v_out) if tuple(p) not in at]
    out_kept, in_kept = (np.array(x, dtype=int) for x in zip(*kept))
    return out_kept, in_kept, np.array(new, dtype=int)
