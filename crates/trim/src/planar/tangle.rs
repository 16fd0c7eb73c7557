//! Loops that cross in a projection, resolved by their winding.
//!
//! On a ragged real scan a small smoothed hole can cross the outer border,
//! or two holes cross each other, where the surface between them is a
//! spacing or two wide (on the MeshLab face and statue range maps, loops
//! of 9 and 10 vertices cross the outer border). Parity cannot say what
//! is surface there: a point inside both the outer border and a hole that
//! crosses it is inside two loops either way. Winding can, once each loop
//! knows which side the surface is on: counting an outer border +1 round
//! its inside and a hole −1 round its own, the surface is where the count
//! is at least 1 (the outer border's inside less every hole, the union of
//! overlapping patches).
//!
//! 1. **Split at the crossings.** Every proper crossing (each segment
//!    passes strictly between the other's ends, exact predicates) becomes
//!    one new vertex shared by both loops, with the same coordinates bit
//!    for bit; its 3D position is that of the larger loop's segment (by
//!    area) at that spot. The two may lie at different depths (a loop
//!    round a few strays in front of the surface crosses its border); the
//!    larger loop is the main surface's border, and a mean would be on
//!    neither (on the statue's range map, 21 β from the nearest point).
//!    Where a loop passes exactly through another's vertex (a touch, as
//!    loops through the border points themselves make), that vertex is
//!    put into the segment it lies on; loops that share a vertex need no
//!    split. Loops that run along one line and meet are left an error: no
//!    split resolves them.
//! 2. **Lobes.** A loop that crossed itself now visits a vertex twice; it
//!    is cut there into two closed loops, so that each lobe of a twist
//!    gets its own side. Lobes of fewer than 3 vertices or no area go.
//! 3. **Sides.** Each loop's surface side is voted by the cloud points
//!    near it: every point within [`VOTE_REACH`]·βᵢ of a loop votes for the
//!    side of its nearest segment it lies on. The surface lies on the side
//!    with the points; a loop no point votes for keeps its inside as
//!    surface.
//! 4. **The faces** of winding at least 1 are kept, but for two cases
//!    parity never meets ([`pinches_opened`]): where two holes (or a
//!    twist's two lobes) touch at a crossing vertex, the surface pinches to
//!    that vertex, and the faces of the smaller fan round it go; a patch of
//!    faces that holds no cloud point (a lobe the vote took for surface)
//!    goes too.

use super::ring::Ring;
use super::{Contact, SegmentGrid};
use crate::geom::{lerp, lerp2, orient, UnionFind};
use crate::hash::{HashMap, HashSet};
use crate::mesh::pinches::fan_labels;

/// Cloud points within this many β of a loop vote for its surface side.
pub(crate) const VOTE_REACH: f64 = 2.0;

/// Loops split at their crossings into closed loops that cross no other
/// and themselves nowhere, but may share crossing vertices.
#[derive(Debug, Clone)]
pub(crate) struct Untangled {
    pub(crate) rings: Vec<Ring>,
    /// Places where loops crossed or touched, split.
    pub(crate) crossings: usize,
}

/// A crossing vertex inserted into segment `segment` at parameter `t`.
struct Insert {
    segment: u32,
    t: f64,
    p2: [f64; 2],
    p3: crate::geom::Point3,
    beta: f64,
    reference: u32,
}

/// Steps 1 and 2 of the module doc. Returns the pair of segments (indices
/// into `grid`'s owners) that meet in a way no split resolves.
pub(crate) fn untangle(rings: &[Ring], grid: &SegmentGrid) -> Result<Untangled, (u32, u32)> {
    let contacts = grid.contacts()?;
    let area: Vec<f64> = rings.iter().map(|r| r.area().abs()).collect();
    let end_of = |segment: u32, start: bool| {
        let (l, i) = grid.owner[segment as usize];
        let (a, b) = self::segment(&rings[l as usize], i as usize);
        if start {
            a
        } else {
            b
        }
    };
    let mut inserts = Vec::with_capacity(2 * contacts.len());
    for &contact in &contacts {
        match contact {
            Contact::Cross(s, t) => inserts.extend(crossing(rings, grid, &area, s, t)?),
            Contact::Touch {
                segment,
                other,
                start,
            } => {
                // The touching end, put into the segment it lies on.
                let v = end_of(other, start);
                let (l, i) = grid.owner[segment as usize];
                let (a, b) = self::segment(&rings[l as usize], i as usize);
                inserts.push(Insert {
                    segment,
                    t: along(a.p2, b.p2, v.p2),
                    p2: v.p2,
                    p3: v.p3,
                    beta: v.beta,
                    reference: v.reference,
                });
            }
        }
    }
    // A touching end shared by two segments of its loop is found twice.
    inserts.sort_by(|x, y| {
        (x.segment, x.p2[0], x.p2[1])
            .partial_cmp(&(y.segment, y.p2[0], y.p2[1]))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    inserts.dedup_by(|x, y| x.segment == y.segment && x.p2 == y.p2);
    let places: HashSet<(u64, u64)> = inserts
        .iter()
        .map(|x| (x.p2[0].to_bits(), x.p2[1].to_bits()))
        .collect();
    let split = insert_crossings(rings, grid, inserts);
    let rings = split.iter().flat_map(lobes).collect();
    Ok(Untangled {
        rings,
        crossings: places.len(),
    })
}

/// The crossing vertex of segments `s` and `t`, for both of them.
fn crossing(
    rings: &[Ring],
    grid: &SegmentGrid,
    area: &[f64],
    s: u32,
    t: u32,
) -> Result<[Insert; 2], (u32, u32)> {
    let (ls, is) = grid.owner[s as usize];
    let (lt, it) = grid.owner[t as usize];
    let (a, b) = segment(&rings[ls as usize], is as usize);
    let (c, d) = segment(&rings[lt as usize], it as usize);
    // Parameters along each segment from the orientation areas (their
    // exact signs are opposite; the plain values may underflow).
    let (oa, ob) = (orient(c.p2, d.p2, a.p2), orient(c.p2, d.p2, b.p2));
    let (oc, od) = (orient(a.p2, b.p2, c.p2), orient(a.p2, b.p2, d.p2));
    let ts = (oa / (oa - ob)).clamp(0.0, 1.0);
    let tt = (oc / (oc - od)).clamp(0.0, 1.0);
    let p2 = lerp2(a.p2, b.p2, ts);
    let rounds_onto_a_vertex = [a.p2, b.p2, c.p2, d.p2].contains(&p2);
    if !(ts.is_finite() && tt.is_finite()) || rounds_onto_a_vertex {
        // No point to split at: left as a touch.
        return Err((s, t));
    }
    let (p3, beta, reference) = if area[lt as usize] > area[ls as usize] {
        on_segment(c, d, tt)
    } else {
        on_segment(a, b, ts)
    };
    let insert = |segment, t| Insert {
        segment,
        t,
        p2,
        p3,
        beta,
        reference,
    };
    Ok([insert(s, ts), insert(t, tt)])
}

/// Where `p` (on segment ab) lies along it, 0 at a and 1 at b.
fn along(a: [f64; 2], b: [f64; 2], p: [f64; 2]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1];
    ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / len2
}

/// One vertex of a ring, by value.
#[derive(Clone, Copy)]
struct Vertex {
    p2: [f64; 2],
    p3: crate::geom::Point3,
    beta: f64,
    reference: u32,
}

fn vertex(ring: &Ring, j: usize) -> Vertex {
    Vertex {
        p2: ring.p2[j],
        p3: ring.p3[j],
        beta: ring.beta[j],
        reference: ring.reference[j],
    }
}

fn segment(ring: &Ring, i: usize) -> (Vertex, Vertex) {
    (vertex(ring, i), vertex(ring, (i + 1) % ring.len()))
}

fn push(ring: &mut Ring, v: Vertex) {
    ring.p2.push(v.p2);
    ring.p3.push(v.p3);
    ring.beta.push(v.beta);
    ring.reference.push(v.reference);
}

/// The rings with each crossing inserted into its segments, in order
/// along them.
fn insert_crossings(rings: &[Ring], grid: &SegmentGrid, mut inserts: Vec<Insert>) -> Vec<Ring> {
    inserts.sort_by(|x, y| x.segment.cmp(&y.segment).then(x.t.total_cmp(&y.t)));
    let mut at: HashMap<(u32, u32), Vec<usize>> = HashMap::default();
    for (k, ins) in inserts.iter().enumerate() {
        at.entry(grid.owner[ins.segment as usize])
            .or_default()
            .push(k);
    }
    rings
        .iter()
        .enumerate()
        .map(|(l, ring)| {
            let mut out = Ring::default();
            for j in 0..ring.len() {
                push(&mut out, vertex(ring, j));
                for &k in at.get(&(l as u32, j as u32)).map_or(&[][..], Vec::as_slice) {
                    let ins = &inserts[k];
                    push(
                        &mut out,
                        Vertex {
                            p2: ins.p2,
                            p3: ins.p3,
                            beta: ins.beta,
                            reference: ins.reference,
                        },
                    );
                }
            }
            out
        })
        .collect()
}

/// Step 2: a ring cut into closed loops at every vertex it visits twice;
/// lobes of fewer than 3 vertices or no area are left out.
fn lobes(ring: &Ring) -> Vec<Ring> {
    let key = |p: [f64; 2]| (p[0].to_bits(), p[1].to_bits());
    let mut path: Vec<Vertex> = Vec::with_capacity(ring.len());
    let mut seen: HashMap<(u64, u64), usize> = HashMap::default();
    let mut out = Vec::new();
    for j in 0..ring.len() {
        let v = vertex(ring, j);
        if let Some(&i) = seen.get(&key(v.p2)) {
            // The path closes a loop at its vertex i: that loop is cut off,
            // and the path goes on from vertex i.
            let tail = path.split_off(i + 1);
            for w in &tail {
                seen.remove(&key(w.p2));
            }
            let mut lobe = Ring::default();
            push(&mut lobe, path[i]);
            tail.into_iter().for_each(|w| push(&mut lobe, w));
            out.push(lobe);
        } else {
            seen.insert(key(v.p2), path.len());
            path.push(v);
        }
    }
    let mut rest = Ring::default();
    path.into_iter().for_each(|w| push(&mut rest, w));
    out.push(rest);
    out.retain(|r| r.len() >= 3 && r.area() != 0.0);
    out
}

/// Step 3: each ring's surface side as a sign, +1 where the surface is on
/// its left as it runs (inside, for a counter-clockwise ring), −1 on its
/// right, from the sides of the ring's nearest segment that the cloud
/// points within [`VOTE_REACH`]·βᵢ of a ring lie on (`votes`: each such
/// point's segment and side). A ring no point voted for keeps its inside.
pub(crate) fn surface_sides(
    rings: &[Ring],
    grid: &SegmentGrid,
    votes: impl Iterator<Item = (u32, f64)>,
) -> Vec<i32> {
    let mut tally = vec![0i64; rings.len()];
    for (s, side) in votes {
        tally[grid.owner[s as usize].0 as usize] += side as i64;
    }
    rings
        .iter()
        .zip(&tally)
        .map(|(ring, &t)| match t.signum() {
            0 => ring.area().signum() as i32,
            sign => sign as i32,
        })
        .collect()
}

/// Step 4: drops the faces (id triples; ids below `points` are cloud
/// points, the others loop vertices) of every fan but the largest round
/// each vertex from id `pinch_from` on where the surface pinches, then
/// every patch of faces without a cloud point. Returns how many faces
/// went.
pub(crate) fn pinches_opened(
    faces: &mut Vec<[u32; 3]>,
    ids: usize,
    points: usize,
    pinch_from: usize,
) -> usize {
    let before = faces.len();
    loop {
        let pinched = pinched_faces(faces, ids, pinch_from);
        if pinched.is_empty() {
            break;
        }
        let mut k = 0;
        faces.retain(|_| {
            k += 1;
            pinched.binary_search(&(k - 1)).is_err()
        });
    }
    let mut patches = UnionFind::new(ids);
    for f in faces.iter() {
        patches.union(f[0], f[1]);
        patches.union(f[0], f[2]);
    }
    let mut has_point = vec![false; ids];
    for f in faces.iter() {
        for &v in f.iter().filter(|&&v| (v as usize) < points) {
            has_point[patches.find(v) as usize] = true;
        }
    }
    faces.retain(|f| has_point[patches.find(f[0]) as usize]);
    before - faces.len()
}

/// The faces (indices, ascending) of every fan but the largest round each
/// loop vertex (id `points` on) whose faces make more than one fan (faces
/// round a vertex are one fan when they connect through edges at it).
/// Cloud points lie off the loops, so their stars are whole.
pub(crate) fn pinched_faces(faces: &[[u32; 3]], ids: usize, points: usize) -> Vec<usize> {
    let mut round: Vec<Vec<u32>> = vec![Vec::new(); ids - points];
    for (k, f) in faces.iter().enumerate() {
        for &v in f.iter().filter(|&&v| v as usize >= points) {
            round[v as usize - points].push(k as u32);
        }
    }
    let mut pinched = Vec::new();
    for (j, star) in round.iter().enumerate() {
        let v = j + points;
        if star.len() < 2 {
            continue;
        }
        let fan = fan_labels(faces, v as u32, star);
        let mut size: HashMap<u32, usize> = HashMap::default();
        fan.iter().for_each(|&r| *size.entry(r).or_default() += 1);
        if size.len() < 2 {
            continue;
        }
        // The largest fan stays, the first in star order among equals.
        let keep = fan
            .iter()
            .copied()
            .max_by(|a, b| size[a].cmp(&size[b]).then(b.cmp(a)))
            .unwrap_or(0);
        pinched.extend(
            star.iter()
                .zip(&fan)
                .filter(|&(_, &r)| r != keep)
                .map(|(&k, _)| k as usize),
        );
    }
    pinched.sort_unstable();
    pinched.dedup();
    pinched
}

/// The 3D position, β and reference point at parameter `t` of segment
/// ab: the reference is the nearer end's.
fn on_segment(a: Vertex, b: Vertex, t: f64) -> (crate::geom::Point3, f64, u32) {
    let reference = if t <= 0.5 { a.reference } else { b.reference };
    (
        lerp(a.p3, b.p3, t),
        a.beta + t * (b.beta - a.beta),
        reference,
    )
}

#[cfg(test)]
mod tests {
    use super::super::ring::flat_ring as ring;
    use super::*;

    fn square(o: [f64; 2], s: f64) -> Vec<[f64; 2]> {
        vec![o, [o[0] + s, o[1]], [o[0] + s, o[1] + s], [o[0], o[1] + s]]
    }

    #[test]
    fn a_hole_across_the_border_is_split_where_they_cross() {
        let rings = vec![
            ring(square([0.0, 0.0], 10.0)),
            ring(square([8.0, 4.0], 4.0)),
        ];
        let grid = SegmentGrid::new(&rings, 0.1);
        let u = untangle(&rings, &grid).unwrap();
        assert_eq!(u.crossings, 2);
        assert_eq!(u.rings.iter().map(Ring::len).collect::<Vec<_>>(), [6, 6]);
        // The crossings are shared bit for bit.
        for p in [[10.0, 4.0], [10.0, 8.0]] {
            assert!(u.rings.iter().all(|r| r.p2.contains(&p)), "{p:?}");
        }
    }

    #[test]
    fn a_figure_eight_falls_into_two_lobes() {
        let rings = vec![ring(vec![[0.0, 0.0], [2.0, 2.0], [2.0, 0.0], [0.0, 2.0]])];
        let grid = SegmentGrid::new(&rings, 0.1);
        let u = untangle(&rings, &grid).unwrap();
        assert_eq!(u.crossings, 1);
        let mut areas: Vec<f64> = u.rings.iter().map(Ring::area).collect();
        areas.sort_by(f64::total_cmp);
        assert_eq!(areas, [-1.0, 1.0]);
    }

    #[test]
    fn a_loop_through_another_s_vertex_shares_it() {
        let rings = vec![
            ring(square([0.0, 0.0], 10.0)),
            ring(vec![[10.0, 5.0], [12.0, 3.0], [12.0, 7.0]]),
        ];
        let grid = SegmentGrid::new(&rings, 0.1);
        let u = untangle(&rings, &grid).unwrap();
        assert_eq!(u.crossings, 1);
        assert_eq!(u.rings[0].len(), 5);
        assert!(u.rings[0].p2.contains(&[10.0, 5.0]));
    }

    #[test]
    fn loops_along_one_line_are_not_split() {
        let rings = vec![
            ring(square([0.0, 0.0], 10.0)),
            ring(square([10.0, 2.0], 4.0)),
        ];
        let grid = SegmentGrid::new(&rings, 0.1);
        assert!(untangle(&rings, &grid).is_err());
    }

    #[test]
    fn the_surface_side_follows_the_points() {
        // A clockwise outer ring with points inside, a clockwise hole with
        // points round it, and a ring nobody votes for.
        let mut outer = square([0.0, 0.0], 10.0);
        outer.reverse();
        let mut hole = square([4.0, 4.0], 2.0);
        hole.reverse();
        let rings = vec![ring(outer), ring(hole), ring(square([20.0, 0.0], 1.0))];
        let grid = SegmentGrid::new(&rings, 0.1);
        let points = [[1.0, 5.0], [9.0, 5.0], [3.5, 5.0], [6.5, 5.0], [5.0, 3.5]];
        let votes = points.iter().filter_map(|&p| grid.nearest(p, 2.0));
        assert_eq!(surface_sides(&rings, &grid, votes), [-1, 1, 1]);
    }
}
