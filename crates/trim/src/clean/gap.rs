//! The gap between the kept mesh and the smoothed loops, filled again
//! (step 5 of the cleanup): a constrained Delaunay triangulation of the
//! walls, the smoothed loops and the kept vertices, refined where it is
//! wide, lifted back onto the surface.

use super::*;

/// What filling one band's gap reads besides the faces removed.
pub(super) struct Gap {
    pub(super) projection: Projection,
    /// The smoothed loops, projected and untwisted.
    pub(super) rings: Vec<Ring>,
    /// Whether each vertex of the band's faces stays.
    pub(super) stay: HashMap<u32, bool>,
    /// The vertices of turned faces: they belong to a fold's second layer,
    /// so the new faces are made without them.
    pub(super) folded: BTreeSet<u32>,
    /// The directed edges of the group's old borders.
    pub(super) border_edges: BTreeSet<(u32, u32)>,
}

/// The edges (directed as the removed faces run them) that bound the removed region against what stays: shared with a kept
/// face, or on the border of a loop outside the group.
pub(super) fn walls(
    mesh: &Mesh,
    band: &[u32],
    removed: &[u32],
    group_border: &BTreeSet<(u32, u32)>,
    stay: &HashMap<u32, bool>,
) -> Vec<[u32; 2]> {
    let removed_set: BTreeSet<u32> = removed.iter().copied().collect();
    let mut uses: HashMap<(u32, u32), Vec<u32>> = HashMap::default();
    for &f in band {
        let face = mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            uses.entry((a.min(b), a.max(b))).or_default().push(f);
        }
    }
    let mut walls = Vec::new();
    for &f in removed {
        let face = mesh.faces[f as usize];
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let others: Vec<u32> = uses[&(a.min(b), a.max(b))]
                .iter()
                .copied()
                .filter(|&g| g != f)
                .collect();
            let wall = match others.first() {
                Some(g) => !removed_set.contains(g),
                // The border of a loop outside the group (too small, or
                // left): it bounds the new faces where it stays, and is
                // absorbed where the new border takes its vertices.
                None => !group_border.contains(&(a, b)) && stay[&a] && stay[&b],
            };
            if wall {
                walls.push([a, b]);
            }
        }
    }
    walls
}

/// The constrained Delaunay triangulation of the band's gap (step 5).
pub(super) fn triangulate(
    mesh: &Mesh,
    projection: &Projection,
    rings: &[Ring],
    walls: &[[u32; 2]],
    free: &BTreeSet<u32>,
    scale: f64,
) -> Result<Patch, Blocked> {
    let mut gap = GapTriangulation::new(mesh);
    let ring_handles = gap.insert_rings(rings).map_err(Blocked::Other)?;
    gap.insert_mesh_vertices(mesh, projection, walls, free)
        .map_err(Blocked::Other)?;
    gap.constrain_rings(&ring_handles)?;
    gap.constrain_walls(walls)?;
    refine_gap(&mut gap.cdt, mesh, &mut gap.patch, scale);
    Ok(gap.into_patch())
}

/// A gap's triangulation as it is built: its vertices are the smoothed
/// loops' (new vertices of the patch) and mesh vertices, each inserted
/// once under its id.
pub(super) struct GapTriangulation {
    pub(super) cdt: Cdt,
    pub(super) patch: Patch,
    pub(super) handle_of: HashMap<u32, FixedVertexHandle>,
    /// The mesh's vertex count: ids from here on are the patch's vertices.
    pub(super) n: u32,
}

impl GapTriangulation {
    pub(super) fn new(mesh: &Mesh) -> Self {
        GapTriangulation {
            cdt: Cdt::new(),
            patch: Patch::default(),
            handle_of: HashMap::default(),
            n: mesh.vertices.len() as u32,
        }
    }

    /// Inserts vertex `id` at `p`, or gives its handle if it is in. Two
    /// vertices at the same place cannot both be vertices of the new
    /// faces: the loop `ring` is left (or, for a mesh vertex, the group).
    pub(super) fn insert(
        &mut self,
        p: [f64; 2],
        id: u32,
        ring: Option<usize>,
    ) -> Result<FixedVertexHandle, Retry> {
        if let Some(&h) = self.handle_of.get(&id) {
            return Ok(h);
        }
        if let PositionInTriangulation::OnVertex(_) = self.cdt.locate(crate::planar::point(p)) {
            return Err(coincide(ring));
        }
        let h = self
            .cdt
            .insert(Node::new(p, id))
            .map_err(|_| coincide(ring))?;
        self.handle_of.insert(id, h);
        Ok(h)
    }

    /// Inserts every smoothed loop's vertices as new vertices of the
    /// patch; their handles, loop by loop.
    pub(super) fn insert_rings(
        &mut self,
        rings: &[Ring],
    ) -> Result<Vec<Vec<FixedVertexHandle>>, Retry> {
        let mut ring_handles = Vec::new();
        for (k, ring) in rings.iter().enumerate() {
            let mut hs = Vec::with_capacity(ring.len());
            for (j, &p) in ring.p2.iter().enumerate() {
                let id = self.n + self.patch.vertices.len() as u32;
                self.patch.vertices.push(ring.p3[j]);
                hs.push(self.insert(p, id, Some(k))?);
            }
            ring_handles.push(hs);
        }
        Ok(ring_handles)
    }

    /// Inserts the walls' vertices, then the free vertices, ascending.
    pub(super) fn insert_mesh_vertices(
        &mut self,
        mesh: &Mesh,
        projection: &Projection,
        walls: &[[u32; 2]],
        free: &BTreeSet<u32>,
    ) -> Result<(), Retry> {
        let wall_vertices: BTreeSet<u32> = walls.iter().flatten().copied().collect();
        for &v in wall_vertices.iter().chain(free) {
            self.insert(projection.vertex_to2(mesh, v), v, None)?;
        }
        Ok(())
    }

    /// Every segment of the smoothed loops as a constraint.
    pub(super) fn constrain_rings(
        &mut self,
        ring_handles: &[Vec<FixedVertexHandle>],
    ) -> Result<(), Blocked> {
        for (k, hs) in ring_handles.iter().enumerate() {
            for j in 0..hs.len() {
                self.constrain(hs[j], hs[(j + 1) % hs.len()], Some(k))?;
            }
        }
        Ok(())
    }

    /// Every wall as a constraint.
    pub(super) fn constrain_walls(&mut self, walls: &[[u32; 2]]) -> Result<(), Blocked> {
        for w in walls {
            self.constrain(self.handle_of[&w[0]], self.handle_of[&w[1]], None)?;
        }
        Ok(())
    }

    /// Adds the constraint from `a` to `b` unless a vertex or constraint is
    /// in its way: then a smoothed loop's segment (of loop `ring`) leaves
    /// that loop, and a wall reports the vertices involved, so that the
    /// faces round them can go.
    pub(super) fn constrain(
        &mut self,
        a: FixedVertexHandle,
        b: FixedVertexHandle,
        ring: Option<usize>,
    ) -> Result<(), Blocked> {
        if let Some(other) = obstacle(&self.cdt, a, b) {
            return Err(match ring {
                Some(k) => Blocked::Other(leave(LeftReason::CrossesKeptMesh, vec![k])),
                None => Blocked::Walls(vec![
                    self.cdt.vertex(a).data().id,
                    self.cdt.vertex(b).data().id,
                    other,
                ]),
            });
        }
        self.cdt.add_constraint(a, b);
        Ok(())
    }

    /// The patch with its faces: those between the constraints (the
    /// parity flood fill of [`inside_faces`]), each turned to run
    /// counter-clockwise in the projection, as the band's unturned faces do.
    pub(super) fn into_patch(mut self) -> Patch {
        for f in inside_faces(&self.cdt) {
            let vs = self.cdt.face(f).vertices();
            let mut ids = vs.map(|v| v.data().id);
            let p = vs.map(|v| {
                let q = v.position();
                [q.x, q.y]
            });
            if orientation(p[0], p[1], p[2]) < 0.0 {
                ids.swap(1, 2);
            }
            self.patch.faces.push(ids);
        }
        self.patch
    }
}

/// Two vertices coincide in the projection: the loop `ring` is left, or,
/// without one, the whole group.
pub(super) fn coincide(ring: Option<usize>) -> Retry {
    leave(LeftReason::VerticesCoincide, ring.into_iter().collect())
}

/// Where the gap is wide and holds no mesh vertex (a deep notch the
/// smoothed border bridges), its triangles would join border vertices far
/// apart in thin slivers: Delaunay refinement (spade, Ruppert/Chew) adds
/// points inside the new faces until their angles reach [`REFINE_ANGLE`].
/// The constraints are never split (a point on a wall would open a crack
/// against the kept face there). Each added point is lifted onto the
/// plane of the unrefined triangle it falls in, whose corners are points
/// of the surface.
pub(super) fn refine_gap(cdt: &mut Cdt, mesh: &Mesh, patch: &mut Patch, scale: f64) {
    let n = mesh.vertices.len() as u32;
    let before = cdt.clone();
    cdt.refine(refinement(before.num_vertices(), scale));
    let position = |id: u32| {
        if id < n {
            mesh.vertices[id as usize]
        } else {
            patch.vertices[(id - n) as usize]
        }
    };
    let added: Vec<(FixedVertexHandle, Point3)> = cdt
        .fixed_vertices()
        .filter(|&h| cdt.vertex(h).data().id == STEINER)
        .map(|h| (h, lift(&before, cdt.vertex(h).position(), &position)))
        .collect();
    for (h, p) in added {
        cdt.vertex_data_mut(h).id = n + patch.vertices.len() as u32;
        patch.vertices.push(p);
    }
}

/// Delaunay refinement of the faces between constraints to
/// [`REFINE_ANGLE`], the constraints never split, faces below
/// [`REFINE_MIN_AREA`]·`scale`² left alone, and at most about four points
/// added per vertex of the `vertices` triangulated.
pub(super) fn refinement(vertices: usize, scale: f64) -> RefinementParameters<f64> {
    RefinementParameters::<f64>::new()
        .exclude_outer_faces(true)
        .keep_constraint_edges()
        .with_angle_limit(AngleLimit::from_deg(REFINE_ANGLE))
        .with_min_required_area(REFINE_MIN_AREA * scale * scale)
        .with_max_additional_vertices(4 * vertices + 16)
}

/// The 3D point of the surface at `p` of the unrefined triangulation: the
/// barycentric blend of its triangle's (or edge's) corners.
pub(super) fn lift(cdt: &Cdt, p: SpadePoint<f64>, position: &impl Fn(u32) -> Point3) -> Point3 {
    let blend = |ids: &[u32], weights: &[f64]| {
        let mut q = [0.0; 3];
        for (&id, &w) in ids.iter().zip(weights) {
            let x = position(id);
            for c in 0..3 {
                q[c] += w * x[c];
            }
        }
        q
    };
    let along = |e: spade::handles::FixedDirectedEdgeHandle| {
        let edge = cdt.directed_edge(e);
        let (a, b) = (edge.from(), edge.to());
        let (pa, pb) = (a.position(), b.position());
        let d = [pb.x - pa.x, pb.y - pa.y];
        let len2 = d[0] * d[0] + d[1] * d[1];
        let t = if len2 > 0.0 {
            (((p.x - pa.x) * d[0] + (p.y - pa.y) * d[1]) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        blend(&[a.data().id, b.data().id], &[1.0 - t, t])
    };
    match cdt.locate(p) {
        PositionInTriangulation::OnVertex(v) => position(cdt.vertex(v).data().id),
        PositionInTriangulation::OnEdge(e) | PositionInTriangulation::OutsideOfConvexHull(e) => {
            along(e)
        }
        PositionInTriangulation::OnFace(f) => {
            let vs = cdt.face(f).vertices();
            let [a, b, c] = vs.map(|v| {
                let q = v.position();
                [q.x, q.y]
            });
            let area = orient(a, b, c);
            let q = [p.x, p.y];
            let weights = [
                orient(q, b, c) / area,
                orient(a, q, c) / area,
                orient(a, b, q) / area,
            ];
            blend(&vs.map(|v| v.data().id), &weights)
        }
        PositionInTriangulation::NoTriangulation => position(0),
    }
}
