//! `[[probe]]`: what is sampled every output interval, and the reference curve drawn with it.

use serde::{Deserialize, Serialize};

/// Probe kind.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ProbeKind {
    /// Displacement of the FE node nearest `point` (reference configuration), `component` x or y.
    NodeDisplacement,
    /// Energy: `part` = kinetic | strain | potential | total, of `solid` (one solid), or of `of` = structure |
    /// fluid | all (default all).
    Energy,
    /// Extreme fluid particle coordinate along `component` (the front of a dam break).
    SurgeFront,
    /// Highest fluid particle among those with x ≤ `x_max` (the residual column of a dam break).
    ColumnHeight,
    /// Height of the water surface above `point` (the gauge's foot) along the vertical line through it: where the
    /// SPH fluid fraction passes ½, the highest such surface (a gauge looking down; 0 where the line is dry).
    WaterLevel,
    /// SPH-interpolated pressure at `point`; optionally the mean over a sensor face (`radius`, `normal`) and over
    /// the sampling interval (`average = "interval"`).
    Pressure,
    /// The load the fluid puts on the structure through the contact (the sum of every interface node's contact
    /// impulse, `interface_load` in the frames), `component` x or y, of `solid` (default every solid): the mean
    /// over the sampling interval, total impulse since the last sample divided by the time since it [N per unit
    /// thickness].
    InterfaceLoad,
}

/// What a pressure probe's sample stands for in time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Average {
    /// The value at the output time (the raw value).
    #[default]
    None,
    /// The time mean over the sampling interval: every SPH step's value since the last sample weighted by its
    /// step, as a sensor of finite bandwidth integrates (the fluid node computes it, `docs/PROTOCOL.md` §7).
    Interval,
}

/// Which bodies an energy probe sums over.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyOf {
    /// Every solid.
    Structure,
    /// The water.
    Fluid,
    /// Both.
    All,
}

/// A vector component.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    /// x.
    X,
    /// y.
    Y,
}

impl Component {
    /// Index into a 2-vector.
    pub fn index(self) -> usize {
        match self {
            Component::X => 0,
            Component::Y => 1,
        }
    }
}

/// Energy part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EnergyPart {
    /// ½ m v².
    Kinetic,
    /// Stored elastic energy.
    Strain,
    /// −m g·x relative to the reference configuration.
    Potential,
    /// Sum of the three.
    Total,
}

/// `[[probe]]`. Flat so that a missing or misplaced key gets a precise message.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    /// Column name in `probes.csv`.
    pub name: String,
    /// Kind.
    pub kind: ProbeKind,
    /// Solid name (node_displacement; optional for energy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub solid: Option<String>,
    /// Point (node_displacement).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub point: Option<[f64; 2]>,
    /// Component (node_displacement).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub component: Option<Component>,
    /// Energy part (energy).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub part: Option<EnergyPart>,
    /// Bodies an energy probe covers (energy; default all).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub of: Option<EnergyOf>,
    /// Half the width of a pressure sensor's face [m] (pressure; default 0, a point): the sample is the mean of the
    /// pressure at points spread over the face, a quarter spacing apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// The sensor face's outward normal, pointing into the fluid (pressure, with a `radius` > 0); the face lies
    /// across it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal: Option<[f64; 2]>,
    /// `none` (default): the value at the output time; `interval`: its time mean since the last sample (pressure).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub average: Option<Average>,
    /// Column probes look at particles with x ≤ x_max (column_height).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x_max: Option<f64>,
    /// Reference data drawn in the plot: a CSV file (relative to the scene file) and its columns.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<ReferenceSpec>,
}

/// Reference curve for a probe's plot.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceSpec {
    /// CSV file with a header row; relative paths are relative to the scene file.
    pub file: String,
    /// Column holding time.
    pub t: String,
    /// Column holding the value.
    pub value: String,
    /// Label in the legend.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
    /// Multiply the value column by this (e.g. to change units).
    #[serde(default = "one")]
    pub scale: f64,
    /// Multiply the time column by this (e.g. to turn a dimensionless time into seconds).
    #[serde(default = "one")]
    pub t_scale: f64,
    /// Add this to the time column (after scaling).
    #[serde(default)]
    pub t_offset: f64,
}

fn one() -> f64 {
    1.0
}
