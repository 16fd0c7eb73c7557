//! STEP output of the smoothed edges (`meshtrim edges CLOUD -o OUT.step`):
//! true curves for CAD, not facets.
//!
//! An ISO 10303-21 file, AP214 (`AUTOMOTIVE_DESIGN`): one product whose
//! shape is a `GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION` over a
//! `GEOMETRIC_CURVE_SET` holding
//!
//! - one cubic `B_SPLINE_CURVE_WITH_KNOTS` per edge: the C¹ Catmull–Rom
//!   cubic through the edge's smoothed points (`trim::interpolate_bspline`),
//!   every point a control point the curve passes through exactly (far
//!   inside the 0.01 β asked of the fit); an open edge's curve starts and
//!   ends exactly at its corners, and a loop without corners is one curve
//!   through its points and back to the first, marked closed;
//! - every corner as a `CARTESIAN_POINT` named `corner`.
//!
//! A cloud file does not say its unit, so the length unit is declared as
//! told (`--units mm`, the default, `m` or `in`). Written by hand: no crate
//! writes B-spline curves to STEP without a geometry kernel (truck's STEP
//! output wants a topological shape; `curvo` fits curves but writes no
//! STEP), and the file is a few dozen entity types. OpenCASCADE (through
//! gmsh) reads it back in the tests. Deterministic: no time stamp.

use std::fmt::Write as _;
use std::io::Write;

use super::EdgeData;
use crate::io::Point3;

/// The length unit a STEP file declares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum LengthUnit {
    /// Millimetres.
    #[default]
    Mm,
    /// Metres.
    M,
    /// Inches.
    In,
}

impl LengthUnit {
    /// The unit `--units` names (`mm`, `m`, `in`), for callers without
    /// the command line's parser.
    pub fn from_name(name: &str) -> Option<Self> {
        <Self as clap::ValueEnum>::from_str(name, false).ok()
    }
}

/// Writes the edges as STEP (see the module doc).
pub fn write_step(w: &mut dyn Write, data: EdgeData) -> std::io::Result<()> {
    let mut file = StepFile::default();
    let context = file.context(data.options.units);
    let mut items = Vec::new();
    for l in &data.edges.loops {
        for e in &l.edges {
            if let Some(curve) = file.curve(&e.points, e.closed) {
                items.push(curve);
            }
            if !e.closed {
                if let Some(&corner) = e.points.first() {
                    items.push(file.point("corner", corner));
                }
            }
        }
    }
    let set = file.add(format!(
        "GEOMETRIC_CURVE_SET('smoothed edges',({}))",
        refs(&items)
    ));
    file.product(set, context);
    w.write_all(file.finish().as_bytes())
}

/// The DATA section being built: entities numbered from 1.
#[derive(Default)]
struct StepFile {
    entities: Vec<String>,
}

impl StepFile {
    /// Adds an entity; its reference number.
    fn add(&mut self, entity: String) -> usize {
        self.entities.push(entity);
        self.entities.len()
    }

    fn point(&mut self, name: &str, p: Point3) -> usize {
        self.add(format!(
            "CARTESIAN_POINT('{name}',({},{},{}))",
            real(p[0]),
            real(p[1]),
            real(p[2])
        ))
    }

    /// The cubic through `points` (closed: back to the first point too).
    fn curve(&mut self, points: &[Point3], closed: bool) -> Option<usize> {
        let curve = trim::interpolate_bspline(points, closed)?;
        let controls: Vec<usize> = curve
            .control_points
            .iter()
            .map(|&p| self.point("", p))
            .collect();
        let multiplicities: Vec<String> =
            curve.multiplicities.iter().map(|m| m.to_string()).collect();
        let knots: Vec<String> = curve.knots.iter().map(|&k| real(k)).collect();
        let flag = if closed { ".T." } else { ".F." };
        Some(self.add(format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},({}),.UNSPECIFIED.,{flag},.F.,({}),({}),.UNSPECIFIED.)",
            curve.degree,
            refs(&controls),
            multiplicities.join(","),
            knots.join(",")
        )))
    }

    /// The geometric context with its units; its reference.
    fn context(&mut self, units: LengthUnit) -> usize {
        let length = match units {
            LengthUnit::Mm => {
                self.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into())
            }
            LengthUnit::M => self.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT($,.METRE.))".into()),
            LengthUnit::In => {
                let mm = self.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))".into());
                let measure = self.add(format!(
                    "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#{mm})"
                ));
                let exponents = self.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)".into());
                self.add(format!(
                    "(CONVERSION_BASED_UNIT('INCH',#{measure})LENGTH_UNIT()NAMED_UNIT(#{exponents}))"
                ))
            }
        };
        let angle = self.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))".into());
        let solid = self.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())".into());
        let uncertainty = self.add(format!(
            "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE(1.E-07),#{length},'distance_accuracy_value','')"
        ));
        self.add(format!(
            "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{uncertainty}))\
             GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{solid}))REPRESENTATION_CONTEXT('',''))"
        ))
    }

    /// The product whose shape is the curve set: what CAD systems import.
    fn product(&mut self, set: usize, context: usize) {
        let application = self.add("APPLICATION_CONTEXT('automotive design')".into());
        self.add(format!(
            "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{application})"
        ));
        let product_context = self.add(format!("PRODUCT_CONTEXT('',#{application},'mechanical')"));
        let product = self.add(format!(
            "PRODUCT('meshtrim_edges','smoothed boundary edges','',(#{product_context}))"
        ));
        let formation = self.add(format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"));
        let definition_context = self.add(format!(
            "PRODUCT_DEFINITION_CONTEXT('part definition',#{application},'design')"
        ));
        let definition = self.add(format!(
            "PRODUCT_DEFINITION('design','',#{formation},#{definition_context})"
        ));
        let shape = self.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{definition})"));
        let representation = self.add(format!(
            "GEOMETRICALLY_BOUNDED_WIREFRAME_SHAPE_REPRESENTATION('smoothed edges',(#{set}),#{context})"
        ));
        self.add(format!(
            "SHAPE_DEFINITION_REPRESENTATION(#{shape},#{representation})"
        ));
    }

    fn finish(self) -> String {
        let mut out = String::from(
            "ISO-10303-21;\nHEADER;\n\
             FILE_DESCRIPTION(('meshtrim edges: smoothed boundary curves'),'2;1');\n\
             FILE_NAME('','',(''),(''),'meshtrim','meshtrim','');\n\
             FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n",
        );
        for (i, entity) in self.entities.iter().enumerate() {
            let _ = writeln!(out, "#{}={entity};", i + 1);
        }
        out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
        out
    }
}

/// `#a,#b,…`
fn refs(ids: &[usize]) -> String {
    ids.iter()
        .map(|i| format!("#{i}"))
        .collect::<Vec<_>>()
        .join(",")
}

/// A STEP REAL in the shortest digits that read back as `v`: always with
/// a decimal point, the exponent as `E` (`1.5`, `-2.`, `1.E-07` style).
pub(super) fn real(v: f64) -> String {
    let text = format!("{v:?}");
    let (mantissa, exponent) = match text.split_once('e') {
        Some((m, e)) => (m.to_string(), Some(e.to_string())),
        None => (text, None),
    };
    let mantissa = if mantissa.contains('.') {
        mantissa
    } else {
        format!("{mantissa}.")
    };
    match exponent {
        Some(e) => format!("{mantissa}E{e}"),
        None => mantissa,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_have_a_point_and_read_back() {
        for v in [
            0.0,
            -0.0,
            1.0,
            -2.5,
            1e-7,
            1.5e16,
            123456.789,
            f64::MIN_POSITIVE,
            0.1 + 0.2,
        ] {
            let text = real(v);
            assert!(text.contains('.'), "{text}");
            assert!(!text.contains('e'), "{text}");
            assert_eq!(text.replace('E', "e").parse::<f64>().unwrap(), v, "{text}");
        }
        assert_eq!(real(1e-7), "1.E-7");
        assert_eq!(real(2.0), "2.0");
    }
}
