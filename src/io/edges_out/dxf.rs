//! DXF output of the smoothed edges (`meshtrim edges CLOUD -o OUT.dxf`),
//! for CAD and CAM systems: the part's outline and holes as 3-D polylines.
//!
//! An ASCII DXF R12 (AC1009) file, which every DXF reader takes:
//!
//! - one closed 3-D `POLYLINE` per loop (flags 1 + 8: closed, 3-D), its
//!   `VERTEX`es the loop's smoothed edge points in loop order, each corner
//!   once: exactly the points of the JSON output, written in the shortest
//!   decimals that read back to the same f64;
//! - layer `OUTER` for a loop that bounds a patch from outside, `HOLES` for
//!   a loop inside one (see [`outer_loops`]);
//! - every corner (where an edge ends and the next begins, on the smoothed
//!   curve) a `POINT` on layer `CORNERS`.
//!
//! Written by hand rather than with the `dxf` crate: that crate writes
//! floats with 12 decimals (not the last bit), stamps the file with the
//! time (not the same bytes twice) and brings in an image codec; the R12
//! subset needed here is a few group codes. ezdxf reads and audits the
//! output in the tests.

use std::io::Write;

use super::{EdgeData, PicturePlane};
use crate::io::float_text::push_f64;
use crate::io::Point3;

/// Layers, with their AutoCAD colour numbers.
const LAYERS: [(&str, u8); 3] = [("OUTER", 7), ("HOLES", 1), ("CORNERS", 3)];

/// Writes the edges as DXF (see the module doc).
pub fn write_dxf(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let mut out = Vec::new();
    header(&mut out);
    let polylines: Vec<Vec<Point3>> = data.edges.loops.iter().map(closed_polyline).collect();
    let outer = outer_loops(&polylines, &PicturePlane::of(data.points));
    for (polyline, is_outer) in polylines.iter().zip(outer) {
        let layer = if is_outer { "OUTER" } else { "HOLES" };
        write_polyline(&mut out, polyline, layer);
    }
    for l in &data.edges.loops {
        for e in l.edges.iter().filter(|e| !e.closed) {
            if let Some(&corner) = e.points.first() {
                group(&mut out, 0, "POINT");
                group(&mut out, 8, "CORNERS");
                point(&mut out, 10, corner);
            }
        }
    }
    group(&mut out, 0, "ENDSEC");
    group(&mut out, 0, "EOF");
    w.write_all(&out)
}

/// A loop as one closed polyline: each open edge without its last point
/// (the next edge's first, a corner), or the one closed edge whole.
fn closed_polyline(l: &trim::Loop) -> Vec<Point3> {
    let mut points = Vec::new();
    for e in &l.edges {
        let take = if e.closed {
            e.points.len()
        } else {
            e.points.len().saturating_sub(1)
        };
        points.extend_from_slice(&e.points[..take]);
    }
    points
}

/// Which loops bound their patch from outside: seen in the cloud's
/// best-fit plane, a loop inside an even number of other loops (none, or
/// an island in a hole) is outer, one inside an odd number is a hole. On a
/// surface that folds over its plane the projection can mislead; the
/// polylines themselves are exact either way.
fn outer_loops(polylines: &[Vec<Point3>], plane: &PicturePlane) -> Vec<bool> {
    let projected: Vec<Vec<[f64; 2]>> = polylines
        .iter()
        .map(|p| p.iter().map(|q| plane.project(q)).collect())
        .collect();
    (0..projected.len())
        .map(|i| {
            let Some(&probe) = projected[i].first() else {
                return true;
            };
            let around = (0..projected.len())
                .filter(|&j| j != i && contains(&projected[j], probe))
                .count();
            around % 2 == 0
        })
        .collect()
}

/// Even-odd rule: does the closed polygon contain `p`?
fn contains(polygon: &[[f64; 2]], p: [f64; 2]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for k in 0..n {
        let (a, b) = (polygon[k], polygon[(k + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
            if p[0] < x {
                inside = !inside;
            }
        }
    }
    inside
}

/// The HEADER (R12) and the TABLES section with the line type and layers.
fn header(out: &mut Vec<u8>) {
    group(
        out,
        999,
        "meshtrim edges: smoothed boundary loops (OUTER, HOLES), corners (CORNERS)",
    );
    group(out, 0, "SECTION");
    group(out, 2, "HEADER");
    group(out, 9, "$ACADVER");
    group(out, 1, "AC1009");
    group(out, 0, "ENDSEC");
    group(out, 0, "SECTION");
    group(out, 2, "TABLES");
    group(out, 0, "TABLE");
    group(out, 2, "LTYPE");
    group(out, 70, "1");
    group(out, 0, "LTYPE");
    group(out, 2, "CONTINUOUS");
    group(out, 70, "0");
    group(out, 3, "Solid line");
    group(out, 72, "65");
    group(out, 73, "0");
    group(out, 40, "0.0");
    group(out, 0, "ENDTAB");
    group(out, 0, "TABLE");
    group(out, 2, "LAYER");
    group(out, 70, &LAYERS.len().to_string());
    for (name, colour) in LAYERS {
        group(out, 0, "LAYER");
        group(out, 2, name);
        group(out, 70, "0");
        group(out, 62, &colour.to_string());
        group(out, 6, "CONTINUOUS");
    }
    group(out, 0, "ENDTAB");
    group(out, 0, "ENDSEC");
    group(out, 0, "SECTION");
    group(out, 2, "ENTITIES");
}

fn write_polyline(out: &mut Vec<u8>, polyline: &[Point3], layer: &str) {
    group(out, 0, "POLYLINE");
    group(out, 8, layer);
    group(out, 66, "1");
    point(out, 10, [0.0; 3]);
    group(out, 70, "9"); // 1 closed + 8 3-D polyline
    for &p in polyline {
        group(out, 0, "VERTEX");
        group(out, 8, layer);
        point(out, 10, p);
        group(out, 70, "32"); // a 3-D polyline's vertex
    }
    group(out, 0, "SEQEND");
    group(out, 8, layer);
}

/// One group: the code on its line, the value on the next.
fn group(out: &mut Vec<u8>, code: u16, value: &str) {
    out.extend_from_slice(format!("{code:>3}\n{value}\n").as_bytes());
}

/// A point as the groups `code`, `code + 10`, `code + 20` (x, y, z).
fn point(out: &mut Vec<u8>, code: u16, p: Point3) {
    for (axis, c) in p.into_iter().enumerate() {
        out.extend_from_slice(format!("{:>3}\n", code + 10 * axis as u16).as_bytes());
        push_f64(out, c);
        out.push(b'\n');
    }
}
