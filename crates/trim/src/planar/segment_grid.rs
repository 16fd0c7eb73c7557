//! The loops' segments in a uniform grid.

use super::ring::{dist2d, Ring};
use crate::geom::{lerp2, orientation, segments_meet};

/// Where two loop segments meet ([`SegmentGrid::contacts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Contact {
    /// The two segments cross properly.
    Cross(u32, u32),
    /// `segment` passes through an end of `other` (its start when
    /// `start`, else its end), between its own ends.
    Touch {
        segment: u32,
        other: u32,
        start: bool,
    },
}

/// The loops' segments in a uniform grid, for parity, proximity and
/// crossing queries in 2D.
pub(crate) struct SegmentGrid {
    a: Vec<[f64; 2]>,
    b: Vec<[f64; 2]>,
    /// (loop, index of the segment's first vertex in it).
    pub(crate) owner: Vec<(u32, u32)>,
    sizes: Vec<u32>,
    x0: f64,
    y0: f64,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
}

impl SegmentGrid {
    pub(crate) fn new(rings: &[Ring], min_cell: f64) -> Self {
        let mut g = SegmentGrid {
            a: Vec::new(),
            b: Vec::new(),
            owner: Vec::new(),
            sizes: rings.iter().map(|r| r.len() as u32).collect(),
            x0: 0.0,
            y0: 0.0,
            cell: 1.0,
            nx: 1,
            ny: 1,
            cells: Vec::new(),
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        let mut length = 0.0;
        for (l, ring) in rings.iter().enumerate() {
            let m = ring.len();
            for i in 0..m {
                let (a, b) = (ring.p2[i], ring.p2[(i + 1) % m]);
                for c in 0..2 {
                    lo[c] = lo[c].min(a[c]);
                    hi[c] = hi[c].max(a[c]);
                }
                length += dist2d(a, b);
                g.a.push(a);
                g.b.push(b);
                g.owner.push((l as u32, i as u32));
            }
        }
        let segments = g.a.len();
        if segments == 0 {
            g.cells = vec![Vec::new()];
            return g;
        }
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]).max(f64::MIN_POSITIVE);
        let mut cell = (2.0 * length / segments as f64)
            .max(min_cell)
            .max(extent * 1e-9);
        let dims = |cell: f64| {
            (
                ((hi[0] - lo[0]) / cell).floor() as usize + 1,
                ((hi[1] - lo[1]) / cell).floor() as usize + 1,
            )
        };
        while {
            let (nx, ny) = dims(cell);
            nx.saturating_mul(ny) > 4 * segments + 16
        } {
            cell *= 1.5;
        }
        (g.nx, g.ny) = dims(cell);
        g.x0 = lo[0];
        g.y0 = lo[1];
        g.cell = cell;
        g.cells = vec![Vec::new(); g.nx * g.ny];
        for s in 0..segments {
            let (a, b) = (g.a[s], g.b[s]);
            let (c0, c1) = (g.col(a[0].min(b[0])), g.col(a[0].max(b[0])));
            let (r0, r1) = (g.row(a[1].min(b[1])), g.row(a[1].max(b[1])));
            for r in r0..=r1 {
                for c in c0..=c1 {
                    g.cells[r * g.nx + c].push(s as u32);
                }
            }
        }
        g
    }

    fn col(&self, x: f64) -> usize {
        (((x - self.x0) / self.cell).floor().max(0.0) as usize).min(self.nx - 1)
    }

    fn row(&self, y: f64) -> usize {
        (((y - self.y0) / self.cell).floor().max(0.0) as usize).min(self.ny - 1)
    }

    /// True if `p` is inside an odd number of loops (ray to +x).
    pub(crate) fn parity(&self, p: [f64; 2]) -> bool {
        let mut odd = false;
        self.ray_crossings(p, |_, _| odd = !odd);
        odd
    }

    /// The winding number of the loops round `p`, each loop's turn weighed
    /// by `sign[loop]` (ray to +x: a segment crossing it upwards counts
    /// +sign, downwards −sign). With every sign +1 this is the plain
    /// winding number; its parity is [`SegmentGrid::parity`].
    pub(crate) fn winding(&self, p: [f64; 2], sign: &[i32]) -> i32 {
        let mut winding = 0;
        self.ray_crossings(p, |s, upwards| {
            let turn = sign[self.owner[s as usize].0 as usize];
            winding += if upwards { turn } else { -turn };
        });
        winding
    }

    /// Calls `visit` with every segment the ray from `p` to +x crosses,
    /// and whether it crosses upwards. Each crossing is counted in the
    /// cell it lies in, once.
    fn ray_crossings(&self, p: [f64; 2], mut visit: impl FnMut(u32, bool)) {
        if self.a.is_empty()
            || p[1] < self.y0
            || p[1] > self.y0 + self.cell * self.ny as f64
            || p[0] > self.x0 + self.cell * self.nx as f64
        {
            return;
        }
        let r = self.row(p[1]);
        for c in self.col(p[0])..self.nx {
            for &s in &self.cells[r * self.nx + c] {
                let (a, b) = (self.a[s as usize], self.b[s as usize]);
                if (a[1] > p[1]) != (b[1] > p[1]) {
                    let t = (p[1] - a[1]) / (b[1] - a[1]);
                    let x = (a[0] + t * (b[0] - a[0])).clamp(a[0].min(b[0]), a[0].max(b[0]));
                    if x > p[0] && self.col(x) == c {
                        visit(s, b[1] > a[1]);
                    }
                }
            }
        }
    }

    /// The segment nearest to `p` among those within `radius` of it, with
    /// the exact side `p` lies on (1 left of it as it runs, −1 right, 0 on
    /// its line).
    pub(crate) fn nearest(&self, p: [f64; 2], radius: f64) -> Option<(u32, f64)> {
        self.nearest_where(p, radius, |_| true)
            .map(|(s, _)| (s, orientation(self.a[s as usize], self.b[s as usize], p)))
    }

    /// The segment `s` nearest to `p` within `radius` among those for
    /// which `accept(s)` holds (the lower index on a tie), and the
    /// parameter of its point nearest to `p` (0 at its start, 1 at its
    /// end).
    pub(crate) fn nearest_where(
        &self,
        p: [f64; 2],
        radius: f64,
        accept: impl Fn(u32) -> bool,
    ) -> Option<(u32, f64)> {
        if self.a.is_empty() {
            return None;
        }
        let (c0, c1) = (self.col(p[0] - radius), self.col(p[0] + radius));
        let (r0, r1) = (self.row(p[1] - radius), self.row(p[1] + radius));
        let mut best: Option<(f64, u32, f64)> = None;
        for r in r0..=r1 {
            for c in c0..=c1 {
                for &s in &self.cells[r * self.nx + c] {
                    let (a, b) = (self.a[s as usize], self.b[s as usize]);
                    let t = parameter_on(a, b, p);
                    let d = dist2d(p, lerp2(a, b, t));
                    let better = best.is_none_or(|(bd, bs, _)| d < bd || (d == bd && s < bs));
                    if d < radius && better && accept(s) {
                        best = Some((d, s, t));
                    }
                }
            }
        }
        best.map(|(_, s, t)| (s, t))
    }

    /// Every place where two segments meet other than at the vertex two
    /// consecutive segments share, in order: proper crossings (each passes
    /// strictly between the other's ends) and touches (a segment passes
    /// through an end of another); segments that only share an end are
    /// left out. Or the first pair that no split resolves: segments along
    /// one line that meet, or a spike turning straight back.
    pub(crate) fn contacts(&self) -> Result<Vec<Contact>, (u32, u32)> {
        let mut found = Vec::new();
        for cell in &self.cells {
            for (x, &s) in cell.iter().enumerate() {
                for &t in &cell[x + 1..] {
                    let (s, t) = (s.min(t), s.max(t));
                    if self.adjacent(s, t) {
                        if self.turns_back(s, t) {
                            return Err((s, t));
                        }
                        continue;
                    }
                    let (sa, sb) = (self.a[s as usize], self.b[s as usize]);
                    let (ta, tb) = (self.a[t as usize], self.b[t as usize]);
                    if !segments_meet(sa, sb, ta, tb) {
                        continue;
                    }
                    let side = [
                        orientation(sa, sb, ta),
                        orientation(sa, sb, tb),
                        orientation(ta, tb, sa),
                        orientation(ta, tb, sb),
                    ];
                    if side.iter().all(|&o| o == 0.0) {
                        return Err((s, t));
                    }
                    if side[0] * side[1] < 0.0 && side[2] * side[3] < 0.0 {
                        found.push(Contact::Cross(s, t));
                    } else if [sa, sb].iter().any(|p| [ta, tb].contains(p)) {
                        // Meeting at a shared end, and only there.
                    } else {
                        // Not along one line, so they meet at one point:
                        // an end of one, inside the other.
                        let touch = [(s, t, ta, true), (s, t, tb, false)]
                            .into_iter()
                            .chain([(t, s, sa, true), (t, s, sb, false)])
                            .find(|&(segment, _, p, _)| self.passes_through(segment, p));
                        match touch {
                            Some((segment, other, _, start)) => found.push(Contact::Touch {
                                segment,
                                other,
                                start,
                            }),
                            None => return Err((s, t)),
                        }
                    }
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        Ok(found)
    }

    /// Does segment `s` pass through `p` between its ends (exactly)?
    fn passes_through(&self, s: u32, p: [f64; 2]) -> bool {
        let (a, b) = (self.a[s as usize], self.b[s as usize]);
        let within = p[0] >= a[0].min(b[0])
            && p[0] <= a[0].max(b[0])
            && p[1] >= a[1].min(b[1])
            && p[1] <= a[1].max(b[1]);
        orientation(a, b, p) == 0.0 && within && p != a && p != b
    }

    /// Consecutive segments of one loop.
    fn adjacent(&self, s: u32, t: u32) -> bool {
        let ((ls, is), (lt, it)) = (self.owner[s as usize], self.owner[t as usize]);
        let m = self.sizes[ls as usize];
        ls == lt && ((is + 1) % m == it || (it + 1) % m == is)
    }

    /// Consecutive segments `s`, `t` that run straight back over each other.
    fn turns_back(&self, s: u32, t: u32) -> bool {
        let ((ls, is), (_, it)) = (self.owner[s as usize], self.owner[t as usize]);
        let m = self.sizes[ls as usize];
        let (first, second) = if (is + 1) % m == it { (s, t) } else { (t, s) };
        let (p, q, r) = (
            self.a[first as usize],
            self.b[first as usize],
            self.b[second as usize],
        );
        let back = (q[0] - p[0]) * (r[0] - q[0]) + (q[1] - p[1]) * (r[1] - q[1]);
        m > 3 && orientation(p, q, r) == 0.0 && back < 0.0
    }

    /// True if a segment passes within `radius` of `p`.
    pub(crate) fn near(&self, p: [f64; 2], radius: f64) -> bool {
        self.near_where(p, radius, |_| true)
    }

    /// True if a segment `s` for which `accept(s)` holds passes within
    /// `radius` of `p`.
    pub(crate) fn near_where(
        &self,
        p: [f64; 2],
        radius: f64,
        accept: impl Fn(u32) -> bool,
    ) -> bool {
        if self.a.is_empty() {
            return false;
        }
        let (c0, c1) = (self.col(p[0] - radius), self.col(p[0] + radius));
        let (r0, r1) = (self.row(p[1] - radius), self.row(p[1] + radius));
        for r in r0..=r1 {
            for c in c0..=c1 {
                for &s in &self.cells[r * self.nx + c] {
                    let q = closest_on(self.a[s as usize], self.b[s as usize], p);
                    if dist2d(p, q) < radius && accept(s) {
                        return true;
                    }
                }
            }
        }
        false
    }

    /// True if a loop segment meets the segment from `p` to `q`.
    pub(crate) fn crosses(&self, p: [f64; 2], q: [f64; 2]) -> bool {
        if self.a.is_empty() {
            return false;
        }
        let (c0, c1) = (self.col(p[0].min(q[0])), self.col(p[0].max(q[0])));
        let (r0, r1) = (self.row(p[1].min(q[1])), self.row(p[1].max(q[1])));
        (r0..=r1).any(|r| {
            (c0..=c1).any(|c| {
                self.cells[r * self.nx + c]
                    .iter()
                    .any(|&s| segments_meet(self.a[s as usize], self.b[s as usize], p, q))
            })
        })
    }

    /// Some pair of segments that meet other than at their shared vertex
    /// (or that share one and turn straight back).
    pub(crate) fn first_crossing(&self) -> Option<(u32, u32)> {
        for cell in &self.cells {
            for (x, &s) in cell.iter().enumerate() {
                for &t in &cell[x + 1..] {
                    let meet = if self.adjacent(s, t) {
                        self.turns_back(s, t)
                    } else {
                        let (sa, sb) = (self.a[s as usize], self.b[s as usize]);
                        segments_meet(sa, sb, self.a[t as usize], self.b[t as usize])
                    };
                    if meet {
                        return Some((s, t));
                    }
                }
            }
        }
        None
    }
}

/// The point of segment ab nearest to `p`.
fn closest_on(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> [f64; 2] {
    lerp2(a, b, parameter_on(a, b, p))
}

/// The parameter of the point of segment a–b nearest to `p`.
fn parameter_on(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    if len2 > 0.0 {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}
