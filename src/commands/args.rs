//! Argument groups that several commands share: the stages' options and
//! the scanner's view, with their value parsers.

use std::path::Path;

use clap::Args;
use trim::{BpdOptions, EdgeOptions, View};

use crate::io::edges_out::step::LengthUnit;
use crate::io::edges_out::{EdgeFileOptions, EdgesFormat};
use crate::stages::Stages;

/// The options of detection and edge reconstruction that every command
/// after `detect` shares.
#[derive(Debug, Clone, PartialEq, Args)]
pub struct StageArgs {
    /// Neighbourhood size of boundary detection, the point itself included.
    #[arg(long, default_value_t = 30, value_parser = parse_k)]
    pub k: usize,
    /// Use the paper's isotropic detection, without the sampling-tensor map.
    #[arg(long)]
    pub no_anisotropy: bool,
    /// Use the paper's edges, through the boundary points, instead of the
    /// estimated physical edge half a row beyond them: for clouds whose
    /// outermost samples lie on the edge itself (a mesh's own vertices,
    /// points sampled from CAD).
    #[arg(long)]
    pub no_offset: bool,
    /// Where a range scanner saw the cloud from.
    #[command(flatten)]
    pub view: ViewArgs,
}

impl StageArgs {
    /// The stages' options.
    pub fn stages(&self) -> Stages {
        Stages {
            detection: bpd_options(self.k, self.no_anisotropy, &self.view),
            edges: EdgeOptions {
                offset: !self.no_offset,
            },
        }
    }
}

/// How an edges file is written, beyond the format its extension names.
#[derive(Debug, Clone, Copy, PartialEq, Args)]
pub struct EdgeFileArgs {
    /// The length unit declared (help: `UNITS_HELP`).
    #[arg(long, value_enum, default_value_t = LengthUnit::Mm, help = UNITS_HELP)]
    pub units: LengthUnit,
    /// DXF splines (help: `DXF_SPLINES_HELP`).
    #[arg(long, help = DXF_SPLINES_HELP)]
    pub dxf_splines: bool,
}

/// `--units`' help, for every command that writes edges.
pub(crate) const UNITS_HELP: &str = "The length unit a STEP, IGES or DXF-with-splines output declares (a cloud's file does not say its unit): mm, m or in";

/// `--dxf-splines`' help.
pub(crate) const DXF_SPLINES_HELP: &str = "DXF output: also each edge as a cubic SPLINE on layer SPLINES, the curve of the STEP output (the file is then AutoCAD 2000, not R12, and declares --units)";

impl EdgeFileArgs {
    /// The writers' options.
    pub fn options(&self) -> EdgeFileOptions {
        EdgeFileOptions {
            units: self.units,
            dxf_splines: self.dxf_splines,
        }
    }

    /// Refuses `--dxf-splines` unless the edges go to a DXF file
    /// (`output`, none when the command writes no edges).
    pub fn check(&self, output: Option<&Path>) -> anyhow::Result<()> {
        if !self.dxf_splines {
            return Ok(());
        }
        match output {
            None => anyhow::bail!("--dxf-splines needs an edges output: --edges FILE.dxf"),
            Some(path) if EdgesFormat::from_path(path) != Some(EdgesFormat::Dxf) => {
                anyhow::bail!(
                    "{}: --dxf-splines writes splines into a .dxf file, and this is not one",
                    path.display()
                )
            }
            Some(_) => Ok(()),
        }
    }
}

/// Where a range scanner (a depth camera, a laser line or structured-light
/// scanner) saw the cloud from, when it is known. Such scanners err along
/// their line of sight; with it, detection projects each neighbourhood
/// along it instead of along the neighbourhood's normal, so that depth
/// noise and the terraces of a quantised depth do not open gaps where the
/// surface is inclined to the scanner (docs/bpd.md, "Scanner's line of
/// sight").
#[derive(Debug, Clone, Copy, PartialEq, Default, Args)]
pub struct ViewArgs {
    /// The scanner's line of sight (help: `VIEW_ALONG_HELP`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_direction, allow_hyphen_values = true, conflicts_with = "view_from", help = VIEW_ALONG_HELP, long_help = VIEW_ALONG_LONG_HELP)]
    pub view_along: Option<[f64; 3]>,
    /// The scanner's position (help: `VIEW_FROM_HELP`).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vector, allow_hyphen_values = true, help = VIEW_FROM_HELP, long_help = VIEW_FROM_LONG_HELP)]
    pub view_from: Option<[f64; 3]>,
}

// The view options' help, one text for every command that takes them:
// the one line `-h` shows, and under it in `--help` why the view matters.
macro_rules! view_along_help {
    () => {
        "The scanner's line of sight as a direction X,Y,Z in the cloud's frame (either sense), for a distant scanner or a frame whose axis it looked along, e.g. 0,0,1"
    };
}
macro_rules! view_from_help {
    () => {
        "The scanner's position X,Y,Z in the cloud's frame (a depth camera's centre: 0,0,0 for a cloud in the camera's own frame); the line of sight to each point runs from there"
    };
}
macro_rules! view_why {
    () => {
        "Range scanners (depth cameras, laser line and structured-light scanners) err along their line of sight. Given it, detection projects each neighbourhood along it instead of along the neighbourhood's normal, so that depth noise and the terraces of a quantised depth do not open gaps where the surface is inclined to the scanner (docs/bpd.md, \"Scanner's line of sight\"), and the edges' loops are traced as the border of the cloud in the scanner's image plane, so ragged borders close (docs/edges.md); `mesh` triangulates the cloud in that image, where a single-view scan is a height field whatever the object's shape (docs/trimming.md). Without it, the paper's projection along each neighbourhood's normal; ragged borders are then traced in the cloud's own best-fit plane when that plane sees the cloud as a height field."
    };
}
/// `--view-along`'s one-line help.
pub(crate) const VIEW_ALONG_HELP: &str = view_along_help!();
/// `--view-from`'s one-line help.
pub(crate) const VIEW_FROM_HELP: &str = view_from_help!();
/// `--view-along`'s help with why the view matters.
pub(crate) const VIEW_ALONG_LONG_HELP: &str = concat!(view_along_help!(), ".\n\n", view_why!());
/// `--view-from`'s help with why the view matters.
pub(crate) const VIEW_FROM_LONG_HELP: &str = concat!(view_from_help!(), ".\n\n", view_why!());

impl ViewArgs {
    /// The view, if one was given.
    pub fn view(&self) -> Option<View> {
        self.view_along
            .map(View::Along)
            .or(self.view_from.map(View::From))
    }
}

/// Boundary detection's options from the command line's.
pub(crate) fn bpd_options(k: usize, no_anisotropy: bool, view: &ViewArgs) -> BpdOptions {
    BpdOptions {
        k,
        anisotropy: !no_anisotropy,
        view: view.view(),
    }
}

/// `--k`: a whole number of at least [`BpdOptions::MIN_K`]. Checked here,
/// not only by detection, so that a value it would refuse is a usage error
/// before any file is read, not once per file of a batch.
pub(crate) fn parse_k(text: &str) -> Result<usize, String> {
    let k: usize = text.parse().map_err(|e| format!("{e}"))?;
    let min = BpdOptions::MIN_K;
    if k < min {
        return Err(format!(
            "k = {k} is too small: boundary detection needs k >= {min} \
             (the point itself and at least {} neighbours)",
            min - 1
        ));
    }
    Ok(k)
}

/// A finite factor above zero, to scale a cloud by.
pub(crate) fn parse_scale(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(factor) if factor.is_finite() && factor > 0.0 => Ok(factor),
        _ => Err(format!(
            "'{text}' is not a factor: give a number above zero, e.g. 1000 for a cloud in \
             metres and a mesh in millimetres"
        )),
    }
}

/// A distance above zero (`--max-deviation`).
pub(crate) fn parse_distance(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(d) if d.is_finite() && d > 0.0 => Ok(d),
        _ => Err(format!(
            "'{text}' is not a distance: give a number above zero, in the mesh's units"
        )),
    }
}

/// Three finite numbers separated by commas.
pub(crate) fn parse_vector(text: &str) -> Result<[f64; 3], String> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected three numbers X,Y,Z separated by commas, got {} part(s)",
            parts.len()
        ));
    };
    let number = |s: &str| match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(format!("`{s}` is not a finite number")),
        Err(_) => Err(format!("`{s}` is not a number")),
    };
    Ok([number(x)?, number(y)?, number(z)?])
}

/// A line of sight: [`parse_vector`], not zero.
pub(crate) fn parse_direction(text: &str) -> Result<[f64; 3], String> {
    let v = parse_vector(text)?;
    if v == [0.0; 3] {
        return Err("a direction cannot be 0,0,0".into());
    }
    Ok(v)
}
