//! Bad input to a contact routine, reported before anything is modified.

/// Bad input to a contact routine. Nothing is modified when one is returned.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ContactError {
    /// Two arrays that must match in length do not.
    #[error("{what} has {got} entries, expected {expected}")]
    Length {
        /// Which array.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Actual length.
        got: usize,
    },
    /// A segment names a node that does not exist, or the same node twice.
    #[error(
        "segment {segment} ({a} -> {b}) is invalid: there are {nodes} nodes and a segment needs two distinct ones"
    )]
    Segment {
        /// Segment index.
        segment: usize,
        /// Its start node.
        a: usize,
        /// Its end node.
        b: usize,
        /// Number of nodes.
        nodes: usize,
    },
    /// A non-finite coordinate or velocity, or a mass that is not positive and finite.
    #[error("{what} {index}: {field} is {value}, it must be finite{positive}")]
    Value {
        /// `particle` or `node`.
        what: &'static str,
        /// Its index.
        index: usize,
        /// `x`, `v` or `m`.
        field: &'static str,
        /// The offending value.
        value: f64,
        /// `" and positive"` for masses.
        positive: &'static str,
    },
    /// A contact parameter out of range.
    #[error("contact parameter `{name}` is {value}: it must be {expected}")]
    Param {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
}

/// Checks that a parameter is finite and satisfies `ok`.
pub(crate) fn param(name: &'static str, value: f64, ok: bool, expected: &'static str) -> Result<(), ContactError> {
    if ok && value.is_finite() {
        Ok(())
    } else {
        Err(ContactError::Param { name, value, expected })
    }
}
