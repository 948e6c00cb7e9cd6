//! Scenes shared by the integration tests.
#![allow(dead_code)]

use cosim_proto::scene::{parse, Scene};

/// A tank of inner width `width` holding still water `depth` deep, walls 3Δx thick below and at both sides.
pub fn still_water(width: f64, depth: f64, dx: f64, extra: &str) -> Scene {
    let t = 3.0 * dx;
    let text = format!(
        r#"
version = 1
[run]
name = "still_water"
end_time = 1.0
output_interval = 0.1
[fluid]
density = 1000.0
spacing = {dx}
{extra}
[[fluid.block]]
min = [0.0, 0.0]
max = [{width}, {depth}]
[[wall]]
min = [{mt}, {mt}]
max = [{wt}, 0.0]
[[wall]]
min = [{mt}, 0.0]
max = [0.0, {top}]
[[wall]]
min = [{width}, 0.0]
max = [{wt}, {top}]
"#,
        mt = -t,
        wt = width + t,
        top = depth * 1.4,
    );
    parse("still_water.toml", &text, &[]).expect("valid scene")
}

/// A dam break: a water column `a` wide and `2a` high at the left end of a tank `length` long.
pub fn dam_break(a: f64, length: f64, dx: f64, extra: &str) -> Scene {
    let t = 3.0 * dx;
    let text = format!(
        r#"
version = 1
[run]
name = "dam_break"
end_time = 1.0
output_interval = 0.1
[fluid]
density = 1000.0
spacing = {dx}
{extra}
[[fluid.block]]
min = [0.0, 0.0]
max = [{a}, {h}]
[[wall]]
min = [{mt}, {mt}]
max = [{lt}, 0.0]
[[wall]]
min = [{mt}, 0.0]
max = [0.0, {top}]
[[wall]]
min = [{length}, 0.0]
max = [{lt}, {top}]
"#,
        h = 2.0 * a,
        mt = -t,
        lt = length + t,
        top = 3.0 * a,
    );
    parse("dam_break.toml", &text, &[]).expect("valid scene")
}
