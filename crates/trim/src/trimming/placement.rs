//! Where the cloud lies against the mesh, for the error of a trim that
//! found no part of the mesh supported (meshtrim's own diagnosis; no
//! section of the paper). A cloud in other units than its mesh is tried
//! at each usual unit ratio: scaled by the right one, its points lie
//! within the cloud's reach of the mesh.

use super::*;
use crate::error::Placement;
use crate::spatial::closest_face::{bounds, Aabb};

/// Unit pairs a cloud and its mesh may be given in: how many of the
/// second make one of the first.
const UNIT_RATIOS: [(f64, &str, &str); 8] = [
    (1000.0, "metres", "millimetres"),
    (100.0, "metres", "centimetres"),
    (10.0, "centimetres", "millimetres"),
    (25.4, "inches", "millimetres"),
    (1.0 / 0.0254, "metres", "inches"),
    (12.0, "feet", "inches"),
    (304.8, "feet", "millimetres"),
    (1.0 / 0.3048, "metres", "feet"),
];

/// Cloud points tried against the mesh per unit ratio.
const SAMPLE: usize = 256;
/// The share of them that must lie within reach of the mesh. Measured on
/// the fixture blade's Poisson envelope: every point at the right ratio,
/// at most 70 % at a wrong one (a closed envelope spans more space than
/// its cloud, so points scaled wrongly still pass near it).
const ON_MESH: f64 = 0.95;

/// Where `cloud` (with its local resolutions `beta`) lies against `mesh`,
/// a point counting as on the mesh within `reach` β of it.
pub(super) fn placement(mesh: &Mesh, cloud: &[Point3], beta: &[f64], reach: f64) -> Placement {
    if let Some(units) = unit_ratio(mesh, cloud, beta, reach) {
        return units;
    }
    if mesh.vertices.is_empty() || cloud.is_empty() {
        return Placement::Overlapping;
    }
    let mesh_box = bounds(mesh.vertices.iter().copied());
    let cloud_box = bounds(cloud.iter().copied());
    let (mesh_diagonal, cloud_diagonal) = (diagonal(mesh_box), diagonal(cloud_box));
    let ratio = cloud_diagonal / mesh_diagonal;
    if mesh_diagonal > 0.0 && cloud_diagonal > 0.0 && !(1.0 / 3.0..=3.0).contains(&ratio) {
        Placement::Scaled { ratio }
    } else if meet(mesh_box, cloud_box) {
        Placement::Overlapping
    } else {
        Placement::Apart {
            distance: centre_distance(mesh_box, cloud_box),
            mesh_diagonal,
        }
    }
}

/// The unit ratio, either way round, that puts most of a sample of the
/// cloud within reach of the mesh, if it puts nearly all there.
fn unit_ratio(mesh: &Mesh, cloud: &[Point3], beta: &[f64], reach: f64) -> Option<Placement> {
    if mesh.faces.is_empty() || cloud.is_empty() || beta.len() != cloud.len() {
        return None;
    }
    let index = FaceIndex::new(mesh);
    let every_face = vec![0; mesh.faces.len()];
    let one_piece = index.labels(&every_face);
    let sample: Vec<usize> = (0..cloud.len())
        .step_by(cloud.len().div_ceil(SAMPLE))
        .collect();
    let mut scratch = Scratch::default();
    let mut on_mesh = |factor: f64| {
        sample
            .iter()
            .filter(|&&i| {
                let p = cloud[i].map(|c| c * factor);
                let within = reach * beta[i] * factor;
                index
                    .nearest_label(p, within, &one_piece, &mut scratch)
                    .is_some()
            })
            .count()
    };
    let candidates = UNIT_RATIOS.iter().flat_map(|&(ratio, large, small)| {
        [(ratio, (large, small)), (1.0 / ratio, (small, large))]
    });
    let (hits, factor, units) = candidates
        .map(|(factor, units)| (on_mesh(factor), factor, units))
        .fold(
            (0, 1.0, ("", "")),
            |best, c| if c.0 > best.0 { c } else { best },
        );
    (hits > 0 && hits as f64 >= ON_MESH * sample.len() as f64)
        .then_some(Placement::Units { factor, units })
}

fn diagonal((low, high): Aabb) -> f64 {
    dist2(low, high).sqrt()
}

fn meet(a: Aabb, b: Aabb) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

fn centre_distance(a: Aabb, b: Aabb) -> f64 {
    let centre = |(low, high): Aabb| lerp(low, high, 0.5);
    dist2(centre(a), centre(b)).sqrt()
}
