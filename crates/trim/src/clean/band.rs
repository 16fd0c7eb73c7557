//! The band round a border loop (steps 3 and 4 of the cleanup): the faces
//! within a few rings of the border, their projection along the band's
//! mean normal, the smoothed loops in it, and the faces that go.

use super::*;
use crate::geom::segment_dist2;
use crate::spatial::PointTree;

/// The faces within some rings of a group's border, projected.
pub(super) struct Band {
    pub(super) depth: u32,
    /// Ring distance of each band vertex from the border, and the loop
    /// (position in the group) it is nearest to.
    pub(super) rings_from_border: HashMap<u32, (u32, usize)>,
    /// Band faces, ascending.
    pub(super) faces: Vec<u32>,
}

impl Band {
    /// Faces with a vertex less than `depth` rings from the border of the
    /// `group`'s loops.
    pub(super) fn around(cx: &Context, group: &[usize], depth: u32) -> Band {
        let mut distance: HashMap<u32, (u32, usize)> = HashMap::default();
        for (k, &l) in group.iter().enumerate() {
            for &v in &cx.borders[l] {
                distance.entry(v).or_insert((0, k));
            }
        }
        let mut frontier: Vec<u32> = distance.keys().copied().collect();
        frontier.sort_unstable();
        for d in 1..=depth {
            let mut next = Vec::new();
            for &v in &frontier {
                let origin = distance[&v].1;
                for &f in cx.topology.faces_of(v) {
                    for w in cx.mesh.faces[f as usize] {
                        distance.entry(w).or_insert_with(|| {
                            next.push(w);
                            (d, origin)
                        });
                    }
                }
            }
            next.sort_unstable();
            frontier = next;
        }
        let faces: BTreeSet<u32> = distance
            .iter()
            .filter(|&(_, &(d, _))| d < depth)
            .flat_map(|(&v, _)| cx.topology.faces_of(v).iter().copied())
            .collect();
        Band {
            depth,
            rings_from_border: distance,
            faces: faces.into_iter().collect(),
        }
    }

    /// The patch replacing the group's loops, or why not: the smoothed
    /// loops in the band's projection (steps 2 and 3), what goes (step 4)
    /// and the gap filled (step 5).
    /// With `check`, a patch that would break the manifold by itself
    /// ([`where_patch_breaks`]) is refused, its loops there left.
    pub(super) fn replace(
        &self,
        cx: &Context,
        group: &[usize],
        check: bool,
    ) -> Result<Patch, Retry> {
        let mesh = cx.mesh;
        let projection = Projection::of(cx, &self.faces);
        let mut rings = projected_rings(cx, group, &projection);
        let cell = GRID_CELL * cx.beta_median;
        let (grid, _) = untwist(&mut rings, cell, MAX_UNTWIST)
            .map_err(|tangle| untwist_failure(tangle, &rings))?;
        let (rings, grid) = apart(rings, grid, cell);
        let stay = self.staying_vertices(cx, group, &projection, &grid, &rings);
        let removed = self.cut_faces(mesh, &projection, &grid, &stay);
        let turned = self.turned_faces(mesh, &projection);
        let removed = with_turned_neighbours(mesh, removed, &turned, |f| self.is_inner(mesh, f));
        let gap = Gap {
            border_edges: group_border_edges(cx, group),
            folded: turned
                .iter()
                .flat_map(|&f| mesh.faces[f as usize])
                .collect(),
            projection,
            rings,
            stay,
        };
        self.fill_gap(cx, &gap, removed, check)
    }

    /// Whether each vertex of the band's faces stays: it lies on the
    /// surface's side of the smoothed loops (inside an odd number of them
    /// when one is an outer border, of positive area; an even number when
    /// all are holes), farther than [`MARGIN`]·βᵢ from them (closer, it
    /// would only make a sliver against the new border), and is not a
    /// vertex of the group's old border.
    pub(super) fn staying_vertices(
        &self,
        cx: &Context,
        group: &[usize],
        projection: &Projection,
        grid: &SegmentGrid,
        rings: &[Ring],
    ) -> HashMap<u32, bool> {
        let mesh = cx.mesh;
        let has_outer = rings.iter().any(|r| r.area() > 0.0);
        let old_border: BTreeSet<u32> = group
            .iter()
            .flat_map(|&l| cx.borders[l].iter().copied())
            .collect();
        let stays = |v: u32| {
            let p = projection.vertex_to2(mesh, v);
            !old_border.contains(&v)
                && grid.parity(p) == has_outer
                && !grid.near(p, MARGIN * cx.beta.beta(v as usize))
        };
        let mut vertices: Vec<u32> = self
            .faces
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .collect();
        vertices.sort_unstable();
        vertices.dedup();
        // β is found here for most of the band's vertices: on every thread.
        let stay: Vec<bool> = vertices.par_iter().map(|&v| stays(v)).collect();
        vertices.into_iter().zip(stay).collect()
    }

    /// The band's faces with a vertex that goes, or crossed by a smoothed
    /// loop, ascending.
    pub(super) fn cut_faces(
        &self,
        mesh: &Mesh,
        projection: &Projection,
        grid: &SegmentGrid,
        stay: &HashMap<u32, bool>,
    ) -> Vec<u32> {
        let p2 = |v: u32| projection.vertex_to2(mesh, v);
        self.faces
            .par_iter()
            .copied()
            .filter(|&f| {
                let face = mesh.faces[f as usize];
                let all_stay = face.iter().all(|v| stay[v]);
                let crossed =
                    all_stay && (0..3).any(|k| grid.crosses(p2(face[k]), p2(face[(k + 1) % 3])));
                !all_stay || crossed
            })
            .collect()
    }

    /// The band's faces that turn over in the projection (a range scan's
    /// skirt across a depth jump at a silhouette, a fold). They go too
    /// when they touch what goes and lie inside the band
    /// ([`with_turned_neighbours`], [`Band::is_inner`]): the gap filling
    /// replaces them by one layer. Kept faces beyond may turn over: the
    /// new faces join them along the walls with opposite edge directions
    /// all the same (the safety net of [`assemble_manifold`] checks it).
    pub(super) fn turned_faces(&self, mesh: &Mesh, projection: &Projection) -> BTreeSet<u32> {
        self.faces
            .iter()
            .copied()
            .filter(|&f| {
                let [a, b, c] = mesh.faces[f as usize].map(|v| projection.vertex_to2(mesh, v));
                orientation(a, b, c) <= 0.0
            })
            .collect()
    }

    /// Whether every vertex of face `f` lies more than two rings inside
    /// the band's rim.
    pub(super) fn is_inner(&self, mesh: &Mesh, f: u32) -> bool {
        mesh.faces[f as usize]
            .iter()
            .all(|v| self.rings_from_border[v].0 + 2 < self.depth)
    }

    /// Step 5 for the faces `removed`. Where a fold beyond the turned
    /// faces makes two walls cross in the projection, the faces round the
    /// crossing go too, and the gap is triangulated again, a few times at
    /// most ([`WALL_REPAIRS`]).
    pub(super) fn fill_gap(
        &self,
        cx: &Context,
        gap: &Gap,
        mut removed: Vec<u32>,
        check: bool,
    ) -> Result<Patch, Retry> {
        for _ in 0..=WALL_REPAIRS {
            let at_rim = self.loops_reaching_rim(cx.mesh, &removed);
            if !at_rim.is_empty() {
                return Err(Retry::Grow(at_rim.into_iter().collect()));
            }
            match self.triangulate_gap(cx, gap, &removed) {
                Ok(mut patch) => {
                    patch.reaches_far = removes_far_vertices(cx, &gap.rings, &removed);
                    patch.removed = removed;
                    let breaks = if check {
                        where_patch_breaks(cx, &patch)
                    } else {
                        Vec::new()
                    };
                    if breaks.is_empty() {
                        return Ok(patch);
                    }
                    let culprits: BTreeSet<usize> = breaks
                        .iter()
                        .filter_map(|v| self.rings_from_border.get(v))
                        .map(|&(_, origin)| origin)
                        .collect();
                    return Err(leave(
                        LeftReason::NonManifold,
                        culprits.into_iter().collect(),
                    ));
                }
                Err(Blocked::Walls(vertices)) => {
                    let before = removed.len();
                    removed = self.with_faces_round(cx, removed, &vertices);
                    if removed.len() == before {
                        break;
                    }
                }
                Err(Blocked::Other(retry)) => return Err(retry),
            }
        }
        Err(leave(LeftReason::Folds, Vec::new()))
    }

    /// The loops (positions in the group) whose cut reaches the band's
    /// rim: a removed face has a vertex `depth` − 1 or more rings from the
    /// border.
    pub(super) fn loops_reaching_rim(&self, mesh: &Mesh, removed: &[u32]) -> BTreeSet<usize> {
        removed
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .map(|v| self.rings_from_border[&v])
            .filter(|&(d, _)| d + 1 >= self.depth)
            .map(|(_, origin)| origin)
            .collect()
    }

    /// The gap left by the faces `removed`, triangulated: bounded by the
    /// smoothed loops and the walls, with the kept vertices of the removed
    /// faces (not those of the fold's second layer) inside.
    pub(super) fn triangulate_gap(
        &self,
        cx: &Context,
        gap: &Gap,
        removed: &[u32],
    ) -> Result<Patch, Blocked> {
        let mesh = cx.mesh;
        let walls = walls(mesh, &self.faces, removed, &gap.border_edges, &gap.stay);
        let free: BTreeSet<u32> = removed
            .iter()
            .flat_map(|&f| mesh.faces[f as usize])
            .filter(|v| gap.stay[v] && !gap.folded.contains(v))
            .collect();
        triangulate(
            mesh,
            &gap.projection,
            &gap.rings,
            &walls,
            &free,
            cx.beta_median,
        )
    }

    /// `removed` and the band's faces round `vertices` (where two walls
    /// cross), ascending.
    pub(super) fn with_faces_round(
        &self,
        cx: &Context,
        removed: Vec<u32>,
        vertices: &[u32],
    ) -> Vec<u32> {
        let mut all: BTreeSet<u32> = removed.into_iter().collect();
        all.extend(
            vertices
                .iter()
                .flat_map(|&v| cx.topology.faces_of(v).iter().copied())
                .filter(|&f| self.faces.binary_search(&f).is_ok()),
        );
        all.into_iter().collect()
    }
}

/// The best-fit plane of a band, oriented with its faces.
pub(super) struct Projection {
    pub(super) origin: Point3,
    pub(super) u: Point3,
    pub(super) v: Point3,
}

impl Projection {
    /// Fits the band's plane, oriented so the faces face its normal.
    pub(super) fn of(cx: &Context, faces: &[u32]) -> Projection {
        let mesh = cx.mesh;
        let origin = mesh.vertices[mesh.faces[faces[0] as usize][0] as usize];
        // The area-weighted mean face normal, not the best-fit plane: a
        // range scan faces its scanner everywhere, so every face projects
        // the right way up along the mean normal even where a band that
        // curves round a silhouette has a best-fit plane at a steep angle.
        let normal = mesh
            .mean_normal_of(faces.iter().map(|&f| f as usize))
            .unwrap_or_else(|| {
                let members: Vec<u32> =
                    faces.iter().flat_map(|&f| mesh.faces[f as usize]).collect();
                fit_plane(&mesh.vertices, &members).normal
            });
        // Any tangent axis: the coordinate axis least aligned with n.
        let axis = (0..3)
            .min_by(|&a, &b| normal[a].abs().total_cmp(&normal[b].abs()))
            .unwrap_or(0);
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        let u = cross(normal, e);
        let u = u.map(|c| c / norm2(u).sqrt());
        Projection {
            origin,
            u,
            v: cross(normal, u),
        }
    }

    pub(super) fn to2(&self, p: Point3) -> [f64; 2] {
        let d = sub(p, self.origin);
        [dot(d, self.u), dot(d, self.v)]
    }

    /// The projection of the mesh's vertex `v`.
    pub(super) fn vertex_to2(&self, mesh: &Mesh, v: u32) -> [f64; 2] {
        self.to2(mesh.vertices[v as usize])
    }
}

/// The group's smoothed loops in the band's projection, with the vertices
/// that coincide there merged.
pub(super) fn projected_rings(cx: &Context, group: &[usize], projection: &Projection) -> Vec<Ring> {
    group
        .iter()
        .filter_map(|&l| cx.rings[l].as_ref())
        .map(|r| {
            let mut ring = r.clone();
            ring.p2 = ring.p3.iter().map(|&p| projection.to2(p)).collect();
            ring.merge_coincident();
            ring
        })
        .collect()
}

/// The directed edges of the borders of the group's loops.
/// The rings with loops that nearly touch moved apart to [`LOOP_GAP`]·β
/// ([`kept_apart`]) where that makes no crossing, and their segment grid
/// (cells no smaller than `cell`).
fn apart(rings: Vec<Ring>, grid: SegmentGrid, cell: f64) -> (Vec<Ring>, SegmentGrid) {
    if let Some(moved) = kept_apart(&rings, &grid, LOOP_GAP) {
        let moved_grid = SegmentGrid::new(&moved, cell);
        if moved_grid.first_crossing().is_none() {
            return (moved, moved_grid);
        }
    }
    (rings, grid)
}

pub(super) fn group_border_edges(cx: &Context, group: &[usize]) -> BTreeSet<(u32, u32)> {
    group
        .iter()
        .flat_map(|&l| {
            let b = &cx.borders[l];
            (0..b.len()).map(move |i| (b[i], b[(i + 1) % b.len()]))
        })
        .collect()
}

/// `removed` and every turned face connected to it through turned faces
/// (sharing a vertex), ascending.
pub(super) fn with_turned_neighbours(
    mesh: &Mesh,
    removed: Vec<u32>,
    turned: &BTreeSet<u32>,
    inner: impl Fn(u32) -> bool,
) -> Vec<u32> {
    let mut by_vertex: HashMap<u32, Vec<u32>> = HashMap::default();
    for &f in turned {
        for v in mesh.faces[f as usize] {
            by_vertex.entry(v).or_default().push(f);
        }
    }
    let mut all: BTreeSet<u32> = removed.iter().copied().collect();
    let mut stack = removed;
    while let Some(f) = stack.pop() {
        for v in mesh.faces[f as usize] {
            for &g in by_vertex.get(&v).map_or(&[][..], Vec::as_slice) {
                if inner(g) && all.insert(g) {
                    stack.push(g);
                }
            }
        }
    }
    all.into_iter().collect()
}

/// The loop to leave when the smoothed loops cross: the one that crosses
/// itself, or the smaller of two that cross each other.
pub(super) fn untwist_failure(tangle: Tangle, rings: &[Ring]) -> Retry {
    match tangle {
        Tangle::SelfCrossing {
            index,
            vertices,
            dropped,
        } => leave(LeftReason::CrossesItself { dropped, vertices }, vec![index]),
        Tangle::Crossing { a, b } => {
            let smaller = if rings[a].len() <= rings[b].len() {
                a
            } else {
                b
            };
            leave(LeftReason::CrossesAnotherLoop, vec![smaller])
        }
    }
}

/// The mesh vertices where `patch`, applied alone, would make an edge
/// non-manifold: ends of its new edges that kept faces already cover (run
/// the same way by a kept face, or shared by two). This happens where the
/// band's projection folds: a hole's border beside the group bounds no
/// wall where its vertices stay, so the parity of the gap's fill leaks
/// past a wall onto the kept side.
pub(super) fn where_patch_breaks(cx: &Context, patch: &Patch) -> Vec<u32> {
    let n = cx.mesh.vertices.len() as u32;
    let removed: HashSet<u32> = patch.removed.iter().copied().collect();
    let mut breaks = BTreeSet::new();
    for face in &patch.faces {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            if a >= n || b >= n {
                continue;
            }
            let kept: Vec<[u32; 3]> = cx
                .topology
                .faces_of(a)
                .iter()
                .filter(|f| !removed.contains(f))
                .map(|&f| cx.mesh.faces[f as usize])
                .filter(|g| g.contains(&b))
                .collect();
            let same_way = kept.iter().any(|&g| runs(g, a, b));
            if same_way || kept.len() > 1 {
                breaks.insert(a);
            }
        }
    }
    breaks.into_iter().collect()
}

/// Whether the faces `removed` take away more than [`MAX_FAR_REMOVED`]
/// vertices (all their faces) farther than [`REACH`]·β from the smoothed
/// loops `rings` (measured to the segments round the nearest loop vertex).
fn removes_far_vertices(cx: &Context, rings: &[Ring], removed: &[u32]) -> bool {
    let mut points = Vec::new();
    let mut segments = Vec::new();
    for ring in rings {
        let m = ring.p3.len();
        for k in 0..m {
            points.push(ring.p3[k]);
            segments.push([ring.p3[(k + m - 1) % m], ring.p3[k], ring.p3[(k + 1) % m]]);
        }
    }
    let Some(tree) = PointTree::new(&points) else {
        return false;
    };
    let distance2 = |p: Point3| {
        let [before, at, after] = segments[tree.nearest(&p).0];
        segment_dist2(p, before, at).min(segment_dist2(p, at, after))
    };
    let is_removed = |f: &u32| removed.binary_search(f).is_ok();
    let mut candidates: Vec<u32> = removed
        .iter()
        .flat_map(|&f| cx.mesh.faces[f as usize])
        .collect();
    candidates.sort_unstable();
    candidates.dedup();
    let far = candidates.into_iter().filter(|&v| {
        let reach = REACH * cx.beta.beta(v as usize);
        cx.topology.faces_of(v).iter().all(is_removed)
            && distance2(cx.mesh.vertices[v as usize]) > reach * reach
    });
    far.count() > MAX_FAR_REMOVED
}
