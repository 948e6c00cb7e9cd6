//! The zenoh session settings every process uses, as `(key, json5 value)` pairs for zenoh's
//! `Config::insert_json5`; `super` puts them on top of the base config.

/// Settings of a peer session: multicast scouting off (gossip stays on so peers that only know a hub find each
/// other), listen on `listen`, connect to `connect`, and fail within `timeout_ms` when a connect endpoint does
/// not answer instead of retrying forever.
pub fn peer_settings(listen: &[String], connect: &[String], timeout_ms: u64) -> Vec<(String, String)> {
    let list = |v: &[String]| {
        let quoted: Vec<String> = v.iter().map(|e| format!("{e:?}")).collect();
        format!("[{}]", quoted.join(","))
    };
    let mut s = vec![
        ("mode".to_string(), "\"peer\"".to_string()),
        ("scouting/multicast/enabled".to_string(), "false".to_string()),
        ("listen/endpoints".to_string(), list(listen)),
        ("connect/endpoints".to_string(), list(connect)),
    ];
    if !connect.is_empty() {
        s.push(("connect/timeout_ms".to_string(), timeout_ms.to_string()));
        s.push(("connect/exit_on_failure".to_string(), "true".to_string()));
    }
    if !listen.is_empty() {
        s.push(("listen/timeout_ms".to_string(), timeout_ms.to_string()));
        s.push(("listen/exit_on_failure".to_string(), "true".to_string()));
    }
    s
}

/// Settings of a client session, for a process that joins a run through a zenoh router (`zenohd`, or any process
/// in router mode) on another host: every message goes through the router. Peers connected to a router do not get
/// each other's messages through it in zenoh 1.10 (the router stops brokering between peers it believes have met
/// through gossip, and ours listen on nothing), so a run spread over hosts puts every process in client mode.
/// Multicast scouting off; a router that does not answer within `timeout_ms` is an error.
pub fn client_settings(connect: &[String], timeout_ms: u64) -> Vec<(String, String)> {
    let quoted: Vec<String> = connect.iter().map(|e| format!("{e:?}")).collect();
    vec![
        ("mode".to_string(), "\"client\"".to_string()),
        ("scouting/multicast/enabled".to_string(), "false".to_string()),
        ("connect/endpoints".to_string(), format!("[{}]", quoted.join(","))),
        ("connect/timeout_ms".to_string(), timeout_ms.to_string()),
        ("connect/exit_on_failure".to_string(), "true".to_string()),
    ]
}

/// Settings of a router session (`cosim router`, the same router `zenohd` runs): the hub every client of a run
/// spread over hosts connects to. Router mode, multicast scouting off, listen on `listen` (an endpoint that cannot
/// be bound within `timeout_ms` is an error), connect to nothing.
pub fn router_settings(listen: &[String], timeout_ms: u64) -> Vec<(String, String)> {
    let quoted: Vec<String> = listen.iter().map(|e| format!("{e:?}")).collect();
    vec![
        ("mode".to_string(), "\"router\"".to_string()),
        ("scouting/multicast/enabled".to_string(), "false".to_string()),
        ("listen/endpoints".to_string(), format!("[{}]", quoted.join(","))),
        ("listen/timeout_ms".to_string(), timeout_ms.to_string()),
        ("listen/exit_on_failure".to_string(), "true".to_string()),
        ("connect/endpoints".to_string(), "[]".to_string()),
    ]
}
