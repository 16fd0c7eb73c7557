//! The strip's slivers refined in its own plane (the last step of the
//! strip way). Where the kept mesh's new border lies several spacings
//! behind the smoothed loop (the range grid's long faces at a silhouette
//! end there), zipping the two polylines joins each short segment of one
//! to a vertex of the other far across: a sliver whose small angle no
//! choice of diagonal avoids, only points between the two polylines.
//!
//! The strip is a chain of faces, each sharing one edge (a *rung*, from a
//! wall vertex to a smoothed loop vertex) with the next, so a run of it
//! unfolds into the plane without stretching: each face is laid across
//! the rung it shares with the one before. In that plane the run is
//! triangulated again with its outline as constraints and refined (spade's
//! constrained Delaunay refinement, as the planar way's gap, with the
//! outline never split: it is shared with the kept faces and is the new
//! border). Each added point is put back on the strip at the same spot of
//! the zip face it falls in, so the strip keeps its shape. The rung
//! between two runs that are both refined is split into pieces of about
//! a spacing, the same points for both: refinement never splits a run's
//! outline, and a long whole rung would keep it out of the run's end.
//! A run that cannot be unfolded into a simple polygon, whose refinement
//! would draw an edge of the kept mesh again, or does not raise its
//! smallest angle, is halved and tried again, down to runs of
//! [`MIN_RUN`] faces; what is left keeps the zip's faces.

use super::*;
use std::collections::BTreeMap;
use std::ops::{Range, RangeInclusive};

/// Faces of a run unfolded at once: short enough that a run of a strip
/// that turns within the surface cannot overlap itself in the plane …
const RUN: usize = 64;
/// … and ended at the shortest rung within this many faces of that
/// length, because the run's ends stay as they are.
const RUN_SLACK: usize = 16;
/// A run that cannot be refined whole (it overlaps itself in the plane
/// where the strip folds, or its refinement would join kept vertices) is
/// halved, at its shortest rung, while the halves have about this many
/// faces. On the bunny's range scans (bun000, bun045, bun090, chin) the
/// new faces below 10° were 66 / 99 / 104 / 147 halving down to 8 faces
/// and 48 / 83 / 88 / 130 down to 2 (none refined: 289 / 332 / 291 /
/// 351).
const MIN_RUN: usize = 2;
/// Points a rung between two runs is split by, at most.
const MAX_RUNG_POINTS: usize = 64;

/// The strip's faces `faces` (a closed chain in which each face shares an
/// edge with the next), with runs that hold a face below
/// [`REFINE_ANGLE`] refined. Vertex ids are those of `faces`, at
/// `position`; the added vertices get ids from `first_id` on and are
/// returned in that order. `scale` (a local spacing) sets the smallest
/// face refinement splits further. A run is not refined into a new edge
/// for which `joined` holds (an edge of the mesh the strip is sewn into:
/// it would be used by three faces).
pub(super) fn refine_strip(
    faces: &[[u32; 3]],
    position: &impl Fn(u32) -> Point3,
    joined: &impl Fn(u32, u32) -> bool,
    first_id: u32,
    scale: f64,
) -> (Vec<[u32; 3]>, Vec<Point3>) {
    let runs = runs(faces, position);
    let thin: Vec<bool> = runs
        .iter()
        .map(|run| smallest_angle_of(&faces[run.clone()], position, &[]) < REFINE_ANGLE)
        .collect();
    let mut rung_points = Vec::new();
    let candidates = split_rungs(
        faces,
        &runs,
        &thin,
        position,
        first_id,
        scale,
        &mut rung_points,
    );
    let strip = Strip {
        faces,
        position,
        joined,
        first_id,
        scale,
        rung_points,
    };
    let (splits, mut refined) = strip.settle(&runs, &thin, candidates);
    let mut out = Assembled::default();
    for (k, run) in runs.iter().enumerate() {
        match refined[k].take() {
            Some(run_refined) => out.take(run_refined),
            // Both its rungs are whole (see `settle`).
            None if thin[k] => strip.refine_in_halves(run.clone(), &splits, &mut out),
            None => out.keep(&faces[run.clone()]),
        }
    }
    numbered(out.faces, strip.rung_points, out.steiner, first_id)
}

/// A run's faces refined (ids from [`STEINER_BASE`] for its added
/// points) and its added points.
type Refined = (Vec<[u32; 3]>, Vec<Point3>);

/// What refining one strip reads.
struct Strip<'a, P, J> {
    faces: &'a [[u32; 3]],
    position: &'a P,
    joined: &'a J,
    first_id: u32,
    scale: f64,
    /// The points of the split rungs (ids from `first_id`).
    rung_points: Vec<Point3>,
}

impl<P: Fn(u32) -> Point3, J: Fn(u32, u32) -> bool> Strip<'_, P, J> {
    fn at(&self, id: u32) -> Point3 {
        if id >= self.first_id {
            self.rung_points[(id - self.first_id) as usize]
        } else {
            (self.position)(id)
        }
    }

    /// The run refined with the rungs `splits` split, if that raises its
    /// smallest angle and draws no edge of the kept mesh again.
    fn attempt(&self, run: &Range<usize>, splits: &Splits) -> Option<Refined> {
        let at = |id: u32| self.at(id);
        let original = &self.faces[run.clone()];
        let smallest = smallest_angle_of(original, &at, &[]);
        refine_run(original, &at, splits, self.scale)
            .filter(|(f, _)| !joins_anew(original, f, self.joined))
            .filter(|(f, v)| smallest_angle_of(f, &at, v) > smallest)
            .filter(|(f, v)| crossing::crossing_pairs(f, &with_added(&at, v)).is_empty())
    }

    /// The rungs that stay split, and each thin run refined with them. A
    /// rung stays split only while both runs beside it refine with the
    /// rungs split so far; leaving one whole can only make runs fail, so
    /// this ends, and a run that fails has both its rungs whole.
    fn settle(
        &self,
        runs: &[Range<usize>],
        thin: &[bool],
        mut splits: Splits,
    ) -> (Splits, Vec<Option<Refined>>) {
        let count = runs.len();
        let mut refined: Vec<Option<Refined>> = runs
            .iter()
            .zip(thin)
            .map(|(run, &thin)| thin.then(|| self.attempt(run, &splits)).flatten())
            .collect();
        loop {
            // The runs beside a rung left whole again are tried again;
            // the others saw the same rungs.
            let mut again = BTreeSet::new();
            splits.retain(|_, rung| {
                let before = (rung.after + count - 1) % count;
                let stays = refined[before].is_some() && refined[rung.after].is_some();
                if !stays {
                    again.extend([before, rung.after]);
                }
                stays
            });
            if again.is_empty() {
                return (splits, refined);
            }
            for k in again.into_iter().filter(|&k| thin[k]) {
                refined[k] = self.attempt(&runs[k], &splits);
            }
        }
    }

    /// A run that cannot be refined whole (it folds over itself in the
    /// plane, or its refinement would join kept vertices), refined in
    /// halves, split at their shortest rung, down to [`MIN_RUN`] faces;
    /// what is left keeps its faces.
    fn refine_in_halves(&self, run: Range<usize>, splits: &Splits, out: &mut Assembled) {
        let mut pending = vec![run];
        while let Some(part) = pending.pop() {
            match self.attempt(&part, splits) {
                Some(refined) => out.take(refined),
                None if part.len() >= 2 * MIN_RUN => {
                    let middle = part.start + part.len() / 4..=part.end - part.len() / 4;
                    let split = shortest_rung(self.faces, self.position, middle);
                    pending.push(split..part.end);
                    pending.push(part.start..split);
                }
                None => out.keep(&self.faces[part]),
            }
        }
    }
}

/// The strip's faces as they are made, run after run.
#[derive(Default)]
struct Assembled {
    /// Faces; ids from [`STEINER_BASE`] index `steiner`.
    faces: Vec<[u32; 3]>,
    steiner: Vec<Point3>,
}

impl Assembled {
    fn take(&mut self, (faces, added): Refined) {
        let base = STEINER_BASE + self.steiner.len() as u32;
        let renumber = |id: u32| match id {
            STEINER_BASE.. => base + (id - STEINER_BASE),
            _ => id,
        };
        self.faces.extend(faces.iter().map(|f| f.map(renumber)));
        self.steiner.extend(added);
    }

    fn keep(&mut self, faces: &[[u32; 3]]) {
        self.faces.extend_from_slice(faces);
    }
}

/// The faces with their vertices numbered from `first_id`: the points of
/// `rung_points` (ids from `first_id`) that the faces use, in order, then
/// the runs' added points (ids from [`STEINER_BASE`]). Rung points whose
/// rung was left whole again are dropped.
fn numbered(
    faces: Vec<[u32; 3]>,
    rung_points: Vec<Point3>,
    steiner: Vec<Point3>,
    first_id: u32,
) -> (Vec<[u32; 3]>, Vec<Point3>) {
    let is_rung_point = |id: u32| (first_id..STEINER_BASE).contains(&id);
    let used: BTreeSet<u32> = faces
        .iter()
        .flatten()
        .copied()
        .filter(|&id| is_rung_point(id))
        .collect();
    let new_id: BTreeMap<u32, u32> = used
        .iter()
        .enumerate()
        .map(|(k, &id)| (id, first_id + k as u32))
        .collect();
    let mut vertices: Vec<Point3> = used
        .iter()
        .map(|&id| rung_points[(id - first_id) as usize])
        .collect();
    let steiner_first = first_id + vertices.len() as u32;
    vertices.extend(steiner);
    let faces = faces
        .into_iter()
        .map(|f| {
            f.map(|id| match id {
                STEINER_BASE.. => steiner_first + (id - STEINER_BASE),
                id => new_id.get(&id).copied().unwrap_or(id),
            })
        })
        .collect();
    (faces, vertices)
}

/// The points a rung between two runs is split by.
struct SplitRung {
    /// The run the rung starts (the one before it ends there).
    after: usize,
    /// Ids of the points, from the rung's lower-id end.
    points: Vec<u32>,
}

/// The split rungs, by their ends (lower id first).
type Splits = BTreeMap<(u32, u32), SplitRung>;

/// The rungs between two runs that both hold a face below
/// [`REFINE_ANGLE`], each split into pieces of at most `scale` (at most
/// [`MAX_RUNG_POINTS`] points): a run's outline is never split by its
/// refinement (the wall is shared with the kept faces), and a long
/// unsplit rung keeps refinement out of the half of the run round it.
/// Both runs take the same points. The points are pushed onto
/// `rung_points` (ids from `first_id`).
fn split_rungs(
    faces: &[[u32; 3]],
    runs: &[Range<usize>],
    thin: &[bool],
    position: &impl Fn(u32) -> Point3,
    first_id: u32,
    scale: f64,
    rung_points: &mut Vec<Point3>,
) -> Splits {
    let mut splits = Splits::new();
    if runs.len() < 2 {
        return splits;
    }
    for (k, run) in runs.iter().enumerate() {
        let previous_face = (run.start + faces.len() - 1) % faces.len();
        let Some((a, b)) = shared_edge(&faces[previous_face], &faces[run.start]) else {
            continue;
        };
        if !(thin[(k + runs.len() - 1) % runs.len()] && thin[k]) {
            continue;
        }
        let (low, high) = (a.min(b), a.max(b));
        let (p, q) = (position(low), position(high));
        let pieces = (dist2(p, q).sqrt() / scale).ceil();
        // Short rungs, and a NaN length, stay whole.
        if pieces.is_nan() || pieces < 2.0 {
            continue;
        }
        let pieces = pieces.min(MAX_RUNG_POINTS as f64 + 1.0) as usize;
        let points = (1..pieces)
            .map(|i| {
                let t = i as f64 / pieces as f64;
                rung_points.push(std::array::from_fn(|c| p[c] + t * (q[c] - p[c])));
                first_id + rung_points.len() as u32 - 1
            })
            .collect();
        splits.insert((low, high), SplitRung { after: k, points });
    }
    splits
}

/// The points along edge `a` → `b`, in that order, if it is split.
fn points_along(splits: &Splits, a: u32, b: u32) -> Option<Vec<u32>> {
    let mut points = splits.get(&(a.min(b), a.max(b)))?.points.clone();
    if a > b {
        points.reverse();
    }
    Some(points)
}

/// Ids at and above this stand for a run's added points (index from it)
/// until they are numbered for the patch.
const STEINER_BASE: u32 = STEINER - (1 << 30);

/// The runs of faces, each about [`RUN`] long and ended at the shortest
/// rung near that length.
fn runs(faces: &[[u32; 3]], position: &impl Fn(u32) -> Point3) -> Vec<Range<usize>> {
    let mut runs = Vec::new();
    let mut start = 0;
    while start < faces.len() {
        let end = if faces.len() - start <= RUN + RUN_SLACK {
            faces.len()
        } else {
            let last = (start + RUN + RUN_SLACK).min(faces.len() - 2);
            shortest_rung(faces, position, start + RUN - RUN_SLACK..=last)
        };
        runs.push(start..end);
        start = end;
    }
    runs
}

/// The face `t` among `among` whose rung with the face before it (the
/// last face, before face 0) is the shortest; the first of equals.
fn shortest_rung(
    faces: &[[u32; 3]],
    position: &impl Fn(u32) -> Point3,
    among: RangeInclusive<usize>,
) -> usize {
    let before = |t: usize| (t + faces.len() - 1) % faces.len();
    let rung_length = |t: usize| match shared_edge(&faces[before(t)], &faces[t]) {
        Some((a, b)) => dist2(position(a), position(b)),
        None => 0.0,
    };
    let first = *among.start();
    among
        .min_by(|&a, &b| rung_length(a).total_cmp(&rung_length(b)).then(a.cmp(&b)))
        .unwrap_or(first)
}

/// The edge two faces share, as `second` runs it.
fn shared_edge(first: &[u32; 3], second: &[u32; 3]) -> Option<(u32, u32)> {
    (0..3)
        .map(|k| (second[k], second[(k + 1) % 3]))
        .find(|(a, b)| first.contains(a) && first.contains(b))
}

/// Whether `refined` has an edge between two of the run's own vertices
/// that `original` lacks and for which `joined` holds.
fn joins_anew(
    original: &[[u32; 3]],
    refined: &[[u32; 3]],
    joined: &impl Fn(u32, u32) -> bool,
) -> bool {
    let undirected = |f: &[u32; 3], k: usize| {
        let (a, b) = (f[k], f[(k + 1) % 3]);
        (a.min(b), a.max(b))
    };
    let old: BTreeSet<(u32, u32)> = original
        .iter()
        .flat_map(|f| (0..3).map(move |k| undirected(f, k)))
        .collect();
    refined
        .iter()
        .flat_map(|f| (0..3).map(move |k| undirected(f, k)))
        .any(|(a, b)| b < STEINER_BASE && !old.contains(&(a, b)) && joined(a, b))
}

/// The smallest angle (degrees) of `faces`, whose ids from
/// [`STEINER_BASE`] on index `added`.
fn smallest_angle_of(
    faces: &[[u32; 3]],
    position: &impl Fn(u32) -> Point3,
    added: &[Point3],
) -> f64 {
    let at = with_added(position, added);
    faces
        .iter()
        .map(|f| {
            let corners = f.map(&at);
            smallest_angle(&corners, [0, 1, 2])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Positions of a refined run's vertices: ids from [`STEINER_BASE`] on
/// index `added`.
fn with_added<'a>(
    position: &'a impl Fn(u32) -> Point3,
    added: &'a [Point3],
) -> impl Fn(u32) -> Point3 + 'a {
    move |id: u32| match id {
        STEINER_BASE.. => added[(id - STEINER_BASE) as usize],
        _ => position(id),
    }
}

/// A run's faces laid into the plane: each face keeps its edge lengths
/// and runs counter-clockwise.
struct Unfolded {
    /// The run's vertex ids, in the order first met.
    ids: Vec<u32>,
    /// Their places in the plane.
    at: Vec<[f64; 2]>,
    /// The run's faces, as indices into `ids`.
    faces: Vec<[usize; 3]>,
}

impl Unfolded {
    /// Lays `faces` out face by face across the rung each shares with the
    /// one before; `None` where a face does not share an edge with the one
    /// before, or comes back to a vertex already laid out.
    fn new(faces: &[[u32; 3]], position: &impl Fn(u32) -> Point3) -> Option<Unfolded> {
        let first = faces.first()?;
        let mut run = Unfolded {
            ids: Vec::new(),
            at: Vec::new(),
            faces: Vec::with_capacity(faces.len()),
        };
        let [p0, p1, p2] = first.map(position);
        let d01 = dist2(p0, p1).sqrt();
        run.push(first[0], [0.0, 0.0]);
        run.push(first[1], [d01, 0.0]);
        run.push(first[2], apex([0.0, 0.0], [d01, 0.0], p0, p1, p2)?);
        run.faces.push([0, 1, 2]);
        for pair in faces.windows(2) {
            let (a, b) = shared_edge(&pair[0], &pair[1])?;
            let k = (0..3).find(|&k| pair[1][k] == a)?;
            let c = pair[1][(k + 2) % 3];
            if run.ids.contains(&c) {
                return None;
            }
            let (ia, ib) = (run.index(a)?, run.index(b)?);
            let place = apex(
                run.at[ia],
                run.at[ib],
                position(a),
                position(b),
                position(c),
            )?;
            run.push(c, place);
            let ic = run.ids.len() - 1;
            run.faces.push([ia, ib, ic]);
        }
        Some(run)
    }

    fn push(&mut self, id: u32, at: [f64; 2]) {
        self.ids.push(id);
        self.at.push(at);
    }

    fn index(&self, id: u32) -> Option<usize> {
        self.ids.iter().position(|&v| v == id)
    }

    /// The edges of the run's outline (used by one face only).
    fn outline(&self) -> Vec<(usize, usize)> {
        let edges: Vec<(usize, usize)> = self
            .faces
            .iter()
            .flat_map(|f| (0..3).map(move |k| (f[k], f[(k + 1) % 3])))
            .collect();
        edges
            .iter()
            .copied()
            .filter(|&(a, b)| !edges.contains(&(b, a)))
            .collect()
    }

    /// The outline's edges, those of split rungs in pieces: their points
    /// are added to the run's vertices, in the plane along the rung.
    fn outline_with_splits(&mut self, splits: &Splits) -> Vec<(usize, usize)> {
        let mut pieces = Vec::new();
        for (a, b) in self.outline() {
            let Some(points) = points_along(splits, self.ids[a], self.ids[b]) else {
                pieces.push((a, b));
                continue;
            };
            let (pa, pb) = (self.at[a], self.at[b]);
            let count = points.len() + 1;
            let mut last = a;
            for (i, id) in points.into_iter().enumerate() {
                let t = (i + 1) as f64 / count as f64;
                self.push(
                    id,
                    [pa[0] + t * (pb[0] - pa[0]), pa[1] + t * (pb[1] - pa[1])],
                );
                let next = self.ids.len() - 1;
                pieces.push((last, next));
                last = next;
            }
            pieces.push((last, b));
        }
        pieces
    }

    /// The point of the strip at `q` of the plane: the blend of the zip
    /// face `q` lies in (or nearest to lying in) by its barycentric
    /// weights.
    fn lift(&self, q: [f64; 2], position: &impl Fn(u32) -> Point3) -> Point3 {
        let weights = |f: &[usize; 3]| {
            let [a, b, c] = f.map(|i| self.at[i]);
            let area = orient(a, b, c);
            [
                orient(q, b, c) / area,
                orient(a, q, c) / area,
                orient(a, b, q) / area,
            ]
        };
        let (face, w) = self
            .faces
            .iter()
            .map(|f| (f, weights(f)))
            .max_by(|(_, u), (_, v)| min3(*u).total_cmp(&min3(*v)))
            .unwrap_or((&self.faces[0], [1.0, 0.0, 0.0]));
        let mut p = [0.0; 3];
        for (k, &i) in face.iter().enumerate() {
            let x = position(self.ids[i]);
            for c in 0..3 {
                p[c] += w[k] * x[c];
            }
        }
        p
    }
}

fn min3(w: [f64; 3]) -> f64 {
    w[0].min(w[1]).min(w[2])
}

/// The place in the plane of a face's third corner `pc`, on the left of
/// `a` → `b` (the places of `pa`, `pb`) at its distances from them.
fn apex(a: [f64; 2], b: [f64; 2], pa: Point3, pb: Point3, pc: Point3) -> Option<[f64; 2]> {
    let d = [b[0] - a[0], b[1] - a[1]];
    let ab = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if ab.is_nan() || ab <= 0.0 {
        return None;
    }
    let (ac2, bc2) = (dist2(pa, pc), dist2(pb, pc));
    let along = (ac2 + ab * ab - bc2) / (2.0 * ab);
    let height = (ac2 - along * along).max(0.0).sqrt();
    let (u, left) = ([d[0] / ab, d[1] / ab], [-d[1] / ab, d[0] / ab]);
    let place = [
        a[0] + along * u[0] + height * left[0],
        a[1] + along * u[1] + height * left[1],
    ];
    place.iter().all(|c| c.is_finite()).then_some(place)
}

/// One run triangulated again in its plane and refined; its faces (ids of
/// the run, and [`STEINER_BASE`] + k for the k-th added point) and the
/// added points on the strip. `None` where the unfolded run is no simple
/// polygon, or the refined triangulation is not a disk of the run's
/// outline.
fn refine_run(
    faces: &[[u32; 3]],
    position: &impl Fn(u32) -> Point3,
    splits: &Splits,
    scale: f64,
) -> Option<(Vec<[u32; 3]>, Vec<Point3>)> {
    let mut run = Unfolded::new(faces, position)?;
    let outline = run.outline_with_splits(splits);
    let mut cdt = Cdt::new();
    let mut handles = Vec::with_capacity(run.ids.len());
    for (i, &p) in run.at.iter().enumerate() {
        if let PositionInTriangulation::OnVertex(_) = cdt.locate(crate::planar::point(p)) {
            return None;
        }
        handles.push(cdt.insert(Node::new(p, i as u32)).ok()?);
    }
    for &(a, b) in &outline {
        if obstacle(&cdt, handles[a], handles[b]).is_some() {
            return None;
        }
        cdt.add_constraint(handles[a], handles[b]);
    }
    cdt.refine(refinement(run.ids.len(), scale));
    let mut added = Vec::new();
    let mut index_of = vec![0u32; cdt.num_vertices()];
    for h in cdt.fixed_vertices() {
        let id = cdt.vertex(h).data().id;
        index_of[h.index()] = if id == STEINER {
            let q = cdt.vertex(h).position();
            added.push(run.lift([q.x, q.y], position));
            STEINER_BASE + (added.len() - 1) as u32
        } else {
            run.ids[id as usize]
        };
    }
    let inside = inside_faces(&cdt);
    // A disk whose corners are all on its outline has two faces fewer
    // than corners; each point inside adds two.
    if inside.len() + 2 != run.ids.len() + 2 * added.len() {
        return None;
    }
    let refined = inside
        .iter()
        .map(|&f| {
            let vs = cdt.face(f).vertices();
            let p = vs.map(|v| {
                let q = v.position();
                [q.x, q.y]
            });
            let mut ids = vs.map(|v| index_of[v.fix().index()]);
            if orientation(p[0], p[1], p[2]) < 0.0 {
                ids.swap(1, 2);
            }
            ids
        })
        .collect();
    Some((refined, added))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use std::collections::BTreeMap;

    /// A closed strip zipped, the way the zip runs, between a wall of `p`
    /// points at radius `inner` (ids 0..p) and a loop of `m` points at
    /// radius 10 (ids p..), both jittered by `jitter` in angle (a fraction
    /// of a step), then lifted off the plane by `lift`.
    fn ring_strip(
        p: usize,
        m: usize,
        inner: f64,
        jitter: f64,
        seed: u64,
        lift: impl Fn(f64, f64) -> f64,
    ) -> (Vec<Point3>, Vec<[u32; 3]>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let tau = std::f64::consts::TAU;
        let mut at = |r: f64, i: usize, count: usize, offset: f64| {
            let t = tau * (i as f64 + offset + jitter * rng.random_range(-0.5..0.5)) / count as f64;
            let (x, y) = (r * t.cos(), r * t.sin());
            [x, y, lift(x, y)]
        };
        let mut points: Vec<Point3> = (0..p).map(|i| at(inner, i, p, 0.0)).collect();
        points.extend((0..m).map(|k| at(10.0, k, m, 0.5)));
        let (mut i, mut k) = (0, 0);
        let mut faces = Vec::new();
        let (w, g) = (|i: usize| (i % p) as u32, |k: usize| (p + k % m) as u32);
        while i < p || k < m {
            let wall_next = (i + 1) as f64 / p as f64;
            let guide_next = (k as f64 + 1.5) / m as f64;
            if k == m || (i < p && wall_next <= guide_next) {
                faces.push([w(i + 1), w(i), g(k)]);
                i += 1;
            } else {
                faces.push([g(k), g(k + 1), w(i)]);
                k += 1;
            }
        }
        (points, faces)
    }

    fn edge_uses(faces: &[[u32; 3]]) -> BTreeMap<(u32, u32), usize> {
        let mut uses = BTreeMap::new();
        for f in faces {
            for k in 0..3 {
                *uses.entry((f[k], f[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        uses
    }

    fn outline(faces: &[[u32; 3]]) -> BTreeSet<(u32, u32)> {
        let uses = edge_uses(faces);
        uses.keys()
            .copied()
            .filter(|&(a, b)| !uses.contains_key(&(b, a)))
            .collect()
    }

    /// Whether `q` lies on the triangle `t` (in its plane, within it), to
    /// `tolerance` of its size.
    fn on_triangle(q: Point3, t: [Point3; 3], tolerance: f64) -> bool {
        let normal = cross(sub(t[1], t[0]), sub(t[2], t[0]));
        let area2 = norm2(normal);
        let size = dist2(t[0], t[1]).max(dist2(t[1], t[2])).sqrt();
        let height = dot(sub(q, t[0]), normal) / area2.sqrt();
        let weight = |a: Point3, b: Point3| dot(cross(sub(b, a), sub(q, a)), normal) / area2;
        height.abs() < tolerance * size && (0..3).all(|k| weight(t[k], t[(k + 1) % 3]) > -tolerance)
    }

    /// The refined strip against the zip it came from: every directed edge
    /// once and the same outline (so it is sewn in as the zip was), every
    /// added point on one of the zip's faces (the strip keeps its shape),
    /// the same orientation, and the smallest angle raised.
    fn check_refined(
        points: &[Point3],
        faces: &[[u32; 3]],
        joined: &impl Fn(u32, u32) -> bool,
        scale: f64,
    ) -> f64 {
        let position = |id: u32| points[id as usize];
        let n = points.len() as u32;
        let before = smallest_angle_of(faces, &position, &[]);
        let (refined, added) = refine_strip(faces, &position, joined, n, scale);
        let all: Vec<Point3> = points.iter().chain(&added).copied().collect();
        let after = refined
            .iter()
            .map(|&f| smallest_angle(&all, f))
            .fold(f64::INFINITY, f64::min);
        assert!(after >= before, "{before} -> {after}");
        assert!(edge_uses(&refined).values().all(|&u| u == 1));
        assert_eq!(outline(&refined), outline(faces));
        for q in &added {
            assert!(
                faces.iter().any(|f| on_triangle(*q, f.map(position), 1e-9)),
                "{q:?}"
            );
        }
        let mean_normal = |pts: &[Point3], fs: &[[u32; 3]]| {
            fs.iter().fold([0.0; 3], |acc, f| {
                let [a, b, c] = f.map(|i| pts[i as usize]);
                add(acc, cross(sub(b, a), sub(c, a)))
            })
        };
        let (old, new) = (mean_normal(points, faces), mean_normal(&all, &refined));
        assert!(dot(old, new) > 0.9 * norm2(old).sqrt() * norm2(new).sqrt());
        after
    }

    #[test]
    fn a_wide_flat_strip_is_refined_in_place() {
        let (points, faces) = ring_strip(120, 100, 4.0, 0.0, 1, |_, _| 0.0);
        let before = smallest_angle_of(&faces, &|id: u32| points[id as usize], &[]);
        // The wall's spacing (4 × 2π / 120) as the scale.
        let after = check_refined(&points, &faces, &|_, _| false, 0.2);
        assert!(before < 10.0 && after > 14.0, "{before} -> {after}");
    }

    #[test]
    fn random_bent_strips_keep_their_outline_and_surface() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for seed in 0..40 {
            let p = rng.random_range(12..150);
            let m = rng.random_range(12..150);
            let inner = rng.random_range(2.0..9.5);
            let jitter = rng.random_range(0.0..0.9);
            let (bend, wave) = (rng.random_range(0.0..0.3), rng.random_range(0.0..2.0));
            let lift = move |x: f64, y: f64| bend * (x * x + y * y) + wave * (x / 3.0).sin();
            let (points, faces) = ring_strip(p, m, inner, jitter, seed, lift);
            let spacing = std::f64::consts::TAU * inner / p as f64;
            check_refined(&points, &faces, &|_, _| false, spacing.min(1.0));
        }
    }

    #[test]
    fn a_strip_that_folds_keeps_its_outline() {
        // A wall that zig-zags back and forth along the loop makes faces
        // that overlap once unfolded: those runs are halved, or kept.
        let (mut points, faces) = ring_strip(90, 60, 3.0, 0.0, 3, |_, _| 0.0);
        for (i, q) in points.iter_mut().take(90).enumerate() {
            let t = std::f64::consts::TAU * (i as f64 + if i % 2 == 0 { 1.6 } else { -1.6 }) / 90.0;
            *q = [3.0 * t.cos(), 3.0 * t.sin(), 0.3 * (i % 2) as f64];
        }
        check_refined(&points, &faces, &|_, _| false, 0.2);
    }

    #[test]
    fn no_edge_of_the_kept_mesh_is_drawn_again() {
        // Every pair of wall vertices stands for an edge of the kept mesh:
        // the refinement may not join two of them anew.
        let (points, faces) = ring_strip(150, 40, 5.0, 0.5, 5, |x, _| 0.05 * x * x);
        let wall = |a: u32, b: u32| a < 150 && b < 150;
        check_refined(&points, &faces, &wall, 0.2);
        let position = |id: u32| points[id as usize];
        let (refined, _) = refine_strip(&faces, &position, &wall, points.len() as u32, 0.2);
        let undirected = |fs: &[[u32; 3]]| -> BTreeSet<(u32, u32)> {
            fs.iter()
                .flat_map(|f| {
                    (0..3).map(move |k| (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3])))
                })
                .filter(|&(a, b)| wall(a, b))
                .collect()
        };
        assert_eq!(undirected(&refined), undirected(&faces));
    }
}
