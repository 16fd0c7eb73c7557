//! ASTM E57 point clouds (the `e57` crate, pure Rust), as terrestrial and
//! arm-mounted laser scanners export them (FARO, Leica, Trimble,
//! CloudCompare).
//!
//! Every `data3D` scan is read in file order, each scan's points in file
//! order, its pose (a unit quaternion and a translation) applied in f64,
//! so the merged cloud is in the file's common frame; or one scan alone
//! (`--scan N`, the 0-based `data3D` index). Cartesian and spherical
//! coordinates (range, azimuth, elevation, converted) are read, scaled
//! integers and floats alike. A point whose `cartesianInvalidState` (or
//! `sphericalInvalidState`) is not 0 has no position (at most a direction)
//! and is dropped and counted, as PCD's NaN points are. Every page's CRC is
//! checked. Row and column indices, intensity and colour are not kept.

use std::io::Cursor;

use anyhow::{anyhow, bail, Context, Result};
use e57::{CartesianCoordinate, E57Reader};

use super::{Cloud, Format, Point3};

/// The file signature at the start of every E57 file.
const SIGNATURE: &[u8] = b"ASTM-E57";

/// True when `bytes` start with the E57 signature.
pub fn is_e57(bytes: &[u8]) -> bool {
    bytes.starts_with(SIGNATURE)
}

/// Reads the scans of an E57 file, all merged or the one numbered `scan`
/// (see the module doc).
pub fn read_e57(bytes: Vec<u8>, scan: Option<usize>) -> Result<Cloud> {
    let mut reader = E57Reader::new(Cursor::new(bytes)).map_err(|e| anyhow!("{e}"))?;
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
    let mut points: Vec<Point3> = Vec::with_capacity(records as usize);
    let mut dropped = 0;
    for n in chosen {
        dropped +=
            read_scan(&mut reader, &scans[n], &mut points).with_context(|| format!("scan {n}"))?;
    }
    Ok(Cloud {
        points,
        normals: None,
        dropped_non_finite: dropped,
        format: Format::E57,
        scale_offset: None,
    })
}

/// Appends one scan's valid points, posed, to `points`; returns how many
/// points had no position.
fn read_scan(
    reader: &mut E57Reader<Cursor<Vec<u8>>>,
    scan: &e57::PointCloud,
    points: &mut Vec<Point3>,
) -> Result<usize> {
    let mut iter = reader.pointcloud_simple(scan).map_err(|e| anyhow!("{e}"))?;
    iter.apply_pose(true);
    iter.spherical_to_cartesian(true);
    let mut dropped = 0;
    for (index, point) in iter.enumerate() {
        let point = point.map_err(|e| anyhow!("point {index}: {e}"))?;
        match point.cartesian {
            CartesianCoordinate::Valid { x, y, z } => {
                if !(x.is_finite() && y.is_finite() && z.is_finite()) {
                    bail!("point {index} has a non-finite coordinate ({x}, {y}, {z})");
                }
                points.push([x, y, z]);
            }
            CartesianCoordinate::Direction { .. } | CartesianCoordinate::Invalid => dropped += 1,
        }
    }
    Ok(dropped)
}
