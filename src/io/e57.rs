//! ASTM E57 point clouds (the `e57` crate, pure Rust), as terrestrial and
//! arm-mounted laser scanners export them (FARO, Leica, Trimble,
//! CloudCompare).
//!
//! Every `data3D` scan is read in file order, each scan's points in file
//! order, its pose (a quaternion, normalised, and a translation) applied
//! in f64, so the merged cloud is in the file's common frame; or one scan alone
//! (`--scan N`, the 0-based `data3D` index). Cartesian and spherical
//! coordinates (range, azimuth, elevation, converted) are read, scaled
//! integers and floats alike. A point whose `cartesianInvalidState` (or
//! `sphericalInvalidState`) is not 0 has no position (at most a direction)
//! and is dropped and counted, as PCD's NaN points are. Every page's CRC is
//! checked. Row and column indices (`rowIndex`, `columnIndex`) are kept with
//! each point's scan, when a scan read has them, for `detect`'s CSV and PLY
//! outputs. Colours (`colorRed`, `colorGreen`, `colorBlue`, scaled to
//! 0..1 by the scan's colour limits) are kept when every scan read has
//! them, so that `mesh` carries them to its vertices; a point whose
//! colour is marked invalid is black. Intensity is kept likewise, as the
//! file's own value `intensity` (`f32`, as stored: not scaled by the
//! scans' limits, which may differ), NaN where it is marked invalid.

use std::io::Cursor;

use anyhow::{anyhow, bail, Context, Result};
use e57::{CartesianCoordinate, E57Reader, RecordName};
use rayon::prelude::*;

use super::ply::Scalar;
use super::{unit_channel, Cloud, Colours, Format, GridIndex, Point3, ScalarField};

/// The file signature at the start of every E57 file.
const SIGNATURE: &[u8] = b"ASTM-E57";

/// True when `bytes` start with the E57 signature.
pub fn is_e57(bytes: &[u8]) -> bool {
    bytes.starts_with(SIGNATURE)
}

/// Reads the scans of an E57 file, all merged or the one numbered `scan`
/// (see the module doc). Scans are read in parallel, each by its own
/// reader over the same bytes, and joined in file order.
pub fn read_e57(bytes: Vec<u8>, scan: Option<usize>) -> Result<Cloud> {
    let reader = open(&bytes)?;
    let scans = reader.pointclouds();
    if scans.is_empty() {
        bail!("no scans: the file's data3D list is empty");
    }
    let chosen: Vec<usize> = match scan {
        Some(n) if n >= scans.len() => bail!(
            "there is no scan {n}: the file has {} scan(s), numbered from 0 to {}",
            scans.len(),
            scans.len() - 1
        ),
        Some(n) => vec![n],
        None => (0..scans.len()).collect(),
    };
    let records: u64 = chosen.iter().map(|&n| scans[n].records).sum();
    if records > u64::from(u32::MAX) {
        bail!(
            "the scans hold {records} points; meshtrim reads at most {}",
            u32::MAX
        );
    }
    let with_grid = chosen.iter().any(|&n| has_grid(&scans[n]));
    let with_colour = chosen.iter().all(|&n| scans[n].has_color());
    let with_intensity = chosen.iter().all(|&n| scans[n].has_intensity());
    let read: Vec<Result<Scan>> = chosen
        .par_iter()
        .map(|&n| {
            let wanted = Wanted {
                grid_of: with_grid.then_some(n),
                colour: with_colour,
                intensity: with_intensity,
            };
            read_scan(&bytes, &scans[n], wanted).with_context(|| format!("scan {n}"))
        })
        .collect();
    let mut points: Vec<Point3> = Vec::with_capacity(reservation(records, bytes.len()));
    let mut grid: Vec<GridIndex> = Vec::new();
    let mut rgba: Vec<[f64; 4]> = Vec::new();
    let mut intensity: Vec<f64> = Vec::new();
    let mut dropped = 0;
    for scan in read {
        let scan = scan?;
        points.extend_from_slice(&scan.points);
        grid.extend_from_slice(&scan.grid);
        rgba.extend_from_slice(&scan.colours);
        intensity.extend_from_slice(&scan.intensity);
        dropped += scan.dropped;
    }
    let intensity = with_intensity.then(|| ScalarField {
        name: "intensity".to_string(),
        kind: Scalar::F32,
        values: intensity,
    });
    Ok(Cloud {
        points,
        normals: None,
        scalars: intensity.into_iter().collect(),
        dropped_non_finite: dropped,
        format: Format::E57,
        scale_offset: None,
        colours: with_colour.then_some(Colours { rgba, alpha: false }),
        grid: with_grid.then_some(grid),
    })
}

fn open(bytes: &[u8]) -> Result<E57Reader<Cursor<&[u8]>>> {
    E57Reader::new(Cursor::new(bytes)).map_err(|e| anyhow!("{e}"))
}

/// Points to reserve room for: as many as the file announces, but no more
/// than it has bytes (a corrupt count must not make the reader allocate
/// what the machine does not have; a real file this dense grows the
/// vector as it is read).
fn reservation(records: u64, file_bytes: usize) -> usize {
    records.min(file_bytes as u64) as usize
}

/// True when the scan's records hold row or column indices.
fn has_grid(scan: &e57::PointCloud) -> bool {
    scan.prototype
        .iter()
        .any(|r| matches!(r.name, RecordName::RowIndex | RecordName::ColumnIndex))
}

/// One scan's valid points, posed, their grid indices and colours (when
/// asked for), and how many had no position.
struct Scan {
    points: Vec<Point3>,
    grid: Vec<GridIndex>,
    colours: Vec<[f64; 4]>,
    intensity: Vec<f64>,
    dropped: usize,
}

/// What a scan's reading keeps besides positions.
#[derive(Clone, Copy)]
struct Wanted {
    /// The scan's `data3D` index, to keep each point's row and column
    /// (−1 where the scan has none).
    grid_of: Option<usize>,
    /// Whether to keep each point's colour.
    colour: bool,
    /// Whether to keep each point's intensity.
    intensity: bool,
}

/// Reads one scan, keeping what `wanted` asks for besides positions.
fn read_scan(bytes: &[u8], scan: &e57::PointCloud, wanted: Wanted) -> Result<Scan> {
    let pose = Pose::of(scan)?;
    let mut reader = open(bytes)?;
    let mut iter = reader.pointcloud_simple(scan).map_err(|e| anyhow!("{e}"))?;
    // The pose is applied here, with the quaternion normalised.
    iter.apply_pose(false);
    iter.spherical_to_cartesian(true);
    iter.normalize_intensity(false);
    // Colours in 0..1 by the scan's colour limits.
    iter.normalize_color(true);
    let mut points = Vec::with_capacity(reservation(scan.records, bytes.len()));
    let mut grid = Vec::new();
    let mut colours = Vec::new();
    let mut intensity = Vec::new();
    let mut dropped = 0;
    for (index, point) in iter.enumerate() {
        let point = point.map_err(|e| anyhow!("point {index}: {e}"))?;
        match point.cartesian {
            CartesianCoordinate::Valid { x, y, z } => {
                if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                    bail!("point {index} has a non-finite coordinate ({x}, {y}, {z})");
                }
                points.push(pose.apply([x, y, z]));
                if let Some(n) = wanted.grid_of {
                    grid.push(grid_index(n, point.row, point.column, index)?);
                }
                if wanted.colour {
                    colours.push(colour_of(point.color.as_ref()));
                }
                if wanted.intensity {
                    intensity.push(point.intensity.map_or(f64::NAN, f64::from));
                }
            }
            CartesianCoordinate::Direction { .. } | CartesianCoordinate::Invalid => dropped += 1,
        }
    }
    Ok(Scan {
        points,
        grid,
        colours,
        intensity,
        dropped,
    })
}

/// A point's colour in 0..1 (clamped: limits a file understates leave
/// values beyond them), black where the point's colour is invalid.
fn colour_of(colour: Option<&e57::Color>) -> [f64; 4] {
    let channel = |c: f32| unit_channel(f64::from(c));
    match colour {
        Some(c) => [channel(c.red), channel(c.green), channel(c.blue), 1.0],
        None => [0.0, 0.0, 0.0, 1.0],
    }
}

/// A point's [`GridIndex`]; the e57 crate gives −1 for a missing index.
/// Indices beyond 32 bits (no scanner's image is that large) are refused.
fn grid_index(scan: usize, row: i64, column: i64, index: usize) -> Result<GridIndex> {
    let small = |value: i64, what: &str| {
        i32::try_from(value)
            .map_err(|_| anyhow!("point {index}: {what} index {value} is beyond 32 bits"))
    };
    Ok(GridIndex {
        scan: u32::try_from(scan).map_err(|_| anyhow!("scan {scan}: too many scans"))?,
        row: small(row, "row")?,
        column: small(column, "column")?,
    })
}

/// A scan's pose as a rotation matrix (rows) and a translation.
struct Pose {
    rotation: [[f64; 3]; 3],
    translation: Point3,
}

impl Pose {
    /// The scan's pose; the identity when it has none. The quaternion is
    /// normalised first: files store it rounded (seven digits are common),
    /// and an unnormalised one would scale the scan by its squared norm.
    fn of(scan: &e57::PointCloud) -> Result<Pose> {
        let Some(t) = &scan.transform else {
            return Ok(Pose {
                rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
                translation: [0.0; 3],
            });
        };
        let q = &t.rotation;
        let norm = (q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z).sqrt();
        let translation = [t.translation.x, t.translation.y, t.translation.z];
        if !(norm.is_finite() && norm > 0.0 && translation.iter().all(|c| c.is_finite())) {
            bail!(
                "the pose is not usable: rotation ({}, {}, {}, {}) is no quaternion or the translation is not finite",
                q.w,
                q.x,
                q.y,
                q.z
            );
        }
        let unit = [q.w, q.x, q.y, q.z].map(|c| c / norm);
        Ok(Pose {
            rotation: trim::rotation_from_quaternion(unit),
            translation,
        })
    }

    fn apply(&self, p: Point3) -> Point3 {
        let row = |r: [f64; 3], t: f64| r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + t;
        [
            row(self.rotation[0], self.translation[0]),
            row(self.rotation[1], self.translation[1]),
            row(self.rotation[2], self.translation[2]),
        ]
    }
}
