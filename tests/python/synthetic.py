"""Synthetic validation clouds with known boundaries (numpy only).

The shapes are those of the Rust test kit's generators
(``crates/testkit/src/synthetic.rs``), so the Python validation and the Rust
accuracy tests measure the same parts; the random draws differ (numpy's PCG64
instead of splitmix64), so the points are not byte-identical to the Rust ones.

Every generator returns a :class:`Cloud`: points on a parametric surface
S(u, v) over a region of the (u, v) plane (an outer polygon minus circular
holes), the true unit normals, the true boundary loops as dense closed 3D
polylines (outer border first, then the holes), the true area of the part,
and the sampling pitch ``spacing``.

Sampling (as in Rust): a *jittered hex lattice*. Columns along u are
``sqrt(3)/2 * h`` apart, samples in a column ``h`` apart, every other column
shifted by h/2; the lattice is placed with a random phase, and every sample
is moved by an independent uniform offset of +-0.15 h on each parameter
axis. Samples outside the region are dropped, so the outermost samples lie
up to about one row inside the true boundary (on average about 0.4
spacings, as docs/edges.md measured), as on a real scan.

``spacing`` is the pitch h in the parameter domain; the surfaces stretch by
at most a few percent (``Cloud.stretch_max``), so h is also the 3D spacing
up to that. Distances "in spacings" divide by h.

The true area is the surface integral of |S_u x S_v| over the region,
computed by Green's theorem along very dense boundary polylines with
Gauss-Legendre quadrature across u (relative error below 1e-7).
"""

from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field

import numpy as np

JITTER = 0.15
"""Half-width of the uniform jitter, as a fraction of the pitch."""

BOUNDARY_OVERSAMPLING = 20
"""True boundary loops have at most spacing / 20 between samples."""


# --------------------------------------------------------------------------
# Surfaces: vectorised maps (u, v) -> xyz, arrays of shape (n,) -> (n, 3).


def plane(u, v):
    return np.stack([u, v, np.zeros_like(u)], axis=-1)


def saddle(a):
    def f(u, v):
        return np.stack([u, v, a * (u * u - v * v)], axis=-1)

    return f


def twisted_blade(span=600.0, half_chord=120.0, twist=math.pi / 6.0, camber=15.0):
    """The Rust ``BLADE``: u along the span (x), v along the chord; the chord
    section is a parabolic camber line of height ``camber`` at v = 0, rotated
    about the span axis by an angle growing linearly from -twist/2 at u = 0 to
    +twist/2 at u = span."""

    def f(u, v):
        theta = twist * (u / span - 0.5)
        s = v / half_chord
        c = camber * (1.0 - s * s)
        sn, cs = np.sin(theta), np.cos(theta)
        return np.stack([u, v * cs - c * sn, v * sn + c * cs], axis=-1)

    return f


def _tangents(surface, u, v, scale):
    e = 1e-6 * scale
    su = (surface(u + e, v) - surface(u - e, v)) / (2 * e)
    sv = (surface(u, v + e) - surface(u, v - e)) / (2 * e)
    return su, sv


def _normals(surface, u, v, scale):
    su, sv = _tangents(surface, u, v, scale)
    n = np.cross(su, sv)
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _area_element(surface, u, v, scale):
    su, sv = _tangents(surface, u, v, scale)
    return np.linalg.norm(np.cross(su, sv), axis=1)


def _stretch(surface, u, v, scale):
    """Largest singular value of the Jacobian."""
    su, sv = _tangents(surface, u, v, scale)
    e = np.einsum("ij,ij->i", su, su)
    f = np.einsum("ij,ij->i", su, sv)
    g = np.einsum("ij,ij->i", sv, sv)
    tr = 0.5 * (e + g)
    det = e * g - f * f
    return np.sqrt(tr + np.sqrt(np.maximum(tr * tr - det, 0.0)))


# --------------------------------------------------------------------------
# Regions of the parameter domain.


@dataclass
class Region:
    outer: np.ndarray  # (m, 2) simple polygon, first vertex not repeated
    holes: list = field(default_factory=list)  # [(cu, cv, radius)]

    def contains(self, uv: np.ndarray) -> np.ndarray:
        u, v = uv[:, 0], uv[:, 1]
        inside = np.zeros(len(uv), dtype=bool)
        a = self.outer
        b = np.roll(self.outer, -1, axis=0)
        for (au, av), (bu, bv) in zip(a, b):
            crosses = (av > v) != (bv > v)
            with np.errstate(divide="ignore", invalid="ignore"):
                x = au + (v - av) / (bv - av) * (bu - au)
            inside ^= crosses & (u < x)
        for cu, cv, r in self.holes:
            inside &= np.hypot(u - cu, v - cv) > r
        return inside

    def bounds(self):
        return self.outer.min(axis=0), self.outer.max(axis=0)

    def boundary_uv(self, step: float) -> list[np.ndarray]:
        """Closed polylines (first sample not repeated), at most ``step``
        apart: the outer polygon, then one per hole."""
        loops = []
        pts = []
        a = self.outer
        b = np.roll(self.outer, -1, axis=0)
        for p, q in zip(a, b):
            m = max(1, int(math.ceil(np.linalg.norm(q - p) / step)))
            t = np.arange(m)[:, None] / m
            pts.append(p + t * (q - p))
        loops.append(np.concatenate(pts))
        for cu, cv, r in self.holes:
            m = max(8, int(math.ceil(2 * math.pi * r / step)))
            t = 2 * math.pi * np.arange(m) / m
            loops.append(np.stack([cu + r * np.cos(t), cv + r * np.sin(t)], axis=1))
        return loops


def jittered_hex(region: Region, h: float, rng: np.random.Generator, jitter=JITTER):
    """Jittered hex-lattice samples (u, v) of ``region`` with pitch h."""
    lo, hi = region.bounds()
    row = 0.5 * math.sqrt(3.0)
    phase = rng.random(2)
    us = np.arange(lo[0] - phase[0] * row * h, hi[0] + h, row * h)
    j = np.arange(math.floor((lo[1] - h) / h), math.ceil((hi[1] + h) / h) + 1)
    col = np.arange(len(us))
    shift = phase[1] + 0.5 * (col % 2)
    uu = np.repeat(us, len(j))
    vv = ((j[None, :] + shift[:, None]) * h).ravel()
    uv = np.stack([uu, vv], axis=1)
    uv = uv + rng.uniform(-jitter, jitter, size=uv.shape) * h
    return uv[region.contains(uv)]


def _loop_integral(surface, loop_uv, u0, scale, gauss=24):
    """Signed integral of P dv around a closed uv polyline, with
    P(u, v) = int_{u0}^{u} J(s, v) ds (Green: area = closed integral P dv)."""
    x, w = np.polynomial.legendre.leggauss(gauss)
    q = np.roll(loop_uv, -1, axis=0)
    mid = 0.5 * (loop_uv + q)
    dv = q[:, 1] - loop_uv[:, 1]
    # Midpoint rule along the (very dense) loop; Gauss-Legendre across u.
    u, v = mid[:, 0], mid[:, 1]
    half = 0.5 * (u - u0)
    s = u0 + half[:, None] * (x[None, :] + 1.0)
    vv = np.broadcast_to(v[:, None], s.shape)
    j = _area_element(surface, s.ravel(), vv.ravel(), scale).reshape(s.shape)
    p = half * (j @ w)
    return float(np.sum(p * dv))


def true_area(surface, region: Region, scale: float) -> float:
    lo, _ = region.bounds()
    step = scale * 2e-4
    loops = region.boundary_uv(step)
    vals = [abs(_loop_integral(surface, lp, lo[0], scale)) for lp in loops]
    return vals[0] - sum(vals[1:])


# --------------------------------------------------------------------------
# Clouds.


@dataclass
class Cloud:
    name: str
    points: np.ndarray  # (n, 3) float64
    normals: np.ndarray  # (n, 3) true unit normals
    uv: np.ndarray  # (n, 2) parameter coordinates
    loops: list  # true boundary loops, each (m, 3), closed (first not repeated)
    area: float  # true area of the part
    spacing: float  # sampling pitch h
    stretch_max: float = 1.0  # largest stretch of the surface map over the points
    surface: object = None  # the map (u, v) -> xyz
    region: Region | None = None  # the part's region of the parameter domain

    @property
    def n(self) -> int:
        return len(self.points)


def _make(name, surface, region, h, seed, scale):
    rng = np.random.default_rng(seed)
    uv = jittered_hex(region, h, rng)
    u, v = uv[:, 0], uv[:, 1]
    pts = surface(u, v)
    nrm = _normals(surface, u, v, scale)
    loops = []
    for lp in region.boundary_uv(h / BOUNDARY_OVERSAMPLING):
        loops.append(surface(lp[:, 0], lp[:, 1]))
    return Cloud(
        name=name,
        points=pts,
        normals=nrm,
        uv=uv,
        loops=loops,
        area=true_area(surface, region, scale),
        spacing=h,
        stretch_max=float(_stretch(surface, u, v, scale).max()),
        surface=surface,
        region=region,
    )


BLADE_HOLES = ((150.0, 16.0), (300.0, 32.0), (450.0, 64.0))
"""The paper's hole radii (16, 32, 64 mm) at u = 150, 300, 450 mm (v = 0)."""


def blade_hole_radius(paper_radius: float, h: float) -> float:
    """The paper's radius, raised to 2.5 h so the sampling resolves the hole,
    capped at 60 mm so it fits in the chord (as Rust, which raises to 2 h)."""
    return max(paper_radius, min(2.5 * h, 60.0))


def blade_outline(n=24) -> np.ndarray:
    """Chord 240 mm at the root (u = 0), 210 mm at the tip (u = 600), curved
    leading edge; 2 x (n + 1) vertices (the Rust ``blade_outline``)."""
    u = 600.0 * np.arange(n + 1) / n
    te = -120.0 + 10.0 * (u / 600.0)
    le = 120.0 - 20.0 * (u / 600.0) ** 2
    return np.concatenate([np.stack([u, te], 1), np.stack([u, le], 1)[::-1]])


def blade(spacing: float = 4.0, seed: int = 1) -> Cloud:
    """Twisted blade-like sheet, 600 mm span x 210-240 mm chord, 30 deg twist,
    15 mm camber, three holes (BLADE_HOLES, radius >= 2.5 spacings).
    About 9,000 points at 4 mm, 2,300 at 8 mm."""
    holes = [(u, 0.0, blade_hole_radius(r, spacing)) for u, r in BLADE_HOLES]
    region = Region(blade_outline(), holes)
    return _make(f"blade {spacing:g} mm", twisted_blade(), region, spacing, seed, 600.0)


def notched_plate(spacing: float = 1.0, seed: int = 1) -> Cloud:
    """Flat 60h x 40h plate with a 15h x 15h rectangular notch in a long side
    and a round hole of radius 5h (the Rust ``notched_plate``)."""
    h = spacing
    outer = np.array(
        [[0, 0], [60, 0], [60, 40], [35, 40], [35, 25], [20, 25], [20, 40], [0, 40]],
        dtype=float,
    ) * h
    region = Region(outer, [(47.0 * h, 15.0 * h, 5.0 * h)])
    return _make(f"notched plate h={h:g}", plane, region, h, seed, 60.0 * h)


def curved_disc(spacing: float = 1.5, seed: int = 1) -> Cloud:
    """Saddle z = 0.004 (x^2 - y^2) over a disc of radius 50 (a 720-gon)
    with a hole of radius 12 at (15, -10) (the Rust ``curved_disc_with_hole``)."""
    t = 2 * math.pi * np.arange(720) / 720
    region = Region(np.stack([50 * np.cos(t), 50 * np.sin(t)], 1), [(15.0, -10.0, 12.0)])
    return _make(f"curved disc h={spacing:g}", saddle(0.004), region, spacing, seed, 100.0)


def cylinder(radius: float):
    """The cylinder of ``radius`` about the y axis, by arc length u round
    it from the top line (seen along z, u = 0 faces the viewer) and height
    v: x = r sin(u / r), z = r cos(u / r)."""

    def surface(u, v):
        t = np.asarray(u, dtype=float) / radius
        return np.stack([radius * np.sin(t), np.asarray(v, dtype=float) * np.ones_like(t), radius * np.cos(t)], axis=-1)

    return surface


def wrapped_cylinder(spacing: float = 1.5, seed: int = 1, wrap_deg: float = 110.0) -> Cloud:
    """A cylinder of radius 40 seen from the side, as one range scan sees
    it and more: the part covers +-``wrap_deg`` round the axis (past the
    silhouettes at +-90 degrees) and 60 high, with a hole of radius 6
    beside one silhouette (at 75 degrees). Its outer border wraps round the
    object: no plane sees it as a height field."""
    r = 40.0
    half = math.radians(wrap_deg) * r
    outer = np.array([[-half, 0.0], [half, 0.0], [half, 60.0], [-half, 60.0]])
    region = Region(outer, [(math.radians(75.0) * r, 30.0, 6.0)])
    return _make(f"wrapped cylinder h={spacing:g}", cylinder(r), region, spacing, seed, 2.0 * r)


# The validation suite's cases by name (blade-like surface
# with three holes at two resolutions, notched plate, curved disc with a
# hole); the trim and clean suites both run them.
VALIDATION_CASES = {
    "blade4": lambda: blade(4.0, 1),
    "blade8": lambda: blade(8.0, 1),
    "plate": lambda: notched_plate(1.0, 1),
    "disc": lambda: curved_disc(1.5, 1),
}


def validation_clouds(seed: int = 1) -> list[Cloud]:
    """The clouds of the validation suite."""
    return [
        blade(4.0, seed),
        blade(8.0, seed),
        notched_plate(1.0, seed),
        curved_disc(1.5, seed),
    ]


# --------------------------------------------------------------------------
# PLY output.


def write_cloud_ply(path, points, normals=None, single=False) -> None:
    """Binary little-endian PLY: ``double x y z`` (``float`` with
    ``single``, as many scanners write) (+ ``float nx ny nz``)."""
    kind, name = ("<f4", "float") if single else ("<f8", "double")
    points = np.ascontiguousarray(points, dtype=kind)
    n = len(points)
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {n}"]
    header += [f"property {name} {c}" for c in "xyz"]
    fields = [("x", kind), ("y", kind), ("z", kind)]
    if normals is not None:
        header += [f"property float n{c}" for c in "xyz"]
        fields += [("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")]
    header.append("end_header")
    rec = np.empty(n, dtype=fields)
    rec["x"], rec["y"], rec["z"] = points.T
    if normals is not None:
        nn = np.asarray(normals, dtype="<f4")
        rec["nx"], rec["ny"], rec["nz"] = nn.T
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(rec.tobytes())


def write_mesh_ply(path, vertices, faces, quality=None, double=False) -> None:
    """Binary little-endian PLY mesh: ``float x y z`` (``double`` with
    ``double=True``) (+ ``float quality``), ``list uchar int vertex_indices``."""
    v = np.asarray(vertices)
    f = np.asarray(faces, dtype="<i4")
    ctype, cfmt = ("double", "<f8") if double else ("float", "<f4")
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(v)}"]
    header += [f"property {ctype} {c}" for c in "xyz"]
    fields = [("x", cfmt), ("y", cfmt), ("z", cfmt)]
    if quality is not None:
        header.append("property float quality")
        fields.append(("quality", "<f4"))
    header += [f"element face {len(f)}", "property list uchar int vertex_indices", "end_header"]
    rec = np.empty(len(v), dtype=fields)
    rec["x"], rec["y"], rec["z"] = v.T
    if quality is not None:
        rec["quality"] = quality
    frec = np.empty(len(f), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    frec["n"] = 3
    frec["i"] = f
    with open(path, "wb") as fh:
        fh.write(("\n".join(header) + "\n").encode("ascii"))
        fh.write(rec.tobytes())
        fh.write(frec.tobytes())


def read_ply(path):
    """Reads a binary little-endian or ascii PLY with a vertex element (any
    scalar properties) and optionally a face element (``list`` of indices).
    Returns (dict of vertex property arrays, faces (m, 3) int array or None);
    polygons are fan-triangulated."""
    types = {
        "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
        "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
        "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
        "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
    }
    with open(path, "rb") as fh:
        data = fh.read()
    end = data.index(b"end_header") + len(b"end_header")
    end = data.index(b"\n", end) + 1
    lines = data[:end].decode("ascii").splitlines()
    fmt = None
    elements = []
    for ln in lines:
        p = ln.split()
        if not p:
            continue
        if p[0] == "format":
            fmt = p[1]
        elif p[0] == "element":
            elements.append([p[1], int(p[2]), []])
        elif p[0] == "property":
            elements[-1][2].append(p[1:])
    body = data[end:]
    verts, faces = {}, None
    if fmt == "ascii":
        tokens = body.split()
        pos = 0
        for name, count, props in elements:
            if name == "vertex":
                k = len(props)
                arr = np.array(tokens[pos:pos + k * count], dtype=float).reshape(count, k)
                pos += k * count
                verts = {pr[-1]: arr[:, i] for i, pr in enumerate(props)}
            elif name == "face":
                tris = []
                for _ in range(count):
                    m = int(tokens[pos])
                    idx = [int(t) for t in tokens[pos + 1:pos + 1 + m]]
                    pos += 1 + m
                    tris += [(idx[0], idx[i], idx[i + 1]) for i in range(1, m - 1)]
                faces = np.array(tris, dtype=np.int64).reshape(-1, 3)
            else:
                raise ValueError(f"ascii PLY element {name} not supported")
        return verts, faces
    if fmt != "binary_little_endian":
        raise ValueError(f"PLY format {fmt} not supported")
    pos = 0
    for name, count, props in elements:
        if all(pr[0] != "list" for pr in props):
            dt = np.dtype([(pr[-1], "<" + types[pr[0]]) for pr in props])
            arr = np.frombuffer(body, dtype=dt, count=count, offset=pos)
            pos += dt.itemsize * count
            if name == "vertex":
                verts = {k: arr[k].astype(float) for k in dt.names}
        elif name == "face" and len(props) == 1:
            _, ct, it, _ = props[0]
            ct, it = np.dtype("<" + types[ct]), np.dtype("<" + types[it])
            # Fast path: all triangles.
            dt = np.dtype([("n", ct), ("i", it, (3,))])
            arr = np.frombuffer(body, dtype=dt, count=count, offset=pos)
            if count and np.all(arr["n"] == 3):
                faces = arr["i"].astype(np.int64)
                pos += dt.itemsize * count
            else:
                tris = []
                for _ in range(count):
                    m = int(np.frombuffer(body, ct, 1, pos)[0])
                    idx = np.frombuffer(body, it, m, pos + ct.itemsize)
                    pos += ct.itemsize + m * it.itemsize
                    tris += [(idx[0], idx[i], idx[i + 1]) for i in range(1, m - 1)]
                faces = np.array(tris, dtype=np.int64).reshape(-1, 3)
        else:
            raise ValueError(f"PLY element {name} not supported")
    return verts, faces


def _selftest():
    import time

    for c in validation_clouds():
        t = time.time()
        nrm_ok = np.allclose(np.linalg.norm(c.normals, axis=1), 1.0)
        print(
            f"{c.name:20s} n={c.n:6d} area={c.area:12.3f} loops={len(c.loops)} "
            f"loop samples={sum(len(lp) for lp in c.loops)} stretch={c.stretch_max:.4f} "
            f"unit normals={nrm_ok} ({time.time() - t:.2f} s)"
        )
    # Exact areas where they are known.
    p = notched_plate(1.0)
    exact = 60 * 40 - 15 * 15 - math.pi * 25
    print("plate area error", p.area - exact)


if __name__ == "__main__":
    _selftest()

