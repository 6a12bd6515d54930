//! Cylinder fits to the vertices of a bore's facets: the axis from the facet normals (the
//! eigenvector of Σ n nᵀ of least eigenvalue: the normals of a cylinder are ⟂ to its axis), the
//! circle by Kåsa's algebraic fit (I. Kåsa, IEEE Trans. Instrum. Meas. 25 (1976)), refined by a few
//! Gauss–Newton steps of the geometric fit (Lukács, Martin & Marshall, *Faithful least-squares
//! fitting of spheres, cylinders, cones and tori*, 1998).

use nalgebra::{Matrix3, Vector3};

/// The direction with its largest component positive.
pub(super) fn canonical(a: Vector3<f64>) -> Vector3<f64> {
    let k = a.iamax();
    if a[k] < 0.0 { -a } else { a }
}

/// One fitted cylinder: a point of the axis, the unit axis, the radius, the RMS residual.
#[derive(Debug, Clone, Copy)]
pub(super) struct Cylinder {
    pub(super) origin: Vector3<f64>,
    pub(super) axis: Vector3<f64>,
    pub(super) radius: f64,
    pub(super) rms: f64,
}

/// Two unit vectors completing `a` to a right-handed orthonormal frame.
pub(super) fn frame_of(a: Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = a.cross(&helper).normalize();
    (u, a.cross(&u))
}

/// Kåsa's algebraic circle fit to plane points: (centre, radius), or None when degenerate.
pub(super) fn kasa(points: &[(f64, f64)]) -> Option<((f64, f64), f64)> {
    let n = points.len() as f64;
    let (mx, my) = points
        .iter()
        .fold((0.0, 0.0), |(a, b), &(x, y)| (a + x / n, b + y / n));
    let mut m = Matrix3::zeros();
    let mut rhs = Vector3::zeros();
    for &(x, y) in points {
        let (x, y) = (x - mx, y - my);
        let row = Vector3::new(x, y, 1.0);
        m += row * row.transpose();
        rhs -= row * (x * x + y * y);
    }
    let s = m.lu().solve(&rhs)?;
    let (cx, cy) = (-s.x / 2.0, -s.y / 2.0);
    let r2 = cx * cx + cy * cy - s.z;
    (r2 > 0.0).then(|| ((cx + mx, cy + my), r2.sqrt()))
}

/// Geometric cylinder fit to `points` starting from axis `axis`: Kåsa on the projection, then
/// Gauss–Newton over (centre offset ×2, axis tilt ×2, radius), the frame re-centred after each step.
pub(super) fn fit_cylinder(points: &[Vector3<f64>], axis: Vector3<f64>) -> Option<Cylinder> {
    if points.len() < 5 {
        return None;
    }
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    let mut a = axis.normalize();
    let (u, v) = frame_of(a);
    let plane: Vec<(f64, f64)> = points
        .iter()
        .map(|p| ((p - mean).dot(&u), (p - mean).dot(&v)))
        .collect();
    let ((cx, cy), mut r) = kasa(&plane)?;
    let mut o = mean + u * cx + v * cy;
    let mut rms = f64::INFINITY;
    for _ in 0..12 {
        let (u, v) = frame_of(a);
        // centre the origin on the points' axial mean
        let wm = points.iter().map(|p| (p - o).dot(&a)).sum::<f64>() / points.len() as f64;
        o += a * wm;
        let mut jtj = nalgebra::Matrix5::<f64>::zeros();
        let mut jtr = nalgebra::Vector5::<f64>::zeros();
        let mut ss = 0.0;
        for p in points {
            let d = p - o;
            let (x, y, w) = (d.dot(&u), d.dot(&v), d.dot(&a));
            let rho = (x * x + y * y).sqrt();
            if rho == 0.0 {
                continue;
            }
            let res = rho - r;
            ss += res * res;
            let j = nalgebra::Vector5::new(-x / rho, -y / rho, -w * x / rho, -w * y / rho, -1.0);
            jtj += j * j.transpose();
            jtr += j * res;
        }
        rms = (ss / points.len() as f64).sqrt();
        let Some(step) = jtj.cholesky().map(|c| c.solve(&(-jtr))) else {
            break;
        };
        o += u * step[0] + v * step[1];
        a = (a + u * step[2] + v * step[3]).normalize();
        r += step[4];
        if step.norm() <= 1e-13 * r.max(1e-300) {
            break;
        }
    }
    // the residual at the final parameters
    let mut ss = 0.0;
    for p in points {
        let d = p - o;
        let rho = (d - a * a.dot(&d)).norm();
        ss += (rho - r) * (rho - r);
    }
    rms = rms.min((ss / points.len() as f64).sqrt());
    (r.is_finite() && r > 0.0).then_some(Cylinder {
        origin: o,
        axis: a,
        radius: r,
        rms,
    })
}
