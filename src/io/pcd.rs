//! PCD (Point Cloud Library) reading: `DATA ascii`, `binary` and
//! `binary_compressed`.
//!
//! The header lists the fields of a point (FIELDS, SIZE, TYPE, COUNT); x, y
//! and z may have any numeric type and every other field (rgba, normals,
//! curvature, padding `_`, COUNT > 1 descriptors) is skipped by its size.
//! `binary` stores points one after the other; `binary_compressed` is a u32
//! compressed size, a u32 uncompressed size and LZF data that holds the
//! fields one after the other (all x, then all y, ...).
//!
//! Points with a NaN or infinite coordinate are dropped and counted:
//! organised clouds from depth cameras mark empty pixels that way, so they
//! are expected, not an error. Binary PCD is read as little-endian, the byte
//! order of every machine PCL writes on in practice.

use anyhow::{anyhow, bail, Result};

use rayon::prelude::*;

use super::{
    capacity, cut_after_newlines, lines, mixed_line_ending, strip_bom, truncated, Cloud, Format,
    HeaderEol, Point3, PIECE_BYTES,
};

/// One field of a PCD point.
#[derive(Debug, Clone, PartialEq)]
struct Field {
    name: String,
    size: usize,
    ty: char,
    count: usize,
}

impl Field {
    /// Bytes the field takes in one point.
    fn bytes(&self) -> usize {
        self.size * self.count
    }

    /// Decodes the first element of the field from little-endian bytes.
    fn decode(&self, b: &[u8]) -> f64 {
        let mut raw = [0u8; 8];
        raw[..self.size].copy_from_slice(&b[..self.size]);
        match (self.ty, self.size) {
            ('F', 4) => f64::from(f32::from_le_bytes([raw[0], raw[1], raw[2], raw[3]])),
            ('F', _) => f64::from_le_bytes(raw),
            ('U', _) => u64::from_le_bytes(raw) as f64,
            // Sign-extend by shifting the value to the top and back.
            (_, size) => {
                let shift = 64 - 8 * size as u32;
                ((i64::from_le_bytes(raw) << shift) >> shift) as f64
            }
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Data {
    Ascii,
    Binary,
    Compressed,
}

#[derive(Debug, Clone, PartialEq)]
struct Header {
    fields: Vec<Field>,
    points: usize,
    data: Data,
    body_start: usize,
    lines: usize,
    /// Bytes per point, checked not to overflow.
    point_bytes: usize,
}

impl Header {
    fn field(&self, name: &str) -> Option<usize> {
        self.fields.iter().position(|f| f.name == name)
    }
}

/// The fields the reader keeps: x, y, z and, if present, a normal.
struct Wanted {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
}

/// Reads a PCD file, dropping (and counting) non-finite points.
pub fn read_pcd(bytes: &[u8]) -> Result<Cloud> {
    let bytes = strip_bom(bytes);
    let header = parse_header(bytes)?;
    let wanted = wanted_fields(&header)?;
    let body = &bytes[header.body_start..];
    let raw = match header.data {
        Data::Ascii => read_ascii(&header, &wanted, body)?,
        Data::Binary => read_binary(&header, &wanted, body)?,
        Data::Compressed => read_compressed(&header, &wanted, body)?,
    };
    Ok(keep_finite(raw))
}

fn wanted_fields(header: &Header) -> Result<Wanted> {
    let f = |n| header.field(n);
    let xyz = match (f("x"), f("y"), f("z")) {
        (Some(x), Some(y), Some(z)) => [x, y, z],
        _ => bail!("the PCD fields have no x, y and z"),
    };
    let normal = match (f("normal_x"), f("normal_y"), f("normal_z")) {
        (Some(x), Some(y), Some(z)) => Some([x, y, z]),
        _ => None,
    };
    Ok(Wanted { xyz, normal })
}

fn parse_header(bytes: &[u8]) -> Result<Header> {
    let mut fields: Vec<Field> = Vec::new();
    let (mut sizes, mut types, mut counts) = (None, None, None);
    let (mut width, mut height, mut points) = (None, None, None);
    let mut start = 0;
    let mut line_no = 0;
    let mut count_line = 0;
    // Every header line ends as the first does, so that binary data
    // starts exactly after the DATA line's own ending.
    let eol = HeaderEol::of(bytes);
    while start < bytes.len() {
        line_no += 1;
        let (text, next) = eol.line_or_rest(bytes, start);
        let line = String::from_utf8_lossy(text);
        start = next;
        let at = |what: String| anyhow!("malformed PCD header: line {line_no}: {what}");
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some((key, values)) = words.split_first() else {
            continue;
        };
        if let Some(e) = mixed_line_ending(&line).filter(|_| !key.starts_with('#')) {
            return Err(at(e));
        }
        match *key {
            k if k.starts_with('#') => {}
            "VERSION" | "VIEWPOINT" => {}
            "FIELDS" | "COLUMNS" => fields = values.iter().map(|n| new_field(n)).collect(),
            "SIZE" => sizes = Some(numbers(values).map_err(at)?),
            "TYPE" => types = Some(values.iter().map(|t| t.to_string()).collect::<Vec<_>>()),
            "COUNT" => {
                counts = Some(numbers(values).map_err(at)?);
                count_line = line_no;
            }
            "WIDTH" => width = Some(number(values).map_err(at)?),
            "HEIGHT" => height = Some(number(values).map_err(at)?),
            "POINTS" => points = Some(number(values).map_err(at)?),
            "DATA" => {
                let data = parse_data(values).map_err(at)?;
                let points = match points {
                    Some(points) => points,
                    None => points_of(width, height).map_err(at)?,
                };
                let fields = fill_fields(fields, sizes, types, counts).map_err(at)?;
                let (fields, point_bytes) = check_counts(fields)
                    .map_err(|e| anyhow!("malformed PCD header: line {count_line}: {e}"))?;
                return Ok(Header {
                    fields,
                    points,
                    data,
                    body_start: start,
                    lines: line_no,
                    point_bytes,
                });
            }
            other => return Err(at(format!("unknown header line '{other}'"))),
        }
    }
    bail!("malformed PCD header: no DATA line")
}

/// POINTS' default, WIDTH × HEIGHT; a product that overflows would wrap
/// to a small count and misread the file.
fn points_of(width: Option<usize>, height: Option<usize>) -> Result<usize, String> {
    let (w, h) = width
        .zip(height)
        .ok_or("no POINTS, WIDTH or HEIGHT".to_string())?;
    w.checked_mul(h).ok_or(format!(
        "WIDTH {w} × HEIGHT {h} is too many points (and no POINTS)"
    ))
}

/// Drops the fields of COUNT 0, which hold no data (PCL drops them too),
/// and returns the fields left with the bytes a point takes. x, y and z
/// must keep at least one element; a record size that overflows is an
/// error rather than a wrapped, wrong stride.
fn check_counts(fields: Vec<Field>) -> Result<(Vec<Field>, usize), String> {
    if let Some(f) = fields
        .iter()
        .find(|f| f.count == 0 && ["x", "y", "z"].contains(&f.name.as_str()))
    {
        return Err(format!(
            "COUNT 0 for field '{}': x, y and z need a COUNT of at least 1",
            f.name
        ));
    }
    let fields: Vec<Field> = fields.into_iter().filter(|f| f.count > 0).collect();
    let mut total = 0usize;
    for f in &fields {
        total = f
            .size
            .checked_mul(f.count)
            .and_then(|bytes| total.checked_add(bytes))
            .ok_or(format!(
                "COUNT {} for field '{}' makes a point larger than memory can hold",
                f.count, f.name
            ))?;
    }
    Ok((fields, total))
}

fn new_field(name: &str) -> Field {
    Field {
        name: name.to_string(),
        size: 4,
        ty: 'F',
        count: 1,
    }
}

fn number(values: &[&str]) -> Result<usize, String> {
    match values {
        [v] => v.parse().map_err(|_| format!("'{v}' is not a count")),
        _ => Err(format!("expected one number, found '{}'", values.join(" "))),
    }
}

fn numbers(values: &[&str]) -> Result<Vec<usize>, String> {
    values.iter().map(|v| number(&[v])).collect()
}

fn parse_data(values: &[&str]) -> Result<Data, String> {
    match values {
        ["ascii"] => Ok(Data::Ascii),
        ["binary"] => Ok(Data::Binary),
        ["binary_compressed"] => Ok(Data::Compressed),
        _ => Err(format!("unsupported DATA '{}'", values.join(" "))),
    }
}

/// Puts SIZE, TYPE and COUNT into the fields and checks them.
fn fill_fields(
    mut fields: Vec<Field>,
    sizes: Option<Vec<usize>>,
    types: Option<Vec<String>>,
    counts: Option<Vec<usize>>,
) -> Result<Vec<Field>, String> {
    let n = fields.len();
    let check = |what: &str, len: Option<usize>| match len {
        Some(len) if len != n => Err(format!("{what} has {len} entries for {n} fields")),
        _ => Ok(()),
    };
    check("SIZE", sizes.as_ref().map(Vec::len))?;
    check("TYPE", types.as_ref().map(Vec::len))?;
    check("COUNT", counts.as_ref().map(Vec::len))?;
    for (i, field) in fields.iter_mut().enumerate() {
        field.size = sizes.as_ref().map_or(4, |s| s[i]);
        field.count = counts.as_ref().map_or(1, |c| c[i]);
        field.ty = types
            .as_ref()
            .map_or('F', |t| t[i].chars().next().unwrap_or('?'));
        match (field.ty, field.size) {
            ('F', 4 | 8) | ('I' | 'U', 1 | 2 | 4 | 8) => {}
            (ty, size) => {
                return Err(format!(
                    "unsupported type {ty} of size {size} for field '{}'",
                    field.name
                ))
            }
        }
    }
    Ok(fields)
}

/// Points as read, non-finite ones included.
struct Raw {
    points: Vec<Point3>,
    normals: Option<Vec<Point3>>,
}

impl Raw {
    fn new(wanted: &Wanted, n: usize) -> Self {
        Raw {
            points: Vec::with_capacity(capacity(n)),
            normals: wanted.normal.map(|_| Vec::with_capacity(capacity(n))),
        }
    }

    /// Appends one point, reading field `f` with `value(f)` (the test
    /// reference's one-pass reading).
    #[cfg(test)]
    fn push(&mut self, wanted: &Wanted, mut value: impl FnMut(usize) -> Result<f64>) -> Result<()> {
        let [x, y, z] = wanted.xyz;
        self.points.push([value(x)?, value(y)?, value(z)?]);
        if let (Some([x, y, z]), Some(normals)) = (wanted.normal, self.normals.as_mut()) {
            normals.push([value(x)?, value(y)?, value(z)?]);
        }
        Ok(())
    }
}

/// `DATA ascii`: one point per line, values separated by whitespace; blank
/// lines are skipped and lines after the declared points ignored. Pieces
/// of the text are parsed in parallel and joined in order, so the error
/// reported is the first in the file, as a one-pass reading gives.
fn read_ascii(header: &Header, wanted: &Wanted, body: &[u8]) -> Result<Raw> {
    read_ascii_in_pieces(header, wanted, body, PIECE_BYTES)
}

fn read_ascii_in_pieces(
    header: &Header,
    wanted: &Wanted,
    body: &[u8],
    piece_bytes: usize,
) -> Result<Raw> {
    let text = std::str::from_utf8(body)
        .map_err(|e| anyhow!("the ASCII data is not text (byte {})", e.valid_up_to()))?;
    let layout = AsciiLayout::of(header);
    let pieces: Vec<AsciiPiece> = cut_after_newlines(text, piece_bytes)
        .into_par_iter()
        .map(|piece| parse_ascii_piece(piece, wanted, &layout))
        .collect();
    let mut raw = Raw::new(wanted, header.points);
    let mut line0 = header.lines;
    for piece in pieces {
        // Points beyond the declared count, and errors after them, are
        // not the cloud's.
        let room = header.points - raw.points.len();
        let take = piece.points.len().min(room);
        raw.points.extend_from_slice(&piece.points[..take]);
        if let (Some(normals), Some(more)) = (raw.normals.as_mut(), piece.normals.as_ref()) {
            normals.extend_from_slice(&more[..take]);
        }
        if take == room {
            break;
        }
        if let Some((i, e)) = piece.error {
            bail!("line {}: {e}", line0 + i);
        }
        line0 += piece.lines;
    }
    if raw.points.len() < header.points {
        return Err(truncated(header.points, "point", raw.points.len()));
    }
    Ok(raw)
}

/// Where each field's first value sits among a line's values.
struct AsciiLayout {
    first: Vec<usize>,
    /// Values per line.
    total: usize,
}

impl AsciiLayout {
    fn of(header: &Header) -> Self {
        let mut first = Vec::with_capacity(header.fields.len());
        let mut total = 0;
        for f in &header.fields {
            first.push(total);
            total += f.count;
        }
        AsciiLayout { first, total }
    }
}

/// The points of one piece of `DATA ascii`; line numbers count from the
/// piece's start.
#[derive(Default)]
struct AsciiPiece {
    points: Vec<Point3>,
    normals: Option<Vec<Point3>>,
    lines: usize,
    /// The piece's first error; parsing stops there.
    error: Option<(usize, String)>,
}

fn parse_ascii_piece(text: &str, wanted: &Wanted, layout: &AsciiLayout) -> AsciiPiece {
    let mut piece = AsciiPiece {
        normals: wanted.normal.map(|_| Vec::new()),
        ..AsciiPiece::default()
    };
    // Not sized by the header's counts, which a damaged file makes absurd.
    let mut tokens = Vec::new();
    for line in lines(text) {
        piece.lines += 1;
        if line.trim().is_empty() {
            continue;
        }
        tokens.clear();
        tokens.extend(line.split_whitespace());
        if let Err(e) = push_ascii_point(&mut piece, wanted, layout, &tokens) {
            piece.error = Some((piece.lines, e));
            break;
        }
    }
    piece
}

/// Appends the point (and normal) of one line's values.
fn push_ascii_point(
    piece: &mut AsciiPiece,
    wanted: &Wanted,
    layout: &AsciiLayout,
    tokens: &[&str],
) -> Result<(), String> {
    if tokens.len() < layout.total {
        return Err(format!(
            "expected {} values, found {}",
            layout.total,
            tokens.len()
        ));
    }
    let value = |f: usize| {
        let token = tokens[layout.first[f]];
        token
            .parse::<f64>()
            .map_err(|_| format!("'{token}' is not a number"))
    };
    let [x, y, z] = wanted.xyz;
    let point = [value(x)?, value(y)?, value(z)?];
    let normal = match wanted.normal {
        Some([x, y, z]) => Some([value(x)?, value(y)?, value(z)?]),
        None => None,
    };
    piece.points.push(point);
    if let (Some(normal), Some(normals)) = (normal, piece.normals.as_mut()) {
        normals.push(normal);
    }
    Ok(())
}

fn read_binary(header: &Header, wanted: &Wanted, body: &[u8]) -> Result<Raw> {
    let stride = header.point_bytes;
    let available = body.len() / stride;
    if available < header.points {
        return Err(truncated(header.points, "point", available));
    }
    let offsets = offsets(header, |f| f.bytes());
    Ok(decode_points(wanted, header.points, |i, f| {
        header.fields[f].decode(&body[i * stride + offsets[f]..])
    }))
}

fn read_compressed(header: &Header, wanted: &Wanted, body: &[u8]) -> Result<Raw> {
    if header.points == 0 {
        return Ok(Raw::new(wanted, 0));
    }
    let expected = header
        .points
        .checked_mul(header.point_bytes)
        .filter(|&e| e <= u32::MAX as usize)
        .ok_or_else(|| {
            anyhow!(
                "{} points are too many for binary_compressed data",
                header.points
            )
        })?;
    let size_at = |at: usize| {
        body.get(at..at + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
            .ok_or_else(|| anyhow!("the compressed data is truncated: no size header"))
    };
    let (compressed, uncompressed) = (size_at(0)?, size_at(4)?);
    if uncompressed != expected {
        bail!(
            "the compressed data holds {uncompressed} bytes, but {} points need {expected}",
            header.points
        );
    }
    let data = body.get(8..8 + compressed).ok_or_else(|| {
        anyhow!(
            "the compressed data is truncated: the header says {compressed} bytes, the file has {}",
            body.len().saturating_sub(8)
        )
    })?;
    let data = lzf::decompress(data, uncompressed)
        .map_err(|e| anyhow!("the LZF-compressed data is corrupt ({e:?})"))?;
    if data.len() != expected {
        bail!(
            "the compressed data decompresses to {} bytes, not {expected}",
            data.len()
        );
    }
    // Field f's block starts after all points of the earlier fields.
    let starts = offsets(header, |f| f.bytes() * header.points);
    Ok(decode_points(wanted, header.points, |i, f| {
        let field = &header.fields[f];
        field.decode(&data[starts[f] + i * field.bytes()..])
    }))
}

/// Points decoded per parallel task, at least: fewer would cost more in
/// scheduling than in decoding.
const POINTS_PER_TASK: usize = 1 << 14;

/// The wanted fields of `n` binary points, `value(i, f)` being field `f`
/// of point `i`; decoded in parallel, in order. The caller has checked
/// that the data holds `n` points.
fn decode_points(wanted: &Wanted, n: usize, value: impl Fn(usize, usize) -> f64 + Sync) -> Raw {
    let triple = |[x, y, z]: [usize; 3]| {
        let mut out = Vec::new();
        (0..n)
            .into_par_iter()
            .with_min_len(POINTS_PER_TASK)
            .map(|i| [value(i, x), value(i, y), value(i, z)])
            .collect_into_vec(&mut out);
        out
    };
    Raw {
        points: triple(wanted.xyz),
        normals: wanted.normal.map(triple),
    }
}

/// Running sums of `len` over the fields: where each field starts.
fn offsets(header: &Header, len: impl Fn(&Field) -> usize) -> Vec<usize> {
    let mut at = 0;
    header
        .fields
        .iter()
        .map(|f| {
            let start = at;
            at += len(f);
            start
        })
        .collect()
}

fn keep_finite(raw: Raw) -> Cloud {
    let finite: Vec<bool> = raw
        .points
        .par_iter()
        .map(|p| p.iter().all(|c| c.is_finite()))
        .collect();
    if !finite.contains(&false) {
        return Cloud {
            points: raw.points,
            normals: raw.normals,
            dropped_non_finite: 0,
            format: Format::Pcd,
        };
    }
    let keep = |v: Vec<Point3>| -> Vec<Point3> {
        v.into_iter()
            .zip(&finite)
            .filter(|(_, &ok)| ok)
            .map(|(p, _)| p)
            .collect()
    };
    let dropped = finite.iter().filter(|&&ok| !ok).count();
    Cloud {
        points: keep(raw.points),
        normals: raw.normals.map(keep),
        dropped_non_finite: dropped,
        format: Format::Pcd,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The one-pass reading of `DATA ascii` the pieces must match.
    fn read_ascii_serial(header: &Header, wanted: &Wanted, body: &[u8]) -> Result<Raw> {
        let text = std::str::from_utf8(body)
            .map_err(|e| anyhow!("the ASCII data is not text (byte {})", e.valid_up_to()))?;
        let layout = AsciiLayout::of(header);
        let mut raw = Raw::new(wanted, header.points);
        let lines = lines(text)
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        for (i, line) in lines.take(header.points) {
            let line_no = header.lines + i + 1;
            let tokens: Vec<&str> = line.split_whitespace().collect();
            if tokens.len() < layout.total {
                bail!(
                    "line {line_no}: expected {} values, found {}",
                    layout.total,
                    tokens.len()
                );
            }
            raw.push(wanted, |f| {
                let token = tokens[layout.first[f]];
                token
                    .parse()
                    .map_err(|_| anyhow!("line {line_no}: '{token}' is not a number"))
            })?;
        }
        if raw.points.len() < header.points {
            return Err(truncated(header.points, "point", raw.points.len()));
        }
        Ok(raw)
    }

    /// Random ASCII bodies (blank lines, every line ending, short and bad
    /// lines, more or fewer lines than declared) read in pieces of a few
    /// bytes give what the one-pass reading gives.
    #[test]
    fn ascii_pieces_read_as_one_pass_does() {
        // The file is a header with a random declared count, then the body;
        // both readings get the body after the parsed header.
        let read = |text: &str, piece_bytes: Option<usize>| {
            let header = parse_header(text.as_bytes()).map_err(|e| e.to_string())?;
            let wanted = wanted_fields(&header).map_err(|e| e.to_string())?;
            let data = &text.as_bytes()[header.body_start..];
            match piece_bytes {
                None => read_ascii_serial(&header, &wanted, data),
                Some(bytes) => read_ascii_in_pieces(&header, &wanted, data, bytes),
            }
            .map(|r| (r.points, r.normals))
            .map_err(|e| e.to_string())
        };
        let errors = crate::io::piece_tests::compare_with_one_pass(
            29,
            2000,
            15,
            |below, _| {
                let declared = below(12);
                format!(
                    "FIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n\
                     TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH {declared}\nHEIGHT 1\n\
                     POINTS {declared}\nDATA ascii\n"
                )
            },
            |below, l, case| match below(20) {
                0 => String::new(),
                1 => "  \t".to_string(),
                2 => "1 2 3".to_string(),
                3 => "1 2 x 0 0 1".to_string(),
                4 => "1 2 3 0 0 y".to_string(),
                _ => format!("{l} {case} -{} 0 0 1 7", below(100)),
            },
            |text| read(text, None),
            |text, piece_bytes| read(text, Some(piece_bytes)),
        );
        assert!(
            (400..1600).contains(&errors),
            "{errors} errors in 2000 cases"
        );
    }

    const HEAD: &str = "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z rgba normal_x normal_y normal_z\n\
        SIZE 4 8 4 4 4 4 4\nTYPE F F F U F F F\nCOUNT 1 1 1 1 1 1 1\nWIDTH 3\nHEIGHT 1\n\
        VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 3\n";

    const POINTS: [[f64; 3]; 3] = [[1.5, 2.25, -3.0], [f64::NAN, 0.0, 0.0], [4.0, 5.0, 6.0]];

    /// Field values of point i, in header order.
    fn record(i: usize) -> (f32, f64, f32, u32, [f32; 3]) {
        let p = POINTS[i];
        (p[0] as f32, p[1], p[2] as f32, 0xff00ff, [0.0, 0.0, 1.0])
    }

    fn binary() -> Vec<u8> {
        let mut out = format!("{HEAD}DATA binary\n").into_bytes();
        for i in 0..3 {
            let (x, y, z, rgba, n) = record(i);
            out.extend(x.to_le_bytes());
            out.extend(y.to_le_bytes());
            out.extend(z.to_le_bytes());
            out.extend(rgba.to_le_bytes());
            n.iter().for_each(|c| out.extend(c.to_le_bytes()));
        }
        out
    }

    fn compressed() -> Vec<u8> {
        let mut soa = Vec::new();
        (0..3).for_each(|i| soa.extend(record(i).0.to_le_bytes()));
        (0..3).for_each(|i| soa.extend(record(i).1.to_le_bytes()));
        (0..3).for_each(|i| soa.extend(record(i).2.to_le_bytes()));
        (0..3).for_each(|i| soa.extend(record(i).3.to_le_bytes()));
        for k in 0..3 {
            (0..3).for_each(|i| soa.extend(record(i).4[k].to_le_bytes()));
        }
        let packed = lzf::compress(&soa).unwrap_or_else(|_| soa.clone());
        let mut out = format!("{HEAD}DATA binary_compressed\n").into_bytes();
        out.extend((packed.len() as u32).to_le_bytes());
        out.extend((soa.len() as u32).to_le_bytes());
        out.extend(packed);
        out
    }

    fn ascii() -> String {
        let mut out = format!("{HEAD}DATA ascii\n");
        for p in POINTS {
            out += &format!("{} {} {} 16711935 0 0 1\n", p[0], p[1], p[2]);
        }
        out
    }

    fn check(cloud: Cloud) {
        assert_eq!(cloud.points, vec![POINTS[0], POINTS[2]]);
        assert_eq!(cloud.normals, Some(vec![[0.0, 0.0, 1.0]; 2]));
        assert_eq!(cloud.dropped_non_finite, 1);
    }

    /// A random cloud in all three encodings: fields of random types and
    /// sizes around x, y, z and the normal, NaN now and then, up to 40,000
    /// points (several parallel tasks). Binary and compressed data are
    /// decoded in parallel, ASCII parsed by its own code; all three must
    /// agree.
    #[test]
    fn random_clouds_read_alike_in_all_three_encodings() {
        let mut rng = testkit::synthetic::SplitMix64::new(43);
        let mut below = |n: u64| (rng.next_u64() % n) as usize;
        for case in 0..60 {
            let n = if case % 10 == 0 {
                20_000 + below(20_000)
            } else {
                below(50)
            };
            let mut names = vec!["x", "y", "z"];
            if below(2) == 0 {
                names.extend(["normal_x", "normal_y", "normal_z"]);
            }
            for extra in ["rgb", "intensity", "label"] {
                if below(2) == 0 {
                    names.insert(below(names.len() as u64 + 1), extra);
                }
            }
            // (TYPE, SIZE) per field; coordinates and normals are floats.
            let types: Vec<(char, usize)> = names
                .iter()
                .map(|name| match name.len() {
                    1 | 8 => [('F', 4), ('F', 8)][below(2)],
                    _ => [('U', 1), ('U', 2), ('I', 4), ('U', 8), ('I', 8), ('F', 4)][below(6)],
                })
                .collect();
            let value = |below: &mut dyn FnMut(u64) -> usize, (ty, size): (char, usize)| -> f64 {
                match (ty, size) {
                    ('F', _) if below(200) == 0 => f64::NAN,
                    ('F', 4) => f64::from((below(2_000_000) as f32 - 1e6) / 7.0),
                    ('F', _) => (below(2_000_000) as f64 - 1e6) / 7.0,
                    ('U', size) => below(1 << (8 * size.min(4) - 1)) as f64,
                    _ => below(1000) as f64 - 500.0,
                }
            };
            let values: Vec<Vec<f64>> = (0..n)
                .map(|_| types.iter().map(|&t| value(&mut below, t)).collect())
                .collect();
            let column = |k: usize| -> Vec<u8> {
                let (ty, size) = types[k];
                let mut out = Vec::new();
                for v in values.iter().map(|r| r[k]) {
                    match (ty, size) {
                        ('F', 4) => out.extend((v as f32).to_le_bytes()),
                        ('F', _) => out.extend(v.to_le_bytes()),
                        ('U', _) => out.extend(&(v as u64).to_le_bytes()[..size]),
                        _ => out.extend(&(v as i64).to_le_bytes()[..size]),
                    }
                }
                out
            };
            let columns: Vec<Vec<u8>> = (0..names.len()).map(column).collect();
            let sizes: Vec<usize> = types.iter().map(|t| t.1).collect();
            let head = format!(
                "VERSION 0.7\nFIELDS {}\nSIZE {}\nTYPE {}\nCOUNT {}\nWIDTH {n}\nHEIGHT 1\n\
                 POINTS {n}\n",
                names.join(" "),
                sizes
                    .iter()
                    .map(|s| s.to_string())
                    .collect::<Vec<_>>()
                    .join(" "),
                types
                    .iter()
                    .map(|t| t.0.to_string())
                    .collect::<Vec<_>>()
                    .join(" "),
                vec!["1"; names.len()].join(" "),
            );
            let mut ascii = format!("{head}DATA ascii\n");
            for row in &values {
                let text: Vec<String> = row.iter().map(|v| v.to_string()).collect();
                ascii += &(text.join(" ") + "\n");
            }
            let mut binary = format!("{head}DATA binary\n").into_bytes();
            for i in 0..n {
                for (column, size) in columns.iter().zip(&sizes) {
                    binary.extend(&column[i * size..(i + 1) * size]);
                }
            }
            let soa = columns.concat();
            let read = |bytes: &[u8]| read_pcd(bytes).map(|c| format!("{c:?}"));
            // Debug text, so that NaN normals compare equal.
            let read = |bytes: &[u8]| read(bytes).map_err(|e| e.to_string());
            let want = read(ascii.as_bytes());
            assert_eq!(read(&binary), want, "case {case}, binary");
            // LZF cannot pack a few bytes smaller; PCL writes no file then.
            if let Ok(packed) = lzf::compress(&soa) {
                let mut compressed = format!("{head}DATA binary_compressed\n").into_bytes();
                compressed.extend((packed.len() as u32).to_le_bytes());
                compressed.extend((soa.len() as u32).to_le_bytes());
                compressed.extend(packed);
                assert_eq!(read(&compressed), want, "case {case}, binary_compressed");
            }
            if n > 0 && want.is_err() {
                panic!("case {case}: {want:?}");
            }
        }
    }

    #[test]
    fn all_three_encodings_drop_nan() {
        check(read_pcd(ascii().as_bytes()).unwrap());
        check(read_pcd(&binary()).unwrap());
        check(read_pcd(&compressed()).unwrap());
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        check(read_pcd(format!("\u{feff}{}", ascii()).as_bytes()).unwrap());
    }

    #[test]
    fn integer_fields_and_counts() {
        let text =
            "FIELDS j x y z\nSIZE 2 1 2 8\nTYPE I I U I\nCOUNT 2 1 1 1\nPOINTS 1\nDATA binary\n";
        let mut bytes = text.as_bytes().to_vec();
        bytes.extend([0, 0, 0, 0, 0xfe, 0x34, 0x12]);
        bytes.extend((-5i64).to_le_bytes());
        let cloud = read_pcd(&bytes).unwrap();
        assert_eq!(cloud.points, vec![[-2.0, 4660.0, -5.0]]);
    }

    fn err(bytes: &[u8]) -> String {
        format!("{:#}", read_pcd(bytes).unwrap_err())
    }

    #[test]
    fn truncation_is_reported() {
        let b = binary();
        assert_eq!(
            err(&b[..b.len() - 1]),
            "expected 3 points, file ends after 2"
        );
        let c = compressed();
        assert!(err(&c[..c.len() - 1]).contains("compressed data is truncated"));
        let a = ascii();
        let a = a.trim_end().rsplit_once('\n').unwrap().0;
        assert_eq!(err(a.as_bytes()), "expected 3 points, file ends after 2");
    }

    #[test]
    fn absurd_counts_are_errors_not_allocations() {
        let huge = "FIELDS x y z\nPOINTS 18446744073709551615\nDATA";
        assert!(err(format!("{huge} binary\n").as_bytes()).contains("file ends after 0"));
        assert!(err(format!("{huge} ascii\n").as_bytes()).contains("file ends after 0"));
        assert!(err(format!("{huge} binary_compressed\n").as_bytes()).contains("too many"));
    }

    #[test]
    fn zero_or_huge_xyz_counts_are_header_errors() {
        // Each encoding once: COUNT 0 used to index past the tokens
        // (ascii), decode from an empty slice (binary) or make a zero
        // stride (COUNT 0 0 0); a huge COUNT overflowed SIZE × COUNT.
        for data in [
            "ascii\n1 2\n3 4\n",
            "binary\nabcdefgh",
            "binary_compressed\n",
        ] {
            for counts in ["1 1 0", "0 0 0"] {
                let file = format!("FIELDS x y z\nCOUNT {counts}\nPOINTS 2\nDATA {data}");
                assert_eq!(
                    err(file.as_bytes()),
                    format!(
                        "malformed PCD header: line 2: COUNT 0 for field '{}': \
                         x, y and z need a COUNT of at least 1",
                        if counts == "0 0 0" { "x" } else { "z" }
                    )
                );
            }
            let file = format!(
                "FIELDS x y z\nCOUNT 1 1 {}\nPOINTS 2\nDATA {data}",
                usize::MAX
            );
            assert!(
                err(file.as_bytes()).starts_with("malformed PCD header: line 2: COUNT 1844"),
                "{}",
                err(file.as_bytes())
            );
        }
    }

    #[test]
    fn fields_of_count_zero_hold_no_data() {
        let text = "FIELDS x pad y z\nCOUNT 1 0 1 1\nPOINTS 1\nDATA binary\n";
        let mut bytes = text.as_bytes().to_vec();
        [1f32, 2.0, 3.0]
            .iter()
            .for_each(|c| bytes.extend(c.to_le_bytes()));
        assert_eq!(read_pcd(&bytes).unwrap().points, vec![[1.0, 2.0, 3.0]]);
        let text = "FIELDS x pad y z\nCOUNT 1 0 1 1\nPOINTS 1\nDATA ascii\n1 2 3\n";
        assert_eq!(
            read_pcd(text.as_bytes()).unwrap().points,
            vec![[1.0, 2.0, 3.0]]
        );
    }

    #[test]
    fn width_times_height_must_not_wrap() {
        let file = "FIELDS x y z\nWIDTH 4294967296\nHEIGHT 4294967296\nDATA ascii\n1 2 3\n";
        assert_eq!(
            err(file.as_bytes()),
            "malformed PCD header: line 4: WIDTH 4294967296 × HEIGHT 4294967296 \
             is too many points (and no POINTS)"
        );
    }

    #[test]
    fn header_and_value_errors() {
        assert!(err(b"FIELDS x y z\nPOINTS 1\n").contains("no DATA line"));
        assert!(err(b"FIELDS x y z\nSIZE 2 2 2\nPOINTS 1\nDATA ascii\n")
            .contains("line 4: unsupported type F of size 2"));
        assert!(
            err(b"FIELDS x y z\nSIZE 4 4\nPOINTS 1\nDATA ascii\n").contains("SIZE has 2 entries")
        );
        assert!(err(b"FIELDS a b c\nPOINTS 1\nDATA ascii\n1 2 3\n").contains("no x, y and z"));
        assert!(err(b"FIELDS x y z\nPOINTS 1\nDATA lzma\n").contains("line 3: unsupported DATA"));
        assert_eq!(
            err(b"FIELDS x y z\nPOINTS 2\nDATA ascii\n1 2 3\n1 zz 3\n"),
            "line 5: 'zz' is not a number"
        );
        assert_eq!(
            err(b"FIELDS x y z\nPOINTS 1\nDATA ascii\n1 2\n"),
            "line 4: expected 3 values, found 2"
        );
    }
}
