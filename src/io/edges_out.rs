//! Output of `meshtrim edges`: the reconstructed boundary loops and edges.
//!
//! Six formats, chosen by the output's extension, all deterministic byte
//! for byte (no timestamps, floats in Rust's or serde_json's shortest
//! round-trip form, or rounded the same way every time in SVG):
//!
//! - JSON: every loop with its ordered boundary point indices, its corners
//!   and its smoothed edges;
//! - OBJ: the smoothed edges as polylines (`l` lines), one `o` group per
//!   loop;
//! - SVG: a picture like the paper's Figure 4, the cloud seen along the
//!   normal of its best-fit plane;
//! - DXF: one closed 3-D polyline per loop on layers `OUTER` and `HOLES`,
//!   the corners as points, and on request each edge as a spline on
//!   `SPLINES` (`dxf.rs`);
//! - STEP: one cubic B-spline curve per edge through its points, the
//!   corners as points ([`step`]);
//! - IGES: the same curves and points as IGES entities 126 and 116
//!   (`iges.rs`).

use std::fmt::Write as _;
use std::io::Write;

use serde::Serialize;
use trim::{fit_plane, Edges, Frame};

use super::Point3;

/// The input of the writers: the cloud, its boundary labels and its edges.
#[derive(Debug, Clone, Copy)]
pub struct EdgeData<'a> {
    /// The input points, in input order (the loops index them).
    pub points: &'a [Point3],
    /// BPD's labels, one per point; true for boundary points. Only the SVG
    /// picture uses them.
    pub boundary: &'a [bool],
    /// The reconstructed loops.
    pub edges: &'a Edges,
    /// How the file is written: the unit it declares, DXF splines.
    pub options: EdgeFileOptions,
}

/// Choices of an edges file beyond its format.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EdgeFileOptions {
    /// The length unit a STEP, IGES or DXF-with-splines file declares (the
    /// cloud's file does not say it).
    pub units: step::LengthUnit,
    /// DXF: also each edge as a spline, in an R2000 file (`dxf.rs`).
    pub dxf_splines: bool,
}

/// Writes `data` to `path` (atomically), in the format its extension
/// names: what `meshtrim edges -o` writes.
pub fn write_file(path: &std::path::Path, data: EdgeData) -> anyhow::Result<()> {
    let format = edges_format(path)?;
    crate::io::atomic::write_atomic(path, |w| format.write(w, data))
}

/// Output formats of `edges`, chosen by the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgesFormat {
    /// Loops, corners and edges as one JSON object.
    Json,
    /// The smoothed edges as Wavefront OBJ polylines.
    Obj,
    /// A picture of the cloud, the raw loops and the smoothed edges.
    Svg,
    /// DXF: 3-D polylines and corner points (R12), with splines (R2000).
    Dxf,
    /// STEP AP214: cubic B-spline curves and corner points.
    Step,
    /// IGES 5.3: the same curves (entity 126) and points (entity 116).
    Iges,
}

/// The format of an edges output, or the error naming what is accepted.
pub fn edges_format(path: &std::path::Path) -> anyhow::Result<EdgesFormat> {
    EdgesFormat::from_path(path).ok_or_else(|| {
        anyhow::anyhow!(
            "{}: unsupported output format: use .json, .obj, .svg, .dxf, .step or .igs",
            path.display()
        )
    })
}

impl EdgesFormat {
    /// The format an output path asks for, if supported.
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "json" => Some(EdgesFormat::Json),
            "obj" => Some(EdgesFormat::Obj),
            "svg" => Some(EdgesFormat::Svg),
            "dxf" => Some(EdgesFormat::Dxf),
            "step" | "stp" => Some(EdgesFormat::Step),
            "igs" | "iges" => Some(EdgesFormat::Iges),
            _ => None,
        }
    }

    /// Writes `data` in this format.
    pub fn write(self, w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
        match self {
            EdgesFormat::Json => write_json(w, data),
            EdgesFormat::Obj => write_obj(w, data.edges),
            EdgesFormat::Svg => write_svg(w, data),
            EdgesFormat::Dxf => dxf::write_dxf(w, data),
            EdgesFormat::Step => step::write_step(w, data),
            EdgesFormat::Iges => iges::write_iges(w, data),
        }
    }
}

#[derive(Serialize)]
struct JsonEdges<'a> {
    loops: Vec<JsonLoop<'a>>,
}

#[derive(Serialize)]
struct JsonLoop<'a> {
    closed: bool,
    boundary_points: &'a [u32],
    corners: Vec<Point3>,
    edges: Vec<JsonEdge<'a>>,
}

#[derive(Serialize)]
struct JsonEdge<'a> {
    closed: bool,
    points: &'a [Point3],
}

/// One compact JSON object and a newline:
/// `{"loops":[{"closed":true,"boundary_points":[..],"corners":[[x,y,z],..],
/// "edges":[{"closed":false,"points":[[x,y,z],..]},..]},..]}`.
///
/// `boundary_points` are indices into the input cloud in loop order;
/// `corners` are the input coordinates of the corner points; a loop is
/// always closed, an edge only when its loop has no corner.
pub fn write_json(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let loops = data
        .edges
        .loops
        .iter()
        .map(|l| JsonLoop {
            closed: true,
            boundary_points: &l.boundary_points,
            corners: l.corner_points(data.points),
            edges: l
                .edges
                .iter()
                .map(|e| JsonEdge {
                    closed: e.closed,
                    points: &e.points,
                })
                .collect(),
        })
        .collect();
    serde_json::to_writer(&mut *w, &JsonEdges { loops })?;
    writeln!(w)
}

/// The smoothed edges as OBJ polylines: a header comment, then per loop an
/// `o loop_N` group (N from 0, the loop's position in the JSON output), its
/// `v` lines and one `l` line per edge (1-based indices). A closed edge
/// repeats its first index at the end. Consecutive edges of a loop share
/// their corner vertex when the coordinates are identical, as the library
/// makes them, so each loop is one connected polyline.
pub fn write_obj(w: &mut dyn Write, edges: &Edges) -> std::io::Result<()> {
    let edge_count: usize = edges.loops.iter().map(|l| l.edges.len()).sum();
    writeln!(w, "# meshtrim edges")?;
    writeln!(
        w,
        "# {} loops, {edge_count} edges; one l line per edge",
        edges.loops.len()
    )?;
    let mut next = 1usize; // the next vertex's OBJ index
    for (n, l) in edges.loops.iter().enumerate() {
        writeln!(w, "o loop_{n}")?;
        // (coordinates, index) of the loop's first vertex and of the last one
        // written, to share corners between consecutive edges.
        let mut first: Option<(Point3, usize)> = None;
        let mut last: Option<(Point3, usize)> = None;
        let mut lines = Vec::with_capacity(l.edges.len());
        for e in &l.edges {
            let mut ids = Vec::with_capacity(e.points.len() + 1);
            for (i, &p) in e.points.iter().enumerate() {
                let shared = match (i, last, first) {
                    (0, Some((q, id)), _) if q == p => Some(id),
                    (i, _, Some((q, id))) if i + 1 == e.points.len() && q == p => Some(id),
                    _ => None,
                };
                let id = shared.unwrap_or(next);
                if shared.is_none() {
                    writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
                    next += 1;
                }
                first.get_or_insert((p, id));
                last = Some((p, id));
                ids.push(id);
            }
            if e.closed {
                if let Some(&id) = ids.first() {
                    ids.push(id);
                }
            }
            lines.push(ids);
        }
        for ids in lines.iter().filter(|ids| ids.len() >= 2) {
            write!(w, "l")?;
            for id in ids {
                write!(w, " {id}")?;
            }
            writeln!(w)?;
        }
    }
    Ok(())
}

/// Interior points drawn at most, every n-th one, to keep the file small.
pub const SVG_MAX_INTERIOR: usize = 20_000;

/// Size of the picture's larger side, in SVG user units.
const SVG_SIZE: f64 = 1000.0;
/// Empty space around the data, in SVG user units.
const SVG_MARGIN: f64 = 20.0;

/// A picture like the paper's Figure 4: the cloud projected onto its
/// best-fit plane and seen from the side its normal points to (first
/// tangent axis to the right, second up), with the interior points as small
/// grey dots (every n-th one, at most [`SVG_MAX_INTERIOR`]), all boundary
/// points as red circles, the raw ordered loops as dashed grey-blue lines,
/// the smoothed edges as solid dark lines and the corners as asterisks.
///
/// The data is scaled so the larger side is 1000 units plus a margin, and
/// coordinates are rounded to 0.01 units.
pub fn write_svg(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let view = SvgView::new(data);
    write_svg_header(w, data, &view)?;
    write_interior_points(w, data, &view)?;
    write_boundary_points(w, data, &view)?;
    write_raw_loops(w, data.edges, &view)?;
    write_smoothed_edges(w, data.edges, &view)?;
    write_corners(w, data.edges, &view)?;
    writeln!(w, "</svg>")
}

/// The cloud's best-fit plane, in which the picture is drawn.
struct PicturePlane {
    frame: Frame,
    origin: Point3,
}

impl PicturePlane {
    /// The plane of all the points, relative to the first (any plane for
    /// no points).
    fn of(points: &[Point3]) -> Self {
        let frame = if points.is_empty() {
            Frame {
                u: [1.0, 0.0, 0.0],
                v: [0.0, 1.0, 0.0],
                normal: [0.0, 0.0, 1.0],
            }
        } else {
            let all: Vec<u32> = (0..points.len() as u32).collect();
            fit_plane(points, &all)
        };
        PicturePlane {
            frame,
            origin: points.first().copied().unwrap_or([0.0; 3]),
        }
    }

    /// Plane coordinates with the y axis pointing down, as SVG's does.
    fn project(&self, p: &Point3) -> [f64; 2] {
        let origin = self.origin;
        let d = [p[0] - origin[0], p[1] - origin[1], p[2] - origin[2]];
        let dot = |a: &Point3| d[0] * a[0] + d[1] * a[1] + d[2] * a[2];
        [dot(&self.frame.u), -dot(&self.frame.v)]
    }
}

/// How the picture sees the cloud: its plane, and the scale and offset
/// from plane coordinates to picture coordinates.
struct SvgView {
    plane: PicturePlane,
    /// Every input point in plane coordinates.
    projected: Vec<[f64; 2]>,
    /// Smallest plane coordinates of the points and edges.
    lo: [f64; 2],
    /// Picture units per plane unit.
    scale: f64,
    width: f64,
    height: f64,
}

impl SvgView {
    /// Fits the points and the smoothed edges in a picture whose larger
    /// side is [`SVG_SIZE`], plus the margins.
    fn new(data: EdgeData) -> Self {
        let plane = PicturePlane::of(data.points);
        let projected: Vec<[f64; 2]> = data.points.iter().map(|p| plane.project(p)).collect();
        let (lo, hi) = bounds(&plane, &projected, data.edges);
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let scale = if extent > 0.0 { SVG_SIZE / extent } else { 1.0 };
        SvgView {
            plane,
            projected,
            lo,
            scale,
            width: (hi[0] - lo[0]) * scale + 2.0 * SVG_MARGIN,
            height: (hi[1] - lo[1]) * scale + 2.0 * SVG_MARGIN,
        }
    }

    /// Plane coordinates to picture coordinates.
    fn to_svg(&self, q: [f64; 2]) -> [f64; 2] {
        [
            (q[0] - self.lo[0]) * self.scale + SVG_MARGIN,
            (q[1] - self.lo[1]) * self.scale + SVG_MARGIN,
        ]
    }

    /// Input point `i` in picture coordinates.
    fn at(&self, i: usize) -> [f64; 2] {
        self.to_svg(self.projected[i])
    }

    /// Any point in picture coordinates.
    fn point(&self, p: &Point3) -> [f64; 2] {
        self.to_svg(self.plane.project(p))
    }
}

/// The bounding box of the `projected` points and the smoothed edges in
/// the plane; the unit square when there is nothing.
fn bounds(plane: &PicturePlane, projected: &[[f64; 2]], edges: &Edges) -> ([f64; 2], [f64; 2]) {
    let edge_points = edges
        .loops
        .iter()
        .flat_map(|l| &l.edges)
        .flat_map(|e| &e.points);
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for q in projected
        .iter()
        .copied()
        .chain(edge_points.map(|p| plane.project(p)))
    {
        for a in 0..2 {
            lo[a] = lo[a].min(q[a]);
            hi[a] = hi[a].max(q[a]);
        }
    }
    if lo[0] > hi[0] {
        (lo, hi) = ([0.0; 2], [1.0; 2]);
    }
    (lo, hi)
}

/// Is input point `i` labelled a boundary point?
fn is_boundary(data: EdgeData, i: usize) -> bool {
    data.boundary.get(i).copied().unwrap_or(false)
}

/// The `<svg>` element's opening, a title with the counts, and a white
/// background.
fn write_svg_header(w: &mut dyn Write, data: EdgeData, view: &SvgView) -> std::io::Result<()> {
    let loops = &data.edges.loops;
    let edge_count: usize = loops.iter().map(|l| l.edges.len()).sum();
    let corner_count: usize = loops.iter().map(|l| l.corners.len()).sum();
    let (w_, h_) = (num(view.width), num(view.height));
    writeln!(
        w,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"0 0 {w_} {h_}\" \
         width=\"{w_}\" height=\"{h_}\">"
    )?;
    writeln!(
        w,
        "<title>meshtrim edges: {} points, {} loops, {edge_count} edges, {corner_count} corners</title>",
        data.points.len(),
        loops.len()
    )?;
    writeln!(w, "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>")
}

/// Every n-th interior point, at most [`SVG_MAX_INTERIOR`], as a grey dot:
/// zero-length round-capped segments, the most compact dots SVG has, 1000
/// to a path.
fn write_interior_points(w: &mut dyn Write, data: EdgeData, view: &SvgView) -> std::io::Result<()> {
    let interior: Vec<usize> = (0..data.points.len())
        .filter(|&i| !is_boundary(data, i))
        .collect();
    let step = interior.len().div_ceil(SVG_MAX_INTERIOR).max(1);
    writeln!(
        w,
        "<g id=\"interior\" fill=\"none\" stroke=\"#a8a8a8\" stroke-width=\"2\" stroke-linecap=\"round\">"
    )?;
    for chunk in interior
        .iter()
        .step_by(step)
        .collect::<Vec<_>>()
        .chunks(1000)
    {
        writeln!(w, "<path d=\"{}\"/>", dots(chunk, view).trim_end())?;
    }
    writeln!(w, "</g>")
}

/// The path data of a dot at each of the `points` (input indices), 16 to
/// a line.
fn dots(points: &[&usize], view: &SvgView) -> String {
    let mut d = String::new();
    for (n, &&i) in points.iter().enumerate() {
        let [x, y] = view.at(i);
        let sep = if n % 16 == 15 { "\n" } else { "" };
        let _ = write!(d, "M{} {}h0{sep}", num(x), num(y));
    }
    d
}

/// Every boundary point as a red circle.
fn write_boundary_points(w: &mut dyn Write, data: EdgeData, view: &SvgView) -> std::io::Result<()> {
    writeln!(
        w,
        "<g id=\"boundary-points\" fill=\"none\" stroke=\"#d02020\" stroke-width=\"0.8\">"
    )?;
    for i in (0..data.points.len()).filter(|&i| is_boundary(data, i)) {
        let [x, y] = view.at(i);
        writeln!(w, "<circle cx=\"{}\" cy=\"{}\" r=\"2.5\"/>", num(x), num(y))?;
    }
    writeln!(w, "</g>")
}

/// Each loop's ordered boundary points, closed, as a dashed grey-blue
/// line.
fn write_raw_loops(w: &mut dyn Write, edges: &Edges, view: &SvgView) -> std::io::Result<()> {
    writeln!(
        w,
        "<g id=\"raw-loops\" fill=\"none\" stroke=\"#6f8fb0\" stroke-width=\"1\" stroke-dasharray=\"4 3\">"
    )?;
    for l in &edges.loops {
        let ring = l.boundary_points.iter().chain(l.boundary_points.first());
        polyline(w, ring.map(|&i| view.at(i as usize)))?;
    }
    writeln!(w, "</g>")
}

/// The smoothed edges as solid dark lines, a closed edge back to its first
/// point.
fn write_smoothed_edges(w: &mut dyn Write, edges: &Edges, view: &SvgView) -> std::io::Result<()> {
    writeln!(
        w,
        "<g id=\"edges\" fill=\"none\" stroke=\"#202020\" stroke-width=\"1.6\" stroke-linejoin=\"round\">"
    )?;
    for e in edges.loops.iter().flat_map(|l| &l.edges) {
        let closing = if e.closed { e.points.first() } else { None };
        polyline(w, e.points.iter().chain(closing).map(|p| view.point(p)))?;
    }
    writeln!(w, "</g>")
}

/// The corners as asterisks, at their input points.
fn write_corners(w: &mut dyn Write, edges: &Edges, view: &SvgView) -> std::io::Result<()> {
    writeln!(
        w,
        "<g id=\"corners\" fill=\"none\" stroke=\"black\" stroke-width=\"1.4\">"
    )?;
    for l in &edges.loops {
        for &c in &l.corners {
            let [x, y] = view.at(l.boundary_points[c] as usize);
            // A six-pointed asterisk of radius 6, as in the paper.
            writeln!(
                w,
                "<path d=\"M{} {}h12M{} {}l6 10.39M{} {}l-6 10.39\"/>",
                num(x - 6.0),
                num(y),
                num(x - 3.0),
                num(y - 5.2),
                num(x + 3.0),
                num(y - 5.2)
            )?;
        }
    }
    writeln!(w, "</g>")
}

/// One `<polyline>` through `points`, 8 points a line.
fn polyline(w: &mut dyn Write, points: impl Iterator<Item = [f64; 2]>) -> std::io::Result<()> {
    let mut text = String::new();
    for (n, [x, y]) in points.enumerate() {
        let sep = match n {
            0 => "",
            n if n % 8 == 0 => "\n",
            _ => " ",
        };
        let _ = write!(text, "{sep}{},{}", num(x), num(y));
    }
    writeln!(w, "<polyline points=\"{text}\"/>")
}

/// A picture coordinate, rounded to 0.01 (six significant digits at most on
/// a 1000-unit picture), without trailing zeros.
fn num(x: f64) -> String {
    let s = format!("{x:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

mod dxf;
mod iges;
pub mod step;

#[cfg(test)]
mod tests;
