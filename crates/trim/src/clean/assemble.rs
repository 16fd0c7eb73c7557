//! The patches put into the mesh (step 6 of the cleanup): each band's
//! faces replaced by its patch, the patches that would break the manifold
//! found, and the report's figures of the new faces.

use super::*;
use crate::mesh::topology::for_each_edge;

/// The input with every patch applied, and which outcome's patch made
/// each output face ([`Origins`]).
pub(super) fn assemble(mesh: &Mesh, outcomes: &[Outcome]) -> (Mesh, Origins) {
    let n = mesh.vertices.len() as u32;
    let mut removed = vec![false; mesh.faces.len()];
    let mut vertices = mesh.vertices.clone();
    let mut new_faces = Vec::new();
    let mut origins = Origins::default();
    for (g, outcome) in outcomes.iter().enumerate() {
        let Some(patch) = &outcome.patch else {
            continue;
        };
        for &f in &patch.removed {
            removed[f as usize] = true;
        }
        let base = vertices.len() as u32;
        vertices.extend_from_slice(&patch.vertices);
        for face in &patch.faces {
            new_faces.push(face.map(|id| if id < n { id } else { base + id - n }));
            origins.of_new_faces.push(g);
        }
    }
    let mut faces: Vec<[u32; 3]> = Vec::with_capacity(mesh.faces.len() + new_faces.len());
    faces.extend(
        mesh.faces
            .iter()
            .zip(&removed)
            .filter(|(_, &r)| !r)
            .map(|(f, _)| *f),
    );
    origins.input_faces = faces.len();
    faces.extend(new_faces);
    (Mesh { vertices, faces }, origins)
}

/// Which outcome each face of an assembled mesh comes from: the input's
/// kept faces come first, from none; then each patch's new faces.
#[derive(Default)]
pub(super) struct Origins {
    pub(super) input_faces: usize,
    pub(super) of_new_faces: Vec<usize>,
}

impl Origins {
    /// The outcome face `f` comes from; `None` for an input face.
    pub(super) fn of(&self, f: usize) -> Option<usize> {
        f.checked_sub(self.input_faces)
            .and_then(|k| self.of_new_faces.get(k).copied())
    }
}

/// The outcomes whose new faces use an edge more than twice or twice the
/// same way.
pub(super) fn patches_breaking_manifold(mesh: &Mesh, origins: &Origins) -> BTreeSet<usize> {
    let mut bad = BTreeSet::new();
    // The usual case, told without counting each edge's uses.
    if EdgeRows::new(&mesh.faces).no_edge_run_twice() {
        return bad;
    }
    for_each_edge(mesh, |faces, forward, backward| {
        if forward > 1 || backward > 1 {
            bad.extend(faces.iter().filter_map(|e| origins.of(e.2 as usize)));
        }
    });
    bad
}

/// Counts what the applied patches did: the loops left, and the new faces
/// and vertices (those of the output that are not the input's).
pub(super) fn summarise(input: &Mesh, replaced: &Replaced, report: &mut CleanReport) {
    let out = &replaced.mesh;
    report.loops_left.extend(replaced.left.iter().cloned());
    let new_faces = &out.faces[replaced.kept_input_faces..];
    report.faces_removed = input.faces.len() - replaced.kept_input_faces;
    report.faces_added = new_faces.len();
    let n = input.vertices.len() as u32;
    let new_vertices: BTreeSet<u32> = new_faces
        .iter()
        .flatten()
        .copied()
        .filter(|&v| v >= n)
        .collect();
    report.vertices_added = new_vertices.len();
    let min_angle = new_faces
        .iter()
        .map(|&face| smallest_angle(&out.vertices, face))
        .fold(f64::INFINITY, f64::min);
    report.min_angle_new = if min_angle.is_finite() {
        min_angle
    } else {
        0.0
    };
}

/// Smallest angle of a triangle, in degrees.
pub(super) fn smallest_angle(vertices: &[Point3], face: [u32; 3]) -> f64 {
    let p = face.map(|i| vertices[i as usize]);
    (0..3)
        .map(|k| {
            let (a, b) = (sub(p[(k + 1) % 3], p[k]), sub(p[(k + 2) % 3], p[k]));
            let c = dot(a, b) / (norm2(a) * norm2(b)).sqrt();
            c.clamp(-1.0, 1.0).acos().to_degrees()
        })
        .fold(f64::INFINITY, f64::min)
}
