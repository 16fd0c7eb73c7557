//! PCD (Point Cloud Library) reading: `DATA ascii`, `binary` and
//! `binary_compressed`.
//!
//! The header lists the fields of a point (FIELDS, SIZE, TYPE, COUNT); x, y
//! and z may have any numeric type. Kept besides: `normal_x`, `normal_y`,
//! `normal_z`, and the colour PCL packs into one field, `rgb` (a 4-byte
//! float whose bits are 0x00RRGGBB) or `rgba` (a 4-byte unsigned integer,
//! 0xAARRGGBB; the alpha is not kept). Every other field of COUNT 1
//! (`intensity`, `curvature`, `label`, …) is kept as the file's own value
//! ([`ScalarField`], in the PLY type of its TYPE and SIZE; 64-bit integers
//! as doubles); padding `_` and COUNT > 1 descriptors are skipped by
//! their size.
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

use super::ply::Scalar;
use super::{
    capacity, column_triples, columns_of_triples, cut_after_newlines, is_written_name, lines,
    mixed_line_ending, strip_bom, truncated, Cloud, Colours, Format, HeaderEol, Point3,
    ScalarField, PIECE_BYTES,
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

/// The fields the reader keeps: x, y, z and, if present, a normal and
/// the packed colour (its field three times, so that it is read as the
/// others are; unpacked at the end).
struct Wanted {
    xyz: [usize; 3],
    normal: Option<[usize; 3]>,
    colour: Option<[usize; 3]>,
    /// Whether the colour field is a float (`rgb`) rather than an integer.
    colour_is_float: bool,
    /// The other fields of COUNT 1, the file's own values.
    own: Vec<usize>,
    /// `own` in triples, as the points are read (the last padded with its
    /// last field).
    own_triples: Vec<[usize; 3]>,
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
    Ok(keep_finite(raw, &header, &wanted))
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
    // A packed colour is four bytes; any other size is not PCL's.
    let colour = f("rgb")
        .or_else(|| f("rgba"))
        .filter(|&c| header.fields[c].size == 4);
    let mut taken: Vec<usize> = xyz
        .into_iter()
        .chain(normal.into_iter().flatten())
        .collect();
    taken.extend(colour);
    let mut own: Vec<usize> = Vec::new();
    for (k, field) in header.fields.iter().enumerate() {
        let name = field.name.as_str();
        let repeated = own.iter().any(|&o| header.fields[o].name == name);
        let packed = matches!(name, "rgb" | "rgba" | "_");
        if field.count == 1 && !taken.contains(&k) && !packed && !is_written_name(name) && !repeated
        {
            own.push(k);
        }
    }
    let own_triples = column_triples(&own);
    Ok(Wanted {
        xyz,
        normal,
        colour: colour.map(|c| [c; 3]),
        colour_is_float: colour.is_some_and(|c| header.fields[c].ty == 'F'),
        own,
        own_triples,
    })
}

/// The PLY type that holds a PCD field's values: its own for integers of
/// up to 4 bytes and floats, `double` for 8-byte integers.
fn kind_of(field: &Field) -> Scalar {
    match (field.ty, field.size) {
        ('F', 4) => Scalar::F32,
        ('U', 1) => Scalar::U8,
        ('U', 2) => Scalar::U16,
        ('U', 4) => Scalar::U32,
        ('I', 1) => Scalar::I8,
        ('I', 2) => Scalar::I16,
        ('I', 4) => Scalar::I32,
        _ => Scalar::F64,
    }
}

/// A PCL packed colour, read as a number, as RGBA in 0..1: a float's bits
/// or an integer's value hold 0x??RRGGBB.
fn unpack_colour(value: f64, is_float: bool) -> [f64; 4] {
    let bits = if is_float {
        (value as f32).to_bits()
    } else {
        value as u32
    };
    let channel = |shift: u32| f64::from((bits >> shift) & 0xff) / 255.0;
    [channel(16), channel(8), channel(0), 1.0]
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
    /// The packed colour field, three times.
    colours: Option<Vec<Point3>>,
    /// The file's own values, in [`Wanted::own_triples`].
    own: Vec<Vec<Point3>>,
}

impl Raw {
    fn new(wanted: &Wanted, n: usize) -> Self {
        Raw {
            points: Vec::with_capacity(capacity(n)),
            normals: wanted.normal.map(|_| Vec::with_capacity(capacity(n))),
            colours: wanted.colour.map(|_| Vec::with_capacity(capacity(n))),
            own: vec![Vec::with_capacity(capacity(n)); wanted.own_triples.len()],
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
        if let (Some([c, _, _]), Some(colours)) = (wanted.colour, self.colours.as_mut()) {
            colours.push([value(c)?; 3]);
        }
        for (own, &[a, b, c]) in self.own.iter_mut().zip(&wanted.own_triples) {
            own.push([value(a)?, value(b)?, value(c)?]);
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
        if let (Some(colours), Some(more)) = (raw.colours.as_mut(), piece.colours.as_ref()) {
            colours.extend_from_slice(&more[..take]);
        }
        for (own, more) in raw.own.iter_mut().zip(&piece.own) {
            own.extend_from_slice(&more[..take]);
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
    colours: Option<Vec<Point3>>,
    own: Vec<Vec<Point3>>,
    lines: usize,
    /// The piece's first error; parsing stops there.
    error: Option<(usize, String)>,
}

fn parse_ascii_piece(text: &str, wanted: &Wanted, layout: &AsciiLayout) -> AsciiPiece {
    let mut piece = AsciiPiece {
        normals: wanted.normal.map(|_| Vec::new()),
        colours: wanted.colour.map(|_| Vec::new()),
        own: vec![Vec::new(); wanted.own_triples.len()],
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
    let colour = match wanted.colour {
        Some([c, _, _]) => Some([value(c)?; 3]),
        None => None,
    };
    let own = wanted
        .own_triples
        .iter()
        .map(|&[a, b, c]| Ok([value(a)?, value(b)?, value(c)?]))
        .collect::<Result<Vec<Point3>, String>>()?;
    for (values, triple) in piece.own.iter_mut().zip(own) {
        values.push(triple);
    }
    piece.points.push(point);
    if let (Some(normal), Some(normals)) = (normal, piece.normals.as_mut()) {
        normals.push(normal);
    }
    if let (Some(colour), Some(colours)) = (colour, piece.colours.as_mut()) {
        colours.push(colour);
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
        colours: wanted.colour.map(triple),
        own: wanted.own_triples.iter().map(|&t| triple(t)).collect(),
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

/// The points with finite coordinates, with their normals, colours and
/// the file's own values.
fn keep_finite(raw: Raw, header: &Header, wanted: &Wanted) -> Cloud {
    let finite: Vec<bool> = raw
        .points
        .par_iter()
        .map(|p| p.iter().all(|c| c.is_finite()))
        .collect();
    let dropped = finite.iter().filter(|&&ok| !ok).count();
    let keep = |v: Vec<Point3>| -> Vec<Point3> {
        if dropped == 0 {
            return v;
        }
        v.into_iter()
            .zip(&finite)
            .filter(|(_, &ok)| ok)
            .map(|(p, _)| p)
            .collect()
    };
    let colours = raw.colours.map(|packed| Colours {
        rgba: keep(packed)
            .par_iter()
            .map(|c| unpack_colour(c[0], wanted.colour_is_float))
            .collect(),
        alpha: false,
    });
    Cloud {
        points: keep(raw.points),
        normals: raw.normals.map(keep),
        scalars: own_fields(header, wanted, raw.own.into_iter().map(&keep).collect()),
        dropped_non_finite: dropped,
        format: Format::Pcd,
        scale_offset: None,
        colours,
        grid: None,
    }
}

/// The file's own values from their triples: each field under its name,
/// in the PLY type of its PCD type ([`ScalarField::read_as`]).
fn own_fields(header: &Header, wanted: &Wanted, triples: Vec<Vec<Point3>>) -> Vec<ScalarField> {
    let values = columns_of_triples(&triples, wanted.own.len());
    wanted
        .own
        .iter()
        .zip(values)
        .map(|(&f, values)| {
            let field = &header.fields[f];
            ScalarField::read_as(field.name.clone(), kind_of(field), values)
        })
        .collect()
}

#[cfg(test)]
mod tests;
