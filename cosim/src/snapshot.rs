//! `cosim snapshot RUN --out DIR`: the current state of a live run (paused or running; a running run answers
//! between two steps) as ParaView frames in `DIR/frames/`, written with the run's own frame writers:
//! `structure_00000.vtu` (the mesh as the run's structure frames), `particles_00000.vtu` (fluid and wall
//! particles, as the run's particle frames), each with its `.pvd`, and `contacts.vtu`: one point per contact of
//! the last contact pass, at the particle, with `particle`, `segment` (−1 for a node contact), `node`, `gap`,
//! `lambda`, `impulse`, `dx`, `dv`, `recorded` (`look::contacts`): the (particle, master) pairs the particle–element
//! pass recorded (`recorded` = 1: gap at detection, λ and J it applied), or for `particle_particle`, which records
//! none, each corrected particle against its nearest segment with λ, J reconstructed from the correction (0). `DIR/snapshot.json` says which step and time, why the run is paused, and lists
//! the contacts.

use std::process::ExitCode;

use anyhow::Context;
use contact_broker::output::{FrameWriter, Part, PointField};

use crate::cli::SnapshotArgs;
use crate::join::join;
use crate::look::{self, Look};

/// Run `cosim snapshot`.
pub fn snapshot(args: &SnapshotArgs) -> anyhow::Result<ExitCode> {
    // The frames are numbered 0: in a run's own folder they took the place of its first frames, which its .pvd
    // still listed at t = 0 (found 2026-12-06). A snapshot's folder holds snapshots.
    anyhow::ensure!(
        !args.out.join("summary.json").exists(),
        "--out {}: holds a run's outputs (summary.json); the snapshot's frames would take the place of its first \
         ones: give the snapshot a folder of its own",
        args.out.display()
    );
    let (session, connect) = join(&args.id, &args.join)?;
    let look = match look::fetch(
        &session,
        &args.id,
        cosim_bus::seconds::wait(args.join.timeout),
        cosim_proto::control::StateOf::All,
    ) {
        Ok(look) => look,
        Err(e) => {
            eprintln!("cosim: run `{}` at {connect}: {e:#}", args.id);
            return Ok(ExitCode::from(1));
        }
    };
    let contacts = write(&look, &args.out)?;
    println!(
        "snapshot of run {} at step {} (t = {} s{}): {} contact(s) -> {}",
        args.id,
        look.step,
        // The sum of the run's steps: 0.30000000000000004 reads 0.3 at 12 digits.
        cosim_proto::Num(cosim_proto::readable::significant(look.t, 12)),
        if look.paused.is_empty() {
            String::new()
        } else {
            format!(", {}", look.paused)
        },
        contacts,
        args.out.join("frames").display()
    );
    Ok(ExitCode::SUCCESS)
}

/// Write the frames and `snapshot.json` of `look` into `out`; the number of contacts.
pub fn write(look: &Look, out: &std::path::Path) -> anyhow::Result<usize> {
    let mut frames = FrameWriter::new(out)?;
    if let Some(fem) = &look.fem {
        frames.write_structure(0, look.t, &fem.mesh, &fem.snap, None)?;
    }
    if let Some(sph) = &look.sph {
        let (s, w) = (&sph.solver.state, &sph.solver.walls);
        let (fluid, walls) = (s.x.len(), w.x.len());
        frames.write_particle_parts(
            0,
            look.t,
            &[Part::Slice(&s.x), Part::Slice(&w.x)],
            &[
                PointField::VectorParts("velocity", &[Part::Slice(&s.v), Part::Repeat([0.0; 2], walls)]),
                PointField::ScalarParts("pressure", &[Part::Slice(&s.p), Part::Slice(&w.p)]),
                PointField::ScalarParts("density", &[Part::Slice(&s.rho), Part::Slice(&w.rho)]),
                PointField::ScalarParts("wall", &[Part::Repeat(0.0, fluid), Part::Repeat(1.0, walls)]),
            ],
        )?;
    }
    let rows = look::contacts(look);
    let column = |f: &dyn Fn(&look::ContactRow) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    let x: Vec<[f64; 2]> = rows.iter().map(|r| r.x).collect();
    let (dx, dv): (Vec<[f64; 2]>, Vec<[f64; 2]>) = rows.iter().map(|r| (r.dx, r.dv)).unzip();
    let (particle, segment) = (column(&|r| f64::from(r.particle)), column(&|r| r.segment as f64));
    let node = column(&|r| if r.segment < 0 { f64::from(r.nodes[0]) } else { -1.0 });
    let recorded = column(&|r| if r.source == "recorded" { 1.0 } else { 0.0 });
    let (gap, lambda, impulse) = (column(&|r| r.gap), column(&|r| r.lambda), column(&|r| r.impulse));
    frames.write_points(
        "contacts.vtu",
        &[Part::Slice(&x)],
        &[
            PointField::Scalar("particle", &particle),
            PointField::Scalar("segment", &segment),
            PointField::Scalar("node", &node),
            PointField::Scalar("gap", &gap),
            PointField::Scalar("lambda", &lambda),
            PointField::Scalar("impulse", &impulse),
            PointField::Vector("dx", &dx),
            PointField::Vector("dv", &dv),
            PointField::Scalar("recorded", &recorded),
        ],
    )?;
    let doc = serde_json::json!({
        "step": look.step,
        "t": look.t,
        "paused": look.paused,
        "max_penetration": look.debug.max_penetration,
        "particles": look.sph.as_ref().map_or(0, |s| s.solver.state.x.len()),
        "fem_nodes": look.fem.as_ref().map_or(0, |f| f.mesh.nodes.len()),
        "contacts_source": if look.debug.contacts.is_some() { "recorded" } else { "reconstructed" },
        "contacts": rows,
    });
    let path = out.join("snapshot.json");
    std::fs::write(&path, format!("{doc:#}\n")).with_context(|| format!("cannot write {}", path.display()))?;
    Ok(rows.len())
}
