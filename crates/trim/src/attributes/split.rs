//! The output's vertices split again where the input's were split along a
//! seam, so that each side keeps its own attributes.
//!
//! The cleanup stitches a seam's copies into one vertex (`mesh/seams.rs`),
//! and a vertex holds one value of each attribute: a texture coordinate
//! at a chart's border has one value per side. So each output face corner
//! at or along a seam asks which side it is on: its face's own input face
//! says, the input face with the same corners in the same turn, else,
//! among the input faces round the seam vertices its corners' sources
//! read, the one nearest the face's centroid (one face for all three
//! corners, so that they read one side).
//! A corner whose side reads other input vertices than its vertex's source
//! moves to a copy of the vertex, one copy per side, as the input stored
//! it. Everywhere else (no seam near) nothing changes.

use rayon::prelude::*;

use super::{
    bits, centroid, closest_on_face, corners_from, face_source, nearest_corner, Corners,
    VertexSource,
};
use crate::geom::Point3;
use crate::hash::{HashMap, HashSet};
use crate::mesh::Mesh;

/// Where the vertices of a mesh take their attributes from, its vertices
/// split where the input's are along a seam ([`split_sources`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SplitSources {
    /// One source per vertex: the output's, then its copies'.
    pub sources: Vec<VertexSource>,
    /// The output vertex each copy repeats; copy `i` is vertex
    /// `to.vertices.len() + i`.
    pub copies: Vec<u32>,
    /// The output's faces, with the corners on another side of a seam
    /// than their vertex's source renamed to copies; `None` when no vertex
    /// is split (`copies` is empty).
    pub faces: Option<Vec<[u32; 3]>>,
}

impl SplitSources {
    /// `to` with its vertices split (the copies at the end), or `None`
    /// when none is.
    pub fn split_mesh(&self, to: &Mesh) -> Option<Mesh> {
        let faces = self.faces.clone()?;
        let mut vertices = to.vertices.clone();
        vertices.extend(self.copies.iter().map(|&o| to.vertices[o as usize]));
        Some(Mesh { vertices, faces })
    }
}

/// [`super::vertex_sources`] of `to` from `from`, with `to`'s vertices
/// split where `from`'s are along a seam (see the module doc). `None`
/// when `from` has no vertex to take attributes from.
pub fn split_sources(from: &Mesh, to: &Mesh) -> Option<SplitSources> {
    let (mut sources, seams) = super::sources_and_seams(from, to)?;
    let split = seams.and_then(|seam_faces| split_at_seams(&seam_faces, to, &mut sources));
    let (faces, copies) = match split {
        Some((faces, copies)) => (Some(faces), copies),
        None => (None, Vec::new()),
    };
    Some(SplitSources {
        sources,
        copies,
        faces,
    })
}

/// A weight below this (of a corner's 1) reads nothing from the corner:
/// a point cut on an edge is off it by rounding.
const SIGNIFICANT: f64 = 1e-9;

/// The seam vertices a source reads, ascending, padded with `u32::MAX`:
/// two corners of one output vertex are on two sides when they read one
/// position through two of its copies.
type Side = [u32; 3];

const NO_SEAM: Side = [u32::MAX; 3];

/// The input's faces round its seam positions (positions several input
/// vertices share), which tell a seam's sides apart.
pub(super) struct SeamFaces<'a> {
    pub(super) from: &'a Mesh,
    seams: HashSet<[u64; 3]>,
    on_seam: Vec<bool>,
    /// The input vertex at each corner (on a seam) of each input face,
    /// keyed by the face's corner positions from that corner on.
    corner: HashMap<Corners, u32>,
    /// The input faces round each seam position, in face order.
    around: HashMap<[u64; 3], Vec<u32>>,
}

impl<'a> SeamFaces<'a> {
    pub(super) fn new(from: &'a Mesh, seams: HashSet<[u64; 3]>) -> Self {
        let on_seam: Vec<bool> = from
            .vertices
            .par_iter()
            .map(|p| seams.contains(&bits(p)))
            .collect();
        let mut corner = HashMap::default();
        let mut around: HashMap<[u64; 3], Vec<u32>> = HashMap::default();
        for (f, &face) in from.faces.iter().enumerate() {
            for k in 0..3 {
                if on_seam[face[k] as usize] {
                    let key = corners_from(&from.vertices, face, k);
                    corner.entry(key).or_insert(face[k]);
                    around.entry(key[0]).or_default().push(f as u32);
                }
            }
        }
        SeamFaces {
            from,
            seams,
            on_seam,
            corner,
            around,
        }
    }

    /// Whether `p` is at a seam position.
    pub(super) fn is_seam(&self, p: &Point3) -> bool {
        self.seams.contains(&bits(p))
    }

    /// The input vertex at the first corner of the input face whose corner
    /// positions, in turn from that corner, are `corners`.
    pub(super) fn twin(&self, corners: &Corners) -> Option<u32> {
        self.corner.get(corners).copied()
    }

    /// The input faces round a seam position.
    pub(super) fn around(&self, position: &[u64; 3]) -> &[u32] {
        self.around.get(position).map_or(&[][..], Vec::as_slice)
    }

    fn side(&self, source: &VertexSource) -> Side {
        let mut side = NO_SEAM;
        let mut read = |v: u32, slot: &mut usize| {
            if self.on_seam[v as usize] {
                side[*slot] = v;
                *slot += 1;
            }
        };
        let mut slot = 0;
        match *source {
            VertexSource::Vertex(v) => read(v, &mut slot),
            VertexSource::Face { face, weights } => {
                for (k, &v) in self.from.faces[face as usize].iter().enumerate() {
                    if weights[k] > SIGNIFICANT {
                        read(v, &mut slot);
                    }
                }
            }
        }
        side.sort_unstable();
        side
    }

    /// The input faces that may hold a corner whose own source is
    /// `source`: those round the seam vertices it reads (and, for a point
    /// of a face, that face).
    fn candidates(&self, source: VertexSource, out: &mut Vec<u32>) {
        match source {
            VertexSource::Vertex(v) => out.extend(self.around_vertex(v)),
            VertexSource::Face { face, .. } => {
                for &v in &self.from.faces[face as usize] {
                    if self.on_seam[v as usize] {
                        out.extend(self.around_vertex(v));
                    }
                }
                out.push(face);
            }
        }
    }

    /// A point inside the input face on output face `face`'s side of the
    /// seam: the centroid of the candidate face nearest its centroid (the
    /// lower index on a tie). One point for the whole face, so that its
    /// corners read one side even where a new face lies along the seam.
    fn side_point(&self, to: &Mesh, face: [u32; 3], sources: &[VertexSource]) -> Point3 {
        let centre = centroid(&to.vertices, face);
        let mut candidates = Vec::new();
        for v in face {
            self.candidates(sources[v as usize], &mut candidates);
        }
        candidates.sort_unstable();
        candidates.dedup();
        candidates
            .into_iter()
            .map(|c| (closest_on_face(self.from, c, centre).0, c))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .map_or(centre, |(_, c)| {
                centroid(&self.from.vertices, self.from.faces[c as usize])
            })
    }

    /// The source of corner `k` of output face `face`, whose vertex's own
    /// source `own` reads a seam vertex: the input face with the face's
    /// corners, else the candidate nearest the face's `side_point`.
    fn corner_source(
        &self,
        to: &Mesh,
        face: [u32; 3],
        k: usize,
        own: VertexSource,
        side_point: Point3,
    ) -> VertexSource {
        let p = to.vertices[face[k] as usize];
        if let VertexSource::Vertex(_) = own {
            let corners = corners_from(&to.vertices, face, k);
            if let Some(twin) = self.twin(&corners) {
                return VertexSource::Vertex(twin);
            }
            return nearest_corner(self.from, self.around(&corners[0]), corners[0], side_point)
                .map_or(own, VertexSource::Vertex);
        }
        let mut candidates = Vec::new();
        self.candidates(own, &mut candidates);
        // The face's side, even where the corner is nearer the other (a
        // new face laid across the seam): one face reads one texture chart.
        candidates
            .into_iter()
            .map(|c| (closest_on_face(self.from, c, side_point).0, c))
            .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)))
            .map_or(own, |(_, c)| face_source(self.from, c, p))
    }

    /// Whether a corner reading the seam vertices `side` is across a seam
    /// from the corners that read `read`: some position is read there
    /// through one copy and here through another. (Corners that read no
    /// position in common are not told apart: nothing says they differ.)
    fn across(&self, read: &[u32], side: &Side) -> bool {
        let position = |v: u32| bits(&self.from.vertices[v as usize]);
        side.iter()
            .filter(|&&v| v != u32::MAX)
            .any(|&v| read.iter().any(|&r| r != v && position(r) == position(v)))
    }

    fn around_vertex(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.around(&bits(&self.from.vertices[v as usize]))
            .iter()
            .copied()
    }
}

/// The seam vertices a side reads.
fn read(side: &Side) -> Vec<u32> {
    side.iter().copied().filter(|&v| v != u32::MAX).collect()
}

/// Splits `to`'s vertices along `from`'s seams: the faces with corners
/// renamed and the output vertex each copy repeats, the copies' sources
/// pushed onto `sources`; `None` when no vertex is split.
fn split_at_seams(
    seam_faces: &SeamFaces,
    to: &Mesh,
    sources: &mut Vec<VertexSource>,
) -> Option<(Vec<[u32; 3]>, Vec<u32>)> {
    if seam_faces.from.faces.is_empty() {
        return None;
    }
    let own_side: Vec<Side> = sources.par_iter().map(|s| seam_faces.side(s)).collect();
    if own_side.iter().all(|&s| s == NO_SEAM) {
        return None;
    }
    let mut faces = to.faces.clone();
    let mut copies = Copies::new(to.vertices.len());
    for (out, face) in faces.iter_mut().enumerate() {
        let original = to.faces[out];
        if original.iter().all(|&o| own_side[o as usize] == NO_SEAM) {
            continue;
        }
        let side_point = seam_faces.side_point(to, original, sources);
        for (k, corner) in face.iter_mut().enumerate() {
            let o = original[k];
            if own_side[o as usize] == NO_SEAM {
                continue;
            }
            let own = sources[o as usize];
            let source = seam_faces.corner_source(to, original, k, own, side_point);
            *corner = copies.holder(seam_faces, o, &own_side[o as usize], source);
        }
    }
    sources.extend(copies.sources);
    (!copies.of.is_empty()).then_some((faces, copies.of))
}

/// The copies made of the output's vertices, one per further side.
struct Copies {
    /// The number of output vertices (the first copy's index).
    first: usize,
    /// The output vertex each copy repeats.
    of: Vec<u32>,
    /// Each copy's source.
    sources: Vec<VertexSource>,
    /// The sides found at each vertex near a seam: the seam vertices read
    /// there, and the vertex (the output's own, or a copy) that holds them.
    sides: HashMap<u32, Vec<(Vec<u32>, u32)>>,
}

impl Copies {
    fn new(first: usize) -> Self {
        Copies {
            first,
            of: Vec::new(),
            sources: Vec::new(),
            sides: HashMap::default(),
        }
    }

    /// The vertex that holds output vertex `o` (whose own source reads
    /// `own_side`) for a corner whose source is `source`: the first side
    /// found there that the corner is not across a seam from, else a new
    /// copy.
    fn holder(
        &mut self,
        seam_faces: &SeamFaces,
        o: u32,
        own_side: &Side,
        source: VertexSource,
    ) -> u32 {
        let side = seam_faces.side(&source);
        let known = self
            .sides
            .entry(o)
            .or_insert_with(|| vec![(read(own_side), o)]);
        if let Some((read, holder)) = known
            .iter_mut()
            .find(|(read, _)| !seam_faces.across(read, &side))
        {
            read.extend(side.iter().filter(|&&v| v != u32::MAX));
            return *holder;
        }
        let copy = (self.first + self.of.len()) as u32;
        self.of.push(o);
        self.sources.push(source);
        known.push((read(&side), copy));
        copy
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(p: Point3) -> [u64; 3] {
        bits(&p)
    }

    /// A strip of squares along x at y in 0..2, its faces right of x = 2
    /// given their own copies of the vertices on x = 2.
    fn split_strip() -> Mesh {
        let at = |x: u32, y: u32| [x as f64, y as f64, 0.0];
        let mut vertices = Vec::new();
        let mut index = HashMap::default();
        let mut vertex = |x: u32, y: u32, right: bool| -> u32 {
            let side = right && x == 2;
            *index.entry((x, y, side)).or_insert_with(|| {
                vertices.push(at(x, y));
                (vertices.len() - 1) as u32
            })
        };
        let mut faces = Vec::new();
        for x in 0..4 {
            for y in 0..2 {
                let right = x >= 2;
                let [a, b, c, d] = [
                    vertex(x, y, right),
                    vertex(x + 1, y, right),
                    vertex(x + 1, y + 1, right),
                    vertex(x, y + 1, right),
                ];
                faces.push([a, b, c]);
                faces.push([a, c, d]);
            }
        }
        Mesh { vertices, faces }
    }

    #[test]
    fn a_stitched_seam_is_split_again_as_the_input_was() {
        let from = split_strip();
        let stitched = crate::stitch_seams(&from);
        assert_eq!(stitched.edges, 2);
        let split = split_sources(&from, &stitched.mesh).unwrap();
        let out = split.split_mesh(&stitched.mesh).unwrap();
        assert_eq!(split.copies.len(), 3);
        // Every corner reads the vertex the input face in its place has.
        for (o, face) in out.faces.iter().enumerate() {
            let read = face.map(|v| match split.sources[v as usize] {
                VertexSource::Vertex(v) => v,
                other => panic!("a kept corner reads {other:?}"),
            });
            assert_eq!(read, from.faces[o], "face {o}");
        }
    }

    #[test]
    fn a_new_vertex_on_a_seam_edge_gets_a_copy_for_each_side() {
        let from = split_strip();
        let mut to = crate::stitch_seams(&from).mesh.into_owned();
        // The seam's edge (2, 0)–(2, 1) cut at its middle, and each face
        // on it split in two there.
        let (low, high) = (key([2.0, 0.0, 0.0]), key([2.0, 1.0, 0.0]));
        let at = |p: [u64; 3]| to.vertices.iter().position(|q| key(*q) == p).unwrap() as u32;
        let (a, b) = (at(low), at(high));
        let m = to.vertices.len() as u32;
        to.vertices.push([2.0, 0.5, 0.0]);
        let mut faces = Vec::new();
        for face in &to.faces {
            match (0..3).find(|&k| {
                let (u, v) = (face[k], face[(k + 1) % 3]);
                (u, v) == (a, b) || (u, v) == (b, a)
            }) {
                Some(k) => {
                    let (u, v, w) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
                    faces.push([u, m, w]);
                    faces.push([m, v, w]);
                }
                None => faces.push(*face),
            }
        }
        to.faces = faces;
        let split = split_sources(&from, &to).unwrap();
        let out = split.split_mesh(&to).unwrap();
        let at_middle: HashSet<u32> = out
            .faces
            .iter()
            .flatten()
            .copied()
            .filter(|&v| out.vertices[v as usize] == [2.0, 0.5, 0.0])
            .collect();
        assert_eq!(at_middle.len(), 2, "one vertex per side");
        for v in at_middle {
            let VertexSource::Face { face, weights } = split.sources[v as usize] else {
                panic!("the middle is no input vertex");
            };
            let corners = from.faces[face as usize];
            // Its face's corners are those of the faces using this copy.
            let users: Vec<&[u32; 3]> = out.faces.iter().filter(|f| f.contains(&v)).collect();
            let right = |c: &[u32; 3]| c.iter().any(|&x| from.vertices[x as usize][0] > 2.0);
            assert!(users.iter().all(|f| {
                let user_right = f.iter().any(|&x| out.vertices[x as usize][0] > 2.0);
                user_right == right(&corners)
            }));
            assert!(
                weights.iter().filter(|&&w| w > 0.4).count() == 2,
                "{weights:?}"
            );
        }
    }

    /// A jittered sheet cut into charts by two random wavy lines, each
    /// chart with its own copies of the vertices it shares with another
    /// (three or four copies where the lines cross); and each face's
    /// chart.
    fn charted_sheet(n: u32, seed: u64) -> (Mesh, Vec<usize>) {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let vertices: Vec<Point3> = (0..n * n)
            .map(|i| {
                let (x, y) = ((i % n) as f64, (i / n) as f64);
                let jitter = |rng: &mut rand::rngs::StdRng| rng.random_range(-0.3..0.3);
                [x + jitter(&mut rng), y + jitter(&mut rng), (0.3 * x).sin()]
            })
            .collect();
        let (a, b) = (rng.random_range(0.3..0.7), rng.random_range(0.3..0.7));
        let (wave, phase) = (rng.random_range(0.5..2.0), rng.random_range(0.0..6.0));
        let size = n as f64;
        let chart = |p: Point3| {
            let right = p[0] > a * size + wave * (p[1] + phase).sin();
            let top = p[1] > b * size + wave * (p[0] * 0.7).cos();
            usize::from(right) + 2 * usize::from(top)
        };
        let mut faces = Vec::new();
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let v = j * n + i;
                faces.push([v, v + 1, v + n + 1]);
                faces.push([v, v + n + 1, v + n]);
            }
        }
        let mut mesh = Mesh { vertices, faces };
        let charts: Vec<usize> = mesh
            .faces
            .iter()
            .map(|&face| chart(centroid(&mesh.vertices, face)))
            .collect();
        let mut copy: HashMap<(u32, usize), u32> = HashMap::default();
        for (f, &c) in charts.iter().enumerate() {
            for k in 0..3 {
                let v = mesh.faces[f][k];
                let first = *copy.entry((v, usize::MAX)).or_insert(c as u32);
                if first as usize != c {
                    let next = mesh.vertices.len() as u32;
                    let id = *copy.entry((v, c)).or_insert(next);
                    if id == next {
                        mesh.vertices.push(mesh.vertices[v as usize]);
                    }
                    mesh.faces[f][k] = id;
                }
            }
        }
        (mesh, charts)
    }

    /// Stitched and split again, random charted sheets come back as they
    /// were stored: every corner reads its input face's vertex, and there
    /// is one vertex per copy.
    #[test]
    fn random_charts_stitched_are_split_back_as_stored() {
        for seed in 0..8 {
            let (from, _) = charted_sheet(24, seed);
            let stitched = crate::stitch_seams(&from);
            assert!(stitched.edges > 20, "seed {seed}: {}", stitched.edges);
            let split = split_sources(&from, &stitched.mesh).unwrap();
            let out = split.split_mesh(&stitched.mesh).unwrap();
            assert_eq!(out.vertices.len(), from.vertices.len(), "seed {seed}");
            for (o, face) in out.faces.iter().enumerate() {
                let read = face.map(|v| match split.sources[v as usize] {
                    VertexSource::Vertex(v) => v,
                    other => panic!("seed {seed}: a kept corner reads {other:?}"),
                });
                assert_eq!(read, from.faces[o], "seed {seed}, face {o}");
            }
        }
    }

    /// The faces of `mesh` at a seam position each cut in four at their
    /// edges' middles (one middle per edge of the stitched surface, so
    /// the middles of the seam's edges are on faces of both sides), with
    /// the face of `mesh` each face of the result was cut from.
    fn cut_at_seams(mesh: &Mesh, seam: &HashSet<[u64; 3]>) -> (Mesh, Vec<usize>) {
        let mut out = Mesh {
            vertices: mesh.vertices.clone(),
            faces: Vec::new(),
        };
        let mut parent = Vec::new();
        let mut middles: HashMap<(u32, u32), u32> = HashMap::default();
        for (f, &face) in mesh.faces.iter().enumerate() {
            if !face
                .iter()
                .any(|&v| seam.contains(&bits(&mesh.vertices[v as usize])))
            {
                out.faces.push(face);
                parent.push(f);
                continue;
            }
            let m: [u32; 3] = std::array::from_fn(|k| {
                let (a, b) = (face[k], face[(k + 1) % 3]);
                *middles.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    let [p, q] = [a, b].map(|v| mesh.vertices[v as usize]);
                    out.vertices
                        .push(std::array::from_fn(|c| 0.5 * (p[c] + q[c])));
                    (out.vertices.len() - 1) as u32
                })
            });
            let [a, b, c] = face;
            for piece in [[a, m[0], m[2]], [m[0], b, m[1]], [m[2], m[1], c], m] {
                out.faces.push(piece);
                parent.push(f);
            }
        }
        (out, parent)
    }

    /// Random charted sheets stitched and their faces at the seams cut:
    /// every corner of every piece reads the chart of the input face it
    /// was cut from (a chart number per input vertex, carried as any
    /// label is).
    #[test]
    fn pieces_cut_at_random_seams_read_their_own_chart() {
        for seed in 0..8 {
            let (from, charts) = charted_sheet(20, seed);
            let mut chart_of_vertex = vec![0; from.vertices.len()];
            for (face, &chart) in from.faces.iter().zip(&charts) {
                for &v in face {
                    chart_of_vertex[v as usize] = chart;
                }
            }
            let stitched = crate::stitch_seams(&from);
            let seam = super::super::vertex_at_position(&from.vertices).1;
            let (to, parent) = cut_at_seams(&stitched.mesh, &seam);
            let split = split_sources(&from, &to).unwrap();
            let out = split.split_mesh(&to).unwrap();
            assert!(split.copies.len() > 20, "seed {seed}");
            let read = crate::carry_nearest_corner(&from, &split.sources, &chart_of_vertex);
            for (o, face) in out.faces.iter().enumerate() {
                let own = charts[parent[o]];
                assert_eq!(
                    face.map(|v| read[v as usize]),
                    [own; 3],
                    "seed {seed}, face {o}"
                );
            }
        }
    }

    #[test]
    fn a_mesh_without_seams_is_not_split() {
        let mut from = split_strip();
        from = crate::stitch_seams(&from).mesh.into_owned();
        let split = split_sources(&from, &from).unwrap();
        assert_eq!((split.copies.len(), split.faces), (0, None));
    }
}
