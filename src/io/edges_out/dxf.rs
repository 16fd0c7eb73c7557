//! DXF output of the smoothed edges (`meshtrim edges CLOUD -o OUT.dxf`),
//! for CAD and CAM systems: the part's outline and holes as 3-D polylines,
//! and on request each edge as a spline curve.
//!
//! By default an ASCII DXF R12 (AC1009) file, which every DXF reader takes:
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
//! With splines ([`super::EdgeFileOptions::dxf_splines`]) an AutoCAD 2000
//! (AC1015) file instead, since R12 has no spline entity: the same
//! polylines and points, and each edge also as a cubic `SPLINE` on layer
//! `SPLINES`: the curve of the STEP and IGES outputs
//! (`trim::interpolate_bspline`, with interior knots of multiplicity 2 as
//! in IGES: C¹ in its parameter), through every edge point. Such a file
//! needs the structure of its version: handles and owners on every
//! object, the nine symbol tables with their required records (layer `0`,
//! line types `ByBlock`, `ByLayer` and `Continuous`, text and dimension
//! style `Standard`, application `ACAD`, the `*ACTIVE` viewport, centred
//! on the edges), the model and paper space block records and blocks, and
//! the root dictionary with `ACAD_GROUP`. The header declares the length
//! unit (`$INSUNITS`, from `--units`), which R12 cannot.
//!
//! Written by hand rather than with the `dxf` crate: that crate writes
//! floats with 12 decimals (not the last bit), stamps the file with the
//! time (not the same bytes twice) and brings in an image codec; the
//! subset needed here is a few group codes. ezdxf reads and audits the
//! output in the tests.

use std::io::Write;

use super::step::LengthUnit;
use super::{EdgeData, PicturePlane};
use crate::io::float_text::push_f64;
use crate::io::Point3;

/// Layers, with their AutoCAD colour numbers.
const LAYERS: [(&str, u8); 3] = [("OUTER", 7), ("HOLES", 1), ("CORNERS", 3)];

/// The splines' layer and colour (cyan).
const SPLINE_LAYER: (&str, u8) = ("SPLINES", 4);

/// Writes the edges as DXF (see the module doc).
pub fn write_dxf(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let polylines: Vec<Vec<Point3>> = data.edges.loops.iter().map(closed_polyline).collect();
    let mut file = if data.options.dxf_splines {
        Dxf::r2000(&polylines)
    } else {
        Dxf::r12()
    };
    let outer = outer_loops(&polylines, &PicturePlane::of(data.points));
    for (polyline, is_outer) in polylines.iter().zip(outer) {
        // A loop of fewer than two points (only a caller's own loops can
        // be) has no polyline: CAD systems refuse an empty one.
        if polyline.len() < 2 {
            continue;
        }
        let layer = if is_outer { "OUTER" } else { "HOLES" };
        file.polyline(polyline, layer);
    }
    for l in &data.edges.loops {
        for e in l.edges.iter().filter(|e| !e.closed) {
            if let Some(&corner) = e.points.first() {
                file.point(corner);
            }
        }
    }
    if data.options.dxf_splines {
        for e in data.edges.loops.iter().flat_map(|l| &l.edges) {
            if let Some(curve) = trim::interpolate_bspline(&e.points, e.closed) {
                file.spline(&curve.with_double_knots());
            }
        }
    }
    w.write_all(&file.finish(data.options.units))
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

/// A DXF file being written: for R2000 its tables and blocks, its
/// ENTITIES section, and for R2000 the handles given out so far.
struct Dxf {
    head: Vec<u8>,
    entities: Vec<u8>,
    /// `None` for R12, which has no handles.
    handles: Option<Handles>,
}

/// R2000's handles: hexadecimal numbers, unique in the file, given out in
/// writing order; the model space's block record owns every entity.
struct Handles {
    next: u64,
    model_space: u64,
}

impl Handles {
    fn take(&mut self) -> u64 {
        let h = self.next;
        self.next += 1;
        h
    }
}

impl Dxf {
    fn r12() -> Self {
        Dxf {
            head: Vec::new(),
            entities: Vec::new(),
            handles: None,
        }
    }

    /// An R2000 file, its tables and blocks written: the viewport shows
    /// `polylines`.
    fn r2000(polylines: &[Vec<Point3>]) -> Self {
        let mut head = Vec::new();
        let (next, model_space) = r2000_tables_and_blocks(&mut head, polylines);
        Dxf {
            head,
            entities: Vec::new(),
            handles: Some(Handles { next, model_space }),
        }
    }

    /// Starts an entity of `kind` on `layer`, owned by `owner` (the model
    /// space when `None`), with R2000's subclass markers after the layer;
    /// returns its handle (0 in R12).
    fn entity(&mut self, kind: &str, layer: &str, owner: Option<u64>, classes: &[&str]) -> u64 {
        let out = &mut self.entities;
        group(out, 0, kind);
        let Some(handles) = &mut self.handles else {
            group(out, 8, layer);
            return 0;
        };
        let handle = handles.take();
        group(out, 5, &hex(handle));
        group(out, 330, &hex(owner.unwrap_or(handles.model_space)));
        group(out, 100, "AcDbEntity");
        group(out, 8, layer);
        for class in classes {
            group(out, 100, class);
        }
        handle
    }

    /// One closed 3-D polyline, its vertices and the end of its sequence.
    fn polyline(&mut self, polyline: &[Point3], layer: &str) {
        let owner = Some(self.entity("POLYLINE", layer, None, &["AcDb3dPolyline"]));
        group(&mut self.entities, 66, "1");
        point(&mut self.entities, 10, [0.0; 3]);
        group(&mut self.entities, 70, "9"); // 1 closed + 8 3-D polyline
        for &p in polyline {
            self.entity(
                "VERTEX",
                layer,
                owner,
                &["AcDbVertex", "AcDb3dPolylineVertex"],
            );
            point(&mut self.entities, 10, p);
            group(&mut self.entities, 70, "32"); // a 3-D polyline's vertex
        }
        self.entity("SEQEND", layer, owner, &[]);
    }

    /// A corner as a point on `CORNERS`.
    fn point(&mut self, at: Point3) {
        self.entity("POINT", "CORNERS", None, &["AcDbPoint"]);
        point(&mut self.entities, 10, at);
    }

    /// A B-spline curve on `SPLINES` (R2000 only): degree, the full knot
    /// vector, the control points. A closed loop's curve is clamped, its
    /// first and last control points the same point, and is written
    /// without the closed flag (70 = 0): to some readers that flag means a
    /// periodic curve whose control polygon wraps round, which would be
    /// another curve; the knots and points alone say this one.
    fn spline(&mut self, curve: &trim::BSpline) {
        self.entity("SPLINE", SPLINE_LAYER.0, None, &["AcDbSpline"]);
        let knots = curve.knot_vector();
        let out = &mut self.entities;
        group(out, 70, "0");
        group(out, 71, &curve.degree.to_string());
        group(out, 72, &knots.len().to_string());
        group(out, 73, &curve.control_points.len().to_string());
        group(out, 74, "0"); // no fit points: the control points define it
        group(out, 42, "1e-10");
        group(out, 43, "1e-10");
        for k in knots {
            real(out, 40, k);
        }
        for &p in &curve.control_points {
            point(out, 10, p);
        }
    }

    /// The whole file: header, tables (and for R2000 the classes and
    /// blocks), the entities, and for R2000 the objects.
    fn finish(mut self, units: LengthUnit) -> Vec<u8> {
        let mut out = Vec::new();
        group(
            &mut out,
            999,
            if self.handles.is_some() {
                "meshtrim edges: smoothed boundary loops (OUTER, HOLES), corners (CORNERS), edge curves (SPLINES)"
            } else {
                "meshtrim edges: smoothed boundary loops (OUTER, HOLES), corners (CORNERS)"
            },
        );
        // The objects' handles are the last given out, so the header's
        // seed is known before it is written.
        let dictionaries = self.handles.as_mut().map(|h| [h.take(), h.take()]);
        match &self.handles {
            None => r12_header(&mut out),
            Some(handles) => r2000_header(&mut out, handles.next, units),
        }
        out.extend_from_slice(&self.head);
        section(&mut out, "ENTITIES");
        out.extend_from_slice(&self.entities);
        group(&mut out, 0, "ENDSEC");
        if let Some(dictionaries) = dictionaries {
            r2000_objects(&mut out, dictionaries);
        }
        group(&mut out, 0, "EOF");
        out
    }
}

/// The HEADER (R12) and the TABLES section with the line type and layers.
fn r12_header(out: &mut Vec<u8>) {
    section(out, "HEADER");
    group(out, 9, "$ACADVER");
    group(out, 1, "AC1009");
    group(out, 0, "ENDSEC");
    section(out, "TABLES");
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
}

/// R2000's HEADER and (empty) CLASSES sections; `seed` is the next free
/// handle.
fn r2000_header(out: &mut Vec<u8>, seed: u64, units: LengthUnit) {
    section(out, "HEADER");
    group(out, 9, "$ACADVER");
    group(out, 1, "AC1015");
    group(out, 9, "$HANDSEED");
    group(out, 5, &hex(seed));
    // AutoCAD's unit codes: 1 inches, 4 millimetres, 6 metres; and the
    // drawing's measurement system (0 imperial, 1 metric).
    let (insunits, measurement) = match units {
        LengthUnit::In => ("1", "0"),
        LengthUnit::Mm => ("4", "1"),
        LengthUnit::M => ("6", "1"),
    };
    group(out, 9, "$INSUNITS");
    group(out, 70, insunits);
    group(out, 9, "$MEASUREMENT");
    group(out, 70, measurement);
    group(out, 0, "ENDSEC");
    section(out, "CLASSES");
    group(out, 0, "ENDSEC");
}

/// R2000's TABLES and BLOCKS sections, handles from 1; returns the next
/// free handle and the model space's block record (every entity's owner).
fn r2000_tables_and_blocks(out: &mut Vec<u8>, polylines: &[Vec<Point3>]) -> (u64, u64) {
    section(out, "TABLES");
    let mut tables = Tables {
        out,
        next: 1,
        table: 0,
    };
    tables.vport(polylines);
    tables.ltypes();
    tables.layers();
    tables.styles();
    tables.empty("VIEW");
    tables.empty("UCS");
    tables.appids();
    tables.dimstyles();
    let [model_space, paper_space] = tables.block_records();
    group(tables.out, 0, "ENDSEC");
    section(tables.out, "BLOCKS");
    tables.block("*Model_Space", model_space, false);
    tables.block("*Paper_Space", paper_space, true);
    group(tables.out, 0, "ENDSEC");
    (tables.next, model_space)
}

/// R2000's OBJECTS section: the root dictionary, holding the empty group
/// dictionary (their handles, in that order).
fn r2000_objects(out: &mut Vec<u8>, [root, groups]: [u64; 2]) {
    section(out, "OBJECTS");
    group(out, 0, "DICTIONARY");
    group(out, 5, &hex(root));
    group(out, 330, "0");
    group(out, 100, "AcDbDictionary");
    group(out, 281, "1");
    group(out, 3, "ACAD_GROUP");
    group(out, 350, &hex(groups));
    group(out, 0, "DICTIONARY");
    group(out, 5, &hex(groups));
    group(out, 330, &hex(root));
    group(out, 100, "AcDbDictionary");
    group(out, 281, "1");
    group(out, 0, "ENDSEC");
}

/// R2000's symbol tables being written, handles given out in order from 1.
struct Tables<'a> {
    out: &'a mut Vec<u8>,
    next: u64,
    /// The handle of the table being written (its records' owner).
    table: u64,
}

impl Tables<'_> {
    fn take(&mut self) -> u64 {
        let h = self.next;
        self.next += 1;
        h
    }

    /// A table's head: its name, handle and number of records.
    fn begin(&mut self, name: &str, records: usize) {
        self.table = self.take();
        group(self.out, 0, "TABLE");
        group(self.out, 2, name);
        group(self.out, 5, &hex(self.table));
        group(self.out, 330, "0");
        group(self.out, 100, "AcDbSymbolTable");
        group(self.out, 70, &records.to_string());
    }

    /// A record's head: its kind, handle (under `handle_code`, 105 for a
    /// dimension style), owner, subclass, name and flags; returns the handle.
    fn record(&mut self, kind: &str, handle_code: u16, class: &str, name: &str) -> u64 {
        let handle = self.take();
        group(self.out, 0, kind);
        group(self.out, handle_code, &hex(handle));
        group(self.out, 330, &hex(self.table));
        group(self.out, 100, "AcDbSymbolTableRecord");
        group(self.out, 100, class);
        group(self.out, 2, name);
        group(self.out, 70, "0");
        handle
    }

    fn end(&mut self) {
        group(self.out, 0, "ENDTAB");
    }

    fn empty(&mut self, name: &str) {
        self.begin(name, 0);
        self.end();
    }

    /// The `*ACTIVE` viewport, looking down z at the edges' extent.
    fn vport(&mut self, polylines: &[Vec<Point3>]) {
        let (centre, height) = plan_view(polylines);
        self.begin("VPORT", 1);
        self.record("VPORT", 5, "AcDbViewportTableRecord", "*ACTIVE");
        let out = &mut *self.out;
        let plane = |out: &mut Vec<u8>, code: u16, x: f64, y: f64| {
            real(out, code, x);
            real(out, code + 10, y);
        };
        plane(out, 10, 0.0, 0.0); // the viewport's corners on the screen
        plane(out, 11, 1.0, 1.0);
        plane(out, 12, centre[0], centre[1]);
        plane(out, 13, 0.0, 0.0); // snap base, snap and grid spacing
        plane(out, 14, 1.0, 1.0);
        plane(out, 15, 1.0, 1.0);
        point(out, 16, [0.0, 0.0, 1.0]); // view direction
        point(out, 17, [0.0; 3]); // target
        real(out, 40, height);
        real(out, 41, 1.0); // aspect ratio
        real(out, 42, 50.0); // lens length
        real(out, 43, 0.0);
        real(out, 44, 0.0);
        real(out, 50, 0.0);
        real(out, 51, 0.0);
        for (code, value) in [(71, "0"), (72, "100"), (73, "1"), (74, "3")] {
            group(out, code, value);
        }
        for code in [75, 76, 77, 78] {
            group(out, code, "0");
        }
        self.end();
    }

    fn ltypes(&mut self) {
        let types = [
            ("ByBlock", ""),
            ("ByLayer", ""),
            ("Continuous", "Solid line"),
        ];
        self.begin("LTYPE", types.len());
        for (name, description) in types {
            self.record("LTYPE", 5, "AcDbLinetypeTableRecord", name);
            group(self.out, 3, description);
            group(self.out, 72, "65");
            group(self.out, 73, "0");
            real(self.out, 40, 0.0);
        }
        self.end();
    }

    fn layers(&mut self) {
        let layers = [("0", 7)].into_iter().chain(LAYERS).chain([SPLINE_LAYER]);
        self.begin("LAYER", 2 + LAYERS.len());
        for (name, colour) in layers {
            self.record("LAYER", 5, "AcDbLayerTableRecord", name);
            group(self.out, 62, &colour.to_string());
            group(self.out, 6, "Continuous");
        }
        self.end();
    }

    fn styles(&mut self) {
        self.begin("STYLE", 1);
        self.record("STYLE", 5, "AcDbTextStyleTableRecord", "Standard");
        real(self.out, 40, 0.0); // no fixed height
        real(self.out, 41, 1.0); // width factor
        real(self.out, 50, 0.0); // oblique angle
        group(self.out, 71, "0");
        real(self.out, 42, 2.5); // last height used
        group(self.out, 3, "txt");
        group(self.out, 4, "");
        self.end();
    }

    fn appids(&mut self) {
        self.begin("APPID", 1);
        self.record("APPID", 5, "AcDbRegAppTableRecord", "ACAD");
        self.end();
    }

    fn dimstyles(&mut self) {
        self.begin("DIMSTYLE", 1);
        group(self.out, 100, "AcDbDimStyleTable");
        self.record("DIMSTYLE", 105, "AcDbDimStyleTableRecord", "Standard");
        self.end();
    }

    /// The model and paper space block records; returns their handles.
    fn block_records(&mut self) -> [u64; 2] {
        self.begin("BLOCK_RECORD", 2);
        let handles = ["*Model_Space", "*Paper_Space"]
            .map(|name| self.record("BLOCK_RECORD", 5, "AcDbBlockTableRecord", name));
        self.end();
        handles
    }

    /// An empty block (its entities are in the ENTITIES section) owned by
    /// `record`; `paper` for the paper space's.
    fn block(&mut self, name: &str, record: u64, paper: bool) {
        self.block_part("BLOCK", record, paper, "AcDbBlockBegin");
        group(self.out, 2, name);
        group(self.out, 70, "0");
        point(self.out, 10, [0.0; 3]);
        group(self.out, 3, name);
        group(self.out, 1, "");
        self.block_part("ENDBLK", record, paper, "AcDbBlockEnd");
    }

    /// The head of a block's begin or end (`kind`), on layer 0.
    fn block_part(&mut self, kind: &str, record: u64, paper: bool, class: &str) {
        let handle = self.take();
        group(self.out, 0, kind);
        group(self.out, 5, &hex(handle));
        group(self.out, 330, &hex(record));
        group(self.out, 100, "AcDbEntity");
        if paper {
            group(self.out, 67, "1");
        }
        group(self.out, 8, "0");
        group(self.out, 100, class);
    }
}

/// Centre and height of a view down z that shows every polyline, with a
/// margin; the unit square round the origin when there is nothing.
fn plan_view(polylines: &[Vec<Point3>]) -> ([f64; 2], f64) {
    let mut low = [f64::INFINITY; 2];
    let mut high = [f64::NEG_INFINITY; 2];
    for p in polylines.iter().flatten() {
        for axis in 0..2 {
            low[axis] = low[axis].min(p[axis]);
            high[axis] = high[axis].max(p[axis]);
        }
    }
    if low[0] > high[0] {
        return ([0.0; 2], 1.0);
    }
    let size = (high[0] - low[0]).max(high[1] - low[1]);
    let centre = [0.5 * (low[0] + high[0]), 0.5 * (low[1] + high[1])];
    (centre, if size > 0.0 { 1.1 * size } else { 1.0 })
}

/// A handle as DXF writes it: uppercase hexadecimal.
fn hex(handle: u64) -> String {
    format!("{handle:X}")
}

fn section(out: &mut Vec<u8>, name: &str) {
    group(out, 0, "SECTION");
    group(out, 2, name);
}

/// One group: the code on its line, the value on the next.
fn group(out: &mut Vec<u8>, code: u16, value: &str) {
    out.extend_from_slice(format!("{code:>3}\n{value}\n").as_bytes());
}

/// A real value under `code`, in the shortest decimals that read back.
fn real(out: &mut Vec<u8>, code: u16, value: f64) {
    out.extend_from_slice(format!("{code:>3}\n").as_bytes());
    push_f64(out, value);
    out.push(b'\n');
}

/// A point as the groups `code`, `code + 10`, `code + 20` (x, y, z).
fn point(out: &mut Vec<u8>, code: u16, p: Point3) {
    for (axis, c) in p.into_iter().enumerate() {
        real(out, code + 10 * axis as u16, c);
    }
}
