//! IGES output of the smoothed edges (`meshtrim edges CLOUD -o OUT.igs`),
//! for CAM systems that take IGES rather than STEP.
//!
//! An IGES 5.3 file in fixed 80-column records (Start, Global, Directory
//! Entry, Parameter Data and Terminate sections) holding the same curves
//! as the STEP output ([`super::step`]): one rational B-spline curve
//! (entity 126, form 0, polynomial: all weights 1) per edge, the cubic
//! through the edge's smoothed points that `trim::interpolate_bspline`
//! gives, closed for a loop without corners, written with interior knots
//! of multiplicity 2 (`BSpline::with_double_knots`: the same curve, C¹ in
//! its parameter, which OpenCASCADE's IGES reader keeps as one edge where
//! it splits the triple-knot form at every point); every corner a point
//! (entity 116). The Global section declares the length unit as told (`--units`).
//! Deterministic: the file's date field holds a fixed value, and the file
//! name field names the product, not the path.

use std::fmt::Write as _;
use std::io::Write;

use super::step::{real, LengthUnit};
use super::EdgeData;
use crate::io::Point3;

/// Columns of data in a record (the last eight hold the section letter and
/// the sequence number).
const DATA_COLUMNS: usize = 72;

/// Columns of parameters in a Parameter Data record (then the entity's
/// directory pointer).
const PARAMETER_COLUMNS: usize = 64;

/// Writes the edges as IGES (see the module doc).
pub fn write_iges(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let mut entities = Vec::new();
    let mut largest = 0f64;
    for l in &data.edges.loops {
        for e in &l.edges {
            for p in &e.points {
                largest = p.iter().fold(largest, |m, c| m.max(c.abs()));
            }
            if let Some(curve) = curve(&e.points, e.closed) {
                entities.push(curve);
            }
            if let (false, Some(&corner)) = (e.closed, e.points.first()) {
                entities.push(point(corner));
            }
        }
    }
    w.write_all(file(&entities, data.options.units, largest).as_bytes())
}

/// One entity: its type number, its parameters (without the type) and a
/// label for the directory entry.
struct Entity {
    kind: u32,
    parameters: Vec<String>,
    label: &'static str,
}

/// Entity 126 for the cubic through `points` (back to the first when
/// `closed`).
fn curve(points: &[Point3], closed: bool) -> Option<Entity> {
    let curve = trim::interpolate_bspline(points, closed)?.with_double_knots();
    let last = curve.control_points.len() - 1;
    let mut parameters = vec![
        last.to_string(),
        curve.degree.to_string(),
        "0".into(),                                 // not known to be planar
        if closed { "1" } else { "0" }.to_string(), // closed
        "1".into(),                                 // polynomial
        "0".into(),                                 // not periodic
    ];
    parameters.extend(curve.knot_vector().iter().map(|&k| real(k)));
    parameters.extend(std::iter::repeat_n("1.0".to_string(), last + 1));
    for p in &curve.control_points {
        parameters.extend(p.iter().map(|&c| real(c)));
    }
    let (start, end) = (curve.knots[0], curve.knots[curve.knots.len() - 1]);
    parameters.extend([real(start), real(end)]);
    parameters.extend(["0.0", "0.0", "0.0"].map(String::from));
    Some(Entity {
        kind: 126,
        parameters,
        label: "EDGE",
    })
}

/// Entity 116, a point with no display symbol.
fn point(p: Point3) -> Entity {
    let mut parameters: Vec<String> = p.iter().map(|&c| real(c)).collect();
    parameters.push("0".into());
    Entity {
        kind: 116,
        parameters,
        label: "CORNER",
    }
}

/// The whole file, its sections in order.
fn file(entities: &[Entity], units: LengthUnit, largest: f64) -> String {
    let start = records(
        &["meshtrim edges: smoothed boundary curves".to_string()],
        'S',
    );
    let global = records(&wrap(&global_parameters(units, largest), DATA_COLUMNS), 'G');
    let mut directory = Vec::new();
    let mut parameter_lines = Vec::new();
    for (i, entity) in entities.iter().enumerate() {
        let directory_line = 2 * i + 1;
        let mut tokens = vec![entity.kind.to_string()];
        tokens.extend(entity.parameters.iter().cloned());
        let lines = wrap(&tokens, PARAMETER_COLUMNS);
        let first_line = parameter_lines.len() + 1;
        for line in &lines {
            parameter_lines.push(format!("{line:<PARAMETER_COLUMNS$} {directory_line:>7}"));
        }
        directory.extend(directory_entry(entity, first_line, lines.len()));
    }
    let directory = records(&directory, 'D');
    let parameters = records(&parameter_lines, 'P');
    let count = |section: &str| section.lines().count();
    let terminate = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        count(&start),
        count(&global),
        count(&directory),
        count(&parameters)
    );
    [
        start,
        global,
        directory,
        parameters,
        records(&[terminate], 'T'),
    ]
    .concat()
}

/// The Global section's parameters (IGES 5.3, section 2.2.4).
fn global_parameters(units: LengthUnit, largest: f64) -> Vec<String> {
    let (flag, name) = match units {
        LengthUnit::Mm => (2, "MM"),
        LengthUnit::M => (6, "M"),
        LengthUnit::In => (1, "INCH"),
    };
    [
        hollerith(","),
        hollerith(";"),
        hollerith("meshtrim edges"), // sender's product
        hollerith("meshtrim edges"), // file name
        hollerith("meshtrim"),       // native system
        hollerith(env!("CARGO_PKG_VERSION")),
        "32".into(),                 // bits of an integer
        "38".into(),                 // single precision: largest power of ten,
        "6".into(),                  // and significant digits
        "308".into(),                // double precision: largest power of ten,
        "15".into(),                 // and significant digits
        hollerith("meshtrim edges"), // receiver's product
        "1.0".into(),                // model space scale
        flag.to_string(),
        hollerith(name),
        "1".into(),                   // line weight gradations
        "1.0".into(),                 // widest line
        hollerith("19700101.000000"), // fixed: same edges, same bytes
        "1.0E-7".into(),              // smallest distance that matters
        real(largest),
        String::new(), // author
        String::new(), // organisation
        "11".into(),   // IGES 5.3
        "0".into(),    // no drafting standard
    ]
    .into()
}

/// A Hollerith string: `nH` then the n characters.
fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// Tokens joined by commas and ended by a semicolon, broken into lines of
/// at most `width` columns between tokens (a token never spans two lines).
fn wrap(tokens: &[String], width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut line = String::new();
    for (i, token) in tokens.iter().enumerate() {
        let delimiter = if i + 1 == tokens.len() { ';' } else { ',' };
        let piece = format!("{token}{delimiter}");
        if !line.is_empty() && line.len() + piece.len() > width {
            lines.push(std::mem::take(&mut line));
        }
        line.push_str(&piece);
    }
    lines.push(line);
    lines
}

/// The two Directory Entry lines of an entity whose parameters start on
/// Parameter Data line `first_line` and take `line_count` lines.
fn directory_entry(entity: &Entity, first_line: usize, line_count: usize) -> [String; 2] {
    let field = |v: &dyn std::fmt::Display| format!("{v:>8}");
    let mut first = String::new();
    for v in [
        &entity.kind as &dyn std::fmt::Display,
        &first_line,
        &0, // structure
        &0, // line font
        &0, // level
        &0, // view
        &0, // transformation matrix
        &0, // label display
    ] {
        first.push_str(&field(v));
    }
    first.push_str("00000000"); // status: visible, independent, geometry
    let mut second = String::new();
    for v in [
        &entity.kind as &dyn std::fmt::Display,
        &0, // line weight
        &0, // colour
        &line_count,
        &0, // form
        &"",
        &"",
        &entity.label,
        &0, // subscript
    ] {
        second.push_str(&field(v));
    }
    [first, second]
}

/// Lines as records of section `letter`: data padded to 72 columns, the
/// letter, the sequence number in 7 columns.
fn records(lines: &[String], letter: char) -> String {
    let mut out = String::new();
    for (i, line) in lines.iter().enumerate() {
        let _ = writeln!(out, "{line:<DATA_COLUMNS$}{letter}{:>7}", i + 1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn records_are_80_columns_and_tokens_stay_whole() {
        let tokens: Vec<String> = (0..40).map(|i| real(f64::from(i) / 7.0)).collect();
        let lines = wrap(&tokens, PARAMETER_COLUMNS);
        assert!(lines.iter().all(|l| l.len() <= PARAMETER_COLUMNS));
        let joined: String = lines.concat();
        assert_eq!(joined.trim_end_matches(';').split(',').count(), 40);
        assert!(joined.ends_with(';') && joined.matches(';').count() == 1);
        let text = records(&lines, 'P');
        assert!(text
            .lines()
            .all(|l| l.len() == 80 && l.as_bytes()[72] == b'P'));
    }

    #[test]
    fn a_curve_entity_counts_its_knots_weights_and_points() {
        let points = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.5]];
        let entity = curve(&points, false).unwrap();
        let (last, degree) = (5, 3); // 2·3 control points (double knots)
        assert_eq!(entity.parameters[0], last.to_string());
        let knots = last + degree + 2;
        let expected = 6 + knots + (last + 1) + 3 * (last + 1) + 2 + 3;
        assert_eq!(entity.parameters.len(), expected);
        assert_eq!(hollerith("MM"), "2HMM");
    }
}
