//! The five committed designs against the thesis' Table 5.1 (SPEC "The five designs"): mass
//! within 0.1 %, l1 within 0.2 mm, long-axis inertia within 1 %, each a valid single solid with
//! its pins in bores; and the peak pin force of rows 1, 3, 4, 5 within 0.1 % of the thesis.

use rodstudy::geometry::design::mass_of_design;
use rodstudy::mechanism::{DrivenScene, Method, TABLE_5_1};
use rodstudy::stages::dynamics::dynamics;
use std::path::PathBuf;

fn design(n: u8) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("designs")
        .join(format!("design{n}.stl"))
}

#[test]
fn committed_designs_have_the_calibrated_properties() {
    for row in TABLE_5_1 {
        let d = mass_of_design(&design(row.design)).unwrap_or_else(|e| {
            panic!(
                "design {} must pass validation and the bore check: {e:#}",
                row.design
            )
        });
        let l1_target = row
            .l1_m
            .unwrap_or(rodstudy::mechanism::table_5_1::DESIGN_2_L1_M);
        let mass_err = (d.mass_kg - row.mass_kg) / row.mass_kg;
        let ixx_err = (d.i_xx_kgm2 - row.thesis_inertia_kgm2) / row.thesis_inertia_kgm2;
        // measured: mass and I_xx within 1.4e-6 of Table 5.1, l1 within 1e-6 m (the generator's
        // calibration on the exported STL)
        assert!(
            mass_err.abs() < 1e-5,
            "design {}: mass {} vs {} kg",
            row.design,
            d.mass_kg,
            row.mass_kg
        );
        assert!(
            (d.l1_m - l1_target).abs() < 1e-5,
            "design {}: l1 {} vs {} m",
            row.design,
            d.l1_m,
            l1_target
        );
        assert!(
            ixx_err.abs() < 1e-5,
            "design {}: I_xx {} vs {}",
            row.design,
            d.i_xx_kgm2,
            row.thesis_inertia_kgm2
        );
        assert!(
            d.offset_m.abs() < 1e-5 && d.offset_z_m.abs() < 1e-5,
            "design {}: symmetric",
            row.design
        );
        assert!(
            d.warnings.is_empty(),
            "design {}: {:?}",
            row.design,
            d.warnings
        );
        // Realistic bores: crank pin about 50 mm, piston pin about 25 mm across.
        assert!(
            (0.020..0.030).contains(&d.crank_bore_radius_m),
            "design {}: crank bore",
            row.design
        );
        assert!(
            (0.010..0.016).contains(&d.piston_bore_radius_m),
            "design {}: piston bore",
            row.design
        );
        // The pin-axis inertia is an order of magnitude above the long-axis one (SPEC finding).
        assert!(d.i_zz_kgm2 > 5.0 * d.i_xx_kgm2, "design {}", row.design);
    }
}

#[test]
fn committed_designs_reproduce_the_thesis_peak_forces() {
    for row in TABLE_5_1 {
        let d = mass_of_design(&design(row.design)).unwrap();
        let (dyn_, _) = dynamics(&d, &DrivenScene::default(), true, Method::ClosedForm).unwrap();
        let err = (dyn_.peak_pin_force_n - row.peak_force_n) / row.peak_force_n;
        if row.l1_m.is_some() {
            // measured within 4e-6 of the thesis' (rounded) peaks
            assert!(
                err.abs() < 4e-5,
                "design {}: {} N vs thesis {} N",
                row.design,
                dyn_.peak_pin_force_n,
                row.peak_force_n
            );
        } else {
            // Row 2 is unreachable: any rod of that mass peaks at 7481 N or more.
            assert!(
                dyn_.peak_pin_force_n > 7481.0,
                "design 2: {}",
                dyn_.peak_pin_force_n
            );
        }
    }
}
