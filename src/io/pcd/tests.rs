//! Tests of the PCD reader.

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
        .map(|r| (r.points, r.normals, r.own))
        .map_err(|e| e.to_string())
    };
    let errors = crate::io::piece_tests::compare_with_one_pass(
        29,
        2000,
        15,
        |below, _| {
            let declared = below(12);
            format!(
                "FIELDS x y z normal_x normal_y normal_z intensity\nSIZE 4 4 4 4 4 4 4\n\
                 TYPE F F F F F F F\nCOUNT 1 1 1 1 1 1 1\nWIDTH {declared}\nHEIGHT 1\n\
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
    // rgba 0x00ff00ff: red and blue; kept beside the points kept.
    let colours = cloud.colours.unwrap();
    assert_eq!(colours.rgba, vec![[1.0, 0.0, 1.0, 1.0]; 2]);
    assert_eq!(cloud.dropped_non_finite, 1);
}

/// PCL's float `rgb`: the float's bits hold 0x00RRGGBB (a denormal or a
/// tiny number), read alike from ASCII and binary data.
#[test]
fn packed_float_rgb_is_read_by_its_bits() {
    let bits: u32 = 0x0012_80ff;
    let rgb = f32::from_bits(bits);
    let head = "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\n";
    let ascii = format!("{head}DATA ascii\n0 0 0 {rgb:e}\n");
    let mut binary = format!("{head}DATA binary\n").into_bytes();
    for v in [0.0f32, 0.0, 0.0, rgb] {
        binary.extend(v.to_le_bytes());
    }
    let want = [18.0 / 255.0, 128.0 / 255.0, 1.0, 1.0];
    for bytes in [ascii.as_bytes(), &binary[..]] {
        assert_eq!(read_pcd(bytes).unwrap().colours.unwrap().rgba, vec![want]);
    }
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
    let text = "FIELDS j x y z\nSIZE 2 1 2 8\nTYPE I I U I\nCOUNT 2 1 1 1\nPOINTS 1\nDATA binary\n";
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
    // Each encoding once: COUNT 0 must not index past the tokens
    // (ascii), decode from an empty slice (binary) or make a zero
    // stride (COUNT 0 0 0); a huge COUNT must not overflow SIZE × COUNT.
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
    assert!(err(b"FIELDS x y z\nSIZE 4 4\nPOINTS 1\nDATA ascii\n").contains("SIZE has 2 entries"));
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

/// Fields of COUNT 1 other than the position, normal and packed colour
/// are the file's own values, in the PLY type of their TYPE and SIZE;
/// padding, descriptors and a repeated name are not.
#[test]
fn other_fields_are_the_files_own_values() {
    let text = "VERSION 0.7\nFIELDS x y z intensity label _ curvature fpfh intensity big\n\
                SIZE 4 4 4 4 4 1 4 4 2 8\nTYPE F F F F U U F F U I\n\
                COUNT 1 1 1 1 1 3 1 2 1 1\nWIDTH 3\nHEIGHT 1\nPOINTS 3\nDATA ascii\n\
                0 0 0 0.5 7 0 0 0 0.25 1 2 3 -9\nnan 0 0 1 8 0 0 0 0 1 2 3 5\n\
                1 1 1 2 9 0 0 0 0.125 1 2 3 6\n";
    let cloud = read_pcd(text.as_bytes()).unwrap();
    let fields = crate::io::field_rows(&cloud.scalars);
    assert_eq!(
        fields,
        [
            ("intensity", Scalar::F32, &[0.5, 2.0][..]),
            ("label", Scalar::U32, &[7.0, 9.0]),
            ("curvature", Scalar::F32, &[0.25, 0.125]),
            ("big", Scalar::F64, &[-9.0, 6.0]),
        ],
        "kept beside the points kept"
    );
}
