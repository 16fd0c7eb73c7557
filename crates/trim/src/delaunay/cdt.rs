//! Steps 5 and 6 of the Delaunay path: the constrained Delaunay
//! triangulation of the points and the loops, its faces on the surface
//! kept, those across an occlusion dropped, and the rest lifted to 3D.

use super::*;

/// A face whose unit normal makes |n_t·s| below this with the line of
/// sight s stands nearly edge-on to the scanner (within 11.5°).
const EDGE_ON_COS: f64 = 0.2;

/// Step 5, the **constrained Delaunay triangulation** (spade, exact
/// predicates) of the inserted points and the rings, with what its loop
/// vertices stand for. Node ids: cloud points below n, loop vertex j at
/// n + j.
pub(super) struct LoopCdt {
    pub(super) cdt: Cdt,
    /// Number of cloud points.
    pub(super) n: usize,
    /// Smoothed 3D position of each loop vertex.
    pub(super) loop_p3: Vec<Point3>,
    /// The boundary point each loop vertex was smoothed from.
    pub(super) loop_ref: Vec<u32>,
    /// The ring each loop vertex belongs to, to name it in errors.
    pub(super) loop_of: Vec<u32>,
    /// Each ring's vertex handles, in ring order.
    pub(super) ring_handles: Vec<Vec<FixedVertexHandle>>,
    /// Where loops crossed, the constraint edges' turns of the winding
    /// ([`winding_faces`]); `None` for parity.
    pub(super) turns: Option<Turns>,
    /// What the errors call the plane.
    pub(super) onto: &'static str,
}

impl LoopCdt {
    /// Bulk-loads the `nodes`, then inserts every ring's vertices and adds
    /// its segments as constraint edges, outer borders first. A ring vertex
    /// or segment that meets another ring's (or its own) is an error, never
    /// a panic in spade; where loops were split at their crossings, those
    /// crossing vertices and the segments between them are shared. Fills
    /// `points_merged` (nodes spade found coincident, the first kept).
    pub(super) fn build(
        nodes: Vec<Node>,
        bounds: &Bounds,
        n: usize,
        report: &mut DelaunayReport,
    ) -> Result<Self, DelaunayError> {
        let rings = &bounds.rings;
        let inserted = nodes.len();
        let cdt: Cdt = if nodes.is_empty() {
            Cdt::new()
        } else {
            Cdt::bulk_load(nodes).map_err(|_| DelaunayError::Input(MeshError::NoFaces))?
        };
        report.points_merged = inserted - cdt.num_vertices();
        let mut t = LoopCdt {
            cdt,
            n,
            loop_p3: Vec::new(),
            loop_ref: Vec::new(),
            loop_of: Vec::new(),
            ring_handles: vec![Vec::new(); rings.len()],
            turns: bounds.sides.as_ref().map(|_| Turns::default()),
            onto: bounds.onto,
        };
        for l in largest_first(rings) {
            let handles = t.insert_ring_vertices(l, &rings[l])?;
            let side = bounds.sides.as_ref().map_or(1, |sides| sides[l]);
            t.constrain_ring(l, rings[l].len(), &handles, side)?;
            t.ring_handles[l] = handles;
        }
        Ok(t)
    }

    /// Inserts the vertices of ring `l`, refusing one that lands on an
    /// existing vertex or on a constraint edge; returns their handles.
    fn insert_ring_vertices(
        &mut self,
        l: usize,
        ring: &Ring,
    ) -> Result<Vec<FixedVertexHandle>, DelaunayError> {
        let mut handles = Vec::with_capacity(ring.p2.len());
        for j in 0..ring.p2.len() {
            let id = (self.n + self.loop_p3.len()) as u32;
            let position = point(ring.p2[j]);
            match self.cdt.locate(position) {
                PositionInTriangulation::OnVertex(h) if self.is_shared_crossing(h, position) => {
                    handles.push(h);
                    continue;
                }
                PositionInTriangulation::OnVertex(h) => {
                    let other = self.cdt.vertex(h).data().id;
                    return Err(self.crossing(l, ring.len(), other));
                }
                PositionInTriangulation::OnEdge(e)
                    if self.cdt.is_constraint_edge(e.as_undirected()) =>
                {
                    let other = self.cdt.directed_edge(e).from().data().id;
                    return Err(self.crossing(l, ring.len(), other));
                }
                _ => {}
            }
            let h = self
                .cdt
                .insert(Node::new(ring.p2[j], id))
                .map_err(|_| DelaunayError::Input(MeshError::NonFinite { index: 0 }))?;
            self.loop_p3.push(ring.p3[j]);
            self.loop_ref.push(ring.reference[j]);
            self.loop_of.push(l as u32);
            handles.push(h);
        }
        Ok(handles)
    }

    /// Where loops were split at their crossings, is `h` a loop vertex at
    /// exactly `position`: a crossing another loop inserted first?
    fn is_shared_crossing(&self, h: FixedVertexHandle, position: spade::Point2<f64>) -> bool {
        let v = self.cdt.vertex(h);
        self.turns.is_some() && v.data().id as usize >= self.n && v.position() == position
    }

    /// Adds the closed polyline through `handles` (ring `l`, of `vertices`
    /// vertices, its surface on the side `side`) as constraint edges,
    /// checking each first with exact predicates: spade panics on crossing
    /// constraints. Where loops were split at their crossings, a segment
    /// two loops share is added once and each turn of the winding noted.
    fn constrain_ring(
        &mut self,
        l: usize,
        vertices: usize,
        handles: &[FixedVertexHandle],
        side: i32,
    ) -> Result<(), DelaunayError> {
        let m = handles.len();
        for j in 0..m {
            let (a, b) = (handles[j], handles[(j + 1) % m]);
            if let Some(turns) = self.turns.as_mut() {
                // Crossing a → b from its right to its left, the winding
                // gains the ring's side.
                let (key, turn) = if a < b {
                    ((a, b), side)
                } else {
                    ((b, a), -side)
                };
                *turns.entry(key).or_default() += turn;
                let shared = self
                    .cdt
                    .get_edge_from_neighbors(a, b)
                    .is_some_and(|e| e.is_constraint_edge());
                if shared {
                    continue;
                }
            }
            if let Some(other) = obstacle(&self.cdt, a, b) {
                return Err(self.crossing(l, vertices, other));
            }
            self.cdt.add_constraint(a, b);
        }
        Ok(())
    }

    /// The error for ring `l` meeting the vertex `other` ([`crossing`]).
    pub(super) fn crossing(&self, l: usize, vertices: usize, other: u32) -> DelaunayError {
        crossing(l, vertices, other, self.n, &self.loop_of, self.onto)
    }

    /// Step 6, **kept faces, lifted**: the odd faces ([`inside_faces`]),
    /// counter-clockwise seen from the plane normal's side, co-circular
    /// quads given their canonical diagonal ([`canonical_diagonals`]) and listed in
    /// the order of their ids, so that moving the cloud, which rounds its
    /// coordinates, changes nothing. Lifted back to 3D: cloud points keep
    /// their exact coordinates, loop vertices take their smoothed 3D
    /// positions. Returns the mesh and, per vertex, the cloud point it is
    /// or was smoothed from. Fills `diagonals_flipped`, `points_used` and
    /// `loops`.
    pub(super) fn lift(
        &self,
        jumps: &DepthJumps,
        report: &mut DelaunayReport,
    ) -> Result<(Mesh, Vec<u32>), DelaunayError> {
        let cloud = jumps.cloud;
        // Jittered and real float clouds have no co-circular quad: the
        // flip pass, which indexes every edge and needs every position, is
        // skipped without changing its result (it flips only where a quad
        // is co-circular).
        let flips_possible = self.has_cocircular_quad();
        let KeptFaces {
            mut faces,
            positions,
            mut used,
        } = self.kept_faces(flips_possible);
        if self.turns.is_some() {
            report.crossing_faces_dropped = pinches_opened(&mut faces, used.len(), self.n, self.n);
        }
        let spans = self.across_occlusions(&faces, jumps);
        report.occlusion_faces_dropped = spans.iter().filter(|&&s| s).count();
        if report.occlusion_faces_dropped > 0 {
            let mut k = 0;
            faces.retain(|_| {
                k += 1;
                !spans[k - 1]
            });
            // Where the dropped faces met at a vertex, the surface may
            // pinch there now, at a cloud point as well as a loop vertex.
            report.occlusion_faces_dropped += pinches_opened(&mut faces, used.len(), self.n, 0);
        }
        if self.turns.is_some() || report.occlusion_faces_dropped > 0 {
            used.fill(false);
            faces
                .iter()
                .flatten()
                .for_each(|&id| used[id as usize] = true);
        }
        report.diagonals_flipped = if flips_possible {
            canonical_diagonals(&positions, &mut faces, &self.constraint_pairs())
        } else {
            0
        };
        sort_faces(&mut faces);
        let (out_index, vertices, reference) = self.number_vertices(cloud, &used);
        report.points_used = out_index[..self.n]
            .iter()
            .filter(|&&s| s != u32::MAX)
            .count();
        let mesh = Mesh {
            vertices,
            faces: faces
                .iter()
                .map(|f| f.map(|id| out_index[id as usize]))
                .collect(),
        };
        report.loops = self.ring_vertices(&out_index);
        mesh.validate()?;
        Ok((mesh, reference))
    }

    /// The cloud point id `id` stands for: itself, or the boundary point a
    /// loop vertex was smoothed from.
    pub(super) fn reference(&self, id: u32) -> u32 {
        match (id as usize).checked_sub(self.n) {
            None => id,
            Some(j) => self.loop_ref[j],
        }
    }

    /// The 3D position of id `id`.
    pub(super) fn position(&self, id: u32, cloud: &[Point3]) -> Point3 {
        match (id as usize).checked_sub(self.n) {
            None => cloud[id as usize],
            Some(j) => self.loop_p3[j],
        }
    }

    /// Step 6, **occlusions**: per face, does it span a depth jump: an
    /// edge longer than [`DelaunayOptions::occlusion_reach`] times the
    /// resolution at both its ends, on a face nearly edge-on to the line of
    /// sight (|n_t·s| < 0.2)?
    fn across_occlusions(&self, faces: &[[u32; 3]], jumps: &DepthJumps) -> Vec<bool> {
        if jumps.reach.is_infinite() {
            return vec![false; faces.len()];
        }
        faces
            .par_iter()
            .map(|f| {
                let p = f.map(|id| self.position(id, jumps.cloud));
                let r = f.map(|id| self.reference(id) as usize);
                let long = (0..3).any(|k| {
                    let (a, b) = (k, (k + 1) % 3);
                    let reach = jumps.reach * jumps.beta[r[a]].max(jumps.beta[r[b]]);
                    norm2(sub(p[b], p[a])) > reach * reach
                });
                long && {
                    let nt = unit(cross(sub(p[1], p[0]), sub(p[2], p[0])));
                    let centroid = [0, 1, 2].map(|c| (p[0][c] + p[1][c] + p[2][c]) / 3.0);
                    dot(nt, jumps.plane.sight(centroid)).abs() < EDGE_ON_COS
                }
            })
            .collect()
    }

    /// Each ring's vertices as output numbers, in ring order; those the
    /// output does not use (where loops crossed) are left out, and rings
    /// with none.
    fn ring_vertices(&self, out_index: &[u32]) -> Vec<Vec<u32>> {
        self.ring_handles
            .iter()
            .map(|hs| {
                hs.iter()
                    .map(|&h| out_index[self.cdt.vertex(h).data().id as usize])
                    .filter(|&v| v != u32::MAX)
                    .collect::<Vec<u32>>()
            })
            .filter(|vertices| !vertices.is_empty())
            .collect()
    }

    /// The faces on the surface: odd by parity, or of winding at least 1
    /// where loops crossed.
    pub(super) fn surface_faces(&self) -> Vec<FixedFaceHandle<InnerTag>> {
        match &self.turns {
            None => inside_faces(&self.cdt),
            Some(turns) => winding_faces(&self.cdt, turns),
        }
    }

    /// The faces on the surface ([`LoopCdt::surface_faces`]),
    /// counter-clockwise.
    fn kept_faces(&self, with_positions: bool) -> KeptFaces {
        let kept = self.surface_faces();
        let mut faces: Vec<[u32; 3]> = Vec::with_capacity(kept.len());
        let mut positions = HashMap::default();
        let mut used = vec![false; self.n + self.loop_p3.len()];
        for f in kept {
            let vs = self.cdt.face(f).vertices();
            let mut ids = vs.map(|v| v.data().id);
            let p = vs.map(|v| v.position());
            let orient =
                (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x);
            if orient < 0.0 {
                ids.swap(1, 2);
            }
            faces.push(ids);
            for (id, p) in vs.map(|v| v.data().id).into_iter().zip(p) {
                used[id as usize] = true;
                if with_positions {
                    positions.insert(id, [p.x, p.y]);
                }
            }
        }
        KeptFaces {
            faces,
            positions,
            used,
        }
    }

    /// Whether some edge that is not a constraint has two triangles whose
    /// quad is co-circular, tested exactly as [`canonical_diagonals`] tests
    /// its first edges (ids a < b, c left of a → b, d left of b → a): if
    /// none is, that pass flips nothing. Faces outside the loops are
    /// tested too, so this can only say yes more often.
    fn has_cocircular_quad(&self) -> bool {
        let at = |v: FixedVertexHandle| {
            let p = self.cdt.vertex(v).position();
            [p.x, p.y]
        };
        self.cdt.undirected_edges().any(|edge| {
            if edge.is_constraint_edge() {
                return false;
            }
            let mut forward = edge.as_directed();
            if forward.from().data().id > forward.to().data().id {
                forward = forward.rev();
            }
            let (Some(c), Some(d)) = (forward.opposite_vertex(), forward.rev().opposite_vertex())
            else {
                return false;
            };
            let [a, b] = [forward.from().fix(), forward.to().fix()];
            cocircular(at(a), at(b), at(c.fix()), at(d.fix()))
        })
    }

    /// The rings' segments as id pairs, smaller id first: diagonals that
    /// are constraints never flip.
    fn constraint_pairs(&self) -> HashSet<[u32; 2]> {
        self.ring_handles
            .iter()
            .flat_map(|hs| {
                (0..hs.len()).map(|j| {
                    let [a, b] =
                        [hs[j], hs[(j + 1) % hs.len()]].map(|h| self.cdt.vertex(h).data().id);
                    [a.min(b), a.max(b)]
                })
            })
            .collect()
    }

    /// Output numbers for the `used` ids, in id order (so cloud points in
    /// cloud order, then loop vertices): returns, per id, its output number
    /// (u32::MAX if unused), and the output vertices with the cloud points
    /// they are or were smoothed from.
    fn number_vertices(
        &self,
        cloud: &[Point3],
        used: &[bool],
    ) -> (Vec<u32>, Vec<Point3>, Vec<u32>) {
        let mut out_index = vec![u32::MAX; used.len()];
        let mut vertices = Vec::new();
        let mut reference = Vec::new();
        for (id, slot) in out_index.iter_mut().enumerate() {
            if used[id] {
                *slot = vertices.len() as u32;
                vertices.push(self.position(id as u32, cloud));
                reference.push(self.reference(id as u32));
            }
        }
        (out_index, vertices, reference)
    }
}

/// What step 6 needs to find the faces that span an occlusion.
pub(super) struct DepthJumps<'a> {
    pub(super) cloud: &'a [Point3],
    pub(super) beta: &'a [f64],
    pub(super) plane: &'a Projection,
    /// [`DelaunayOptions::occlusion_reach`].
    pub(super) reach: f64,
}

/// The faces step 6 keeps, before their diagonals are made canonical.
struct KeptFaces {
    /// Counter-clockwise id triples.
    faces: Vec<[u32; 3]>,
    /// The 2D position of every id they use (empty unless asked for).
    positions: HashMap<u32, [f64; 2]>,
    /// Per id, whether they use it.
    used: Vec<bool>,
}

/// Ring indices, the largest by area first: the outer borders go in
/// before the holes they hold.
fn largest_first(rings: &[Ring]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..rings.len()).collect();
    order.sort_by(|&a, &b| rings[b].area().abs().total_cmp(&rings[a].area().abs()));
    order
}

/// Faces in an order of their own ids (the triangulation's internal
/// order depends on its history), each starting at its lowest id.
fn sort_faces(faces: &mut [[u32; 3]]) {
    for f in faces.iter_mut() {
        *f = lowest_first(*f);
    }
    faces.sort_unstable();
}

/// The error for loop `l` meeting the vertex `other` (a vertex id).
pub(super) fn crossing(
    l: usize,
    vertices: usize,
    other: u32,
    n: usize,
    loop_of: &[u32],
    onto: &'static str,
) -> DelaunayError {
    let b = (other as usize)
        .checked_sub(n)
        .and_then(|j| loop_of.get(j))
        .map_or(l, |&b| b as usize);
    if b == l {
        DelaunayError::LoopNotSimple {
            onto,
            index: l,
            vertices,
            dropped: 0,
        }
    } else {
        DelaunayError::LoopsCross {
            onto,
            a: b.min(l),
            b: b.max(l),
        }
    }
}
