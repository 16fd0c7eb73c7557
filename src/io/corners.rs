//! Vertices split by what their face corners read: an OBJ's `vt` and
//! `vn`, a PLY face's `texcoord` list. A vertex read with two texture
//! coordinates (at a chart's border) or two normals (at a hard edge)
//! becomes one vertex per pair, as glTF and PLY store them per vertex.

use anyhow::{anyhow, Result};

use super::hash::HashMap;

/// A corner without a texture coordinate or normal.
pub(crate) const NONE: u32 = u32::MAX;

/// Corner references renamed to the first of the values equal to theirs
/// (bit for bit), so that only different values split a vertex: writers
/// often repeat a value once per face corner.
pub(crate) fn by_value<const N: usize>(
    mut refs: Vec<[u32; 3]>,
    values: &[[f64; N]],
) -> Vec<[u32; 3]> {
    let mut first: HashMap<[u64; N], u32> = HashMap::default();
    let canonical: Vec<u32> = values
        .iter()
        .enumerate()
        .map(|(i, value)| *first.entry(value.map(f64::to_bits)).or_insert(i as u32))
        .collect();
    for r in refs.iter_mut().flatten() {
        *r = canonical[*r as usize];
    }
    refs
}

/// The vertices after splitting: each file vertex keeps its index for the
/// first pair of references its corners read; each other pair is a copy
/// (after the file's vertices).
pub(crate) struct SplitVertices {
    /// Per file vertex, the (texture coordinate, normal) pair it kept,
    /// `None` for a vertex no face uses.
    pub(crate) kept: Vec<Option<[u32; 2]>>,
    /// Per copy, its file vertex and its pair.
    pub(crate) copies: Vec<(u32, [u32; 2])>,
}

impl SplitVertices {
    /// Per-vertex values of the file followed by their copies' values.
    pub(crate) fn extend<T: Copy>(&self, mut values: Vec<T>) -> Vec<T> {
        let copied: Vec<T> = self
            .copies
            .iter()
            .map(|&(v, _)| values[v as usize])
            .collect();
        values.extend(copied);
        values
    }

    /// The values the vertices read through their pairs' element `k`
    /// (0: texture coordinate, 1: normal); `unused` for a vertex no face
    /// uses.
    pub(crate) fn read<T: Copy>(&self, values: &[T], k: usize, unused: T) -> Vec<T> {
        let at = |pair: [u32; 2]| values[pair[k] as usize];
        self.kept
            .iter()
            .map(|pair| pair.map_or(unused, at))
            .chain(self.copies.iter().map(|&(_, pair)| at(pair)))
            .collect()
    }
}

/// Renames the corners of `faces` to split vertices: a corner whose
/// vertex was first read with another (texture coordinate, normal) pair
/// goes to the copy for its pair. With neither list, nothing is split.
pub(crate) fn split_corners(
    vertices: usize,
    faces: &mut [[u32; 3]],
    texcoords: Option<&[[u32; 3]]>,
    normals: Option<&[[u32; 3]]>,
) -> Result<SplitVertices> {
    let mut split = SplitVertices {
        kept: vec![None; vertices],
        copies: Vec::new(),
    };
    if texcoords.is_none() && normals.is_none() {
        return Ok(split);
    }
    let mut copy_of: HashMap<(u32, [u32; 2]), u32> = HashMap::default();
    for (f, face) in faces.iter_mut().enumerate() {
        for (k, corner) in face.iter_mut().enumerate() {
            let pair = [texcoords, normals].map(|refs| refs.map_or(NONE, |r| r[f][k]));
            let kept = &mut split.kept[*corner as usize];
            match kept {
                None => *kept = Some(pair),
                Some(first) if *first == pair => {}
                Some(_) => {
                    let next = vertices + split.copies.len();
                    let copy = match copy_of.get(&(*corner, pair)) {
                        Some(&copy) => copy,
                        None => {
                            let index = u32::try_from(next).map_err(|_| {
                                anyhow!("more than {} vertices once split by their texture coordinates and normals", u32::MAX)
                            })?;
                            copy_of.insert((*corner, pair), index);
                            split.copies.push((*corner, pair));
                            index
                        }
                    };
                    *corner = copy;
                }
            }
        }
    }
    Ok(split)
}
