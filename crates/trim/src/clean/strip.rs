//! A border loop replaced without any projection: the smoothed loop zipped
//! to the kept mesh by a strip of new faces (the cleanup's second way, for
//! the loops whose band is no height field over one plane: outer borders
//! that wrap round the object, borders on steep or folded surface).
//!
//! 0. **The depth of a silhouette.** On a scan seen from one side, the
//!    smoothed loop's depth (its component along the direction the scan
//!    was seen from) is smoothed again, by a local quadratic fit with
//!    Gaussian weights of [`DEPTH_SIGMA`]·β over arc length
//!    ([`smooth_depth`]): where the
//!    surface turns away from the scanner, consecutive border samples jump
//!    between front and back by up to 20 spacings (grazing incidence: the
//!    depth is measured worst there), and the low-pass filter, whose
//!    cut-off follows β, passes those jumps of a few samples' width on.
//!    The outline across the view keeps the filter's result.
//! 1. **Which side is the surface.** Every segment of the smoothed loop
//!    gets the direction into the surface there: the mean direction from
//!    the border vertices it was smoothed from to the faces around them,
//!    made square to the segment. A vertex's *depth* is its distance from
//!    the nearest point of the smoothed loop along that direction
//!    (the pseudo-normal, the mean of two segments' directions, where the
//!    nearest point is a vertex of the loop, so the sign is right at
//!    corners).
//! 2. **What goes.** From the old border inwards, ring by ring, every
//!    vertex less than [`MARGIN`]·βᵢ deep goes, as in the planar way, and
//!    with it every face that has such a vertex. Another border the cut
//!    reaches goes with it when most of its vertices lie outside the
//!    smoothed loop (it is absorbed: its hole or notch lies beyond the new
//!    border), and is kept out of the cut otherwise, with the vertices
//!    round it.
//! 3. **The wall.** The edges where removed faces meet kept ones chain
//!    into the kept mesh's new border. A vertex where the chain touches
//!    itself (the cut pinches there) loses its faces too; kept islands the
//!    cut surrounds go.
//! 4. **The strip.** The wall's vertices are placed along the smoothed
//!    loop in order, each on the segment that makes the sum of squared
//!    distances least ([`place_along`]: a wall cutting across a bay of the
//!    loop skips it, and a neck of the surface draws no vertex across), and
//!    the two polylines are zipped in that order: each new face joins one
//!    segment of either polyline to a vertex of the other. Every corner is
//!    a mesh vertex or a smoothed loop vertex, so the strip follows the
//!    surface without any lifting, and its faces turn as the kept faces
//!    beside them.
//! 5. **The slivers.** Where the wall lies several spacings behind the
//!    smoothed loop, runs of the strip that hold slivers are unfolded
//!    into the plane and refined there ([`refine_strip`]).
//! 6. **Kept faces passed through.** Where the wall lies behind the loop
//!    across a range grid's skirts, a strip face can pierce the kept
//!    surface between them. The kept faces a strip face passes through
//!    ([`crossing`]) go with the cut, their vertices with the border's,
//!    and the strip is made again, up to [`CROSSING_ROUNDS`] times; where
//!    it can no longer be made, the strip before stays.

use super::*;
use crate::edges::smooth::arc_lengths;
use crate::geom::{scale, segment_param, unit};
use crate::spatial::PointTree;

/// Width (σ, in median β) of the Gaussian weights of the fit that smooths
/// a one-sided scan's silhouette depth ([`smooth_depth`]). Measured on the
/// bunny's range scans (bun000, bun045, bun090, chin), the median turning
/// angle of the output's outer border in degrees: without, 13.6 / 13.0 /
/// 15.7 / 12.5; with σ = 2 β 11.7 / 11.3 / 13.0 / 11.3; 3 β 10.5 / 10.1 /
/// 11.7 / 10.1; 4 β 9.5 / 9.2 / 10.3 / 9.3. A weighted mean instead of the
/// quadratic smooths more for its width (2 β: 10.2 / 9.9 / 11.1 / 10.2)
/// but pulls a rim that curves in depth towards its chords: on the
/// wrapped cylinder of the tests (radius 40, 1.5 spacing) its border moved
/// from 0.120 / 0.124 to 0.135 / 0.137 spacings from the truth; the
/// quadratic's stays at 0.120 / 0.125.
const DEPTH_SIGMA: f64 = 3.0;
/// The Gaussian's window, in σ on either side.
const DEPTH_WINDOW: f64 = 2.0;

/// Borders one strip may absorb because they lie one face from others it
/// absorbs.
const MAX_ABSORBED: usize = 64;
/// Times a strip is made again after passing through kept faces or
/// folding over itself, the kept faces and the wall's vertices at the
/// folds then going with the cut ([`crossing`]) …
const CROSSING_ROUNDS: usize = 8;
/// … ending early after this many remakes in a row cross no less than
/// the best so far.
const PATIENCE: usize = 2;
/// The cells of the grids that find those kept faces and folds, in β.
const CROSSING_CELL: f64 = 2.0;
/// Times the faces round a pinched wall vertex are removed before the loop
/// is left.
const PINCH_REPAIRS: usize = 16;
/// Largest share of the new faces that may turn against the surface beside
/// them (the smoothed loop doubling back on itself across a narrow notch).
const MAX_TURNED: f64 = 0.15;

/// Why a loop could not be replaced by a strip.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum StripFailure {
    /// The cut runs more than [`MAX_DEPTH`] rings from the border.
    TooDeep,
    /// The kept mesh's new border does not close into one loop.
    Wall,
    /// The smoothed loop would cut the mesh in two.
    Splits,
    /// Too many new faces turn against the surface.
    Turned { turned: usize, faces: usize },
    /// The cut reaches a border replaced another way.
    MeetsReplaced(usize),
}

impl StripFailure {
    /// The reason reported for the loop left.
    pub(super) fn reason(self) -> LeftReason {
        match self {
            Self::TooDeep => LeftReason::TooFarFromBorder { rings: MAX_DEPTH },
            Self::Wall => LeftReason::TangledWall,
            Self::Splits => LeftReason::SplitsMesh,
            Self::Turned { turned, faces } => LeftReason::DoublesBack { turned, faces },
            Self::MeetsReplaced(_) => LeftReason::MeetsAnotherBorder,
        }
    }
}

/// The smoothed loop with the direction into the surface along it.
pub(super) struct Guide {
    points: Vec<Point3>,
    /// Unit direction into the surface, per segment (j to j + 1).
    inward: Vec<Point3>,
    /// Arc length at each vertex, from vertex 0; the last entry is the
    /// loop's length.
    arc: Vec<f64>,
    tree: PointTree,
}

/// The nearest point of a guide: its segment, the position along it
/// (0 to 1) and the squared distance.
#[derive(Debug, Clone, Copy)]
struct Nearest {
    segment: usize,
    t: f64,
    d2: f64,
}

impl Guide {
    /// The guide of border `l`'s smoothed loop, running as the border runs
    /// (the surface on its left).
    pub(super) fn new(cx: &Context, l: usize, ring: &Ring) -> Option<Guide> {
        let border = &cx.borders[l];
        let mut points = ring.p3.clone();
        let mut references = ring.reference.clone();
        if !runs_as_border(border, &ring.reference) {
            points.reverse();
            references.reverse();
        }
        let m = points.len();
        if m < 3 {
            return None;
        }
        if let Some(view) = cx.view {
            smooth_depth(&mut points, view, DEPTH_SIGMA * cx.beta_median);
            if let Some(max) = cx.max_deviation {
                tolerance::keep_within(&mut points, &references, &cx.mesh.vertices, max);
            }
        }
        // The direction into the surface at each smoothed vertex, from the
        // border vertex nearest it.
        let at_border: Vec<Point3> = border
            .iter()
            .map(|&v| cx.mesh.vertices[v as usize])
            .collect();
        let border_tree = PointTree::new(&at_border)?;
        let into_faces: Vec<Point3> = points
            .iter()
            .map(|p| into_the_faces(cx, border[border_tree.nearest(p).0]))
            .collect();
        let inward = (0..m)
            .map(|j| {
                let k = (j + 1) % m;
                let t = unit(sub(points[k], points[j]));
                let d = add(into_faces[j], into_faces[k]);
                unit(sub(d, scale(t, dot(d, t))))
            })
            .collect();
        let arc = arc_lengths(&points, true);
        // A loop of one point (or of non-finite length) has no direction
        // along it.
        if !arc[m].is_finite() || arc[m] <= 0.0 {
            return None;
        }
        let tree = PointTree::new(&points)?;
        Some(Guide {
            points,
            inward,
            arc,
            tree,
        })
    }

    fn len(&self) -> usize {
        self.points.len()
    }

    /// The place of a strip vertex: a mesh vertex, or (ids from the mesh's
    /// vertex count on) a vertex of the smoothed loop.
    fn position(&self, cx: &Context, id: u32) -> Point3 {
        let n = cx.mesh.vertices.len() as u32;
        if id < n {
            cx.mesh.vertices[id as usize]
        } else {
            self.points[(id - n) as usize]
        }
    }

    fn length(&self) -> f64 {
        self.arc[self.len()]
    }

    fn on_segment(&self, j: usize, p: Point3) -> Nearest {
        let a = self.points[j];
        let b = self.points[(j + 1) % self.len()];
        let t = segment_param(p, a, b);
        let q = add(a, scale(sub(b, a), t));
        Nearest {
            segment: j,
            t,
            d2: dist2(p, q),
        }
    }

    /// The nearest point among the segments round the few nearest
    /// vertices.
    fn nearest(&self, p: Point3) -> Nearest {
        let m = self.len();
        let found = self.tree.nearest_n(
            &p,
            std::num::NonZeroUsize::new(4.min(m)).unwrap_or(std::num::NonZeroUsize::MIN),
        );
        let mut best: Option<Nearest> = None;
        for (_, j) in found {
            for segment in [(j as usize + m - 1) % m, j as usize] {
                let near = self.on_segment(segment, p);
                if best.is_none_or(|b| near.d2 < b.d2) {
                    best = Some(near);
                }
            }
        }
        best.unwrap_or(Nearest {
            segment: 0,
            t: 0.0,
            d2: f64::INFINITY,
        })
    }

    /// Whether a vertex at `p` of local resolution `beta` goes: it lies
    /// less than [`MARGIN`]·β deep behind the smoothed loop, or beyond it,
    /// and within [`REACH`]·β of it (farther, the direction into the
    /// surface measured at the loop says nothing of it).
    fn goes(&self, p: Point3, beta: f64) -> bool {
        let (depth, distance) = self.depth(p);
        depth < MARGIN * beta && distance < REACH * beta
    }

    /// How deep `p` lies in the surface behind the smoothed loop (negative
    /// beyond it), and its distance from the loop.
    fn depth(&self, p: Point3) -> (f64, f64) {
        let near = self.nearest(p);
        let m = self.len();
        let j = near.segment;
        let direction = if near.t <= 0.0 {
            unit(add(self.inward[(j + m - 1) % m], self.inward[j]))
        } else if near.t >= 1.0 {
            unit(add(self.inward[j], self.inward[(j + 1) % m]))
        } else {
            self.inward[j]
        };
        let a = self.points[j];
        let q = add(a, scale(sub(self.points[(j + 1) % m], a), near.t));
        (dot(sub(p, q), direction), near.d2.sqrt())
    }

    /// The surface normal at segment `j` (the segment, then the direction
    /// into the surface, turn counter-clockwise about it).
    fn normal(&self, j: usize) -> Point3 {
        let m = self.len();
        let t = unit(sub(self.points[(j + 1) % m], self.points[j]));
        cross(t, self.inward[j])
    }
}

/// Whether a smoothed loop whose vertices were smoothed from the border
/// vertices `reference` runs the way the border does.
fn runs_as_border(border: &[u32], reference: &[u32]) -> bool {
    let n = border.len() as i64;
    let position: HashMap<u32, i64> = border
        .iter()
        .enumerate()
        .map(|(i, &v)| (v, i as i64))
        .collect();
    let mut turn = 0i64;
    for j in 0..reference.len() {
        let (Some(&a), Some(&b)) = (
            position.get(&reference[j]),
            position.get(&reference[(j + 1) % reference.len()]),
        ) else {
            continue;
        };
        let mut step = (b - a).rem_euclid(n);
        if step > n / 2 {
            step -= n;
        }
        turn += step;
    }
    turn >= 0
}

/// The mean unit direction from border vertex `r` to the centroids of its
/// faces: into the surface.
fn into_the_faces(cx: &Context, r: u32) -> Point3 {
    let p = cx.mesh.vertices[r as usize];
    cx.topology
        .faces_of(r)
        .iter()
        .map(|&f| {
            let c = cx.mesh.faces[f as usize]
                .map(|v| cx.mesh.vertices[v as usize])
                .iter()
                .fold([0.0; 3], |acc, &q| add(acc, scale(q, 1.0 / 3.0)));
            unit(sub(c, p))
        })
        .fold([0.0; 3], add)
}

/// A strip's patch, with the loops it absorbs and the faces whose
/// neighbourhood it changes.
pub(super) struct Strip {
    pub(super) patch: Patch,
    /// The removed faces and every face sharing a vertex with them.
    pub(super) footprint: Vec<u32>,
}

/// Border `l` replaced by a strip (see the module doc). `replaced` marks
/// the loops other patches replace: the cut may not reach them.
pub(super) fn replace_by_strip(
    cx: &Context,
    l: usize,
    replaced: &[bool],
) -> Result<Strip, StripFailure> {
    let ring = cx.rings[l].as_ref().ok_or(StripFailure::Wall)?;
    let guide = Guide::new(cx, l, ring).ok_or(StripFailure::Wall)?;
    let owner = border_owner(cx);
    // Vertices of kept faces a strip passed through go, and so do the
    // wall's vertices where it folded over itself, and the strip is made
    // again; the one that crosses least stays (the first on a tie).
    let site = Site {
        cx,
        l,
        guide: &guide,
        owner: &owner,
        replaced,
    };
    let mut pushed = BTreeSet::new();
    let mut best = strip_once(site, &pushed)?;
    let mut to_push = std::mem::take(&mut best.to_push);
    let mut since_best = 0;
    for _ in 0..CROSSING_ROUNDS {
        if to_push.is_empty() || since_best == PATIENCE {
            break;
        }
        pushed.extend(to_push);
        let Ok(mut again) = strip_once(site, &pushed) else {
            break;
        };
        to_push = std::mem::take(&mut again.to_push);
        if again.crossings < best.crossings {
            best = again;
            since_best = 0;
        } else {
            since_best += 1;
        }
    }
    Ok(best.strip)
}

/// What every attempt at one border's strip reads: border `l`, its guide,
/// the border each border vertex is on, and the loops other patches
/// replace.
#[derive(Clone, Copy)]
struct Site<'a> {
    cx: &'a Context<'a>,
    l: usize,
    guide: &'a Guide,
    owner: &'a HashMap<u32, usize>,
    replaced: &'a [bool],
}

/// A strip made once, and how it crosses the kept faces and itself.
struct Made {
    strip: Strip,
    /// The vertices that should go for it not to cross: those of the kept
    /// faces it passes through, and the wall's at its folds.
    to_push: Vec<u32>,
    /// Kept faces it passes through, and pairs of its faces that cross.
    crossings: usize,
}

/// The strip of the site's border (steps 2–5) with the vertices of
/// `pushed` going too.
fn strip_once(site: Site, pushed: &BTreeSet<u32>) -> Result<Made, StripFailure> {
    let Site { cx, l, guide, .. } = site;
    let (cut, removed) = cut_and_removed(site, pushed)?;
    let (removed, wall) = closed_wall(cx, removed)?;
    let faces = zip(cx, guide, &wall)?;
    let n = cx.mesh.vertices.len() as u32;
    let m = guide.len() as u32;
    let position = |id: u32| guide.position(cx, id);
    let joined = |a: u32, b: u32| {
        a < n && b < n && (face_running(cx, a, b).is_some() || face_running(cx, b, a).is_some())
    };
    let (faces, mut added) = refine_strip(&faces, &position, &joined, n + m, cx.beta_median);
    if let Some(max) = cx.max_deviation {
        tolerance::pull_within(&mut added, cx.mesh, &removed, max);
    }
    let mut vertices = guide.points.clone();
    vertices.extend(added);
    let at = |id: u32| match id.checked_sub(n) {
        None => cx.mesh.vertices[id as usize],
        Some(k) => vertices[k as usize],
    };
    let cell = CROSSING_CELL * cx.beta_median;
    let crossed = crossing::kept_faces_crossed(cx.mesh, &removed, &faces, &at, cell);
    let folds = crossing::crossing_pairs_filed(&faces, &at, cell);
    let mut to_push: Vec<u32> = crossed
        .iter()
        .flat_map(|&f| cx.mesh.faces[f as usize])
        .chain(wall_at_folds(&faces, &folds, n))
        .collect();
    to_push.sort_unstable();
    to_push.dedup();
    let footprint = footprint(cx, &removed);
    let mut loops = vec![l];
    loops.extend(cut.absorbed.iter().copied());
    let strip = Strip {
        patch: Patch {
            loops,
            removed,
            vertices,
            faces,
            reaches_far: false,
        },
        footprint,
    };
    Ok(Made {
        strip,
        to_push,
        crossings: crossed.len() + folds.len(),
    })
}

/// The wall's vertices (ids below `n`) of the strip faces in `folds`, or
/// where a face has none, of the strip faces sharing a vertex with it.
fn wall_at_folds(faces: &[[u32; 3]], folds: &[(u32, u32)], n: u32) -> Vec<u32> {
    let on_wall = |f: &[u32; 3]| f.iter().copied().filter(|&v| v < n).collect::<Vec<u32>>();
    let mut wall = Vec::new();
    for f in folds.iter().flat_map(|&(a, b)| [a, b]) {
        let face = &faces[f as usize];
        let own = on_wall(face);
        if own.is_empty() {
            for other in faces.iter().filter(|g| g.iter().any(|v| face.contains(v))) {
                wall.extend(on_wall(other));
            }
        } else {
            wall.extend(own);
        }
    }
    wall
}

/// The cut (step 2) and the faces it removes. A border kept out of the
/// cut that lies one face from an absorbed one cannot keep the faces
/// between them: it is absorbed too, and the cut made again.
fn cut_and_removed(site: Site, pushed: &BTreeSet<u32>) -> Result<(Cut, Vec<u32>), StripFailure> {
    let Site {
        cx,
        l,
        owner,
        replaced,
        ..
    } = site;
    let mut forced = BTreeSet::new();
    loop {
        let cut = Cut::new(site, &forced, pushed)?;
        let removed = cut.removed_faces(cx);
        let (kept, touched) = clear_of_other_borders(cx, l, &cut, owner, removed);
        // A smaller border another patch replaces would be absorbed if that
        // patch gave way: say so, rather than leave a wall that runs into
        // it.
        if let Some(&k) = touched
            .iter()
            .find(|&&k| replaced[k] && cx.borders[k].len() < cx.borders[l].len())
        {
            return Err(StripFailure::MeetsReplaced(k));
        }
        let absorbable = touched
            .iter()
            .all(|&k| !replaced[k] && cx.borders[k].len() < cx.borders[l].len());
        if touched.is_empty() || !absorbable || forced.len() >= MAX_ABSORBED {
            return Ok((cut, kept));
        }
        forced.extend(cut.absorbed.iter().copied());
        forced.extend(touched);
    }
}

/// The border loop each border vertex is on.
fn border_owner(cx: &Context) -> HashMap<u32, usize> {
    cx.borders
        .iter()
        .enumerate()
        .flat_map(|(l, b)| b.iter().map(move |&v| (v, l)))
        .collect()
}

/// The vertices that go (step 2).
struct Cut {
    going: HashSet<u32>,
    absorbed: BTreeSet<usize>,
}

impl Cut {
    fn new(
        site: Site,
        forced: &BTreeSet<usize>,
        pushed: &BTreeSet<u32>,
    ) -> Result<Cut, StripFailure> {
        let Site {
            cx,
            l,
            guide,
            owner,
            replaced,
        } = site;
        let mut cut = Cut {
            going: HashSet::default(),
            absorbed: forced.clone(),
        };
        let mut protected: HashSet<u32> = HashSet::default();
        let mut seen: HashSet<u32> = HashSet::default();
        let mut frontier: Vec<u32> = cx.borders[l].clone();
        let own: HashSet<u32> = frontier.iter().copied().collect();
        frontier.extend(pushed.iter().filter(|v| !own.contains(v)));
        for &v in &frontier {
            cut.going.insert(v);
            seen.insert(v);
        }
        // A border that shares a vertex with this one (they touch at a
        // pinched vertex) loses its faces there: it goes too.
        for (other, border) in cx.borders.iter().enumerate() {
            if other != l
                && !forced.contains(&other)
                && border.iter().any(|v| cut.going.contains(v))
            {
                if border.len() >= cx.borders[l].len() {
                    return Err(StripFailure::Wall);
                }
                if replaced[other] {
                    return Err(StripFailure::MeetsReplaced(other));
                }
                cut.absorbed.insert(other);
            }
        }
        for &other in &cut.absorbed {
            for &v in &cx.borders[other] {
                if cut.going.insert(v) {
                    seen.insert(v);
                    frontier.push(v);
                }
            }
        }
        let goes = |v: u32| guide.goes(cx.mesh.vertices[v as usize], cx.beta.beta(v as usize));
        for _ in 0..MAX_DEPTH {
            let mut next = Vec::new();
            for &v in &frontier {
                for &f in cx.topology.faces_of(v) {
                    for w in cx.mesh.faces[f as usize] {
                        if !seen.insert(w) || protected.contains(&w) {
                            continue;
                        }
                        if let Some(&other) = owner.get(&w) {
                            if other != l && !cut.absorbed.contains(&other) {
                                cut.meet_border(cx, l, other, guide, replaced, &mut protected)?;
                                if !cut.absorbed.contains(&other) {
                                    continue;
                                }
                                for &b in &cx.borders[other] {
                                    if cut.going.insert(b) {
                                        seen.insert(b);
                                        next.push(b);
                                    }
                                }
                                continue;
                            }
                        }
                        if goes(w) {
                            cut.going.insert(w);
                            next.push(w);
                        }
                    }
                }
            }
            if next.is_empty() {
                return Ok(cut);
            }
            next.sort_unstable();
            frontier = next;
        }
        Err(StripFailure::TooDeep)
    }

    /// The cut reaches border `other`: absorbed when most of its vertices
    /// lie beyond the smoothed loop (or within the margin), else kept out
    /// of the cut with the vertices round it.
    fn meet_border(
        &mut self,
        cx: &Context,
        l: usize,
        other: usize,
        guide: &Guide,
        replaced: &[bool],
        protected: &mut HashSet<u32>,
    ) -> Result<(), StripFailure> {
        let border = &cx.borders[other];
        let beyond = border
            .iter()
            .filter(|&&v| guide.goes(cx.mesh.vertices[v as usize], cx.beta.beta(v as usize)))
            .count();
        // A border one face from this one cannot keep the faces between.
        let own: HashSet<u32> = cx.borders[l].iter().copied().collect();
        let touching = border.iter().any(|&v| {
            cx.topology
                .faces_of(v)
                .iter()
                .any(|&f| cx.mesh.faces[f as usize].iter().any(|w| own.contains(w)))
        });
        // Only a smaller border is absorbed: never the outer border into a
        // hole.
        let smaller = border.len() < cx.borders[l].len();
        if smaller && (touching || 2 * beyond > border.len()) {
            if replaced[other] {
                return Err(StripFailure::MeetsReplaced(other));
            }
            self.absorbed.insert(other);
        } else if touching {
            return Err(StripFailure::Wall);
        } else {
            for &v in border {
                protected.insert(v);
                for &f in cx.topology.faces_of(v) {
                    protected.extend(cx.mesh.faces[f as usize]);
                }
            }
            // Vertices found going before the border was met stay, but
            // the old border goes whatever is near it.
            self.going.retain(|v| !protected.contains(v));
            self.going.extend(cx.borders[l].iter().copied());
            for &k in &self.absorbed {
                self.going.extend(cx.borders[k].iter().copied());
            }
        }
        Ok(())
    }

    /// The faces with a vertex that goes, ascending.
    fn removed_faces(&self, cx: &Context) -> Vec<u32> {
        let faces: BTreeSet<u32> = self
            .going
            .iter()
            .flat_map(|&v| cx.topology.faces_of(v).iter().copied())
            .collect();
        faces.into_iter().collect()
    }
}

/// The removed faces without those that touch a border neither replaced
/// nor absorbed (the cut reached it between two of its own vertices). When
/// such a face holds a vertex that must go (of this border or an absorbed
/// one), it is kept all the same, and the borders it touches are given
/// too.
fn clear_of_other_borders(
    cx: &Context,
    l: usize,
    cut: &Cut,
    owner: &HashMap<u32, usize>,
    removed: Vec<u32>,
) -> (Vec<u32>, BTreeSet<usize>) {
    let stays_on_border = |v: &u32| {
        owner
            .get(v)
            .filter(|&&k| k != l && !cut.absorbed.contains(&k) && !cut.going.contains(v))
            .copied()
    };
    let must_go = |v: &u32| {
        cx.borders[l].contains(v) || owner.get(v).is_some_and(|k| cut.absorbed.contains(k))
    };
    let mut kept = Vec::with_capacity(removed.len());
    let mut touched = BTreeSet::new();
    for f in removed {
        let face = cx.mesh.faces[f as usize];
        let others: Vec<usize> = face.iter().filter_map(stays_on_border).collect();
        if others.is_empty() {
            kept.push(f);
        } else if face.iter().any(must_go) {
            touched.extend(others);
        }
    }
    (kept, touched)
}

/// The removed faces grown until the kept mesh's new border closes into
/// one loop without touching itself (step 3), and that loop: directed as
/// the kept faces run it.
fn closed_wall(cx: &Context, mut removed: Vec<u32>) -> Result<(Vec<u32>, Vec<u32>), StripFailure> {
    for _ in 0..=PINCH_REPAIRS {
        let walls = wall_edges(cx, &removed);
        let mut next: HashMap<u32, Vec<u32>> = HashMap::default();
        for &(a, b) in &walls {
            next.entry(a).or_default().push(b);
        }
        let mut pinched: Vec<u32> = next
            .iter()
            .filter(|(_, to)| to.len() > 1)
            .map(|(&v, _)| v)
            .collect();
        if pinched.is_empty() {
            let loops = chain(&next).ok_or(StripFailure::Wall)?;
            match loops.len() {
                0 => return Err(StripFailure::Wall),
                1 => return Ok((removed, loops.into_iter().next().unwrap_or_default())),
                _ => {
                    let (grown, main) = without_islands(cx, removed, loops)?;
                    removed = grown;
                    if let Some(main) = main {
                        return Ok((removed, main));
                    }
                    continue;
                }
            }
        }
        pinched.sort_unstable();
        let mut all: BTreeSet<u32> = removed.into_iter().collect();
        for v in pinched {
            all.extend(cx.topology.faces_of(v).iter().copied());
        }
        removed = all.into_iter().collect();
    }
    Err(StripFailure::Wall)
}

/// The directed edges of kept faces whose other face is removed, ascending.
fn wall_edges(cx: &Context, removed: &[u32]) -> Vec<(u32, u32)> {
    let is_removed = |f: u32| removed.binary_search(&f).is_ok();
    let mut walls = Vec::new();
    for &f in removed {
        let face = cx.mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            // The kept face on the other side runs the edge from b to a.
            if face_running(cx, b, a).is_some_and(|g| !is_removed(g)) {
                walls.push((b, a));
            }
        }
    }
    walls.sort_unstable();
    walls.dedup();
    walls
}

/// Whether `face` runs the edge from `a` to `b`.
pub(super) fn runs(face: [u32; 3], a: u32, b: u32) -> bool {
    (0..3).any(|k| face[k] == a && face[(k + 1) % 3] == b)
}

/// The face that runs the edge from `a` to `b` (one at most: the mesh is
/// checked manifold and oriented).
fn face_running(cx: &Context, a: u32, b: u32) -> Option<u32> {
    cx.topology
        .faces_of(a)
        .iter()
        .copied()
        .find(|&g| runs(cx.mesh.faces[g as usize], a, b))
}

/// The loops of a map where every vertex has one successor; `None` when a
/// chain ends.
fn chain(next: &HashMap<u32, Vec<u32>>) -> Option<Vec<Vec<u32>>> {
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut done: HashSet<u32> = HashSet::default();
    let mut loops = Vec::new();
    for s in starts {
        if done.contains(&s) {
            continue;
        }
        let mut lp = vec![s];
        done.insert(s);
        let mut v = *next.get(&s)?.first()?;
        while v != s {
            if !done.insert(v) {
                return None;
            }
            lp.push(v);
            v = *next.get(&v)?.first()?;
        }
        loops.push(lp);
    }
    Some(loops)
}

/// Where the wall has several loops: kept islands the cut surrounds (kept
/// faces whose whole border is one wall loop, fewer than the removed ones)
/// are removed too. The removed faces and, when only one loop is left that
/// is no island, that loop; two loops bounding large kept parts mean the
/// smoothed loop would cut the mesh in two.
fn without_islands(
    cx: &Context,
    removed: Vec<u32>,
    loops: Vec<Vec<u32>>,
) -> Result<(Vec<u32>, Option<Vec<u32>>), StripFailure> {
    let mut all: BTreeSet<u32> = removed.iter().copied().collect();
    let mut mainland = Vec::new();
    let limit = removed.len();
    for lp in loops {
        match island(cx, &removed, &lp, limit) {
            Some(faces) => all.extend(faces),
            None => mainland.push(lp),
        }
    }
    let removed: Vec<u32> = all.into_iter().collect();
    match mainland.len() {
        0 => Err(StripFailure::Wall),
        1 if removed.len() == limit => Ok((removed, mainland.pop())),
        1 => Ok((removed, None)),
        _ => Err(StripFailure::Splits),
    }
}

/// The kept faces reached from wall loop `lp` without crossing removed
/// faces, when they are fewer than `limit` and bounded by the loop alone.
fn island(cx: &Context, removed: &[u32], lp: &[u32], limit: usize) -> Option<Vec<u32>> {
    let is_removed = |f: u32| removed.binary_search(&f).is_ok();
    let on_loop: HashSet<u32> = lp.iter().copied().collect();
    let mut seen: BTreeSet<u32> = BTreeSet::new();
    let mut stack: Vec<u32> = Vec::new();
    for k in 0..lp.len() {
        let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
        if let Some(g) = face_running(cx, a, b).filter(|&g| !is_removed(g)) {
            if seen.insert(g) {
                stack.push(g);
            }
        }
    }
    while let Some(f) = stack.pop() {
        if seen.len() > limit {
            return None;
        }
        let face = cx.mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            match face_running(cx, b, a) {
                // A mesh border other than the wall: the part is no island.
                None if !(on_loop.contains(&a) && on_loop.contains(&b)) => return None,
                Some(g) if !is_removed(g) && seen.insert(g) => stack.push(g),
                _ => {}
            }
        }
    }
    Some(seen.into_iter().collect())
}

/// The strip's faces (step 4): the wall (as the kept faces run it) and the
/// smoothed loop zipped in the order of their positions along the loop.
/// Ids from the mesh's vertex count on are the guide's vertices.
fn zip(cx: &Context, guide: &Guide, wall: &[u32]) -> Result<Vec<[u32; 3]>, StripFailure> {
    let n = cx.mesh.vertices.len() as u32;
    let m = guide.len();
    let p = wall.len();
    let length = guide.length();
    let position = |v: u32| cx.mesh.vertices[v as usize];
    // Start at the wall vertex nearest the smoothed loop.
    let distance: Vec<f64> = wall
        .iter()
        .map(|&v| guide.nearest(position(v)).d2)
        .collect();
    let first = (0..p)
        .min_by(|&a, &b| distance[a].total_cmp(&distance[b]).then(a.cmp(&b)))
        .unwrap_or(0);
    let wall: Vec<u32> = (0..p).map(|i| wall[(first + i) % p]).collect();
    let start = guide.nearest(position(wall[0]));
    let along = |near: Nearest| {
        guide.arc[near.segment] + near.t * (guide.arc[near.segment + 1] - guide.arc[near.segment])
    };
    let origin = along(start);
    let wall_points: Vec<Point3> = wall.iter().map(|&v| position(v)).collect();
    let mut wall_at = place_along(
        &guide.points,
        &guide.arc,
        &wall_points,
        (start.segment, start.t),
    );
    let turns = *wall_at.last().unwrap_or(&0.0);
    if turns < length / 2.0 {
        return Err(StripFailure::Wall);
    }
    wall_at.push(length);
    // Guide vertices from the first at or after the start, placed
    // relative to it and increasing.
    let j0 = if start.t > 0.0 {
        (start.segment + 1) % m
    } else {
        start.segment
    };
    let first_at = (guide.arc[j0] - origin).rem_euclid(length);
    let guide_at: Vec<f64> = (0..=m)
        .map(|k| {
            let j = (j0 + k) % m;
            match k {
                0 => first_at,
                _ if k == m => first_at + length,
                _ => first_at + (guide.arc[j] - guide.arc[j0]).rem_euclid(length),
            }
        })
        .collect();
    let wid = |i: usize| wall[i % p];
    let gid = |k: usize| n + ((j0 + k) % m) as u32;
    let mut faces = Vec::with_capacity(p + m);
    let (mut i, mut k) = (0, 0);
    while i < p || k < m {
        let advance_wall = k == m
            || (i < p && {
                // Both ways keep the order within a segment of the loop:
                // the shorter new edge makes the rounder face.
                let slack = guide_at[k + 1] - guide_at[k];
                let wall_may = wall_at[i + 1] <= guide_at[k + 1] + slack;
                let guide_may = guide_at[k + 1] <= wall_at[i + 1] + slack;
                if wall_may && guide_may {
                    let to_wall = dist2(position(wall[(i + 1) % p]), guide.points[(j0 + k) % m]);
                    let to_guide = dist2(position(wall[i]), guide.points[(j0 + k + 1) % m]);
                    to_wall <= to_guide
                } else {
                    wall_may
                }
            });
        if advance_wall {
            faces.push([wid(i + 1), wid(i), gid(k)]);
            i += 1;
        } else {
            faces.push([gid(k), gid(k + 1), wid(i)]);
            k += 1;
        }
    }
    let turned = faces.iter().filter(|f| turns_against(cx, guide, f)).count();
    if turned as f64 > MAX_TURNED * faces.len() as f64 {
        return Err(StripFailure::Turned {
            turned,
            faces: faces.len(),
        });
    }
    Ok(faces)
}

/// Whether a strip face turns against the surface at the nearest segment
/// of the smoothed loop.
fn turns_against(cx: &Context, guide: &Guide, face: &[u32; 3]) -> bool {
    let p = face.map(|id| guide.position(cx, id));
    let normal = cross(sub(p[1], p[0]), sub(p[2], p[0]));
    let centre = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
    let near = guide.nearest(centre);
    dot(normal, guide.normal(near.segment)) < 0.0
}

/// The removed faces and every face sharing a vertex with them, ascending.
fn footprint(cx: &Context, removed: &[u32]) -> Vec<u32> {
    let faces: BTreeSet<u32> = removed
        .iter()
        .flat_map(|&f| cx.mesh.faces[f as usize])
        .flat_map(|v| cx.topology.faces_of(v).iter().copied())
        .collect();
    faces.into_iter().collect()
}

/// Smooths the closed loop `points`' depth along `view` (a unit vector):
/// each point's depth becomes the value at the point of the quadratic (in
/// arc length) fitted by least squares to the depths around it, weighted
/// by a Gaussian of width `sigma` cut at [`DEPTH_WINDOW`]·σ on either
/// side. A quadratic, not a weighted mean, so that a rim curving in depth
/// keeps its curve while jumps a few samples wide go. Each point moves
/// along `view` only, so the loop's outline across the view is kept. A
/// loop of no length, or a `sigma` that is not positive, is left as it is.
fn smooth_depth(points: &mut [Point3], view: Point3, sigma: f64) {
    let m = points.len();
    if m < 2 {
        return;
    }
    let depth: Vec<f64> = points.iter().map(|&p| dot(p, view)).collect();
    // Arc length along the loop itself, not along its outline: where the
    // surface really turns away (past a silhouette) the outline folds
    // back, and a window over its length would span far along the
    // surface.
    let arc = arc_lengths(points, true);
    let total = arc[m];
    let reach = DEPTH_WINDOW * sigma;
    if !(total > 0.0 && total.is_finite() && sigma > 0.0) {
        return;
    }
    let weight = |along: f64| (-0.5 * (along / sigma).powi(2)).exp();
    let smoothed: Vec<f64> = (0..m)
        .map(|i| {
            // Depths relative to the point's own, so that a loop far from
            // the origin keeps its digits in the sums.
            let mut fit = LocalFit::default();
            fit.take(0.0, 1.0, 0.0);
            // Each neighbour within reach counts once, the short way round:
            // walking ahead, those no farther ahead than behind …
            for step in 1..m {
                let j = (i + step) % m;
                let ahead = forward(&arc, i, j, total);
                if ahead > reach {
                    break;
                }
                if ahead <= total - ahead {
                    fit.take(ahead / sigma, weight(ahead), depth[j] - depth[i]);
                }
            }
            // … and walking behind, the others.
            for step in 1..m {
                let j = (i + m - step) % m;
                let behind = forward(&arc, j, i, total);
                if behind > reach {
                    break;
                }
                if behind < total - behind {
                    fit.take(-behind / sigma, weight(behind), depth[j] - depth[i]);
                }
            }
            depth[i] + fit.quadratic_at_zero()
        })
        .collect();
    for ((p, d), s) in points.iter_mut().zip(&depth).zip(&smoothed) {
        *p = add(*p, scale(view, s - d));
    }
}

/// Weighted moments of depth against a signed offset t along the loop.
#[derive(Default)]
struct LocalFit {
    /// Σ w tᵏ for k = 0..4.
    t: [f64; 5],
    /// Σ w tᵏ d for k = 0..2.
    d: [f64; 3],
}

impl LocalFit {
    fn take(&mut self, t: f64, w: f64, d: f64) {
        let mut power = w;
        for k in 0..5 {
            self.t[k] += power;
            if k < 3 {
                self.d[k] += power * d;
            }
            power *= t;
        }
    }

    fn mean(&self) -> f64 {
        self.d[0] / self.t[0]
    }

    /// The weighted least-squares quadratic's value at t = 0; the mean
    /// where the offsets cannot fix a quadratic.
    fn quadratic_at_zero(&self) -> f64 {
        let [s0, s1, s2, s3, s4] = self.t;
        let [d0, d1, d2] = self.d;
        // Cramer's rule on the 3×3 normal equations, for the constant.
        let det = s0 * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s3 * s2) + s2 * (s1 * s3 - s2 * s2);
        let scale = s0 * s2 * s4;
        if det.is_nan() || det <= 1e-9 * scale {
            return self.mean();
        }
        (d0 * (s2 * s4 - s3 * s3) - s1 * (d1 * s4 - s3 * d2) + s2 * (d1 * s3 - s2 * d2)) / det
    }
}

/// Arc length from loop vertex `from` forwards to vertex `to`.
fn forward(arc: &[f64], from: usize, to: usize, total: f64) -> f64 {
    if to >= from {
        arc[to] - arc[from]
    } else {
        total - arc[from] + arc[to]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};

    /// A circle of `n` points round the z axis, of radius 10, its depth
    /// (z) `depth(i)`.
    fn circle(n: usize, depth: impl FnMut(usize) -> f64) -> Vec<Point3> {
        let turns: Vec<f64> = (0..n).map(|i| i as f64 / n as f64).collect();
        circle_at(&turns, depth)
    }

    /// Points on the same circle at the given fractions of a turn.
    fn circle_at(turns: &[f64], mut depth: impl FnMut(usize) -> f64) -> Vec<Point3> {
        turns
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let a = std::f64::consts::TAU * t;
                [10.0 * a.cos(), 10.0 * a.sin(), depth(i)]
            })
            .collect()
    }

    /// The plain fit: every point of the loop, its signed offset the short
    /// way round, the weighted quadratic solved by nalgebra (the weighted
    /// mean where the window cannot fix a quadratic): the reference for
    /// the windowed walk and its closed-form solve.
    fn smooth_depth_reference(points: &[Point3], view: Point3, sigma: f64) -> Vec<f64> {
        let m = points.len();
        let arc = arc_lengths(points, true);
        let total = arc[m];
        (0..m)
            .map(|i| {
                let mut rows = Vec::new();
                for j in 0..m {
                    let ahead = (arc[j] - arc[i]).rem_euclid(total);
                    let t = if ahead <= total - ahead {
                        ahead
                    } else {
                        ahead - total
                    };
                    if t.abs() <= DEPTH_WINDOW * sigma {
                        let w = (-0.5 * (t / sigma).powi(2)).exp();
                        rows.push((t / sigma, w, dot(points[j], view)));
                    }
                }
                let a = nalgebra::DMatrix::from_fn(rows.len(), 3, |r, k| {
                    rows[r].1.sqrt() * rows[r].0.powi(k as i32)
                });
                let b = nalgebra::DVector::from_fn(rows.len(), |r, _| rows[r].1.sqrt() * rows[r].2);
                let normal = a.transpose() * &a;
                let mean = rows.iter().map(|r| r.1 * r.2).sum::<f64>()
                    / rows.iter().map(|r| r.1).sum::<f64>();
                if normal.determinant() <= 1e-9 * normal[(0, 0)] * normal[(1, 1)] * normal[(2, 2)] {
                    return mean;
                }
                normal
                    .lu()
                    .solve(&(a.transpose() * b))
                    .map_or(mean, |x| x[0])
            })
            .collect()
    }

    #[test]
    fn depth_is_smoothed_along_the_view_only() {
        // A zig-zag in depth of ±0.2 at every other point (0.63 apart
        // round the circle).
        let zigzag = circle(100, |i| if i % 2 == 0 { 0.2 } else { -0.2 });
        let mut smoothed = zigzag.clone();
        smooth_depth(&mut smoothed, [0.0, 0.0, 1.0], 1.5);
        for (a, b) in zigzag.iter().zip(&smoothed) {
            assert_eq!((a[0], a[1]), (b[0], b[1]), "the outline is kept");
            assert!(b[2].abs() < 0.02, "{b:?}");
        }
        // A constant depth stays where it is.
        let flat = circle(60, |_| 3.25);
        let mut same = flat.clone();
        smooth_depth(&mut same, [0.0, 0.0, 1.0], 1.5);
        for (a, b) in flat.iter().zip(&same) {
            assert!((a[2] - b[2]).abs() < 1e-12);
        }
    }

    #[test]
    fn windowed_smoothing_matches_the_plain_sum() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        for n in [3, 4, 7, 50, 201] {
            // Unevenly spaced: bunched points make the short way round
            // differ from the walk's direction.
            let mut turns: Vec<f64> = (0..n).map(|_| rng.random::<f64>().powi(3)).collect();
            turns.sort_unstable_by(f64::total_cmp);
            let points = circle_at(&turns, |_| rng.random_range(-1.0..1.0));
            for sigma in [0.05, 0.7, 3.0, 100.0] {
                let view = unit([0.1, -0.2, 1.0]);
                let mut fast = points.clone();
                smooth_depth(&mut fast, view, sigma);
                let plain = smooth_depth_reference(&points, view, sigma);
                for (p, d) in fast.iter().zip(&plain) {
                    assert!((dot(*p, view) - d).abs() < 1e-9, "n {n} sigma {sigma}");
                }
            }
        }
    }

    /// A rim that curves in depth keeps its curve: a circle in a tilted
    /// plane, whose depth is a sinusoid along it (a weighted mean would
    /// pull it in by σ²/2 times its curvature, 0.034 here).
    #[test]
    fn depth_that_curves_smoothly_is_kept() {
        let tilted = circle(200, |_| 0.0)
            .into_iter()
            .map(|[x, y, _]| [x, y, 0.3 * x])
            .collect::<Vec<_>>();
        let mut smoothed = tilted.clone();
        smooth_depth(&mut smoothed, [0.0, 0.0, 1.0], 1.5);
        for (a, b) in tilted.iter().zip(&smoothed) {
            assert!((a[2] - b[2]).abs() < 1e-3, "{a:?} {b:?}");
        }
    }

    #[test]
    fn a_loop_of_no_length_is_left_alone() {
        let mut one = vec![[1.0, 2.0, 3.0]; 5];
        smooth_depth(&mut one, [0.0, 0.0, 1.0], 1.0);
        assert_eq!(one, vec![[1.0, 2.0, 3.0]; 5]);
    }
}
