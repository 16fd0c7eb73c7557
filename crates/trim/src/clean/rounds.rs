//! Loops left, tried again on the mesh with the other loops' patches in
//! (step 5 of the cleanup, repeated).
//!
//! Where a loop is left, what stood in the way is often another border's
//! patch, which a round later is part of the mesh:
//!
//! - Two patches applied to one mesh must keep apart: a strip keeps clear
//!   of every face another patch removes or touches. Where a hole lies a
//!   few faces from the outer border, the outer border's strip goes round
//!   it, and the hole's own patch would touch the strip's faces
//!   (`MeetsAnotherBorder`).
//! - A strip takes the place of the planar patches it reaches, and the
//!   holes whose planar patch it took out need strips of their own, which
//!   fail more often on a small hole (`DoublesBack`, `TangledWall`) than
//!   the planar way.
//!
//! Once those patches are in, the hole is a loop of an ordinary mesh
//! again, its smoothed loop is the same (its vertices are the input's),
//! and both ways are tried for it as in the first round; the new borders
//! are borders like any other, which it keeps clear of or absorbs. New
//! vertices take the β of the nearest input vertex. A round takes the
//! loops the round before left, until a round replaces none of them, or
//! after [`MAX_ROUNDS`].

use super::*;
use crate::spatial::PointTree;

/// Rounds of replacement, the first included.
const MAX_ROUNDS: usize = 3;

/// The mesh with every patch of every round applied, and what became of
/// the input's loops.
pub(super) struct Replaced {
    pub(super) mesh: Mesh,
    /// The number of input faces the mesh keeps: they come first, in the
    /// input's order; the faces from here on are new.
    pub(super) kept_input_faces: usize,
    /// Whether each input loop was replaced.
    pub(super) replaced: Vec<bool>,
    /// The input loops left, with why.
    pub(super) left: Vec<LeftLoops>,
}

/// Steps 3 to 5 for every smoothed loop, in rounds (see the module doc).
pub(super) fn replace_in_rounds(
    mesh: &Mesh,
    beta: &dyn PointResolution,
    borders: &[Vec<u32>],
    rings: &[Option<Ring>],
    shaping: Shaping,
) -> Replaced {
    let beta_median = beta.median();
    let (outcomes, out) = replace_bands(mesh, beta, borders, rings, shaping, beta_median);
    let mut done = Replaced {
        kept_input_faces: kept_below(mesh.faces.len(), &outcomes),
        replaced: replaced_loops(borders.len(), &outcomes),
        left: outcomes.into_iter().flat_map(|o| o.left).collect(),
        mesh: out,
    };
    for _ in 1..MAX_ROUNDS {
        if !done.round(mesh, beta, borders, rings, shaping, beta_median) {
            break;
        }
    }
    done
}

impl Replaced {
    /// One more round for the loops left; whether it replaced any.
    fn round(
        &mut self,
        input: &Mesh,
        beta: &dyn PointResolution,
        borders: &[Vec<u32>],
        rings: &[Option<Ring>],
        shaping: Shaping,
        beta_median: f64,
    ) -> bool {
        let again: BTreeSet<usize> = self
            .left
            .iter()
            .flat_map(|x| x.loops.iter().copied())
            .filter(|&l| rings[l].is_some())
            .collect();
        if again.is_empty() {
            return false;
        }
        let mesh = &self.mesh;
        let here = mesh.boundary_loops();
        let input_loop = as_input_loops(borders, &here);
        let here_rings: Vec<Option<Ring>> = input_loop
            .iter()
            .map(|l| {
                l.filter(|l| again.contains(l))
                    .and_then(|l| rings[l].clone())
            })
            .collect();
        let here_beta = beta_of_new_vertices(input, beta, mesh);
        let (outcomes, out) =
            replace_bands(mesh, &here_beta, &here, &here_rings, shaping, beta_median);
        let now_replaced: Vec<usize> = replaced_loops(here.len(), &outcomes)
            .iter()
            .enumerate()
            .filter(|&(_, &r)| r)
            .filter_map(|(k, _)| input_loop[k])
            .collect();
        if now_replaced.is_empty() {
            return false;
        }
        let left_here: Vec<LeftLoops> = outcomes
            .iter()
            .flat_map(|o| o.left.iter())
            .map(|x| LeftLoops {
                loops: x.loops.iter().filter_map(|&k| input_loop[k]).collect(),
                vertices: Vec::new(),
                reason: x.reason,
            })
            .filter(|x| !x.loops.is_empty())
            .collect();
        self.kept_input_faces = kept_below(self.kept_input_faces, &outcomes);
        self.mesh = out;
        // The loops tried this round take this round's reasons; loops a
        // patch absorbed are replaced, whichever round left them.
        for &l in &now_replaced {
            self.replaced[l] = true;
        }
        // A loop whose border a patch changed was not tried: it keeps its
        // reason.
        let tried = input_loop.iter().flatten().filter(|l| again.contains(l));
        let retried: BTreeSet<usize> = tried.copied().chain(now_replaced).collect();
        for entry in &mut self.left {
            entry.loops.retain(|l| !retried.contains(l));
        }
        self.left.retain(|x| !x.loops.is_empty());
        self.left.extend(left_here);
        true
    }
}

/// For each border of the mesh, the input loop it is (the same vertices),
/// if any: the new borders of replaced loops are none.
fn as_input_loops(input: &[Vec<u32>], here: &[Vec<u32>]) -> Vec<Option<usize>> {
    let owner: HashMap<u32, usize> = input
        .iter()
        .enumerate()
        .flat_map(|(l, b)| b.iter().map(move |&v| (v, l)))
        .collect();
    here.iter()
        .map(|border| {
            let l = *owner.get(border.first()?)?;
            let same =
                input[l].len() == border.len() && border.iter().all(|v| owner.get(v) == Some(&l));
            same.then_some(l)
        })
        .collect()
}

/// β of every vertex of a mesh whose first vertices are the input's:
/// theirs, and for the new ones that of the nearest input vertex.
struct WithNewVertices<'a> {
    input: &'a dyn PointResolution,
    new: Vec<f64>,
}

impl PointResolution for WithNewVertices<'_> {
    fn len(&self) -> usize {
        self.input.len() + self.new.len()
    }
    fn beta(&self, i: usize) -> f64 {
        match i.checked_sub(self.input.len()) {
            Some(new) => self.new[new],
            None => self.input.beta(i),
        }
    }
    fn median(&self) -> f64 {
        self.input.median()
    }
}

fn beta_of_new_vertices<'a>(
    input: &Mesh,
    beta: &'a dyn PointResolution,
    mesh: &Mesh,
) -> WithNewVertices<'a> {
    // The mesh keeps every input vertex first ([`assemble`]).
    let new_vertices = mesh.vertices.get(input.vertices.len()..).unwrap_or(&[]);
    let new = match PointTree::new(&input.vertices) {
        Some(tree) => new_vertices
            .iter()
            .map(|p| beta.beta(tree.nearest(p).0))
            .collect(),
        None => vec![beta.median(); new_vertices.len()],
    };
    WithNewVertices { input: beta, new }
}

/// How many of a mesh's first `count` faces no patch removes.
fn kept_below(count: usize, outcomes: &[Outcome]) -> usize {
    let mut removed = vec![false; count];
    for patch in outcomes.iter().filter_map(|o| o.patch.as_ref()) {
        for &f in patch.removed.iter().filter(|&&f| (f as usize) < count) {
            removed[f as usize] = true;
        }
    }
    removed.iter().filter(|&&r| !r).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_border_is_an_input_loop_only_with_the_same_vertices() {
        let input = vec![vec![0, 1, 2, 3], vec![10, 11, 12]];
        let here = vec![
            vec![11, 12, 10],    // the second loop, from another vertex
            vec![0, 1, 2, 7, 3], // the first, with a new vertex in it
            vec![20, 21, 22],    // a new border
            vec![0, 1, 2],       // part of the first
        ];
        assert_eq!(
            as_input_loops(&input, &here),
            vec![Some(1), None, None, None]
        );
    }

    #[test]
    fn kept_faces_are_counted_below_the_limit_once() {
        let patch = |removed: Vec<u32>| Outcome {
            band: Vec::new(),
            patch: Some(Patch {
                removed,
                ..Default::default()
            }),
            left: Vec::new(),
            strip: false,
        };
        let outcomes = vec![patch(vec![1, 3, 8]), patch(vec![3, 4])];
        // Faces 0..6: 1, 3 and 4 removed (3 by both).
        assert_eq!(kept_below(6, &outcomes), 3);
        assert_eq!(kept_below(10, &outcomes), 6);
    }
}
