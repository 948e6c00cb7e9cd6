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
    /// SPH-interpolated pressure at `point`.
    Pressure,
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
