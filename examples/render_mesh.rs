//! Draws meshes to PNG for the docs: flat-shaded, z-buffered, seen along a
//! tilted best-fit normal of the first mesh so that an envelope's far side
//! and skirts show.
//!
//! `cargo run --release --example render_mesh -- OUT.png MESH [MESH...]`
//! (several meshes are drawn side by side, in the same view and scale).

use std::path::Path;

use trim::Point3;

const SIZE: (usize, usize) = (700, 520);

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (out, inputs) = args
        .split_first()
        .ok_or_else(|| anyhow::anyhow!("usage: OUT.png MESH..."))?;
    let meshes: Vec<meshtrim::io::Mesh> = inputs
        .iter()
        .map(|p| meshtrim::io::read_mesh(Path::new(p)))
        .collect::<anyhow::Result<_>>()?;
    let view = view_of(&meshes[0].vertices);
    let projected: Vec<Vec<Point3>> = meshes
        .iter()
        .map(|m| m.vertices.iter().map(|&v| view(v)).collect())
        .collect();
    let bounds = projected.iter().flatten().fold(
        [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, p| {
            [
                b[0].min(p[0]),
                b[1].max(p[0]),
                b[2].min(p[1]),
                b[3].max(p[1]),
            ]
        },
    );
    let scale = ((SIZE.0 - 40) as f64 / (bounds[1] - bounds[0]))
        .min((SIZE.1 - 40) as f64 / (bounds[3] - bounds[2]));
    let width = SIZE.0 * meshes.len();
    let mut rgb = vec![255u8; width * SIZE.1 * 3];
    for (k, (mesh, pts)) in meshes.iter().zip(&projected).enumerate() {
        let mut depth = vec![f64::NEG_INFINITY; SIZE.0 * SIZE.1];
        let screen: Vec<[f64; 3]> = pts
            .iter()
            .map(|p| {
                [
                    20.0 + (p[0] - bounds[0]) * scale,
                    SIZE.1 as f64 - 20.0 - (p[1] - bounds[2]) * scale,
                    p[2],
                ]
            })
            .collect();
        for f in mesh.faces.as_deref().unwrap_or(&[]) {
            let [a, b, c] = f.map(|i| pts[i as usize]);
            let n = cross(sub(b, a), sub(c, a));
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt().max(1e-300);
            // Two-sided Lambert light from the viewer, a little from above.
            let light = (n[2] / len).abs() * 0.75 + (n[1] / len).abs() * 0.1 + 0.15;
            let front = n[2] >= 0.0;
            let base = if front {
                [120.0, 160.0, 210.0]
            } else {
                [215.0, 150.0, 110.0]
            };
            let colour = base.map(|c: f64| (c * light).min(255.0) as u8);
            fill(
                &mut rgb,
                width,
                k * SIZE.0,
                &mut depth,
                f.map(|i| screen[i as usize]),
                colour,
            );
        }
    }
    let file = std::io::BufWriter::new(std::fs::File::create(out)?);
    let mut encoder = png::Encoder::new(file, width as u32, SIZE.1 as u32);
    encoder.set_color(png::ColorType::Rgb);
    encoder.write_header()?.write_image_data(&rgb)?;
    Ok(())
}

/// A view: best-fit plane axes of `vertices`, tilted by 35° about u.
fn view_of(vertices: &[Point3]) -> impl Fn(Point3) -> Point3 {
    let members: Vec<u32> = (0..vertices.len() as u32).collect();
    let f = trim::fit_plane(vertices, &members);
    let (c, s) = (35f64.to_radians().cos(), 35f64.to_radians().sin());
    let v = [0, 1, 2].map(|i| c * f.v[i] + s * f.normal[i]);
    let n = [0, 1, 2].map(|i| -s * f.v[i] + c * f.normal[i]);
    let u = f.u;
    move |p: Point3| {
        let d = |a: [f64; 3]| a[0] * p[0] + a[1] * p[1] + a[2] * p[2];
        [d(u), d(v), d(n)]
    }
}

fn sub(a: Point3, b: Point3) -> Point3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: Point3, b: Point3) -> Point3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Rasterises one triangle (screen x, y, depth) with a z-buffer.
fn fill(
    rgb: &mut [u8],
    width: usize,
    x0: usize,
    depth: &mut [f64],
    t: [[f64; 3]; 3],
    colour: [u8; 3],
) {
    let (w, h) = SIZE;
    let min_x = t
        .iter()
        .map(|p| p[0])
        .fold(f64::INFINITY, f64::min)
        .max(0.0) as usize;
    let max_x = (t
        .iter()
        .map(|p| p[0])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as usize)
        .min(w - 1);
    let min_y = t
        .iter()
        .map(|p| p[1])
        .fold(f64::INFINITY, f64::min)
        .max(0.0) as usize;
    let max_y = (t
        .iter()
        .map(|p| p[1])
        .fold(f64::NEG_INFINITY, f64::max)
        .ceil() as usize)
        .min(h - 1);
    let area =
        (t[1][0] - t[0][0]) * (t[2][1] - t[0][1]) - (t[1][1] - t[0][1]) * (t[2][0] - t[0][0]);
    if area.abs() < 1e-12 {
        return;
    }
    for y in min_y..=max_y {
        for x in min_x..=max_x {
            let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
            let edge = |a: [f64; 3], b: [f64; 3]| {
                ((b[0] - a[0]) * (py - a[1]) - (b[1] - a[1]) * (px - a[0])) / area
            };
            let (l0, l1, l2) = (edge(t[1], t[2]), edge(t[2], t[0]), edge(t[0], t[1]));
            if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                continue;
            }
            let z = l0 * t[0][2] + l1 * t[1][2] + l2 * t[2][2];
            if z > depth[y * w + x] {
                depth[y * w + x] = z;
                let at = (y * width + x0 + x) * 3;
                rgb[at..at + 3].copy_from_slice(&colour);
            }
        }
    }
}
