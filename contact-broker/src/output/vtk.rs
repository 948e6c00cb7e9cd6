//! Frames in `DIR/frames/`: VTK XML unstructured grids (`.vtu`, written with vtkio, base64 binary data) and
//! one ParaView collection per data set (`structure.pvd`, `particles.pvd`).
//!
//! Points carry z = 0: the simulation is 2D, ParaView is 3D.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use cosim_proto::messages::{FemMesh, FemSnapshot};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use super::pvd::PvdCollection;
use super::{with_temporary, write_atomic, OutputError, Result};

/// In-plane von Mises stress `sqrt(σxx² − σxx σyy + σyy² + 3 σxy²)` of `[σxx, σyy, σxy]`.
///
/// This is the plane-stress form (σzz = 0); under plane strain σzz = ν (σxx + σyy) is left out, since ν is not
/// known where frames are written.
pub fn von_mises_2d(s: [f64; 3]) -> f64 {
    let [xx, yy, xy] = s;
    (xx * xx - xx * yy + yy * yy + 3.0 * xy * xy).sqrt()
}

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
fn concat<T: Copy>(parts: &[Part<'_, T>]) -> Vec<T> {
    let mut out = Vec::with_capacity(parts.iter().map(Part::len).sum());
    for part in parts {
        match *part {
            Part::Slice(v) => out.extend_from_slice(v),
            Part::Repeat(x, n) => out.extend(std::iter::repeat_n(x, n)),
        }
    }
    out
}

/// A per-particle array for [`FrameWriter::write_particles`].
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

/// Writes the frames of a run into `DIR/frames/` and keeps their `.pvd` collections current.
#[derive(Debug)]
pub struct FrameWriter {
    dir: PathBuf,
    structure: PvdCollection,
    particles: PvdCollection,
}

impl FrameWriter {
    /// Create `out_dir/frames/` (and `out_dir`) if needed. No collection is written before the first frame.
    pub fn new(out_dir: &Path) -> Result<Self> {
        let dir = out_dir.join("frames");
        std::fs::create_dir_all(&dir).map_err(|e| OutputError::io(&dir, e))?;
        Ok(Self {
            structure: PvdCollection::new(dir.join("structure.pvd")),
            particles: PvdCollection::new(dir.join("particles.pvd")),
            dir,
        })
    }

    /// Continue the frames of a run restarted from a checkpoint: frame `k` was taken at `times[k]`, and those of
    /// them already in `out_dir/frames/` (a restart into the same folder) stay listed in the collections.
    pub fn resume(out_dir: &Path, times: &[f64]) -> Result<Self> {
        let dir = out_dir.join("frames");
        std::fs::create_dir_all(&dir).map_err(|e| OutputError::io(&dir, e))?;
        let kept = |prefix: &str| -> Vec<(f64, String)> {
            times
                .iter()
                .enumerate()
                .map(|(k, &t)| (t, format!("{prefix}_{k:05}.vtu")))
                .filter(|(_, name)| dir.join(name).is_file())
                .collect()
        };
        Ok(Self {
            structure: PvdCollection::with_entries(dir.join("structure.pvd"), kept("structure"))?,
            particles: PvdCollection::with_entries(dir.join("particles.pvd"), kept("particles"))?,
            dir,
        })
    }

    /// The frames folder, `DIR/frames`.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The structure collection (`DIR/frames/structure.pvd`).
    pub fn structure_collection(&self) -> &PvdCollection {
        &self.structure
    }

    /// The particle collection (`DIR/frames/particles.pvd`).
    pub fn particle_collection(&self) -> &PvdCollection {
        &self.particles
    }

    /// Write `DIR/frames/structure_{index:05}.vtu` for time `t` and rewrite `structure.pvd`; returns the
    /// frame's path.
    ///
    /// Points are `snap.x` (z = 0); cells are `mesh.cells` as `VTK_QUAD` (4 nodes) or `VTK_TRIANGLE` (3).
    /// Point data: `displacement` (x − X), `velocity` (3 components, z = 0), `mass`. Cell data: `von_mises`
    /// ([`von_mises_2d`], the active scalar), `stress` (σxx, σyy, σxy), `solid` (index into
    /// `mesh.solid_names`).
    pub fn write_structure(
        &mut self,
        index: usize,
        t: f64,
        mesh: &FemMesh,
        snap: &FemSnapshot,
        load: Option<&[[f64; 2]]>,
    ) -> Result<PathBuf> {
        let name = format!("structure_{index:05}.vtu");
        let path = self.dir.join(&name);
        let piece = structure_piece(&path, mesh, snap, load)?;
        write_vtu(&path, piece)?;
        self.structure.push(t, &name)?;
        Ok(path)
    }

    /// Write `DIR/frames/particles_{index:05}.vtu` for time `t` (one `VTK_VERTEX` cell per particle at `x`,
    /// z = 0, with `fields` as point data) and rewrite `particles.pvd`; returns the frame's path.
    pub fn write_particles(
        &mut self,
        index: usize,
        t: f64,
        x: &[[f64; 2]],
        fields: &[PointField<'_>],
    ) -> Result<PathBuf> {
        self.write_particle_parts(index, t, &[Part::Slice(x)], fields)
    }

    /// [`FrameWriter::write_particles`] with the positions in consecutive parts (e.g. the fluid's, then the
    /// walls'): the frame is streamed from the parts as they are, with no concatenated copy of any array.
    pub fn write_particle_parts(
        &mut self,
        index: usize,
        t: f64,
        x: &[Part<'_, [f64; 2]>],
        fields: &[PointField<'_>],
    ) -> Result<PathBuf> {
        let name = format!("particles_{index:05}.vtu");
        let path = self.dir.join(&name);
        let n = x.iter().map(Part::len).sum();
        for field in fields {
            let len = field.len();
            if len != n {
                return Err(OutputError::input(
                    &path,
                    format!("point field `{}` has {len} entries for {n} particles", field.name()),
                ));
            }
        }
        if super::vtu::particles_writable(n, fields) {
            write_streamed(&path, |out| super::vtu::write_particles(out, n, x, fields))?;
        } else {
            let piece = particle_piece(&concat(x), fields);
            write_vtu(&path, piece)?;
        }
        self.particles.push(t, &name)?;
        Ok(path)
    }
}

/// Write a frame to a temporary file through `write` (streaming), then rename it.
fn write_streamed(
    path: &Path,
    write: impl FnOnce(&mut std::io::BufWriter<std::fs::File>) -> std::io::Result<()>,
) -> Result<()> {
    with_temporary(path, |tmp| {
        let mut out = std::io::BufWriter::with_capacity(64 * 1024, std::fs::File::create(tmp)?);
        write(&mut out)?;
        out.flush()
    })
}

/// Write the frame to a temporary file, streaming (the text of a frame is never held whole), then rename it.
fn write_vtu(path: &Path, piece: UnstructuredGridPiece) -> Result<()> {
    let Some(checked) = super::vtu::check(&piece) else {
        let bytes = vtkio_xml(path, piece)?;
        return write_atomic(path, &bytes);
    };
    write_streamed(path, |out| checked.write(out))
}

/// The `.vtu` file as vtkio writes it (the reference the direct writer is tested against, and its fallback).
fn vtkio_xml(path: &Path, piece: UnstructuredGridPiece) -> Result<Vec<u8>> {
    let vtk = Vtk {
        // XML format 1.0: 64-bit block headers (the `header_type="UInt64"` vtkio writes).
        version: Version::new((1, 0)),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(piece),
    };
    let mut bytes = Vec::new();
    vtk.write_xml(&mut bytes).map_err(|e| OutputError::Vtk {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    Ok(bytes)
}

fn vec3(v: &[[f64; 2]]) -> Vec<f64> {
    v.iter().flat_map(|p| [p[0], p[1], 0.0]).collect()
}

fn scalars(name: &str, num_comp: u32, data: impl Into<IOBuffer>) -> Attribute {
    Attribute::DataArray(DataArray {
        name: name.to_string(),
        elem: ElementType::Scalars {
            num_comp,
            lookup_table: None,
        },
        data: data.into(),
    })
}

fn vectors(name: &str, data: Vec<f64>) -> Attribute {
    Attribute::DataArray(DataArray {
        name: name.to_string(),
        elem: ElementType::Vectors,
        data: data.into(),
    })
}

fn structure_piece(
    path: &Path,
    mesh: &FemMesh,
    snap: &FemSnapshot,
    load: Option<&[[f64; 2]]>,
) -> Result<UnstructuredGridPiece> {
    let n = mesh.nodes.len();
    let m = mesh.cells.len();
    let check = |what: &str, len: usize, expected: usize, of: &str| {
        if len == expected {
            Ok(())
        } else {
            Err(OutputError::input(
                path,
                format!("{what} has {len} entries, the mesh has {expected} {of}"),
            ))
        }
    };
    check("snapshot x", snap.x.len(), n, "nodes")?;
    check("snapshot v", snap.v.len(), n, "nodes")?;
    check("mesh masses", mesh.masses.len(), n, "nodes")?;
    check("snapshot stress", snap.stress.len(), m, "elements")?;
    if let Some(load) = load {
        check("interface load", load.len(), n, "nodes")?;
    }
    check("mesh cell_solid", mesh.cell_solid.len(), m, "elements")?;

    let mut connectivity = Vec::with_capacity(4 * m);
    let mut offsets = Vec::with_capacity(m);
    let mut types = Vec::with_capacity(m);
    for (e, cell) in mesh.cells.iter().enumerate() {
        types.push(match cell.len() {
            3 => CellType::Triangle,
            4 => CellType::Quad,
            k => {
                return Err(OutputError::input(
                    path,
                    format!("element {e} has {k} nodes (3 or 4 expected)"),
                ))
            }
        });
        if let Some(&bad) = cell.iter().find(|&&id| id as usize >= n) {
            return Err(OutputError::input(
                path,
                format!("element {e} refers to node {bad}, the mesh has {n}"),
            ));
        }
        connectivity.extend(cell.iter().map(|&id| u64::from(id)));
        offsets.push(connectivity.len() as u64);
    }

    let displacement: Vec<[f64; 2]> = snap
        .x
        .iter()
        .zip(&mesh.nodes)
        .map(|(x, x0)| [x[0] - x0[0], x[1] - x0[1]])
        .collect();
    let von_mises: Vec<f64> = snap.stress.iter().map(|&s| von_mises_2d(s)).collect();
    let stress: Vec<f64> = snap.stress.iter().flatten().copied().collect();
    let mut point = vec![
        vectors("displacement", vec3(&displacement)),
        vectors("velocity", vec3(&snap.v)),
        scalars("mass", 1, mesh.masses.clone()),
    ];
    if let Some(load) = load {
        // DESIGN.md §4.5: the interface load is the contact impulse on each node over the coupling step [N/m].
        point.push(vectors("interface_load", vec3(load)));
    }

    Ok(UnstructuredGridPiece {
        points: vec3(&snap.x).into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML { connectivity, offsets },
            types,
        },
        data: Attributes {
            point,
            cell: vec![
                // First scalar array is the active one ParaView colours by.
                scalars("von_mises", 1, von_mises),
                scalars("stress", 3, stress),
                scalars("solid", 1, mesh.cell_solid.clone()),
            ],
        },
    })
}

/// The vtkio piece of a particle frame (the fallback of [`FrameWriter::write_particle_parts`], and the reference
/// its streamed writer is tested against); the fields' lengths are checked by the caller.
fn particle_piece(x: &[[f64; 2]], fields: &[PointField<'_>]) -> UnstructuredGridPiece {
    let n = x.len();
    let point = fields
        .iter()
        .map(|field| match *field {
            PointField::Scalar(name, v) => scalars(name, 1, v.to_vec()),
            PointField::Vector(name, v) => vectors(name, vec3(v)),
            PointField::ScalarParts(name, parts) => scalars(name, 1, concat(parts)),
            PointField::VectorParts(name, parts) => vectors(name, vec3(&concat(parts))),
        })
        .collect();
    UnstructuredGridPiece {
        points: vec3(x).into(),
        cells: Cells {
            cell_verts: VertexNumbers::XML {
                connectivity: (0..n as u64).collect(),
                offsets: (1..=n as u64).collect(),
            },
            types: vec![CellType::Vertex; n],
        },
        data: Attributes {
            point,
            cell: Vec::new(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::super::pvd::parse_xml_elements;
    use super::super::test_dir;
    use super::*;
    use vtkio::model::Piece;

    /// Two elements sharing an edge: a unit quad (nodes 0 1 4 3) and a triangle (1 2 4), two solids.
    fn two_element_mesh() -> (FemMesh, FemSnapshot) {
        let nodes = vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        let mesh = FemMesh {
            solid_names: vec!["a".into(), "b".into()],
            masses: vec![0.25, 0.5, 0.125, 0.25, 0.375],
            node_solid: vec![0, 0, 1, 0, 0],
            cells: vec![vec![0, 1, 4, 3], vec![1, 2, 4]],
            cell_solid: vec![0, 1],
            interface: Vec::new(),
            fixed: vec![0],
            dt_stable: 1e-4,
            nodes,
        };
        let snap = FemSnapshot {
            x: mesh.nodes.iter().map(|p| [p[0] + 0.1, p[1] - 0.3]).collect(),
            v: vec![[1.0, 2.0]; 5],
            stress: vec![[3.0, 1.0, 0.5], [-2.0e6, 1.0e5, 7.5e4]],
            energies: Vec::new(),
        };
        (mesh, snap)
    }

    fn read_piece(path: &Path) -> UnstructuredGridPiece {
        let vtk = Vtk::import(path).unwrap();
        let DataSet::UnstructuredGrid { mut pieces, .. } = vtk.data else {
            panic!("not an unstructured grid")
        };
        assert_eq!(pieces.len(), 1);
        match pieces.remove(0) {
            Piece::Inline(p) => *p,
            _ => panic!("piece not inline"),
        }
    }

    fn array<'a>(attrs: &'a [Attribute], name: &str) -> &'a DataArray {
        attrs
            .iter()
            .find_map(|a| match a {
                Attribute::DataArray(d) if d.name == name => Some(d),
                _ => None,
            })
            .unwrap_or_else(|| panic!("no array `{name}`"))
    }

    fn f64s(d: &DataArray) -> Vec<f64> {
        d.data.clone().cast_into::<f64>().unwrap()
    }

    /// The direct writer (`vtu.rs`) produces vtkio's bytes for every frame shape the runs write.
    #[test]
    fn direct_writer_matches_vtkio_byte_for_byte() {
        let path = Path::new("frame.vtu");
        let (mesh, snap) = two_element_mesh();
        let load = vec![[0.5, -1.5]; 5];
        let mut pieces = vec![
            structure_piece(path, &mesh, &snap, None).unwrap(),
            structure_piece(path, &mesh, &snap, Some(&load)).unwrap(),
        ];
        for n in [1usize, 2, 3, 7, 1000] {
            // Values with every byte pattern: thirds, negatives, subnormals, infinities.
            let x: Vec<[f64; 2]> = (0..n).map(|i| [i as f64 / 3.0, -1.0e-310 * i as f64]).collect();
            let v: Vec<[f64; 2]> = (0..n).map(|i| [f64::INFINITY, (i * 7919 % 13) as f64 - 6.5]).collect();
            let p: Vec<f64> = (0..n).map(|i| (i as f64).sqrt() * 1.0e5).collect();
            let kind: Vec<f64> = (0..n).map(|i| (i % 2) as f64).collect();
            let fields = [
                PointField::Vector("velocity", &v),
                PointField::Scalar("pressure", &p),
                PointField::Scalar("wall", &kind),
            ];
            for fields in [&fields[..], &fields[1..], &[]] {
                let piece = particle_piece(&x, fields);
                // The streamed particle writer, from the whole arrays and from parts of them.
                let mut streamed = Vec::new();
                super::super::vtu::write_particles(&mut streamed, n, &[Part::Slice(&x)], fields).unwrap();
                let reference = vtkio_xml(path, piece.clone()).unwrap();
                assert_eq!(
                    String::from_utf8(streamed).unwrap(),
                    String::from_utf8(reference.clone()).unwrap()
                );
                let k = n / 3;
                let xs = [Part::Slice(&x[..k]), Part::Slice(&x[k..])];
                let vs = [Part::Slice(&v[..k]), Part::Slice(&v[k..])];
                let ps = [Part::Repeat(p[0], 1), Part::Slice(&p[1..])];
                let parts = [
                    PointField::VectorParts("velocity", &vs),
                    PointField::ScalarParts("pressure", &ps),
                    PointField::Scalar("wall", &kind),
                ];
                let parts = &parts[3 - fields.len()..];
                let mut streamed = Vec::new();
                super::super::vtu::write_particles(&mut streamed, n, &xs, parts).unwrap();
                assert_eq!(
                    String::from_utf8(streamed).unwrap(),
                    String::from_utf8(reference).unwrap()
                );
                pieces.push(piece);
            }
        }
        for piece in pieces {
            let direct = super::super::vtu::to_xml(&piece).expect("a frame shape");
            assert_eq!(
                String::from_utf8(direct).unwrap(),
                String::from_utf8(vtkio_xml(path, piece).unwrap()).unwrap()
            );
        }
        // Empty frames are left to vtkio.
        assert!(super::super::vtu::to_xml(&particle_piece(&[], &[])).is_none());
        assert!(!super::super::vtu::particles_writable(0, &[]));
    }

    #[test]
    fn structure_frame_round_trips_through_vtkio() {
        let out = test_dir("vtk");
        let (mesh, snap) = two_element_mesh();
        let mut w = FrameWriter::new(&out).unwrap();
        let path = w.write_structure(3, 0.015, &mesh, &snap, None).unwrap();
        assert_eq!(path, out.join("frames/structure_00003.vtu"));

        let piece = read_piece(&path);
        assert_eq!(piece.num_points(), 5);
        assert_eq!(piece.cells.types, vec![CellType::Quad, CellType::Triangle]);
        let (connectivity, offsets) = piece.cells.cell_verts.clone().into_xml();
        assert_eq!(connectivity, vec![0, 1, 4, 3, 1, 2, 4]);
        assert_eq!(offsets, vec![4, 7]);
        let points = piece.points.clone().cast_into::<f64>().unwrap();
        assert_eq!(points[3..6], [1.1, -0.3, 0.0]);

        let disp = f64s(array(&piece.data.point, "displacement"));
        assert_eq!(disp.len(), 15);
        assert_eq!(disp[12].to_bits(), (1.0f64 + 0.1 - 1.0).to_bits());
        assert_eq!(disp[13].to_bits(), (1.0f64 - 0.3 - 1.0).to_bits());
        assert_eq!(f64s(array(&piece.data.point, "velocity"))[..3], [1.0, 2.0, 0.0]);
        assert_eq!(f64s(array(&piece.data.point, "mass")), mesh.masses);

        let stress = array(&piece.data.cell, "stress");
        assert_eq!(stress.num_comp(), 3);
        assert_eq!(f64s(stress), vec![3.0, 1.0, 0.5, -2.0e6, 1.0e5, 7.5e4]);
        let vm = f64s(array(&piece.data.cell, "von_mises"));
        assert_eq!(vm[0], (9.0f64 - 3.0 + 1.0 + 0.75).sqrt());
        assert_eq!(
            array(&piece.data.cell, "solid")
                .data
                .clone()
                .cast_into::<u32>()
                .unwrap(),
            vec![0, 1]
        );
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn collection_lists_every_structure_frame_with_its_time() {
        let out = test_dir("pvd-frames");
        let (mesh, snap) = two_element_mesh();
        let mut w = FrameWriter::new(&out).unwrap();
        let times = [0.0, 0.005, 0.01];
        for (i, &t) in times.iter().enumerate() {
            w.write_structure(i, t, &mesh, &snap, None).unwrap();
            // After every frame the collection on disk is complete and well-formed.
            let text = std::fs::read_to_string(out.join("frames/structure.pvd")).unwrap();
            let elements = parse_xml_elements(&text).unwrap();
            assert_eq!(elements[0].0, "VTKFile");
            assert!(elements[0].1.contains(&("type".into(), "Collection".into())));
            let data_sets: Vec<_> = elements.iter().filter(|(n, _)| n == "DataSet").collect();
            assert_eq!(data_sets.len(), i + 1);
            for (j, (_, attrs)) in data_sets.iter().enumerate() {
                let get = |k: &str| attrs.iter().find(|(a, _)| a == k).map(|(_, v)| v.as_str());
                assert_eq!(get("timestep").unwrap().parse::<f64>().unwrap(), times[j]);
                assert_eq!(get("file"), Some(format!("structure_{j:05}.vtu").as_str()));
                assert!(out.join("frames").join(get("file").unwrap()).is_file());
            }
        }
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn inconsistent_snapshot_is_an_error_naming_the_frame() {
        let out = test_dir("vtk-bad");
        let (mesh, mut snap) = two_element_mesh();
        snap.stress.pop();
        let mut w = FrameWriter::new(&out).unwrap();
        let e = w.write_structure(0, 0.0, &mesh, &snap, None).unwrap_err().to_string();
        assert!(e.contains("structure_00000.vtu") && e.contains("stress"), "{e}");
        assert!(w.structure_collection().entries().is_empty());
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn particle_frame_round_trips_through_vtkio() {
        let out = test_dir("vtk-particles");
        let mut w = FrameWriter::new(&out).unwrap();
        let x = [[0.0, 0.0], [0.5, 0.25], [1.0, 2.0]];
        let v = [[1.0, 0.0], [0.0, 1.0], [-1.0, -1.0]];
        let p = [1.0, 2.0, 3.0];
        let path = w.write_particles(
            0,
            0.0,
            &x,
            &[PointField::Vector("velocity", &v), PointField::Scalar("pressure", &p)],
        );
        let piece = read_piece(&path.unwrap());
        assert_eq!(piece.num_points(), 3);
        assert_eq!(piece.cells.types, vec![CellType::Vertex; 3]);
        assert_eq!(f64s(array(&piece.data.point, "pressure")), p);
        assert!(out.join("frames/particles.pvd").is_file());
        let bad = w.write_particles(1, 0.1, &x, &[PointField::Scalar("pressure", &p[..2])]);
        assert!(bad.unwrap_err().to_string().contains("pressure"));
        std::fs::remove_dir_all(&out).unwrap();
    }

    #[test]
    fn von_mises_of_pure_shear_and_uniaxial() {
        assert_eq!(von_mises_2d([2.0, 0.0, 0.0]), 2.0);
        assert_eq!(von_mises_2d([0.0, 0.0, 1.0]), 3f64.sqrt());
        assert_eq!(von_mises_2d([1.0, 1.0, 0.0]), 1.0);
    }
}
