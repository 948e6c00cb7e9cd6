//! The vtkio side of the frames (`DIR/frames/`): the unstructured-grid pieces of a structure frame and a particle
//! frame, and the `.vtu` bytes vtkio writes for them (base64 binary data, XML format 1.0). It is the reference the
//! direct writer (`vtu.rs`) is tested against byte for byte, and the writer of the frame shapes that one leaves
//! alone.
//!
//! Points carry z = 0: the simulation is 2D, ParaView is 3D.

use std::path::Path;

use cosim_proto::messages::{FemMesh, FemSnapshot};
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

use super::fields::{concat, PointField};
use super::{OutputError, Result};

/// In-plane von Mises stress `sqrt(σxx² − σxx σyy + σyy² + 3 σxy²)` of `[σxx, σyy, σxy]`.
///
/// This is the plane-stress form (σzz = 0); under plane strain σzz = ν (σxx + σyy) is left out, since ν is not
/// known where frames are written.
pub fn von_mises_2d(s: [f64; 3]) -> f64 {
    let [xx, yy, xy] = s;
    (xx * xx - xx * yy + yy * yy + 3.0 * xy * xy).sqrt()
}

/// The `.vtu` file as vtkio writes it (the reference the direct writer is tested against, and its fallback).
pub(super) fn vtkio_xml(path: &Path, piece: UnstructuredGridPiece) -> Result<Vec<u8>> {
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

/// The vtkio piece of a structure frame (see [`super::FrameWriter::write_structure`]); an error names `path` and
/// what in `mesh`, `snap` or `load` does not fit the mesh.
pub(super) fn structure_piece(
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

/// The vtkio piece of a particle frame (the fallback of [`super::FrameWriter::write_particle_parts`], and the reference
/// its streamed writer is tested against); the fields' lengths are checked by the caller.
pub(super) fn particle_piece(x: &[[f64; 2]], fields: &[PointField<'_>]) -> UnstructuredGridPiece {
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

/// Two elements sharing an edge: a unit quad (nodes 0 1 4 3) and a triangle (1 2 4), two solids.
#[cfg(test)]
pub(super) fn two_element_mesh() -> (FemMesh, FemSnapshot) {
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

#[cfg(test)]
mod tests {
    use super::super::fields::Part;
    use super::*;

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
    fn von_mises_of_pure_shear_and_uniaxial() {
        assert_eq!(von_mises_2d([2.0, 0.0, 0.0]), 2.0);
        assert_eq!(von_mises_2d([0.0, 0.0, 1.0]), 3f64.sqrt());
        assert_eq!(von_mises_2d([1.0, 1.0, 0.0]), 1.0);
    }
}
