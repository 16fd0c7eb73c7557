//! Values filed by row in a counting sort, on every thread: the compressed
//! rows behind a mesh's edge rows, vertex stars and face buckets
//! (infrastructure of meshtrim's mesh stages; no section of the paper).
//!
//! One pass of a counting sort over a large mesh's faces is a scatter
//! into millions of rows, and the mesh stages make several. Here each
//! thread owns a range of rows: it reads every face but counts and files
//! only the values of its own rows, in face order. So each row comes out
//! exactly as one sequential pass files it, whatever the number of
//! threads, with no atomics and no shared writes.

use rayon::prelude::*;

/// Below this many faces a single pass is as fast.
const PARALLEL_FROM: usize = 1 << 16;

/// Values in rows: row `r` is `values[start[r]..start[r + 1]]`.
pub(crate) struct Rows<T> {
    pub(crate) start: Vec<u32>,
    pub(crate) values: Vec<T>,
}

/// Files what `item(f, face, k)` gives for each face `f` and corner
/// `k = 0, 1, 2` — a row below `rows` and a value, or nothing — into rows:
/// each row holds its values in face order, then corner order.
pub(crate) fn file_by_row<T, F>(rows: usize, faces: &[[u32; 3]], item: F) -> Rows<T>
where
    T: Copy + Default + Send,
    F: Fn(u32, &[u32; 3], usize) -> Option<(u32, T)> + Sync,
{
    let ranges = row_ranges(rows, faces.len());
    let mut start = vec![0u32; rows + 1];
    for_each_part(&ranges, &mut start[1..], |range, count| {
        items_in_range(faces, &item, range, |r, _| count[r] += 1);
    });
    for r in 1..start.len() {
        start[r] += start[r - 1];
    }
    let mut values = vec![T::default(); start[rows] as usize];
    let value_ranges: Vec<_> = ranges
        .iter()
        .map(|r| start[r.start] as usize..start[r.end] as usize)
        .collect();
    let mut parts = split_by(&mut values, &value_ranges);
    parts.par_iter_mut().zip(&ranges).for_each(|(part, range)| {
        let base = start[range.start];
        let mut fill: Vec<u32> = start[range.clone()].iter().map(|s| s - base).collect();
        items_in_range(faces, &item, range, |r, value| {
            part[fill[r] as usize] = value;
            fill[r] += 1;
        });
    });
    Rows { start, values }
}

/// Calls `file(r - range.start, value)` for each item of a row in `range`,
/// in face order, then corner order.
fn items_in_range<T, F>(
    faces: &[[u32; 3]],
    item: &F,
    range: &std::ops::Range<usize>,
    mut file: impl FnMut(usize, T),
) where
    F: Fn(u32, &[u32; 3], usize) -> Option<(u32, T)>,
{
    for (f, face) in faces.iter().enumerate() {
        for k in 0..3 {
            if let Some((r, value)) = item(f as u32, face, k) {
                let r = r as usize;
                if range.contains(&r) {
                    file(r - range.start, value);
                }
            }
        }
    }
}

impl<T: Send> Rows<T> {
    /// Sorts each row by `key`, stably, rows on every thread.
    pub(crate) fn sort_each_by_key<K: Ord>(&mut self, key: impl Fn(&T) -> K + Sync) {
        let rows = self.start.len() - 1;
        let ranges = row_ranges(rows, self.values.len());
        let value_ranges: Vec<_> = ranges
            .iter()
            .map(|r| self.start[r.start] as usize..self.start[r.end] as usize)
            .collect();
        let start = &self.start;
        let mut parts = split_by(&mut self.values, &value_ranges);
        parts.par_iter_mut().zip(&ranges).for_each(|(part, range)| {
            let base = start[range.start];
            for w in start[range.start..=range.end].windows(2) {
                part[(w[0] - base) as usize..(w[1] - base) as usize].sort_by_key(&key);
            }
        });
    }
}

/// The rows split into one range per thread (one range for small inputs).
fn row_ranges(rows: usize, work: usize) -> Vec<std::ops::Range<usize>> {
    let parts = if work < PARALLEL_FROM {
        1
    } else {
        rayon::current_num_threads().clamp(1, rows.max(1))
    };
    (0..parts)
        .map(|p| rows * p / parts..rows * (p + 1) / parts)
        .collect()
}

/// Runs `work` on each range of rows with its own part of `per_row`
/// (indexed from the range's start), on every thread.
fn for_each_part<T: Send>(
    ranges: &[std::ops::Range<usize>],
    per_row: &mut [T],
    work: impl Fn(&std::ops::Range<usize>, &mut [T]) + Sync,
) {
    let mut parts = split_by(per_row, ranges);
    parts
        .par_iter_mut()
        .zip(ranges)
        .for_each(|(part, range)| work(range, part));
}

/// `slice` cut into the consecutive `ranges`, which cover it from 0.
fn split_by<'a, T>(mut slice: &'a mut [T], ranges: &[std::ops::Range<usize>]) -> Vec<&'a mut [T]> {
    let mut parts = Vec::with_capacity(ranges.len());
    for range in ranges {
        let (part, rest) = slice.split_at_mut(range.len());
        parts.push(part);
        slice = rest;
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// One sequential pass of a counting sort: the reference.
    fn file_by_row_reference<T: Copy>(
        rows: usize,
        faces: &[[u32; 3]],
        item: impl Fn(u32, &[u32; 3], usize) -> Option<(u32, T)>,
    ) -> (Vec<u32>, Vec<T>) {
        let mut filed: Vec<Vec<T>> = vec![Vec::new(); rows];
        for (f, face) in faces.iter().enumerate() {
            for k in 0..3 {
                if let Some((r, value)) = item(f as u32, face, k) {
                    filed[r as usize].push(value);
                }
            }
        }
        let mut start = vec![0u32];
        for row in &filed {
            start.push(start.last().unwrap() + row.len() as u32);
        }
        (start, filed.concat())
    }

    fn random_faces(rng: &mut ChaCha8Rng, faces: usize, vertices: u32) -> Vec<[u32; 3]> {
        (0..faces)
            .map(|_| std::array::from_fn(|_| rng.random_range(0..vertices)))
            .collect()
    }

    #[test]
    fn files_as_one_sequential_pass_on_any_number_of_threads() {
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for (faces, vertices) in [(0, 1), (5, 3), (1000, 50), (70_000, 9_000), (90_000, 7)] {
            let faces = random_faces(&mut rng, faces, vertices);
            // Some corners give nothing, as a filter would.
            let item = |f: u32, face: &[u32; 3], k: usize| {
                (face[k] % 5 != 1).then(|| (face[k].min(face[(k + 1) % 3]), (f, k as u8)))
            };
            let expected = file_by_row_reference(vertices as usize, &faces, item);
            for threads in [1, 2, 3, 5] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let rows = pool.install(|| file_by_row(vertices as usize, &faces, item));
                assert_eq!((rows.start, rows.values), expected, "{threads} threads");
            }
        }
    }

    #[test]
    fn sorts_each_row_stably() {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let faces = random_faces(&mut rng, 80_000, 20_000);
        let item = |f: u32, face: &[u32; 3], k: usize| Some((face[k], (face[(k + 1) % 3], f)));
        let (start, mut expected) = file_by_row_reference(20_000, &faces, item);
        for w in start.windows(2) {
            expected[w[0] as usize..w[1] as usize].sort_by_key(|v| v.0);
        }
        for threads in [1, 2, 4] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let mut rows = pool.install(|| file_by_row(20_000, &faces, item));
            pool.install(|| rows.sort_each_by_key(|v| v.0));
            assert_eq!(rows.values, expected, "{threads} threads");
        }
    }
}
