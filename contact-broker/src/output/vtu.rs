//! A direct serialiser of the VTK XML unstructured grids the frames are made of: the very bytes vtkio 0.6 writes
//! for them (inline `binary` data arrays, base64 of a UInt64 byte count followed by the little-endian values, no
//! whitespace), produced in one pass. vtkio's serde path takes 15–120 ms for a 26,000-particle frame; this one a
//! few ms. Only the shapes [`super::vtk`] builds are handled (f64 points, `XML` connectivity and offsets, scalar and
//! vector arrays of f64, u64, u32 or u8 with plain names); for anything else [`check`] answers `None` and the
//! caller falls back to vtkio. The tests compare the two byte for byte.

use std::io::{self, Write};

use vtkio::model::{Attribute, CellType, ElementType, IOBuffer, UnstructuredGridPiece, VertexNumbers};

use super::fields::{Part, PointField};

const B64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// A streaming standard base64 encoder (with `=` padding): bytes go in as they come, the text goes out in blocks,
/// so a data array is never held whole a second time (or a third, as text) while a frame is written.
struct Base64<'w, W: Write> {
    out: &'w mut W,
    /// Bytes waiting for a full group of three.
    pending: [u8; 3],
    held: usize,
    text: Vec<u8>,
}

impl<'w, W: Write> Base64<'w, W> {
    const BLOCK: usize = 16 * 1024;

    fn new(out: &'w mut W) -> Self {
        Self {
            out,
            pending: [0; 3],
            held: 0,
            text: Vec::with_capacity(Self::BLOCK + 4),
        }
    }

    fn group(&mut self, c: [u8; 3]) {
        let n = u32::from(c[0]) << 16 | u32::from(c[1]) << 8 | u32::from(c[2]);
        self.text.extend([18, 12, 6, 0].map(|s| B64[(n >> s & 63) as usize]));
    }

    fn push(&mut self, mut bytes: &[u8]) -> io::Result<()> {
        while self.held > 0 && !bytes.is_empty() {
            self.pending[self.held] = bytes[0];
            self.held += 1;
            bytes = &bytes[1..];
            if self.held == 3 {
                self.held = 0;
                self.group(self.pending);
            }
        }
        let mut groups = bytes.chunks_exact(3);
        for c in &mut groups {
            self.group([c[0], c[1], c[2]]);
            if self.text.len() >= Self::BLOCK {
                self.out.write_all(&self.text)?;
                self.text.clear();
            }
        }
        for &b in groups.remainder() {
            self.pending[self.held] = b;
            self.held += 1;
        }
        Ok(())
    }

    fn finish(mut self) -> io::Result<()> {
        let n = u32::from(self.pending[0]) << 16 | u32::from(self.pending[1]) << 8;
        match self.held {
            1 => self
                .text
                .extend([B64[(n >> 18) as usize], B64[(n >> 12 & 63) as usize], b'=', b'=']),
            2 => self.text.extend([
                B64[(n >> 18) as usize],
                B64[(n >> 12 & 63) as usize],
                B64[(n >> 6 & 63) as usize],
                b'=',
            ]),
            _ => {}
        }
        self.out.write_all(&self.text)
    }
}

/// Standard base64 (with `=` padding) of `bytes`, appended to `out`.
#[cfg(test)]
fn base64(bytes: &[u8], out: &mut Vec<u8>) {
    let mut enc = Base64::new(out);
    enc.push(bytes).expect("writing to memory");
    enc.finish().expect("writing to memory");
}

/// VTK type name and byte count of a buffer; `None` for types the frames never hold.
fn kind(buf: &IOBuffer) -> Option<(&'static str, usize)> {
    Some(match buf {
        IOBuffer::F64(v) => ("Float64", 8 * v.len()),
        IOBuffer::U64(v) => ("UInt64", 8 * v.len()),
        IOBuffer::U32(v) => ("UInt32", 4 * v.len()),
        IOBuffer::U8(v) => ("UInt8", v.len()),
        _ => return None,
    })
}

/// The little-endian bytes of the values, into the encoder a few thousand at a time.
fn values<W: Write>(enc: &mut Base64<'_, W>, buf: &IOBuffer) -> io::Result<()> {
    fn each<W: Write, const N: usize, T: Copy>(
        enc: &mut Base64<'_, W>,
        v: &[T],
        le: impl Fn(T) -> [u8; N],
    ) -> io::Result<()> {
        let mut block = Vec::with_capacity(N * 1024);
        for chunk in v.chunks(1024) {
            block.clear();
            block.extend(chunk.iter().flat_map(|&x| le(x)));
            enc.push(&block)?;
        }
        Ok(())
    }
    match buf {
        IOBuffer::F64(v) => each(enc, v, f64::to_le_bytes),
        IOBuffer::U64(v) => each(enc, v, u64::to_le_bytes),
        IOBuffer::U32(v) => each(enc, v, u32::to_le_bytes),
        IOBuffer::U8(v) => enc.push(v),
        _ => unreachable!("checked by `kind`"),
    }
}

/// `<DataArray …>base64</DataArray>`; `name` is omitted for the points. The buffer's kind is checked first.
fn array<W: Write>(out: &mut W, name: Option<&str>, components: u32, buf: &IOBuffer) -> io::Result<()> {
    let (ty, len) = kind(buf).expect("checked by `check`");
    array_with(out, name, ty, components, len, |enc| values(enc, buf))
}

/// `<DataArray …>base64</DataArray>` of `len` bytes that `body` pushes into the encoder.
fn array_with<W: Write>(
    out: &mut W,
    name: Option<&str>,
    ty: &str,
    components: u32,
    len: usize,
    body: impl FnOnce(&mut Base64<'_, W>) -> io::Result<()>,
) -> io::Result<()> {
    write!(out, "<DataArray type=\"{ty}\"")?;
    if let Some(name) = name {
        write!(out, " Name=\"{name}\"")?;
    }
    write!(out, " format=\"binary\" NumberOfComponents=\"{components}\">")?;
    let mut enc = Base64::new(out);
    // vtkio's binary block: a UInt64 byte count, then the values.
    enc.push(&(len as u64).to_le_bytes())?;
    body(&mut enc)?;
    enc.finish()?;
    out.write_all(b"</DataArray>")
}

/// Values into the encoder a few thousand bytes at a time.
struct Blocks<'e, 'w, W: Write> {
    enc: &'e mut Base64<'w, W>,
    block: Vec<u8>,
}

impl<'e, 'w, W: Write> Blocks<'e, 'w, W> {
    const BYTES: usize = 8 * 1024;

    fn new(enc: &'e mut Base64<'w, W>) -> Self {
        Self {
            enc,
            block: Vec::with_capacity(Self::BYTES + 24),
        }
    }

    #[inline]
    fn put(&mut self, bytes: &[u8]) -> io::Result<()> {
        self.block.extend_from_slice(bytes);
        if self.block.len() >= Self::BYTES {
            self.enc.push(&self.block)?;
            self.block.clear();
        }
        Ok(())
    }

    fn finish(self) -> io::Result<()> {
        self.enc.push(&self.block)
    }
}

/// The little-endian bytes of every value of `parts`, `le` writing one value.
fn parts_values<W: Write, T: Copy>(
    enc: &mut Base64<'_, W>,
    parts: &[Part<'_, T>],
    le: impl Fn(T, &mut Blocks<'_, '_, W>) -> io::Result<()>,
) -> io::Result<()> {
    let mut blocks = Blocks::new(enc);
    for part in parts {
        match *part {
            Part::Slice(v) => v.iter().try_for_each(|&x| le(x, &mut blocks))?,
            Part::Repeat(x, n) => (0..n).try_for_each(|_| le(x, &mut blocks))?,
        }
    }
    blocks.finish()
}

/// A 2D vector as a VTK 3-vector (z = 0).
fn vec3_le<W: Write>(p: [f64; 2], b: &mut Blocks<'_, '_, W>) -> io::Result<()> {
    b.put(&p[0].to_le_bytes())?;
    b.put(&p[1].to_le_bytes())?;
    b.put(&0f64.to_le_bytes())
}

/// Whether [`write_particles`] writes a frame of `n` points with `columns` as vtkio would (names it can write
/// as they are, at least one point); else the caller builds the piece and falls back to vtkio.
pub(crate) fn particles_writable(n: usize, columns: &[PointField<'_>]) -> bool {
    n > 0
        && columns.iter().all(|c| {
            let name = c.name();
            !name.is_empty() && name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
        })
}

/// The opening of a `.vtu` file as vtkio writes it, up to the `<Piece …>` of `points` points and `cells` cells.
fn header<W: Write>(out: &mut W, points: usize, cells: usize) -> io::Result<()> {
    out.write_all(
        b"<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\
          <UnstructuredGrid>",
    )?;
    write!(
        out,
        "<Piece NumberOfPoints=\"{points}\" NumberOfCells=\"{cells}\" NumberOfLines=\"0\" NumberOfStrips=\"0\" \
         NumberOfPolys=\"0\" NumberOfVerts=\"0\">"
    )
}

/// The `.vtu` file of `n` particles at `x` (one `VTK_VERTEX` cell each, z = 0) with `columns` as point data,
/// streamed from the parts as they are: byte for byte what [`Checked::write`] writes for the piece
/// `super::vtk` builds of the same values (the tests compare the two), without that piece or its copies.
/// Every part list must hold `n` values and [`particles_writable`] must hold.
pub(crate) fn write_particles<W: Write>(
    out: &mut W,
    n: usize,
    x: &[Part<'_, [f64; 2]>],
    columns: &[PointField<'_>],
) -> io::Result<()> {
    header(out, n, n)?;
    if columns.is_empty() {
        out.write_all(b"<PointData/>")?;
    } else {
        out.write_all(b"<PointData")?;
        // vtkio marks the first scalar and the first vector array as the active ones.
        if let Some(c) = columns.iter().find(|c| !c.is_vector()) {
            write!(out, " Scalars=\"{}\"", c.name())?;
        }
        if let Some(c) = columns.iter().find(|c| c.is_vector()) {
            write!(out, " Vectors=\"{}\"", c.name())?;
        }
        out.write_all(b">")?;
        let scalar = |v: f64, b: &mut Blocks<'_, '_, W>| b.put(&v.to_le_bytes());
        for c in columns {
            let name = Some(c.name());
            match *c {
                PointField::Scalar(_, v) => array_with(out, name, "Float64", 1, 8 * n, |enc| {
                    parts_values(enc, &[Part::Slice(v)], scalar)
                })?,
                PointField::ScalarParts(_, parts) => {
                    array_with(out, name, "Float64", 1, 8 * n, |enc| parts_values(enc, parts, scalar))?
                }
                PointField::Vector(_, v) => array_with(out, name, "Float64", 3, 24 * n, |enc| {
                    parts_values(enc, &[Part::Slice(v)], vec3_le)
                })?,
                PointField::VectorParts(_, parts) => {
                    array_with(out, name, "Float64", 3, 24 * n, |enc| parts_values(enc, parts, vec3_le))?
                }
            }
        }
        out.write_all(b"</PointData>")?;
    }
    out.write_all(b"<CellData/><Points>")?;
    array_with(out, None, "Float64", 3, 24 * n, |enc| parts_values(enc, x, vec3_le))?;
    out.write_all(b"</Points><Cells>")?;
    let counting = |first: u64| {
        move |enc: &mut Base64<'_, W>| {
            let mut blocks = Blocks::new(enc);
            (first..first + n as u64).try_for_each(|k| blocks.put(&k.to_le_bytes()))?;
            blocks.finish()
        }
    };
    array_with(out, Some("connectivity"), "UInt64", 1, 8 * n, counting(0))?;
    array_with(out, Some("offsets"), "UInt64", 1, 8 * n, counting(1))?;
    array_with(out, Some("types"), "UInt8", 1, n, |enc| {
        parts_values(enc, &[Part::Repeat(CellType::Vertex as u8, n)], |t, b| b.put(&[t]))
    })?;
    out.write_all(b"</Cells></Piece></UnstructuredGrid></VTKFile>")
}

/// The arrays of a `<PointData>` or `<CellData>`: (name, components, data), and the active scalar and vector
/// names; `None` for what this writer does not handle.
type Arrays<'a> = (Vec<(&'a str, u32, &'a IOBuffer)>, Option<&'a str>, Option<&'a str>);

fn arrays(attrs: &[Attribute]) -> Option<Arrays<'_>> {
    let (mut scalars, mut vectors) = (None, None);
    let mut arrays = Vec::with_capacity(attrs.len());
    for a in attrs {
        let Attribute::DataArray(d) = a else {
            return None;
        };
        if d.name.is_empty() || !d.name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') {
            return None;
        }
        // vtkio marks the first scalar and the first vector array as the active ones.
        let components = match d.elem {
            ElementType::Scalars {
                num_comp,
                lookup_table: None,
            } => {
                scalars.get_or_insert(d.name.as_str());
                num_comp
            }
            ElementType::Vectors => {
                vectors.get_or_insert(d.name.as_str());
                3
            }
            _ => return None,
        };
        if kind(&d.data)?.1 == 0 {
            return None;
        }
        arrays.push((d.name.as_str(), components, &d.data));
    }
    Some((arrays, scalars, vectors))
}

/// `<PointData …>` or `<CellData …>` with its arrays (`<Tag/>` when there are none).
fn attributes<W: Write>(out: &mut W, tag: &str, (arrays, scalars, vectors): Arrays<'_>) -> io::Result<()> {
    if arrays.is_empty() {
        return write!(out, "<{tag}/>");
    }
    write!(out, "<{tag}")?;
    if let Some(s) = scalars {
        write!(out, " Scalars=\"{s}\"")?;
    }
    if let Some(v) = vectors {
        write!(out, " Vectors=\"{v}\"")?;
    }
    out.write_all(b">")?;
    for (name, components, data) in arrays {
        array(out, Some(name), components, data)?;
    }
    write!(out, "</{tag}>")
}

/// A piece this writer can write: its point and cell arrays and its connectivity.
pub(crate) struct Checked<'a> {
    piece: &'a UnstructuredGridPiece,
    point: Arrays<'a>,
    cell: Arrays<'a>,
    connectivity: IOBuffer,
    offsets: IOBuffer,
}

/// Whether `piece` has the shape this writer handles (f64 points, `XML` connectivity, named scalar and vector arrays
/// of f64, u64, u32 or u8, none empty); `None` when the caller should fall back to vtkio.
pub(crate) fn check(piece: &UnstructuredGridPiece) -> Option<Checked<'_>> {
    let VertexNumbers::XML { connectivity, offsets } = &piece.cells.cell_verts else {
        return None;
    };
    if !matches!(piece.points, IOBuffer::F64(_)) || piece.points.is_empty() || connectivity.is_empty() {
        return None;
    }
    Some(Checked {
        piece,
        point: arrays(&piece.data.point)?,
        cell: arrays(&piece.data.cell)?,
        connectivity: IOBuffer::U64(connectivity.clone()),
        offsets: IOBuffer::U64(offsets.clone()),
    })
}

impl Checked<'_> {
    /// Write the `.vtu` file as vtkio writes it (XML format 1.0, little endian, UInt64 headers), streaming.
    pub(crate) fn write<W: Write>(self, out: &mut W) -> io::Result<()> {
        let piece = self.piece;
        let points = piece.points.len() / 3;
        let cells = piece.cells.types.len();
        header(out, points, cells)?;
        attributes(out, "PointData", self.point)?;
        attributes(out, "CellData", self.cell)?;
        out.write_all(b"<Points>")?;
        array(out, None, 3, &piece.points)?;
        out.write_all(b"</Points><Cells>")?;
        array(out, Some("connectivity"), 1, &self.connectivity)?;
        array(out, Some("offsets"), 1, &self.offsets)?;
        let types: Vec<u8> = piece.cells.types.iter().map(|&t| t as u8).collect();
        array(out, Some("types"), 1, &IOBuffer::U8(types))?;
        out.write_all(b"</Cells></Piece></UnstructuredGrid></VTKFile>")
    }
}

/// The `.vtu` file of `piece` in memory (tests compare it with vtkio's), or `None` when the piece holds something
/// this writer does not handle.
#[cfg(test)]
pub(crate) fn to_xml(piece: &UnstructuredGridPiece) -> Option<Vec<u8>> {
    let mut out = Vec::new();
    check(piece)?.write(&mut out).expect("writing to memory");
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_the_rfc_examples() {
        for (plain, encoded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut out = Vec::new();
            base64(plain.as_bytes(), &mut out);
            assert_eq!(String::from_utf8(out).unwrap(), encoded);
        }
    }
}
