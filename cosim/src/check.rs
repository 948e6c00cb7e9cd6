//! `cosim check`: validate a scene and print what would run.

use std::process::ExitCode;

use anyhow::Context;
use cosim_bus::memory;
use cosim_proto::scene::disk::DiskEstimate;
use cosim_proto::scene::DensityFilter;
use cosim_proto::sizing::{bytes_text, count, Part, Sizing};
use cosim_proto::Num;
use fem_node::core::FemCore;
use sph_node::core::SphCore;

use crate::cli::CheckArgs;

/// Validate and describe; `Err` (exit 2) names the file, the key and the problem.
pub fn check(args: &CheckArgs) -> anyhow::Result<ExitCode> {
    // Loaded and refused as `cosim run` and `contact-broker` do (memory, ids, a run that could never end).
    let setup = contact_broker::setup::RunSetup::load(&args.scene, &args.set, Part::Run)?;
    let s = &setup.scene.scene;
    // Sized from the scene alone, before the structure and the fluid are built below.
    let sizing = Sizing::of(s);
    let available = memory::available();
    let (dt_fem, nodes, elements) = if s.solids.is_empty() {
        (None, 0, 0)
    } else {
        let core = FemCore::new(s).with_context(|| format!("{}: building the structure", args.scene.display()))?;
        (
            Some(core.mesh().dt_stable),
            core.mesh().nodes.len(),
            core.mesh().cells.len(),
        )
    };
    let fluid = match &s.fluid {
        Some(_) => Some(SphCore::new(s).with_context(|| format!("{}: filling the fluid", args.scene.display()))?),
        None => None,
    };
    let (particles, walls, dt_fluid) = fluid.as_ref().map_or((0, 0, f64::INFINITY), |f| {
        (f.setup().particles as usize, f.setup().walls.len(), f.setup().dt_stable)
    });
    // Fluid-only runs sub-cycle inside the fluid node; only coupled runs step the broker at the fluid's step (or
    // `coupling.fluid_substeps` of them).
    let coupled = fluid.is_some() && !s.solids.is_empty();
    let dt = contact_broker::coordinator::first_step(s, !s.solids.is_empty(), dt_fluid);
    let steps = (s.run.end_time / dt).ceil() as u64;
    // WCSPH + particle_particle: the contact shortens the coupling step as the run goes (contact_step.rs).
    let contact_bound = coupled && contact_broker::contact_step::applies(s);
    let substeps = dt_fem.map(|d| (dt / d).ceil() as u64);
    // How many fluid steps a coupling step spans at most (`coupling.fluid_substeps`; WCSPH with particle_element).
    let fluid_span = s.fluid_steps_per_pass(dt_fluid);
    let ratios = s.particle_to_cell_mass();
    let mut warnings = s.warnings(dt_fluid);
    if let (true, Some(d), Some(k)) = (coupled, dt_fem, substeps) {
        warnings.extend(s.long_coupling_step_warning(dt, d, k));
    }
    let samples = s.run.sample_count();
    let frames = s.run.frame_count();
    // What the run writes into its output folder, with the checkpoints of `--checkpoint-interval` if given.
    contact_broker::checkpoint::check_interval(args.checkpoint_interval)?;
    let disk = DiskEstimate::of(s, &sizing, args.checkpoint_interval, 0.0);
    // The run's work from the same estimates: what its time grows with (a mesh of 1e5 thin cells was "valid" at
    // 3e14 element-steps, a year on one core, and nothing said so).
    let fluid_steps = fluid.as_ref().map(|_| (s.run.end_time / dt_fluid).ceil());
    let element_steps = elements as f64 * steps as f64 * substeps.unwrap_or(0) as f64;
    let particle_steps = particles as f64 * fluid_steps.unwrap_or(0.0);
    // What that work costs on one core at the rates measured here (estimate.rs): seconds, hours or years.
    let cpu_seconds =
        crate::estimate::cpu_seconds(element_steps, particle_steps, s.fluid.as_ref().map(|f| f.solver), steps);
    if args.json {
        let doc = serde_json::json!({
            "scene": args.scene.display().to_string(),
            "name": s.run.name,
            "end_time": s.run.end_time,
            "fem_nodes": nodes,
            "fem_elements": elements,
            "particles": particles,
            "wall_particles": walls,
            "sph_dt_stable": fluid.as_ref().map(|_| dt_fluid),
            "sph_steps_estimate": fluid_steps.map(|n| n as u64),
            "coupling_dt": dt,
            "coupling_steps": steps,
            "coupling_dt_bounded_by_contact": contact_bound,
            "coupling_fluid_steps_per_pass": coupled.then_some(fluid_span),
            "fem_dt_stable": dt_fem,
            "fem_substeps_per_step": substeps,
            "work": { "element_steps": element_steps, "particle_steps": particle_steps, "cpu_seconds": cpu_seconds },
            // A fluid particle's mass over one mesh cell's, per solid (proto::scene::mass_ratio).
            "particle_to_cell_mass": ratios
                .iter()
                .map(|&(name, r)| (name.to_string(), serde_json::json!(r)))
                .collect::<serde_json::Map<_, _>>(),
            "warnings": warnings,
            "frames": frames,
            "samples": samples,
            "probes": s.probes.iter().map(|p| p.name.clone()).collect::<Vec<_>>(),
            // From the scene alone (proto::sizing): what `run` compares with the memory available.
            "estimate": {
                "fluid_particles": sizing.fluid_particles as u64,
                "wall_particles": sizing.wall_particles as u64,
                "grid_cells": sizing.grid_cells as u64,
                "fem_nodes": sizing.fem_nodes as u64,
                "fem_elements": sizing.fem_elements as u64,
                "probe_samples": sizing.probe_samples as u64,
                "memory_bytes": sizing.bytes(Part::Run) as u64,
                "sph_node_bytes": sizing.bytes(Part::Fluid) as u64,
                "fem_node_bytes": sizing.bytes(Part::Structure) as u64,
                "broker_bytes": sizing.bytes(Part::Broker) as u64,
                "available_bytes": available,
                "output_bytes": disk.total() as u64,
                "frame_bytes": disk.frame_bytes as u64,
                "checkpoint_bytes": disk.checkpoint_bytes as u64,
                "checkpoints": disk.checkpoints as u64,
            },
            // The corrections in force (§4.4), the per-solver defaults filled in.
            "corrections": s.fluid.as_ref().map(|f| serde_json::json!({
                "density_filter": f.density_filter(),
                "density_filter_interval": f.density_filter_interval,
                "xsph": f.xsph,
                "apd": f.apd(),
                "density_diffusion": f.density_diffusion,
                "verlet_skin": f.verlet_skin(),
            })),
        });
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(ExitCode::SUCCESS);
    }
    println!("scene {} ({}): valid", args.scene.display(), s.run.name);
    println!(
        "  run: end_time {} s, output every {} s ({samples} probe samples, {frames} frames{}), gravity {:?}",
        Num(s.run.end_time),
        Num(s.run.output_interval),
        s.run
            .frame_interval
            .map_or(String::new(), |f| format!(" every {} s", Num(f))),
        s.run.gravity
    );
    for solid in &s.solids {
        let [nx, ny] = solid.grid_size();
        println!(
            "  solid {}: {:?} {}x{} cells, {} nodes, {} elements, {:?} E = {} Pa, nu = {}, rho = {} kg/m3, {} fixed box(es), damping {} 1/s",
            solid.name,
            solid.element,
            solid.divisions[0],
            solid.divisions[1],
            nx * ny,
            solid.element_count(),
            solid.material.model,
            Num(solid.material.youngs_modulus),
            Num(solid.material.poisson_ratio),
            Num(solid.material.density),
            solid.fixed.len(),
            Num(solid.damping)
        );
        if solid.mesh_damping() > 0.0 {
            println!(
                "    mesh damping: stiffness-proportional, a ratio of {} at the mesh's highest mode{}",
                Num(solid.mesh_damping()),
                if solid.mesh_damping.is_none() {
                    " (the default of a solid held nowhere)"
                } else {
                    ""
                }
            );
        }
    }
    match (&s.fluid, &fluid) {
        (Some(f), Some(core)) => println!(
            "  fluid: {:?}, {particles} particles + {walls} wall particles, spacing {} m, h = {:.4} m, stable dt {:.3e} s (about {} steps)",
            f.solver,
            Num(f.spacing),
            core.setup().h,
            dt_fluid,
            fluid_steps.unwrap_or(0.0)
        ),
        _ => println!("  fluid: none"),
    }
    if let Some(f) = &s.fluid {
        // The corrections in force (§4.4), the per-solver defaults filled in.
        let filter = match f.density_filter() {
            DensityFilter::None => "no density filter".to_string(),
            other => format!("{other:?} density filter every {} steps", f.density_filter_interval),
        };
        let diffusion = match f.density_diffusion {
            d if d > 0.0 => format!(", density diffusion delta = {} (Fourtakas et al. 2019)", Num(d)),
            _ => String::new(),
        };
        println!(
            "  corrections: {filter}, XSPH eps = {}, APD beta = {}{diffusion}",
            Num(f.xsph),
            Num(f.apd())
        );
        if f.verlet_skin() > 0.0 {
            println!(
                "  search: Verlet candidates within 2h + {} h, gathered again when a particle has moved {} h",
                Num(f.verlet_skin()),
                Num(0.5 * f.verlet_skin())
            );
        }
    }
    match (dt_fem, substeps) {
        (Some(d), Some(k)) => println!(
            "  steps: coupling dt {dt:.4e} s x {steps} steps; FEM stable dt {d:.3e} s -> {k} sub-step(s) per coupling step"
        ),
        _ => println!("  steps: coupling dt {dt:.4e} s x {steps} steps"),
    }
    if coupled && fluid_span > 1 {
        println!(
            "  coupling: a contact pass every {fluid_span} fluid steps at most (coupling.fluid_substeps = {}; 1: after \
             every fluid step, the paper's lockstep)",
            s.coupling.fluid_substeps
        );
    }
    for (name, ratio) in &ratios {
        println!(
            "  contact: a fluid particle weighs {:.1} cells of solid {name}",
            Num(*ratio)
        );
    }
    for w in &warnings {
        println!("  warning: {w}");
    }
    if contact_bound {
        println!(
            "  steps: particle_particle with WCSPH shortens the coupling step to what its stiff force needs as the run \
             goes (2-3 times the steps above on the shipped scenes; summary.json contact_step_bound)"
        );
    }
    println!("  totals: {nodes} FE nodes, {elements} elements, {particles} particles (coupling steps are estimated from the initial stable step)");
    println!(
        "  work: about {} element-steps and {} fluid particle-steps (what the run time grows with; docs/PERFORMANCE.md \
         has each solver's rate)",
        count(element_steps),
        count(particle_steps)
    );
    println!(
        "  time: about {} of CPU on one core at the rates measured on this project's 2-core machine (docs/PERFORMANCE.md; \
         a machine and the flow move it by up to about twice either way, and two threads take roughly 0.6 of it in \
         wall time)",
        crate::estimate::duration_text(cpu_seconds)
    );
    // A node the scene does not start has no share.
    let part = |p: Part, name: &str| (sizing.bytes(p) > 0.0).then(|| format!("{name} {}", bytes_text(sizing.bytes(p))));
    let parts: Vec<String> = [
        part(Part::Fluid, "sph-node"),
        part(Part::Structure, "fem-node"),
        part(Part::Broker, "contact-broker"),
    ]
    .into_iter()
    .flatten()
    .collect();
    println!(
        "  memory: about {} at its peak ({}; estimated from the scene, processes mode), {} available",
        bytes_text(sizing.bytes(Part::Run)),
        parts.join(", "),
        available.map_or("unknown".to_string(), |a| bytes_text(a as f64))
    );
    println!("  disk: {}", disk.text());
    for p in &s.probes {
        println!("  probe {}: {:?}", p.name, p.kind);
    }
    Ok(ExitCode::SUCCESS)
}
