//! `cosim inspect ID [--once]`: the live status of every process of a run (`DESIGN.md` §5), from the
//! `cosim/<ID>/*/status` queryables the broker and the nodes answer (`cosim_bus::status`).

use std::io::{IsTerminal, Write};
use std::process::ExitCode;
use std::time::{Duration, Instant};

use cosim_bus::status::query_all;
use cosim_proto::control::StateOf;

use crate::cli::InspectArgs;

/// One document: `{"run": ID, "nodes": {"contact-broker": {...}, "fem-node": {...}, "sph-node": {...}}}`.
fn document(run: &str, answers: &[(String, String)]) -> serde_json::Value {
    let mut nodes = serde_json::Map::new();
    for (key, text) in answers {
        let value: serde_json::Value =
            serde_json::from_str(text).unwrap_or_else(|_| serde_json::json!({ "unreadable": text }));
        let name = value
            .get("node")
            .and_then(|n| n.as_str())
            .map(str::to_string)
            .unwrap_or_else(|| key.clone());
        nodes.insert(name, value);
    }
    serde_json::json!({ "run": run, "nodes": nodes })
}

fn number(v: &serde_json::Value, key: &str) -> f64 {
    v.get(key).and_then(|x| x.as_f64()).unwrap_or(f64::NAN)
}

/// The table `cosim inspect` refreshes.
fn table(doc: &serde_json::Value) -> String {
    let mut out = format!(
        "run {}\n{:<15} {:<9} {:>8} {:>10} {:>10} {:>12} {:>12}  {}\n",
        doc["run"].as_str().unwrap_or("?"),
        "process",
        "health",
        "step",
        "t [s]",
        "dt [s]",
        "compute/step",
        "wait/step",
        "sizes"
    );
    if let Some(nodes) = doc["nodes"].as_object() {
        for (name, s) in nodes {
            let counts: Vec<String> = s["counts"]
                .as_object()
                .map(|c| c.iter().map(|(k, v)| format!("{k} {v}")).collect())
                .unwrap_or_default();
            out += &format!(
                "{:<15} {:<9} {:>8} {:>10.5} {:>10.3e} {:>10.2} ms {:>9.2} ms  {}\n",
                name,
                s["health"].as_str().unwrap_or("?"),
                s["step"].as_u64().unwrap_or(0),
                number(s, "t"),
                number(s, "dt"),
                1e3 * number(s, "compute_per_step"),
                1e3 * number(s, "waiting_per_step"),
                counts.join(", ")
            );
            if let Some(energy) = s["extra"].get("energy").and_then(|e| e.as_object()) {
                let parts: Vec<String> = energy
                    .iter()
                    .map(|(k, v)| format!("{k} {:.4e}", v.as_f64().unwrap_or(f64::NAN)))
                    .collect();
                out += &format!("{:<15} energy [J/m]: {}\n", "", parts.join(", "));
            }
            if let (Some(c), Some(p)) = (s["extra"].get("contacts"), s["extra"].get("max_penetration")) {
                out += &format!(
                    "{:<15} contacts {c}, max penetration {:.3e} m, particles exchanged {}\n",
                    "",
                    p.as_f64().unwrap_or(f64::NAN),
                    s["extra"].get("exchanged").unwrap_or(&serde_json::Value::Null)
                );
            }
            if let Some(g) = s["extra"].get("energy_made").and_then(|g| g.as_f64()) {
                out += &format!(
                    "{:<15} energy gained since t = 0: at most {:.2} % of what the water can release{}\n",
                    "",
                    100.0 * g,
                    if contact_broker::energy_balance::made_energy(g) {
                        " (made by the scheme: see summary.json energy_growth)"
                    } else {
                        ""
                    }
                );
            }
            if let Some(stats) = s["extra"].get("contact_stats") {
                out += &format!("{:<15} contact_stats {stats}\n", "");
            }
            if let Some(p) = s["extra"].get("paused").and_then(|p| p.as_str()) {
                out += &format!("{:<15} {p}\n", "");
            }
            if let Some(m) = s["message"].as_str().filter(|m| !m.is_empty()) {
                out += &format!("{:<15} {m}\n", "");
            }
        }
    }
    out
}

/// How `cosim inspect` reaches the run (`join.rs`), waiting `timeout` seconds.
fn join_args(args: &InspectArgs, timeout: f64) -> crate::join::JoinArgs {
    crate::join::JoinArgs {
        connect: args.connect.clone(),
        client: args.client,
        zenoh_config: args.zenoh_config.clone(),
        timeout,
    }
}

/// `cosim inspect ID --particle P | --node N`: one particle's or node's state as JSON (`look.rs`).
fn inspect_one(args: &InspectArgs, id: &str) -> anyhow::Result<ExitCode> {
    // A state is a checkpoint of every node: it may take longer than a status.
    let how = join_args(args, args.timeout.max(10.0));
    let (session, connect) = crate::join::join(id, &how)?;
    let wait = cosim_bus::seconds::wait(how.timeout);
    let fetch = |of| crate::look::fetch(&session, id, wait, of);
    // A particle needs the fluid's state; the structure's only for its contact. Where the run's state cannot be had
    // whole (an outside program in the structure node's place saves no checkpoint), the fluid's alone is asked for.
    let (look, partial) = match fetch(StateOf::All) {
        Ok(look) => (look, None),
        Err(e) => match args.particle.is_some().then(|| fetch(StateOf::Fluid)) {
            Some(Ok(look)) => (look, Some(e)),
            _ => {
                eprintln!("cosim: run `{id}` at {connect}: {e:#}");
                return Ok(ExitCode::from(1));
            }
        },
    };
    let mut doc = match (args.particle, args.node) {
        (Some(p), _) => crate::look::particle(&look, p)?,
        (None, Some(n)) => crate::look::node(&look, n)?,
        (None, None) => unreachable!("inspect_one is called with --particle or --node"),
    };
    if let Some(e) = partial {
        let why = format!("{e:#}");
        eprintln!("cosim: the structure is not shown (its contact with the particle neither): {why}");
        doc["structure"] = serde_json::Value::String(format!("not shown: {why}"));
    }
    println!("{doc:#}");
    Ok(ExitCode::SUCCESS)
}

/// Run `cosim inspect`; `Err` for bad input (exit 2).
pub fn inspect(args: &InspectArgs) -> anyhow::Result<ExitCode> {
    let Some(id) = args.id.as_deref() else {
        anyhow::ensure!(
            args.particle.is_none() && args.node.is_none(),
            "--particle and --node need the run's id: `cosim inspect ID --particle P`"
        );
        return list(args.once);
    };
    if args.particle.is_some() || args.node.is_some() {
        return inspect_one(args, id);
    }
    let (session, connect) = crate::join::join(id, &join_args(args, args.timeout))?;
    let timeout = cosim_bus::seconds::wait(args.timeout);
    if args.once {
        let answers = query_all(&session, id, timeout)?;
        if answers.is_empty() {
            eprintln!("cosim: no process of run `{id}` answered at {connect}");
            return Ok(ExitCode::from(1));
        }
        println!("{:#}", document(id, &answers));
        return Ok(ExitCode::SUCCESS);
    }
    let terminal = std::io::stdout().is_terminal();
    let mut silent_since: Option<Instant> = None;
    loop {
        let answers = query_all(&session, id, timeout)?;
        let doc = document(id, &answers);
        let mut out = std::io::stdout().lock();
        if terminal {
            let _ = write!(out, "\x1b[2J\x1b[H");
        }
        let _ = writeln!(out, "{}", table(&doc));
        let _ = out.flush();
        drop(out);
        let done = doc["nodes"].as_object().is_some_and(|n| {
            !n.is_empty()
                && n.values()
                    .all(|s| s["health"] != "running" && s["health"] != "starting")
        });
        if done {
            return Ok(ExitCode::SUCCESS);
        }
        if answers.is_empty() {
            let since = *silent_since.get_or_insert_with(Instant::now);
            if since.elapsed() > Duration::from_secs(3) {
                eprintln!("cosim: run `{id}` no longer answers (finished or gone)");
                return Ok(ExitCode::SUCCESS);
            }
        } else {
            silent_since = None;
        }
        std::thread::sleep(cosim_bus::seconds::wait(args.interval));
    }
}

/// `cosim inspect` without an id: the runs on this machine (`registry::live`), one line each, or with `--once` a JSON
/// array of their entries. None running is not an error.
fn list(json: bool) -> anyhow::Result<ExitCode> {
    let runs = crate::registry::live();
    if json {
        println!("{:#}", serde_json::to_value(&runs)?);
        return Ok(ExitCode::SUCCESS);
    }
    if runs.is_empty() {
        println!(
            "no run is going on this machine (none registered in {}; a run in one process cannot be inspected)",
            crate::registry::dir().display()
        );
        return Ok(ExitCode::SUCCESS);
    }
    let now = crate::registry::now().unwrap_or(0);
    let width = runs.iter().map(|e| e.run.len()).max().unwrap_or(0).max(3);
    let scene_width = runs
        .iter()
        .filter_map(|e| e.scene.as_ref())
        .map(String::len)
        .max()
        .unwrap_or(0)
        .max(5);
    let mut out = std::io::stdout().lock();
    let _ = writeln!(
        out,
        "{:width$}  {:>7}  {:scene_width$}  {:>9}  {:24}  out",
        "run", "pid", "scene", "running", "endpoint"
    );
    for e in &runs {
        let running = e
            .since
            .map_or("?".to_string(), |t| crate::progress::hms(now.saturating_sub(t) as f64));
        let _ = writeln!(
            out,
            "{:width$}  {:>7}  {:scene_width$}  {running:>9}  {:24}  {}",
            e.run,
            e.pid,
            e.scene.as_deref().unwrap_or("?"),
            e.connect,
            e.out.display()
        );
    }
    Ok(ExitCode::SUCCESS)
}
