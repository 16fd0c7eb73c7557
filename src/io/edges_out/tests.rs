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
        ..Edges::default()
    };
    (points, boundary, edges)
}

fn render(format: EdgesFormat) -> String {
    let (points, boundary, edges) = sample();
    let data = EdgeData {
        points: &points,
        boundary: &boundary,
        edges: &edges,
        options: Default::default(),
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
        options: Default::default(),
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

/// The groups of a DXF file as (code, value) pairs.
fn dxf_groups(text: &str) -> Vec<(u16, &str)> {
    let lines: Vec<&str> = text.lines().collect();
    lines
        .chunks_exact(2)
        .map(|pair| (pair[0].trim().parse().unwrap(), pair[1]))
        .collect()
}

fn render_dxf(options: EdgeFileOptions) -> String {
    let (points, boundary, edges) = sample();
    let data = EdgeData {
        points: &points,
        boundary: &boundary,
        edges: &edges,
        options,
    };
    let mut out = Vec::new();
    EdgesFormat::Dxf.write(&mut out, data).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn dxf_with_splines_has_unique_handles_and_known_owners() {
    let text = render_dxf(EdgeFileOptions {
        dxf_splines: true,
        ..Default::default()
    });
    let groups = dxf_groups(&text);
    // 5 is a handle (but in the header $HANDSEED's value), 105 a dimension
    // style's; 330 an owner, 350 a dictionary entry.
    let objects = groups.iter().position(|g| *g == (2, "TABLES")).unwrap();
    let handles: Vec<u64> = groups[objects..]
        .iter()
        .filter(|(code, _)| matches!(code, 5 | 105))
        .map(|(_, v)| u64::from_str_radix(v, 16).unwrap())
        .collect();
    let unique: std::collections::BTreeSet<u64> = handles.iter().copied().collect();
    assert_eq!(unique.len(), handles.len(), "handles are unique");
    let seed = groups
        .windows(2)
        .find(|w| w[0] == (9, "$HANDSEED"))
        .map(|w| u64::from_str_radix(w[1].1, 16).unwrap())
        .unwrap();
    assert!(
        unique.iter().all(|&h| 0 < h && h < seed),
        "the seed is beyond every handle"
    );
    for (code, value) in &groups {
        if matches!(code, 330 | 350) && *value != "0" {
            let h = u64::from_str_radix(value, 16).unwrap();
            assert!(
                unique.contains(&h),
                "{code} names {value}, which is no object"
            );
        }
    }
    let kinds: Vec<&str> = groups.iter().filter(|g| g.0 == 0).map(|g| g.1).collect();
    assert_eq!(
        kinds.iter().filter(|&&k| k == "SPLINE").count(),
        3,
        "one per edge"
    );
    assert_eq!(
        kinds.iter().filter(|&&k| k == "POINT").count(),
        2,
        "one per corner"
    );
    assert!(text.contains("AC1015") && text.ends_with("  0\nEOF\n"));
}

#[test]
fn dxf_splines_interpolate_the_edge_points() {
    let text = render_dxf(EdgeFileOptions {
        dxf_splines: true,
        ..Default::default()
    });
    let groups = dxf_groups(&text);
    let (_, edges) = (sample().0, sample().2);
    let splines: Vec<usize> = (0..groups.len())
        .filter(|&i| groups[i] == (0, "SPLINE"))
        .collect();
    for (&at, edge) in splines
        .iter()
        .zip(edges.loops.iter().flat_map(|l| &l.edges))
    {
        let entity: Vec<(u16, &str)> = groups[at + 1..]
            .iter()
            .take_while(|g| g.0 != 0)
            .copied()
            .collect();
        let values = |code: u16| -> Vec<f64> {
            entity
                .iter()
                .filter(|g| g.0 == code)
                .map(|g| g.1.parse().unwrap())
                .collect()
        };
        let knots = values(40);
        let (x, y, z) = (values(10), values(20), values(30));
        assert_eq!(values(71), [3.0]);
        assert_eq!(values(72), [knots.len() as f64]);
        assert_eq!(values(73), [x.len() as f64]);
        assert_eq!(knots.len(), x.len() + 4, "a cubic's knot count");
        assert_eq!(
            values(70),
            [0.0],
            "clamped, never flagged periodic or closed"
        );
        // The curve the file holds is the one STEP and IGES write.
        let curve = trim::interpolate_bspline(&edge.points, edge.closed)
            .unwrap()
            .with_double_knots();
        assert_eq!(knots, curve.knot_vector());
        let control: Vec<Point3> = (0..x.len()).map(|i| [x[i], y[i], z[i]]).collect();
        assert_eq!(control, curve.control_points);
        // It starts at the edge's first point (and a closed edge's ends
        // there too) and passes through each.
        assert_eq!(control[0], edge.points[0]);
        if edge.closed {
            assert_eq!(control.last(), Some(&edge.points[0]));
        }
        for (p, &k) in edge.points.iter().zip(&curve.knots) {
            let on = curve.point_at(k);
            assert!((0..3).all(|c| (on[c] - p[c]).abs() < 1e-12), "{on:?} {p:?}");
        }
    }
}

#[test]
fn dxf_declares_the_unit_only_with_splines() {
    for (units, code) in [
        (step::LengthUnit::Mm, "4"),
        (step::LengthUnit::M, "6"),
        (step::LengthUnit::In, "1"),
    ] {
        let text = render_dxf(EdgeFileOptions {
            units,
            dxf_splines: true,
        });
        assert!(
            text.contains(&format!("$INSUNITS\n 70\n{code}\n")),
            "{units:?}"
        );
    }
    let r12 = render_dxf(EdgeFileOptions::default());
    assert!(r12.contains("AC1009") && !r12.contains("$INSUNITS") && !r12.contains("SPLINE"));
}
