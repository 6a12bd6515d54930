//! Tables for people (Markdown), shared by the commands and the study's reports.

use crate::geometry::design::DesignMass;

/// The table for people: the figures a rod designer compares with CAD, in mm and kg·m².
pub fn mass_table(designs: &[&DesignMass]) -> String {
    let mut out = String::from(
        "| design | mass [kg] | volume [cm³] | l1 [mm] | offset [mm] | I_zz pin axis [kg·m²] | I_xx long axis [kg·m²] | bores A / B [mm] | triangles |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in designs {
        out.push_str(&format!(
            "| {} | {:.6} | {:.3} | {:.3} | {:.3} | {:.6e} | {:.6e} | Ø{:.1} / Ø{:.1} | {} |\n",
            d.design,
            d.mass_kg,
            d.volume_m3 * 1e6,
            d.l1_m * 1e3,
            d.offset_m * 1e3,
            d.i_zz_kgm2,
            d.i_xx_kgm2,
            2e3 * d.crank_bore_radius_m,
            2e3 * d.piston_bore_radius_m,
            d.triangles
        ));
    }
    out
}

/// The stage-2 table for people: the peak crank–rod pin force of each design.
pub fn dynamics_table(designs: &[&crate::study::dynamics_stage::DesignDynamics]) -> String {
    let mut out = String::from(
        "| design | peak pin force [N] | at crank angle [°] | at t [s] | TDC formula [N] | ∂F/∂m3 [N/kg] | ∂F/∂l1 [N/mm] | ∂F/∂I_zz [N/(kg·m²)] | gravity |\n|---|---|---|---|---|---|---|---|---|\n",
    );
    for d in designs {
        let s = &d.sensitivity;
        out.push_str(&format!(
            "| {} | {:.2} | {:.3} | {:.5} | {:.2} | {:.2} | {:.3} | {:.2e} | {} |\n",
            d.design,
            d.peak_pin_force_n,
            d.peak_crank_angle_deg,
            d.peak_time_s,
            d.tdc_formula_n,
            s.d_mass_n_per_kg,
            s.d_l1_n_per_m * 1e-3,
            s.d_izz_n_per_kgm2,
            if d.gravity { "on" } else { "off" }
        ));
    }
    out
}
