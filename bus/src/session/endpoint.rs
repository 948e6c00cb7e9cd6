//! A zenoh endpoint as the command lines take it (`--connect`, `--listen`), checked when the line is read: a
//! malformed one made a command wait its whole timeout and then print zenoh's parse error with the paths of zenoh's
//! sources (`--connect garbage`, found 2026-12-06 by the sweep of hostile external nodes, D25).

use zenoh::config::EndPoint;

/// The transports this build of zenoh has (the workspace's zenoh features).
pub const TRANSPORTS: [&str; 3] = ["tcp", "tls", "unixsock-stream"];

/// `text` as a zenoh endpoint (`PROTOCOL/ADDRESS`, with optional `?metadata` and `#config`) of a transport this
/// build has; for clap's `value_parser`.
pub fn endpoint(text: &str) -> Result<String, String> {
    let example = "e.g. tcp/127.0.0.1:7447";
    let e = EndPoint::try_from(text.to_string())
        .map_err(|_| format!("not a zenoh endpoint: the form is PROTOCOL/ADDRESS, {example}"))?;
    let protocol = e.protocol();
    if !TRANSPORTS.contains(&protocol.as_str()) {
        return Err(format!(
            "the transport `{}` is not in this build (it has {}), {example}",
            protocol.as_str(),
            TRANSPORTS.join(", ")
        ));
    }
    Ok(text.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn endpoints_of_the_built_transports_pass_and_the_rest_are_named() {
        for ok in [
            "tcp/127.0.0.1:7447",
            "tls/localhost:7447",
            "unixsock-stream//tmp/z.sock",
            "tcp/[::1]:0",
        ] {
            assert_eq!(endpoint(ok).as_deref(), Ok(ok));
        }
        assert_eq!(
            endpoint("garbage").unwrap_err(),
            "not a zenoh endpoint: the form is PROTOCOL/ADDRESS, e.g. tcp/127.0.0.1:7447"
        );
        assert_eq!(
            endpoint("udp/127.0.0.1:7447").unwrap_err(),
            "the transport `udp` is not in this build (it has tcp, tls, unixsock-stream), e.g. tcp/127.0.0.1:7447"
        );
    }
}
