//! Synthetic point clouds with ground truth, for testing boundary detection.
//!
//! Every generator returns a [`SyntheticCloud`]: sample points on a known
//! [`Surface`] over a known 2D [`Region`] of its parameter domain, with the
//! true normal, the parameter coordinates and the intended local spacing of
//! every point, and the true boundary curves densely sampled. Everything is
//! deterministic from a `u64` seed (an inline splitmix64 generator; the
//! library does not depend on `rand`), and nothing here does I/O.
//!
//! # Sampling
//!
//! Points are a *jittered grid*: columns of the parameter domain spaced by
//! the local spacing h(u) along u, and in each column samples spaced by h(u)
//! along v; every sample is then moved by an independent uniform offset of
//! ±[`JITTER`]·h on each axis (blue-noise-like, no two rows aligned, no
//! collinear runs). Samples that fall outside the region (beyond the outer
//! polygon, inside a hole) are removed. With a uniform spacing field the
//! columns form a square lattice of pitch h before jitter; a graded field
//! ([`SpacingField::Graded`]) gives columns of varying pitch whose rows do
//! not line up, which is fine. [`line_scan`] samples along straight scan
//! lines instead, and [`flat_grid`] is an unjittered axis-aligned lattice.
//! [`decimated_blade`] thins a dense jittered blade by Poisson-disk
//! elimination, as the paper's clouds were decimated from a dense scan:
//! blue noise with no lattice left in it.
//!
//! # Spacing
//!
//! `spacing[i]` is the *intended local resolution* at point i in 3D: the
//! grid pitch h at that place of the parameter domain times the largest
//! stretch of the surface map there (the largest singular value of its
//! Jacobian: exactly 1 for the plane and the cylinder, up to a few percent
//! above 1 on the saddle and the blade). It is the same notion as the
//! paper's "target resolution" (the paper's 4 mm cloud has mean β = 4.19 mm):
//! a jittered grid of pitch h has mean nearest-neighbour distance below h
//! and β = μ + 2σ close to h. On line scans it is the larger of the two
//! pitches (the distance between scan lines).
//!
//! # Ground truth
//!
//! The true boundary is the boundary of the region: the outer polygon and
//! the hole circles, as closed polylines with at most h_min/[`BOUNDARY_OVERSAMPLING`]
//! between consecutive samples (h_min the smallest pitch of the cloud).
//! [`SyntheticCloud::boundary_3d`] maps them onto the surface;
//! distances to the boundary are measured in 3D by
//! [`crate::synthetic::BoundaryIndex`]. [`SyntheticCloud::distance_to_boundary_uv`]
//! is the exact distance in the parameter domain (equal to the surface
//! distance on the plane and the cylinder, an approximation elsewhere).
//!
//! # Noise
//!
//! [`SyntheticCloud::with_noise`] moves every point along its true normal by
//! uniform(−p, p)·`spacing[i]`: p is a fraction of the intended local
//! resolution (p = 0.25 is the paper's "25 % of the cloud resolution"). The
//! paper moves points along the normal of the k-neighbourhood's best-fit
//! plane by a percentage of β_i; on these smooth surfaces the true normal is
//! that plane's normal up to curvature, and the intended spacing is β up to a
//! few percent.

use std::f64::consts::PI;

use kiddo::{ImmutableKdTree, SquaredEuclidean};

use crate::vec3::dist2;

pub mod jagged;
mod truth;

pub use truth::BoundaryIndex;

/// A position in the parameter domain.
pub type Uv = [f64; 2];
/// A position in 3D.
pub type P3 = [f64; 3];

/// Half-width of the uniform jitter, as a fraction of the local pitch.
pub const JITTER: f64 = 0.15;
/// Boundary curves are sampled at least this many times per smallest pitch.
pub const BOUNDARY_OVERSAMPLING: f64 = 20.0;

/// A small deterministic PRNG (splitmix64), enough for sampling jitter.
#[derive(Debug, Clone)]
pub struct SplitMix64(u64);

impl SplitMix64 {
    /// A generator seeded with `seed`.
    pub fn new(seed: u64) -> Self {
        Self(seed)
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }
}

/// A parametric surface: maps the parameter domain (u, v) to 3D.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Surface {
    /// (u, v, 0): exactly flat, axis-aligned.
    Plane,
    /// (u, v, a·(u² − v²)).
    Saddle {
        /// Curvature coefficient (1/length).
        a: f64,
    },
    /// A cylinder of the given radius about an axis parallel to y through
    /// (0, ·, radius): u is the arc length around the axis, v the position
    /// along it. Isometric to the plane.
    Cylinder {
        /// Radius (length).
        radius: f64,
    },
    /// A blade-like sheet: u runs along the span (x), v along the chord.
    /// The chord section is a parabolic camber line of height `camber` at
    /// v = 0 (zero at |v| = `half_chord`), rotated about the span axis by an
    /// angle growing linearly from −twist/2 at u = 0 to +twist/2 at u = span.
    TwistedBlade {
        /// Span length (u range 0..span).
        span: f64,
        /// Reference half chord of the camber parabola.
        half_chord: f64,
        /// Total twist over the span, radians.
        twist: f64,
        /// Camber height.
        camber: f64,
    },
}

impl Surface {
    /// The 3D point at `uv`.
    pub fn point(&self, uv: Uv) -> P3 {
        let [u, v] = uv;
        match *self {
            Surface::Plane => [u, v, 0.0],
            Surface::Saddle { a } => [u, v, a * (u * u - v * v)],
            Surface::Cylinder { radius } => {
                let t = u / radius;
                [radius * t.sin(), v, radius * (1.0 - t.cos())]
            }
            Surface::TwistedBlade {
                span,
                half_chord,
                twist,
                camber,
            } => {
                let theta = twist * (u / span - 0.5);
                let s = v / half_chord;
                let c = camber * (1.0 - s * s);
                let (sin, cos) = theta.sin_cos();
                [u, v * cos - c * sin, v * sin + c * cos]
            }
        }
    }

    /// The partial derivatives ∂/∂u and ∂/∂v at `uv`.
    pub fn tangents(&self, uv: Uv) -> (P3, P3) {
        let [u, v] = uv;
        match *self {
            Surface::Plane => ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            Surface::Saddle { a } => ([1.0, 0.0, 2.0 * a * u], [0.0, 1.0, -2.0 * a * v]),
            Surface::Cylinder { radius } => {
                let t = u / radius;
                ([t.cos(), 0.0, t.sin()], [0.0, 1.0, 0.0])
            }
            Surface::TwistedBlade {
                span,
                half_chord,
                twist,
                camber,
            } => {
                let theta = twist * (u / span - 0.5);
                let dtheta = twist / span;
                let s = v / half_chord;
                let c = camber * (1.0 - s * s);
                let dc = -2.0 * camber * s / half_chord;
                let (sin, cos) = theta.sin_cos();
                let du = [
                    1.0,
                    (-v * sin - c * cos) * dtheta,
                    (v * cos - c * sin) * dtheta,
                ];
                let dv = [0.0, cos - dc * sin, sin + dc * cos];
                (du, dv)
            }
        }
    }

    /// The unit normal at `uv` (∂u × ∂v, normalised). Exactly (0, 0, 1) on
    /// the plane.
    pub fn normal(&self, uv: Uv) -> P3 {
        if *self == Surface::Plane {
            return [0.0, 0.0, 1.0];
        }
        let (a, b) = self.tangents(uv);
        normalised(cross(a, b))
    }

    /// Largest stretch of the map at `uv`: the largest singular value of
    /// its Jacobian (how long a unit step in the parameter domain can be in
    /// 3D).
    pub fn stretch(&self, uv: Uv) -> f64 {
        let (a, b) = self.tangents(uv);
        let (e, f, g) = (dot(a, a), dot(a, b), dot(b, b));
        let tr = 0.5 * (e + g);
        let det = e * g - f * f;
        (tr + (tr * tr - det).max(0.0).sqrt()).sqrt()
    }
}

/// A circular hole in the parameter domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Circle {
    /// Centre (u, v).
    pub centre: Uv,
    /// Radius.
    pub radius: f64,
}

/// A region of the parameter domain: a simple polygon minus disjoint
/// circular holes lying strictly inside it.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    /// Outer boundary, a simple polygon (first vertex not repeated).
    pub outer: Vec<Uv>,
    /// Circular holes.
    pub holes: Vec<Circle>,
}

impl Region {
    /// An axis-aligned rectangle.
    pub fn rectangle(min: Uv, max: Uv) -> Self {
        Self {
            outer: vec![min, [max[0], min[1]], max, [min[0], max[1]]],
            holes: Vec::new(),
        }
    }

    /// True if `p` lies inside the outer polygon and outside every hole.
    pub fn contains(&self, p: Uv) -> bool {
        let mut inside = false;
        let n = self.outer.len();
        for i in 0..n {
            let a = self.outer[i];
            let b = self.outer[(i + 1) % n];
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if p[0] < x {
                    inside = !inside;
                }
            }
        }
        inside && self.holes.iter().all(|h| dist2d(p, h.centre) > h.radius)
    }

    /// Exact distance from `p` to the region's boundary, in the parameter
    /// domain.
    pub fn distance_to_boundary(&self, p: Uv) -> f64 {
        let n = self.outer.len();
        let mut best = f64::INFINITY;
        for i in 0..n {
            best = best.min(dist_to_segment2(p, self.outer[i], self.outer[(i + 1) % n]));
        }
        for h in &self.holes {
            best = best.min((dist2d(p, h.centre) - h.radius).abs());
        }
        best
    }

    /// Bounding box (min, max) of the outer polygon.
    pub fn bounds(&self) -> (Uv, Uv) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &self.outer {
            for a in 0..2 {
                lo[a] = lo[a].min(p[a]);
                hi[a] = hi[a].max(p[a]);
            }
        }
        (lo, hi)
    }

    /// The boundary curves as closed polylines (first sample not repeated)
    /// with at most `step` between consecutive samples: the outer polygon
    /// first, then one curve per hole.
    pub fn boundary_curves(&self, step: f64) -> Vec<Vec<Uv>> {
        let mut curves = Vec::with_capacity(1 + self.holes.len());
        let n = self.outer.len();
        let mut outer = Vec::new();
        for i in 0..n {
            let a = self.outer[i];
            let b = self.outer[(i + 1) % n];
            let m = (dist2d(a, b) / step).ceil().max(1.0) as usize;
            for j in 0..m {
                let t = j as f64 / m as f64;
                outer.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        curves.push(outer);
        for h in &self.holes {
            let m = (2.0 * PI * h.radius / step).ceil().max(8.0) as usize;
            curves.push(
                (0..m)
                    .map(|j| {
                        let t = 2.0 * PI * j as f64 / m as f64;
                        [
                            h.centre[0] + h.radius * t.cos(),
                            h.centre[1] + h.radius * t.sin(),
                        ]
                    })
                    .collect(),
            );
        }
        curves
    }
}

/// The intended sample pitch over the parameter domain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpacingField {
    /// The same pitch everywhere.
    Uniform(f64),
    /// Pitch varying geometrically (smoothly) from `h0` at u ≤ `u0` to `h1`
    /// at u ≥ `u1`.
    Graded {
        /// Pitch at the start.
        h0: f64,
        /// Pitch at the end.
        h1: f64,
        /// Where the grading starts.
        u0: f64,
        /// Where it ends.
        u1: f64,
    },
}

impl SpacingField {
    /// The pitch at parameter position `u`.
    pub fn at(&self, u: f64) -> f64 {
        match *self {
            SpacingField::Uniform(h) => h,
            SpacingField::Graded { h0, h1, u0, u1 } => {
                let t = ((u - u0) / (u1 - u0)).clamp(0.0, 1.0);
                h0 * (h1 / h0).powf(t)
            }
        }
    }

    /// The smallest pitch.
    pub fn min(&self) -> f64 {
        match *self {
            SpacingField::Uniform(h) => h,
            SpacingField::Graded { h0, h1, .. } => h0.min(h1),
        }
    }
}

/// A sampled surface with its ground truth.
#[derive(Debug, Clone)]
pub struct SyntheticCloud {
    /// A short name for reports.
    pub name: String,
    /// Sample points in 3D.
    pub points: Vec<P3>,
    /// True unit surface normal at each point.
    pub normals: Vec<P3>,
    /// Parameter-domain coordinates of each point.
    pub uv: Vec<Uv>,
    /// Intended local resolution at each point, in 3D (see the module doc).
    pub spacing: Vec<f64>,
    /// True boundary curves in the parameter domain, closed polylines
    /// (first sample not repeated), densely sampled.
    pub boundary: Vec<Vec<Uv>>,
    /// The surface the points lie on.
    pub surface: Surface,
    /// The sampled region of the parameter domain.
    pub region: Region,
    /// The intended pitch over the parameter domain (before the surface's
    /// stretch).
    pub field: SpacingField,
}

impl SyntheticCloud {
    fn build(
        name: String,
        surface: Surface,
        region: Region,
        field: SpacingField,
        samples: Vec<(Uv, f64)>,
    ) -> Self {
        let mut cloud = SyntheticCloud {
            name,
            points: Vec::with_capacity(samples.len()),
            normals: Vec::with_capacity(samples.len()),
            uv: Vec::with_capacity(samples.len()),
            spacing: Vec::with_capacity(samples.len()),
            boundary: region.boundary_curves(field.min() / BOUNDARY_OVERSAMPLING),
            surface,
            region,
            field,
        };
        for (uv, h) in samples {
            cloud.points.push(surface.point(uv));
            cloud.normals.push(surface.normal(uv));
            cloud.uv.push(uv);
            cloud.spacing.push(h * surface.stretch(uv));
        }
        cloud
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True if there are no points.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Exact distance from `uv` to the true boundary in the parameter
    /// domain.
    pub fn distance_to_boundary_uv(&self, uv: Uv) -> f64 {
        self.region.distance_to_boundary(uv)
    }

    /// The boundary curves mapped to 3D, with the intended local
    /// resolution at each sample (the pitch there times the surface's
    /// stretch).
    pub fn boundary_3d(&self) -> Vec<Vec<(P3, f64)>> {
        self.boundary
            .iter()
            .map(|curve| {
                curve
                    .iter()
                    .map(|&uv| (self.surface.point(uv), self.spacing_at(uv)))
                    .collect()
            })
            .collect()
    }

    /// Intended local resolution at a parameter position (3D units): the
    /// pitch of the field there times the surface's stretch.
    pub fn spacing_at(&self, uv: Uv) -> f64 {
        self.field.at(uv[0]) * self.surface.stretch(uv)
    }

    /// The points moved along their true normals by uniform(−p, p) times
    /// their intended spacing (p a fraction: 0.25 = 25 % of the local
    /// resolution). The same seed gives the same unit draws for every p, so
    /// a sweep over p scales one noise pattern.
    pub fn with_noise(&self, p: f64, seed: u64) -> Vec<P3> {
        let mut rng = SplitMix64::new(seed ^ 0x6e6f_6973_655f_5f5f);
        self.points
            .iter()
            .zip(&self.normals)
            .zip(&self.spacing)
            .map(|((x, n), h)| {
                let d = rng.range(-1.0, 1.0) * p * h;
                [x[0] + d * n[0], x[1] + d * n[1], x[2] + d * n[2]]
            })
            .collect()
    }

    /// The points as a range scanner looking along `direction` would
    /// report them with its depth rounded to multiples of `step` (3D
    /// units), as depth cameras quantise it: each point moves along the
    /// line of sight to the nearest depth level, by at most `step`/2.
    /// Where the surface is inclined to the line of sight the points form
    /// terraces, one per level.
    pub fn with_quantised_depth(&self, direction: P3, step: f64) -> Vec<P3> {
        let d = normalised(direction);
        self.points
            .iter()
            .map(|x| {
                let depth = dot(*x, d);
                let moved = (depth / step).round() * step - depth;
                [
                    x[0] + moved * d[0],
                    x[1] + moved * d[1],
                    x[2] + moved * d[2],
                ]
            })
            .collect()
    }

    /// The points as a depth camera at `origin` would report them with
    /// its range (distance from `origin`) rounded to multiples of `step`:
    /// each point moves along its own line of sight from `origin`.
    pub fn with_quantised_range(&self, origin: P3, step: f64) -> Vec<P3> {
        self.points
            .iter()
            .map(|x| {
                let ray = [x[0] - origin[0], x[1] - origin[1], x[2] - origin[2]];
                let range = dot(ray, ray).sqrt();
                let scale = (range / step).round() * step / range;
                [0, 1, 2].map(|a| origin[a] + scale * ray[a])
            })
            .collect()
    }

    /// The normalised mean of the true normals: where a scanner facing
    /// the whole cloud would look from.
    pub fn mean_normal(&self) -> P3 {
        let sum = self
            .normals
            .iter()
            .fold([0.0; 3], |s, n| [s[0] + n[0], s[1] + n[1], s[2] + n[2]]);
        normalised(sum)
    }

    /// The points moved along a line of sight `direction` (a range
    /// scanner's depth noise) by uniform(−p, p) times their intended
    /// spacing; [`SyntheticCloud::with_noise`] moves them along their
    /// normals instead, with the same draws for the same seed.
    pub fn with_depth_noise(&self, direction: P3, p: f64, seed: u64) -> Vec<P3> {
        let d = normalised(direction);
        let mut rng = SplitMix64::new(seed ^ 0x6e6f_6973_655f_5f5f);
        self.points
            .iter()
            .zip(&self.spacing)
            .map(|(x, h)| {
                let m = rng.range(-1.0, 1.0) * p * h;
                [x[0] + m * d[0], x[1] + m * d[1], x[2] + m * d[2]]
            })
            .collect()
    }

    /// The points moved within the surface's tangent plane, in a random
    /// direction, by uniform(0, p) times their intended spacing: sampling
    /// jitter rather than measurement noise (a scanner's timing or
    /// encoder error along its lines).
    pub fn with_tangent_noise(&self, p: f64, seed: u64) -> Vec<P3> {
        let mut rng = SplitMix64::new(seed ^ 0x7461_6e67_656e_7421);
        self.points
            .iter()
            .zip(&self.uv)
            .zip(&self.spacing)
            .map(|((x, &uv), h)| {
                let (tu, tv) = self.surface.tangents(uv);
                let (tu, tv) = (normalised(tu), normalised(tv));
                let angle = rng.range(0.0, std::f64::consts::TAU);
                let m = rng.unit() * p * h;
                let (c, s) = (m * angle.cos(), m * angle.sin());
                [0, 1, 2].map(|a| x[a] + c * tu[a] + s * tv[a])
            })
            .collect()
    }
}

/// A range scan of `truth` as the tests see it, with depth quantised in
/// terraces 1.5 spacings apart: what the scanner was, the points it
/// reports, and the view it was seen along.
pub struct RangeScan {
    /// "orthographic" or "from a camera".
    pub scanner: &'static str,
    /// The reported points (each moved along its line of sight).
    pub points: Vec<P3>,
    /// The scanner's line of sight.
    pub view: trim::View,
}

/// Two range scans of `truth` whose line of sight is inclined 40° to its
/// mean normal: an orthographic scanner (depth quantised along the sight)
/// and a camera 3,000 units back along it (range quantised from the
/// camera), with terraces 1.5 spacings (`spacing`) apart.
pub fn range_scans(truth: &SyntheticCloud, spacing: f64) -> [RangeScan; 2] {
    let sight = tilted(truth.mean_normal(), 40f64.to_radians());
    let n = truth.len() as f64;
    let centre: P3 = std::array::from_fn(|a| truth.points.iter().map(|p| p[a]).sum::<f64>() / n);
    let camera: P3 = std::array::from_fn(|a| centre[a] - 3000.0 * sight[a]);
    [
        RangeScan {
            scanner: "orthographic",
            points: truth.with_quantised_depth(sight, 1.5 * spacing),
            view: trim::View::Along(sight),
        },
        RangeScan {
            scanner: "from a camera",
            points: truth.with_quantised_range(camera, 1.5 * spacing),
            view: trim::View::From(camera),
        },
    ]
}

/// The unit vector `normal` turned by `angle` (radians) towards the x
/// axis, or the y axis when `normal` is nearly along x: a line of sight
/// inclined to a surface whose mean normal is `normal`.
pub fn tilted(normal: P3, angle: f64) -> P3 {
    let helper = if normal[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let along = dot(helper, normal);
    let e = normalised([0, 1, 2].map(|a| helper[a] - along * normal[a]));
    let (s, c) = angle.sin_cos();
    [0, 1, 2].map(|a| c * normal[a] + s * e[a])
}

/// Jittered-grid samples of `region` with pitch `field` (see the module
/// doc): each sample with its pitch. `jitter` is the half-width of the
/// uniform offset as a fraction of the pitch; `phase`, in pitches, places
/// the lattice (random when `None`).
pub fn jittered_grid(
    region: &Region,
    field: SpacingField,
    jitter: f64,
    phase: Option<Uv>,
    seed: u64,
) -> Vec<(Uv, f64)> {
    let mut rng = SplitMix64::new(seed);
    let (lo, hi) = region.bounds();
    let phase = phase.unwrap_or_else(|| [rng.unit(), rng.unit()]);
    let mut out = Vec::new();
    let row = 0.5 * 3f64.sqrt();
    let mut u = lo[0] - phase[0] * row * field.at(lo[0]);
    let mut column = 0u64;
    while u <= hi[0] + field.at(hi[0]) {
        let h = field.at(u);
        let shift = phase[1] + 0.5 * (column % 2) as f64;
        let first = ((lo[1] - h) / h).floor() as i64;
        let last = ((hi[1] + h) / h).ceil() as i64;
        for j in first..=last {
            let v = (j as f64 + shift) * h;
            let p = [
                u + rng.range(-jitter, jitter) * h,
                v + rng.range(-jitter, jitter) * h,
            ];
            if region.contains(p) {
                out.push((p, h));
            }
        }
        u += row * field.at(u + 0.5 * row * h);
        column += 1;
    }
    out
}

fn jittered(
    name: String,
    surface: Surface,
    region: Region,
    field: SpacingField,
    seed: u64,
) -> SyntheticCloud {
    jittered_by(name, surface, region, field, JITTER, seed)
}

/// [`jittered`] with the jitter's half-width chosen.
fn jittered_by(
    name: String,
    surface: Surface,
    region: Region,
    field: SpacingField,
    jitter: f64,
    seed: u64,
) -> SyntheticCloud {
    let samples = jittered_grid(&region, field, jitter, None, seed);
    SyntheticCloud::build(name, surface, region, field, samples)
}

/// Hole radii of [`plane_with_holes`], in units of the pitch h: 2β, 4β and
/// 8β with β ≈ 1.3·h (the local resolution of a jittered grid).
pub const PLANE_HOLE_RADII: [f64; 3] = [2.6, 5.2, 10.4];

/// The plane z = 0 over an 80h × 50h rectangle with three circular holes
/// of radius [`PLANE_HOLE_RADII`]·h (h = `spacing`). About 3,600 points.
pub fn plane_with_holes(spacing: f64, seed: u64) -> SyntheticCloud {
    let h = spacing;
    let mut region = Region::rectangle([0.0, 0.0], [80.0 * h, 50.0 * h]);
    for (cx, r) in [(12.0, PLANE_HOLE_RADII[0]), (30.0, PLANE_HOLE_RADII[1])]
        .into_iter()
        .chain([(58.0, PLANE_HOLE_RADII[2])])
    {
        region.holes.push(Circle {
            centre: [cx * h, 25.0 * h],
            radius: r * h,
        });
    }
    jittered(
        format!("plane, holes 2β/4β/8β, h={h}"),
        Surface::Plane,
        region,
        SpacingField::Uniform(h),
        seed,
    )
}

/// The plane z = 0 over a 60h × 40h plate with a 15h × 15h rectangular
/// notch in one long side (two concave corners) and a hole of radius 5h.
pub fn notched_plate(spacing: f64, seed: u64) -> SyntheticCloud {
    jittered(
        format!("notched plate, h={spacing}"),
        Surface::Plane,
        notched_plate_region(spacing),
        SpacingField::Uniform(spacing),
        seed,
    )
}

/// The region of [`notched_plate`] in units of `h`.
fn notched_plate_region(h: f64) -> Region {
    let outer = [
        [0.0, 0.0],
        [60.0, 0.0],
        [60.0, 40.0],
        [35.0, 40.0],
        [35.0, 25.0],
        [20.0, 25.0],
        [20.0, 40.0],
        [0.0, 40.0],
    ];
    Region {
        outer: outer.iter().map(|p| [p[0] * h, p[1] * h]).collect(),
        holes: vec![Circle {
            centre: [47.0 * h, 15.0 * h],
            radius: 5.0 * h,
        }],
    }
}

/// The saddle z = 0.004·(x² − y²) over [−50, 50]² (slopes up to 0.4) with
/// a hole of radius 12 at (15, −10).
pub fn saddle_with_hole(spacing: f64, seed: u64) -> SyntheticCloud {
    let mut region = Region::rectangle([-50.0, -50.0], [50.0, 50.0]);
    region.holes.push(Circle {
        centre: [15.0, -10.0],
        radius: 12.0,
    });
    jittered(
        format!("saddle with hole, h={spacing}"),
        Surface::Saddle { a: 0.004 },
        region,
        SpacingField::Uniform(spacing),
        seed,
    )
}

/// A curved disc with a hole and no corner: the saddle z = 0.004·(x² − y²)
/// over a disc of radius 50 (a 720-gon, as smooth as the sampling can tell),
/// with a hole of radius 12 at (15, −10).
pub fn curved_disc_with_hole(spacing: f64, seed: u64) -> SyntheticCloud {
    jittered(
        format!("curved disc with hole, h={spacing}"),
        Surface::Saddle { a: 0.004 },
        curved_disc_region(),
        SpacingField::Uniform(spacing),
        seed,
    )
}

/// The region of [`curved_disc_with_hole`].
fn curved_disc_region() -> Region {
    let outer = (0..720)
        .map(|i| {
            let t = i as f64 / 720.0 * 2.0 * PI;
            [50.0 * t.cos(), 50.0 * t.sin()]
        })
        .collect();
    Region {
        outer,
        holes: vec![Circle {
            centre: [15.0, -10.0],
            radius: 12.0,
        }],
    }
}

/// A cylinder patch of radius 50: arc length 0..150 (172°) by 0..100 along
/// the axis, with a hole of radius 15 at (75, 50).
pub fn cylinder_with_hole(spacing: f64, seed: u64) -> SyntheticCloud {
    let mut region = Region::rectangle([0.0, 0.0], [150.0, 100.0]);
    region.holes.push(Circle {
        centre: [75.0, 50.0],
        radius: 15.0,
    });
    jittered(
        format!("cylinder with hole, h={spacing}"),
        Surface::Cylinder { radius: 50.0 },
        region,
        SpacingField::Uniform(spacing),
        seed,
    )
}

/// The blade surface: 600 mm span, 30° twist, 15 mm camber.
pub const BLADE: Surface = Surface::TwistedBlade {
    span: 600.0,
    half_chord: 120.0,
    twist: PI / 6.0,
    camber: 15.0,
};

/// The blade outline in the parameter domain: chord 240 mm at the root
/// (u = 0) tapering to 210 mm at the tip (u = 600), with a curved leading
/// edge, 2 × 25 vertices. (The paper's blade is 640 × 300 mm.)
pub fn blade_outline() -> Vec<Uv> {
    let n = 24;
    let le = |u: f64| 120.0 - 20.0 * (u / 600.0).powi(2);
    let te = |u: f64| -120.0 + 10.0 * (u / 600.0);
    let mut outer: Vec<Uv> = (0..=n)
        .map(|i| {
            let u = 600.0 * i as f64 / n as f64;
            [u, te(u)]
        })
        .collect();
    outer.extend((0..=n).rev().map(|i| {
        let u = 600.0 * i as f64 / n as f64;
        [u, le(u)]
    }));
    outer
}

/// The paper's hole radii (16, 32 and 64 mm) at u = 150, 300, 450 mm.
pub const BLADE_HOLES: [(f64, f64); 3] = [(150.0, 16.0), (300.0, 32.0), (450.0, 64.0)];

/// Radius of a blade hole at pitch h: the paper's radius, raised to 2h so
/// that the sampling resolves it (the paper's 16 mm hole vanishes in its
/// 34 mm cloud), capped at 60 mm so that it fits in the chord.
pub fn blade_hole_radius(paper_radius: f64, h: f64) -> f64 {
    paper_radius.max((2.0 * h).min(60.0))
}

fn blade_region(h: f64) -> Region {
    Region {
        outer: blade_outline(),
        holes: BLADE_HOLES
            .iter()
            .map(|&(u, r)| Circle {
                centre: [u, 0.0],
                radius: blade_hole_radius(r, h),
            })
            .collect(),
    }
}

/// A blade-like sheet ([`BLADE`], [`blade_outline`]) with three holes
/// ([`BLADE_HOLES`], [`blade_hole_radius`]), sampled at `spacing` mm.
/// About 8,500 points at 4 mm.
pub fn blade(spacing: f64, seed: u64) -> SyntheticCloud {
    jittered(
        format!("blade {spacing} mm"),
        BLADE,
        blade_region(spacing),
        SpacingField::Uniform(spacing),
        seed,
    )
}

/// The clouds of the noise sweeps (section 4 of the paper; the Ω / Ψ
/// tables in `docs/results.md`): [`blade`] at 4, 8, 16 and 34 mm (seeds
/// 10–13) and [`variable_density`] from 3.4 mm (the paper's cloud e).
pub fn noise_sweep_clouds() -> Vec<SyntheticCloud> {
    let mut clouds: Vec<SyntheticCloud> = [4.0, 8.0, 16.0, 34.0]
        .into_iter()
        .zip(10..)
        .map(|(h, seed)| blade(h, seed))
        .collect();
    clouds.push(variable_density(3.4, 5));
    clouds
}

/// Disk radius of [`decimated_blade`]'s thinning, in target pitches:
/// chosen so that mean β matches the paper's Table 1 (4.22 / 8.48 / 16.64 /
/// 35.91 mm at 4 / 8 / 16 / 34 mm here, against the paper's 4.19 / 8.44 /
/// 16.87 / 34.52).
pub const DECIMATION_RADIUS: f64 = 0.8;

/// The blade of [`blade`] (same region and holes), sampled the way the
/// paper's clouds were made: a dense scan "decimated to obtain … target
/// resolution" (section 4). A jittered blade at a quarter of `spacing` is
/// thinned by Poisson-disk elimination: its points in a seeded random
/// order, each kept unless a kept point lies within
/// [`DECIMATION_RADIUS`]·`spacing` (3D). The result is blue noise: no two
/// points closer than the disk, no lattice rows left, and β about as
/// spread as on the jittered lattice (5.5 % of its mean, the paper's
/// 2.6 %); its intended resolution is `spacing`.
pub fn decimated_blade(spacing: f64, seed: u64) -> SyntheticCloud {
    let dense = jittered(
        format!("blade {spacing} mm, decimated"),
        BLADE,
        blade_region(spacing),
        SpacingField::Uniform(spacing / 4.0),
        seed,
    );
    let kept = poisson_disk_thinning(&dense.points, |_| DECIMATION_RADIUS * spacing, seed);
    let uv = pick(&dense.uv, &kept);
    SyntheticCloud {
        points: pick(&dense.points, &kept),
        normals: pick(&dense.normals, &kept),
        spacing: uv.iter().map(|&at| spacing * BLADE.stretch(at)).collect(),
        uv,
        field: SpacingField::Uniform(spacing),
        ..dense
    }
}

/// `values` at the indices `kept`.
fn pick<T: Copy>(values: &[T], kept: &[usize]) -> Vec<T> {
    kept.iter().map(|&i| values[i]).collect()
}

/// Indices (increasing) of the points kept by Poisson-disk elimination,
/// visiting `points` in an order shuffled by `seed`: a point is kept unless
/// a point kept before it lies closer than its own disk radius
/// (`radius_of(i)`, which may vary smoothly over the cloud).
fn poisson_disk_thinning(points: &[P3], radius_of: impl Fn(usize) -> f64, seed: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    let mut rng = SplitMix64::new(seed ^ 0x7468_696e);
    for i in (1..order.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        order.swap(i, j);
    }
    // The kept points are a subset of `points`, so a tree of all of them,
    // built once, answers "is a kept point within the disk?" for any
    // radius, where a grid would need cells as large as the largest disk.
    let tree: ImmutableKdTree<f64, 3> =
        ImmutableKdTree::new_from_slice(points).expect("dense samples fit in u32");
    let mut is_kept = vec![false; points.len()];
    for i in order {
        let r2 = radius_of(i).powi(2);
        let mut taken = false;
        tree.query(&points[i])
            .within::<SquaredEuclidean<f64>>(r2)
            .unsorted()
            .visit(|found| {
                let j = found.item as usize;
                // Strictly closer than the disk, whatever the tree's rule
                // at the rim.
                taken |= is_kept[j] && dist2(points[j], points[i]) < r2;
            });
        is_kept[i] = !taken;
    }
    (0..points.len()).filter(|&i| is_kept[i]).collect()
}

/// [`blade`] with the sampling jitter's half-width chosen (a fraction of
/// the pitch; [`JITTER`] is the default, 0 a perfect lattice in the
/// parameter domain, as a decimated profile scan nearly is).
pub fn blade_with_jitter(spacing: f64, jitter: f64, seed: u64) -> SyntheticCloud {
    jittered_by(
        format!("blade {spacing} mm, jitter {jitter}"),
        BLADE,
        blade_region(spacing),
        SpacingField::Uniform(spacing),
        jitter,
        seed,
    )
}

/// The blade with a pitch growing smoothly (geometrically) by ×10 along
/// the span, from `min_spacing` at the root to 10·`min_spacing` at the tip
/// (3.4 → 34 mm is the paper's cloud e), and one hole of radius
/// 9·`min_spacing` at u = 120 mm, where the pitch is ≈ 1.6·`min_spacing`.
pub fn variable_density(min_spacing: f64, seed: u64) -> SyntheticCloud {
    jittered(
        format!("variable density {min_spacing}–{} mm", 10.0 * min_spacing),
        BLADE,
        variable_density_region(min_spacing),
        variable_density_field(min_spacing),
        seed,
    )
}

/// [`variable_density`]'s pitch: ×10 geometrically along the span.
fn variable_density_field(min_spacing: f64) -> SpacingField {
    SpacingField::Graded {
        h0: min_spacing,
        h1: 10.0 * min_spacing,
        u0: 0.0,
        u1: 600.0,
    }
}

/// [`variable_density`]'s region: the blade with one hole of radius
/// 9·`min_spacing` at u = 120 mm.
fn variable_density_region(min_spacing: f64) -> Region {
    Region {
        outer: blade_outline(),
        holes: vec![Circle {
            centre: [120.0, 0.0],
            radius: 9.0 * min_spacing,
        }],
    }
}

/// [`variable_density`]'s blade (the same ×10 grading and hole) made as
/// [`decimated_blade`] is: a jittered blade graded at a quarter of the
/// pitch, thinned by Poisson-disk elimination with a disk of
/// [`DECIMATION_RADIUS`] times the local pitch. Blue noise whose
/// resolution varies smoothly by ×10, with no lattice columns left.
pub fn decimated_variable_density(min_spacing: f64, seed: u64) -> SyntheticCloud {
    let field = variable_density_field(min_spacing);
    let dense_field = variable_density_field(min_spacing / 4.0);
    let dense = jittered(
        format!(
            "variable density {min_spacing}–{} mm, decimated",
            10.0 * min_spacing
        ),
        BLADE,
        variable_density_region(min_spacing),
        dense_field,
        seed,
    );
    let kept = poisson_disk_thinning(
        &dense.points,
        |i| DECIMATION_RADIUS * field.at(dense.uv[i][0]),
        seed,
    );
    let uv = pick(&dense.uv, &kept);
    SyntheticCloud {
        points: pick(&dense.points, &kept),
        normals: pick(&dense.normals, &kept),
        spacing: uv
            .iter()
            .map(|&at| field.at(at[0]) * BLADE.stretch(at))
            .collect(),
        uv,
        field,
        ..dense
    }
}

/// An unjittered, axis-aligned square lattice of pitch h on the plane
/// z = 0 (every coordinate an exact multiple of h): 60 × 40 points in the
/// rectangle [−h/2, 59.5h] × [−h/2, 39.5h], minus a hole of radius 6.3h at
/// (30.5h, 20.5h).
pub fn flat_grid(spacing: f64) -> SyntheticCloud {
    let h = spacing;
    let mut region = Region::rectangle([-0.5 * h, -0.5 * h], [59.5 * h, 39.5 * h]);
    region.holes.push(Circle {
        centre: [30.5 * h, 20.5 * h],
        radius: 6.3 * h,
    });
    let mut samples = Vec::new();
    for i in 0..60 {
        for j in 0..40 {
            let p = [i as f64 * h, j as f64 * h];
            if region.contains(p) {
                samples.push((p, h));
            }
        }
    }
    SyntheticCloud::build(
        format!("perfect flat grid, h={h}"),
        Surface::Plane,
        region,
        SpacingField::Uniform(h),
        samples,
    )
}

/// [`plane_with_holes`] sampled as a mesh's own vertices are: the jittered
/// lattice inside, and samples `spacing` apart exactly on the true border
/// (the outer rectangle and the three circles), with the lattice's samples
/// closer than half a spacing to the border dropped. The outermost samples
/// lie on the edge, not inside it: the case the edge offset does not
/// model.
pub fn plane_with_border_samples(spacing: f64, seed: u64) -> SyntheticCloud {
    let h = spacing;
    let cloud = plane_with_holes(h, seed);
    let region = cloud.region.clone();
    let field = SpacingField::Uniform(h);
    let mut samples: Vec<(Uv, f64)> = jittered_grid(&region, field, JITTER, None, seed)
        .into_iter()
        .filter(|&(p, _)| region.distance_to_boundary(p) >= 0.5 * h)
        .collect();
    for curve in region.boundary_curves(h) {
        samples.extend(curve.into_iter().map(|p| (p, h)));
    }
    SyntheticCloud::build(
        format!("plane, holes 2β/4β/8β, samples on the border, h={h}"),
        Surface::Plane,
        region,
        field,
        samples,
    )
}

/// A line scan of the plane z = 0: straight scan lines at `angle` radians
/// to the u axis (and so to the plate's borders), samples every `spacing`
/// along a line and lines `ratio`·`spacing` apart, each line with a random
/// phase and every sample jittered by ±0.1·spacing along the line and
/// ±0.05·ratio·spacing across. The plate is 50L × 35L (L = ratio·spacing)
/// with a hole of radius 6L. The intended resolution is L, the larger pitch.
pub fn line_scan(ratio: f64, angle: f64, spacing: f64, seed: u64) -> SyntheticCloud {
    let s = spacing;
    let l = ratio * s;
    let mut region = Region::rectangle([0.0, 0.0], [50.0 * l, 35.0 * l]);
    region.holes.push(Circle {
        centre: [30.0 * l, 17.0 * l],
        radius: 6.0 * l,
    });
    let mut rng = SplitMix64::new(seed);
    let d = [angle.cos(), angle.sin()];
    let n = [-d[1], d[0]];
    let (lo, hi) = region.bounds();
    let corners = [lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]];
    let along = |p: Uv, a: Uv| p[0] * a[0] + p[1] * a[1];
    let range = |a: Uv| {
        corners
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(x, y), &c| {
                (x.min(along(c, a)), y.max(along(c, a)))
            })
    };
    let (t0, t1) = range(d);
    let (w0, w1) = range(n);
    let mut samples = Vec::new();
    let first_line = (w0 / l).floor() as i64 - 1;
    let last_line = (w1 / l).ceil() as i64 + 1;
    for k in first_line..=last_line {
        let w = k as f64 * l;
        let phase = rng.unit();
        let first = (t0 / s).floor() as i64 - 1;
        let last = (t1 / s).ceil() as i64 + 1;
        for m in first..=last {
            let t = (m as f64 + phase) * s + rng.range(-0.1, 0.1) * s;
            let ww = w + rng.range(-0.05, 0.05) * l;
            let p = [t * d[0] + ww * n[0], t * d[1] + ww * n[1]];
            if region.contains(p) {
                samples.push((p, l));
            }
        }
    }
    SyntheticCloud::build(
        format!("line scan 1:{ratio} at {:.0}°", angle.to_degrees()),
        Surface::Plane,
        region,
        SpacingField::Uniform(l),
        samples,
    )
}

fn cross(a: P3, b: P3) -> P3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: P3, b: P3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalised(a: P3) -> P3 {
    let n = dot(a, a).sqrt();
    [a[0] / n, a[1] / n, a[2] / n]
}

fn dist2d(a: Uv, b: Uv) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn dist_to_segment2(p: Uv, a: Uv, b: Uv) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let ap = [p[0] - a[0], p[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    dist2d(p, [a[0] + t * ab[0], a[1] + t * ab[1]])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generators_are_deterministic_and_inside() {
        let a = blade(8.0, 7);
        let b = blade(8.0, 7);
        assert_eq!(a.points, b.points);
        assert_ne!(a.points, blade(8.0, 8).points);
        for uv in &a.uv {
            assert!(a.region.contains(*uv));
        }
    }

    #[test]
    fn plane_is_exactly_flat_and_normals_are_unit() {
        let c = plane_with_holes(1.0, 1);
        assert!(c.points.iter().all(|p| p[2] == 0.0));
        for c in [
            saddle_with_hole(2.0, 1),
            cylinder_with_hole(2.0, 1),
            blade(8.0, 1),
        ] {
            for n in &c.normals {
                assert!((dot(*n, *n) - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn tangents_match_finite_differences() {
        let surfaces = [
            Surface::Saddle { a: 0.004 },
            Surface::Cylinder { radius: 50.0 },
            BLADE,
        ];
        for s in surfaces {
            for uv in [[10.0, 20.0], [300.0, -80.0], [77.0, 3.0]] {
                let (du, dv) = s.tangents(uv);
                let e = 1e-5;
                for (t, d) in [(du, [e, 0.0]), (dv, [0.0, e])] {
                    let a = s.point([uv[0] + d[0], uv[1] + d[1]]);
                    let b = s.point([uv[0] - d[0], uv[1] - d[1]]);
                    for k in 0..3 {
                        assert!(((a[k] - b[k]) / (2.0 * e) - t[k]).abs() < 1e-6, "{s:?}");
                    }
                }
            }
        }
    }

    #[test]
    fn boundary_is_dense_and_on_the_region_boundary() {
        let c = notched_plate(1.0, 3);
        for curve in &c.boundary {
            for (i, p) in curve.iter().enumerate() {
                let q = curve[(i + 1) % curve.len()];
                assert!(dist2d(*p, q) <= 1.0 / BOUNDARY_OVERSAMPLING + 1e-12);
                assert!(c.distance_to_boundary_uv(*p) < 1e-9);
            }
        }
    }

    #[test]
    fn noise_moves_along_the_normal_within_bounds() {
        let c = saddle_with_hole(2.0, 5);
        let noisy = c.with_noise(0.5, 9);
        for (i, q) in noisy.iter().enumerate() {
            let p = c.points[i];
            let d = [q[0] - p[0], q[1] - p[1], q[2] - p[2]];
            let len = dot(d, d).sqrt();
            assert!(len <= 0.5 * c.spacing[i] + 1e-12);
            let along = dot(d, c.normals[i]).abs();
            assert!((along - len).abs() < 1e-9);
        }
    }

    #[test]
    fn graded_decimation_keeps_each_point_its_own_disk_from_the_others() {
        let cloud = decimated_variable_density(3.4, 5);
        assert_eq!(cloud.points, decimated_variable_density(3.4, 5).points);
        let radius = |i: usize| DECIMATION_RADIUS * cloud.field.at(cloud.uv[i][0]);
        let n = cloud.len();
        let (mut nearest_root, mut nearest_tip) = (f64::INFINITY, f64::INFINITY);
        for i in 0..n {
            for j in i + 1..n {
                // Whichever of the two was visited later kept clear of the
                // other by its own disk.
                let d = dist2(cloud.points[i], cloud.points[j]).sqrt();
                assert!(d >= radius(i).min(radius(j)), "{i}, {j}: {d}");
            }
            let u = cloud.uv[i][0];
            let spacing_ratio = cloud.spacing[i] / cloud.field.at(u);
            assert!((1.0..1.1).contains(&spacing_ratio), "{spacing_ratio}");
            if u < 20.0 {
                nearest_root = nearest_root.min(radius(i));
            } else if u > 580.0 {
                nearest_tip = nearest_tip.min(radius(i));
            }
        }
        // The disk, so the resolution, grows about ×10 along the span.
        assert!(nearest_tip.is_finite(), "no point near the tip");
        assert!(
            nearest_tip / nearest_root > 8.0,
            "{nearest_root} → {nearest_tip}"
        );
        // About as many points as the graded lattice.
        let lattice = variable_density(3.4, 5).len() as f64;
        assert!(
            (0.7..1.2).contains(&(n as f64 / lattice)),
            "{n} against {lattice}"
        );
    }

    #[test]
    fn decimation_keeps_every_pair_a_disk_apart_and_covers_the_blade() {
        let h = 16.0;
        let cloud = decimated_blade(h, 3);
        assert_eq!(cloud.points, decimated_blade(h, 3).points);
        let radius = DECIMATION_RADIUS * h;
        let n = cloud.len();
        for i in 0..n {
            let nearest = (0..n)
                .filter(|&j| j != i)
                .map(|j| dist2(cloud.points[i], cloud.points[j]).sqrt())
                .fold(f64::INFINITY, f64::min);
            // Kept points are a disk apart; and a dense point is dropped
            // only for a kept one within the disk, so no gap is wider
            // than about two disks (plus the dense pitch).
            assert!(nearest >= radius, "point {i}: {nearest} < {radius}");
            assert!(nearest < 2.0 * radius + h, "point {i} isolated: {nearest}");
            assert!(cloud.region.contains(cloud.uv[i]));
        }
        // The intended resolution is the target pitch, not the dense one.
        assert_eq!(
            cloud.spacing_at([300.0, 0.0]),
            h * BLADE.stretch([300.0, 0.0])
        );
        // The jittered lattice at this pitch has about as many points.
        let lattice = blade(h, 3).len() as f64;
        assert!(
            (0.8..1.2).contains(&(n as f64 / lattice)),
            "{n} against {lattice}"
        );
    }
}
