//! Test support for the readers that parse text in pieces.

use std::fmt::Debug;

/// A seeded draw: `below(n)` is a number under n.
pub(crate) type Below<'a> = &'a mut dyn FnMut(u64) -> usize;

/// Reads `cases` seeded random texts in one pass (`one_pass`) and in
/// pieces of 1, 5, 16 and 64 bytes (`in_pieces`), and asserts the same
/// outcome, error messages included. Text `case` is `start(below,
/// case)`, then up to `max_lines` lines, line `l` being `line(below, l,
/// case)` ended at random by `\n`, `\r\n` or `\r`. Returns how many
/// texts failed to read, for the caller to check that both outcomes
/// were tried.
pub(crate) fn compare_with_one_pass<T: PartialEq + Debug>(
    seed: u64,
    cases: usize,
    max_lines: u64,
    start: impl Fn(Below, usize) -> String,
    line: impl Fn(Below, usize, usize) -> String,
    one_pass: impl Fn(&str) -> Result<T, String>,
    in_pieces: impl Fn(&str, usize) -> Result<T, String>,
) -> usize {
    let mut rng = testkit::synthetic::SplitMix64::new(seed);
    let mut below = |n: u64| (rng.next_u64() % n) as usize;
    let ends = ["\n", "\r\n", "\r"];
    let mut errors = 0;
    for case in 0..cases {
        let mut text = start(&mut below, case);
        for l in 0..below(max_lines) {
            text += &line(&mut below, l, case);
            text += ends[below(3)];
        }
        let want = one_pass(&text);
        for piece_bytes in [1, 5, 16, 64] {
            let got = in_pieces(&text, piece_bytes);
            assert_eq!(got, want, "pieces of {piece_bytes} bytes: {text:?}");
        }
        errors += usize::from(want.is_err());
    }
    errors
}
