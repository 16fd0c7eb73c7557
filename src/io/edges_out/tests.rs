//! Tests of the edge writers (JSON, OBJ, SVG).

use trim::{Edge, Loop};

use super::*;

/// Six points: a square with corners 0, 1, 2, 3 (plus an interior point
/// 4 and a boundary point 5 that lies in no loop), and a second loop
/// without corners.
fn sample() -> (Vec<Point3>, Vec<bool>, Edges) {
    let points = vec![
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 1.5, 0.0],
        [0.0, 1.5, 0.0],
        [1.0, 0.5, 0.0],
        [0.5, 0.5, 0.25],
    ];
    let boundary = vec![true, true, true, true, false, true];
    let square = Loop {
        boundary_points: vec![0, 1, 2, 3],
        corners: vec![0, 2],
        edges: vec![
            Edge {
                closed: false,
                points: vec![[0.0, 0.0, 0.0], [2.0, 0.1, 0.0], [2.0, 1.5, 0.0]],
            },
            Edge {
                closed: false,
                points: vec![[2.0, 1.5, 0.0], [0.1, 1.5, 0.0], [0.0, 0.0, 0.0]],
            },
        ],
        sides: Vec::new(),
    };
    let hole = Loop {
        boundary_points: vec![5, 4, 1],
        corners: vec![],
        edges: vec![Edge {
            closed: true,
            points: vec![[0.5, 0.5, 0.25], [1.0, 0.5, -1e-7], [0.75, 1.0, 0.0]],
        }],
        sides: Vec::new(),
    };
    let edges = Edges {
        loops: vec![square, hole],
        dropped_clusters: 1,
        thinned_points: 2,
    };
    (points, boundary, edges)
}

fn render(format: EdgesFormat) -> String {
    let (points, boundary, edges) = sample();
    let data = EdgeData {
        points: &points,
        boundary: &boundary,
        edges: &edges,
        units: Default::default(),
    };
    let mut out = Vec::new();
    format.write(&mut out, data).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn formats_from_extensions() {
    let f = |p: &str| EdgesFormat::from_path(std::path::Path::new(p));
    assert_eq!(f("a/b.json"), Some(EdgesFormat::Json));
    assert_eq!(f("b.OBJ"), Some(EdgesFormat::Obj));
    assert_eq!(f("b.svg"), Some(EdgesFormat::Svg));
    assert_eq!(f("b.ply"), None);
    assert_eq!(f("json"), None);
}

#[test]
fn json_has_the_documented_shape() {
    let text = render(EdgesFormat::Json);
    assert_eq!(
        text,
        "{\"loops\":[\
         {\"closed\":true,\"boundary_points\":[0,1,2,3],\
         \"corners\":[[0.0,0.0,0.0],[2.0,1.5,0.0]],\
         \"edges\":[{\"closed\":false,\"points\":[[0.0,0.0,0.0],[2.0,0.1,0.0],[2.0,1.5,0.0]]},\
         {\"closed\":false,\"points\":[[2.0,1.5,0.0],[0.1,1.5,0.0],[0.0,0.0,0.0]]}]},\
         {\"closed\":true,\"boundary_points\":[5,4,1],\"corners\":[],\
         \"edges\":[{\"closed\":true,\"points\":[[0.5,0.5,0.25],[1.0,0.5,-1e-7],[0.75,1.0,0.0]]}]}\
         ]}\n"
    );
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["loops"][1]["edges"][0]["points"][1][2], -1e-7);
}

#[test]
fn obj_shares_corners_and_closes_closed_edges() {
    assert_eq!(
        render(EdgesFormat::Obj),
        "# meshtrim edges\n\
         # 2 loops, 3 edges; one l line per edge\n\
         o loop_0\n\
         v 0 0 0\nv 2 0.1 0\nv 2 1.5 0\nv 0.1 1.5 0\n\
         l 1 2 3\nl 3 4 1\n\
         o loop_1\n\
         v 0.5 0.5 0.25\nv 1 0.5 -0.0000001\nv 0.75 1 0\n\
         l 5 6 7 5\n"
    );
}

#[test]
fn obj_of_nothing_is_just_the_header() {
    let mut out = Vec::new();
    write_obj(&mut out, &Edges::default()).unwrap();
    assert_eq!(
        out,
        b"# meshtrim edges\n# 0 loops, 0 edges; one l line per edge\n"
    );
}

#[test]
fn svg_draws_every_layer() {
    let text = render(EdgesFormat::Svg);
    assert!(text.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 "));
    assert!(text.ends_with("</svg>\n"));
    // 5 boundary points as circles, 2 raw loops and 3 edges as
    // polylines, 2 corners, 1 interior dot.
    assert_eq!(text.matches("<circle ").count(), 5);
    assert_eq!(text.matches("<polyline ").count(), 5);
    assert_eq!(text.matches("l6 10.39").count(), 2);
    assert_eq!(text.matches("h0").count(), 1);
    // The larger side is 1000 units plus the margins.
    let view = text.split("viewBox=\"0 0 ").nth(1).unwrap();
    let size: Vec<f64> = view
        .split('"')
        .next()
        .unwrap()
        .split(' ')
        .map(|s| s.parse().unwrap())
        .collect();
    assert_eq!(size[0].max(size[1]), 1040.0, "{text}");
    // Seen from the side the normal (here about +z) points to, so not
    // mirrored: 0 → 1 → 3 turns counter-clockwise, which with SVG's y
    // axis pointing down is a negative cross product.
    let circles: Vec<[f64; 2]> = text
        .lines()
        .filter(|l| l.starts_with("<circle "))
        .map(|l| {
            let attr = |name: &str| {
                let start = l.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
                let end = start + l[start..].find('"').unwrap();
                l[start..end].parse::<f64>().unwrap()
            };
            [attr("cx"), attr("cy")]
        })
        .collect();
    let (p0, p1, p3) = (circles[0], circles[1], circles[3]);
    let cross = (p1[0] - p0[0]) * (p3[1] - p0[1]) - (p1[1] - p0[1]) * (p3[0] - p0[0]);
    assert!(cross < 0.0, "{circles:?}");
}

#[test]
fn svg_subsamples_interior_points() {
    let n = 2 * SVG_MAX_INTERIOR + 10;
    let points: Vec<Point3> = (0..n)
        .map(|i| [(i % 300) as f64, (i / 300) as f64, 0.0])
        .collect();
    let boundary = vec![false; n];
    let edges = Edges::default();
    let mut out = Vec::new();
    let data = EdgeData {
        points: &points,
        boundary: &boundary,
        edges: &edges,
        units: Default::default(),
    };
    write_svg(&mut out, data).unwrap();
    let text = String::from_utf8(out).unwrap();
    let dots = text.matches("h0").count();
    assert!(
        dots <= SVG_MAX_INTERIOR && dots > SVG_MAX_INTERIOR / 2,
        "{dots}"
    );
}

#[test]
fn numbers_are_rounded_without_trailing_zeros() {
    assert_eq!(num(1.0), "1");
    assert_eq!(num(12.345678), "12.35");
    assert_eq!(num(0.1), "0.1");
    assert_eq!(num(-0.001), "0");
    assert_eq!(num(999.999), "1000");
}
