//! Frames in `DIR/frames/`: one `.vtu` file per frame and data set, and one ParaView collection per data set
//! (`structure.pvd`, `particles.pvd`), kept current after every frame.
//!
//! A frame is streamed by the direct writer (`vtu.rs`) where it handles the frame's shape, else written by vtkio
//! (`vtk.rs`); the two give the same bytes.

use std::io::Write as _;
use std::path::{Path, PathBuf};

use cosim_proto::messages::{FemMesh, FemSnapshot};
use vtkio::model::UnstructuredGridPiece;

use super::fields::{concat, Part, PointField};
use super::pvd::PvdCollection;
use super::vtk::{particle_piece, structure_piece, vtkio_xml};
use super::{vtu, with_temporary, write_atomic, OutputError, Result};

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
    /// ([`super::von_mises_2d`], the active scalar), `stress` (σxx, σyy, σxy), `solid` (index into
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
        let path = self.write_points(&name, x, fields)?;
        self.particles.push(t, &name)?;
        Ok(path)
    }

    /// Write `DIR/frames/{name}` (one `VTK_VERTEX` cell per point at `x`, z = 0, with `fields` as point data),
    /// listed in no collection (a snapshot's contacts, `cosim snapshot`); returns its path.
    pub fn write_points(&mut self, name: &str, x: &[Part<'_, [f64; 2]>], fields: &[PointField<'_>]) -> Result<PathBuf> {
        let path = self.dir.join(name);
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
        if vtu::particles_writable(n, fields) {
            write_streamed(&path, |out| vtu::write_particles(out, n, x, fields))?;
        } else {
            let piece = particle_piece(&concat(x), fields);
            write_vtu(&path, piece)?;
        }
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
    let Some(checked) = vtu::check(&piece) else {
        let bytes = vtkio_xml(path, piece)?;
        return write_atomic(path, &bytes);
    };
    write_streamed(path, |out| checked.write(out))
}

#[cfg(test)]
mod tests {
    use super::super::pvd::parse_xml_elements;
    use super::super::test_dir;
    use super::super::vtk::two_element_mesh;
    use super::*;
    use vtkio::model::{Attribute, CellType, DataArray, DataSet, Piece, Vtk};

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
}
