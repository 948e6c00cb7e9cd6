//! The per-point columns of a frame, as the frame writers take them: whole slices, or consecutive parts (the fluid's
//! values, then the walls') that no writer has to copy into one array.

/// A run of consecutive values of a per-particle column: the values of a slice, or one value repeated.
#[derive(Clone, Copy, Debug)]
pub enum Part<'a, T> {
    /// These values.
    Slice(&'a [T]),
    /// This value, this many times.
    Repeat(T, usize),
}

impl<T> Part<'_, T> {
    /// Number of values.
    pub fn len(&self) -> usize {
        match self {
            Part::Slice(v) => v.len(),
            Part::Repeat(_, n) => *n,
        }
    }

    /// True when the part holds no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The values of `parts`, one after the other, in a new vector.
pub(super) fn concat<T: Copy>(parts: &[Part<'_, T>]) -> Vec<T> {
    let mut out = Vec::with_capacity(parts.iter().map(Part::len).sum());
    for part in parts {
        match *part {
            Part::Slice(v) => out.extend_from_slice(v),
            Part::Repeat(x, n) => out.extend(std::iter::repeat_n(x, n)),
        }
    }
    out
}

/// A per-particle array for [`super::FrameWriter::write_particles`].
#[derive(Clone, Copy, Debug)]
pub enum PointField<'a> {
    /// One value per point.
    Scalar(&'a str, &'a [f64]),
    /// A 2D vector per point (written with z = 0).
    Vector(&'a str, &'a [[f64; 2]]),
    /// One value per point, from consecutive parts (no concatenated copy is made).
    ScalarParts(&'a str, &'a [Part<'a, f64>]),
    /// A 2D vector per point (written with z = 0), from consecutive parts.
    VectorParts(&'a str, &'a [Part<'a, [f64; 2]>]),
}

impl PointField<'_> {
    /// The array's name.
    pub fn name(&self) -> &str {
        match self {
            PointField::Scalar(name, _)
            | PointField::Vector(name, _)
            | PointField::ScalarParts(name, _)
            | PointField::VectorParts(name, _) => name,
        }
    }

    /// Number of values (points).
    pub fn len(&self) -> usize {
        match self {
            PointField::Scalar(_, v) => v.len(),
            PointField::Vector(_, v) => v.len(),
            PointField::ScalarParts(_, parts) => parts.iter().map(Part::len).sum(),
            PointField::VectorParts(_, parts) => parts.iter().map(Part::len).sum(),
        }
    }

    /// True when the field holds no value.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A vector field (else a scalar one).
    pub fn is_vector(&self) -> bool {
        matches!(self, PointField::Vector(..) | PointField::VectorParts(..))
    }
}
