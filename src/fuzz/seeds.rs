//! Seed inputs: small valid shapes built in code, written in every format the readers take
//! (13 encodings: STL ASCII and binary, OBJ, OFF, MSH 2.2 and 4.1 ASCII and 4.1 binary, Medit
//! ASCII and binary, Cart3D ASCII and binary, UH3D; and VTU volume meshes for `check`).

use std::fmt::Write as _;

use crate::geometry::DVec3;
use crate::mesh::VolumeMesh;
use crate::surface::{shapes, Surface};

/// A file format and how [`write`] encodes it; `extension` chooses the reader.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Encoding {
    StlAscii,
    StlBinary,
    Obj,
    Off,
    Msh2,
    Msh4Ascii,
    Msh4Binary,
    MeditAscii,
    MeditBinary,
    Cart3dAscii,
    Cart3dBinary,
    Uh3d,
    /// A volume mesh (`check` reads it; the others are surfaces).
    Vtu,
}

impl Encoding {
    pub const SURFACES: [Encoding; 12] = [
        Encoding::StlAscii,
        Encoding::StlBinary,
        Encoding::Obj,
        Encoding::Off,
        Encoding::Msh2,
        Encoding::Msh4Ascii,
        Encoding::Msh4Binary,
        Encoding::MeditAscii,
        Encoding::MeditBinary,
        Encoding::Cart3dAscii,
        Encoding::Cart3dBinary,
        Encoding::Uh3d,
    ];

    pub fn extension(self) -> &'static str {
        match self {
            Encoding::StlAscii | Encoding::StlBinary => "stl",
            Encoding::Obj => "obj",
            Encoding::Off => "off",
            Encoding::Msh2 | Encoding::Msh4Ascii | Encoding::Msh4Binary => "msh",
            Encoding::MeditAscii => "mesh",
            Encoding::MeditBinary => "meshb",
            Encoding::Cart3dAscii | Encoding::Cart3dBinary => "tri",
            Encoding::Uh3d => "uh3d",
            Encoding::Vtu => "vtu",
        }
    }

    /// Text formats get text mutations (numbers, lines) besides byte ones.
    pub fn is_text(self) -> bool {
        !matches!(
            self,
            Encoding::StlBinary | Encoding::Msh4Binary | Encoding::MeditBinary | Encoding::Cart3dBinary
        )
    }
}

/// The small closed shapes the seeds are made of: a cube, a finer box, a sphere, a block with
/// a concave groove (concave ridges) and an L of voxels (a concave corner).
pub fn shapes() -> Vec<(&'static str, Surface)> {
    vec![
        ("cube", shapes::cuboid(DVec3::ONE, 1)),
        ("box", shapes::cuboid(DVec3::new(2.0, 1.0, 0.5), 2)),
        ("sphere", shapes::icosphere(1.0, 1)),
        ("groove", shapes::grooved_block(90.0, 1)),
        ("ell", shapes::voxels([2, 2, 1], 1.0, 1, |i, j, _| i == 0 || j == 0)),
    ]
}

/// A small hybrid volume mesh for the `check` seeds.
pub fn volume() -> VolumeMesh {
    crate::quality::samples::hybrid_column()
}

/// `s` encoded as `encoding` (surfaces only).
pub fn write(s: &Surface, encoding: Encoding) -> Vec<u8> {
    match encoding {
        Encoding::StlAscii => stl_ascii(s).into_bytes(),
        Encoding::StlBinary => stl_binary(s),
        Encoding::Obj => obj(s).into_bytes(),
        Encoding::Off => off(s).into_bytes(),
        Encoding::Msh2 => msh2(s).into_bytes(),
        Encoding::Msh4Ascii | Encoding::Msh4Binary => msh4(s, encoding == Encoding::Msh4Ascii),
        Encoding::MeditAscii | Encoding::MeditBinary => {
            let mut out = Vec::new();
            crate::io::medit::write_surface(&mut out, s, encoding == Encoding::MeditBinary)
                .expect("writing to memory");
            out
        }
        Encoding::Cart3dAscii => cart3d_ascii(s).into_bytes(),
        Encoding::Cart3dBinary => cart3d_binary(s),
        Encoding::Uh3d => uh3d(s).into_bytes(),
        Encoding::Vtu => panic!("VTU holds volume meshes: use write_volume"),
    }
}

/// A volume mesh as VTU.
pub fn write_volume(mesh: &VolumeMesh) -> Vec<u8> {
    let mut out = Vec::new();
    crate::io::vtu::write(&mut out, mesh).expect("writing to memory");
    out
}

/// Shortest text that reads back as the same `f64`.
fn num(x: f64) -> String {
    format!("{x:?}")
}

fn stl_ascii(s: &Surface) -> String {
    let mut out = String::from("solid wall\n");
    for t in 0..s.triangles.len() {
        out += "facet normal 0 0 0\nouter loop\n";
        for p in s.triangle_points(t) {
            let _ = writeln!(out, "vertex {} {} {}", num(p.x), num(p.y), num(p.z));
        }
        out += "endloop\nendfacet\n";
    }
    out + "endsolid wall\n"
}

fn stl_binary(s: &Surface) -> Vec<u8> {
    let mut out = vec![0u8; 80];
    out.extend((s.triangles.len() as u32).to_le_bytes());
    for t in 0..s.triangles.len() {
        out.extend([0u8; 12]);
        for p in s.triangle_points(t) {
            p.to_array().iter().for_each(|&x| out.extend((x as f32).to_le_bytes()));
        }
        out.extend([0u8; 2]);
    }
    out
}

fn obj(s: &Surface) -> String {
    let mut out = String::new();
    s.points.iter().for_each(|p| _ = writeln!(out, "v {} {} {}", num(p.x), num(p.y), num(p.z)));
    out += "g wall\n";
    s.triangles.iter().for_each(|t| _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1));
    out
}

fn off(s: &Surface) -> String {
    let mut out = format!("OFF\n{} {} 0\n", s.points.len(), s.triangles.len());
    s.points.iter().for_each(|p| _ = writeln!(out, "{} {} {}", num(p.x), num(p.y), num(p.z)));
    s.triangles.iter().for_each(|t| _ = writeln!(out, "3 {} {} {}", t[0], t[1], t[2]));
    out
}

fn msh2(s: &Surface) -> String {
    let mut out = String::from("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    let _ = writeln!(out, "$PhysicalNames\n1\n2 1 \"wall\"\n$EndPhysicalNames\n$Nodes\n{}", s.points.len());
    for (i, p) in s.points.iter().enumerate() {
        let _ = writeln!(out, "{} {} {} {}", i + 1, num(p.x), num(p.y), num(p.z));
    }
    let _ = writeln!(out, "$EndNodes\n$Elements\n{}", s.triangles.len());
    for (i, t) in s.triangles.iter().enumerate() {
        let _ = writeln!(out, "{} 2 2 1 1 {} {} {}", i + 1, t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out + "$EndElements\n"
}

/// Through the volume writer: a mesh of no cells whose boundary is the surface.
fn msh4(s: &Surface, ascii: bool) -> Vec<u8> {
    let mut mesh = VolumeMesh { points: s.points.clone(), ..VolumeMesh::default() };
    mesh.boundary.triangles = s.triangles.clone();
    mesh.boundary.triangle_patch = s.triangle_patch.clone();
    mesh.patch_names = s.patch_names.clone();
    let mut out = Vec::new();
    crate::io::msh::write(&mut out, &mesh, ascii).expect("writing to memory");
    out
}

fn cart3d_ascii(s: &Surface) -> String {
    let mut out = format!("{} {}\n", s.points.len(), s.triangles.len());
    s.points.iter().for_each(|p| _ = writeln!(out, "{} {} {}", num(p.x), num(p.y), num(p.z)));
    s.triangles.iter().for_each(|t| _ = writeln!(out, "{} {} {}", t[0] + 1, t[1] + 1, t[2] + 1));
    s.triangle_patch.iter().for_each(|p| _ = writeln!(out, "{}", p + 1));
    out
}

/// Little-endian Fortran records with 4-byte integers and 8-byte reals.
fn cart3d_binary(s: &Surface) -> Vec<u8> {
    let mut out = Vec::new();
    let mut record = |body: Vec<u8>| {
        out.extend((body.len() as u32).to_le_bytes());
        out.extend(&body);
        out.extend((body.len() as u32).to_le_bytes());
    };
    let ints = |v: &mut dyn Iterator<Item = u32>| v.flat_map(u32::to_le_bytes).collect::<Vec<u8>>();
    record(ints(&mut [s.points.len() as u32, s.triangles.len() as u32].into_iter()));
    record(s.points.iter().flat_map(|p| p.to_array()).flat_map(f64::to_le_bytes).collect());
    record(ints(&mut s.triangles.iter().flatten().map(|v| v + 1)));
    record(ints(&mut s.triangle_patch.iter().map(|p| p + 1)));
    out
}

fn uh3d(s: &Surface) -> String {
    let (n, t) = (s.points.len(), s.triangles.len());
    let mut out = format!("seed\n{n}, {n}, {t}, {t}, 1, 1\n");
    for (i, p) in s.points.iter().enumerate() {
        let _ = writeln!(out, "{}, {}, {}, {}", i + 1, num(p.x), num(p.y), num(p.z));
    }
    for (i, tri) in s.triangles.iter().enumerate() {
        let _ = writeln!(out, "{}, {}, {}, {}, 1", i + 1, tri[0] + 1, tri[1] + 1, tri[2] + 1);
    }
    out + "1, 'wall'\n99,99,99,99,99\n"
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::SurfaceFormat;

    /// Every seed reads back as its shape: the mutations start from valid files.
    #[test]
    fn every_seed_reads_back() {
        for (name, shape) in shapes() {
            for encoding in Encoding::SURFACES {
                let bytes = write(&shape, encoding);
                let format =
                    SurfaceFormat::from_path(format!("x.{}", encoding.extension()).as_ref()).unwrap();
                let read = format.parse(&bytes).unwrap_or_else(|e| panic!("{name} as {encoding:?}: {e}"));
                assert_eq!(read.triangles.len(), shape.triangles.len(), "{name} as {encoding:?}");
            }
        }
        let mesh = crate::io::vtu::parse(&write_volume(&volume())).unwrap();
        assert_eq!(mesh.points.len(), volume().points.len());
    }
}
