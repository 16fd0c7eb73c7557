//! Output of `meshtrim detect`: the input points with their labels.
//!
//! Both formats keep the points in input order and are deterministic byte
//! for byte: no timestamps, and floats written exactly (binary doubles, or
//! Rust's shortest round-trip decimal form in CSV).

use std::io::Write;

use byteorder::{LittleEndian, WriteBytesExt};

use super::float_text::push_f64;
use super::{GridIndex, Point3};

/// Points with their boundary labels and local resolution β.
#[derive(Debug, Clone, Copy)]
pub struct Labelled<'a> {
    /// The points, in input order.
    pub points: &'a [Point3],
    /// True for boundary points.
    pub boundary: &'a [bool],
    /// Local resolution of each point.
    pub beta: &'a [f64],
    /// The input's LAS grid, when it was LAS or LAZ (for LAS output).
    pub scale_offset: Option<super::las::ScaleOffset>,
    /// Each point's scan, row and column, when the input had them (E57):
    /// written by the CSV and PLY outputs.
    pub grid: Option<&'a [GridIndex]>,
    /// The LAS or LAZ file the points were read from, whose point records
    /// a LAS or LAZ output writes again with the labels added.
    pub las_source: Option<&'a std::path::Path>,
}

impl Labelled<'_> {
    /// The grid indices when there is one per point; a grid of another
    /// length is not written (the columns would not line up).
    fn full_grid(&self) -> Option<&[GridIndex]> {
        self.grid.filter(|grid| grid.len() == self.points.len())
    }
}

/// Output formats of `detect`, chosen by the output's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LabelFormat {
    /// Binary little-endian PLY.
    Ply,
    /// CSV with a header line.
    Csv,
    /// LAS 1.4 with `boundary` and `beta` extra-bytes dimensions.
    Las,
    /// LAZ: the same, compressed.
    Laz,
}

impl LabelFormat {
    /// The format an output path asks for, if supported.
    pub fn from_path(path: &std::path::Path) -> Option<Self> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        match ext.as_str() {
            "ply" => Some(LabelFormat::Ply),
            "csv" => Some(LabelFormat::Csv),
            "las" => Some(LabelFormat::Las),
            "laz" => Some(LabelFormat::Laz),
            _ => None,
        }
    }

    /// Writes `data` in this format.
    pub fn write(self, w: &mut dyn Write, data: Labelled) -> std::io::Result<()> {
        match self {
            LabelFormat::Ply => write_ply(w, data),
            LabelFormat::Csv => write_csv(w, data),
            LabelFormat::Las | LabelFormat::Laz if data.las_source.is_some() => {
                let source = data.las_source.map(std::fs::read).transpose()?;
                super::las::write_labels_las_over(
                    w,
                    source.unwrap_or_default(),
                    data.boundary,
                    data.beta,
                    self == LabelFormat::Laz,
                )
            }
            LabelFormat::Las | LabelFormat::Laz => {
                let frame = data
                    .scale_offset
                    .unwrap_or_else(|| super::las::grid_for(data.points));
                let compressed = self == LabelFormat::Laz;
                super::las::write_labels_las(
                    w,
                    data.points,
                    data.boundary,
                    data.beta,
                    frame,
                    compressed,
                )
            }
        }
    }
}

/// Binary little-endian PLY: double x, y, z, uchar boundary (1 = boundary),
/// double beta, and with a grid uint scan, int row, int column.
pub fn write_ply(w: &mut dyn Write, data: Labelled) -> std::io::Result<()> {
    writeln!(w, "ply\nformat binary_little_endian 1.0")?;
    writeln!(
        w,
        "comment meshtrim detect: boundary 1 = boundary point, beta = local resolution"
    )?;
    writeln!(w, "element vertex {}", data.points.len())?;
    writeln!(w, "property double x\nproperty double y\nproperty double z")?;
    writeln!(w, "property uchar boundary\nproperty double beta")?;
    let grid = data.full_grid();
    if grid.is_some() {
        writeln!(
            w,
            "property uint scan\nproperty int row\nproperty int column"
        )?;
    }
    writeln!(w, "end_header")?;
    for (i, ((p, &b), &beta)) in data
        .points
        .iter()
        .zip(data.boundary)
        .zip(data.beta)
        .enumerate()
    {
        for &c in p {
            w.write_f64::<LittleEndian>(c)?;
        }
        w.write_u8(u8::from(b))?;
        w.write_f64::<LittleEndian>(beta)?;
        if let Some(g) = grid.map(|grid| grid[i]) {
            w.write_u32::<LittleEndian>(g.scan)?;
            w.write_i32::<LittleEndian>(g.row)?;
            w.write_i32::<LittleEndian>(g.column)?;
        }
    }
    Ok(())
}

/// CSV with header `x,y,z,boundary,beta` (and `scan,row,column` with a
/// grid), floats in shortest round-trip form (lines formatted in parallel
/// pieces, written in order).
pub fn write_csv(w: &mut dyn Write, data: Labelled) -> std::io::Result<()> {
    let grid = data.full_grid();
    let grid_columns = if grid.is_some() {
        ",scan,row,column"
    } else {
        ""
    };
    writeln!(w, "x,y,z,boundary,beta{grid_columns}")?;
    let n = data
        .points
        .len()
        .min(data.boundary.len())
        .min(data.beta.len());
    super::write_formatted(w, n, |out, i| {
        for c in data.points[i] {
            push_f64(out, c);
            out.push(b',');
        }
        out.extend_from_slice(if data.boundary[i] { b"1," } else { b"0," });
        push_f64(out, data.beta[i]);
        if let Some(g) = grid.map(|grid| grid[i]) {
            // Writing to a Vec cannot fail.
            let _ = write!(out, ",{},{},{}", g.scan, g.row, g.column);
        }
        out.push(b'\n');
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::{ply, text};

    fn sample() -> (Vec<Point3>, Vec<bool>, Vec<f64>) {
        (
            vec![[0.1, 2.0, -3e-9], [1.0 / 3.0, 0.0, 5.0]],
            vec![true, false],
            vec![0.25, 1e-7],
        )
    }

    #[test]
    fn ply_reads_back() {
        let (points, boundary, beta) = sample();
        let mut out = Vec::new();
        let data = Labelled {
            points: &points,
            boundary: &boundary,
            beta: &beta,
            scale_offset: None,
            grid: None,
            las_source: None,
        };
        write_ply(&mut out, data).unwrap();
        assert_eq!(ply::read_ply(&out).unwrap().vertices, points);
        assert_eq!(
            out.len() - (out.windows(11).position(|w| w == b"end_header\n").unwrap() + 11),
            2 * 33
        );
    }

    #[test]
    fn csv_is_exact() {
        let (points, boundary, beta) = sample();
        let mut out = Vec::new();
        let data = Labelled {
            points: &points,
            boundary: &boundary,
            beta: &beta,
            scale_offset: None,
            grid: None,
            las_source: None,
        };
        write_csv(&mut out, data).unwrap();
        let s = String::from_utf8(out.clone()).unwrap();
        assert!(
            s.starts_with("x,y,z,boundary,beta\n0.1,2,-0.000000003,1,0.25\n"),
            "{s}"
        );
        assert_eq!(text::read_text(&out).unwrap().vertices, points);
    }

    #[test]
    fn grid_indices_follow_the_labels() {
        let (points, boundary, beta) = sample();
        let grid = [
            GridIndex {
                scan: 0,
                row: 7,
                column: 3,
            },
            GridIndex {
                scan: 1,
                row: -1,
                column: -1,
            },
        ];
        let data = Labelled {
            points: &points,
            boundary: &boundary,
            beta: &beta,
            scale_offset: None,
            grid: Some(&grid),
            las_source: None,
        };
        let mut csv = Vec::new();
        write_csv(&mut csv, data).unwrap();
        let csv = String::from_utf8(csv).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines[0], "x,y,z,boundary,beta,scan,row,column");
        assert!(lines[1].ends_with(",1,0.25,0,7,3"), "{csv}");
        assert!(lines[2].ends_with(",0.0000001,1,-1,-1"), "{csv}");
        let mut ply = Vec::new();
        write_ply(&mut ply, data).unwrap();
        assert_eq!(ply::read_ply(&ply).unwrap().vertices, points);
        let body = ply.len() - (ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11);
        assert_eq!(body, 2 * (33 + 12));
        assert_eq!(
            &ply[ply.len() - 12..],
            [1, 0, 0, 0, 255, 255, 255, 255, 255, 255, 255, 255]
        );
    }
}
