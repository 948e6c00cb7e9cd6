//! The inconsistencies the fuzzing puts into one message of a run: what each spoils, the strategies that draw them,
//! and the functions that apply them to a message, each returning the field the broker must name.

use cosim_proto::messages::{FemMesh, FemState, SphSetup, SphState};
use proptest::prelude::*;

/// One inconsistency, put into one message of the run.
#[derive(Clone, Debug)]
pub(crate) enum Spoil {
    Mesh(MeshSpoil),
    Fem { step: u64, how: FemSpoil },
    Setup(SetupSpoil),
    Sph { step: u64, how: SphSpoil },
}

#[derive(Clone, Debug)]
pub(crate) enum MeshSpoil {
    SegmentEnd(usize, u32),
    FewerMasses(usize),
    Mass(usize, f64),
    Node(usize, f64),
    NodeSolid(usize, u32),
    CellNode(usize, u32),
    ShortCell(usize),
    Fixed(u32),
    DtStable(f64),
    NoNodes,
    NoSolids,
    NoInterface,
    HugeCellSolid(usize),
    Scale(f64),
    ReversedCell(usize),
    SegmentTwice(usize),
    FixedTwice(usize),
    SecondSolid,
}

#[derive(Clone, Debug)]
pub(crate) enum FemSpoil {
    Id(usize, u32),
    DropId,
    ShortX,
    X(usize, f64),
    V(usize, f64),
    Collapse,
    SnapshotShort,
    StressShort,
    NoSnapshot,
    DtStable(f64),
    Seconds(f64),
}

#[derive(Clone, Debug)]
pub(crate) enum SetupSpoil {
    Spacing(f64),
    H(f64),
    Density(f64),
    Wall(usize, f64),
    DtStable(f64),
}

#[derive(Clone, Debug)]
pub(crate) enum SphSpoil {
    Id(u32),
    Duplicate,
    ShortM,
    Mass(f64),
    X(f64),
    V(f64),
    SnapshotShort,
    WallPShort,
    Rho(f64),
    DtStable(f64),
    HugeIds(usize),
}

/// Not a number a state can hold: NaN, ±∞, or finite beyond ±1e50 (`cosim_proto::validate::LARGEST`).
pub(crate) fn bad_number() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(1e200),
        Just(-1e308)
    ]
}

/// A finite speed beyond ten times the scene's fastest wave speed (the plate's, 5,000 m/s: limit 50 km/s), which
/// no run of it reaches (`cosim_proto::validate::speed_limit`).
pub(crate) fn flung() -> impl Strategy<Value = f64> {
    prop_oneof![Just(1e20), Just(-1e6), Just(5.1e4)]
}

pub(crate) fn not_positive() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(0.0),
        Just(-1.0),
        Just(-1e-300),
        Just(f64::NAN),
        Just(f64::NEG_INFINITY)
    ]
}

pub(crate) fn spoils() -> impl Strategy<Value = Spoil> {
    let mesh = prop_oneof![
        (any::<usize>(), any::<u32>()).prop_map(|(i, v)| MeshSpoil::SegmentEnd(i, v)),
        (1usize..50).prop_map(MeshSpoil::FewerMasses),
        (any::<usize>(), prop_oneof![not_positive(), Just(1.7e308)]).prop_map(|(i, v)| MeshSpoil::Mass(i, v)),
        (any::<usize>(), bad_number()).prop_map(|(i, v)| MeshSpoil::Node(i, v)),
        (any::<usize>(), 1u32..).prop_map(|(i, v)| MeshSpoil::NodeSolid(i, v)),
        (any::<usize>(), any::<u32>()).prop_map(|(i, v)| MeshSpoil::CellNode(i, v)),
        any::<usize>().prop_map(MeshSpoil::ShortCell),
        any::<u32>().prop_map(MeshSpoil::Fixed),
        not_positive().prop_map(MeshSpoil::DtStable),
        Just(MeshSpoil::NoNodes),
        Just(MeshSpoil::NoSolids),
        Just(MeshSpoil::NoInterface),
        (1usize..200_000).prop_map(MeshSpoil::HugeCellSolid),
        prop_oneof![Just(20.0), Just(1e6)].prop_map(MeshSpoil::Scale),
        any::<usize>().prop_map(MeshSpoil::ReversedCell),
        any::<usize>().prop_map(MeshSpoil::SegmentTwice),
        any::<usize>().prop_map(MeshSpoil::FixedTwice),
        Just(MeshSpoil::SecondSolid),
    ];
    let fem = prop_oneof![
        (any::<usize>(), any::<u32>()).prop_map(|(i, v)| FemSpoil::Id(i, v)),
        Just(FemSpoil::DropId),
        Just(FemSpoil::ShortX),
        (any::<usize>(), bad_number()).prop_map(|(i, v)| FemSpoil::X(i, v)),
        (any::<usize>(), prop_oneof![bad_number(), flung()]).prop_map(|(i, v)| FemSpoil::V(i, v)),
        Just(FemSpoil::Collapse),
        Just(FemSpoil::SnapshotShort),
        Just(FemSpoil::StressShort),
        Just(FemSpoil::NoSnapshot),
        not_positive().prop_map(FemSpoil::DtStable),
        prop_oneof![Just(f64::NAN), Just(-1.0), Just(1.7e308)].prop_map(FemSpoil::Seconds),
    ];
    let setup = prop_oneof![
        // Positive but not the scene's: a spacing of 1e-300 made `particle_particle` build 1e300 points a segment,
        // and one of 0.2 ran `ok` with no contact.
        prop_oneof![not_positive(), Just(1e-300), Just(0.2)].prop_map(SetupSpoil::Spacing),
        prop_oneof![not_positive(), Just(0.5)].prop_map(SetupSpoil::H),
        prop_oneof![Just(1.0), Just(1e6)].prop_map(SetupSpoil::Density),
        (any::<usize>(), bad_number()).prop_map(|(i, v)| SetupSpoil::Wall(i, v)),
        prop_oneof![Just(0.0), Just(-1e-4), Just(f64::NAN)].prop_map(SetupSpoil::DtStable),
    ];
    let sph = prop_oneof![
        (200u32..).prop_map(SphSpoil::Id),
        Just(SphSpoil::Duplicate),
        Just(SphSpoil::ShortM),
        not_positive().prop_map(SphSpoil::Mass),
        bad_number().prop_map(SphSpoil::X),
        prop_oneof![bad_number(), flung()].prop_map(SphSpoil::V),
        Just(SphSpoil::SnapshotShort),
        Just(SphSpoil::WallPShort),
        not_positive().prop_map(SphSpoil::Rho),
        // A zero or NaN stable step made the coordinator take zero-length steps for ever.
        prop_oneof![Just(0.0), Just(-1e-4), Just(f64::NAN)].prop_map(SphSpoil::DtStable),
        (1usize..300_000).prop_map(SphSpoil::HugeIds),
    ];
    prop_oneof![
        mesh.prop_map(Spoil::Mesh),
        (0u64..=12, fem).prop_map(|(step, how)| Spoil::Fem { step, how }),
        setup.prop_map(Spoil::Setup),
        (0u64..=12, sph).prop_map(|(step, how)| Spoil::Sph { step, how }),
    ]
}

pub(crate) fn pick(i: usize, len: usize) -> usize {
    i % len.max(1)
}

pub(crate) fn spoil_mesh(m: &mut FemMesh, how: &MeshSpoil) -> &'static str {
    let n = m.nodes.len() as u32;
    match *how {
        MeshSpoil::SegmentEnd(i, v) => {
            let k = pick(i, m.interface.len());
            m.interface[k].b = n + v % (u32::MAX - n);
            "interface"
        }
        MeshSpoil::FewerMasses(k) => {
            m.masses.truncate(m.masses.len().saturating_sub(k));
            "masses"
        }
        MeshSpoil::Mass(i, v) => {
            let k = pick(i, m.masses.len());
            m.masses[k] = v;
            "masses"
        }
        MeshSpoil::Node(i, v) => {
            let k = pick(i, m.nodes.len());
            m.nodes[k][i % 2] = v;
            "nodes"
        }
        MeshSpoil::NodeSolid(i, v) => {
            let k = pick(i, m.node_solid.len());
            m.node_solid[k] = v;
            "node_solid"
        }
        MeshSpoil::CellNode(i, v) => {
            let k = pick(i, m.cells.len());
            m.cells[k][i % 3] = n + v % (u32::MAX - n);
            "cells"
        }
        MeshSpoil::ShortCell(i) => {
            let k = pick(i, m.cells.len());
            m.cells[k].truncate(2);
            "cells"
        }
        MeshSpoil::Fixed(v) => {
            m.fixed.push(n + v % (u32::MAX - n));
            "fixed"
        }
        MeshSpoil::DtStable(v) => {
            m.dt_stable = v;
            "dt_stable"
        }
        MeshSpoil::NoNodes => {
            m.nodes.clear();
            "nodes"
        }
        MeshSpoil::NoSolids => {
            m.solid_names.clear();
            "solid_names"
        }
        MeshSpoil::NoInterface => {
            // A coupled structure with no surface made an infinite region of interest, refused by the fluid node
            // as the broker's fault.
            m.interface.clear();
            "interface"
        }
        MeshSpoil::HugeCellSolid(k) => {
            m.cell_solid.extend(std::iter::repeat_n(0, k));
            "cell_solid"
        }
        MeshSpoil::Scale(f) => {
            m.nodes.iter_mut().for_each(|x| *x = x.map(|c| c * f));
            "interface"
        }
        MeshSpoil::ReversedCell(i) => {
            let k = pick(i, m.cells.len());
            m.cells[k].reverse();
            "cells"
        }
        MeshSpoil::SegmentTwice(i) => {
            let k = pick(i, m.interface.len());
            m.interface.push(m.interface[k]);
            "interface"
        }
        MeshSpoil::FixedTwice(i) => {
            if m.fixed.is_empty() {
                m.fixed.push(0);
            }
            let k = pick(i, m.fixed.len());
            m.fixed.push(m.fixed[k]);
            "fixed"
        }
        MeshSpoil::SecondSolid => {
            // A solid the scene does not have, owning the last cell.
            m.solid_names.push("intruder".into());
            if let Some(s) = m.cell_solid.last_mut() {
                *s = 1;
            }
            "solid_names"
        }
    }
}

pub(crate) fn spoil_fem(s: &mut FemState, how: &FemSpoil) -> Option<&'static str> {
    match *how {
        FemSpoil::Id(i, v) if !s.ids.is_empty() => {
            let k = pick(i, s.ids.len());
            s.ids[k] = s.ids[k].wrapping_add(1 + v % (u32::MAX - 1));
            Some("ids")
        }
        FemSpoil::DropId if !s.ids.is_empty() => {
            s.ids.pop();
            Some("ids")
        }
        FemSpoil::ShortX if !s.x.is_empty() => {
            s.x.pop();
            Some("x")
        }
        FemSpoil::X(i, v) if !s.x.is_empty() => {
            let k = pick(i, s.x.len());
            s.x[k][i % 2] = v;
            Some("x")
        }
        FemSpoil::V(i, v) if !s.v.is_empty() => {
            let k = pick(i, s.v.len());
            s.v[k][i % 2] = v;
            Some("v")
        }
        FemSpoil::Collapse if s.x.len() >= 2 => {
            // Every interface node at one point (the sweep's `mesh_all_same`: the water fell through).
            let first = s.x[0];
            s.x.iter_mut().for_each(|x| *x = first);
            Some("x")
        }
        FemSpoil::SnapshotShort => s.snapshot.as_mut().map(|snap| {
            snap.x.pop();
            "x"
        }),
        FemSpoil::StressShort => s.snapshot.as_mut().map(|snap| {
            snap.stress.pop();
            "stress"
        }),
        FemSpoil::NoSnapshot => s.snapshot.take().map(|_| "snapshot"),
        FemSpoil::DtStable(v) => {
            s.dt_stable = v;
            Some("dt_stable")
        }
        FemSpoil::Seconds(v) => {
            s.compute_seconds = v;
            Some("compute_seconds")
        }
        _ => None,
    }
}

pub(crate) fn spoil_setup(s: &mut SphSetup, how: &SetupSpoil) -> &'static str {
    match *how {
        SetupSpoil::Spacing(v) => {
            s.spacing = v;
            "spacing"
        }
        SetupSpoil::H(v) => {
            s.h = v;
            "h"
        }
        SetupSpoil::Density(v) => {
            s.density = v;
            "density"
        }
        SetupSpoil::Wall(i, v) => {
            let k = pick(i, s.walls.len());
            s.walls[k][i % 2] = v;
            "walls"
        }
        SetupSpoil::DtStable(v) => {
            s.dt_stable = v;
            "dt_stable"
        }
    }
}

pub(crate) fn spoil_sph(s: &mut SphState, particles: u32, how: &SphSpoil) -> Option<&'static str> {
    match *how {
        SphSpoil::Id(v) if !s.ids.is_empty() => {
            let last = s.ids.len() - 1;
            s.ids[last] = v.max(particles);
            Some("ids")
        }
        SphSpoil::Duplicate if s.ids.len() >= 2 => {
            s.ids[1] = s.ids[0];
            Some("ids")
        }
        SphSpoil::ShortM if !s.m.is_empty() => {
            s.m.pop();
            Some("m")
        }
        SphSpoil::Mass(v) if !s.m.is_empty() => {
            s.m[0] = v;
            Some("m")
        }
        SphSpoil::X(v) if !s.x.is_empty() => {
            s.x[0][1] = v;
            Some("x")
        }
        SphSpoil::V(v) if !s.v.is_empty() => {
            s.v[0][1] = v;
            Some("v")
        }
        SphSpoil::SnapshotShort => s.snapshot.as_mut().map(|snap| {
            snap.p.pop();
            "p"
        }),
        SphSpoil::WallPShort => s.snapshot.as_mut().map(|snap| {
            snap.wall_p.clear();
            "wall_p"
        }),
        SphSpoil::Rho(v) => s.snapshot.as_mut().map(|snap| {
            snap.rho[0] = v;
            "rho"
        }),
        SphSpoil::DtStable(v) => {
            s.dt_stable = v;
            Some("dt_stable")
        }
        SphSpoil::HugeIds(k) => {
            // Ids beyond the particle count, with positions, velocities and masses to match.
            s.ids.extend((0..k as u32).map(|i| particles.saturating_add(i)));
            s.x.resize(s.ids.len(), [0.0; 2]);
            s.v.resize(s.ids.len(), [0.0; 2]);
            s.m.resize(s.ids.len(), 1.0);
            Some("ids")
        }
        _ => None,
    }
}
