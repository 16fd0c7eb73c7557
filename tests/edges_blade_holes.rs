//! The smoothed edges of `fixtures/meshes/blade_holes.ply` against the
//! fixture's true geometry (fixtures/meshes/README.md): a strip of 120 ×
//! 40 mm, twisted and cambered, with holes of radius 3, 5 and 8 mm,
//! sampled on a jittered 0.8 mm grid. Two samplings in one cloud: the
//! outer border's samples are clamped onto the border (as a mesh's own
//! vertices are), the holes' outermost samples lie inside the surface,
//! up to a row from the rim (as a scan's do).

use std::path::Path;

use trim::{detect_boundary, reconstruct_edges, BpdOptions, EdgeOptions, Point3};

const SPACING: f64 = 0.8;
const HOLES: [([f64; 2], f64); 3] = [([30.0, 0.0], 3.0), ([65.0, 8.0], 5.0), ([95.0, -6.0], 8.0)];

/// The point's (u, v) on the strip: u = x, and v undoes the twist
/// θ = 30°·u/120 (the camber is the other coordinate of the rotation).
fn strip_coordinates(p: Point3) -> [f64; 2] {
    let theta = 30f64.to_radians() * p[0] / 120.0;
    [p[0], p[1] * theta.cos() + p[2] * theta.sin()]
}

/// Signed distance in (u, v) from the nearest true border, positive
/// outside the surface (beyond the strip's outline or inside a hole), and
/// whether that border is the outline.
fn distance_to_truth([u, v]: [f64; 2]) -> (f64, bool) {
    let outline = (u - 120.0).max(-u).max(v.abs() - 20.0);
    let (hole, _) = HOLES
        .iter()
        .map(|&([cu, cv], r)| (r - ((u - cu).powi(2) + (v - cv).powi(2)).sqrt(), r))
        .fold(
            (f64::NEG_INFINITY, 0.0),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    if outline.abs() <= hole.abs() {
        (outline, true)
    } else {
        (hole, false)
    }
}

/// Distances to the true border, in spacings, of the edge points on the
/// outline and on the holes: (mean |d|, max |d|, mean d) for each.
struct Placement {
    outline: [f64; 3],
    holes: [f64; 3],
}

fn placement(offset: bool) -> Placement {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures/meshes/blade_holes.ply");
    let cloud = meshtrim::io::read_cloud(&path).unwrap();
    let detection = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
    let edges = reconstruct_edges(&cloud.points, &detection, &EdgeOptions { offset });
    assert_eq!(edges.loops.len(), 4, "the outline and three holes");
    let (mut outline, mut holes) = (Vec::new(), Vec::new());
    for l in &edges.loops {
        for e in &l.edges {
            for &p in &e.points {
                let (d, on_outline) = distance_to_truth(strip_coordinates(p));
                if on_outline { &mut outline } else { &mut holes }.push(d / SPACING);
            }
        }
    }
    assert!(
        outline.len() > 300 && holes.len() > 90,
        "{} {}",
        outline.len(),
        holes.len()
    );
    let summary = |d: &[f64]| {
        let n = d.len() as f64;
        [
            d.iter().map(|x| x.abs()).sum::<f64>() / n,
            d.iter().fold(0f64, |m, x| m.max(x.abs())),
            d.iter().sum::<f64>() / n,
        ]
    };
    let p = Placement {
        outline: summary(&outline),
        holes: summary(&holes),
    };
    eprintln!(
        "offset {offset}: outline mean {:.3} max {:.3} signed {:.3}; holes mean {:.3} max {:.3} signed {:.3} (spacings, + outside)",
        p.outline[0], p.outline[1], p.outline[2], p.holes[0], p.holes[1], p.holes[2]
    );
    p
}

/// As the other edge tests require: mean distance at most a quarter
/// spacing, none beyond 1.5.
fn on_the_truth([mean, max, _]: [f64; 3]) -> bool {
    mean <= 0.25 && max <= 1.5
}

/// The holes' outermost samples lie inside the surface, as the offset
/// assumes: with it (the default) their edges are on the rims, without it
/// about half a row inside.
#[test]
fn holes_sampled_inside_the_surface_are_found_on_their_rims() {
    let (with, without) = (placement(true), placement(false));
    assert!(on_the_truth(with.holes), "{:?}", with.holes);
    assert!(
        with.holes[0] < without.holes[0] && without.holes[2] < -0.3,
        "{:?}",
        without.holes
    );
}

/// The outline's samples are clamped onto it: `--no-offset` (the edge
/// through the boundary points) puts the edge on it.
#[test]
fn an_outline_sampled_on_the_border_is_found_without_the_offset() {
    assert!(on_the_truth(placement(false).outline));
}

/// Falls short (a strict expected failure): the default offset moves an
/// outline whose samples lie on it half a row out (0.37 spacings on
/// average). Nothing local tells samples on the edge from a row of samples
/// parallel to it at an unknown depth (both lie on a line), so the offset
/// cannot detect it; `--no-offset`'s help says when to use it.
#[test]
#[should_panic(expected = "outline placed by the offset")]
fn the_offset_misplaces_an_outline_sampled_on_the_border() {
    let outline = placement(true).outline;
    assert!(
        on_the_truth(outline),
        "outline placed by the offset: {outline:?}"
    );
}
