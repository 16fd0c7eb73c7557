//! Step 1 of the Delaunay path: the plane the cloud is triangulated in,
//! its best-fit plane or the scanner's image.

use super::*;

/// Step 1, **projection**: the cloud's best-fit plane, or with a view the
/// scanner's image, with (u, v) coordinates relative to the first point
/// (or the scanner), which keeps precision for clouds far from the origin.
pub(super) struct Projection {
    pub(super) frame: Frame,
    pub(super) origin: Point3,
    /// For a view from a position: the image is the camera's, each point
    /// divided by its depth along the axis (−`frame.normal`) and scaled by
    /// this, the points' mean depth, so that image lengths at the cloud are
    /// about the cloud's own (the β-scaled distances of steps 3 and 4 hold).
    pub(super) perspective: Option<f64>,
    /// What the errors call the plane.
    pub(super) onto: &'static str,
}

pub(super) const BEST_FIT_PLANE: &str = "the best-fit plane";
const SCANNER_IMAGE: &str = "the scanner's image";

impl Projection {
    /// The plane of all the points (PCA, [`fit_plane`]), or the image of
    /// the detection's view: along a direction, the plane square to it;
    /// from a position, the camera's image about the mean line of sight
    /// to the points, its normal towards the scanner (faces then face
    /// it). Refuses a point beside or behind the scanner's position,
    /// which no camera image holds.
    pub(super) fn new(cloud: &[Point3], view: Option<View>) -> Result<Self, DelaunayError> {
        match view {
            None => {
                let all: Vec<u32> = (0..cloud.len() as u32).collect();
                Ok(Projection {
                    frame: fit_plane(cloud, &all),
                    origin: cloud[0],
                    perspective: None,
                    onto: BEST_FIT_PLANE,
                })
            }
            Some(View::Along(direction)) => Ok(Projection {
                frame: Frame::of_normal(unit(direction)),
                origin: cloud[0],
                perspective: None,
                onto: SCANNER_IMAGE,
            }),
            Some(View::From(eye)) => {
                let axis = View::camera_axis(eye, cloud);
                let mut depths = 0.0;
                for (index, &p) in cloud.iter().enumerate() {
                    depths += View::camera_depth(sub(p, eye), axis)
                        .ok_or(DelaunayError::NotInView { index })?;
                }
                Ok(Projection {
                    frame: Frame::of_normal(axis.map(|c| -c)),
                    origin: eye,
                    perspective: Some(depths / cloud.len() as f64),
                    onto: SCANNER_IMAGE,
                })
            }
        }
    }

    /// `p` in the image's (u, v) coordinates.
    pub(super) fn to2(&self, p: Point3) -> [f64; 2] {
        let d = sub(p, self.origin);
        let (u, v) = (dot(d, self.frame.u), dot(d, self.frame.v));
        match self.perspective {
            None => [u, v],
            Some(scale) => {
                let depth = -dot(d, self.frame.normal);
                [scale * u / depth, scale * v / depth]
            }
        }
    }

    /// The line of sight through `p` (unit): the plane's normal, or from
    /// the scanner's position.
    pub(super) fn sight(&self, p: Point3) -> Point3 {
        match self.perspective {
            None => self.frame.normal,
            Some(_) => unit(sub(p, self.origin)),
        }
    }
}
