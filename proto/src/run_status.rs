//! How a run ended, or how a node says it failed: `summary.json` `status` (`DESIGN.md` §5) and the `status` of a
//! node's error report (`NodeError`, docs/PROTOCOL.md).
//!
//! It is written as its name, a string, in every format (JSON and bincode alike), so a summary, a checkpoint or a
//! message holds the same bytes as when the status was a plain string.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// How a run ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RunStatus {
    /// It reached its end time.
    Ok,
    /// A solver blew up numerically (it said so, or sent a NaN or an infinity in a state).
    Unstable,
    /// Anything else that ended it early: a node that failed, died, timed out or sent something unusable, an
    /// output that could not be written, an interrupt (Ctrl-C, SIGTERM) or a launcher gone. The summary's message
    /// says which.
    Failed,
}

impl RunStatus {
    /// Every status, in the order of the declaration.
    pub const ALL: [RunStatus; 3] = [RunStatus::Ok, RunStatus::Unstable, RunStatus::Failed];

    /// The status's name as written: `ok`, `unstable` or `failed`.
    pub fn as_str(self) -> &'static str {
        match self {
            RunStatus::Ok => "ok",
            RunStatus::Unstable => "unstable",
            RunStatus::Failed => "failed",
        }
    }

    /// The status named `name`, if it is one.
    pub fn parse(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|s| s.as_str() == name)
    }

    /// The status a node's error report (`NodeError` `status`) gives the run: `unstable` where it says so, `failed`
    /// for anything else (a report is a failure whatever it names).
    pub fn of_node_report(status: &str) -> Self {
        match Self::parse(status) {
            Some(RunStatus::Unstable) => RunStatus::Unstable,
            _ => RunStatus::Failed,
        }
    }

    /// Whether the run reached its end.
    pub fn is_ok(self) -> bool {
        self == RunStatus::Ok
    }
}

impl std::fmt::Display for RunStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Serialize for RunStatus {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

impl<'de> Deserialize<'de> for RunStatus {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = String::deserialize(deserializer)?;
        Self::parse(&name).ok_or_else(|| {
            serde::de::Error::custom(format!("status `{name}`: expected one of `ok`, `unstable`, `failed`"))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_status_is_written_as_its_name_in_json_and_bincode() {
        for status in RunStatus::ALL {
            let json = serde_json::to_string(&status).unwrap();
            assert_eq!(json, format!("\"{}\"", status.as_str()));
            assert_eq!(serde_json::from_str::<RunStatus>(&json).unwrap(), status);
            // The bytes of the string it replaced.
            let bytes = bincode::serialize(&status).unwrap();
            assert_eq!(bytes, bincode::serialize(status.as_str()).unwrap());
            assert_eq!(bincode::deserialize::<RunStatus>(&bytes).unwrap(), status);
        }
        assert_eq!(RunStatus::Unstable.to_string(), "unstable");
    }

    #[test]
    fn an_unknown_status_is_refused_by_name() {
        let e = serde_json::from_str::<RunStatus>("\"stopped\"")
            .unwrap_err()
            .to_string();
        assert!(e.contains("status `stopped`"), "{e}");
    }

    #[test]
    fn a_node_report_is_unstable_or_failed() {
        assert_eq!(RunStatus::of_node_report("unstable"), RunStatus::Unstable);
        assert_eq!(RunStatus::of_node_report("failed"), RunStatus::Failed);
        assert_eq!(RunStatus::of_node_report("ok"), RunStatus::Failed);
        assert_eq!(RunStatus::of_node_report(""), RunStatus::Failed);
    }
}
