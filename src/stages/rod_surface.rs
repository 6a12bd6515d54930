//! The rod's surface as stage 3 meshes it: the validated surface of stage 1 (metres, the file's
//! axes) moved into the rod frame and scaled to millimetres (origin at the crank pin A, x̂ along
//! A→B, ẑ the pin axis: the mechanism frame of [`crate::geometry::mechanism_frame`]), then
//! simplified by quadric error metrics ([`crate::geometry::simplify`]) within
//! [`SIMPLIFY_TOLERANCE_MM`], so that what gmsh reads does not grow with the export's triangle
//! count. gmsh's sizes and tolerances are then millimetres of a rod in one pose, whatever the CAD
//! export's units and placement, and the bores sit at (0, 0, 0) and (l, 0, 0).

use super::records::LoadedDesign;
use crate::geometry::primitives::{binary_stl, to_soup};
use crate::geometry::simplify::simplify;
use crate::geometry::validate::validate;
use crate::rod::BoreSpec;

/// The rod surface in the rod frame, mm, and the binary STL of it that the mesher reads.
pub struct RodFrameSurface {
    /// The binary STL of the surface (rod frame, mm).
    pub stl_bytes: Vec<u8>,
    /// Vertices (mm, rod frame) and triangles.
    pub vertices: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    /// Centre distance A→B in the plane of motion, mm.
    pub centre_distance_mm: f64,
    /// SHA-256 of the STL bytes (keys the classified-surface cache).
    pub digest: String,
    /// Rod frame (origin A, x̂, ŷ, ẑ) in the file's axes, metres, for meshes given by the user.
    pub frame: crate::geometry::mechanism_frame::MechanismFrame,
    /// File units → metres.
    pub to_metres: f64,
    /// Triangles of the export (the STL written has `triangles.len()`).
    pub triangles_export: usize,
    /// Largest distance of a kept vertex from the facets it absorbed, mm.
    pub simplify_max_error_mm: f64,
}

/// Tolerance of the simplification of the export before meshing, mm (5 µm: far below any element
/// size, above the float32 noise of a millimetre export).
pub const SIMPLIFY_TOLERANCE_MM: f64 = 0.005;

impl RodFrameSurface {
    /// The volume the surface encloses, mm³ (divergence theorem over its triangles).
    pub fn volume_mm3(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| nalgebra::Vector3::from(self.vertices[i as usize]));
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum::<f64>()
            .abs()
    }

    /// The pin axes in the rod frame: A at the origin, B at (l, 0, 0), along z.
    pub fn bores(&self) -> BoreSpec {
        BoreSpec::from_mm(
            [0.0, 0.0, 0.0],
            [self.centre_distance_mm, 0.0, 0.0],
            [0.0, 0.0, 1.0],
        )
    }
}

/// The validated surface of a loaded design in the rod frame, mm; simplified for gmsh when
/// `simplified` (a given mesh needs the surface only for its sharp re-entrant edges: the export as
/// it is, without the simplification's cost).
pub fn rod_frame_surface(d: &LoadedDesign, simplified: bool) -> RodFrameSurface {
    let f = &d.frame;
    let mut mesh = d.mesh.clone();
    for v in &mut mesh.vertices {
        let p = *v - f.origin;
        *v = nalgebra::Vector3::new(p.dot(&f.x), p.dot(&f.y), p.dot(&f.z)) * 1e3;
    }
    // what gmsh reads must not grow with the export's triangle count: flat facets cut into many
    // triangles merge back (zero error), curved ones stay within SIMPLIFY_TOLERANCE_MM
    let before = mesh.triangles.len();
    let (mesh, max_error) = if simplified {
        let (simpler, report) = simplify(&mesh, SIMPLIFY_TOLERANCE_MM);
        match validate(simpler) {
            Ok(v) if v.warnings.is_empty() => (v.mesh, report.max_error),
            _ => (mesh, report.max_error),
        }
    } else {
        (mesh, 0.0)
    };
    let bytes = binary_stl(&to_soup(&mesh));
    RodFrameSurface {
        vertices: mesh.vertices.iter().map(|v| [v.x, v.y, v.z]).collect(),
        triangles: mesh.triangles.clone(),
        centre_distance_mm: f.centre_distance * 1e3,
        digest: sha256_hex(&bytes),
        stl_bytes: bytes,
        frame: *f,
        to_metres: d.settings.units.to_metres(),
        triangles_export: before,
        simplify_max_error_mm: max_error,
    }
}

/// SHA-256 of `bytes`, lower-case hex (the key of gmsh's classified-surface cache).
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}
