//! LAS 1.0–1.4 and LAZ point clouds (the `las` crate; LAZ through its `laz`
//! feature), in and out.
//!
//! **Reading.** Every point format (0–10) is read; x, y, z are kept, and
//! the colour of the formats that have one (2, 3, 5, 7, 8, 10), so that
//! `mesh` carries it to its vertices (unless every point is black: a
//! writer that fills in no colour leaves zeros). The standard stores colour channels
//! as 16 bits, but many writers put 8-bit values there: a file whose
//! channels are all at most 255 is read as 0–255, any other as 0–65535
//! (the rule CloudCompare's reader offers). Intensity and classification,
//! fields of every point format, are kept as the file's own values
//! (`intensity` u16, `classification` u8, the low five bits in the legacy
//! formats 0–5) when some point has a value other than 0.
//! LAZ chunks are decompressed in parallel, which needs the chunk table (a
//! file whose table is lost is refused, as laspy refuses it). LAZ has no
//! checksums: damage inside a chunk decodes into wrong points, which no
//! reader can tell; a truncated file or a broken table is an error.
//! A coordinate is `integer × scale + offset` in f64, computed as laspy
//! computes it (a multiply, then an add), so the points are laspy's bit
//! for bit and a survey cloud at a UTM-sized offset keeps its precision.
//! The header's scale and offset are kept ([`ScaleOffset`]) so that
//! `detect -o OUT.las` writes the points back on the same grid.
//!
//! **Writing** (`meshtrim detect CLOUD -o OUT.las|OUT.laz`): the points in
//! input order, LAS 1.4, with two extra-bytes dimensions, `boundary`
//! (uint8, 1 = boundary) and `beta` (float64), which laspy, PDAL and
//! CloudCompare read as scalar fields. From a LAS or LAZ input, its point
//! records byte for byte, the labels appended, with its point format,
//! scale, offset, VLRs and EVLRs ([`write_labels_las_over`]); from another
//! format, point format 0 on a grid per axis whose offset is the middle of
//! the points' range and whose scale is the finest power of ten spanning
//! that range in 32-bit integers.

use std::io::{Cursor, Write};
use std::sync::Arc;

use anyhow::{anyhow, bail, Context, Result};
use las::{Builder, PointDataBuilder, Transform, Vector, Vlr};

use rayon::prelude::*;

use super::ply::Scalar;
use super::{Cloud, Colours, Format, Point3, ScalarField};

/// Bytes of decompressed records read per chunk: a bounded buffer however
/// many points the header announces or however long it says a record is.
const CHUNK_BYTES: u64 = 64 << 20;

/// Per axis, the grid of a LAS file's integer coordinates:
/// `coordinate = integer × scale + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleOffset {
    /// Scale of x, y and z.
    pub scale: [f64; 3],
    /// Offset of x, y and z.
    pub offset: [f64; 3],
}

/// True when `bytes` start with a LAS (or LAZ) header's signature.
pub fn is_las(bytes: &[u8]) -> bool {
    bytes.starts_with(b"LASF")
}

/// Reads a LAS or LAZ file's points (see the module doc).
pub fn read_las(bytes: Vec<u8>) -> Result<Cloud> {
    check_chunk_table(&bytes)?;
    let bytes = Shared(Arc::new(bytes));
    let mut reader = las::Reader::new(Cursor::new(bytes.clone()))
        .map_err(|e| anyhow!("cannot read the LAS header or the LAZ chunk table: {e}"))?;
    let header = reader.header().clone();
    let frame = frame_of(&header)?;
    check_laz_items(&header)?;
    let total = header.number_of_points();
    if total > u64::from(u32::MAX) {
        bail!(
            "the header announces {total} points; meshtrim reads at most {}",
            u32::MAX
        );
    }
    let PointsRead {
        points,
        rgb,
        intensity,
        classification,
    } = if header.point_format().is_compressed {
        read_compressed(&mut reader, &header, total)?
    } else {
        read_uncompressed(bytes.as_ref(), &header, frame, total)?
    };
    let scalars = [
        ("intensity", Scalar::U16, intensity),
        ("classification", Scalar::U8, classification),
    ];
    Ok(Cloud {
        points,
        normals: None,
        scalars: scalars.into_iter().filter_map(field_if_set).collect(),
        dropped_non_finite: 0,
        format: Format::Las,
        scale_offset: Some(frame),
        colours: rgb
            .filter(|rgb| rgb.par_iter().any(|c| *c != [0; 3]))
            .map(colours_of),
        grid: None,
    })
}

/// The points' colours in 0..1 from their 16-bit channels: 0–255 when no
/// channel exceeds 255 (8-bit values in 16-bit fields), else 0–65535.
fn colours_of(rgb: Vec<[u16; 3]>) -> Colours {
    let eight_bit = rgb.par_iter().all(|c| c.iter().all(|&v| v <= 255));
    let full = if eight_bit { 255.0 } else { 65535.0 };
    let rgba = rgb
        .par_iter()
        .map(|c| {
            let [r, g, b] = c.map(|v| f64::from(v) / full);
            [r, g, b, 1.0]
        })
        .collect();
    Colours { rgba, alpha: false }
}

/// A field of every point format as the file's own value, unless every
/// point has it 0 (the writer did not fill it in).
fn field_if_set((name, kind, values): (&str, Scalar, Vec<f64>)) -> Option<ScalarField> {
    values.par_iter().any(|&v| v != 0.0).then(|| ScalarField {
        name: name.to_string(),
        kind,
        values,
    })
}

/// Points, their colours when the point format has them, and the fields
/// every format has.
struct PointsRead {
    points: Vec<Point3>,
    rgb: Option<Vec<[u16; 3]>>,
    intensity: Vec<f64>,
    classification: Vec<f64>,
}

/// The file's bytes, shared by the `las` reader (which wants to own its
/// source) and the direct decoding of uncompressed records.
#[derive(Clone)]
struct Shared(Arc<Vec<u8>>);

impl AsRef<[u8]> for Shared {
    fn as_ref(&self) -> &[u8] {
        &self.0
    }
}

/// LAZ points, decompressed chunk by chunk by the `las` reader.
fn read_compressed(
    reader: &mut las::Reader,
    header: &las::Header,
    total: u64,
) -> Result<PointsRead> {
    let mut points: Vec<Point3> = Vec::new();
    let mut rgb = header.point_format().has_color.then(Vec::new);
    let mut intensity = Vec::new();
    let mut classification = Vec::new();
    let mut data = PointDataBuilder::new().for_header(header).build();
    let chunk = (CHUNK_BYTES / u64::from(header.point_format().len()).max(1)).max(1);
    while (points.len() as u64) < total {
        let read = reader
            .fill_points(chunk, &mut data)
            .map_err(|e| anyhow!("point data from point {}: {e}", points.len()))?;
        if read == 0 {
            break;
        }
        points.reserve(data.len());
        points.extend(
            data.x()
                .zip(data.y())
                .zip(data.z())
                .map(|((x, y), z)| [x, y, z]),
        );
        if let (Some(rgb), Some(read)) = (rgb.as_mut(), data.rgb()) {
            rgb.extend(read.map(|(r, g, b)| [r, g, b]));
        }
        intensity.extend(data.intensity().map(f64::from));
        classification.extend(data.classification().map(f64::from));
    }
    if (points.len() as u64) != total {
        bail!(
            "the header announces {total} points, but the point data holds {}",
            points.len()
        );
    }
    Ok(PointsRead {
        points,
        rgb,
        intensity,
        classification,
    })
}

/// Uncompressed records decoded in place, in parallel: X, Y and Z are the
/// first three little-endian i32 of a record in every point format, each
/// `scale × integer + offset` as the `las` crate and laspy compute it.
fn read_uncompressed(
    bytes: &[u8],
    header: &las::Header,
    frame: ScaleOffset,
    total: u64,
) -> Result<PointsRead> {
    let raw = las::raw::Header::read_from(bytes).map_err(|e| anyhow!("bad LAS header: {e}"))?;
    let start = raw.offset_to_point_data as usize;
    let record = usize::from(header.point_format().len());
    if record < 17 {
        bail!("bad LAS header: point records of {record} bytes cannot hold x, y, z, intensity and classification");
    }
    let held = bytes.len().saturating_sub(start) / record;
    if (held as u64) < total {
        bail!("the header announces {total} points, but the point data holds {held}");
    }
    let data = &bytes[start..start + total as usize * record];
    let [sx, sy, sz] = frame.scale;
    let [ox, oy, oz] = frame.offset;
    let points = data
        .par_chunks_exact(record)
        .with_min_len(1 << 14)
        .map(|r| {
            let int =
                |at: usize| f64::from(i32::from_le_bytes([r[at], r[at + 1], r[at + 2], r[at + 3]]));
            [sx * int(0) + ox, sy * int(4) + oy, sz * int(8) + oz]
        })
        .collect();
    let rgb = match colour_offset(header.point_format()) {
        Some(at) if at + 6 <= record => Some(
            data.par_chunks_exact(record)
                .with_min_len(1 << 14)
                .map(|r| [0, 2, 4].map(|k| u16::from_le_bytes([r[at + k], r[at + k + 1]])))
                .collect(),
        ),
        Some(_) => {
            bail!("bad LAS header: point records of {record} bytes cannot hold their colour")
        }
        None => None,
    };
    // Classification: the low five bits of byte 15 in the legacy formats,
    // all of byte 16 in the extended ones (as the las crate reads it).
    let extended = header.point_format().is_extended;
    let column = |value: fn(&[u8], bool) -> f64| {
        data.par_chunks_exact(record)
            .with_min_len(1 << 14)
            .map(|r| value(r, extended))
            .collect()
    };
    Ok(PointsRead {
        points,
        rgb,
        intensity: column(|r, _| f64::from(u16::from_le_bytes([r[12], r[13]]))),
        classification: column(|r, extended| match extended {
            true => f64::from(r[16]),
            false => f64::from(r[15] & 0x1F),
        }),
    })
}

/// Where a point record's red, green and blue (three little-endian u16)
/// start, for the formats that have a colour: after the 20 bytes of the
/// legacy formats' fields and their GPS time, or after the 30 of the
/// extended formats (6–10), which always have one.
fn colour_offset(format: &las::point::Format) -> Option<usize> {
    if !format.has_color {
        return None;
    }
    Some(match (format.is_extended, format.has_gps_time) {
        (true, _) => 30,
        (false, true) => 28,
        (false, false) => 20,
    })
}

/// A LAZ file's chunk table must fit its point data: the decoder
/// allocates the table's announced number of chunks before reading it, so
/// a corrupt count would take the process down instead of failing. Every
/// chunk holds at least one byte of compressed points, so the count cannot
/// exceed the bytes between the start of point data and the table. Files
/// that are not LAZ, or whose table offset is missing, are left to the
/// reader.
fn check_chunk_table(bytes: &[u8]) -> Result<()> {
    let Ok(raw) = las::raw::Header::read_from(bytes) else {
        return Ok(()); // the reader reports the bad header
    };
    // Bits 7 and 6 of the point format byte mark compressed (LAZ) data.
    if raw.point_data_record_format & 0xC0 == 0 {
        return Ok(());
    }
    let start = raw.offset_to_point_data as usize;
    let i64_at = |at: usize| -> Option<i64> {
        let b = bytes.get(at..at.checked_add(8)?)?;
        Some(i64::from_le_bytes(b.try_into().ok()?))
    };
    let Some(mut table) = i64_at(start) else {
        bail!("the file ends before its LAZ point data");
    };
    if table <= start as i64 {
        // The writer could not seek back: the offset is the file's last 8 bytes.
        table = i64_at(bytes.len().saturating_sub(8)).unwrap_or(-1);
        if table <= start as i64 {
            return Ok(());
        }
    }
    let table = table as u64;
    let count_at = table.saturating_add(4);
    let Some(count) = bytes
        .get(count_at as usize..(count_at as usize).saturating_add(4))
        .and_then(|b| b.try_into().ok())
        .map(u32::from_le_bytes)
    else {
        bail!(
            "the LAZ chunk table (at byte {table}) lies beyond the file's end ({} bytes)",
            bytes.len()
        );
    };
    let data = table - start as u64;
    if u64::from(count) > data {
        bail!(
            "the LAZ chunk table announces {count} chunks in {data} bytes of compressed points: \
             the table is corrupt"
        );
    }
    Ok(())
}

/// A LAZ file's compressed items must make up the header's point record:
/// the decoder asserts it (a panic) rather than returning an error.
fn check_laz_items(header: &las::Header) -> Result<()> {
    if !header.point_format().is_compressed {
        return Ok(());
    }
    let vlr = header.laz_vlr().map_err(|e| anyhow!("bad LAZ VLR: {e}"))?;
    let record = u64::from(header.point_format().len());
    if vlr.items_size() != record {
        bail!(
            "the LAZ items ({} bytes a point) do not match the point record length ({record} \
             bytes): the header or the LAZ VLR is corrupt",
            vlr.items_size()
        );
    }
    Ok(())
}

/// The header's scale and offset, checked: a zero or non-finite scale or
/// a non-finite offset would make every coordinate meaningless.
fn frame_of(header: &las::Header) -> Result<ScaleOffset> {
    let t = header.transforms();
    let axes = [("x", t.x), ("y", t.y), ("z", t.z)];
    for (axis, transform) in axes {
        if !(transform.scale.is_finite() && transform.scale != 0.0 && transform.offset.is_finite())
        {
            bail!(
                "bad LAS header: the {axis} scale {} and offset {} do not give finite coordinates",
                transform.scale,
                transform.offset
            );
        }
    }
    Ok(ScaleOffset {
        scale: axes.map(|(_, t)| t.scale),
        offset: axes.map(|(_, t)| t.offset),
    })
}

/// The grid for points that came from another format: per axis the middle
/// of the range as offset, and the finest power-of-ten scale at which the
/// range fits in ±2³⁰ steps (half of i32, so rounding cannot overflow) and
/// which is still at least two f64 epsilons of the largest coordinate (a
/// finer grid would not be a finer one in f64).
pub fn grid_for(points: &[Point3]) -> ScaleOffset {
    let mut frame = ScaleOffset {
        scale: [1.0; 3],
        offset: [0.0; 3],
    };
    for axis in 0..3 {
        let (lo, hi) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[axis]), hi.max(p[axis]))
            });
        if !(lo.is_finite() && hi.is_finite()) {
            continue;
        }
        let half = (hi - lo) / 2.0;
        let largest = lo.abs().max(hi.abs());
        let finest = (half / f64::from(1u32 << 30)).max(largest * f64::EPSILON * 2.0);
        frame.offset[axis] = lo + half;
        frame.scale[axis] = if finest > 0.0 {
            10f64.powi(finest.log10().ceil() as i32)
        } else {
            1.0 // every coordinate is 0
        };
    }
    frame
}

/// Writes `points` with their labels as LAS (or LAZ when `compressed`):
/// see the module doc.
pub fn write_labels_las(
    w: &mut dyn Write,
    points: &[Point3],
    boundary: &[bool],
    beta: &[f64],
    frame: ScaleOffset,
    compressed: bool,
) -> std::io::Result<()> {
    let bytes = labels_las_bytes(points, boundary, beta, frame, compressed)
        .map_err(std::io::Error::other)?;
    w.write_all(&bytes)
}

fn labels_las_bytes(
    points: &[Point3],
    boundary: &[bool],
    beta: &[f64],
    frame: ScaleOffset,
    compressed: bool,
) -> Result<Vec<u8>> {
    let mut builder = Builder::from((1, 4));
    builder.generating_software = "meshtrim detect".to_string();
    // No creation date: the same input gives the same bytes out.
    builder.date = None;
    builder.point_format = las::point::Format::new(0).context("LAS point format 0")?;
    builder.point_format.extra_bytes = EXTRA_BYTES_LEN;
    builder.point_format.is_compressed = compressed;
    let axis = |i: usize| Transform {
        scale: frame.scale[i],
        offset: frame.offset[i],
    };
    builder.transforms = Vector {
        x: axis(0),
        y: axis(1),
        z: axis(2),
    };
    builder.vlrs.push(extra_bytes_vlr());
    let header = builder.into_header().context("LAS header")?;
    let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).context("LAS writer")?;
    for (i, p) in points.iter().enumerate() {
        let mut extra = Vec::with_capacity(EXTRA_BYTES_LEN as usize);
        extra.push(u8::from(boundary[i]));
        extra.extend_from_slice(&beta[i].to_le_bytes());
        let point = las::Point {
            x: p[0],
            y: p[1],
            z: p[2],
            extra_bytes: extra,
            ..Default::default()
        };
        writer.write_point(point).with_context(|| {
            format!(
                "point {i} ({}, {}, {}) does not fit the LAS grid",
                p[0], p[1], p[2]
            )
        })?;
    }
    let cursor = writer.into_inner().context("finishing the LAS file")?;
    Ok(cursor.into_inner())
}

/// Writes the LAS or LAZ file whose bytes are `source` (the points the
/// labels are of, in file order) again, LAZ when `compressed`: each point
/// record as it was (intensity, returns, classification, GPS time,
/// colour, its own extra bytes), with `boundary` and `beta` added as two
/// more extra-bytes dimensions; the header's VLRs and EVLRs (the
/// coordinate system among them), scale and offset kept; LAS 1.4.
pub fn write_labels_las_over(
    w: &mut dyn Write,
    source: Vec<u8>,
    boundary: &[bool],
    beta: &[f64],
    compressed: bool,
) -> std::io::Result<()> {
    let bytes =
        relabelled_las_bytes(source, boundary, beta, compressed).map_err(std::io::Error::other)?;
    w.write_all(&bytes)
}

fn relabelled_las_bytes(
    source: Vec<u8>,
    boundary: &[bool],
    beta: &[f64],
    compressed: bool,
) -> Result<Vec<u8>> {
    let mut reader = las::Reader::new(Cursor::new(source))
        .map_err(|e| anyhow!("cannot read the input's LAS header again: {e}"))?;
    let input = reader.header().clone();
    let total = input.number_of_points();
    if total != boundary.len() as u64 {
        bail!(
            "the input now holds {total} points, not the {} labelled",
            boundary.len()
        );
    }
    let own_extra_bytes = input.point_format().extra_bytes;
    let mut builder = Builder::from(input.clone());
    builder.version = las::Version::new(1, 4);
    builder.generating_software = "meshtrim detect".to_string();
    builder.point_format.extra_bytes = own_extra_bytes
        .checked_add(EXTRA_BYTES_LEN)
        .context("the input's point records are too long to add the labels to")?;
    builder.point_format.is_compressed = compressed;
    // The LAZ item list is the writer's to make for the output.
    builder.vlrs.retain(|vlr| vlr.user_id != LASZIP_USER_ID);
    add_label_descriptors(&mut builder.vlrs, own_extra_bytes);
    let header = builder.into_header().context("LAS header")?;
    let format = *header.point_format();
    let transforms = *header.transforms();
    let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).context("LAS writer")?;
    // The records are copied as they are, a chunk at a time, the labels
    // appended to each: no field is decoded and encoded again.
    let mut data = PointDataBuilder::new().for_header(&input).build();
    let chunk = (CHUNK_BYTES / u64::from(input.point_format().len()).max(1)).max(1);
    let mut done = 0usize;
    while (done as u64) < total {
        let read = reader
            .fill_points(chunk, &mut data)
            .map_err(|e| anyhow!("point data of the input from point {done}: {e}"))?;
        if read == 0 || done + data.len() > boundary.len() {
            bail!("the input's point data no longer holds the {total} points labelled");
        }
        let mut bytes = Vec::with_capacity(data.len() * usize::from(format.len()));
        for (k, record) in data.raw_bytes().chunks_exact(data.record_len()).enumerate() {
            bytes.extend_from_slice(record);
            bytes.push(u8::from(boundary[done + k]));
            bytes.extend_from_slice(&beta[done + k].to_le_bytes());
        }
        let slab = PointDataBuilder::new()
            .with_format(format)
            .with_transforms(transforms)
            .build_from_bytes(bytes)
            .context("labelled point records")?;
        writer
            .write_points(&slab)
            .context("writing the labelled points")?;
        done += data.len();
    }
    let cursor = writer.into_inner().context("finishing the LAS file")?;
    Ok(cursor.into_inner())
}

/// The user id of the VLR describing a LAZ file's compressed items.
const LASZIP_USER_ID: &str = "laszip encoded";

/// Adds `boundary` and `beta` to the Extra Bytes VLR after the
/// descriptors of the records' `own` extra bytes; without such a VLR,
/// makes one, the own bytes described as undocumented runs (data type 0,
/// the length in the options byte, as the standard has it).
fn add_label_descriptors(vlrs: &mut Vec<Vlr>, own: u16) {
    let ours = extra_bytes_vlr();
    let existing = vlrs
        .iter_mut()
        .find(|vlr| vlr.user_id == ours.user_id && vlr.record_id == ours.record_id);
    match existing {
        Some(vlr) => vlr.data.extend_from_slice(&ours.data),
        None => {
            let mut vlr = ours;
            // Runs of at most 255 bytes, the most one options byte says.
            let mut undocumented = Vec::new();
            let mut left = own;
            while left > 0 {
                let run = left.min(255);
                let mut descriptor = [0u8; 192];
                descriptor[3] = run as u8;
                descriptor[4..4 + 7].copy_from_slice(b"unnamed");
                undocumented.extend_from_slice(&descriptor);
                left -= run;
            }
            vlr.data.splice(0..0, undocumented);
            vlrs.push(vlr);
        }
    }
}

/// Bytes of the two extra dimensions per point: uint8 + float64.
const EXTRA_BYTES_LEN: u16 = 9;

/// The LAS 1.4 "Extra Bytes" VLR (record 4 of LASF_Spec) describing
/// `boundary` (data type 1, uint8) and `beta` (data type 10, float64).
fn extra_bytes_vlr() -> Vlr {
    let mut data = Vec::with_capacity(2 * 192);
    data.extend(extra_bytes_descriptor(
        1,
        "boundary",
        "1 = boundary point (meshtrim BPD)",
    ));
    data.extend(extra_bytes_descriptor(
        10,
        "beta",
        "local resolution (meshtrim BPD)",
    ));
    Vlr {
        user_id: "LASF_Spec".to_string(),
        record_id: 4,
        description: "Extra Bytes".to_string(),
        data,
    }
}

/// One 192-byte extra-bytes descriptor (LAS 1.4 R15, table 24): no
/// no-data, min, max, scale or offset given (options 0).
fn extra_bytes_descriptor(data_type: u8, name: &str, description: &str) -> [u8; 192] {
    let mut d = [0u8; 192];
    d[2] = data_type;
    d[4..4 + name.len()].copy_from_slice(name.as_bytes());
    let text = &description.as_bytes()[..description.len().min(32)];
    d[160..160 + text.len()].copy_from_slice(text);
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_spans_the_range_and_f64_steps() {
        let survey = [
            [612_345.0, 6_012_345.0, 0.0],
            [612_345.6, 6_012_345.2, 0.002],
        ];
        let frame = grid_for(&survey);
        // x: two f64 epsilons at 6e5 (2.7e-10) round up to 1e-9; y: at 6e6
        // (2.7e-9) to 1e-8; z: the range's half, 0.001 / 2^30 (9.3e-13),
        // to 1e-12.
        assert_eq!(frame.scale, [1e-9, 1e-8, 1e-12]);
        let middle = [612_345.3, 6_012_345.1, 0.001];
        for (offset, m) in frame.offset.iter().zip(middle) {
            assert!((offset - m).abs() < 1e-9, "{offset} {m}");
        }
        let flat = grid_for(&[[0.0, 1.0, -2.0]; 3]);
        assert_eq!(flat.scale, [1.0, 1e-15, 1e-15]);
    }

    #[test]
    fn labels_read_back_on_the_grid() {
        let points: Vec<Point3> = (0..50)
            .map(|i| [f64::from(i) * 0.1, f64::from(i % 7), 1e5 + f64::from(i)])
            .collect();
        let boundary: Vec<bool> = (0..50).map(|i| i % 3 == 0).collect();
        let beta = vec![0.25; 50];
        let frame = grid_for(&points);
        for compressed in [false, true] {
            let mut out = Vec::new();
            write_labels_las(&mut out, &points, &boundary, &beta, frame, compressed).unwrap();
            let cloud = read_las(out).unwrap();
            assert_eq!(cloud.scale_offset, Some(frame));
            for (read, p) in cloud.points.iter().zip(&points) {
                for axis in 0..3 {
                    let step = frame.scale[axis];
                    assert!((read[axis] - p[axis]).abs() <= step, "{read:?} {p:?}");
                }
            }
        }
    }

    /// A LAS file of format 1 (GPS time) whose records carry `own` extra
    /// bytes, undescribed, and a VLR of its own.
    fn survey(own: u16, compressed: bool) -> Vec<u8> {
        let mut builder = Builder::from((1, 2));
        builder.point_format = las::point::Format::new(1).unwrap();
        builder.point_format.extra_bytes = own;
        builder.point_format.is_compressed = compressed;
        builder.vlrs.push(Vlr {
            user_id: "LASF_Projection".to_string(),
            record_id: 2112,
            description: "OGC WKT".to_string(),
            data: b"PROJCS[]".to_vec(),
        });
        let header = builder.into_header().unwrap();
        let mut writer = las::Writer::new(Cursor::new(Vec::new()), header).unwrap();
        for i in 0..300u16 {
            writer
                .write_point(las::Point {
                    x: f64::from(i) * 0.01,
                    y: f64::from(i % 17) * 0.01,
                    z: 1.0,
                    intensity: i,
                    gps_time: Some(f64::from(i) * 0.5),
                    extra_bytes: (0..own).map(|k| (i + k) as u8).collect(),
                    ..Default::default()
                })
                .unwrap();
        }
        writer.into_inner().unwrap().into_inner()
    }

    /// The records of a LAS file's points, decompressed.
    fn records(bytes: Vec<u8>) -> (las::Header, Vec<Vec<u8>>) {
        let mut reader = las::Reader::new(Cursor::new(bytes)).unwrap();
        let header = reader.header().clone();
        let data = reader.read_all().unwrap();
        let records = data
            .raw_bytes()
            .chunks_exact(data.record_len())
            .map(<[u8]>::to_vec);
        (header, records.collect())
    }

    #[test]
    fn a_las_input_is_written_again_with_its_records_and_the_labels() {
        let boundary: Vec<bool> = (0..300).map(|i| i % 4 == 0).collect();
        let beta: Vec<f64> = (0..300).map(|i| f64::from(i) / 7.0).collect();
        for (own, compressed) in [(0, false), (3, true), (3, false)] {
            let source = survey(own, compressed);
            let (_, before) = records(source.clone());
            for out_compressed in [false, true] {
                let bytes =
                    relabelled_las_bytes(source.clone(), &boundary, &beta, out_compressed).unwrap();
                let (header, after) = records(bytes);
                assert_eq!(header.version(), las::Version::new(1, 4));
                assert_eq!(header.point_format().to_u8().unwrap(), 1);
                assert_eq!(header.point_format().extra_bytes, own + EXTRA_BYTES_LEN);
                for (i, (a, b)) in after.iter().zip(&before).enumerate() {
                    assert_eq!(&a[..b.len()], &b[..], "point {i}'s record");
                    assert_eq!(a[b.len()], u8::from(boundary[i]));
                    assert_eq!(a[b.len() + 1..], beta[i].to_le_bytes());
                }
                assert_eq!(after.len(), 300);
                let vlr = |id: u16| header.vlrs().iter().find(|v| v.record_id == id).cloned();
                assert_eq!(vlr(2112).unwrap().data, b"PROJCS[]");
                // The own bytes, undescribed in the input, as one
                // undocumented run (type 0, its length in the options).
                let descriptors = vlr(4).unwrap().data;
                assert_eq!(descriptors.len(), 192 * (2 + usize::from(own > 0)));
                if own > 0 {
                    assert_eq!((descriptors[2], descriptors[3]), (0, 3));
                }
                assert_eq!(&descriptors[descriptors.len() - 188..][..4], b"beta");
            }
        }
        // A file with other points than those labelled is refused.
        let error = relabelled_las_bytes(survey(0, false), &boundary[1..], &beta[1..], false);
        assert!(error
            .unwrap_err()
            .to_string()
            .contains("not the 299 labelled"));
    }

    #[test]
    fn a_descriptor_is_192_bytes_with_its_type_and_name() {
        let d = extra_bytes_descriptor(10, "beta", "local resolution (meshtrim BPD)");
        assert_eq!(d[2], 10);
        assert_eq!(&d[4..8], b"beta");
        assert_eq!(d[8], 0);
        assert_eq!(&d[160..165], b"local");
    }
}
